//! Supervisor parameters (`config/supervisor.yaml`): the policy, the arrangements as ordered task
//! name lists, thresholds with their hysteresis bands, dwell times, the sensing-range ramp, the
//! smoothing gain and the fusion-weight sigmoid. Loaded and validated with errors naming the file
//! and the key.

use std::path::Path;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::declare_params;
use crate::param_file::declare::{Declared, Range};
use crate::param_file::yaml::{self, YamlError};
use crate::param_file::InvalidParam;

/// Which switching policy the supervisor runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Policy {
    /// Intentional-contact paper Table I: avoidance / intentional contact / hard contact, switched on sensed
    /// conditions.
    IntentionalContact,
    /// Interactive-force-control paper Table 1: precontact / contact, switched on request (interactive-force-control paper Sec. 4.2.2).
    Phases,
}

declare_params! {
    /// The five arrangements, each an ordered list of task names, highest priority first
    /// (intentional-contact paper Table I (a)-(c), interactive-force-control paper Table 1). All
    /// five are required whatever the policy.
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct ArrangementNames {
        /// Intentional-contact paper Table I (a): avoidance > goal > contact reaction.
        pub avoidance: Vec<String> => { text: "task names", live: false },
        /// Intentional-contact paper Table I (b): goal > contact reaction > avoidance.
        pub intentional_contact: Vec<String> => { text: "task names", live: false },
        /// Intentional-contact paper Table I (c): contact reaction > goal > avoidance.
        pub hard_contact: Vec<String> => { text: "task names", live: false },
        /// Interactive-force-control paper Table 1, precontact phase.
        pub precontact: Vec<String> => { text: "task names", live: false },
        /// Interactive-force-control paper Table 1, contact phase.
        pub contact: Vec<String> => { text: "task names", live: false },
    }
}

