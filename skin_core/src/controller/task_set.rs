//! The tasks a controller knows, by the names the supervisor's arrangements use, and how each
//! fills its level (or its part of the posture torque) from one cycle's signals.

use nalgebra::{Isometry3, Vector2, Vector3};

use super::setup::{ControllerConfig, SetupError};
use crate::hierarchy::TaskLevel;
use crate::model::{ModelData, RobotModel};
use crate::resolver::BASE_JOINTS;
use crate::skin::aggregate::PatchWrench;
use crate::skin::live::LiveCells;
use crate::tasks::avoidance::ProximityAvoidance;
use crate::tasks::base_avoidance::BaseAvoidance;
use crate::tasks::contact_reaction::ContactReaction;
use crate::tasks::goal::{GoalOrientation, GoalPosition};
use crate::tasks::hand_force::{HandForce, HandMeasurement};
use crate::tasks::position_hold::PositionHold;
use crate::tasks::posture::Posture;
use crate::tasks::tactile_guidance::TactileGuidance;
use crate::tasks::wrist::CompliantWrist;
use crate::tasks::TaskError;

/// A task name of `config/supervisor.yaml`'s `tasks` list and what it does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TaskKind {
    /// `avoidance`: intentional-contact paper eq. (3)-(4), force rows per cell in range.
    Avoidance,
    /// `goal`: intentional-contact paper eq. (7)-(9), end-effector position.
    Goal,
    /// `goal_orientation`: the second goal task of intentional-contact paper Sec. V (end-effector orientation).
    GoalOrientation,
    /// `contact_reaction`: intentional-contact paper eq. (6), force rows per contact cell.
    ContactReaction,
    /// `hand_distance`: interactive-force-control paper eq. (9) on the hand's proximity (approach).
    HandDistance,
    /// `hand_force`: interactive-force-control paper eq. (9) on the fused hand signal (contact).
    HandForce,
    /// `wrist`: interactive-force-control paper eq. (10).
    Wrist,
    /// `tactile_guidance`: interactive-force-control paper eq. (11)-(12).
    TactileGuidance,
    /// `position_hold`: interactive-force-control paper Table 1, `x_d = x_ef,init` captured at the switch.
    PositionHold,
    /// `base_avoidance`: interactive-force-control paper eq. (15)-(17), `τ_oca` in the posture torque.
    BaseAvoidance,
    /// `compliance`: interactive-force-control paper eq. (13)-(14), the body skin torque in the posture torque.
    Compliance,
    /// `posture`: interactive-force-control paper eq. (18), joint compliance toward `q_post`.
    Posture,
}

impl TaskKind {
    /// Every kind with its configuration name.
    pub const ALL: [(&'static str, TaskKind); 12] = [
        ("avoidance", TaskKind::Avoidance),
        ("goal", TaskKind::Goal),
        ("goal_orientation", TaskKind::GoalOrientation),
        ("contact_reaction", TaskKind::ContactReaction),
        ("hand_distance", TaskKind::HandDistance),
        ("hand_force", TaskKind::HandForce),
        ("wrist", TaskKind::Wrist),
        ("tactile_guidance", TaskKind::TactileGuidance),
        ("position_hold", TaskKind::PositionHold),
        ("base_avoidance", TaskKind::BaseAvoidance),
        ("compliance", TaskKind::Compliance),
        ("posture", TaskKind::Posture),
    ];

    /// The kind of a configured task name.
    pub fn from_name(name: &str) -> Option<TaskKind> {
        Self::ALL.iter().find(|(n, _)| *n == name).map(|&(_, k)| k)
    }

    /// Whether the task is a level of the hierarchy (otherwise a term of the posture torque in
    /// the last null space).
    pub fn is_level(self) -> bool {
        !matches!(self, TaskKind::BaseAvoidance | TaskKind::Compliance | TaskKind::Posture)
    }

    /// Rows its level can need on a layout of `cells` cells.
    fn max_rows(self, cells: usize) -> usize {
        match self {
            TaskKind::Avoidance | TaskKind::ContactReaction => cells,
            TaskKind::HandDistance | TaskKind::HandForce => 1,
            TaskKind::BaseAvoidance | TaskKind::Compliance | TaskKind::Posture => 0,
            _ => 3,
        }
    }
}

/// The skin-derived signals of one cycle that the hand, wrist and guidance tasks read.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct HandSignals {
    /// z of the hand patches' summed force in the hand frame (fused signal units).
    pub(crate) fused_force: f64,
    /// Largest proximity signal of the hand patches.
    pub(crate) proximity: f64,
    /// Summed moment of the hand patches, world axes (eq. 10's `Γ`).
    pub(crate) moment_world: Vector3<f64>,
    /// Guidance patches' summed force in the hand frame (eq. 11's `h_F`).
    pub(crate) guidance_force: Vector3<f64>,
}

