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
use r2r::geometry_msgs::msg::{PoseStamped, Twist};
use r2r::nav_msgs::msg::Odometry;
use r2r::sensor_msgs::msg::{JointState, LaserScan};
use r2r::skin_msgs::msg::{Arrangement, ControllerState};
use r2r::std_msgs::msg::{Float64, Float64MultiArray};
use r2r::{ParameterValue, RosParams};
use skin_core::controller::ControllerConfig;

use super::topics::*;
use super::{file_setting, local, resolve, resolved, ros_now, OnceLog, Timing};
use crate::convert::robot::time_msg;
use crate::qos;
use crate::ros_params::StructParams;
use crate::task_controller::{Idle, InputError, Outputs, TaskController, TaskControllerParams, Trigger, DESCRIPTIONS, START_ONLY};

/// Node name.
pub const NODE: &str = "task_controller";

/// Start-up options (the binary's command line; `None`: the ROS parameter, else the default).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct Options {
    /// Controller setup file (skin_core::controller::ControllerSetup) [default: config/controller/tomm.yaml; ROS parameter setup_file].
    #[arg(long, value_name = "FILE")]
    pub setup: Option<String>,
}

struct Publishers {
    arms: Vec<r2r::Publisher<Float64MultiArray>>,
    base: Option<r2r::Publisher<Twist>>,
    state: r2r::Publisher<ControllerState>,
}

impl Publishers {
    /// Sends `out`; the first failure is returned with the topic.
    fn send(&self, out: &Outputs, topics: &[String]) -> std::result::Result<(), String> {
        for ((p, m), t) in self.arms.iter().zip(out.arms).zip(topics) {
            p.publish(m).map_err(|e| format!("{t}: {e}"))?;
        }
        if let (Some(p), Some(m)) = (&self.base, out.base) {
            p.publish(m).map_err(|e| format!("{CMD_VEL}: {e}"))?;
        }
        if let Some(m) = out.state {
            self.state.publish(m).map_err(|e| format!("{CONTROLLER_STATE}: {e}"))?;
        }
        Ok(())
    }
}

struct Shared {
    tc: TaskController,
    pubs: Publishers,
    topics: Vec<String>,
    logger: String,
    clock: Arc<Mutex<r2r::Clock>>,
    fault_log: OnceLog<1>,
    publish_failed: bool,
    stale: bool,
    timing: Timing,
}

impl Shared {
    fn publish(&mut self, which: impl FnOnce(&mut TaskController) -> Outputs<'_>) {
        let out = which(&mut self.tc);
        if let Err(e) = self.pubs.send(&out, &self.topics) {
            if !std::mem::replace(&mut self.publish_failed, true) {
                r2r::log_error!(&self.logger, "publishing failed: {e}");
            }
        }
    }

    fn run_cycle(&mut self, t_s: f64, stamp: &r2r::builtin_interfaces::msg::Time) {
        let start = Instant::now();
        self.publish(|tc| tc.cycle(t_s, stamp));
        self.timing.add(start.elapsed());
        if let Some(f) = self.tc.last_fault() {
            if self.fault_log.first(0) {
                r2r::log_warn!(&self.logger, "cycle at t = {t_s:.4} s was a safe-stop step: {f} (further ones counted)");
            }
        }
    }

    /// The node's clock now \[s\].
    fn now(&self) -> f64 {
        self.clock.lock().unwrap().get_now().map(|d| d.as_secs_f64()).unwrap_or(0.0)
    }

    /// Logs a refused message the first time its kind occurs (all are counted).
    fn refused(&self, result: std::result::Result<(), InputError>) {
        if let Err(e) = result {
            if e.first {
                r2r::log_warn!(&self.logger, "{e} (message ignored; further ones are counted in /controller/state)");
            }
        }
    }

    /// Trigger `inputs`: a cycle when the input set is complete and newer.
    fn maybe_cycle(&mut self) {
        if self.tc.params().trigger == Trigger::Inputs {
            if let Some(stamp) = self.tc.ready_stamp() {
                let t = crate::convert::robot::time_s(&stamp);
                self.run_cycle(t, &stamp);
            }
        }
    }
}

/// The running node: [`TaskControllerHandle::stop`] sends zero commands on every command topic.
pub struct TaskControllerHandle {
    shared: Rc<RefCell<Shared>>,
}

