//! The simulation side of the graph without the node: a `skin_sim::world::World` read into the
//! robot's messages (`/clock`, `/joint_states`, `/base/odom`, `/scan`, `/skin/cells`, and the
//! scene's goals and force references as a user would send them), commands written back into it,
//! one control period stepped at a time. `nodes::mujoco_sim` wires it to topics; the
//! graph-equivalent in-process loop ([`run_in_process`]) uses it without DDS.
use std::path::Path;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use r2r::builtin_interfaces::msg::Time;
use r2r::geometry_msgs::msg::{PoseStamped, Twist};
use r2r::nav_msgs::msg::Odometry;
use r2r::rosgraph_msgs::msg::Clock;
use r2r::sensor_msgs::msg::{JointState, LaserScan};
use r2r::skin_msgs::msg::{ControllerState, SkinCellArray};
use r2r::std_msgs::msg::Float64MultiArray;
use serde::Serialize;
use skin_core::skin::layout::ResolvedLayout;
use skin_core::skin::signals::CellReading;
use skin_core::supervisor::Mode;
use skin_sim::run::runner::Decision;
use skin_sim::scene::Scene;
use skin_sim::world::World;

use skin_control::convert::control::{
    blocked_of, read_arm_command, split_arms, supervisor_input, twist_of, ArmCommand,
};
use skin_control::convert::robot::{time_msg, write_goal, write_joint_state, write_odometry, BaseState};
use skin_control::convert::write_cell_array;
use skin_control::tf::{BASE_FRAME, ODOM_FRAME, WORLD_FRAME};

/// The messages of one control period, stamped with the simulation time.
#[derive(Debug, Clone, Default)]
pub struct SimMessages {
    /// `/clock`.
    pub clock: Clock,
    /// `/joint_states`: every joint but the base's.
    pub joints: JointState,
    /// `/base/odom` (None: no base).
    pub odom: Option<Odometry>,
    /// `/scan` (None: no LIDAR).
    pub scan: Option<LaserScan>,
    /// `/skin/cells`: the cells that read something or changed since the last message (the first
    /// has every cell; None: no skin).
    pub cells: Option<SkinCellArray>,
    /// `/goal`, when a scene goal starts in this period.
    pub goal: Option<PoseStamped>,
    /// `/hand_force_reference` \[N\], while a scene force reference is active.
    pub force_n: Option<f64>,
}

/// One period's commands as the simulation applied them (for records and comparisons).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AppliedCommand {
    /// Simulation time of the state the commands answer \[s\].
    pub t_s: f64,
    /// Arm joint velocities, the world's arm joint order.
    pub joints: Vec<f64>,
    /// Base twist (vx, vy, wz), base frame.
    pub base: [f64; 3],
}

/// The controller's decision of one period as the graph carries it, for a skin_sim record: its
/// `/controller/state` answering the period, the commands the simulation applied,
/// `safe_stops_before` (the state's `safe_stop_cycles` of the period before: a rise marks a
/// safe-stop step), the arrangement's fusion weight and the round trip \[µs\].
pub fn decision(
    state: &ControllerState,
    applied: &AppliedCommand,
    safe_stops_before: u64,
    fusion_weight: f64,
    round_trip_us: f64,
) -> Result<Decision, String> {
    let mode = Mode::from_u8(state.mode)
        .ok_or_else(|| format!("/controller/state: mode = {}: not an Arrangement.MODE_* constant", state.mode))?;
    Ok(Decision {
        joint_velocities: applied.joints.clone(),
        base_twist: applied.base,
        mode,
        blocked: blocked_of(&state.blocked),
        releasing: state.releasing,
        blend: state.blend,
        fusion_weight,
        signals: supervisor_input(state).1,
        torque_norm: state.torque_norm,
        fault: (state.safe_stop_cycles > safe_stops_before).then(|| "safe-stop step (/controller/state)".to_string()),
        compute_us: round_trip_us,
    })
}

/// A world and its message interface.
pub struct SimBridge {
    world: World,
    steps_per_period: u64,
    period_s: f64,
    names: Vec<String>,
    indices: Vec<usize>,
    base: Option<[usize; 3]>,
    arms: Vec<ArmCommand>,
    arm_cmd: Vec<f64>,
    twist: [f64; 3],
    scan_geometry: Option<(String, f32, f32, f32)>,
    goals: Vec<(f64, Isometry3<f64>)>,
    next_goal: usize,
    msgs: SimMessages,
    /// The readings as last published (empty before the first message).
    sent_cells: Vec<CellReading>,
}

