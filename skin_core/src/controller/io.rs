//! What goes into and comes out of one control cycle.

use nalgebra::Vector2;

use crate::resolver::Commands;
use crate::skin::signals::CellReading;
use crate::supervisor::{Blocked, Mode, SupervisorInput};

/// The measurements of one cycle. Vectors are in model joint order (`RobotModel::joint_names`),
/// cells in layout order (`ResolvedLayout::cells`).
#[derive(Debug, Clone, Copy)]
pub struct ControllerInput<'a> {
    /// Time of the measurements \[s\] (simulation or ROS time; should not decrease).
    pub t_s: f64,
    /// Time since the previous cycle \[s\] (the resolver's integration step).
    pub dt_s: f64,
    /// Measured joint positions (base joints: world x, y \[m\], yaw \[rad\]).
    pub q: &'a [f64],
    /// Measured joint velocities.
    pub qd: &'a [f64],
    /// One reading per skin cell.
    pub cells: &'a [CellReading],
    /// Laser points in the base frame \[m\] (empty: nothing seen).
    pub scan: &'a [Vector2<f64>],
}

/// Why a cycle fell back to the safe stop (commands ramp to zero within the acceleration
/// limits). `Copy`, so reporting it allocates nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// An input vector has the wrong length.
    Length {
        /// `q`, `qd` or `cells`.
        input: &'static str,
        /// Expected length.
        expected: usize,
        /// Given length.
        got: usize,
    },
    /// A joint position or velocity is NaN or infinite.
    NonFinite {
        /// `q` or `qd`.
        input: &'static str,
        /// Joint index.
        index: usize,
    },
    /// `dt_s` is not a positive finite number.
    BadTimeStep,
    /// A stage failed (kinematics, a task, the solver, the resolver); the stage is named.
    Stage(&'static str),
}

impl std::fmt::Display for Fault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Fault::Length { input, expected, got } => write!(f, "`{input}` has length {got}, expected {expected}"),
            Fault::NonFinite { input, index } => write!(f, "`{input}[{index}]` is not finite"),
            Fault::BadTimeStep => write!(f, "`dt_s` is not a positive finite number"),
            Fault::Stage(stage) => write!(f, "{stage} failed"),
        }
    }
}

/// The result of one cycle (what `ControllerState.msg` and the command topics carry).
#[derive(Debug, Clone, PartialEq)]
pub struct ControllerOutput {
    /// The velocity commands to send (always finite and within the limits).
    pub commands: Commands,
    /// `None` when the control law ran; otherwise why this cycle is a safe-stop step.
    pub fault: Option<Fault>,
    /// The active arrangement's mode.
    pub mode: Mode,
    /// Why the arm holds in (a) instead of pushing again: a push in intentional contact reached
    /// `ε_c` (`None`: not blocked); `ControllerState.blocked`.
    pub blocked: Option<Blocked>,
    /// Goals set since start ([`crate::controller::Controller::set_goal`] with a changed goal): a
    /// change tells a deciding supervisor of a new goal, which ends its [`Blocked`] hold.
    pub goal_count: u32,
    /// Nothing is to be pressed: in a hard contact (c) and in the blocked hold after a push given
    /// up ([`crate::supervisor::Supervisor::releasing`]).
    pub releasing: bool,
    /// `χ` of intentional-contact paper eq. (10)-(11): the weight of the previous arrangement's torque (0: no
    /// blend in progress).
    pub blend: f64,
    /// Fusion weight `w(t)` of interactive-force-control paper eq. (6) the skin was fused with this cycle.
    pub fusion_weight: f64,
    /// The signals the supervisor decided on (ee speed, `‖F_d‖` at the nominal range, `‖F_c‖`,
    /// goal error; the goal error is NaN without a goal).
    pub signals: SupervisorInput,
    /// `‖τ*‖` of the blended torque \[N m\].
    pub torque_norm: f64,
    /// `ʰΓ` of interactive-force-control paper eq. (10): the hand patches' summed moment in the hand frame `{h}`
    /// (normalized-signal units times metres, like the patch wrenches of eq. 8); zero without hand
    /// patches. What the compliant wrist drives to zero (interactive-force-control paper Fig. 6b, 7b).
    pub hand_moment: nalgebra::Vector3<f64>,
}
