//! `task_controller`: robot state, skin cells, goal, force reference and arrangement in; arm
//! joint velocities, base twist and controller state out (`crate::task_controller` does the work).
use std::cell::RefCell;
use std::rc::Rc;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use anyhow::{Context as _, Result};
use futures::executor::LocalSpawner;
use futures::task::LocalSpawnExt;
use futures::{Stream, StreamExt};
use r2r::diagnostic_msgs::msg::DiagnosticArray;
use r2r::geometry_msgs::msg::{PoseStamped, Twist, TwistStamped};
use r2r::nav_msgs::msg::Odometry;
use r2r::sensor_msgs::msg::{JointState, LaserScan};
use r2r::skin_msgs::msg::{Arrangement, ControllerState};
use r2r::std_msgs::msg::{Float64, Float64MultiArray, Header, String as StringMsg};
use r2r::{ParameterValue, RosParams};
use skin_core::controller::{ControllerConfig, ControllerSetup};
use skin_core::model::RobotModel;
use skin_core::param_file::declare::Declared;

use super::{file_setting, local, resolve, resolved, ros_now, OnceLog};
use crate::convert::robot::time_msg;
use crate::diagnostics::{self, level, Diagnostics, HierarchyReport, LoopReport};
use crate::heartbeat::{self, CommandType, Commander};
use crate::lifecycle::{self, Lifecycle};
use crate::qos;
use crate::robot_description::{self, UrdfSource};
use crate::ros_params::StructParams;
use crate::task_controller::{
    Freshness, Idle, InputError, Outputs, TaskController, TaskControllerParams, Trigger, START_ONLY_SECTION,
};
use crate::tf::BASE_FRAME;
use crate::timing::Timing;
use crate::topics::*;
use r2r::lifecycle_msgs::msg::{
    State as StateMsg, Transition, Transition as TransitionMsg, TransitionDescription, TransitionEvent,
};
use r2r::lifecycle_msgs::srv::{ChangeState, GetAvailableStates, GetAvailableTransitions, GetState};

/// Node name.
pub const NODE: &str = "task_controller";

/// Start-up options (the binary's command line; `None`: the ROS parameter, else the default).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct Options {
    /// Controller setup file (skin_core::controller::ControllerSetup) [default: config/controller/tomm.yaml; ROS parameter setup_file].
    #[arg(long, value_name = "FILE")]
    pub setup: Option<String>,
}

/// The base command's publisher: `Twist`, or `TwistStamped` (`base_command_stamped`).
enum BasePublisher {
    Twist(r2r::Publisher<Twist>),
    Stamped(r2r::Publisher<TwistStamped>),
}

impl BasePublisher {
    fn publish(&self, twist: &Twist, stamp: &r2r::builtin_interfaces::msg::Time) -> r2r::Result<()> {
        match self {
            BasePublisher::Twist(p) => p.publish(twist),
            BasePublisher::Stamped(p) => p.publish(&TwistStamped {
                header: Header { stamp: stamp.clone(), frame_id: BASE_FRAME.into() },
                twist: twist.clone(),
            }),
        }
    }

    fn subscription_count(&self) -> r2r::Result<usize> {
        match self {
            BasePublisher::Twist(p) => p.get_inter_process_subscription_count(),
            BasePublisher::Stamped(p) => p.get_inter_process_subscription_count(),
        }
    }
}

struct Publishers {
    arms: Vec<r2r::Publisher<Float64MultiArray>>,
    base: Option<BasePublisher>,
    state: r2r::Publisher<ControllerState>,
}

impl Publishers {
    /// Sends `out` (a stamped base command stamped `stamp`); the first failure is returned with
    /// the topic.
    fn send(
        &self,
        out: &Outputs,
        topics: &[String],
        stamp: &r2r::builtin_interfaces::msg::Time,
    ) -> std::result::Result<(), String> {
        for ((p, m), t) in self.arms.iter().zip(out.arms).zip(topics) {
            p.publish(m).map_err(|e| format!("{t}: {e}"))?;
        }
        if let (Some(p), Some(m)) = (&self.base, out.base) {
            p.publish(m, stamp).map_err(|e| format!("{CMD_VEL}: {e}"))?;
        }
        if let Some(m) = out.state {
            self.state.publish(m).map_err(|e| format!("{CONTROLLER_STATE}: {e}"))?;
        }
        Ok(())
    }
}

/// Whether this controller may command (one commander per command topic).
#[derive(Debug, Clone, PartialEq)]
enum Command {
    /// At start: listening for another controller's heartbeat until then; nothing is sent.
    Listening(Instant),
    /// Sending commands and the heartbeat.
    Active,
    /// Another controller commands the same topics: nothing is sent (the reason).
    Yielded(String),
}