impl SimBridge {
    /// The bridge of `scene`, commands split into arms like the controller's (`namespaces[k]`
    /// takes the arm joints starting with `prefixes[k]`).
    pub fn new(scene: Scene, namespaces: &[String], prefixes: &[String]) -> Result<Self, String> {
        let spec = scene.spec.clone();
        let world = World::from_scene(scene).map_err(|e| e.to_string())?;
        let model = &world.scene().model;
        let indices = world.arm_joints().to_vec();
        let names = indices.iter().map(|&j| model.joint_names()[j].clone()).collect();
        let arms = split_arms(model.joint_names(), world.arm_joints(), namespaces, prefixes)?;
        let scan_geometry = spec.lidar.as_ref().map(|l| {
            let (first, step) = l.fan();
            (l.frame.clone(), first as f32, step as f32, l.range_m as f32)
        });
        let mut goals: Vec<_> = spec
            .goals
            .iter()
            .map(|g| {
                let r =
                    g.rpy.map_or(UnitQuaternion::identity(), |[r, p, y]| UnitQuaternion::from_euler_angles(r, p, y));
                (g.start_s, Isometry3::from_parts(Translation3::from(Vector3::from(g.position_m)), r))
            })
            .collect();
        goals.sort_by(|a, b| a.0.total_cmp(&b.0));
        Ok(SimBridge {
            steps_per_period: (1.0 / (spec.control_rate_hz * spec.timestep_s)).round() as u64,
            period_s: 1.0 / spec.control_rate_hz,
            arm_cmd: vec![0.0; world.arm_joints().len()],
            twist: [0.0; 3],
            names,
            indices,
            base: model.planar_base(),
            arms,
            scan_geometry,
            goals,
            next_goal: 0,
            msgs: SimMessages::default(),
            sent_cells: Vec::new(),
            world,
        })
    }

    /// Loads the scene file (see [`Self::new`]).
    pub fn from_scene_file(path: &Path, namespaces: &[String], prefixes: &[String]) -> Result<Self, String> {
        let scene = Scene::load(path).map_err(|e| e.to_string())?;
        Self::new(scene, namespaces, prefixes)
    }

    /// The world.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The control period \[s\].
    pub fn period_s(&self) -> f64 {
        self.period_s
    }

    /// The arms and their command topics.
    pub fn arms(&self) -> &[ArmCommand] {
        &self.arms
    }

    /// Whether the robot has a base (a `/base/cmd_vel` input).
    pub fn has_base(&self) -> bool {
        self.base.is_some()
    }

    /// The pose of [`BASE_FRAME`] in [`ODOM_FRAME`] (None: no base): the transform a base driver
    /// publishes on `/tf`.
    pub fn base_pose(&self) -> Option<Isometry3<f64>> {
        let q = self.world.q();
        self.base.map(|[x, y, yaw]| {
            Isometry3::from_parts(
                Translation3::new(q[x], q[y], 0.0),
                UnitQuaternion::from_euler_angles(0.0, 0.0, q[yaw]),
            )
        })
    }

    /// The end time of the scene \[s\].
    pub fn duration_s(&self) -> f64 {
        self.world.scene().spec.duration_s
    }

    /// The messages [`SimBridge::messages`] made last, unchanged: a resend must repeat them
    /// exactly (making them again would strip the event-driven cells already sent).
    pub fn last_messages(&self) -> &SimMessages {
        &self.msgs
    }

