//! One point of the study run for real: the scenario's scene with the point's rates and skin, a
//! controller setup file with the point's layout and inverse, the closed loop, the figures.
//!
//! The controller is built from a setup file (the closed loop takes a path), so each point writes
//! its variant setup (absolute paths) and, for a reduced density, its layout into the work
//! directory: `<work>/p<id>.controller.yaml`, `<work>/p<id>.layout.yaml`.

use std::path::{Path, PathBuf};

use anyhow::Context;
use serde::{Deserialize, Serialize};
use skin_core::controller::ControllerSetup;
use skin_core::skin::layout::SkinLayout;

use super::figures::{self, Figures};
use super::grid::Point;
use super::{cpu_time, density};
use crate::run::runner::RunTarget;
use crate::scene::{RunOverrides, Scene, SceneSpec};

/// What became of a point.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum Outcome {
    /// It ran; its figures.
    Ran {
        /// The figures.
        figures: Figures,
        /// Changes the point needed besides its setting (e.g. a sensor rate fitted to the step).
        notes: Vec<String>,
    },
    /// The setting is not valid for the scene (e.g. a control period that is not a whole number
    /// of timesteps).
    Skipped {
        /// Why.
        reason: String,
    },
    /// It could not be set up.
    Failed {
        /// The error.
        error: String,
    },
}

/// A point and what became of it (`results.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PointResult {
    /// Index of the point in the study.
    pub id: usize,
    /// The point.
    #[serde(flatten)]
    pub point: Point,
    /// Its outcome.
    pub outcome: Outcome,
}

impl PointResult {
    /// The figures, when it ran.
    pub fn figures(&self) -> Option<&Figures> {
        match &self.outcome {
            Outcome::Ran { figures, .. } => Some(figures),
            _ => None,
        }
    }
}

/// Fits the sensor rates to `timestep_s`: each period becomes the nearest whole number of steps
/// (at least one). Returns a note per rate changed.
fn fit_sensor_rates(spec: &mut SceneSpec, timestep_s: f64) -> Vec<String> {
    let mut notes = Vec::new();
    let mut fit = |name: &str, hz: &mut f64| {
        let steps = (1.0 / (*hz * timestep_s)).round().max(1.0);
        let fitted = 1.0 / (steps * timestep_s);
        if (fitted - *hz).abs() > 1e-9 * *hz {
            notes.push(format!("{name} {hz} Hz -> {fitted:.1} Hz"));
            *hz = fitted;
        }
    };
    if let Some(s) = &mut spec.skin {
        fit("skin", &mut s.rate_hz);
    }
    if let Some(l) = &mut spec.lidar {
        fit("lidar", &mut l.rate_hz);
    }
    notes
}

/// Writes the point's controller setup (and its reduced layout) into `work`; returns the setup
/// file and the layout the scene must use.
fn write_variant(target: &RunTarget, point: &Point, id: usize, work: &Path) -> anyhow::Result<(PathBuf, SkinLayout)> {
    let (mut setup, source) = ControllerSetup::load(&target.controller)?;
    let dir = target.controller.parent().unwrap_or(Path::new(".")).canonicalize()?;
    if let Some(urdf) = &mut setup.urdf {
        *urdf = dir.join(&*urdf);
    }
    for p in [&mut setup.skin_model, &mut setup.tasks, &mut setup.supervisor, &mut setup.resolver] {
        *p = dir.join(&*p);
    }
    let layout = density::reduce(&SkinLayout::load(&dir.join(&setup.skin_layout))?, point.setting.density);
    let layout_file = work.join(format!("p{id:03}.layout.yaml"));
    let header =
        format!("{} at density {} (skin_sim sweep)", setup.skin_layout.display(), point.setting.density.name());
    std::fs::write(&layout_file, layout.to_yaml(&header))
        .with_context(|| format!("writing {}", layout_file.display()))?;
    setup.skin_layout = layout_file.canonicalize()?;
    setup.inverse = point.setting.inverse;
    let setup_file = work.join(format!("p{id:03}.controller.yaml"));
    let text = format!(
        "# {} with the study point's layout and inverse ({})\n{}",
        source,
        point.setting.label(),
        serde_saphyr::to_string(&setup)?
    );
    std::fs::write(&setup_file, text).with_context(|| format!("writing {}", setup_file.display()))?;
    Ok((setup_file, layout))
}

/// Runs point `id` of `target`, writing its variant files into `work`.
pub fn run(target: &RunTarget, point: &Point, id: usize, work: &Path) -> PointResult {
    let cpu_start = cpu_time::thread_cpu_s();
    let outcome = match prepare(target, point, id, work) {
        Err(e) => Outcome::Failed { error: format!("{e:#}") },
        Ok(Err(reason)) => Outcome::Skipped { reason },
        Ok(Ok((variant, scene, notes))) => {
            let limits: Vec<f64> = scene.model.joint_limits().iter().map(|l| l.velocity).collect();
            match variant.run_scene(scene, |_| {}) {
                Ok(report) => {
                    let cpu_s = cpu_time::thread_cpu_s().zip(cpu_start).map(|(end, start)| end - start);
                    Outcome::Ran { figures: figures::measure(&report, &limits, cpu_s), notes }
                }
                Err(e) => Outcome::Failed { error: e.to_string() },
            }
        }
    };
    PointResult { id, point: point.clone(), outcome }
}

/// The run target and scene of a point (inner Err: the setting does not fit the scene).
type Prepared = Result<(RunTarget, Scene, Vec<String>), String>;

fn prepare(target: &RunTarget, point: &Point, id: usize, work: &Path) -> anyhow::Result<Prepared> {
    let s = &point.setting;
    let mut scene = Scene::load(&target.scene)?;
    let notes = fit_sensor_rates(&mut scene.spec, s.timestep_s);
    let overrides = RunOverrides {
        duration_s: Some(point.duration_s),
        timestep_s: Some(s.timestep_s),
        control_rate_hz: Some(s.control_rate_hz),
        seed: None,
    };
    if let Err(e) = scene.override_run(&overrides) {
        return Ok(Err(e.to_string()));
    }
    let (controller, layout) = write_variant(target, point, id, work)?;
    scene.set_skin_layout(&layout)?;
    Ok(Ok((RunTarget { controller, ..target.clone() }, scene, notes)))
}
