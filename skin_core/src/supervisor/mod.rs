//! The priority supervisor: intentional-contact paper Table I arrangements and interactive-force-control paper Table 1 phases, with smooth switching.
//!
//! An arrangement is data: an ordered list of task names from `config/supervisor.yaml`
//! ([`SupervisorParams`]), resolved once to indices into the configured task list. The
//! [`Supervisor`] picks the active one each control cycle:
//! - policy `intentional_contact` (intentional-contact paper Table I): (a) avoidance > goal > contact reaction,
//!   (b) goal > contact reaction > avoidance (intentional contact, entered when stuck; the
//!   sensing range ramps down, intentional-contact paper Sec. III), (c) contact reaction > goal > avoidance
//!   (hard contact, `‖F_c‖ ≥ ε_c`), with dwell times and hysteresis bands against chattering;
//! - policy `phases` (interactive-force-control paper Table 1): precontact / contact on request, with the sigmoid
//!   shift of the fusion weight `w` (interactive-force-control paper eq. (6), Sec. 4.2.2).
//!
//! [`TorqueBlender`] blends the torques of the old and new arrangements after a switch (intentional-contact paper
//! eq. (10)-(11), with `χ(t_t) = 1` so there is no step; see [`blend`]). Nothing allocates after
//! construction. Rules, values and the blend bound: `docs/supervisor.md`.
//!
//! ```
//! use skin_core::supervisor::*;
//! let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../config/supervisor.yaml")).unwrap();
//! let params = SupervisorParams::from_yaml_str(&text, "supervisor.yaml").unwrap();
//! let mut sup = Supervisor::new(&params, 0.0).unwrap();
//! let stuck = SupervisorInput { ee_speed_mps: 0.0, avoidance_force_n: 3.0, contact_force_n: 0.0, goal_error_m: 0.2, contact_advance_mps: f64::NAN };
//! let mut t = 0.0;
//! while sup.mode() == Mode::Avoidance { t += 0.01; sup.update(t, &stuck); }
//! assert_eq!(sup.mode(), Mode::IntentionalContact);
//! let names: Vec<&str> = sup.arrangement().task_names(sup.tasks()).collect();
//! assert_eq!(names, ["goal", "contact_reaction", "avoidance"]);
//! ```

pub mod blend;
mod log;
mod machine;
mod params;
mod types;

#[cfg(test)]
mod tests;

pub use blend::{TorqueBlender, WeightShift};
pub use log::TransitionLog;
pub use machine::Supervisor;
pub use params::{
    ArrangementNames, DwellTimes, FusionShift, ParamError, Policy, SensingRange, SupervisorParams,
    SupervisorParamsError, Thresholds,
};
pub use types::{Arrangement, Blocked, Cause, Imposed, Mode, Phase, PhaseRefused, SupervisorInput, Transition};