/// A late period (its gap to the last commands above this many periods) may have tripped
/// `skin_watchdog`, whose default timeout is 1.5 periods: it sends only the heartbeat, so that the
/// watchdog's trip notice, if any, is in before the next commands.
const WATCHDOG_PERIODS: f64 = 1.5;

/// What a timer period sends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Period {
    /// Nothing (listening at start) or the heartbeat alone (a late period).
    Silent,
    /// Zero commands (holding or taking over from the watchdog).
    Hold,
    /// The commands of a cycle when the inputs are fresh.
    Command,
}

/// Periods of zero commands (with the heartbeat) when this controller takes over from
/// `skin_watchdog`'s zeros: the watchdog stops on the first heartbeat, so no zero of its own
/// falls between the commands that ramp up from zero.
const TAKE_OVER_PERIODS: u32 = 2;

struct Shared {
    tc: TaskController,
    lifecycle: Lifecycle,
    transitions: r2r::Publisher<TransitionEvent>,
    pubs: Publishers,
    heartbeat: r2r::Publisher<Header>,
    beat: Header,
    me: Commander,
    command: Command,
    /// ROS time of the last commands sent [s].
    last_sent_s: Option<f64>,
    /// Periods left of zero commands while taking over ([`TAKE_OVER_PERIODS`]).
    take_over: u32,
    topics: Vec<String>,
    logger: String,
    clock: Arc<Mutex<r2r::Clock>>,
    fault_log: OnceLog<2>,
    publish_failed: bool,
    stale: bool,
    timing: Timing,
    /// `/diagnostics`: the reports, the cycle times since the last one, the overrun counts.
    diagnostics: Diagnostics,
    diagnostics_pub: r2r::Publisher<DiagnosticArray>,
    period_timing: Timing,
    overruns: u64,
    late_periods: u64,
}

impl Shared {
    /// Sends the outputs `which` makes, then the heartbeat; nothing unless this controller is the
    /// commander.
    fn publish(&mut self, which: impl FnOnce(&mut TaskController) -> Outputs<'_>) {
        if self.command != Command::Active {
            return;
        }
        let now = self.now();
        let stamp = time_msg(now);
        let out = which(&mut self.tc);
        let sent = self.pubs.send(&out, &self.topics, &stamp);
        self.beat.stamp = stamp;
        let sent =
            sent.and_then(|()| self.heartbeat.publish(&self.beat).map_err(|e| format!("{}: {e}", heartbeat::TOPIC)));
        if let Err(e) = sent {
            if !std::mem::replace(&mut self.publish_failed, true) {
                r2r::log_error!(&self.logger, "publishing failed: {e}");
            }
        }
        self.last_sent_s = Some(now);
    }

    /// Timer mode, before a period's commands: the end of the listening window, a late period.
    fn before_period(&mut self, now: f64) -> Period {
        if let Command::Listening(until) = self.command {
            if Instant::now() < until {
                return Period::Silent;
            }
            r2r::log_info!(&self.logger, "no other task_controller heard on {}: commanding", self.topics.join(", "));
            self.command = Command::Active;
        }
        let period = 1.0 / self.tc.params().control_rate_hz;
        if self.command == Command::Active
            && self.last_sent_s.is_some_and(|last| now - last > WATCHDOG_PERIODS * period)
        {
            self.late_periods += 1;
            self.beat(now);
            return Period::Silent;
        }
        if self.take_over > 0 {
            self.take_over -= 1;
            return Period::Hold;
        }
        Period::Command
    }

    /// Sends the heartbeat alone.
    fn beat(&mut self, now: f64) {
        self.beat.stamp = time_msg(now);
        if let Err(e) = self.heartbeat.publish(&self.beat) {
            if !std::mem::replace(&mut self.publish_failed, true) {
                r2r::log_error!(&self.logger, "{}: {e}", heartbeat::TOPIC);
            }
        }
        self.last_sent_s = Some(now);
    }

    /// Zeros went out from someone else: the commands continue from zero after
    /// [`TAKE_OVER_PERIODS`] zero periods.
    fn restart_from_zero(&mut self) {
        self.tc.restart_from_zero();
        self.take_over = TAKE_OVER_PERIODS;
    }

