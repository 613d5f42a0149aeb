//! The one interface every task implements: built once from its parameters, then each cycle it
//! reads one [`Cycle`] and writes its part of the control law (the rows of its level, or a term
//! of the posture torque of interactive-force-control paper eq. 18). `docs/tasks.md` shows how to
//! add one.

use nalgebra::{DVector, Isometry3, Vector2, Vector3};

use super::error::TaskError;
use super::params::TaskParams;
use crate::hierarchy::TaskLevel;
use crate::model::{ModelData, RobotModel};
use crate::skin::aggregate::PatchWrench;
use crate::skin::layout::ResolvedLayout;
use crate::skin::live::LiveCells;
use crate::skin::params::SkinParams;

/// A commanded base pose and velocity at one instant: the moving `q_d`, `q̇_d` of the base joints
/// (world x, y \[m\], yaw \[rad\], as the base joints measure them; yaw unwrapped like the joint).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BaseReference {
    /// `q_d` of base x, y, yaw.
    pub position: [f64; 3],
    /// `q̇_d` of base x, y, yaw (world frame) \[m/s, rad/s\].
    pub velocity: [f64; 3],
}

impl BaseReference {
    /// Index of the first non-finite value (positions 0-2, velocities 3-5), if any.
    pub fn non_finite(&self) -> Option<usize> {
        self.position.iter().chain(&self.velocity).position(|v| !v.is_finite())
    }
}

/// Where a task acts in the control law.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// A level of the hierarchy (interactive-force-control paper eq. 19-25) with at most this many rows.
    Level(Rows),
    /// A term of `τ_s` in eq. (18), added up over the arrangement's terms and subtracted from the
    /// joint compliance in the null space of every level.
    PostureTerm,
    /// The joint compliance `−K_c (q − q_post) − D_c q̇` of eq. (18) itself.
    Posture,
}

/// The most rows a level can need.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rows {
    /// A fixed number (a point task: 1 or 3).
    Fixed(usize),
    /// One per skin cell of the layout.
    PerCell,
}

impl Role {
    /// The rows of its level on a layout of `cells` cells (0 for a torque).
    pub fn max_rows(self, cells: usize) -> usize {
        match self {
            Role::Level(Rows::Fixed(n)) => n,
            Role::Level(Rows::PerCell) => cells,
            Role::PostureTerm | Role::Posture => 0,
        }
    }

    /// Whether it is a level of the hierarchy.
    pub fn is_level(self) -> bool {
        matches!(self, Role::Level(_))
    }
}

/// What a task is built from (once, when the controller is set up).
#[derive(Debug, Clone, Copy)]
pub struct TaskSetup<'a> {
    /// The robot.
    pub model: &'a RobotModel,
    /// Every task's parameters (`config/tasks.yaml`).
    pub params: &'a TaskParams,
    /// The skin's characteristics.
    pub skin: &'a SkinParams,
    /// End-effector / hand frame index.
    pub end_effector: usize,
    /// Model indices of the mobile base's x, y, yaw joints, if the robot has one.
    pub base_joints: Option<[usize; 3]>,
    /// Desired posture `q_post` of eq. (18), model joint order.
    pub posture: &'a [f64],
}

/// The hand moments the wrist reads in one cycle.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct WristMoments {
    /// `Γ_p`: the hand patches' moment of the proximity signals (eq. 8), world axes.
    pub proximity_world: Vector3<f64>,
    /// `Γ_F`: the hand patches' moment of the pressed cells' newtons \[N m\], world axes.
    pub force_world_nm: Vector3<f64>,
    /// `w` of eq. (6) this cycle (0: proximity only, 1: force only).
    pub fusion_weight: f64,
}

