//! The task controller's work without the node around it: messages in, one
//! `skin_core::controller::Controller` cycle, messages out. The node (`nodes::task_controller`)
//! only wires topics, the timer and the parameters to this.
//!
//! Inputs (docs/ros.md): `/joint_states` (arm joints by name), `/base/odom` (when the model has a
//! base), `/skin/cells` (when the layout has cells; per cell, because avoidance and contact
//! reaction act per cell, intentional-contact paper eq. 3-6), `/scan` (when `use_scan`), `/goal`, the hand force
//! reference (newtons), `/supervisor/arrangement`. A cycle runs only on a complete input set
//! (every required input received at least once); until then, and whenever the inputs go stale,
//! the commands are zero.
use nalgebra::{Isometry3, Vector2};
use r2r::builtin_interfaces::msg::Time;
use r2r::geometry_msgs::msg::{PoseStamped, Twist};
use r2r::nav_msgs::msg::Odometry;
use r2r::sensor_msgs::msg::{JointState, LaserScan};
use r2r::skin_msgs::msg::{Arrangement as ArrangementMsg, ControllerState};
use r2r::std_msgs::msg::Float64MultiArray;
use serde::{Deserialize, Serialize};
use skin_core::controller::HandForceMap;
use skin_core::controller::{Controller, ControllerConfig, ControllerInput};
use skin_core::declare_params;
use skin_core::model::is_base_joint_name;
use skin_core::model::{frame_pose, update_kinematics, ModelData};
use skin_core::param_file::declare::{Declared, Range};
use skin_core::skin::params::SkinParams;
use skin_core::supervisor::Mode;
use skin_core::tasks::params::TaskParams;

use crate::convert::cdr_cells::CdrCells;
use crate::convert::control::{
    imposed_of, split_arms, twist_msg, write_arm_command, write_controller_state, ArmCommand,
};
use crate::convert::robot::{goal_pose, time_s, JointIssue, JointStateIssue, ScanConverter, StateBuffer};
use crate::convert::{update_cells, CellBuffer, CellMessage, Issue, IssueKind};
use crate::input_health::{fresh, IssueTable, StampGate, StampIssue};
use crate::tf::{ODOM_FRAME, WORLD_FRAME};
use crate::topics::{ARRANGEMENT, CELLS, FORCE_REFERENCE, GOAL, JOINT_STATES, ODOM, SCAN};

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

declare_params! {
    /// Which arms get commands: `namespaces[k]` + `/forward_velocity_controller/commands` carries the
    /// arm joints whose names start with `joint_prefixes[k]`.
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct ArmsParams {
        /// Command namespaces, one per arm, e.g. `[left_arm, right_arm]` (relative: under the
        /// node's namespace; an absolute one, `/left_arm`, is not).
        pub namespaces: Vec<String> => { text: "names", live: false },
        /// Joint-name prefix of each arm's joints, pairs with `arms.namespaces`, e.g.
        /// `[left_, right_]` (an empty prefix takes every other joint).
        pub joint_prefixes: Vec<String> => { text: "prefixes", live: false },
    }
}

impl ArmsParams {
    /// The default split for these joints: `left_arm` and `right_arm` by `left_`/`right_`
    /// when both exist (TOMM), else one arm `arm` with every arm joint.
    pub fn for_joints(names: &[String]) -> Self {
        let two = ["left_", "right_"].iter().all(|p| names.iter().any(|n| n.starts_with(p)));
        if two {
            ArmsParams {
                namespaces: vec!["left_arm".into(), "right_arm".into()],
                joint_prefixes: vec!["left_".into(), "right_".into()],
            }
        } else {
            ArmsParams { namespaces: vec!["arm".into()], joint_prefixes: vec![String::new()] }
        }
    }
}