    /// A heartbeat on `/controller/heartbeat`: another controller on the same command topics
    /// that came first makes this one give way.
    fn on_heartbeat(&mut self, msg: &Header) {
        let Some(other) = Commander::parse(&msg.frame_id) else { return };
        if other == self.me || matches!(self.command, Command::Yielded(_)) {
            return;
        }
        if self.me.yields_to(&other) {
            let shared: Vec<&str> = self.me.shared_topics(&other).collect();
            let why = format!(
                "another task_controller (process {}, started earlier) commands {}: this one sends nothing and stops (one commander per robot)",
                other.process,
                shared.join(", ")
            );
            r2r::log_error!(&self.logger, "{why}");
            self.command = Command::Yielded(why);
        } else if self.fault_log.first(1) {
            r2r::log_warn!(
                &self.logger,
                "another task_controller (process {}) heard on the same command topics: it must give way",
                other.process
            );
        }
    }

    /// A managed-node transition asked by `id` (or `label` when `id` is 0): taken and announced on
    /// `transition_event`, or refused with the reason in the log. `shutdown` ends the node (zero
    /// commands first, as on SIGTERM).
    fn change_state(&mut self, id: u8, label: &str) -> bool {
        match self.lifecycle.change(id, label) {
            Ok(t) => {
                let stamp = std::time::SystemTime::now()
                    .duration_since(std::time::UNIX_EPOCH)
                    .map_or(0, |d| d.as_nanos() as u64);
                let event = TransitionEvent {
                    timestamp: stamp,
                    transition: TransitionMsg { id: t.id, label: t.label.into() },
                    start_state: state_msg(t.from),
                    goal_state: state_msg(t.to),
                };
                if let Err(e) = self.transitions.publish(&event) {
                    r2r::log_error!(&self.logger, "transition_event: {e}");
                }
                let what = match t.to {
                    lifecycle::State::Active => "commanding",
                    lifecycle::State::Finalized => "stopping",
                    _ => "holding: the commands ramp to zero within the acceleration limits",
                };
                r2r::log_info!(&self.logger, "lifecycle {}: {} -> {} ({what})", t.label, t.from.label(), t.to.label());
                if t.to == lifecycle::State::Finalized {
                    crate::shutdown::request();
                }
                true
            }
            Err(e) => {
                r2r::log_warn!(&self.logger, "lifecycle: {e}");
                false
            }
        }
    }

    /// Whether this period may command motion (the managed node is active).
    fn active(&self) -> bool {
        self.lifecycle.state() == lifecycle::State::Active
    }

    /// `skin_watchdog` sent zeros: continue from zero.
    fn on_watchdog(&mut self, msg: &Header) {
        self.restart_from_zero();
        r2r::log_warn!(&self.logger, "skin_watchdog sent zero commands ({}): continuing from zero", msg.frame_id);
    }

    fn run_cycle(&mut self, t_s: f64, stamp: &r2r::builtin_interfaces::msg::Time) {
        let start = Instant::now();
        self.publish(|tc| tc.cycle(t_s, stamp));
        let took = start.elapsed();
        self.timing.add(took);
        self.period_timing.add(took);
        if took.as_secs_f64() > 1.0 / self.tc.params().control_rate_hz {
            self.overruns += 1;
        }
        if let Some(f) = self.tc.last_fault() {
            if self.fault_log.first(0) {
                r2r::log_warn!(
                    &self.logger,
                    "cycle at t = {t_s:.4} s was a safe-stop step: {f} (further ones counted)"
                );
            }
        }
    }

    /// The node's clock now [s].
    fn now(&self) -> f64 {
        self.clock.lock().unwrap().get_now().map(|d| d.as_secs_f64()).unwrap_or(0.0)
    }

    /// What the control loop does now, for `/diagnostics`: level and message.
    fn loop_status(&self, now: f64) -> (u8, String) {
        if let Command::Yielded(why) = &self.command {
            return (level::ERROR, format!("not commanding: {why}"));
        }
        if let Command::Listening(_) = self.command {
            return (level::OK, "listening for another task_controller before commanding".into());
        }
        if !self.active() {
            let state = self.lifecycle.state().label();
            return (level::WARN, format!("{state}: holding, zero commands until activated"));
        }
        match self.tc.freshness(now) {
            Freshness::Fresh => (level::OK, "FRESH: commanding".into()),
            Freshness::Waiting => (level::WARN, format!("WAITING for {}: zero commands", self.tc.missing().join(", "))),
            Freshness::Stale { input, age_s, timeout_s } => (
                level::ERROR,
                format!("STALE: {input} {age_s:.3} s old (timeout {timeout_s} s): the commands ramp to zero"),
            ),
        }
    }