/// What a cycle passes to [`TaskSet::fill`].
pub(crate) struct CycleContext<'a> {
    pub(crate) model: &'a RobotModel,
    pub(crate) data: &'a ModelData,
    pub(crate) config: &'a ControllerConfig,
    /// The non-silent cells of this cycle's readings.
    pub(crate) cells: &'a LiveCells,
    pub(crate) hand: HandSignals,
    pub(crate) goal: Option<&'a Isometry3<f64>>,
    pub(crate) sensing_range_m: f64,
}

/// One object per task kind (built once, reused every cycle) and one level per configured name.
#[derive(Debug, Clone)]
pub(crate) struct TaskSet {
    /// Kind of each configured task name (supervisor `tasks` order).
    pub(crate) kinds: Vec<TaskKind>,
    /// One level per configured name (torque-only kinds have zero rows).
    pub(crate) levels: Vec<TaskLevel>,
    pub(crate) avoidance: ProximityAvoidance,
    pub(crate) contact: ContactReaction,
    goal: GoalPosition,
    orientation: GoalOrientation,
    hand: HandForce,
    wrist: CompliantWrist,
    guidance: TactileGuidance,
    pub(crate) hold: PositionHold,
    base: Option<BaseAvoidance>,
    pub(crate) posture: Posture,
}

