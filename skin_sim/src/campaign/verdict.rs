//! What one campaign scene showed: its safety violations and whether it met its goal or its
//! force targets.

use serde::Serialize;
use skin_core::supervisor::Mode;

use crate::metrics::RECOVERY_LIMIT_S;
use crate::outcome::FIRST_CONTACT_OVERSHOOT_N;
use crate::record::RunRecord;
use crate::report::RunReport;

/// Entries into hard contact (intentional-contact paper Table I (c)) within
/// [`CHATTER_WINDOW_S`] that make chatter: the supervisor switching back and forth instead of
/// settling.
pub const CHATTER_ENTRIES: usize = 3;
/// The window of [`CHATTER_ENTRIES`] \[s\].
pub const CHATTER_WINDOW_S: f64 = 10.0;

/// The verdict on one scene.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verdict {
    /// Every safety violation (empty: safe).
    pub violations: Vec<String>,
    /// Goal scenes: the goal was reached.
    pub goal_reached: Option<bool>,
    /// Force scenes: the Table 3 checks held.
    pub force_table3: Option<bool>,
    /// Force scenes: largest hand force over its reference at the first touch \[N\].
    pub first_contact_overshoot_n: Option<f64>,
}

/// Entries into hard contact within any [`CHATTER_WINDOW_S`], at most.
pub fn hard_contact_entries_per_window(record: &RunRecord) -> usize {
    let entries: Vec<f64> = record.switches.iter().filter(|s| s.to == Mode::HardContact).map(|s| s.t_s).collect();
    (0..entries.len())
        .map(|i| entries[i..].iter().take_while(|&&t| t - entries[i] <= CHATTER_WINDOW_S).count())
        .max()
        .unwrap_or(0)
}

/// The verdict on `report`, a run whose commanded joints have the velocity limits `limits`
/// (the order of `record.arm_joints`).
pub fn judge(report: &RunReport, limits: &[f64]) -> Verdict {
    let (r, m) = (&report.record, &report.metrics);
    let mut violations = Vec::new();
    let non_finite = r.cycles.iter().any(|c| c.joint_velocities.iter().chain(&c.base_twist).any(|v| !v.is_finite()));
    if non_finite {
        violations.push("non-finite command".to_string());
    }
    if m.faulted_cycles > 0 {
        violations.push(format!("{} safe-stop cycles", m.faulted_cycles));
    }
    let over = r
        .cycles
        .iter()
        .flat_map(|c| c.joint_velocities.iter().zip(limits))
        .map(|(v, l)| v.abs() / l)
        .fold(0.0, f64::max);
    if over > 1.0 + 1e-9 {
        violations.push(format!("a joint command at {:.0} % of its velocity limit", over * 100.0));
    }
    if let Some(g) = &m.goal {
        if g.longest_contact_over_eps_c_s > RECOVERY_LIMIT_S {
            violations.push(format!("contact above eps_c for {:.2} s in one event", g.longest_contact_over_eps_c_s));
        }
    }
    let entries = hard_contact_entries_per_window(r);
    if entries >= CHATTER_ENTRIES {
        violations.push(format!("chatter: {entries} entries into hard contact within {CHATTER_WINDOW_S} s"));
    }
    let force_table3 =
        m.force.as_ref().map(|_| report.checks.iter().filter(|c| c.name.contains("RMS")).all(|c| c.passed));
    Verdict {
        violations,
        goal_reached: m.goal.as_ref().map(|g| g.goal_reached),
        force_table3,
        first_contact_overshoot_n: m.force.as_ref().map(|f| f.first_contact_peak_force_n - f.first_contact_reference_n),
    }
}

/// Whether an overshoot is within the first-contact limit.
pub fn overshoot_ok(overshoot_n: f64) -> bool {
    overshoot_n <= FIRST_CONTACT_OVERSHOOT_N
}