impl TaskControllerHandle {
    /// Zero commands on every command topic, then the summary in the log.
    pub fn stop(&self) {
        let mut s = self.shared.borrow_mut();
        s.publish(|tc| tc.zero_outputs());
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
            CMD_VEL => p.base.as_ref().map(|b| b.get_inter_process_subscription_count()),
            CONTROLLER_STATE => Some(p.state.get_inter_process_subscription_count()),
            _ => s.topics.iter().position(|t| t == topic).map(|k| p.arms[k].get_inter_process_subscription_count()),
        }
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

/// Creates the node's parameters, subscriptions, publishers and timer, and spawns its tasks.
pub fn start(node: &mut r2r::Node, spawner: &LocalSpawner, options: Options) -> Result<TaskControllerHandle> {
    let logger = node.logger().to_string();
    let setup = file_setting(node, options.setup, "setup_file", "config/controller/tomm.yaml")?;
    let config = ControllerConfig::load(&resolve(&setup, "setup_file")?).context("controller setup")?;
    let mut params = StructParams::new(TaskControllerParams::defaults(&config), TaskControllerParams::validate, DESCRIPTIONS)?
        .with_start_only(START_ONLY)
        .with_read_only("setup_file", ParameterValue::String(setup.clone()), "Controller setup file (read at start)");
    params
        .apply_overrides(&node.params.lock().unwrap())
        .context("ROS parameter overrides (--ros-args -p / --params-file)")?;
    let initial = params.value().clone();
    let params = Arc::new(Mutex::new(params));
    let served: Arc<Mutex<dyn RosParams + Send>> = params.clone();
    let (param_services, mut param_changes) = node.make_derived_parameter_handler(served).context("declaring the parameters")?;
    spawner.spawn_local(param_services)?;

    let tc = TaskController::new(config, initial.clone(), ros_now(node)).map_err(|e| anyhow::anyhow!("{setup}: {e}"))?;
    let topics: Vec<String> = tc.arms().iter().map(|a| a.topic.clone()).collect();
    let pubs = Publishers {
        arms: topics.iter().map(|t| node.create_publisher::<Float64MultiArray>(local(t), qos::stream())).collect::<r2r::Result<_>>()?,
        base: if tc.has_base() { Some(node.create_publisher::<Twist>(local(CMD_VEL), qos::stream())?) } else { None },
        state: node.create_publisher::<ControllerState>(local(CONTROLLER_STATE), qos::stream())?,
    };
    // The command topics as resolved in the node's namespace, for the log and subscriber counts.
    let mut all_topics: Vec<String> = topics.iter().map(|t| resolved(node, t)).collect();
    if tc.has_base() {
        all_topics.push(resolved(node, local(CMD_VEL)));
    }
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
        tc,
        pubs,
        topics: all_topics,
        logger: logger.clone(),
        clock: node.get_ros_clock(),
        fault_log: OnceLog::default(),
        publish_failed: false,
        stale: false,
        timing: Timing::default(),
    }));

    let log = logger.clone();
    spawner.spawn_local(async move {
        while let Some((name, value)) = param_changes.next().await {
            r2r::log_info!(&log, "parameter {name} set to {value:?}");
        }
    })?;

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
        Ok(()) => r2r::log_info!(&s.logger, "{GOAL}: goal ({:.3}, {:.3}, {:.3})", msg.pose.position.x, msg.pose.position.y, msg.pose.position.z),
        Err(e) => s.refused(Err(e)),
    })?;
    let force = node.subscribe::<Float64>(local(FORCE_REFERENCE), qos::user_input())?;
    spawn_sub(spawner, force, &shared, |s, msg| {
        let result = s.tc.on_force_reference(msg.data).map(|_| ());
        s.refused(result);
    })?;
    let arrangement = node.subscribe::<Arrangement>(local(ARRANGEMENT), qos::latched())?;
    spawn_sub(spawner, arrangement, &shared, |s, msg| match s.tc.on_arrangement(&msg) {
        Ok(true) => r2r::log_info!(&s.logger, "{ARRANGEMENT}: following mode {} {:?}", msg.mode, msg.task_order),
        Ok(false) => {}
        Err(e) => s.refused(Err(e)),
    })?;

    if initial.trigger == Trigger::Timer {
        let mut timer = node.create_timer(Duration::from_secs_f64(1.0 / initial.control_rate_hz))?;
        let shared = shared.clone();
        spawner.spawn_local(async move {
            while timer.tick().await.is_ok() {
                let mut s = shared.borrow_mut();
                let now = s.now();
                let (timeout, lead) = {
                    let p = params.lock().unwrap();
                    (p.value().input_timeout_s, p.value().max_stamp_lead_s)
                };
                s.tc.set_freshness(timeout, lead);
                match s.tc.input_age(now) {
                    Some(age) if age <= timeout => {
                        if std::mem::replace(&mut s.stale, false) {
                            r2r::log_info!(&s.logger, "inputs fresh again: control resumes");
                        }
                        s.run_cycle(now, &time_msg(now));
                    }
                    age => {
                        if !std::mem::replace(&mut s.stale, true) {
                            let why = match age {
                                None => format!("waiting for {}", s.tc.missing().join(", ")),
                                Some(a) => format!("inputs {a:.3} s old (input_timeout_s = {timeout})"),
                            };
                            r2r::log_warn!(&s.logger, "commands ramp to zero: {why}");
                        }
                        let why = if age.is_none() { Idle::Waiting } else { Idle::Stale };
                        s.publish(|tc| tc.idle_outputs(why, &time_msg(now)));
                    }
                }
            }
        })?;
    }
    Ok(TaskControllerHandle { shared })
}
