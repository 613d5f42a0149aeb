//! The figures of one study point, from its run report.

use serde::{Deserialize, Serialize};

use super::stability::{self, Instability};
use crate::outputs::report::RunReport;

/// Every figure of a point that ran. Optional figures are None where they do not apply (no goal,
/// no force reference, goal never reached).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Figures {
    /// Median wall-clock time of one `Controller::update` \[µs\].
    pub control_cycle_us_p50: f64,
    /// 99th percentile of the same \[µs\].
    pub control_cycle_us_p99: f64,
    /// Wall-clock time per simulated second, world and controller \[s/s\].
    pub wall_s_per_sim_s: f64,
    /// CPU time of the run's thread per simulated second, set-up included \[s/s\] (None: not
    /// measurable here). Other load on the machine does not inflate it.
    pub cpu_s_per_sim_s: Option<f64>,
    /// RMS force-tracking error in the settled contact phase (interactive-force-control paper Table 3) \[N\].
    pub rms_force_error_n: Option<f64>,
    /// First time the goal error was within the supervisor's tolerance \[s\].
    pub goal_reached_s: Option<f64>,
    /// Goal error at the end of the run \[m\].
    pub goal_error_m: Option<f64>,
    /// The supervisor's goal tolerance \[m\].
    pub goal_tolerance_m: Option<f64>,
    /// Largest contact force on one link over the whole run, pushes included \[N\].
    pub max_contact_force_n: f64,
    /// Largest arm joint speed \[rad/s\].
    pub max_joint_speed_rad_s: f64,
    /// The first sign of instability (None: stable).
    pub unstable: Option<Instability>,
    /// Whether the scenario's outcome checks passed.
    pub checks_passed: bool,
}

impl Figures {
    /// The accuracy figure the trade is judged on: the goal error for a goal scenario, else the
    /// RMS force error (None: neither measured).
    pub fn error(&self) -> Option<f64> {
        self.goal_error_m.or(self.rms_force_error_n)
    }

    /// The cost the trade is judged on: CPU time per simulated second where measured, else wall
    /// time \[s/s\].
    pub fn cost(&self) -> f64 {
        self.cpu_s_per_sim_s.unwrap_or(self.wall_s_per_sim_s)
    }
}

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

fn percentile(mut v: Vec<f64>, p: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * p).round() as usize]
}

/// The figures of `report`; `speed_limits` are the model joints' velocity limits, `cpu_s` the
/// CPU time the run took.
pub fn measure(report: &RunReport, speed_limits: &[f64], cpu_s: Option<f64>) -> Figures {
    let (r, m) = (&report.record, &report.metrics);
    let compute: Vec<f64> = r.cycles.iter().map(|c| c.compute_us).collect();
    let goal = m.goal.as_ref();
    let tolerance = goal.map(|g| g.goal_tolerance_m);
    let reached = tolerance.and_then(|tol| r.cycles.iter().find(|c| c.signals.goal_error_m <= tol).map(|c| c.t_s));
    Figures {
        control_cycle_us_p50: percentile(compute.clone(), 0.5),
        control_cycle_us_p99: percentile(compute, 0.99),
        wall_s_per_sim_s: r.wall_time_s / r.sim_duration_s(),
        cpu_s_per_sim_s: cpu_s.map(|c| c / r.sim_duration_s()),
        rms_force_error_n: m.force.as_ref().and_then(|f| finite(f.rms_force_error_n)),
        goal_reached_s: reached,
        goal_error_m: goal.and_then(|g| finite(g.goal_error_m)),
        goal_tolerance_m: tolerance,
        max_contact_force_n: r.cycles.iter().map(|c| c.link_force_n).fold(0.0, f64::max),
        max_joint_speed_rad_s: m.max_joint_speed_rad_s,
        unstable: stability::detect(r, speed_limits),
        checks_passed: report.passed(),
    }
}
