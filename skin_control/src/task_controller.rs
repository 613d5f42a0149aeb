//! The task controller's work without the node around it: messages in, one
//! `skin_core::controller::Controller` cycle, messages out. The node (`nodes::task_controller`)
//! only wires topics, the timer and the parameters to this.
//!
//! Inputs (docs/ros.md): `/joint_states` (arm joints by name), `/base/odom` (when the model has a
//! base), `/skin/cells` (when the layout has cells; per cell, because avoidance and contact
//! reaction act per cell, paper 000 eq. 3-6), `/scan` (when `use_scan`), `/goal`, the hand force
//! reference (newtons), `/supervisor/arrangement`. A cycle runs only on a complete input set
//! (every required input received at least once); until then, and whenever the inputs go stale,
//! the commands are zero.
use nalgebra::Vector2;
use r2r::builtin_interfaces::msg::Time;
use r2r::geometry_msgs::msg::{PoseStamped, Twist};
use r2r::nav_msgs::msg::Odometry;
use r2r::sensor_msgs::msg::{JointState, LaserScan};
use r2r::skin_msgs::msg::{Arrangement as ArrangementMsg, ControllerState, SkinCellArray};
use r2r::std_msgs::msg::Float64MultiArray;
use serde::{Deserialize, Serialize};
use skin_core::controller::{Controller, ControllerConfig, ControllerInput};
use skin_core::skin::params::SkinParams;
use skin_core::supervisor::Mode;
use skin_core::tasks::params::TaskParams;
use skin_sim::hand_force::HandForceMap;

use crate::convert::control::{
    imposed_of, split_arms, twist_msg, write_arm_command, write_controller_state, ArmCommand,
};
use crate::convert::robot::{goal_pose, time_s, JointStateIssue, ScanConverter, StateBuffer};
use crate::convert::{CellBuffer, Issue};

/// What starts a control cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Trigger {
    /// A timer at `control_rate_hz` on the node's ROS clock (sim time with `use_sim_time`): the
    /// robot's mode. Each cycle uses the latest of every input.
    Timer,
    /// A complete input set with one common stamp, newer than the last cycle's: the lockstep
    /// simulation's mode (`mujoco_sim --lockstep` stamps every input of a period alike), which
    /// makes the graph reproducible.
    Inputs,
}

/// Who decides the arrangement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SupervisorSource {
    /// Follow `/supervisor/arrangement` (the `priority_supervisor` node); until the first one
    /// arrives the controller's own copy of the supervisor (same configuration) decides.
    Topic,
    /// The controller's own supervisor, in the cycle (no one-cycle delay: the in-process loop's
    /// behaviour, used to reproduce it through the graph).
    Internal,
}

/// Which arms get commands: `namespaces[k]` + `/forward_velocity_controller/commands` carries the
/// arm joints whose names start with `joint_prefixes[k]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArmsParams {
    /// Command namespaces, e.g. `[/left_arm, /right_arm]`.
    pub namespaces: Vec<String>,
    /// Joint-name prefixes, e.g. `[left_, right_]` (an empty prefix takes every other joint).
    pub joint_prefixes: Vec<String>,
}

impl ArmsParams {
    /// The default split for these joints: `/left_arm` and `/right_arm` by `left_`/`right_`
    /// when both exist (TOMM), else one arm `/arm` with every arm joint.
    pub fn for_joints(names: &[String]) -> Self {
        let two = ["left_", "right_"].iter().all(|p| names.iter().any(|n| n.starts_with(p)));
        if two {
            ArmsParams { namespaces: vec!["/left_arm".into(), "/right_arm".into()], joint_prefixes: vec!["left_".into(), "right_".into()] }
        } else {
            ArmsParams { namespaces: vec!["/arm".into()], joint_prefixes: vec![String::new()] }
        }
    }
}

/// The task controller's parameters, served as ROS parameters (`ros_params::StructParams`).
/// `skin` and `tasks` are `skin_core`'s structs: their initial values come from the files the
/// controller setup names, and the node's parameter overrides replace single keys.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TaskControllerParams {
    /// Control rate \[Hz\] (the timer's, and `1 / dt` of every cycle).
    pub control_rate_hz: f64,
    /// `timer` or `inputs` ([`Trigger`]).
    pub trigger: Trigger,
    /// `topic` or `internal` ([`SupervisorSource`]).
    pub supervisor: SupervisorSource,
    /// Whether `/scan` is a required input (base avoidance, paper 003 eq. 15-17).
    pub use_scan: bool,
    /// Timer mode: inputs older than this (ROS time) make the commands zero \[s\].
    pub input_timeout_s: f64,
    /// Command topics per arm.
    pub arms: ArmsParams,
    /// Skin model (`config/skin_model.yaml`).
    pub skin: SkinParams,
    /// Task gains (`config/tasks.yaml`).
    pub tasks: TaskParams,
}

