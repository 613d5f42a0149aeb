//! The supervisor's inputs and outputs, mirroring `skin_msgs/msg/Arrangement.msg`.

use thiserror::Error;

/// The active arrangement; the discriminants are the `MODE_*` constants of `Arrangement.msg`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Mode {
    /// Intentional-contact paper Table I (a): avoidance > goal > contact reaction (transitory phases).
    Avoidance = 0,
    /// Intentional-contact paper Table I (b): goal > contact reaction > avoidance (intentional contact).
    IntentionalContact = 1,
    /// Intentional-contact paper Table I (c): contact reaction > goal > avoidance (hard contact).
    HardContact = 2,
    /// Interactive-force-control paper Table 1, precontact phase.
    PreContact = 3,
    /// Interactive-force-control paper Table 1, contact phase.
    Contact = 4,
}

impl Mode {
    /// The mode's name as in `config/supervisor.yaml`'s arrangements.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Avoidance => "avoidance",
            Mode::IntentionalContact => "intentional_contact",
            Mode::HardContact => "hard_contact",
            Mode::PreContact => "precontact",
            Mode::Contact => "contact",
        }
    }
}

impl Mode {
    /// All modes, in discriminant order.
    pub const ALL: [Mode; 5] =
        [Mode::Avoidance, Mode::IntentionalContact, Mode::HardContact, Mode::PreContact, Mode::Contact];

    /// The `Arrangement.msg` mode constant.
    pub fn as_u8(self) -> u8 {
        self as u8
    }

    /// The mode for an `Arrangement.msg` constant, `None` when out of range.
    pub fn from_u8(v: u8) -> Option<Mode> {
        Mode::ALL.get(v as usize).copied()
    }
}

/// A interactive-force-control paper phase that can be requested (interactive-force-control paper Sec. 4.2.2: the switch is manual).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Phase {
    /// Approach: hand distance control > wrist > tactile guidance > avoidance, posture.
    PreContact,
    /// Contact: hand force control > wrist > position hold > avoidance, compliance, posture.
    Contact,
}

impl Phase {
    /// The mode of this phase.
    pub fn mode(self) -> Mode {
        match self {
            Phase::PreContact => Mode::PreContact,
            Phase::Contact => Mode::Contact,
        }
    }
}

/// A phase request that the supervisor refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
#[error("phase request refused: {reason}")]
pub struct PhaseRefused {
    /// Why.
    pub reason: &'static str,
}

/// Sensed signals for one update, SI units. NaN is allowed and handled conservatively (see
/// [`super::Supervisor::update`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SupervisorInput {
    /// `‖ẋ‖` of the end effector \[m/s\].
    pub ee_speed_mps: f64,
    /// `‖F_d‖`, the Euclidean norm over the cells' repulsion forces `F_di` of eq. (3) (not the
    /// largest one) \[N\], computed with the NOMINAL sensing range
    /// (otherwise shrinking the range in (b) would itself read as "nothing in range").
    pub avoidance_force_n: f64,
    /// `‖F_c‖`, the largest contact force on one link: the norm of the sum of its cells'
    /// measured forces along their normals \[N\].
    pub contact_force_n: f64,
    /// Distance of the end effector to its goal \[m\].
    pub goal_error_m: f64,
    /// The speed at which the link pressed hardest moves into what it touches: its pressed
    /// point's velocity along its force \[m/s\] (NaN: no contact). A contact that gives way
    /// lets it advance; a rigid one holds it at 0.
    pub contact_advance_mps: f64,
}

/// Why a transition happened.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cause {
    /// Stopped near an obstacle with the goal not reached (intentional-contact paper Table I (b) conditions).
    Stuck,
    /// Contact force at or above ε_c, or NaN (intentional-contact paper Table I (c) condition).
    ContactOverLimit,
    /// Contact force back below ε_c − band for the dwell time.
    ContactReleased,
    /// Contact force back below ε_c − band for the dwell time after a hard contact entered
    /// from intentional contact (b): the push cannot succeed under ε_c, so the arm goes back to
    /// (a) (backs off) and intentional contact stays off while [`Blocked`] holds.
    PushBlocked,
    /// The push of intentional contact (b) got the goal less than `progress_min_m` nearer in
    /// `dwell.push_stall_s`: given up as [`Cause::PushBlocked`] gives it up, without a hard contact.
    PushStalled,
    /// Goal reached during intentional contact.
    GoalReached,
    /// No obstacle in the nominal range any more.
    ObstacleCleared,
    /// Speed, obstacle force or goal error NaN for the dwell time during intentional contact.
    InvalidInput,
    /// A interactive-force-control paper phase request.
    PhaseRequest,
    /// Decided by another supervisor (the `priority_supervisor` node), see
    /// [`super::Supervisor::impose`].
    Imposed,
}