    /// Publishes the `/diagnostics` report of the last period.
    fn report_diagnostics(&mut self) {
        let now = self.now();
        let (mut lvl, mut message) = self.loop_status(now);
        let p = self.tc.params();
        if self.period_timing.count > 0 && self.period_timing.max.as_secs_f64() > 1.0 / p.control_rate_hz {
            lvl = lvl.max(level::WARN);
            message += "; a cycle took longer than the control period";
        }
        let (cycles, faults) = self.tc.counts();
        let lp = LoopReport {
            level: lvl,
            message,
            lifecycle: self.lifecycle.state().label(),
            rate_hz: p.control_rate_hz,
            timing: std::mem::take(&mut self.period_timing),
            cycles,
            overruns: self.overruns,
            late_periods: self.late_periods,
            safe_stop_cycles: faults,
            idle_periods: self.tc.idle_periods(),
        };
        let inputs = self.tc.input_ages(now);
        let stamp = time_msg(system_now_s());
        let hierarchy = HierarchyReport::of(self.tc.controller());
        let report = self.diagnostics.report(stamp, &lp, &hierarchy, &inputs, p.max_stamp_lead_s, self.tc.issues());
        if let Err(e) = self.diagnostics_pub.publish(&report) {
            if !std::mem::replace(&mut self.publish_failed, true) {
                r2r::log_error!(&self.logger, "{}: {e}", diagnostics::TOPIC);
            }
        }
    }

    /// Logs a refused message the first time its kind occurs (all are counted).
    fn refused(&self, result: std::result::Result<(), InputError>) {
        if let Err(e) = result {
            if e.first {
                r2r::log_warn!(&self.logger, "{e} (message ignored; further ones are counted in /controller/state)");
            }
        }
    }

    /// Trigger `inputs`: a cycle when the input set is complete and newer (a holding period
    /// when the managed node is not active).
    fn maybe_cycle(&mut self) {
        if self.tc.params().trigger == Trigger::Inputs {
            if let Some(stamp) = self.tc.ready_stamp() {
                let t = crate::convert::robot::time_s(&stamp);
                if self.active() {
                    self.run_cycle(t, &stamp);
                } else {
                    self.tc.mark_cycle(&stamp);
                    self.publish(|tc| tc.idle_outputs(Idle::Waiting, &stamp));
                }
            }
        }
    }
}

/// The running node: [`TaskControllerHandle::stop`] sends zero commands on every command topic.
pub struct TaskControllerHandle {
    shared: Rc<RefCell<Shared>>,
}

impl TaskControllerHandle {
    /// Zero commands on every command topic (and a heartbeat): a stopping controller's last word
    /// (unless another controller commands them).
    pub fn send_zeros(&self) {
        let mut s = self.shared.borrow_mut();
        if let Command::Listening(_) = s.command {
            s.command = Command::Active; // nobody else was heard: the zeros are ours to send
        }
        s.publish(|tc| tc.zero_outputs());
    }

    /// Zero commands on every command topic (unless another controller commands them), then the
    /// summary in the log.
    pub fn stop(&self) {
        self.send_zeros();
        let s = self.shared.borrow();
        let (cycles, faults) = s.tc.counts();
        r2r::log_info!(
            &s.logger,
            "stopping after {cycles} cycles ({faults} safe-stop steps, {} idle periods): cycle {}; input issues: {}; zero commands sent on {}",
            s.tc.idle_periods(),
            s.timing,
            s.tc.issues(),
            s.topics.join(", ")
        );
    }

    /// Trigger `inputs`: runs a cycle when a complete, newer input set is buffered. Call after
    /// every executor pass, so that every message taken in the pass (a goal with the state) is
    /// in before the cycle.
    pub fn poll(&self) {
        self.shared.borrow_mut().maybe_cycle();
    }

    /// The output topics (arm commands, base twist if any, controller state).
    pub fn output_topics(&self) -> Vec<String> {
        let s = self.shared.borrow();
        let mut out = s.topics.clone();
        out.extend(s.pubs.base.as_ref().map(|_| CMD_VEL.to_string()));
        out.push(CONTROLLER_STATE.into());
        out
    }

    /// Matched subscribers in other processes of an output topic (`None`: not an output).
    pub fn subscription_count(&self, topic: &str) -> Option<r2r::Result<usize>> {
        let s = self.shared.borrow();
        let p = &s.pubs;
        match topic {
            CMD_VEL => p.base.as_ref().map(BasePublisher::subscription_count),
            CONTROLLER_STATE => Some(p.state.get_inter_process_subscription_count()),
            _ => s.topics.iter().position(|t| t == topic).map(|k| p.arms[k].get_inter_process_subscription_count()),
        }
    }

    /// Why this controller gave way to another one on its command topics, if it did.
    pub fn yielded(&self) -> Option<String> {
        match &self.shared.borrow().command {
            Command::Yielded(why) => Some(why.clone()),
            _ => None,
        }
    }

