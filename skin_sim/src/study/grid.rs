//! The study's grid: the settings a point runs with, the axes they vary along, and the points of
//! the default grid (one axis at a time around each scenario's own setting, control rate ×
//! timestep crossed) and of the full grid (the whole cross product).

use serde::{Deserialize, Serialize};
use skin_core::controller::ControllerConfig;
use skin_core::hierarchy::InverseParams;

use crate::run::runner::RunTarget;
use crate::scene::Scene;

/// Control rates of the grid \[Hz\].
pub const CONTROL_RATES_HZ: [f64; 4] = [125.0, 250.0, 500.0, 1000.0];
/// MuJoCo timesteps of the grid \[s\].
pub const TIMESTEPS_S: [f64; 4] = [0.0005, 0.001, 0.002, 0.004];
/// Damping band widths of the inverse besides the setup's (`docs/hierarchy.md`) \[1/kg\].
pub const DAMPINGS: [f64; 4] = [0.0, 1e-4, 1e-2, 1e-1];
/// Rank thresholds `(rel, abs)` of the inverse besides the setup's.
pub const RANK_THRESHOLDS: [(f64, f64); 3] = [(1e-6, 1e-12), (1e-3, 1e-12), (1e-12, 1e-3)];

/// How many skin cells the robot (and its simulated skin) has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Density {
    /// The layout as generated.
    Full,
    /// Every fourth cell of each patch.
    Quarter,
    /// One virtual cell per patch (see [`super::density`]).
    PerPatch,
}

impl Density {
    /// Every density, densest first.
    pub const ALL: [Density; 3] = [Density::Full, Density::Quarter, Density::PerPatch];

    /// Short name (tables, labels).
    pub fn name(self) -> &'static str {
        match self {
            Density::Full => "full",
            Density::Quarter => "quarter",
            Density::PerPatch => "1/patch",
        }
    }
}

/// Everything a point changes about a scenario's run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Setting {
    /// Control rate \[Hz\].
    pub control_rate_hz: f64,
    /// MuJoCo timestep \[s\].
    pub timestep_s: f64,
    /// Skin density.
    pub density: Density,
    /// The hierarchy's inverse.
    pub inverse: InverseParams,
}

impl Setting {
    /// A readable one-line label, e.g. `500 Hz, 1 ms, full, d 1e-3, thr 1e-12/1e-12`.
    pub fn label(&self) -> String {
        let i = &self.inverse;
        format!(
            "{} Hz, {} ms, {}, d {}, thr {}/{}",
            self.control_rate_hz,
            self.timestep_s * 1e3,
            self.density.name(),
            sci(i.damping),
            sci(i.rank_threshold_rel),
            sci(i.rank_threshold_abs)
        )
    }
}

/// `1e-3`-style text for the inverse parameters (0 stays `0`).
pub fn sci(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else {
        format!("{v:.0e}")
    }
}

/// What a point varies relative to its scenario's own setting.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    /// Control rate and timestep (crossed).
    RateTimestep,
    /// Skin density.
    Density,
    /// Damping or rank thresholds of the inverse.
    Inverse,
    /// Everything at once (the full grid).
    All,
}

impl Axis {
    /// Name in the document.
    pub fn name(self) -> &'static str {
        match self {
            Axis::RateTimestep => "control rate x timestep",
            Axis::Density => "skin density",
            Axis::Inverse => "inverse damping/threshold",
            Axis::All => "full grid",
        }
    }
}

/// One run of the study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Point {
    /// Scenario name.
    pub scenario: String,
    /// Simulated duration \[s\].
    pub duration_s: f64,
    /// What it varies.
    pub axis: Axis,
    /// The settings.
    pub setting: Setting,
    /// Whether it is the scenario's own setting (the baseline of the one-axis variations).
    pub baseline: bool,
}

/// A scenario of the study and how long it runs.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyScenario {
    /// What runs.
    pub target: RunTarget,
    /// Simulated duration \[s\].
    pub duration_s: f64,
}

/// The default study: one intentional-contact paper scenario per robot and one interactive-force-control paper force scenario, with
/// durations that keep `make study` within minutes.
pub const DEFAULT_SCENARIOS: [(&str, f64); 3] =
    [("intentional_contact", 20.0), ("tomm_movable_obstacles", 30.0), ("force_tracking_base_motion", 20.0)];

/// A scenario's own setting: its scene's control rate and timestep, the full layout and its
/// controller setup's inverse.
pub fn baseline(target: &RunTarget) -> anyhow::Result<Setting> {
    let scene = Scene::load(&target.scene)?;
    let config = ControllerConfig::load(&target.controller)?;
    Ok(Setting {
        control_rate_hz: scene.spec.control_rate_hz,
        timestep_s: scene.spec.timestep_s,
        density: Density::Full,
        inverse: config.setup.inverse,
    })
}

/// The inverse settings of the grid: the baseline's, then each damping and each threshold pair.
fn inverses(base: InverseParams) -> Vec<InverseParams> {
    let dampings = DAMPINGS.iter().map(|&damping| InverseParams { damping, ..base });
    let thresholds = RANK_THRESHOLDS.iter().map(|&(rank_threshold_rel, rank_threshold_abs)| InverseParams {
        rank_threshold_rel,
        rank_threshold_abs,
        ..base
    });
    let mut out = vec![base];
    for i in dampings.chain(thresholds) {
        if !out.contains(&i) {
            out.push(i); // a setup whose own value is on the grid appears once
        }
    }
    out
}

/// The points of one scenario. Default grid: control rate × timestep crossed (density and inverse
/// at the baseline), then each other density and each other inverse at the baseline's rate and
/// timestep. Full grid: rate × timestep × density × inverse.
pub fn points(scenario: &StudyScenario, base: Setting, full: bool) -> Vec<Point> {
    let point = |axis, setting: Setting| Point {
        scenario: scenario.target.name.clone(),
        duration_s: scenario.duration_s,
        axis,
        baseline: setting == base,
        setting,
    };
    let rate_dt = CONTROL_RATES_HZ
        .iter()
        .flat_map(|&r| TIMESTEPS_S.iter().map(move |&dt| (r, dt)))
        .map(|(control_rate_hz, timestep_s)| Setting { control_rate_hz, timestep_s, ..base });
    if full {
        return rate_dt
            .flat_map(|s| Density::ALL.into_iter().map(move |density| Setting { density, ..s }))
            .flat_map(|s| inverses(base.inverse).into_iter().map(move |inverse| Setting { inverse, ..s }))
            .map(|s| point(Axis::All, s))
            .collect();
    }
    let mut out: Vec<Point> = rate_dt.map(|s| point(Axis::RateTimestep, s)).collect();
    if !out.iter().any(|p| p.baseline) {
        out.push(point(Axis::RateTimestep, base)); // a scene whose own rate or step is off the grid
    }
    out.extend(Density::ALL[1..].iter().map(|&density| point(Axis::Density, Setting { density, ..base })));
    out.extend(inverses(base.inverse)[1..].iter().map(|&inverse| point(Axis::Inverse, Setting { inverse, ..base })));
    out
}
