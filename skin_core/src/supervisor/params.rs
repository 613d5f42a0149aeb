//! Supervisor parameters (`config/supervisor.yaml`): the policy, the arrangements as ordered task
//! name lists, thresholds with their hysteresis bands, dwell times, the sensing-range ramp, the
//! smoothing gain and the fusion-weight sigmoid. Loaded and validated with errors naming the file
//! and the key.

use std::path::Path;

use serde::{Deserialize, Serialize};
use thiserror::Error;

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

/// The five arrangements, each an ordered list of task names, highest priority first
/// (intentional-contact paper Table I (a)-(c), interactive-force-control paper Table 1). All five are required whatever the policy.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArrangementNames {
    /// Intentional-contact paper Table I (a): avoidance > goal > contact reaction.
    pub avoidance: Vec<String>,
    /// Intentional-contact paper Table I (b): goal > contact reaction > avoidance.
    pub intentional_contact: Vec<String>,
    /// Intentional-contact paper Table I (c): contact reaction > goal > avoidance.
    pub hard_contact: Vec<String>,
    /// Interactive-force-control paper Table 1, precontact phase.
    pub precontact: Vec<String>,
    /// Interactive-force-control paper Table 1, contact phase.
    pub contact: Vec<String>,
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

/// Switching thresholds of intentional-contact paper Table I and their hysteresis bands (SI units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Thresholds {
    /// ε_v [m/s]: the end effector counts as stopped when `‖ẋ‖ ≤ ε_v`.
    pub speed_mps: f64,
    /// \[m/s\] a started stuck dwell is kept while `‖ẋ‖ ≤ ε_v + band`.
    pub speed_band_mps: f64,
    /// ε_c [N]: hard contact when `‖F_c‖ ≥ ε_c`.
    pub contact_force_n: f64,
    /// \[N\] hard contact is left only when `‖F_c‖ < ε_c − band`; `0 ≤ band < ε_c`.
    pub contact_band_n: f64,
    /// \[N\] nothing in range when `‖F_d‖ ≤` this (0: exactly no repulsion, as in Table I).
    pub obstacle_force_n: f64,
    /// \[N\] an obstacle counts as in range for the stuck test when `‖F_d‖ >` threshold + band.
    pub obstacle_band_n: f64,
    /// \[m\] goal reached when the goal error is `≤` this.
    pub goal_tolerance_m: f64,
    /// \[m\] the goal counts as not reached for the stuck test when the error is `>` tol + band.
    pub goal_band_m: f64,
    /// \[s\] window of the progress test: moving but not getting nearer the goal (a crawl along an
    /// obstacle faster than ε_v) counts as stopped when the goal error fell by less than
    /// `progress_min_m` over this long.
    pub progress_window_s: f64,
    /// \[m\] least fall of the goal error over `progress_window_s` that counts as progress.
    pub progress_min_m: f64,
}

/// How long a condition must hold before its switch \[s\] (all `≥ 0`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DwellTimes {
    /// (a) → (b): stopped near an obstacle with the goal not reached.
    pub stuck_s: f64,
    /// (a)/(b) → (c): contact force over ε_c (0: immediate).
    pub hard_contact_s: f64,
    /// (c) → previous: contact force below ε_c − band.
    pub contact_release_s: f64,
    /// (b) → (a): goal reached.
    pub goal_reached_s: f64,
    /// (b) → (a): nothing in range, or invalid (NaN) speed / obstacle / goal inputs.
    pub clear_s: f64,
    /// [s] a push that reached ε_c but got the goal nearer by `progress_min_m` is tried again,
    /// (c) → (b), unless the push before it also reached ε_c less than this long ago: at most
    /// two (b) → (c) in this long, so a retried push never chatters (`docs/supervisor.md`).
    pub retry_interval_s: f64,
}

/// The proximity sensing range `d_range` of intentional-contact paper eq. (3) and its ramp (intentional-contact paper Sec. III:
/// reduced during intentional contact, gradually down to the configured value).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensingRange {
    /// \[m\] range in (a) and in the interactive-force-control paper phases, `> 0`.
    pub nominal_m: f64,
    /// \[m\] range reached during intentional contact (b), in `[0, nominal_m]` (paper: 0).
    pub intentional_contact_m: f64,
    /// \[m/s\] how fast the range shrinks in (b), `> 0`.
    pub shrink_rate_mps: f64,
    /// \[m/s\] how fast it is restored in (a), `> 0`.
    pub restore_rate_mps: f64,
}

/// Interactive-force-control paper eq. (6) fusion weight `w` (0: proximity only, 1: force only) and its sigmoid shift
/// on a phase switch (interactive-force-control paper Sec. 4.2.2).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FusionShift {
    /// `w` in the precontact phase (and under the intentional-contact paper policy), in `[0, 1]`.
    pub w_precontact: f64,
    /// `w` in the contact phase, in `[0, 1]`.
    pub w_contact: f64,
    /// Logistic steepness over the normalized shift time `s ∈ [0, 1]`, `> 0`.
    pub gain: f64,
    /// \[s\] duration of the shift, `> 0`.
    pub duration_s: f64,
}

