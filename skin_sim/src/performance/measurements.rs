//! What `make bench` measured, read from `out/bench/summary.json` (the medians) and
//! `out/bench/stages.json` (each point's sizes and stage shares): the controller's cost curves
//! and the simulation's speed per scenario.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{bail, Context};
use skin_core::controller::Stage;

use super::simulator::{self, SimPoint};

/// One measured point: its median and what it measured.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchPoint {
    /// Benchmark id (`<id>_ns` in the summary).
    pub id: String,
    /// Median time of one `Controller::update` \[ns\].
    pub total_ns: f64,
    /// Cells of the skin.
    pub cells: f64,
    /// Non-silent cells in the readings.
    pub live_cells: f64,
    /// Joints of the model.
    pub joints: f64,
    /// Task levels in the arrangement and their rows in the last cycle.
    pub levels: f64,
    /// Rows of all levels.
    pub level_rows: f64,
    /// Fraction of the time in each stage, in [`Stage::ALL`] order.
    pub shares: [f64; 5],
    /// The machine's 1-minute load average when the point was measured (NaN: not recorded).
    pub load_average: f64,
}

impl BenchPoint {
    /// Time in `stage` \[ns\]: the median times the stage's share.
    pub fn stage_ns(&self, stage: Stage) -> f64 {
        self.total_ns * self.shares[stage as usize]
    }

    /// The stage with the largest share.
    pub fn dominant(&self) -> Stage {
        Stage::ALL.into_iter().max_by(|a, b| self.shares[*a as usize].total_cmp(&self.shares[*b as usize])).unwrap()
    }
}

/// A curve: points along one quantity.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// File stem of its figure.
    pub key: &'static str,
    /// Heading.
    pub title: &'static str,
    /// The quantity along x.
    pub x_label: &'static str,
    /// `(x, point)`, ascending in x.
    pub points: Vec<(f64, BenchPoint)>,
}

/// The series of the benchmarks (`skin_core/benches/scale.rs` and `controller.rs`): by id prefix,
/// and the quantity along x.
const SERIES: [(&str, &str, &str, &str); 4] = [
    ("cells", "Number of cells (TOMM, 36 live cells)", "cells", "controller_update_tomm_cells_"),
    (
        "range",
        "Cells in range of an obstacle (TOMM, 718 cells)",
        "live cells in range",
        "controller_update_tomm_range_",
    ),
    ("contact", "Cells in contact (TOMM, 718 cells)", "live cells in contact", "controller_update_tomm_contact_"),
    ("joints", "Number of joints (planar7, TOMM, humanoid)", "joints", "controller_update_"),
];

/// The robots of the joints' series.
const ROBOTS: [&str; 3] = ["planar7", "tomm", "humanoid"];

/// What `make bench` measured.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurements {
    /// The controller's cost curves.
    pub series: Vec<Series>,
    /// The simulation's speed per scenario (empty when the bench did not run the scenarios).
    pub simulator: Vec<SimPoint>,
}

/// Reads the points present in both files.
pub fn load(summary: &Path, stages: &Path) -> anyhow::Result<Measurements> {
    let read = |p: &Path| std::fs::read_to_string(p).with_context(|| format!("reading {}", p.display()));
    let medians: BTreeMap<String, f64> =
        serde_json::from_str(&read(summary)?).with_context(|| format!("parsing {}", summary.display()))?;
    let figures: BTreeMap<String, BTreeMap<String, f64>> =
        serde_json::from_str(&read(stages)?).with_context(|| format!("parsing {}", stages.display()))?;
    let point = |id: &str| -> anyhow::Result<Option<BenchPoint>> {
        let (Some(&total_ns), Some(f)) = (medians.get(&format!("{id}_ns")), figures.get(id)) else {
            return Ok(None);
        };
        let get =
            |key: &str| f.get(key).copied().with_context(|| format!("{}: `{id}` has no `{key}`", stages.display()));
        let mut shares = [0.0; 5];
        for s in Stage::ALL {
            shares[s as usize] = get(&format!("share_{}", s.name()))?;
        }
        Ok(Some(BenchPoint {
            id: id.to_string(),
            total_ns,
            cells: get("cells")?,
            live_cells: get("live_cells")?,
            joints: get("joints")?,
            levels: get("levels")?,
            level_rows: get("level_rows")?,
            shares,
            load_average: f.get("load_average").copied().unwrap_or(f64::NAN),
        }))
    };
    let mut all = Vec::new();
    for (key, title, x_label, prefix) in SERIES {
        let ids: Vec<String> = if key == "joints" {
            ROBOTS.iter().map(|r| format!("{prefix}{r}")).collect()
        } else {
            figures
                .keys()
                .filter(|id| id.strip_prefix(prefix).is_some_and(|n| n.parse::<u32>().is_ok()))
                .cloned()
                .collect()
        };
        let mut points = Vec::new();
        for id in ids {
            if let Some(p) = point(&id)? {
                let x = match key {
                    "cells" => p.cells,
                    "joints" => p.joints,
                    _ => p.live_cells,
                };
                points.push((x, p));
            }
        }
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        if points.len() < 2 {
            bail!(
                "{} and {}: fewer than two points of the `{key}` series (run `make bench` first)",
                summary.display(),
                stages.display()
            );
        }
        all.push(Series { key, title, x_label, points });
    }
    Ok(Measurements { series: all, simulator: simulator::points(&medians) })
}

/// Least-squares polynomial of `degree` (1 or 2) through `(x, y)`: coefficients from the
/// constant up (normal equations, solved by nalgebra's LU).
pub fn poly_fit(xy: &[(f64, f64)], degree: usize) -> Option<Vec<f64>> {
    let k = degree + 1;
    if xy.len() < k {
        return None;
    }
    let a = nalgebra::DMatrix::from_fn(xy.len(), k, |r, c| xy[r].0.powi(c as i32));
    let b = nalgebra::DVector::from_iterator(xy.len(), xy.iter().map(|p| p.1));
    let at = a.transpose();
    (&at * &a).lu().solve(&(&at * b)).map(|c| c.iter().copied().collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_recover_a_polynomial() {
        let xy: Vec<(f64, f64)> = (0..6).map(|i| i as f64).map(|x| (x, 2.0 + 3.0 * x + 0.5 * x * x)).collect();
        let c = poly_fit(&xy, 2).unwrap();
        for (got, want) in c.iter().zip([2.0, 3.0, 0.5]) {
            assert!((got - want).abs() < 1e-9, "{c:?}");
        }
        let line = poly_fit(&xy[..2], 1).unwrap();
        assert!((line[1] - 3.5).abs() < 1e-9);
        assert!(poly_fit(&xy[..2], 2).is_none());
    }

    #[test]
    fn load_names_a_missing_series() {
        let dir = std::env::temp_dir().join(format!("perf_doc_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (summary, stages) = (dir.join("summary.json"), dir.join("stages.json"));
        std::fs::write(&summary, r#"{"controller_update_tomm_ns": 1000.0}"#).unwrap();
        std::fs::write(&stages, "{}").unwrap();
        let e = load(&summary, &stages).unwrap_err().to_string();
        assert!(e.contains("`cells` series"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