    /// The messages of the current state (the scene's goal only in the period it starts).
    pub fn messages(&mut self) -> &SimMessages {
        let w = &self.world;
        let t = w.time();
        let stamp: Time = time_msg(t);
        let m = &mut self.msgs;
        m.clock.clock = stamp.clone();
        write_joint_state(&self.names, &self.indices, w.q(), w.qd(), &stamp, &mut m.joints);
        m.odom = self.base.map(|[x, y, yaw]| {
            let mut o = m.odom.take().unwrap_or_default();
            let b = BaseState { q: [w.q()[x], w.q()[y], w.q()[yaw]], qd: [w.qd()[x], w.qd()[y], w.qd()[yaw]] };
            write_odometry(&b, &stamp, ODOM_FRAME, BASE_FRAME, &mut o);
            o
        });
        m.scan = match (&self.scan_geometry, w.lidar()) {
            (Some((frame, a0, da, rmax)), Some(lidar)) => {
                let mut s = m.scan.take().unwrap_or_default();
                s.header.stamp = stamp.clone();
                s.header.frame_id.clone_from(frame);
                s.angle_min = *a0;
                s.angle_increment = *da;
                s.angle_max = *a0 + *da * (lidar.ranges().len().saturating_sub(1)) as f32;
                s.range_min = 0.0;
                s.range_max = *rmax;
                s.ranges.clear();
                s.ranges.extend(lidar.ranges().iter().map(|&r| r as f32));
                Some(s)
            }
            _ => None,
        };
        let sent = &mut self.sent_cells;
        m.cells = w.scene().skin.as_ref().map(|skin| {
            let mut c = m.cells.take().unwrap_or_default();
            write_events(&skin.layout, w.skin_readings(), &stamp, sent, &mut c);
            c
        });
        m.goal = None;
        // A goal is due in the period that contains its start time.
        while let Some((start, pose)) = self.goals.get(self.next_goal) {
            if *start > t + 0.5 * self.period_s {
                break;
            }
            m.goal = Some(write_goal(pose, &stamp, WORLD_FRAME));
            self.next_goal += 1;
        }
        let forces = &w.scene().spec.force_references;
        m.force_n =
            forces.iter().filter(|f| f.start_s <= t).max_by(|a, b| a.start_s.total_cmp(&b.start_s)).map(|f| f.value(t));
        &self.msgs
    }

    /// Arm `arm`'s command (held until the next one). Errors name the topic and field.
    pub fn on_arm_command(&mut self, arm: usize, msg: &Float64MultiArray) -> Result<(), String> {
        read_arm_command(&self.arms[arm], msg, &mut self.arm_cmd)
    }

    /// The base twist command (held until the next one).
    pub fn on_twist(&mut self, msg: &Twist) -> Result<(), String> {
        self.twist = twist_of(msg).map_err(|e| format!("{}: {e}", skin_control::topics::CMD_VEL))?;
        Ok(())
    }

    /// The commands as they stand, for the record.
    pub fn applied(&self) -> AppliedCommand {
        AppliedCommand { t_s: self.world.time(), joints: self.arm_cmd.clone(), base: self.twist }
    }

    /// Applies the held commands and steps one control period.
    pub fn step_period(&mut self) {
        self.world.set_arm_velocity_commands(&self.arm_cmd).expect("arm command length checked on receipt");
        self.world.set_base_twist(self.twist);
        for _ in 0..self.steps_per_period {
            self.world.step();
        }
    }
}

/// Writes into `msg` the cells an event-driven skin sends: those that read something, or changed
/// since `sent` (the last message's readings, updated here). A subscriber that keeps each cell's
/// last reading and reads zero before the first (`convert::CellBuffer`) sees every cell as if all
/// were sent, also when it joins late; the message shrinks from every cell to the few near
/// something, which is most of the graph's serialization cost.
fn write_events(
    layout: &ResolvedLayout,
    readings: &[CellReading],
    stamp: &Time,
    sent: &mut Vec<CellReading>,
    msg: &mut SkinCellArray,
) {
    let zero = CellReading::default();
    write_cell_array(layout, readings, stamp, |k| readings[k] != zero || sent.get(k) != Some(&readings[k]), msg);
    sent.clear();
    sent.extend_from_slice(readings);
}