declare_params! {
    /// The task controller's parameters, served as ROS parameters (`ros_params::StructParams`).
    /// `skin` and `tasks` are `skin_core`'s structs: their initial values come from the files the
    /// controller setup names, and the node's parameter overrides replace single keys.
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct TaskControllerParams {
        /// Control rate: the timer's, and `1 / dt` of every cycle.
        pub control_rate_hz: f64 => { unit: "Hz", range: Range::positive(10_000.0), live: false },
        /// `timer`: cycles on the ROS clock; `inputs`: one cycle per complete input set with a
        /// common stamp (lockstep simulation).
        pub trigger: Trigger => { choices: "timer | inputs", live: false },
        /// `topic`: follow /supervisor/arrangement; `internal`: the controller's own supervisor
        /// in the cycle.
        pub supervisor: SupervisorSource => { choices: "topic | internal", live: false },
        /// Whether `/scan` is a required input (base avoidance, interactive-force-control paper eq. 15-17).
        pub use_scan: bool => { choices: "true | false", live: false },
        /// Timer mode: a joint whose last value is older than this (ROS time; per joint) makes
        /// the commands ramp to zero within the acceleration limits.
        pub input_timeout_s: f64 => { unit: "s", range: TIMEOUT_RANGE, live: true },
        /// Timer mode: the same for odometry.
        pub odom_timeout_s: f64 => { unit: "s", range: TIMEOUT_RANGE, live: true },
        /// Timer mode: the same for the skin cells.
        pub cells_timeout_s: f64 => { unit: "s", range: TIMEOUT_RANGE, live: true },
        /// Timer mode: the same for the scan (a LIDAR is slower than a joint driver).
        pub scan_timeout_s: f64 => { unit: "s", range: TIMEOUT_RANGE, live: true },
        /// Timer mode: a message stamped further ahead of the node's clock than this is refused,
        /// and an input whose age is below minus this is stale.
        pub max_stamp_lead_s: f64 => { unit: "s", range: Range::closed(0.0, 0.1), live: true },
        /// Managed node: configure and activate at start (a simulation); false: hold still (zero
        /// commands) until `<node>/change_state` activates it (a robot, as an operator does).
        pub autostart: bool => { choices: "true | false", live: false },
        /// Timer mode: at start, listen this long for another controller's heartbeat on the same
        /// command topics before commanding (one commander; DDS discovery takes up to seconds).
        pub commander_wait_s: f64 => { unit: "s", range: Range::closed(0.0, 10.0), live: false },
        /// The base command as `geometry_msgs/TwistStamped` (frame `base_link`, stamped with the
        /// period's time), as ROS 2 Jazzy's ros2_control base controllers take it; false: `Twist`.
        pub base_command_stamped: bool => { choices: "true | false", live: false },
        /// Command topics per arm.
        pub arms: ArmsParams => nested,
        /// Skin model (`config/skin_model.yaml`); read at start by this node.
        pub skin: SkinParams => nested,
        /// Task gains (`config/tasks.yaml`).
        pub tasks: TaskParams => nested,
    }
}

/// The section this node reads at start only although its declarations are `live` (they are,
/// in the skin aggregator): the controller is built from it once.
pub const START_ONLY_SECTION: &str = "skin.";

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
            use_scan: config.model.planar_base().is_some(),
            input_timeout_s: 0.1,
            odom_timeout_s: 0.1,
            cells_timeout_s: 0.1,
            scan_timeout_s: 0.25,
            max_stamp_lead_s: 0.02,
            autostart: true,
            commander_wait_s: 5.0,
            base_command_stamped: false,
            arms,
            skin: config.skin,
            tasks: config.tasks.clone(),
        }
    }

    /// Checks every value against its declared range, then the skin and task parameters'
    /// own rules; the error names the key.
    pub fn validate(&self) -> Result<(), String> {
        self.check("").map_err(|e| e.to_string())?;
        self.skin.validate().map_err(|e| format!("skin.{e}"))?;
        self.tasks.validate().map_err(|e| format!("tasks.{e}"))?;
        Ok(())
    }
}

/// The node's own parameters (not `skin.*`, `tasks.*`) as a Markdown table, with the values
/// `config` gives them by default (docs/ros.md).
pub fn parameter_table(config: &ControllerConfig) -> String {
    let own: Vec<_> = TaskControllerParams::all_specs()
        .into_iter()
        .filter(|s| !s.key.starts_with("skin.") && !s.key.starts_with("tasks."))
        .collect();
    let values = serde_json::to_value(TaskControllerParams::defaults(config)).expect("parameters serialize");
    skin_core::param_file::declare::markdown_table(&own, &values)
}