/// Keys that only the start reads (everything but `input_timeout_s`): the controller is built
/// from them once (`skin_core::controller::Controller` has no setter for them at run time).
pub const START_ONLY: &[&str] = &["control_rate_hz", "trigger", "supervisor", "use_scan", "arms.", "skin.", "tasks."];

/// `ros2 param describe` texts.
pub const DESCRIPTIONS: &[(&str, &str)] = &[
    ("control_rate_hz", "Control rate [Hz]: timer period and dt of every cycle (start only)"),
    ("trigger", "timer: cycles on the ROS clock; inputs: one cycle per complete input set with a common stamp (lockstep simulation) (start only)"),
    ("supervisor", "topic: follow /supervisor/arrangement; internal: the controller's own supervisor in the cycle (start only)"),
    ("use_scan", "Whether /scan is a required input (start only)"),
    ("input_timeout_s", "Timer mode: inputs older than this [s] make the commands zero (settable)"),
    ("arms.namespaces", "Command namespaces, one per arm: <ns>/forward_velocity_controller/commands (start only)"),
    ("arms.joint_prefixes", "Joint-name prefix of each arm's joints, pairs with arms.namespaces (start only)"),
];

impl TaskControllerParams {
    /// Defaults for `config`: timer at the arm resolver's rate, the supervisor node followed,
    /// scan required when the model has a base, arms `left_`/`right_` when the model has them
    /// (else one arm `/arm` with every arm joint).
    pub fn defaults(config: &ControllerConfig) -> Self {
        let arms = ArmsParams::for_joints(config.model.joint_names());
        TaskControllerParams {
            control_rate_hz: config.resolver.arm.rate_hz,
            trigger: Trigger::Timer,
            supervisor: SupervisorSource::Topic,
            use_scan: crate::convert::robot::base_joints(&config.model).is_some(),
            input_timeout_s: 0.1,
            arms,
            skin: config.skin,
            tasks: config.tasks.clone(),
        }
    }

    /// Checks every value; the error names the key.
    pub fn validate(&self) -> Result<(), String> {
        if !(self.control_rate_hz.is_finite() && self.control_rate_hz > 0.0 && self.control_rate_hz <= 10_000.0) {
            return Err(format!("`control_rate_hz` = {}: must be in (0, 10000]", self.control_rate_hz));
        }
        if !(self.input_timeout_s.is_finite() && self.input_timeout_s > 0.0) {
            return Err(format!("`input_timeout_s` = {}: must be finite and > 0", self.input_timeout_s));
        }
        self.skin.validate().map_err(|e| format!("skin.{e}"))?;
        self.tasks.validate().map_err(|e| format!("tasks.{e}"))?;
        Ok(())
    }
}

/// The messages of one cycle.
pub struct Outputs<'a> {
    /// One command per arm, in [`TaskController::arms`] order.
    pub arms: &'a [Float64MultiArray],
    /// The base twist (None: the model has no base).
    pub base: Option<&'a Twist>,
    /// The controller state (None when the cycle did not run the controller: zero commands).
    pub state: Option<&'a ControllerState>,
}

/// Why an input message was refused.
#[derive(Debug, Clone, PartialEq)]
pub struct InputError {
    /// The topic's role: `odometry`, `scan`, `goal`, `force reference`, `arrangement`.
    pub input: &'static str,
    /// What is wrong (names the field).
    pub reason: String,
}

impl std::fmt::Display for InputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.input, self.reason)
    }
}

fn refuse(input: &'static str) -> impl FnOnce(String) -> InputError {
    move |reason| InputError { input, reason }
}

/// The task controller: inputs buffered, one cycle on demand.
pub struct TaskController {
    controller: Controller,
    params: TaskControllerParams,
    state: StateBuffer,
    cells: CellBuffer,
    scan: ScanConverter,
    no_scan: Vec<Vector2<f64>>,
    hand_map: Option<HandForceMap>,
    arms: Vec<ArmCommand>,
    needs_odom: bool,
    needs_cells: bool,
    cells_stamp: Option<Time>,
    scan_stamp: Option<Time>,
    last_cycle: Option<Time>,
    arm_msgs: Vec<Float64MultiArray>,
    twist: Twist,
    state_msg: ControllerState,
    cycles: u64,
    faults: u64,
}