/// The graph's loop in one process, without DDS: the [`SimBridge`]'s messages into a
/// [`crate::task_controller::TaskController`] (every message conversion of the graph, in the
/// same order), its commands back, for `cycles` periods. What the lockstep graph must reproduce
/// exactly; returns the applied commands per period.
pub fn run_in_process(
    bridge: &mut SimBridge,
    tc: &mut skin_control::task_controller::TaskController,
    cycles: usize,
) -> Vec<AppliedCommand> {
    let mut out = Vec::with_capacity(cycles);
    for _ in 0..cycles {
        let m = bridge.messages().clone();
        if let Some(g) = &m.goal {
            let _ = tc.on_goal(g);
        }
        if let Some(f) = m.force_n {
            let _ = tc.on_force_reference(f);
        }
        // trigger `inputs`: the stamps are checked for their order only, the clock is unused
        let now = 0.0;
        if let Some(o) = &m.odom {
            let _ = tc.on_odometry(o, now);
        }
        if let Some(s) = &m.scan {
            let _ = tc.on_scan(s, now);
        }
        if let Some(c) = &m.cells {
            let _ = tc.on_cells(c, now, |_| {});
        }
        let _ = tc.on_joint_states(&m.joints, now, |_| {});
        let stamp = tc.ready_stamp().expect("a complete input set every period");
        let t = skin_control::convert::robot::time_s(&stamp);
        let o = tc.cycle(t, &stamp);
        let arms: Vec<Float64MultiArray> = o.arms.to_vec();
        let twist = o.base.cloned();
        for (k, a) in arms.iter().enumerate() {
            bridge.on_arm_command(k, a).expect("controller commands fit the world");
        }
        if let Some(t) = twist {
            bridge.on_twist(&t).expect("finite twist");
        }
        out.push(bridge.applied());
        bridge.step_period();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use skin_control::ros_params::flatten;
    use skin_control::task_controller::{SupervisorSource, TaskController, TaskControllerParams, Trigger};
    use skin_core::controller::ControllerConfig;
    use skin_sim::run::closed_loop::ClosedLoop;
    use skin_sim::run::runner::RunTarget;

    /// The event-driven cells: all in the first message, then those that read something or
    /// changed (a cell back to zero once), never an unchanged zero one.
    #[test]
    fn cell_messages_carry_the_active_and_changed_cells() {
        let layout = skin_core::skin::layout::SkinLayout::from_yaml_str(
            include_str!("../../skin_core/src/skin/testdata/two_patches.yaml"),
            "two_patches.yaml",
        )
        .unwrap()
        .resolve_with(|l| Some(if l == "a" { 1 } else { 2 }))
        .unwrap();
        let mut sent = Vec::new();
        let mut m = SkinCellArray::default();
        let mut ids = |readings: &[CellReading]| {
            write_events(&layout, readings, &Time::default(), &mut sent, &mut m);
            m.cell_id.clone()
        };
        let zero = CellReading::default();
        let touched = CellReading::uniform(0.0, 0.5);
        assert_eq!(ids(&[zero, touched, zero]), [10, 11, 20]);
        assert_eq!(ids(&[zero, touched, touched]), [11, 20]);
        assert_eq!(ids(&[zero, zero, touched]), [11, 20]);
        assert_eq!(ids(&[zero; 3]), [20]);
        assert!(ids(&[zero; 3]).is_empty());
        assert_eq!(ids(&[touched, zero, zero]), [10]);
        assert_eq!((m.force.as_slice(), m.proximity.as_slice()), (&[0.0; 3][..], &[0.5][..]));
    }

    /// The graph's loop without DDS against skin_sim's in-process loop: the only difference is
    /// the messages' float32 skin signals (and ns stamps), so commands agree to that precision.
    #[test]
    fn message_loop_matches_the_in_process_loop() {
        let target = RunTarget::resolve("intentional_contact", None).unwrap();
        let scene = Scene::load(&target.scene).unwrap();
        let config = ControllerConfig::load(&target.controller).unwrap();
        let mut params = TaskControllerParams::defaults(&config);
        params.trigger = Trigger::Inputs;
        params.supervisor = SupervisorSource::Internal;
        params.control_rate_hz = scene.spec.control_rate_hz;
        assert!(flatten(&params).unwrap().contains_key("tasks.goal.kp_n_per_m"));
        let mut tc = TaskController::new(config, params.clone(), 0.0).unwrap();
        let mut bridge = SimBridge::new(scene.clone(), &params.arms.namespaces, &params.arms.joint_prefixes).unwrap();
        let cycles: usize = std::env::var("SKIN_CYCLES").ok().and_then(|v| v.parse().ok()).unwrap_or(400);
        let graph = run_in_process(&mut bridge, &mut tc, cycles);
        let mut direct = ClosedLoop::new(scene, &target.controller).unwrap();
        let mut max = 0.0f64;
        let mut peak = 0.0f64;
        let mut first = None;
        for g in &graph {
            let c = direct.cycle();
            assert!((c.t_s - g.t_s).abs() < 1e-12);
            for (a, b) in c.joint_velocities.iter().zip(&g.joints) {
                max = max.max((a - b).abs());
                peak = peak.max(a.abs());
            }
            if max > 0.0 && first.is_none() {
                first = Some(c.t_s);
            }
        }
        println!("message loop vs in-process loop over {cycles} cycles: max |dq_cmd| difference {max:.3e} rad/s (peak command {peak:.3} rad/s), first difference at t = {first:?} s");
        assert!(peak > 1e-3, "the arm moves");
        // Before the skin senses anything the float32 signals are exact (zeros): identical.
        assert!(cycles > 400 || max < 1e-9, "difference {max}");
    }
}