    /// Whether the node was shut down through its lifecycle (`change_state` shutdown): the
    /// service's reply is then still on its way to the caller.
    pub fn finalized(&self) -> bool {
        self.shared.borrow().lifecycle.state() == lifecycle::State::Finalized
    }

    /// The controller's counts (cycles, safe-stop steps).
    pub fn counts(&self) -> (u64, u64) {
        self.shared.borrow().tc.counts()
    }
}

fn spawn_sub<M: 'static>(
    spawner: &LocalSpawner,
    mut stream: impl Stream<Item = M> + Unpin + 'static,
    shared: &Rc<RefCell<Shared>>,
    mut on: impl FnMut(&mut Shared, M) + 'static,
) -> Result<()> {
    let shared = shared.clone();
    spawner.spawn_local(async move {
        while let Some(msg) = stream.next().await {
            let mut s = shared.borrow_mut();
            on(&mut s, msg);
        }
    })?;
    Ok(())
}

/// A `lifecycle_msgs/msg/State`.
fn state_msg(s: lifecycle::State) -> StateMsg {
    StateMsg { id: s.id(), label: s.label().into() }
}

/// The managed-node services under `fqn` (change_state, get_state, get_available_states,
/// get_available_transitions, get_transition_graph). Each request is a few bytes of work: they
/// are served in the control loop.
fn serve_lifecycle(
    node: &mut r2r::Node,
    spawner: &LocalSpawner,
    shared: &Rc<RefCell<Shared>>,
    fqn: &str,
) -> Result<()> {
    let describe = |t: &lifecycle::Transition| TransitionDescription {
        transition: TransitionMsg { id: t.id, label: t.label.into() },
        start_state: state_msg(t.from),
        goal_state: state_msg(t.to),
    };
    let change = node.create_service::<ChangeState::Service>(&format!("{fqn}/change_state"), qos::services())?;
    spawn_sub(spawner, change, shared, |s, req| {
        let success = s.change_state(req.message.transition.id, &req.message.transition.label);
        let _ = req.respond(ChangeState::Response { success });
    })?;
    let get = node.create_service::<GetState::Service>(&format!("{fqn}/get_state"), qos::services())?;
    spawn_sub(spawner, get, shared, |s, req| {
        let _ = req.respond(GetState::Response { current_state: state_msg(s.lifecycle.state()) });
    })?;
    let states =
        node.create_service::<GetAvailableStates::Service>(&format!("{fqn}/get_available_states"), qos::services())?;
    spawn_sub(spawner, states, shared, |_, req| {
        let _ = req
            .respond(GetAvailableStates::Response { available_states: lifecycle::State::ALL.map(state_msg).to_vec() });
    })?;
    let available = node.create_service::<GetAvailableTransitions::Service>(
        &format!("{fqn}/get_available_transitions"),
        qos::services(),
    )?;
    spawn_sub(spawner, available, shared, move |s, req| {
        let _ = req.respond(GetAvailableTransitions::Response {
            available_transitions: s.lifecycle.available().map(describe).collect(),
        });
    })?;
    let graph = node
        .create_service::<GetAvailableTransitions::Service>(&format!("{fqn}/get_transition_graph"), qos::services())?;
    spawn_sub(spawner, graph, shared, move |_, req| {
        let _ = req.respond(GetAvailableTransitions::Response {
            available_transitions: lifecycle::TRANSITIONS.iter().map(describe).collect(),
        });
    })?;
    Ok(())
}

/// The system clock now \[s since the epoch\] (the stamp of `/diagnostics`, as diagnostic_updater's).
fn system_now_s() -> f64 {
    std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0.0, |d| d.as_secs_f64())
}

/// A start-up flag: the ROS parameter `key`, else false.
fn flag(node: &r2r::Node, key: &str) -> Result<bool> {
    let v: Option<bool> = node.get_parameter(key).with_context(|| format!("ROS parameter `{key}`"))?;
    Ok(v.unwrap_or(false))
}

