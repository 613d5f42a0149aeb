//! `mujoco_sim`: a scene's MuJoCo world on the graph, speaking the robot drivers' topics.
//! Publishes `/clock`, `/joint_states`, `/base/odom`, `/scan`, `/skin/cells` (every one stamped
//! with the simulation time of the period), TF as the drivers do (`world -> odom` on
//! `/tf_static`; `odom -> base_link` on `/tf` when the robot has a base) and the scene's goals
//! (`/goal`) and force references (`/hand_force_reference`), latched, each sent once a
//! subscriber is matched (the controller subscribes volatile, as to any user's goal, and gets no
//! history); applies the arm commands and the base twist. Topic names are relative (`skin_control::nodes::local`). The
//! scene's `base_motions` are not on the graph yet (a warning says so at start).
//!
//! - **lockstep**: publishes the state of period k, waits for one new message on every command
//!   topic, applies them, steps one control period. The run is a function of the scene, like the
//!   in-process loop. The state is sent again every `resend_s` of wall time until the commands
//!   come (a sample lost before discovery completes; the controller ignores a stamp it has
//!   already answered).
//! - **real time**: steps one period every `period / realtime_factor` of wall time with the
//!   latest commands, publishing the state after each.
//!
//! With `--out DIR` (lockstep) a period also waits for the controller's `/controller/state`
//! answering it, and the run is recorded as `skin_sim run` records it
//! ([`skin_sim::run::runner::ExternalRun`]: the world, the commands, the published state): the same
//! report, outcome checks and files (`skin_sim::outputs::artifacts::ALL`) are written at the end.
use std::cell::RefCell;
use std::path::PathBuf;
use std::rc::Rc;
use std::time::{Duration, Instant};

use anyhow::{Context as _, Result};
use futures::executor::LocalSpawner;
use futures::task::LocalSpawnExt;
use futures::StreamExt;
use r2r::geometry_msgs::msg::{PoseStamped, Twist, TwistStamped};
use r2r::nav_msgs::msg::Odometry;
use r2r::rosgraph_msgs::msg::Clock;
use r2r::sensor_msgs::msg::{JointState, LaserScan};
use r2r::skin_msgs::msg::{Arrangement, ControllerState, SkinCellArray};
use r2r::std_msgs::msg::{Float64, Float64MultiArray};
use skin_sim::run::runner::{ExternalRun, RunTarget};

use skin_control::convert::robot::time_msg;
use skin_control::nodes::{local, Pass};
use skin_control::qos;
use skin_control::task_controller::ArmsParams;
use skin_control::tf::{FrameTransform, TfPublisher, BASE_FRAME, ODOM_FRAME, WORLD_FRAME};
use skin_control::topics::*;

use crate::sim_bridge::{decision, AppliedCommand, SimBridge, SimMessages};

/// Node name.
pub const NODE: &str = "mujoco_sim";