/// Range of the input timeouts: a longer one would let the controller command from a state a
/// second old.
const TIMEOUT_RANGE: Range = Range::closed(0.001, 1.0);

/// The messages of one cycle.
pub struct Outputs<'a> {
    /// One command per arm, in [`TaskController::arms`] order.
    pub arms: &'a [Float64MultiArray],
    /// The base twist (None: the model has no base).
    pub base: Option<&'a Twist>,
    /// The controller state (None only for the shutdown's zero commands).
    pub state: Option<&'a ControllerState>,
}

/// Why an input message was refused (it is ignored as a whole, and counted).
#[derive(Debug, Clone, PartialEq)]
pub struct InputError {
    /// The topic.
    pub topic: &'static str,
    /// What is wrong (names the field).
    pub reason: String,
    /// Whether this kind of refusal is the first on this topic (log it then; later ones are only
    /// counted).
    pub first: bool,
}

impl std::fmt::Display for InputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.topic, self.reason)
    }
}

/// The inputs' state at a control period ([`TaskController::freshness`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Freshness {
    /// Every required input is fresh: a cycle may run.
    Fresh,
    /// A required input (a joint) has not arrived yet.
    Waiting,
    /// `input`'s age is outside `[-max_stamp_lead_s, timeout_s]`.
    Stale {
        /// The topic.
        input: &'static str,
        /// Its age \[s\] (the oldest joint's for joint states; negative: stamped ahead of the clock).
        age_s: f64,
        /// Its timeout \[s\].
        timeout_s: f64,
    },
}

/// One required input's age at a time ([`TaskController::input_ages`]).
#[derive(Debug, Clone, PartialEq)]
pub struct InputAge {
    /// The topic.
    pub topic: &'static str,
    /// Clock minus the stamp of its last accepted value \[s\] (joint states: of the oldest joint);
    /// None: not received yet.
    pub age_s: Option<f64>,
    /// Its timeout \[s\].
    pub timeout_s: f64,
    /// Joint states: the oldest joint, or the joints not received yet.
    pub detail: Option<String>,
}

/// Where the input status of `/controller/state` comes from when no cycle ran.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Idle {
    /// A required input has not arrived yet.
    Waiting,
    /// An input is older than `input_timeout_s`.
    Stale,
}

/// The timed inputs, each with a stamp gate.
#[derive(Debug, Clone, Copy)]
enum Timed {
    Joints,
    Odometry,
    Cells,
    Scan,
}

const TIMED_TOPICS: [&str; 4] = [JOINT_STATES, ODOM, CELLS, SCAN];
const REFUSED: &str = "message refused";