/// Spins `node` until the URDF arrives on `topic` (`robot_description`, transient local: one
/// published before this node started is delivered too); meanwhile `/diagnostics` says the
/// controller is WAITING for it. Fails on an invalid URDF (naming the topic) and on a stop request.
fn wait_for_description(
    node: &mut r2r::Node,
    topic: &str,
    mobile_base: bool,
    diagnostics: &Diagnostics,
    diagnostics_pub: &r2r::Publisher<DiagnosticArray>,
) -> Result<RobotModel> {
    use futures::FutureExt as _;
    let logger = node.logger().to_string();
    let mut sub = node.subscribe::<StringMsg>(local(robot_description::TOPIC), qos::latched())?;
    let what = format!("the URDF on {topic} (std_msgs/String, transient local, as robot_state_publisher publishes it)");
    r2r::log_info!(&logger, "waiting for {what}");
    let mut next_report = Instant::now();
    loop {
        if crate::shutdown::requested() {
            anyhow::bail!("stopped while waiting for {what}");
        }
        if Instant::now() >= next_report {
            diagnostics_pub.publish(&diagnostics.waiting(time_msg(system_now_s()), &what))?;
            next_report += diagnostics::PERIOD;
        }
        node.spin_once(Duration::from_millis(50));
        if let Some(Some(msg)) = sub.next().now_or_never() {
            let model = robot_description::model(&msg.data, topic, mobile_base).map_err(anyhow::Error::msg)?;
            r2r::log_info!(&logger, "{topic}: robot `{}`, {} joints", model.name(), model.nv());
            return Ok(model);
        }
    }
}