/// Start-up options.
#[derive(Debug, Clone, clap::Args)]
pub struct Options {
    /// Scene: a scenario name (`skin_sim list`) or a scene file.
    #[arg(long, default_value = "intentional_contact")]
    pub scene: String,
    /// Step one control period per received command set (reproducible); default: real time.
    #[arg(long)]
    pub lockstep: bool,
    /// Real-time mode: simulated seconds per wall-clock second.
    #[arg(long, default_value_t = 1.0, value_name = "FACTOR")]
    pub realtime_factor: f64,
    /// Stop after this much simulated time [s] (default: the scene's duration).
    #[arg(long, value_name = "SECONDS")]
    pub duration: Option<f64>,
    /// Lockstep: resend the state after this much wall time without commands [s].
    #[arg(long, default_value_t = 1.0, value_name = "SECONDS")]
    pub resend: f64,
    /// Lockstep: before the first state, wait (at most 30 s) until TOPIC has N subscribers, e.g.
    /// `/skin/cells=3` when the controller, the aggregator and a recorder must all get it.
    /// Without it, a first state sent before discovery completes is lost and sent again after
    /// `--resend` (waiting only for the inputs' readers is not enough: the controller's command
    /// and state writers must be matched too).
    #[arg(long, num_args = 1.., value_name = "TOPIC=N", value_parser = skin_control::nodes::topic_count)]
    pub wait_topic_subscribers: Vec<(String, usize)>,
    /// Command namespaces, one per arm (default: left_arm right_arm for TOMM, else arm; relative: under the node's namespace).
    #[arg(long = "arm-namespace", value_name = "NS")]
    pub arm_namespaces: Vec<String>,
    /// Joint-name prefix per arm, pairs with --arm-namespace (default: left_ right_, else "").
    #[arg(long = "arm-prefix", value_name = "PREFIX")]
    pub arm_prefixes: Vec<String>,
    /// The base command as geometry_msgs/TwistStamped (task_controller's base_command_stamped,
    /// ros2_control's base controllers); default: geometry_msgs/Twist.
    #[arg(long)]
    pub base_command_stamped: bool,
    /// Write the applied commands per period (JSON) here at the end.
    #[arg(long, value_name = "FILE")]
    pub record: Option<PathBuf>,
    /// Lockstep: record the run as `skin_sim run` does and write its metrics.json, summary.txt,
    /// figure.png and run.mcap here at the end (exit code 1 when an outcome check fails).
    #[arg(long, value_name = "DIR", requires = "lockstep")]
    pub out: Option<PathBuf>,
    /// With --out: the controller setup the run is judged with (its thresholds, hand, end
    /// effector) [default: the scenario's].
    #[arg(long, value_name = "FILE")]
    pub controller: Option<PathBuf>,
}

/// The scene file of a scenario name or a path.
pub fn scene_file(arg: &str) -> Result<PathBuf> {
    let target = RunTarget::resolve(arg, Some(PathBuf::new())).map_err(|e| anyhow::anyhow!("--scene: {e}"))?;
    Ok(target.scene)
}

/// The controller setup of a scenario (None: a scene file that is not a scenario's).
pub fn scenario_setup(arg: &str) -> Option<PathBuf> {
    RunTarget::resolve(arg, None).ok().map(|t| t.controller)
}

/// What a launch file needs to start the rest of the graph for `scene` (a scenario name or a
/// scene file): the controller setup (the scenario's, or `setup`), the URDF and skin layout it
/// names, whether the scene has a LIDAR (the controller's `use_scan`) and the robot a base, and
/// the arms' command namespaces and joint prefixes. Paths are absolute.
pub fn describe(scene: &str, setup: Option<PathBuf>) -> Result<serde_json::Value> {
    let target = RunTarget::resolve(scene, setup).map_err(|e| anyhow::anyhow!("--scene: {e}"))?;
    let loaded = skin_sim::scene::Scene::load(&target.scene).with_context(|| format!("--scene {scene}"))?;
    let (setup, _) = skin_core::controller::ControllerSetup::load(&target.controller)
        .with_context(|| target.controller.display().to_string())?;
    let dir = target.controller.parent().unwrap_or(std::path::Path::new("."));
    let scene_dir = target.scene.parent().unwrap_or(std::path::Path::new("."));
    let absolute = |p: &std::path::Path| {
        std::fs::canonicalize(p).or_else(|_| std::path::absolute(p)).unwrap_or_else(|_| p.to_path_buf())
    };
    let arms = ArmsParams::for_joints(loaded.model.joint_names());
    Ok(serde_json::json!({
        "scene": absolute(&target.scene),
        "setup": absolute(&target.controller),
        // a setup without a URDF (its node takes robot_description): the scene's robot
        "urdf": absolute(&setup.urdf.map_or_else(|| scene_dir.join(&loaded.spec.robot.urdf), |u| dir.join(u))),
        "layout": absolute(&dir.join(&setup.skin_layout)),
        "lidar": loaded.spec.lidar.is_some(),
        "base": loaded.model.planar_base().is_some(),
        "arms": {"namespaces": arms.namespaces, "joint_prefixes": arms.joint_prefixes},
    }))
}

