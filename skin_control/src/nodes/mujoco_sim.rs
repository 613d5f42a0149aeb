//! `mujoco_sim`: a scene's MuJoCo world on the graph. Publishes `/clock`, `/joint_states`,
//! `/base/odom`, `/scan`, `/skin/cells` (every one stamped with the simulation time of the
//! period) and the scene's goals (`/goal`, latched) and force references
//! (`/hand_force_reference`, latched); applies the arm commands and the base twist.
//!
//! - **lockstep**: publishes the state of period k, waits for one new message on every command
//!   topic, applies them, steps one control period. The run is a function of the scene, like the
//!   in-process loop. The state is sent again every `resend_s` of wall time until the commands
//!   come (a sample lost before discovery completes; the controller ignores a stamp it has
//!   already answered).
//! - **real time**: steps one period every `period / realtime_factor` of wall time with the
//!   latest commands, publishing the state after each.
use std::cell::RefCell;
use std::path::PathBuf;
use std::rc::Rc;
use std::time::{Duration, Instant};

use anyhow::{Context as _, Result};
use futures::executor::LocalSpawner;
use futures::task::LocalSpawnExt;
use futures::StreamExt;
use r2r::geometry_msgs::msg::{PoseStamped, Twist};
use r2r::nav_msgs::msg::Odometry;
use r2r::rosgraph_msgs::msg::Clock;
use r2r::sensor_msgs::msg::{JointState, LaserScan};
use r2r::skin_msgs::msg::SkinCellArray;
use r2r::std_msgs::msg::{Float64, Float64MultiArray};

use super::topics::*;
use crate::qos;
use crate::sim_bridge::{AppliedCommand, SimBridge, SimMessages};
use crate::task_controller::ArmsParams;

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
    /// Command namespaces, one per arm (default: /left_arm /right_arm for TOMM, else /arm).
    #[arg(long = "arm-namespace", value_name = "NS")]
    pub arm_namespaces: Vec<String>,
    /// Joint-name prefix per arm, pairs with --arm-namespace (default: left_ right_, else "").
    #[arg(long = "arm-prefix", value_name = "PREFIX")]
    pub arm_prefixes: Vec<String>,
    /// Write the applied commands per period (JSON) here at the end.
    #[arg(long, value_name = "FILE")]
    pub record: Option<PathBuf>,
}

/// The scene file of a scenario name or a path.
pub fn scene_file(arg: &str) -> Result<PathBuf> {
    let target = skin_sim::runner::RunTarget::resolve(arg, Some(PathBuf::new())).map_err(|e| anyhow::anyhow!("--scene: {e}"))?;
    Ok(target.scene)
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
    errors: u64,
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
    record: Vec<AppliedCommand>,
    periods: u64,
    resends: u64,
    last_force: Option<f64>,
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
            self.pubs.goal.publish(g).context(GOAL)?;
        }
        if m.force_n != self.last_force {
            if let Some(f) = m.force_n {
                self.pubs.force.publish(&Float64 { data: f }).context(FORCE_REFERENCE)?;
            }
            self.last_force = m.force_n;
        }
        publish_inputs(&self.pubs, m)
    }

    fn republish(&mut self) -> Result<()> {
        // Same state, same stamps (the goal only if it is the period's; force unchanged).
        let m = self.bridge.messages();
        self.pubs.clock.publish(&m.clock).context(CLOCK)?;
        publish_inputs(&self.pubs, m)
    }

    /// Takes the commands in the inbox into the bridge; in lockstep only when every topic has a
    /// new one. Returns whether they were taken.
    fn take_commands(&mut self, all_needed: bool) -> bool {
        let mut inbox = self.inbox.borrow_mut();
        let complete = inbox.arms.iter().all(Option::is_some) && (!self.bridge.has_base() || inbox.twist.is_some());
        if all_needed && !complete {
            return false;
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
    }

    fn advance(&mut self) {
        self.record.push(self.bridge.applied());
        self.bridge.step_period();
        self.periods += 1;
    }

    /// One pass of the spin loop; returns true when the run is over.
    pub fn poll(&mut self) -> Result<bool> {
        let t = self.bridge.world().time();
        if self.options.lockstep {
            let Some(sent) = self.sent_at else {
                self.clear_inbox();
                self.publish_state()?;
                self.sent_at = Some(Instant::now());
                return Ok(false);
            };
            if self.take_commands(true) {
                self.advance();
                if self.bridge.world().time() >= self.end_s - 1e-9 {
                    return Ok(true);
                }
                self.clear_inbox();
                self.publish_state()?;
                self.sent_at = Some(Instant::now());
            } else if sent.elapsed() > Duration::from_secs_f64(self.options.resend) {
                self.resends += 1;
                if self.resends == 1 {
                    r2r::log_info!(&self.logger, "lockstep: no complete command set {:.1} s after the state of t = {t:.4} s: sending it again (and every {:.1} s)", self.options.resend, self.options.resend);
                }
                self.republish()?;
                self.sent_at = Some(Instant::now());
            }
            Ok(false)
        } else {
            let now = Instant::now();
            if now < self.next_tick {
                return Ok(false);
            }
            self.take_commands(false);
            self.advance();
            self.publish_state()?;
            let period = Duration::from_secs_f64(self.bridge.period_s() / self.options.realtime_factor);
            self.next_tick += period;
            if self.next_tick + period * 10 < now {
                self.next_tick = now; // too far behind: do not try to catch up in a burst
            }
            Ok(self.bridge.world().time() >= self.end_s - 1e-9)
        }
    }

    /// Writes the record (if asked) and logs the summary.
    pub fn stop(&self) -> Result<()> {
        let wall = self.started.elapsed().as_secs_f64();
        let sim = self.bridge.world().time();
        r2r::log_info!(
            &self.logger,
            "stopping at t = {sim:.3} s after {} periods ({} resends, {} bad commands); real-time factor {:.2}",
            self.periods,
            self.resends,
            self.inbox.borrow().errors,
            sim / wall.max(1e-9)
        );
        if let Some(path) = &self.options.record {
            let json = serde_json::json!({
                "scene": self.options.scene,
                "arms": self.bridge.arms().iter().map(|a| &a.joints).collect::<Vec<_>>(),
                "realtime_factor": sim / wall.max(1e-9),
                "commands": self.record,
            });
            std::fs::write(path, serde_json::to_string(&json)?).with_context(|| format!("--record {}", path.display()))?;
        }
        Ok(())
    }
}