/// Counters of every input issue ([`IssueTable`], in `/controller/state`) and the stamp gates.
struct Health {
    table: IssueTable,
    /// First counter of the [`JointIssue`] kinds and of the cell [`IssueKind`]s.
    joint_kinds: usize,
    cell_kinds: usize,
    /// Per timed input: its gate and its first [`StampIssue`] counter (joint states: the order is
    /// kept per joint, the gate checks the clock only).
    stamps: [(StampGate, usize); 4],
    /// The `message refused` counter of each topic that refuses whole messages.
    refused: [(&'static str, usize); 6],
    idle_periods: u64,
}

impl Health {
    fn new() -> Self {
        let mut table = IssueTable::default();
        let joint_kinds = table.register(JOINT_STATES, JointIssue::ALL.map(JointIssue::name));
        let cell_kinds = table.register(CELLS, IssueKind::ALL.map(IssueKind::name));
        let stamps =
            TIMED_TOPICS.map(|t| (StampGate::default(), table.register(t, StampIssue::ALL.map(StampIssue::name))));
        let refused =
            [CELLS, ODOM, SCAN, GOAL, FORCE_REFERENCE, ARRANGEMENT].map(|t| (t, table.register(t, [REFUSED])));
        Health { table, joint_kinds, cell_kinds, stamps, refused, idle_periods: 0 }
    }

    /// The stamp check of `input` (`now_s`: the clock to compare with, if any).
    fn check_stamp(
        &mut self,
        input: Timed,
        stamp: &Time,
        now_s: Option<f64>,
        max_lead_s: f64,
    ) -> Result<(), InputError> {
        let gate = &self.stamps[input as usize].0;
        gate.check(stamp, now_s, max_lead_s).map_err(|issue| self.stamp_issue(input, issue, stamp, now_s))
    }

    /// Counts `issue` of `input`'s message stamped `stamp`.
    fn stamp_issue(&mut self, input: Timed, issue: StampIssue, stamp: &Time, now_s: Option<f64>) -> InputError {
        let k = self.stamps[input as usize].1 + issue as usize;
        let clock = now_s.map_or(String::new(), |n| format!(", clock {n:.6} s"));
        InputError {
            topic: TIMED_TOPICS[input as usize],
            reason: format!("header.stamp {:.6} s: {}{clock}", time_s(stamp), issue.name()),
            first: self.table.count(k),
        }
    }

    /// The last accepted stamp of `input` \[s\].
    fn last(&self, input: Timed) -> Option<f64> {
        self.stamps[input as usize].0.last()
    }

    fn accept(&mut self, input: Timed, stamp: &Time) {
        self.stamps[input as usize].0.accept(stamp);
    }

    /// Counts a refused message of `topic`.
    fn refuse(&mut self, topic: &'static str) -> impl FnOnce(String) -> InputError + '_ {
        let k = self.refused.iter().find(|(t, _)| *t == topic).map(|(_, k)| *k).expect("a topic that refuses messages");
        move |reason| InputError { topic, reason, first: self.table.count(k) }
    }
}

/// The task controller: inputs buffered, one cycle on demand.
pub struct TaskController {
    controller: Controller,
    params: TaskControllerParams,
    state: StateBuffer,
    cells: CellBuffer,
    scan: ScanConverter,
    no_scan: Vec<Vector2<f64>>,
    /// The hand has a palm cell facing along the end effector's z axis ([`HandForceMap`]): a
    /// force reference means something.
    hand_senses_force: bool,
    arms: Vec<ArmCommand>,
    needs_odom: bool,
    needs_cells: bool,
    /// The stamp of the last joint state message that wrote a joint.
    joint_msg_stamp: Option<Time>,
    /// The buffer of [`Self::on_cells_cdr`].
    cdr_cells: CdrCells,
    last_cycle: Option<Time>,
    arm_msgs: Vec<Float64MultiArray>,
    twist: Twist,
    state_msg: ControllerState,
    /// Mode, switch time and blocked hold of the last arrangement followed (for the log).
    followed: Option<(Mode, f64, bool)>,
    cycles: u64,
    faults: u64,
    health: Health,
}

impl TaskController {
    /// A controller from `config` with `params` laid over it (skin, tasks), at time `t0_s`.
    pub fn new(mut config: ControllerConfig, params: TaskControllerParams, t0_s: f64) -> Result<Self, String> {
        params.validate()?;
        config.skin = params.skin;
        config.tasks = params.tasks.clone();
        let hand_senses_force = HandForceMap::new(&config).is_some();
        let controller = Controller::new(config, t0_s).map_err(|e| e.to_string())?;
        let cfg = controller.config();
        let model = &cfg.model;
        let arms = split_arms(
            model.joint_names(),
            controller.resolver().arm_joints(),
            &params.arms.namespaces,
            &params.arms.joint_prefixes,
        )?;
        let state = StateBuffer::new(model);
        let scan = ScanConverter::new(model);
        Ok(TaskController {
            needs_odom: state.base().is_some(),
            needs_cells: cfg.layout.num_cells() > 0,
            cells: CellBuffer::new(&cfg.layout),
            cdr_cells: CdrCells::default(),
            arm_msgs: arms
                .iter()
                .map(|a| {
                    let mut m = Float64MultiArray::default();
                    write_arm_command(a, &[], &mut m);
                    m
                })
                .collect(),
            twist: Twist::default(),
            state_msg: ControllerState::default(),
            followed: None,
            state,
            scan,
            no_scan: Vec::new(),
            hand_senses_force,
            arms,
            joint_msg_stamp: None,
            last_cycle: None,
            cycles: 0,
            faults: 0,
            health: Health::new(),
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

    /// Takes the run-time settable keys (the timeouts, `max_stamp_lead_s`) from `p`, the values
    /// the parameter server holds now.
    pub fn take_settable(&mut self, p: &TaskControllerParams) {
        let q = &mut self.params;
        (q.input_timeout_s, q.odom_timeout_s, q.cells_timeout_s, q.scan_timeout_s) =
            (p.input_timeout_s, p.odom_timeout_s, p.cells_timeout_s, p.scan_timeout_s);
        q.max_stamp_lead_s = p.max_stamp_lead_s;
    }

    /// Zeros were sent on the command topics by someone else (the watchdog): the next command
    /// continues from zero within the acceleration limits ([`Controller::restart_from_zero`]).
    pub fn restart_from_zero(&mut self) {
        self.controller.restart_from_zero();
    }

    /// Every input issue counted so far (also in `/controller/state`).
    pub fn issues(&self) -> &IssueTable {
        &self.health.table
    }

    /// Control periods without a cycle (waiting or stale inputs).
    pub fn idle_periods(&self) -> u64 {
        self.health.idle_periods
    }

    /// The clock the stamp checks compare with: the node's in timer mode; none in inputs mode
    /// (lockstep: the stamps are the simulation's and only their order is checked).
    fn clock(&self, now_s: f64) -> Option<f64> {
        (self.params.trigger == Trigger::Timer).then_some(now_s)
    }

    /// `/joint_states` at node time `now_s`; `report` gets the first issue of each kind (all are
    /// counted). Each joint is written only with finite values and a stamp not older than its
    /// own; a message that writes no joint because of its stamp is refused.
    pub fn on_joint_states(
        &mut self,
        msg: &JointState,
        now_s: f64,
        mut report: impl FnMut(&JointStateIssue),
    ) -> Result<(), InputError> {
        let lead = self.params.max_stamp_lead_s;
        let clock = self.clock(now_s);
        let stamp = &msg.header.stamp;
        self.health.check_stamp(Timed::Joints, stamp, clock, lead)?;
        let (table, first) = (&mut self.health.table, self.health.joint_kinds);
        let mut out_of_order = 0;
        let written = self.state.update_joints(msg, clock.map_or(f64::INFINITY, |n| n + lead), |i| {
            out_of_order += usize::from(i.kind == JointIssue::OutOfOrder);
            if table.count(first + i.kind as usize) {
                report(i);
            }
        });
        if written > 0 {
            self.joint_msg_stamp = Some(stamp.clone());
        }
        if out_of_order > 0 {
            let e = self.health.stamp_issue(Timed::Joints, StampIssue::OutOfOrder, stamp, clock);
            if written == 0 {
                return Err(e);
            }
        }
        Ok(())
    }

    /// `/base/odom` at node time `now_s`.
    pub fn on_odometry(&mut self, msg: &Odometry, now_s: f64) -> Result<(), InputError> {
        let lead = self.params.max_stamp_lead_s;
        self.health.check_stamp(Timed::Odometry, &msg.header.stamp, self.clock(now_s), lead)?;
        self.state.update_odometry(msg).map_err(self.health.refuse(ODOM))?;
        self.health.accept(Timed::Odometry, &msg.header.stamp);
        Ok(())
    }

    /// `/skin/cells` at node time `now_s`; `report` gets the first issue of each kind.
    pub fn on_cells(
        &mut self,
        msg: &impl CellMessage,
        now_s: f64,
        mut report: impl FnMut(&Issue),
    ) -> Result<(), InputError> {
        let lead = self.params.max_stamp_lead_s;
        let stamp = msg.stamp();
        self.health.check_stamp(Timed::Cells, &stamp, self.clock(now_s), lead)?;
        let (table, first) = (&mut self.health.table, self.health.cell_kinds);
        let read = update_cells(&mut self.cells, &self.controller.config().layout, msg, |i| {
            if table.count(first + i.kind as usize) {
                report(i);
            }
        });
        read.map_err(self.health.refuse(CELLS))?;
        self.health.accept(Timed::Cells, &stamp);
        Ok(())
    }

    /// `/skin/cells` as serialized bytes (`Node::subscribe_raw`: [`CdrCells`]), else as
    /// [`Self::on_cells`]; bytes that are no `SkinCellArray` are refused.
    pub fn on_cells_cdr(&mut self, data: &[u8], now_s: f64, report: impl FnMut(&Issue)) -> Result<(), InputError> {
        let mut cdr = std::mem::take(&mut self.cdr_cells);
        let result = match cdr.parse(data) {
            Ok(()) => self.on_cells(&cdr, now_s, report),
            Err(e) => Err(self.health.refuse(CELLS)(e)),
        };
        self.cdr_cells = cdr;
        result
    }

    /// `/scan` at node time `now_s`.
    pub fn on_scan(&mut self, msg: &LaserScan, now_s: f64) -> Result<(), InputError> {
        let lead = self.params.max_stamp_lead_s;
        self.health.check_stamp(Timed::Scan, &msg.header.stamp, self.clock(now_s), lead)?;
        // a refused scan leaves no points (nothing seen) and does not refresh the input
        self.scan.update(msg).map_err(self.health.refuse(SCAN))?;
        self.health.accept(Timed::Scan, &msg.header.stamp);
        Ok(())
    }

    /// `/goal`: the end-effector goal in the frame `header.frame_id` names: `world` or `odom`
    /// (the same frame here: the base joints are the odometry pose), or any link of the URDF
    /// (`base_link`, a hand, ...), taken at the measured state when the goal arrives. Any other
    /// frame is refused (and counted).
    pub fn on_goal(&mut self, msg: &PoseStamped) -> Result<(), InputError> {
        let pose = goal_pose(msg).map_err(self.health.refuse(GOAL))?;
        let frame = self.frame_in_world(&msg.header.frame_id).map_err(self.health.refuse(GOAL))?;
        self.controller.set_goal(Some(frame * pose)).map_err(|f| self.health.refuse(GOAL)(f.to_string()))
    }

    /// The world pose of frame `name` at the measured state.
    fn frame_in_world(&self, name: &str) -> Result<Isometry3<f64>, String> {
        if name == WORLD_FRAME || name == ODOM_FRAME {
            return Ok(Isometry3::identity());
        }
        let model = &self.controller.config().model;
        let Some(frame) = model.frame_index(name) else {
            return Err(format!(
                "header.frame_id `{name}`: not {WORLD_FRAME}, {ODOM_FRAME} or a link of the robot's URDF"
            ));
        };
        if !self.state.complete() {
            let missing = self.missing().join(", ");
            return Err(format!(
                "header.frame_id `{name}`: the robot's state is not known yet (waiting for {missing})"
            ));
        }
        let mut data = ModelData::new(model);
        update_kinematics(model, &mut data, self.state.q(), self.state.qd())
            .map_err(|e| format!("header.frame_id `{name}`: {e}"))?;
        Ok(*frame_pose(&data, frame))
    }

    /// The hand force reference `f_c,d` of interactive-force-control paper eq. (9) \[N\] (the
    /// hand cells' measured newtons, `skin_core::skin::measured`). Refused without a palm cell
    /// facing along the end effector's z axis.
    pub fn on_force_reference(&mut self, force_n: f64) -> Result<(), InputError> {
        if !self.hand_senses_force {
            let why = "the controller setup's hand_patches have no cell facing along the end effector's z axis";
            return Err(self.health.refuse(FORCE_REFERENCE)(why.into()));
        };
        if !(force_n.is_finite() && force_n >= 0.0) {
            return Err(self.health.refuse(FORCE_REFERENCE)(format!("data = {force_n}: must be finite and >= 0 N")));
        }
        self.controller
            .set_hand_force_reference(force_n)
            .map_err(|f| self.health.refuse(FORCE_REFERENCE)(f.to_string()))
    }

    /// `/supervisor/arrangement` (ignored with `supervisor: internal`). Returns what a log should
    /// say: a switch, or a blocked hold beginning or ending (not the sensing-range steps, which
    /// republish the arrangement every cycle of a ramp).
    pub fn on_arrangement(&mut self, msg: &ArrangementMsg) -> Result<Option<String>, InputError> {
        if self.params.supervisor == SupervisorSource::Internal {
            return Ok(None);
        }
        let configured = |mode: Mode| -> Vec<String> {
            let params = &self.controller.config().supervisor;
            let names = params.arrangements.by_mode();
            names[mode as usize].1.to_vec()
        };
        let imposed = imposed_of(msg, configured).map_err(self.health.refuse(ARRANGEMENT))?;
        self.controller.impose_arrangement(imposed).map_err(|e| self.health.refuse(ARRANGEMENT)(e.to_string()))?;
        let now = (imposed.mode, imposed.switch_time_s, imposed.blocked.is_some());
        let before = self.followed.replace(now);
        let mut notes = Vec::new();
        if before.map(|(m, t, _)| (m, t)) != Some((now.0, now.1)) {
            notes.push(format!("following mode {} {:?}", msg.mode, msg.task_order));
        }
        match (before.is_some_and(|b| b.2), imposed.blocked) {
            (false, Some(b)) => notes.push(format!("blocked: {b}")),
            (true, None) => notes.push("the blocked hold ended".to_string()),
            _ => {}
        }
        Ok((!notes.is_empty()).then(|| notes.join("; ")))
    }

    /// The required inputs that have not arrived yet (empty: complete).
    pub fn missing(&self) -> Vec<String> {
        let mut m: Vec<String> =
            self.state.missing().filter(|n| !is_base_joint_name(n)).map(|n| format!("joint `{n}`")).collect();
        if self.needs_odom && self.state.odom_time().is_none() {
            m.push("odometry".into());
        }
        if self.needs_cells && self.health.last(Timed::Cells).is_none() {
            m.push("skin cells".into());
        }
        if self.params.use_scan && self.health.last(Timed::Scan).is_none() {
            m.push("scan".into());
        }
        m
    }

    /// The required inputs' times \[s\] (joint states: oldest and newest joint) with their topic
    /// and timeout; None when one has not arrived.
    fn times(&self) -> Option<impl Iterator<Item = (&'static str, f64, f64)> + '_> {
        let (lo, hi) = self.state.joint_times()?;
        let p = &self.params;
        let required = [
            Some((JOINT_STATES, Some(lo), p.input_timeout_s)),
            Some((JOINT_STATES, Some(hi), p.input_timeout_s)),
            self.needs_odom.then(|| (ODOM, self.state.odom_time(), p.odom_timeout_s)),
            self.needs_cells.then(|| (CELLS, self.health.last(Timed::Cells), p.cells_timeout_s)),
            p.use_scan.then(|| (SCAN, self.health.last(Timed::Scan), p.scan_timeout_s)),
        ];
        if required.iter().flatten().any(|(_, t, _)| t.is_none()) {
            return None;
        }
        Some(required.into_iter().flatten().map(|(topic, t, timeout)| (topic, t.unwrap_or(f64::NAN), timeout)))
    }

    /// Every required input's age at `now_s` (the node's clock), in the order joint states,
    /// odometry, skin cells, scan.
    pub fn input_ages(&self, now_s: f64) -> Vec<InputAge> {
        let p = &self.params;
        let age = |t: Option<f64>| t.map(|t| now_s - t);
        let joints = match self.state.oldest_joint() {
            Some((name, t)) => InputAge {
                topic: JOINT_STATES,
                age_s: Some(now_s - t),
                timeout_s: p.input_timeout_s,
                detail: Some(format!("oldest joint `{name}`")),
            },
            None => {
                let missing: Vec<&str> = self.state.missing().filter(|n| !is_base_joint_name(n)).collect();
                InputAge {
                    topic: JOINT_STATES,
                    age_s: None,
                    timeout_s: p.input_timeout_s,
                    detail: Some(format!("no value yet of joint `{}`", missing.join("`, `"))),
                }
            }
        };
        let others = [
            self.needs_odom.then(|| (ODOM, self.state.odom_time(), p.odom_timeout_s)),
            self.needs_cells.then(|| (CELLS, self.health.last(Timed::Cells), p.cells_timeout_s)),
            p.use_scan.then(|| (SCAN, self.health.last(Timed::Scan), p.scan_timeout_s)),
        ];
        let others = others.into_iter().flatten();
        std::iter::once(joints)
            .chain(others.map(|(topic, t, timeout_s)| InputAge { topic, age_s: age(t), timeout_s, detail: None }))
            .collect()
    }

    /// Trigger `inputs`: the common stamp of a complete input set that is newer than the last
    /// cycle, if there is one now (every joint, and every other required input, at one stamp).
    pub fn ready_stamp(&self) -> Option<Time> {
        let stamp = self.joint_msg_stamp.as_ref()?;
        let t = time_s(stamp);
        let common = self.times()?.all(|(_, s, _)| s == t);
        let newer = self.last_cycle.as_ref().is_none_or(|l| t > time_s(l));
        (common && newer).then(|| stamp.clone())
    }

    /// Trigger `timer`: whether every required input is fresh at `now_s`: each input's age
    /// (every joint's, for joint states) within `[-max_stamp_lead_s, its timeout]`.
    pub fn freshness(&self, now_s: f64) -> Freshness {
        let Some(mut times) = self.times() else {
            return Freshness::Waiting;
        };
        let lead = self.params.max_stamp_lead_s;
        match times.find(|&(_, t, timeout)| !fresh(now_s - t, timeout, lead)) {
            None => Freshness::Fresh,
            Some((input, t, timeout_s)) => Freshness::Stale { input, age_s: now_s - t, timeout_s },
        }
    }

    /// Trigger `inputs`: takes `stamp` as the last cycle's without a cycle (a holding period).
    pub fn mark_cycle(&mut self, stamp: &Time) {
        self.last_cycle = Some(stamp.clone());
    }

    /// Zero commands on every output, no controller state: the last messages at shutdown.
    pub fn zero_outputs(&mut self) -> Outputs<'_> {
        for (a, m) in self.arms.iter().zip(&mut self.arm_msgs) {
            write_arm_command(a, &[], m);
        }
        self.twist = twist_msg([0.0; 3]);
        Outputs { arms: &self.arm_msgs, base: self.needs_odom.then_some(&self.twist), state: None }
    }

    /// A period without a cycle (`why`): the commands ramp towards zero within the acceleration
    /// limits (`Controller::idle`; zero before the first cycle); the state keeps the last cycle's
    /// values with the input status and counters of now.
    pub fn idle_outputs(&mut self, why: Idle, stamp: &Time) -> Outputs<'_> {
        self.health.idle_periods += 1;
        let c = self.controller.idle(1.0 / self.params.control_rate_hz);
        for (a, m) in self.arms.iter().zip(&mut self.arm_msgs) {
            write_arm_command(a, &c.joint_velocities, m);
        }
        self.twist = twist_msg(c.base_twist);
        self.state_msg.header.stamp = stamp.clone();
        self.state_msg.input_status = match why {
            Idle::Waiting => ControllerState::INPUT_WAITING as u8,
            Idle::Stale => ControllerState::INPUT_STALE as u8,
        };
        self.write_health();
        Outputs { arms: &self.arm_msgs, base: self.needs_odom.then_some(&self.twist), state: Some(&self.state_msg) }
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
        write_controller_state(
            c.output(),
            sup.tasks(),
            sup.arrangement().task_order(),
            c.level_diagnostics(),
            stamp,
            &mut self.state_msg,
        );
        self.state_msg.input_status = ControllerState::INPUT_FRESH as u8;
        self.write_health();
        self.last_cycle = Some(stamp.clone());
        Outputs { arms: &self.arm_msgs, base: self.needs_odom.then_some(&self.twist), state: Some(&self.state_msg) }
    }

    fn write_health(&mut self) {
        self.state_msg.safe_stop_cycles = self.faults;
        self.state_msg.idle_periods = self.health.idle_periods;
        self.health.table.write(&mut self.state_msg);
    }

    /// The fault text of the last cycle, if it was a safe-stop step.
    pub fn last_fault(&self) -> Option<String> {
        self.controller.output().fault.map(|f| f.to_string())
    }
}

#[cfg(test)]
mod tests;