struct Pubs {
    clock: r2r::Publisher<Clock>,
    joints: r2r::Publisher<JointState>,
    odom: r2r::Publisher<Odometry>,
    scan: r2r::Publisher<LaserScan>,
    cells: r2r::Publisher<SkinCellArray>,
    goal: r2r::Publisher<PoseStamped>,
    force: r2r::Publisher<Float64>,
}

struct Inbox {
    arms: Vec<Option<Float64MultiArray>>,
    twist: Option<Twist>,
    /// `--out`: the controller's state of the period and the arrangement's fusion weight.
    state: Option<ControllerState>,
    fusion_weight: f64,
    errors: u64,
}

/// `--out`: the run's record and where it goes.
struct Recorder {
    run: ExternalRun,
    dir: PathBuf,
    /// The controller state answering the current period, once taken from the inbox.
    state: Option<ControllerState>,
    safe_stops: u64,
}

/// The running node; [`SimHandle::poll`] drives it from the spin loop.
pub struct SimHandle {
    bridge: SimBridge,
    pubs: Pubs,
    inbox: Rc<RefCell<Inbox>>,
    options: Options,
    end_s: f64,
    logger: String,
    sent_at: Option<Instant>,
    next_tick: Instant,
    started: Instant,
    /// When the run's wall time starts: in lockstep the sending of the first state that was
    /// answered, in real time the first step (start-up and discovery, with the resends of a first
    /// state lost before it, excluded, as skin_sim's in-process runs exclude their set-up).
    running: Option<Instant>,
    record: Vec<AppliedCommand>,
    periods: u64,
    resends: u64,
    last_force: Option<f64>,
    recorder: Option<Recorder>,
    progress_s: f64,
    /// `/tf` and `/tf_static` (None: built without tf2_msgs).
    tf: Option<TfPublisher>,
    /// The scene's goal and force reference due but not sent yet: no subscriber was matched.
    pending_goal: Option<PoseStamped>,
    pending_force: Option<f64>,
}

/// The controller's sensor inputs of one period, joint states last: the controller's input set is
/// complete with them.
fn publish_inputs(pubs: &Pubs, m: &SimMessages) -> Result<()> {
    if let Some(o) = &m.odom {
        pubs.odom.publish(o).context(ODOM)?;
    }
    if let Some(s) = &m.scan {
        pubs.scan.publish(s).context(SCAN)?;
    }
    if let Some(c) = &m.cells {
        pubs.cells.publish(c).context(CELLS)?;
    }
    pubs.joints.publish(&m.joints).context(JOINT_STATES)?;
    Ok(())
}

impl SimHandle {
    fn publish_state(&mut self) -> Result<()> {
        let m = self.bridge.messages();
        self.pubs.clock.publish(&m.clock).context(CLOCK)?;
        if let Some(g) = &m.goal {
            self.pending_goal = Some(g.clone());
        }
        if m.force_n != self.last_force {
            self.pending_force = m.force_n;
            self.last_force = m.force_n;
        }
        self.send_references()?;
        publish_inputs(&self.pubs, self.bridge.last_messages())?;
        self.publish_base_tf()
    }

    /// `odom -> base_link` on `/tf` with the period's stamp, as a base driver sends it.
    fn publish_base_tf(&self) -> Result<()> {
        if let (Some(tf), Some(pose)) = (&self.tf, self.bridge.base_pose()) {
            let t = FrameTransform { parent: ODOM_FRAME.into(), child: BASE_FRAME.into(), pose };
            tf.send(&[t], &time_msg(self.bridge.world().time())).context(TF)?;
        }
        Ok(())
    }

