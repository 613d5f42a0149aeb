//! The speed/accuracy study (`skin_sim sweep`, `make study`): scenarios run over a grid of control
//! rate, simulation timestep, skin density and the hierarchy inverse's damping and thresholds, in
//! parallel; per point the cost (controller time per cycle, wall time per simulated second), the
//! accuracy (goal, force tracking), the peaks (contact force, joint speed) and whether and when it
//! went unstable. The results go to `results.json`; [`doc`] and [`charts`] turn them into
//! `docs/tradeoffs.md` and its figures.
//!
//! - [`grid`]: settings, axes and the default and full grids;
//! - [`density`]: the reduced skin layouts;
//! - [`variant`]: one point run for real;
//! - [`figures`] and [`stability`]: what is measured on a run;
//! - [`pool`]: the worker threads, [`cpu_time`]: what a run costs them;
//! - [`analysis`]: Pareto fronts and recommended settings.

pub mod analysis;
pub mod charts;
pub mod cpu_time;
pub mod density;
pub mod doc;
pub mod figures;
pub mod grid;
pub mod pool;
pub mod stability;
pub mod variant;

use std::path::Path;
use std::time::Instant;

use anyhow::Context;
use serde::{Deserialize, Serialize};

pub use grid::{Density, Point, Setting, StudyScenario};
pub use variant::{Outcome, PointResult};

/// `results.json`: how the study was run and every point with every figure.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StudyResults {
    /// The command that produced it.
    pub command: String,
    /// Which grid: `default` or `full`.
    pub grid: String,
    /// Build profile of the binary (`debug (opt-level 1)` or `release`): timings depend on it.
    pub profile: String,
    /// Worker threads.
    pub jobs: usize,
    /// Cores of the machine.
    pub cores: usize,
    /// Wall-clock time of the whole study \[s\].
    pub wall_time_s: f64,
    /// Every point, in grid order.
    pub points: Vec<PointResult>,
}

impl StudyResults {
    /// Reads a `results.json`.
    pub fn load(path: &Path) -> anyhow::Result<Self> {
        let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))
    }

    /// Writes it as pretty JSON.
    pub fn save(&self, path: &Path) -> anyhow::Result<()> {
        let text = serde_json::to_string_pretty(self)? + "\n";
        std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))
    }
}

/// The build profile of this binary.
pub fn profile() -> &'static str {
    if cfg!(debug_assertions) {
        "debug (opt-level 1)"
    } else {
        "release"
    }
}

/// The points of `scenarios`: the default grid, or the full cross product with `full`.
pub fn grid_points(scenarios: &[StudyScenario], full: bool) -> anyhow::Result<Vec<(usize, Point)>> {
    let mut out = Vec::new();
    for (k, s) in scenarios.iter().enumerate() {
        let base = grid::baseline(&s.target).with_context(|| format!("scenario {}", s.target.name))?;
        out.extend(grid::points(s, base, full).into_iter().map(|p| (k, p)));
    }
    Ok(out)
}

/// Runs `points` (each with the index of its scenario in `scenarios`) on `jobs` threads, writing
/// the variant files into `work`; `progress(done, total, result)` after each point.
pub fn run(
    scenarios: &[StudyScenario],
    points: &[(usize, Point)],
    jobs: usize,
    work: &Path,
    mut progress: impl FnMut(usize, usize, &PointResult),
) -> anyhow::Result<Vec<PointResult>> {
    std::fs::create_dir_all(work).with_context(|| format!("creating {}", work.display()))?;
    let mut done = 0;
    Ok(pool::map(
        points,
        jobs,
        |id, (k, point)| variant::run(&scenarios[*k].target, point, id, work),
        |_, r| {
            done += 1;
            progress(done, points.len(), r)
        },
    ))
}

/// A progress line for stderr: `study 12/72 intentional_contact 500 Hz, ... ok, 40 s, ETA 3 min`.
pub fn progress_line(done: usize, total: usize, r: &PointResult, started: Instant) -> String {
    let elapsed = started.elapsed().as_secs_f64();
    let eta = elapsed / done as f64 * (total - done) as f64;
    let status = match &r.outcome {
        Outcome::Ran { figures, .. } => match &figures.unstable {
            Some(u) => format!("unstable at {:.2} s ({})", u.t_s, u.kind.name()),
            None => format!("ok ({:.3} CPU s/s)", figures.cost()),
        },
        Outcome::Skipped { .. } => "skipped".into(),
        Outcome::Failed { error } => format!("FAILED: {error}"),
    };
    format!(
        "study {done}/{total} {} [{}]: {status}; {elapsed:.0} s elapsed, ETA {eta:.0} s",
        r.point.scenario,
        r.point.setting.label()
    )
}

#[cfg(test)]
mod tests;