/// All supervisor parameters (one YAML file).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SupervisorParams {
    /// The switching policy.
    pub policy: Policy,
    /// Every task name the controller knows; arrangements index into this list.
    pub tasks: Vec<String>,
    /// The arrangements as ordered task-name lists.
    pub arrangements: ArrangementNames,
    /// Thresholds and hysteresis bands.
    pub thresholds: Thresholds,
    /// Dwell times.
    pub dwell: DwellTimes,
    /// Sensing range and its ramp.
    pub sensing_range: SensingRange,
    /// δ_t of intentional-contact paper eq. (11) \[1/s\], `> 0`.
    pub smoothing_gain_per_s: f64,
    /// Fusion weight shift (interactive-force-control paper).
    pub fusion: FusionShift,
    /// Capacity of the transition log ring buffer, in [1, 100000].
    pub log_capacity: usize,
}

/// Largest [`SupervisorParams::log_capacity`]: the log is allocated whole when the supervisor is
/// built, so an unbounded value would abort the process there.
const LOG_CAPACITY_MAX: usize = 100_000;

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

fn non_negative(prefix: &str, name: &str, v: f64) -> Result<(), InvalidParam> {
    InvalidParam::in_range(prefix, name, v, 0.0, f64::MAX, "must be finite and >= 0")
}

impl SupervisorParams {
    /// Checks every value and every arrangement; the error's key is the dotted path in the file.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.task_indices().map(|_| ())?;
        let t = &self.thresholds;
        let p = "thresholds.";
        InvalidParam::positive_finite(p, "speed_mps", t.speed_mps)?;
        non_negative(p, "speed_band_mps", t.speed_band_mps)?;
        InvalidParam::positive_finite(p, "contact_force_n", t.contact_force_n)?;
        InvalidParam::in_range(
            p,
            "contact_band_n",
            t.contact_band_n,
            0.0,
            t.contact_force_n,
            "must be >= 0 and < contact_force_n (else hard contact is never left)",
        )?;
        if t.contact_band_n >= t.contact_force_n {
            return Err(InvalidParam {
                key: "thresholds.contact_band_n".into(),
                value: t.contact_band_n,
                reason: "must be >= 0 and < contact_force_n (else hard contact is never left)".into(),
            }
            .into());
        }
        non_negative(p, "obstacle_force_n", t.obstacle_force_n)?;
        non_negative(p, "obstacle_band_n", t.obstacle_band_n)?;
        InvalidParam::positive_finite(p, "goal_tolerance_m", t.goal_tolerance_m)?;
        non_negative(p, "goal_band_m", t.goal_band_m)?;
        InvalidParam::positive_finite(p, "progress_window_s", t.progress_window_s)?;
        non_negative(p, "progress_min_m", t.progress_min_m)?;

        let d = &self.dwell;
        let p = "dwell.";
        non_negative(p, "stuck_s", d.stuck_s)?;
        non_negative(p, "hard_contact_s", d.hard_contact_s)?;
        non_negative(p, "contact_release_s", d.contact_release_s)?;
        non_negative(p, "goal_reached_s", d.goal_reached_s)?;
        non_negative(p, "clear_s", d.clear_s)?;
        non_negative(p, "retry_interval_s", d.retry_interval_s)?;

        let r = &self.sensing_range;
        let p = "sensing_range.";
        InvalidParam::positive_finite(p, "nominal_m", r.nominal_m)?;
        InvalidParam::in_range(
            p,
            "intentional_contact_m",
            r.intentional_contact_m,
            0.0,
            r.nominal_m,
            "must be in [0, nominal_m]",
        )?;
        InvalidParam::positive_finite(p, "shrink_rate_mps", r.shrink_rate_mps)?;
        InvalidParam::positive_finite(p, "restore_rate_mps", r.restore_rate_mps)?;

        InvalidParam::positive_finite("", "smoothing_gain_per_s", self.smoothing_gain_per_s)?;

        let f = &self.fusion;
        let p = "fusion.";
        InvalidParam::in_range(p, "w_precontact", f.w_precontact, 0.0, 1.0, "must be in [0, 1]")?;
        InvalidParam::in_range(p, "w_contact", f.w_contact, 0.0, 1.0, "must be in [0, 1]")?;
        InvalidParam::positive_finite(p, "gain", f.gain)?;
        InvalidParam::positive_finite(p, "duration_s", f.duration_s)?;

        if !(1..=LOG_CAPACITY_MAX).contains(&self.log_capacity) {
            return Err(InvalidParam {
                key: "log_capacity".into(),
                value: self.log_capacity as f64,
                reason: "must be in [1, 100000]".into(),
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