    /// Sends the pending goal and force reference whose topic has a subscriber now.
    fn send_references(&mut self) -> Result<()> {
        fn matched<T: r2r::WrappedTypesupport + 'static>(p: &r2r::Publisher<T>, topic: &'static str) -> Result<bool> {
            p.get_inter_process_subscription_count().context(topic).map(|n| n > 0)
        }
        if self.pending_goal.is_some() && matched(&self.pubs.goal, GOAL)? {
            let g = self.pending_goal.take().expect("checked");
            self.pubs.goal.publish(&g).context(GOAL)?;
        }
        if self.pending_force.is_some() && matched(&self.pubs.force, FORCE_REFERENCE)? {
            let f = self.pending_force.take().expect("checked");
            self.pubs.force.publish(&Float64 { data: f }).context(FORCE_REFERENCE)?;
        }
        Ok(())
    }

    /// Whether a topic of `--wait-topic-subscribers` still lacks subscribers (false after 30 s,
    /// with a warning naming them).
    fn lacking_subscribers(&self) -> Result<bool> {
        let p = &self.pubs;
        let count = |topic: &str| match topic {
            JOINT_STATES => Some(p.joints.get_inter_process_subscription_count()),
            CELLS => Some(p.cells.get_inter_process_subscription_count()),
            ODOM => Some(p.odom.get_inter_process_subscription_count()),
            SCAN => Some(p.scan.get_inter_process_subscription_count()),
            CLOCK => Some(p.clock.get_inter_process_subscription_count()),
            _ => None,
        };
        let lacking =
            skin_control::nodes::lacking_subscribers(&self.options.wait_topic_subscribers, count).map_err(|e| {
                anyhow::anyhow!(
                    "--wait-topic-subscribers: {e} (inputs: {JOINT_STATES}, {CELLS}, {ODOM}, {SCAN}, {CLOCK})"
                )
            })?;
        if !lacking.is_empty() && self.started.elapsed() > Duration::from_secs(30) {
            r2r::log_warn!(&self.logger, "after 30 s too few subscribers on {}: starting anyway", lacking.join(", "));
            return Ok(false);
        }
        Ok(!lacking.is_empty())
    }

    fn republish(&mut self) -> Result<()> {
        // The same messages again (the goal only if it is the period's; force unchanged).
        let m = self.bridge.last_messages();
        self.pubs.clock.publish(&m.clock).context(CLOCK)?;
        publish_inputs(&self.pubs, m)?;
        self.publish_base_tf()
    }

    /// Takes the commands in the inbox into the bridge; in lockstep only when every topic has a
    /// new one (and, recording, the controller state of this period has come). Returns whether
    /// they were taken.
    fn take_commands(&mut self, all_needed: bool) -> bool {
        let mut inbox = self.inbox.borrow_mut();
        let stamp = time_msg(self.bridge.world().time());
        if inbox.state.as_ref().is_some_and(|s| s.header.stamp != stamp) {
            inbox.state = None; // an answer to an earlier period (a resend)
        }
        let complete = inbox.arms.iter().all(Option::is_some)
            && (!self.bridge.has_base() || inbox.twist.is_some())
            && (self.recorder.is_none() || inbox.state.is_some());
        if all_needed && !complete {
            return false;
        }
        if let Some(r) = &mut self.recorder {
            r.state = inbox.state.take();
        }
        for k in 0..inbox.arms.len() {
            if let Some(m) = inbox.arms[k].take() {
                if let Err(e) = self.bridge.on_arm_command(k, &m) {
                    inbox.errors += 1;
                    if inbox.errors == 1 {
                        r2r::log_warn!(&self.logger, "{e} (command ignored; further ones counted)");
                    }
                }
            }
        }
        if let Some(t) = inbox.twist.take() {
            if let Err(e) = self.bridge.on_twist(&t) {
                inbox.errors += 1;
                if inbox.errors == 1 {
                    r2r::log_warn!(&self.logger, "{e} (command ignored; further ones counted)");
                }
            }
        }
        true
    }

    fn clear_inbox(&self) {
        let mut inbox = self.inbox.borrow_mut();
        inbox.arms.iter_mut().for_each(|a| *a = None);
        inbox.twist = None;
        inbox.state = None;
    }

    /// Records the period (with `--out`), applies the commands and steps.
    fn advance(&mut self) -> Result<()> {
        let applied = self.bridge.applied();
        if let Some(r) = &mut self.recorder {
            let state = r.state.take().context("lockstep: no controller state for the period")?;
            let round_trip_us = self.sent_at.map_or(0.0, |s| s.elapsed().as_secs_f64() * 1e6);
            let fusion_weight = self.inbox.borrow().fusion_weight;
            let d =
                decision(&state, &applied, r.safe_stops, fusion_weight, round_trip_us).map_err(anyhow::Error::msg)?;
            r.safe_stops = state.safe_stop_cycles;
            r.run.cycle(self.bridge.world(), self.last_force, d);
        }
        self.record.push(applied);
        self.bridge.step_period();
        self.periods += 1;
        self.log_progress();
        Ok(())
    }

    /// Wall time since the run started [s] (0 before it).
    fn run_wall_s(&self) -> f64 {
        self.running.map_or(0.0, |r| r.elapsed().as_secs_f64())
    }

    /// A progress line at every tenth of the run.
    fn log_progress(&mut self) {
        let t = self.bridge.world().time();
        if t + 1e-9 < self.progress_s {
            return;
        }
        self.progress_s += self.end_s / 10.0;
        let rtf = t / self.run_wall_s().max(1e-9);
        r2r::log_info!(&self.logger, "t = {t:.1} / {:.1} s (real-time factor {rtf:.2})", self.end_s);
    }

    /// One pass of the spin loop: [`Pass::Busy`] when it published, [`Pass::Done`] when the run
    /// is over.
    pub fn poll(&mut self) -> Result<Pass> {
        if self.pending_goal.is_some() || self.pending_force.is_some() {
            self.send_references()?;
        }
        let t = self.bridge.world().time();
        if self.options.lockstep {
            let Some(sent) = self.sent_at else {
                if self.lacking_subscribers()? {
                    return Ok(Pass::Idle);
                }
                self.clear_inbox();
                self.publish_state()?;
                self.sent_at = Some(Instant::now());
                return Ok(Pass::Busy);
            };
            if self.take_commands(true) {
                self.running.get_or_insert(sent);
                self.advance()?;
                if self.bridge.world().time() >= self.end_s - 1e-9 {
                    return Ok(Pass::Done);
                }
                self.clear_inbox();
                self.publish_state()?;
                self.sent_at = Some(Instant::now());
                Ok(Pass::Busy)
            } else if sent.elapsed() > Duration::from_secs_f64(self.options.resend) {
                self.resends += 1;
                if self.resends == 1 {
                    r2r::log_info!(&self.logger, "lockstep: no complete command set {:.1} s after the state of t = {t:.4} s: sending it again (and every {:.1} s)", self.options.resend, self.options.resend);
                }
                self.republish()?;
                self.sent_at = Some(Instant::now());
                Ok(Pass::Busy)
            } else {
                Ok(Pass::Idle)
            }
        } else {
            let now = Instant::now();
            if now < self.next_tick {
                return Ok(Pass::Idle);
            }
            self.running.get_or_insert(now);
            self.take_commands(false);
            self.advance()?;
            self.publish_state()?;
            let period = Duration::from_secs_f64(self.bridge.period_s() / self.options.realtime_factor);
            self.next_tick += period;
            if self.next_tick + period * 10 < now {
                self.next_tick = now; // too far behind: do not try to catch up in a burst
            }
            Ok(if self.bridge.world().time() >= self.end_s - 1e-9 { Pass::Done } else { Pass::Busy })
        }
    }

    /// Writes the record (if asked) and logs the summary; with `--out` writes the run's files,
    /// prints its summary and returns whether every outcome check passed.
    pub fn stop(self) -> Result<Option<bool>> {
        let wall = self.run_wall_s();
        let sim = self.bridge.world().time();
        let start_up = self.running.unwrap_or_else(Instant::now) - self.started;
        r2r::log_info!(
            &self.logger,
            "stopping at t = {sim:.3} s after {} periods ({} resends, {} bad commands); real-time factor {:.2} ({wall:.3} s from the first answered state, {:.3} s of start-up before it)",
            self.periods,
            self.resends,
            self.inbox.borrow().errors,
            sim / wall.max(1e-9),
            start_up.as_secs_f64()
        );
        if let Some(path) = &self.options.record {
            let json = serde_json::json!({
                "scene": self.options.scene,
                "arms": self.bridge.arms().iter().map(|a| &a.joints).collect::<Vec<_>>(),
                "realtime_factor": sim / wall.max(1e-9),
                "commands": self.record,
            });
            std::fs::write(path, serde_json::to_string(&json)?)
                .with_context(|| format!("--record {}", path.display()))?;
        }
        let world = self.bridge.world();
        self.recorder.map(|r| write_report(r, world)).transpose()
    }
}