/// The skin-derived signals of one cycle that the hand, wrist and guidance tasks read.
#[derive(Debug, Clone, Copy, Default)]
pub struct HandSignals {
    /// `F = Σ_i c_i F_i`: the pressed hand cells' newtons along the hand's z axis, eq. (9)'s
    /// `f_c` in newtons (`skin::measured`).
    pub force_n: f64,
    /// Eq. (9)'s `f_c,d` \[N\]: the controller's force reference.
    pub force_reference_n: f64,
    /// Largest proximity signal of the hand patches.
    pub proximity: f64,
    /// Summed moment of the hand patches' fused signals (eq. 8), world axes (recorded as
    /// `ControllerOutput::hand_moment`).
    pub moment_world: Vector3<f64>,
    /// The moments eq. (10)'s compliant wrist drives to zero, per modality.
    pub wrist: WristMoments,
    /// Guidance patches' summed force in the hand frame (eq. 11's `h_F`).
    pub guidance_force: Vector3<f64>,
}

/// Everything a task may read in one control cycle (kinematics already updated).
#[derive(Debug, Clone, Copy)]
pub struct Cycle<'a> {
    /// The robot.
    pub model: &'a RobotModel,
    /// Its kinematics at the measured state.
    pub data: &'a ModelData,
    /// The skin layout, resolved on the model.
    pub layout: &'a ResolvedLayout,
    /// The skin's characteristics and the fusion weight of this cycle's arrangement.
    pub skin: &'a SkinParams,
    /// The non-silent cells of this cycle's readings.
    pub cells: &'a LiveCells,
    /// This cycle's patch wrenches (layout patch order).
    pub wrenches: &'a [PatchWrench],
    /// Patches that are not hand patches: the body of eq. (13)-(14).
    pub body_patches: &'a [bool],
    /// Hand and guidance signals of eq. (9)-(11).
    pub hand: HandSignals,
    /// The end-effector goal, if any.
    pub goal: Option<&'a Isometry3<f64>>,
    /// The arrangement's proximity sensing range \[m\].
    pub sensing_range_m: f64,
    /// The LIDAR points in the base frame \[m\].
    pub scan: &'a [Vector2<f64>],
    /// The commanded base motion with the base joints' model indices.
    pub base_reference: Option<([usize; 3], BaseReference)>,
    /// The control period of this cycle \[s\].
    pub dt_s: f64,
}

/// A task of the control law. Built once ([`Task::build`]), updated every cycle the active
/// arrangement names it, without allocating.
pub trait Task: std::fmt::Debug + Send + Sync {
    /// Its name in `config/supervisor.yaml`'s `tasks` list.
    fn name() -> &'static str
    where
        Self: Sized;

    /// Where it acts (known before it is built: the solver is sized from it).
    fn role() -> Role
    where
        Self: Sized;

    /// Builds it for one controller.
    fn build(setup: &TaskSetup) -> Result<Self, TaskError>
    where
        Self: Sized;

    /// [`Role::Level`]: this cycle's rows into `level` (cleared before).
    fn fill(&mut self, _cx: &Cycle, _level: &mut TaskLevel) -> Result<(), TaskError> {
        Ok(())
    }

    /// [`Role::PostureTerm`]: adds its term to `τ_s`; [`Role::Posture`]: writes the joint
    /// compliance into `tau`.
    fn torque(&mut self, _cx: &Cycle, _tau: &mut DVector<f64>) -> Result<(), TaskError> {
        Ok(())
    }

    /// The arrangement switched at this state (interactive-force-control paper Table 1: the
    /// position hold captures `x_ef,init`).
    fn on_switch(&mut self, _data: &ModelData) {}
}

/// A task by name: how to build it and where it acts.
#[derive(Clone, Copy)]
pub struct TaskEntry {
    /// Configuration name.
    pub name: &'static str,
    /// Where it acts.
    pub role: Role,
    /// Builds it.
    pub build: fn(&TaskSetup) -> Result<Box<dyn Task>, TaskError>,
}

impl std::fmt::Debug for TaskEntry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TaskEntry").field("name", &self.name).field("role", &self.role).finish()
    }
}

fn boxed<T: Task + 'static>(setup: &TaskSetup) -> Result<Box<dyn Task>, TaskError> {
    Ok(Box::new(T::build(setup)?))
}

/// The registry entry of task type `T`.
pub fn entry<T: Task + 'static>() -> TaskEntry {
    TaskEntry { name: T::name(), role: T::role(), build: boxed::<T> }
}