/// Why and since when the intentional-contact paper policy holds the arm in (a) instead of
/// pushing again: a push in intentional contact (b) reached `ε_c` (a fixed obstacle, or one too
/// heavy to slide under `ε_c`). Cleared by a new goal ([`super::Supervisor::new_goal`]), by goal
/// progress (the goal error `progress_min_m` below `goal_error_m`) or by nothing in range for
/// `dwell.clear_s`; until then the stuck test (a) → (b) is off (`docs/supervisor.md`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Blocked {
    /// When the push was given up (the (c) → (a) or the stalled (b) → (a) switch) \[s\].
    pub since_s: f64,
    /// The goal error then \[m\].
    pub goal_error_m: f64,
    /// The largest contact force `‖F_c‖` of the hard contact that blocked the push, or of the
    /// stalled push \[N\].
    pub contact_force_n: f64,
}

impl std::fmt::Display for Blocked {
    /// What an operator reads: when, how hard and how far from the goal the push was given up.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the push was given up at t = {:.3} s ({:.2} N against eps_c, the goal {:.3} m away); \
             holding until a new goal, goal progress or nothing in range",
            self.since_s, self.contact_force_n, self.goal_error_m
        )
    }
}

/// An arrangement decided by another supervisor with the same configuration: what
/// `Arrangement.msg` carries.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Imposed {
    /// The mode (its task order comes from this supervisor's configuration).
    pub mode: Mode,
    /// `t_t` of the switch at the deciding supervisor \[s\].
    pub switch_time_s: f64,
    /// `d_range` \[m\].
    pub sensing_range_m: f64,
    /// The fusion weight `w` the deciding supervisor shifts to.
    pub fusion_weight_target: f64,
    /// The deciding supervisor's [`crate::supervisor::Supervisor::blocked`].
    pub blocked: Option<Blocked>,
}

/// One arrangement switch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transition {
    /// The update time of the switch, `t_t` of intentional-contact paper eq. (11) \[s\].
    pub t_s: f64,
    /// Mode before.
    pub from: Mode,
    /// Mode after.
    pub to: Mode,
    /// Why.
    pub cause: Cause,
}

/// The active arrangement (the Rust side of `Arrangement.msg`).
#[derive(Debug, Clone, PartialEq)]
pub struct Arrangement {
    /// The active mode.
    pub mode: Mode,
    /// Indices into the configured task-name list, highest priority first (capacity reserved
    /// once, so switching does not allocate).
    pub(super) task_order: Vec<usize>,
    /// `t_t` of intentional-contact paper eq. (11): time of the last switch \[s\].
    pub switch_time_s: f64,
    /// δ_t of intentional-contact paper eq. (11) \[1/s\].
    pub smoothing_gain_per_s: f64,
    /// Current `d_range` of intentional-contact paper eq. (3) \[m\] (ramps during (b) and back in (a)).
    pub sensing_range_m: f64,
    /// Current fusion weight `w` of interactive-force-control paper eq. (6) (follows the sigmoid after a phase switch).
    pub fusion_weight: f64,
    /// The value `fusion_weight` goes to (what `Arrangement.msg` carries as `fusion_weight`).
    pub fusion_weight_target: f64,
}

impl Arrangement {
    /// Task indices into the configured task-name list, highest priority first.
    pub fn task_order(&self) -> &[usize] {
        &self.task_order
    }

    /// Task names, highest priority first, given the configured list.
    pub fn task_names<'a>(&'a self, tasks: &'a [String]) -> impl Iterator<Item = &'a str> + 'a {
        self.task_order.iter().map(move |&i| tasks[i].as_str())
    }
}