/// The report of a recorded run into its directory (`world`: its final state), its summary on
/// stdout.
fn write_report(r: Recorder, world: &skin_sim::World) -> Result<bool> {
    anyhow::ensure!(r.run.cycles() > 0, "--out {}: no control period was completed", r.dir.display());
    let report = r.run.finish(world);
    let files = skin_sim::outputs::report::write_all(&report, &r.dir, &skin_sim::outputs::artifacts::ALL)?;
    print!("{}", report.summary());
    let names: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
    println!("  wrote {}", names.join(", "));
    Ok(report.passed())
}

/// Creates the world, the node's entities, and spawns the command subscriptions.
pub fn start(node: &mut r2r::Node, spawner: &LocalSpawner, mut options: Options) -> Result<SimHandle> {
    let logger = node.logger().to_string();
    let file = scene_file(&options.scene)?;
    let scene = skin_sim::scene::Scene::load(&file).with_context(|| format!("--scene {}", options.scene))?;
    if !scene.spec.base_motions.is_empty() {
        // Not yet a topic: the controller's base reference comes from skin_sim's schedule only.
        r2r::log_warn!(
            &logger,
            "{}: its {} base motion(s) (`base_motions`, interactive-force-control paper Exp. 1) are not carried by the graph: the controller holds the base at q_post, and a recorded run's \"with\" RMS covers these windows without the motion (run them with `skin_sim run`)",
            file.display(),
            scene.spec.base_motions.len()
        );
    }
    if options.arm_namespaces.is_empty() && options.arm_prefixes.is_empty() {
        let d = ArmsParams::for_joints(scene.model.joint_names());
        options.arm_namespaces = d.namespaces;
        options.arm_prefixes = d.joint_prefixes;
    }
    if !(options.realtime_factor.is_finite() && options.realtime_factor > 0.0) {
        anyhow::bail!("--realtime-factor {}: must be > 0", options.realtime_factor);
    }
    let bridge = SimBridge::new(scene.clone(), &options.arm_namespaces, &options.arm_prefixes)
        .map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
    let recorder = options.out.as_ref().map(|dir| start_recorder(&options, scene, &bridge, dir)).transpose()?;
    let end_s = options.duration.unwrap_or(bridge.duration_s());
    let pubs = Pubs {
        clock: node.create_publisher(CLOCK, qos::stream())?,
        joints: node.create_publisher(local(JOINT_STATES), qos::stream())?,
        odom: node.create_publisher(local(ODOM), qos::stream())?,
        scan: node.create_publisher(local(SCAN), qos::stream())?,
        cells: node.create_publisher(local(CELLS), qos::stream())?,
        goal: node.create_publisher(local(GOAL), qos::latched())?,
        force: node.create_publisher(local(FORCE_REFERENCE), qos::latched())?,
    };
    let tf = match TfPublisher::new(node)? {
        Ok(tf) => {
            // The controller's world is the odometry frame (its base joints are the odometry).
            let fixed = FrameTransform {
                parent: WORLD_FRAME.into(),
                child: ODOM_FRAME.into(),
                pose: nalgebra::Isometry3::identity(),
            };
            tf.send_static(&[fixed], &time_msg(0.0)).context(TF_STATIC)?;
            Some(tf)
        }
        Err(why) => {
            r2r::log_warn!(&logger, "{why}");
            None
        }
    };
    let inbox = Rc::new(RefCell::new(Inbox {
        arms: vec![None; bridge.arms().len()],
        twist: None,
        state: None,
        fusion_weight: f64::NAN,
        errors: 0,
    }));
    for (k, arm) in bridge.arms().iter().enumerate() {
        let mut sub = node.subscribe::<Float64MultiArray>(local(&arm.topic), qos::stream())?;
        let inbox = inbox.clone();
        spawner.spawn_local(async move {
            while let Some(m) = sub.next().await {
                inbox.borrow_mut().arms[k] = Some(m);
            }
        })?;
    }
    if bridge.has_base() && options.base_command_stamped {
        let mut sub = node.subscribe::<TwistStamped>(local(CMD_VEL), qos::stream())?;
        let inbox = inbox.clone();
        spawner.spawn_local(async move {
            while let Some(m) = sub.next().await {
                inbox.borrow_mut().twist = Some(m.twist);
            }
        })?;
    } else if bridge.has_base() {
        let mut sub = node.subscribe::<Twist>(local(CMD_VEL), qos::stream())?;
        let inbox = inbox.clone();
        spawner.spawn_local(async move {
            while let Some(m) = sub.next().await {
                inbox.borrow_mut().twist = Some(m);
            }
        })?;
    }
    if recorder.is_some() {
        subscribe_controller(node, spawner, &inbox)?;
    }
    let topics: Vec<&str> = bridge.arms().iter().map(|a| a.topic.as_str()).collect();
    r2r::log_info!(
        &logger,
        "{}: {} mode, until t = {end_s} s, period {} s; commands from {}{}",
        file.display(),
        if options.lockstep { "lockstep" } else { "real-time" },
        bridge.period_s(),
        topics.join(", "),
        if bridge.has_base() { format!(", {CMD_VEL}") } else { String::new() }
    );
    Ok(SimHandle {
        bridge,
        pubs,
        inbox,
        end_s,
        logger,
        sent_at: None,
        next_tick: Instant::now(),
        started: Instant::now(),
        running: None,
        record: Vec::new(),
        periods: 0,
        resends: 0,
        last_force: None,
        recorder,
        progress_s: end_s / 10.0,
        options,
        tf,
        pending_goal: None,
        pending_force: None,
    })
}