/// Creates the node's parameters, subscriptions, publishers and timer, and spawns its tasks.
/// With `use_robot_description` it first waits for the URDF on `robot_description`.
pub fn start(node: &mut r2r::Node, spawner: &LocalSpawner, options: Options) -> Result<TaskControllerHandle> {
    let logger = node.logger().to_string();
    let setup = file_setting(node, options.setup, "setup_file", "config/controller/tomm.yaml")?;
    let setup_path = resolve(&setup, "setup_file")?;
    let fqn = node.fully_qualified_name()?;
    let diagnostics_pub = node.create_publisher::<DiagnosticArray>(diagnostics::TOPIC, qos::diagnostics())?;
    let mut diagnostics = Diagnostics::new(&fqn, "none");
    // The URDF: the setup's file, urdf_file, or the robot_description topic (exactly one).
    let urdf_file = file_setting(node, None, "urdf_file", "")?;
    let (use_topic, mobile_base) = (flag(node, "use_robot_description")?, flag(node, "mobile_base")?);
    let (setup_read, _) = ControllerSetup::load(&setup_path).context("controller setup")?;
    let topic = resolved(node, local(robot_description::TOPIC));
    let source = robot_description::choose(&urdf_file, use_topic, setup_read.urdf.as_deref(), &setup, &topic)
        .map_err(anyhow::Error::msg)?;
    let model = match &source {
        UrdfSource::Setup => None,
        UrdfSource::File(f) => Some(RobotModel::from_urdf_file(&resolve(f, "urdf_file")?).context("urdf_file")?),
        UrdfSource::Topic => {
            if let Some(u) = &setup_read.urdf {
                r2r::log_info!(&logger, "the URDF comes from {topic}: {setup}'s urdf {} is not read", u.display());
            }
            Some(wait_for_description(node, &topic, mobile_base, &diagnostics, &diagnostics_pub)?)
        }
    };
    let config = ControllerConfig::load_with_model(&setup_path, model).context("controller setup")?;
    diagnostics.set_hardware_id(config.model.name());
    let mut params =
        StructParams::new(TaskControllerParams::defaults(&config), TaskControllerParams::validate)?
            .with_specs(TaskControllerParams::all_specs())
            .with_start_only_section(START_ONLY_SECTION)
            .with_read_only(
                "setup_file",
                ParameterValue::String(setup.clone()),
                "Controller setup file (read at start)",
            )
            .with_read_only(
                "urdf_file",
                ParameterValue::String(urdf_file),
                "Robot URDF file instead of the setup's (empty: the setup's; read at start)",
            )
            .with_read_only(
                "use_robot_description",
                ParameterValue::Bool(use_topic),
                "Take the URDF from the robot_description topic (transient local) instead of a file (read at start)",
            )
            .with_read_only(
                "mobile_base",
                ParameterValue::Bool(mobile_base),
                "use_robot_description: the URDF is rooted at the base frame; the controller adds its planar base joints (read at start)",
            );
    params
        .apply_overrides(&node.params.lock().unwrap())
        .context("ROS parameter overrides (--ros-args -p / --params-file)")?;
    let initial = params.value().clone();
    let params = Arc::new(Mutex::new(params));
    let served: Arc<Mutex<dyn RosParams + Send>> = params.clone();
    let (param_services, mut param_changes) =
        node.make_derived_parameter_handler(served).context("declaring the parameters")?;

    let tc =
        TaskController::new(config, initial.clone(), ros_now(node)).map_err(|e| anyhow::anyhow!("{setup}: {e}"))?;
    let topics: Vec<String> = tc.arms().iter().map(|a| a.topic.clone()).collect();
    let pubs = Publishers {
        arms: topics
            .iter()
            .map(|t| node.create_publisher::<Float64MultiArray>(local(t), qos::stream()))
            .collect::<r2r::Result<_>>()?,
        base: match (tc.has_base(), initial.base_command_stamped) {
            (false, _) => None,
            (true, false) => Some(BasePublisher::Twist(node.create_publisher(local(CMD_VEL), qos::stream())?)),
            (true, true) => Some(BasePublisher::Stamped(node.create_publisher(local(CMD_VEL), qos::stream())?)),
        },
        state: node.create_publisher::<ControllerState>(local(CONTROLLER_STATE), qos::every_sample())?,
    };
    // The command topics as resolved in the node's namespace, for the log and subscriber counts.
    let mut all_topics: Vec<String> = topics.iter().map(|t| resolved(node, t)).collect();
    if tc.has_base() {
        all_topics.push(resolved(node, local(CMD_VEL)));
    }
    // Resolved names: the watchdog (in any namespace) zeroes these very topics.
    let mut described: Vec<String> =
        tc.arms().iter().map(|a| CommandType::Arm(a.joints.len()).describe(&resolved(node, local(&a.topic)))).collect();
    let base_type = if initial.base_command_stamped { CommandType::TwistStamped } else { CommandType::Twist };
    described.extend(tc.has_base().then(|| base_type.describe(&resolved(node, local(CMD_VEL)))));
    let me = Commander::this_process(&described);
    let beat = Header { stamp: time_msg(0.0), frame_id: me.to_string() };
    // Timer mode (a robot): listen for another commander first. Lockstep: the simulation's only.
    let command = match initial.trigger {
        Trigger::Timer => Command::Listening(Instant::now() + Duration::from_secs_f64(initial.commander_wait_s)),
        Trigger::Inputs => Command::Active,
    };
    r2r::log_info!(
        &logger,
        "{setup}: {} joints, {} cells; trigger {:?} at {} Hz, supervisor {:?}; commands on {}",
        tc.controller().config().model.nv(),
        tc.controller().config().layout.num_cells(),
        initial.trigger,
        initial.control_rate_hz,
        initial.supervisor,
        all_topics.join(", ")
    );
    let shared = Rc::new(RefCell::new(Shared {
        lifecycle: Lifecycle::default(),
        transitions: node.create_publisher::<TransitionEvent>(&format!("{fqn}/transition_event"), qos::stream())?,
        tc,
        pubs,
        heartbeat: node.create_publisher::<Header>(local(heartbeat::TOPIC), qos::stream())?,
        beat,
        me,
        command,
        last_sent_s: None,
        take_over: TAKE_OVER_PERIODS,
        topics: all_topics,
        logger: logger.clone(),
        clock: node.get_ros_clock(),
        fault_log: OnceLog::default(),
        publish_failed: false,
        stale: false,
        timing: Timing::default(),
        diagnostics,
        diagnostics_pub,
        period_timing: Timing::default(),
        overruns: 0,
        late_periods: 0,
    }));

    // Parameter requests are served on a thread of their own: a request of any size (each set
    // validates the whole struct) must not hold up the control timer. The spin (this thread)
    // only takes the request; the control timer reads the values with try_lock.
    let log = logger.clone();
    let log_changes = async move {
        while let Some((name, value)) = param_changes.next().await {
            r2r::log_info!(&log, "parameter {name} set to {value:?}");
        }
    };
    std::thread::Builder::new()
        .name("task_controller parameters".into())
        .spawn(move || futures::executor::block_on(futures::future::join(param_services, log_changes)))
        .context("starting the parameter thread")?;

    serve_lifecycle(node, spawner, &shared, &fqn)?;
    if initial.autostart {
        let mut s = shared.borrow_mut();
        s.change_state(Transition::TRANSITION_CONFIGURE as u8, "");
        s.change_state(Transition::TRANSITION_ACTIVATE as u8, "");
    } else {
        r2r::log_info!(
            &logger,
            "holding until activated: ros2 lifecycle set {fqn} configure, then activate (or {fqn}/change_state)"
        );
    }
    let beats = node.subscribe::<Header>(local(heartbeat::TOPIC), qos::stream())?;
    spawn_sub(spawner, beats, &shared, |s, msg| s.on_heartbeat(&msg))?;
    let trips = node.subscribe::<Header>(local(WATCHDOG), qos::stream())?;
    spawn_sub(spawner, trips, &shared, |s, msg| s.on_watchdog(&msg))?;
    let js = node.subscribe::<JointState>(local(JOINT_STATES), qos::sensor_input(10))?;
    spawn_sub(spawner, js, &shared, |s, msg| {
        let now = s.now();
        let Shared { tc, logger, .. } = &mut *s;
        let result = tc.on_joint_states(&msg, now, |i| {
            r2r::log_warn!(logger, "{JOINT_STATES}: {i} (further ones are counted in /controller/state)");
        });
        s.refused(result);
    })?;
    if shared.borrow().tc.has_base() {
        let odom = node.subscribe::<Odometry>(local(ODOM), qos::sensor_input(10))?;
        spawn_sub(spawner, odom, &shared, |s, msg| {
            let result = s.tc.on_odometry(&msg, s.now());
            s.refused(result);
        })?;
    }
    // Read from the serialized bytes (convert::cdr_cells: the largest input, on the latency path).
    let cells = node.subscribe_raw(local(CELLS), CELLS_TYPE, qos::sensor_input(1000))?;
    spawn_sub(spawner, cells, &shared, |s, msg| {
        let now = s.now();
        let Shared { tc, logger, .. } = &mut *s;
        let result = tc.on_cells_cdr(&msg, now, |i| {
            r2r::log_warn!(logger, "{CELLS}: {i} (further ones are counted in /controller/state)");
        });
        s.refused(result);
    })?;
    if initial.use_scan {
        let scan = node.subscribe::<LaserScan>(local(SCAN), qos::sensor_input(10))?;
        spawn_sub(spawner, scan, &shared, |s, msg| {
            let result = s.tc.on_scan(&msg, s.now());
            s.refused(result);
        })?;
    }
    let goal = node.subscribe::<PoseStamped>(local(GOAL), qos::user_input())?;
    spawn_sub(spawner, goal, &shared, |s, msg| match s.tc.on_goal(&msg) {
        Ok(()) => r2r::log_info!(
            &s.logger,
            "{GOAL}: goal ({:.3}, {:.3}, {:.3})",
            msg.pose.position.x,
            msg.pose.position.y,
            msg.pose.position.z
        ),
        Err(e) => s.refused(Err(e)),
    })?;
    let force = node.subscribe::<Float64>(local(FORCE_REFERENCE), qos::user_input())?;
    spawn_sub(spawner, force, &shared, |s, msg| {
        let result = s.tc.on_force_reference(msg.data);
        s.refused(result);
    })?;
    let arrangement = node.subscribe::<Arrangement>(local(ARRANGEMENT), qos::latched())?;
    spawn_sub(spawner, arrangement, &shared, |s, msg| match s.tc.on_arrangement(&msg) {
        Ok(Some(note)) => r2r::log_info!(&s.logger, "{ARRANGEMENT}: {note}"),
        Ok(None) => {}
        Err(e) => s.refused(Err(e)),
    })?;

    let mut report_timer = node.create_wall_timer(diagnostics::PERIOD)?;
    let reporter = shared.clone();
    spawner.spawn_local(async move {
        while report_timer.tick().await.is_ok() {
            reporter.borrow_mut().report_diagnostics();
        }
    })?;

    if initial.trigger == Trigger::Timer {
        let mut timer = node.create_timer(Duration::from_secs_f64(1.0 / initial.control_rate_hz))?;
        let shared = shared.clone();
        spawner.spawn_local(async move {
            while timer.tick().await.is_ok() {
                let mut s = shared.borrow_mut();
                let now = s.now();
                let period = s.before_period(now);
                if period == Period::Silent {
                    continue;
                }
                let hold = period == Period::Hold || !s.active();
                // busy serving a request: this period keeps the values it had
                if let Ok(p) = params.try_lock() {
                    s.tc.take_settable(p.value());
                }
                match s.tc.freshness(now) {
                    Freshness::Fresh if hold => s.publish(|tc| tc.idle_outputs(Idle::Waiting, &time_msg(now))),
                    Freshness::Fresh => {
                        if std::mem::replace(&mut s.stale, false) {
                            r2r::log_info!(&s.logger, "inputs fresh again: control resumes");
                        }
                        s.run_cycle(now, &time_msg(now));
                    }
                    state => {
                        if !std::mem::replace(&mut s.stale, true) {
                            let why = match state {
                                Freshness::Stale { input, age_s, timeout_s } => {
                                    format!("{input} {age_s:.3} s old (allowed: [-max_stamp_lead_s, {timeout_s}] s)")
                                }
                                _ => format!("waiting for {}", s.tc.missing().join(", ")),
                            };
                            r2r::log_warn!(&s.logger, "commands ramp to zero: {why}");
                        }
                        let why = if state == Freshness::Waiting { Idle::Waiting } else { Idle::Stale };
                        s.publish(|tc| tc.idle_outputs(why, &time_msg(now)));
                    }
                }
            }
        })?;
    }
    Ok(TaskControllerHandle { shared })
}