/// Creates the world, the node's entities, and spawns the command subscriptions.
pub fn start(node: &mut r2r::Node, spawner: &LocalSpawner, mut options: Options) -> Result<SimHandle> {
    let logger = node.logger().to_string();
    let file = scene_file(&options.scene)?;
    let scene = skin_sim::scene::Scene::load(&file).with_context(|| format!("--scene {}", options.scene))?;
    if options.arm_namespaces.is_empty() && options.arm_prefixes.is_empty() {
        let d = ArmsParams::for_joints(scene.model.joint_names());
        options.arm_namespaces = d.namespaces;
        options.arm_prefixes = d.joint_prefixes;
    }
    if !(options.realtime_factor.is_finite() && options.realtime_factor > 0.0) {
        anyhow::bail!("--realtime-factor {}: must be > 0", options.realtime_factor);
    }
    let bridge = SimBridge::new(scene, &options.arm_namespaces, &options.arm_prefixes).map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
    let end_s = options.duration.unwrap_or(bridge.duration_s());
    let pubs = Pubs {
        clock: node.create_publisher(CLOCK, qos::stream())?,
        joints: node.create_publisher(JOINT_STATES, qos::stream())?,
        odom: node.create_publisher(ODOM, qos::stream())?,
        scan: node.create_publisher(SCAN, qos::stream())?,
        cells: node.create_publisher(CELLS, qos::stream())?,
        goal: node.create_publisher(GOAL, qos::latched())?,
        force: node.create_publisher(FORCE_REFERENCE, qos::latched())?,
    };
    let inbox = Rc::new(RefCell::new(Inbox { arms: vec![None; bridge.arms().len()], twist: None, errors: 0 }));
    for (k, arm) in bridge.arms().iter().enumerate() {
        let mut sub = node.subscribe::<Float64MultiArray>(&arm.topic, qos::stream())?;
        let inbox = inbox.clone();
        spawner.spawn_local(async move {
            while let Some(m) = sub.next().await {
                inbox.borrow_mut().arms[k] = Some(m);
            }
        })?;
    }
    if bridge.has_base() {
        let mut sub = node.subscribe::<Twist>(CMD_VEL, qos::stream())?;
        let inbox = inbox.clone();
        spawner.spawn_local(async move {
            while let Some(m) = sub.next().await {
                inbox.borrow_mut().twist = Some(m);
            }
        })?;
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
        record: Vec::new(),
        periods: 0,
        resends: 0,
        last_force: None,
        options,
    })
}