/// `--out`: the run's record, judged with the scenario's (or `--controller`) setup.
fn start_recorder(
    options: &Options,
    scene: skin_sim::scene::Scene,
    bridge: &SimBridge,
    dir: &std::path::Path,
) -> Result<Recorder> {
    let target =
        RunTarget::resolve(&options.scene, options.controller.clone()).map_err(|e| anyhow::anyhow!("--scene: {e}"))?;
    let run = ExternalRun::new(&target, scene, bridge.world())
        .with_context(|| format!("--out: {}", target.controller.display()))?;
    Ok(Recorder { run, dir: dir.to_path_buf(), state: None, safe_stops: 0 })
}

/// `--out`: `/controller/state` (the period's answer) and `/supervisor/arrangement` (its
/// fusion weight) into the inbox.
fn subscribe_controller(node: &mut r2r::Node, spawner: &LocalSpawner, inbox: &Rc<RefCell<Inbox>>) -> Result<()> {
    let mut states = node.subscribe::<ControllerState>(local(CONTROLLER_STATE), qos::stream())?;
    let states_inbox = inbox.clone();
    spawner.spawn_local(async move {
        while let Some(m) = states.next().await {
            states_inbox.borrow_mut().state = Some(m);
        }
    })?;
    let mut arrangements = node.subscribe::<Arrangement>(local(ARRANGEMENT), qos::latched())?;
    let inbox = inbox.clone();
    spawner.spawn_local(async move {
        while let Some(m) = arrangements.next().await {
            inbox.borrow_mut().fusion_weight = m.fusion_weight;
        }
    })?;
    Ok(())
}
