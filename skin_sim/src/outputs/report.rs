//! What a run leaves in its output directory. Every product is a [`RunOutput`]: `metrics.json`
//! and `summary.txt` here; the figure (`skin_sim::outputs::plot`) and the bag (`skin_sim::bag`) plug in
//! as further implementations, all fed the same [`RunReport`].

use std::fmt::Write;
use std::path::{Path, PathBuf};

use anyhow::Context;

use crate::outputs::metrics::Metrics;
use crate::outputs::outcome::Check;
use crate::outputs::record::RunRecord;

/// A finished run: its record, its metrics and its outcome checks.
#[derive(Debug, Clone)]
pub struct RunReport {
    /// Per-cycle record.
    pub record: RunRecord,
    /// `metrics.json`.
    pub metrics: Metrics,
    /// Outcome checks (all must pass).
    pub checks: Vec<Check>,
}

impl RunReport {
    /// Whether every check passed.
    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| c.passed)
    }

    /// The readable summary: the run's cost, its switches, its figures, its checks.
    pub fn summary(&self) -> String {
        let m = &self.metrics;
        let mut s = String::new();
        let _ = writeln!(s, "scenario {} ({})", m.scenario, self.record.scene_file);
        let _ = writeln!(
            s,
            "  {:.1} s simulated in {:.1} s (realtime factor {:.2}), controller update p50 {:.0} us",
            m.sim_duration_s, self.record.wall_time_s, m.realtime_factor, m.control_cycle_us_p50
        );
        let l = &m.loop_time_s;
        let _ = writeln!(
            s,
            "  wall time: physics {:.2} s, sensors {:.2} s, controller {:.2} s, other {:.2} s (physics alone: realtime factor {:.0})",
            l.physics_s, l.sensors_s, l.controller_s, l.other_s, m.realtime_factor_physics_bound
        );
        let _ = writeln!(s, "  max arm joint speed {:.3} rad/s", m.max_joint_speed_rad_s);
        let switches: Vec<String> =
            m.arrangement_switches.iter().map(|w| format!("{:.2} s {} -> {}", w.t, w.from, w.to)).collect();
        let _ = writeln!(s, "  arrangement switches ({}): {}", switches.len(), switches.join(", "));
        if let Some(g) = &m.goal {
            let _ = writeln!(
                s,
                "  goal error {:.4} m ({}), max contact force {:.2} N outside pushes, {:.2} N in intentional contact (eps_c {} N), push relieved after {:.3} s",
                g.goal_error_m, g.outcome, g.max_contact_force_n, g.max_contact_force_intentional_n, g.eps_c_n, g.hard_contact_recovery_s
            );
        }
        let sf = &m.safety;
        let _ = writeln!(
            s,
            "  safety: longest contact over eps_c {:.3} s, one switch at most {} times in 10 s, {} cycles over a joint velocity limit, {} non-finite commands, at most {} touches in 1 s",
            sf.longest_contact_over_eps_c_s,
            sf.max_switch_repeats_in_window,
            sf.joint_speed_over_limit_cycles,
            sf.non_finite_command_cycles,
            sf.max_touches_per_s
        );
        if let Some(f) = &m.force {
            let _ = writeln!(
                s,
                "  hand force mean {:.3} N, RMS error from touch {:.3} N w/o interaction, from reaching the reference {:.3} N (rise {:.2} s), settled {:.3} N ({} cycles), {:.3} N with ({} cycles), first-touch peak {:.2} N (reference {:.2} N), out of contact {:.1} %",
                f.force_mean_n,
                f.rms_force_error_from_touch_n,
                f.rms_force_error_from_reach_n,
                f.force_rise_s,
                f.rms_force_error_n,
                f.rms_cycles[0],
                f.rms_force_error_interaction_n,
                f.rms_cycles[1],
                f.first_contact_peak_force_n,
                f.first_contact_reference_n,
                100.0 * f.contact_lost_fraction
            );
        }
        for c in &self.checks {
            let _ = writeln!(s, "  [{}] {}: {}", if c.passed { "pass" } else { "FAIL" }, c.name, c.detail);
        }
        let _ = writeln!(s, "  outcome: {}", if self.passed() { "PASS" } else { "FAIL" });
        s
    }
}

/// One product of a run, written into the output directory.
pub trait RunOutput {
    /// Writes the product for `report` into `dir` (which exists) and returns the file written.
    fn write(&self, report: &RunReport, dir: &Path) -> anyhow::Result<PathBuf>;
}

/// `metrics.json`.
pub struct MetricsJson;

impl RunOutput for MetricsJson {
    fn write(&self, report: &RunReport, dir: &Path) -> anyhow::Result<PathBuf> {
        let path = dir.join("metrics.json");
        let text = serde_json::to_string_pretty(&report.metrics)?;
        std::fs::write(&path, text + "\n").with_context(|| format!("writing {}", path.display()))?;
        Ok(path)
    }
}

/// `summary.txt`: [`RunReport::summary`].
pub struct SummaryText;

impl RunOutput for SummaryText {
    fn write(&self, report: &RunReport, dir: &Path) -> anyhow::Result<PathBuf> {
        let path = dir.join("summary.txt");
        std::fs::write(&path, report.summary()).with_context(|| format!("writing {}", path.display()))?;
        Ok(path)
    }
}

/// Writes every output into `dir` (created if missing); returns the files written.
pub fn write_all(report: &RunReport, dir: &Path, outputs: &[&dyn RunOutput]) -> anyhow::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    outputs.iter().map(|o| o.write(report, dir)).collect()
}