impl TaskSet {
    /// Builds every task for the configured names; `ee` is the end-effector frame index.
    pub(crate) fn new(config: &ControllerConfig, ee: usize) -> Result<Self, SetupError> {
        let model = &config.model;
        let nv = model.nv();
        let p = &config.tasks;
        let kinds = config
            .supervisor
            .tasks
            .iter()
            .enumerate()
            .map(|(i, name)| {
                TaskKind::from_name(name).ok_or_else(|| {
                    let known: Vec<&str> = TaskKind::ALL.iter().map(|(n, _)| *n).collect();
                    SetupError::Invalid {
                        file: config.setup.supervisor.display().to_string(),
                        key: format!("tasks[{i}]"),
                        reason: format!("unknown task `{name}` (known: {})", known.join(", ")),
                    }
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let levels = config
            .supervisor
            .tasks
            .iter()
            .zip(&kinds)
            .map(|(name, k)| TaskLevel::new(name, nv, k.max_rows(config.layout.num_cells())))
            .collect();
        let base_joints = BASE_JOINTS.map(|j| model.joint_index(j));
        let base = match base_joints {
            [Some(x), Some(y), Some(yaw)] => Some(
                BaseAvoidance::new(nv, [x, y, yaw], p.base_avoidance)
                    .map_err(|error| SetupError::Task { file: config.source.clone(), error })?,
            ),
            _ => None,
        };
        let q_post = if config.setup.posture.is_empty() { vec![0.0; nv] } else { config.setup.posture.clone() };
        let mut posture = Posture::new(nv, &p.posture, &q_post)
            .map_err(|error| SetupError::Task { file: config.source.clone(), error })?;
        if let ([Some(x), Some(y), Some(yaw)], Some(gains)) = (base_joints, p.posture.base) {
            posture
                .set_base_gains([x, y, yaw], gains)
                .map_err(|error| SetupError::Task { file: config.source.clone(), error })?;
        }
        let zero = Vector3::zeros();
        Ok(TaskSet {
            kinds,
            levels,
            avoidance: ProximityAvoidance::new(nv, p.avoidance),
            contact: ContactReaction::new(nv, p.contact_reaction, &config.skin.force),
            goal: GoalPosition::new(nv, ee, zero, p.goal),
            orientation: GoalOrientation::new(nv, ee, p.goal_orientation),
            hand: HandForce::new(nv, ee, p.hand_force),
            wrist: CompliantWrist::new(nv, ee, p.wrist),
            guidance: TactileGuidance::new(nv, ee, p.tactile_guidance),
            hold: PositionHold::new(nv, ee, zero, p.position_hold),
            base,
            posture,
        })
    }

    /// Sets `f_c,d` of the hand force task (interactive-force-control paper eq. 9), in signal units.
    pub(crate) fn set_hand_force_reference(&mut self, signal: f64) {
        self.hand.params.force_signal_desired = signal;
    }

    /// Fills the level of configured task `index` for this cycle. Torque-only kinds and goals
    /// without a goal leave it empty.
    pub(crate) fn fill(&mut self, index: usize, cx: &CycleContext) -> Result<(), TaskError> {
        let (model, data) = (cx.model, cx.data);
        let skin = &cx.config.skin;
        let level = &mut self.levels[index];
        level.clear();
        match self.kinds[index] {
            TaskKind::Avoidance => {
                let layout = &cx.config.layout;
                self.avoidance.update(model, data, layout, cx.cells, cx.sensing_range_m, level)?;
            }
            TaskKind::ContactReaction => {
                let layout = &cx.config.layout;
                self.contact.update(model, data, layout, cx.cells, &skin.fusion, level)?;
            }
            TaskKind::Goal => {
                if let Some(goal) = cx.goal {
                    self.goal.update(model, data, &goal.translation.vector, level)?;
                }
            }
            TaskKind::GoalOrientation => {
                if let Some(goal) = cx.goal {
                    self.orientation.update(model, data, &goal.rotation, level)?;
                }
            }
            TaskKind::HandDistance => {
                let m = HandMeasurement::Distance { proximity_signal: cx.hand.proximity };
                self.hand.update(model, data, m, cx.hand.proximity, &skin.proximity, level)?;
            }
            TaskKind::HandForce => {
                let m = HandMeasurement::Force { fused_signal: cx.hand.fused_force };
                self.hand.update(model, data, m, cx.hand.proximity, &skin.proximity, level)?;
            }
            TaskKind::Wrist => {
                self.wrist.update(model, data, &cx.hand.moment_world, level)?;
            }
            TaskKind::TactileGuidance => {
                self.guidance.update(model, data, &cx.hand.guidance_force, level)?;
            }
            TaskKind::PositionHold => {
                self.hold.update(model, data, level)?;
            }
            TaskKind::BaseAvoidance | TaskKind::Compliance | TaskKind::Posture => {}
        }
        Ok(())
    }

    /// Computes the posture torque `τ_c*` of eq. (18) (read it from `self.posture.torque()`)
    /// with the terms the arrangement `order` names (`posture`, `compliance` over the patches of
    /// `body`, `base_avoidance` from `scan`); `false` when it names none of them.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn posture_torque(
        &mut self,
        order: &[usize],
        model: &RobotModel,
        data: &ModelData,
        config: &ControllerConfig,
        wrenches: &[PatchWrench],
        body: &[bool],
        scan: &[Vector2<f64>],
    ) -> Result<bool, TaskError> {
        let has = |k: TaskKind| order.iter().any(|&i| self.kinds[i] == k);
        let (joint, skin, oca) = (has(TaskKind::Posture), has(TaskKind::Compliance), has(TaskKind::BaseAvoidance));
        if !(joint || skin || oca) {
            return Ok(false);
        }
        let tau_oca = match (&mut self.base, oca) {
            (Some(base), true) => {
                base.update(data.q(), scan)?;
                Some(base.torque())
            }
            _ => None,
        };
        let include = |j: usize| skin && body[j];
        self.posture.update(model, data, &config.layout, wrenches, include, tau_oca, joint)?;
        Ok(true)
    }
}
