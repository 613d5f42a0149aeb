//! What one campaign scene showed: its safety violations and whether it met its goal or its
//! force targets.

use serde::Serialize;

use crate::outputs::metrics::TOPPLED_DEG;
use crate::outputs::outcome::FIRST_CONTACT_OVERSHOOT_N;
use crate::outputs::report::RunReport;
use crate::outputs::safety;

/// The verdict on one scene.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verdict {
    /// Every safety violation (empty: safe).
    pub violations: Vec<String>,
    /// Goal scenes: `reached`, `blocked` (the push could not succeed and the arm held) or
    /// `not_reached`.
    pub outcome: Option<&'static str>,
    /// Goal scenes: the goal was reached, and before the first push on an object when there is
    /// one (a goal that only the push cleared the way to was not reached by the controller).
    pub goal_reached: Option<bool>,
    /// Goal scenes: the largest tilt of a movable object from its start orientation \[deg\]
    /// (over [`TOPPLED_DEG`] one toppled).
    pub object_tilt_max_deg: Option<f64>,
    /// Force scenes: the Table 3 checks held.
    pub force_table3: Option<bool>,
    /// Force scenes: largest hand force over its reference at the first touch \[N\].
    pub first_contact_overshoot_n: Option<f64>,
}

/// The verdict on `report`: its safety by the one definition of [`crate::outputs::safety`], and its
/// success.
pub fn judge(report: &RunReport) -> Verdict {
    let m = &report.metrics;
    let force_table3 =
        m.force.as_ref().map(|_| report.checks.iter().filter(|c| c.name.contains("RMS")).all(|c| c.passed));
    Verdict {
        violations: safety::violations(&m.safety, m.faulted_cycles),
        outcome: m.goal.as_ref().map(|g| g.outcome),
        goal_reached: m.goal.as_ref().map(|g| g.goal_reached && g.reached_before_pushes()),
        object_tilt_max_deg: m.goal.as_ref().map(|g| g.object_tilt_max_deg),
        force_table3,
        first_contact_overshoot_n: m.force.as_ref().map(|f| f.first_contact_peak_force_n - f.first_contact_reference_n),
    }
}

impl Verdict {
    /// Whether a movable object of the scene toppled.
    pub fn toppled(&self) -> bool {
        self.object_tilt_max_deg.is_some_and(|t| t > TOPPLED_DEG)
    }
}

/// Whether an overshoot is within the first-contact limit.
pub fn overshoot_ok(overshoot_n: f64) -> bool {
    overshoot_n <= FIRST_CONTACT_OVERSHOOT_N
}