impl TaskController {
    /// A controller from `config` with `params` laid over it (skin, tasks), at time `t0_s`.
    pub fn new(mut config: ControllerConfig, params: TaskControllerParams, t0_s: f64) -> Result<Self, String> {
        params.validate()?;
        config.skin = params.skin;
        config.tasks = params.tasks.clone();
        let hand_map = HandForceMap::new(&config);
        let controller = Controller::new(config, t0_s).map_err(|e| e.to_string())?;
        let cfg = controller.config();
        let model = &cfg.model;
        let arms = split_arms(model.joint_names(), controller.resolver().arm_joints(), &params.arms.namespaces, &params.arms.joint_prefixes)?;
        let state = StateBuffer::new(model);
        let scan = ScanConverter::new(model);
        Ok(TaskController {
            needs_odom: state.base().is_some(),
            needs_cells: cfg.layout.num_cells() > 0,
            cells: CellBuffer::new(&cfg.layout),
            arm_msgs: arms.iter().map(|a| {
                let mut m = Float64MultiArray::default();
                write_arm_command(a, &[], &mut m);
                m
            }).collect(),
            twist: Twist::default(),
            state_msg: ControllerState::default(),
            state,
            scan,
            no_scan: Vec::new(),
            hand_map,
            arms,
            cells_stamp: None,
            scan_stamp: None,
            last_cycle: None,
            cycles: 0,
            faults: 0,
            params,
            controller,
        })
    }

    /// The controller.
    pub fn controller(&self) -> &Controller {
        &self.controller
    }

    /// The parameters it was built with.
    pub fn params(&self) -> &TaskControllerParams {
        &self.params
    }

    /// The arms and their command topics.
    pub fn arms(&self) -> &[ArmCommand] {
        &self.arms
    }

    /// Whether the model has a base (a `/base/cmd_vel` output and a `/base/odom` input).
    pub fn has_base(&self) -> bool {
        self.needs_odom
    }

    /// Cycles run and cycles that were safe-stop steps.
    pub fn counts(&self) -> (u64, u64) {
        (self.cycles, self.faults)
    }

    /// Joint state input issues so far.
    pub fn joint_issues(&self) -> &crate::convert::robot::JointIssueCounts {
        self.state.issues()
    }

    /// Skin cell input issues so far.
    pub fn cell_issues(&self) -> &crate::convert::IssueCounts {
        self.cells.issues()
    }

    /// `/joint_states`.
    pub fn on_joint_states(&mut self, msg: &JointState, report: impl FnMut(&JointStateIssue)) {
        self.state.update_joints(msg, report);
    }

    /// `/base/odom`.
    pub fn on_odometry(&mut self, msg: &Odometry) -> Result<(), InputError> {
        self.state.update_odometry(msg).map_err(refuse("odometry"))
    }

    /// `/skin/cells`.
    pub fn on_cells(&mut self, msg: &SkinCellArray, report: impl FnMut(&Issue)) {
        self.cells.update(&self.controller.config().layout, msg, report);
        self.cells_stamp = Some(msg.header.stamp.clone());
    }

    /// `/scan`.
    pub fn on_scan(&mut self, msg: &LaserScan) -> Result<(), InputError> {
        self.scan_stamp = Some(msg.header.stamp.clone());
        self.scan.update(msg).map_err(refuse("scan"))
    }

    /// `/goal`: the end-effector goal in the world frame.
    pub fn on_goal(&mut self, msg: &PoseStamped) -> Result<(), InputError> {
        let pose = goal_pose(msg).map_err(refuse("goal"))?;
        self.controller.set_goal(Some(pose)).map_err(|f| InputError { input: "goal", reason: f.to_string() })
    }

    /// The hand force reference \[N\], mapped to the hand signal `f_c,d` of paper 003 eq. (9)
    /// by `skin_sim::hand_force::HandForceMap` (an even contact on the palm cells). Returns the
    /// signal given.
    pub fn on_force_reference(&mut self, force_n: f64) -> Result<f64, InputError> {
        let map = self.hand_map.as_ref().ok_or_else(|| InputError {
            input: "force reference",
            reason: "the controller setup's hand_patches have no cell facing along the end effector's z axis".into(),
        })?;
        if !(force_n.is_finite() && force_n >= 0.0) {
            return Err(InputError { input: "force reference", reason: format!("data = {force_n}: must be finite and >= 0 N") });
        }
        let signal = map.signal(force_n);
        self.controller.set_hand_force_reference(signal).map_err(|f| InputError { input: "force reference", reason: f.to_string() })?;
        Ok(signal)
    }