impl ArrangementNames {
    /// `(key, names)` in [`super::Mode`] order (0..=4).
    pub fn by_mode(&self) -> [(&'static str, &[String]); 5] {
        [
            ("avoidance", &self.avoidance),
            ("intentional_contact", &self.intentional_contact),
            ("hard_contact", &self.hard_contact),
            ("precontact", &self.precontact),
            ("contact", &self.contact),
        ]
    }
}

declare_params! {
    /// Switching thresholds of intentional-contact paper Table I and their hysteresis bands (SI units).
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Thresholds {
        /// ε_v: the end effector counts as stopped when `‖ẋ‖ ≤ ε_v`.
        pub speed_mps: f64 => { unit: "m/s", range: Range::positive(1.0), live: false },
        /// A started stuck dwell is kept while `‖ẋ‖ ≤ ε_v + band`.
        pub speed_band_mps: f64 => { unit: "m/s", range: Range::closed(0.0, 1.0), live: false },
        /// ε_c: hard contact when `‖F_c‖ ≥ ε_c`.
        pub contact_force_n: f64 => { unit: "N", range: Range::positive(1e3), live: false },
        /// An impact: hard contact at once when `‖F_c‖ ≥` this, without `dwell.hard_contact_s`;
        /// at least `contact_force_n`.
        pub impact_force_n: f64 => { unit: "N", range: Range::positive(1e4), live: false },
        /// Hard contact is left only when `‖F_c‖ < ε_c − band`; below `contact_force_n` (else
        /// hard contact is never left).
        pub contact_band_n: f64 => { unit: "N", range: Range::closed(0.0, 1e3), live: false },
        /// No contact (Table I (a): `‖F_c‖ = 0`) when `‖F_c‖ ≤` this: (c) is left for (a) only
        /// then (for (b): below `contact_force_n − contact_band_n`). Above the skin's noise floor.
        pub contact_zero_n: f64 => { unit: "N", range: Range::closed(0.0, 1e3), live: false },
        /// Nothing in range when `‖F_d‖ ≤` this (0: exactly no repulsion, as in Table I).
        pub obstacle_force_n: f64 => { unit: "N", range: Range::closed(0.0, 1e3), live: false },
        /// An obstacle counts as in range for the stuck test when `‖F_d‖ >` threshold + band.
        pub obstacle_band_n: f64 => { unit: "N", range: Range::closed(0.0, 1e3), live: false },
        /// Goal reached when the goal error is `≤` this.
        pub goal_tolerance_m: f64 => { unit: "m", range: Range::positive(1.0), live: false },
        /// The goal counts as not reached for the stuck test when the error is `>` tol + band.
        pub goal_band_m: f64 => { unit: "m", range: Range::closed(0.0, 1.0), live: false },
        /// Window of the crawl test: moving but hardly getting nearer the goal (a crawl along an
        /// obstacle faster than ε_v) counts as stopped when the goal error fell slower than
        /// `crawl_speed_mps` on average over this long.
        pub progress_window_s: f64 => { unit: "s", range: Range::positive(100.0), live: false },
        /// A crawl: the goal error fell by less than `crawl_speed_mps · progress_window_s` over
        /// the last window of (a).
        pub crawl_speed_mps: f64 => { unit: "m/s", range: Range::closed(0.0, 1.0), live: false },
        /// Least fall of the goal error that counts as progress of a push (its retry) or of a
        /// blocked hold (its end).
        pub progress_min_m: f64 => { unit: "m", range: Range::closed(0.0, 1.0), live: false },
        /// A contact gives way when the link pressed hardest advances into it at least this fast
        /// on average (over `dwell.give_way_s`): a rise of `‖F_c‖` to ε_c is then no strike
        /// again, but the peak of a push that slides.
        pub give_way_speed_mps: f64 => { unit: "m/s", range: Range::closed(0.0, 1.0), live: false },
        /// A push (b) holds its link's force at `ε_c −` this margin (the skin's approach bound,
        /// `docs/resolver.md`): a skin that reads a contact this much low still presses under
        /// ε_c. Below `contact_force_n`.
        pub push_margin_n: f64 => { unit: "N", range: Range::closed(0.0, 1e3), live: false },
    }
}

declare_params! {
    /// How long a condition must hold before its switch.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct DwellTimes {
        /// (a) → (b): stopped near an obstacle with the goal not reached.
        pub stuck_s: f64 => { unit: "s", range: DWELL_S, live: false },
        /// (a)/(b) → (c): contact force over ε_c this long (0: immediate; at once from
        /// `impact_force_n`), so one skin sample's peak of a rigid touch is no hard contact.
        pub hard_contact_s: f64 => { unit: "s", range: DWELL_S, live: false },
        /// (a)/(b) → (c) at once: `‖F_c‖` rose to ε_c again, after a dip longer than
        /// `hard_contact_gap_s`, within this long of its last rise (a contact that keeps
        /// striking ε_c is hard, however short each strike; 0: off).
        pub hard_contact_repeat_s: f64 => { unit: "s", range: DWELL_S, live: false },
        /// The `hard_contact_s` dwell survives dips of `‖F_c‖` under ε_c this short: a contact
        /// whose force alternates over and under ε_c from one skin sample to the next is over it,
        /// and a rise after such a dip is no new strike (one impact's ringing is one strike).
        pub hard_contact_gap_s: f64 => { unit: "s", range: DWELL_S, live: false },
        /// Time constant of the average of the pressed link's advance that tells a contact that
        /// gives way (`thresholds.give_way_speed_mps`); it starts from 0 at every switch.
        pub give_way_s: f64 => { unit: "s", range: Range::positive(100.0), live: false },
        /// (c) → previous: contact force below ε_c − band.
        pub contact_release_s: f64 => { unit: "s", range: DWELL_S, live: false },
        /// (b) → (a): goal reached.
        pub goal_reached_s: f64 => { unit: "s", range: DWELL_S, live: false },
        /// (b) → (a): nothing in range, or invalid (NaN) speed / obstacle / goal inputs.
        pub clear_s: f64 => { unit: "s", range: DWELL_S, live: false },
        /// A push that reached ε_c but got the goal nearer by `progress_min_m` is tried again,
        /// (c) → (b), unless the push before it also reached ε_c less than this long ago: at most
        /// two (b) → (c) in this long, so a retried push never chatters (`docs/supervisor.md`).
        pub retry_interval_s: f64 => { unit: "s", range: DWELL_S, live: false },
        /// (b) → (a), blocked: the push got the goal less than `progress_min_m` nearer over this
        /// long (it stalls, or vibrates under ε_c), as if it had reached ε_c without progress.
        pub push_stall_s: f64 => { unit: "s", range: Range::positive(100.0), live: false },
    }
}

/// Dwell times a supervisor accepts.
const DWELL_S: Range = Range::closed(0.0, 100.0);

declare_params! {
    /// The proximity sensing range `d_range` of intentional-contact paper eq. (3) and its ramp
    /// (intentional-contact paper Sec. III: reduced during intentional contact, gradually down to
    /// the configured value).
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct SensingRange {
        /// Range in (a) and in the interactive-force-control paper phases.
        pub nominal_m: f64 => { unit: "m", range: Range::positive(1.0), live: false },
        /// Range reached during intentional contact (b), at most `nominal_m` (paper: 0).
        pub intentional_contact_m: f64 => { unit: "m", range: Range::closed(0.0, 1.0), live: false },
        /// How fast the range shrinks in (b).
        pub shrink_rate_mps: f64 => { unit: "m/s", range: Range::positive(10.0), live: false },
        /// How fast it is restored in (a).
        pub restore_rate_mps: f64 => { unit: "m/s", range: Range::positive(10.0), live: false },
    }
}

declare_params! {
    /// Interactive-force-control paper eq. (6) fusion weight `w` (0: proximity only, 1: force
    /// only) and its sigmoid shift on a phase switch (interactive-force-control paper Sec. 4.2.2).
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct FusionShift {
        /// `w` in the precontact phase (and under the intentional-contact paper policy).
        pub w_precontact: f64 => { unit: "", range: Range::closed(0.0, 1.0), live: false },
        /// `w` in the contact phase.
        pub w_contact: f64 => { unit: "", range: Range::closed(0.0, 1.0), live: false },
        /// Logistic steepness over the normalized shift time `s ∈ [0, 1]`.
        pub gain: f64 => { unit: "", range: Range::positive(1e3), live: false },
        /// Duration of the shift.
        pub duration_s: f64 => { unit: "s", range: Range::positive(100.0), live: false },
    }
}

declare_params! {
    /// All supervisor parameters (one YAML file).
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct SupervisorParams {
        /// The switching policy.
        pub policy: Policy => { choices: "intentional_contact | phases", live: false },
        /// Every task name the controller knows; arrangements index into this list.
        pub tasks: Vec<String> => { text: "task names", live: false },
        /// The arrangements as ordered task-name lists.
        pub arrangements: ArrangementNames => nested,
        /// Thresholds and hysteresis bands.
        pub thresholds: Thresholds => nested,
        /// Dwell times.
        pub dwell: DwellTimes => nested,
        /// Sensing range and its ramp.
        pub sensing_range: SensingRange => nested,
        /// δ_t of intentional-contact paper eq. (11).
        pub smoothing_gain_per_s: f64 => { unit: "1/s", range: Range::positive(1e4), live: false },
        /// Fusion weight shift (interactive-force-control paper).
        pub fusion: FusionShift => nested,
        /// Capacity of the transition log ring buffer (allocated whole when the supervisor is
        /// built, so it is bounded).
        pub log_capacity: usize => { unit: "", range: Range::closed(1.0, 100_000.0), live: false },
    }
}

/// A parameter set that is structurally or numerically invalid.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ParamError {
    /// A number out of range.
    #[error(transparent)]
    Value(#[from] InvalidParam),
    /// An arrangement names a task that is not in `tasks`.
    #[error("`{key}`: unknown task `{name}` (not in `tasks`)")]
    UnknownTask {
        /// Dotted key with index, e.g. `arrangements.avoidance[1]`.
        key: String,
        /// The unknown name.
        name: String,
    },
    /// A task name appears twice in `tasks` or in one arrangement.
    #[error("`{key}`: duplicate task `{name}`")]
    DuplicateTask {
        /// Dotted key with index.
        key: String,
        /// The duplicated name.
        name: String,
    },
    /// An empty list.
    #[error("`{key}`: must not be empty")]
    Empty {
        /// Dotted key.
        key: String,
    },
}