    /// `/supervisor/arrangement` (ignored with `supervisor: internal`; returns whether it was
    /// applied).
    pub fn on_arrangement(&mut self, msg: &ArrangementMsg) -> Result<bool, InputError> {
        if self.params.supervisor == SupervisorSource::Internal {
            return Ok(false);
        }
        let configured = |mode: Mode| -> Vec<String> {
            let params = &self.controller.config().supervisor;
            let names = params.arrangements.by_mode();
            names[mode as usize].1.to_vec()
        };
        let imposed = imposed_of(msg, configured).map_err(refuse("arrangement"))?;
        self.controller.impose_arrangement(imposed).map_err(|e| InputError { input: "arrangement", reason: e.to_string() })?;
        Ok(true)
    }

    /// The required inputs that have not arrived yet (empty: complete).
    pub fn missing(&self) -> Vec<String> {
        let mut m: Vec<String> = self.state.missing().filter(|n| !self.is_base_joint(n)).map(|n| format!("joint `{n}`")).collect();
        if self.needs_odom && self.state.odom_stamp().is_none() {
            m.push("odometry".into());
        }
        if self.needs_cells && self.cells_stamp.is_none() {
            m.push("skin cells".into());
        }
        if self.params.use_scan && self.scan_stamp.is_none() {
            m.push("scan".into());
        }
        m
    }

    fn is_base_joint(&self, name: &str) -> bool {
        skin_core::resolver::BASE_JOINTS.contains(&name)
    }

    /// The inputs' stamps that must be fresh: joint states, and odometry, cells, scan when required.
    fn stamps(&self) -> impl Iterator<Item = Option<&Time>> + '_ {
        [
            Some(self.state.joint_stamp()),
            self.needs_odom.then(|| self.state.odom_stamp()),
            self.needs_cells.then_some(self.cells_stamp.as_ref()),
            self.params.use_scan.then_some(self.scan_stamp.as_ref()),
        ]
        .into_iter()
        .flatten()
    }

    /// Trigger `inputs`: the common stamp of a complete input set that is newer than the last
    /// cycle, if there is one now.
    pub fn ready_stamp(&self) -> Option<Time> {
        if !self.state.complete() {
            return None;
        }
        let first = self.state.joint_stamp()?.clone();
        let common = self.stamps().all(|s| s == Some(&first));
        let newer = self.last_cycle.as_ref().is_none_or(|l| time_s(&first) > time_s(l));
        (common && newer).then_some(first)
    }

    /// Trigger `timer`: the age of the oldest required input at `now_s` (None: one is missing).
    pub fn input_age(&self, now_s: f64) -> Option<f64> {
        if !self.state.complete() {
            return None;
        }
        self.stamps().map(|s| s.map(|t| now_s - time_s(t))).try_fold(0.0f64, |a, age| age.map(|x| a.max(x)))
    }

    /// Zero commands on every output (no controller state).
    pub fn zero_outputs(&mut self) -> Outputs<'_> {
        for (a, m) in self.arms.iter().zip(&mut self.arm_msgs) {
            write_arm_command(a, &[], m);
        }
        self.twist = twist_msg([0.0; 3]);
        Outputs { arms: &self.arm_msgs, base: self.needs_odom.then_some(&self.twist), state: None }
    }

    /// One control cycle at `t_s` with the buffered inputs (call only on a complete input set).
    pub fn cycle(&mut self, t_s: f64, stamp: &Time) -> Outputs<'_> {
        let scan = if self.params.use_scan { self.scan.points() } else { &self.no_scan };
        let input = ControllerInput {
            t_s,
            dt_s: 1.0 / self.params.control_rate_hz,
            q: self.state.q(),
            qd: self.state.qd(),
            cells: self.cells.readings(),
            scan,
        };
        let out = self.controller.update(&input);
        self.cycles += 1;
        if out.fault.is_some() {
            self.faults += 1;
        }
        for (a, m) in self.arms.iter().zip(&mut self.arm_msgs) {
            write_arm_command(a, &out.commands.joint_velocities, m);
        }
        self.twist = twist_msg(out.commands.base_twist);
        let c = &self.controller;
        let sup = c.supervisor();
        write_controller_state(c.output(), sup.tasks(), sup.arrangement().task_order(), c.level_diagnostics(), stamp, &mut self.state_msg);
        self.last_cycle = Some(stamp.clone());
        Outputs { arms: &self.arm_msgs, base: self.needs_odom.then_some(&self.twist), state: Some(&self.state_msg) }
    }

    /// The fault text of the last cycle, if it was a safe-stop step.
    pub fn last_fault(&self) -> Option<String> {
        self.controller.output().fault.map(|f| f.to_string())
    }
}