/// Errors loading a supervisor parameter file.
#[derive(Debug, Error)]
pub enum SupervisorParamsError {
    /// Unreadable or unparsable file (unknown keys included).
    #[error(transparent)]
    Yaml(#[from] YamlError),
    /// Parsed but invalid.
    #[error("{file}: {error}")]
    Invalid {
        /// The file.
        file: String,
        /// What is invalid, with its key.
        error: ParamError,
    },
}

impl SupervisorParams {
    /// Checks every value and every arrangement; the error's key is the dotted path in the file.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.task_indices().map(|_| ())?;
        self.check("")?;
        let (t, r) = (&self.thresholds, &self.sensing_range);
        // the levels under ε_c
        for (key, value, why) in [
            ("contact_band_n", t.contact_band_n, "else hard contact is never left"),
            ("contact_zero_n", t.contact_zero_n, "no contact is below the hard-contact limit"),
            ("push_margin_n", t.push_margin_n, "else a push presses nothing"),
        ] {
            if value >= t.contact_force_n {
                let reason = format!("must be < contact_force_n ({why})");
                return Err(InvalidParam { key: format!("thresholds.{key}"), value, reason: reason.into() }.into());
            }
        }
        if t.impact_force_n < t.contact_force_n {
            return Err(InvalidParam {
                key: "thresholds.impact_force_n".into(),
                value: t.impact_force_n,
                reason: "must be >= contact_force_n (an impact is a hard contact)".into(),
            }
            .into());
        }
        if r.intentional_contact_m > r.nominal_m {
            return Err(InvalidParam {
                key: "sensing_range.intentional_contact_m".into(),
                value: r.intentional_contact_m,
                reason: "must be <= nominal_m".into(),
            }
            .into());
        }
        Ok(())
    }

    /// The five arrangements resolved to indices into [`Self::tasks`], in [`super::Mode`] order.
    pub fn task_indices(&self) -> Result<[Vec<usize>; 5], ParamError> {
        if self.tasks.is_empty() {
            return Err(ParamError::Empty { key: "tasks".into() });
        }
        for (i, name) in self.tasks.iter().enumerate() {
            if self.tasks[..i].contains(name) {
                return Err(ParamError::DuplicateTask { key: format!("tasks[{i}]"), name: name.clone() });
            }
        }
        let mut out: [Vec<usize>; 5] = Default::default();
        for (slot, (key, names)) in out.iter_mut().zip(self.arrangements.by_mode()) {
            if names.is_empty() {
                return Err(ParamError::Empty { key: format!("arrangements.{key}") });
            }
            for (i, name) in names.iter().enumerate() {
                let key = || format!("arrangements.{key}[{i}]");
                let idx = self
                    .tasks
                    .iter()
                    .position(|t| t == name)
                    .ok_or_else(|| ParamError::UnknownTask { key: key(), name: name.clone() })?;
                if slot.contains(&idx) {
                    return Err(ParamError::DuplicateTask { key: key(), name: name.clone() });
                }
                slot.push(idx);
            }
        }
        Ok(out)
    }

    /// Parses and validates YAML text; `source` names the file in errors.
    pub fn from_yaml_str(text: &str, source: &str) -> Result<Self, SupervisorParamsError> {
        let p: SupervisorParams = yaml::parse_str(text, source)?;
        p.validate().map_err(|error| SupervisorParamsError::Invalid { file: source.to_string(), error })?;
        Ok(p)
    }

    /// Reads, parses and validates the file at `path`.
    pub fn load(path: &Path) -> Result<Self, SupervisorParamsError> {
        let (text, file) = yaml::read_text(path)?;
        Self::from_yaml_str(&text, &file)
    }
}
