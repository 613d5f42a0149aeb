//! One closed-loop run from start to report: load the scene (with run overrides), build the loop,
//! run it, compute the metrics and the outcome checks.

use std::path::PathBuf;

use crate::closed_loop::{ClosedLoop, LoopError};
use crate::metrics::{self, Limits};
use crate::outcome;
use crate::report::RunReport;
use crate::scenario::{self, ForceTargets, Scenario};
use crate::scene::{RunOverrides, Scene};

/// What to run: a scene, the controller setup for it, the targets it is judged on.
#[derive(Debug, Clone, PartialEq)]
pub struct RunTarget {
    /// Name in the report (the scenario's, or the scene file's stem).
    pub name: String,
    /// Scene file.
    pub scene: PathBuf,
    /// Controller setup file.
    pub controller: PathBuf,
    /// Paper 003 Table 3 targets, if any.
    pub force_targets: Option<ForceTargets>,
}

impl From<&Scenario> for RunTarget {
    fn from(s: &Scenario) -> Self {
        RunTarget {
            name: s.name.to_string(),
            scene: s.scene_file(),
            controller: s.controller_file(),
            force_targets: s.force_targets,
        }
    }
}

impl RunTarget {
    /// A scenario by name, or a scene file; `controller` overrides the scenario's setup and is
    /// required for a scene file that is not a scenario's.
    pub fn resolve(arg: &str, controller: Option<PathBuf>) -> Result<RunTarget, String> {
        let path = PathBuf::from(arg);
        let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let mut target = match (scenario::find(arg), path.is_file()) {
            (Some(s), _) => RunTarget::from(s),
            (None, true) => match scenario::find(&stem) {
                Some(s) => RunTarget { scene: path, ..RunTarget::from(s) },
                None => RunTarget {
                    name: stem,
                    controller: controller.clone().ok_or_else(|| {
                        format!("{arg} is not a scenario's scene file: give its controller setup with --controller")
                    })?,
                    scene: path,
                    force_targets: None,
                },
            },
            (None, false) => {
                let names: Vec<&str> = scenario::SCENARIOS.iter().map(|s| s.name).collect();
                return Err(format!("`{arg}` is neither a scenario ({}) nor a scene file", names.join(", ")));
            }
        };
        if let Some(c) = controller {
            target.controller = c;
        }
        Ok(target)
    }

    /// Runs it with `overrides`, calling `progress` with the fraction done after every cycle.
    pub fn run(&self, overrides: &RunOverrides, progress: impl FnMut(f64)) -> Result<RunReport, LoopError> {
        let mut scene = Scene::load(&self.scene).map_err(crate::world::WorldError::from)?;
        scene.override_run(overrides).map_err(crate::world::WorldError::from)?;
        self.run_scene(scene, progress)
    }

    /// Runs `scene`, this target's scene as loaded and possibly changed by the caller (the
    /// study's variants: sensor rates, a reduced skin layout), for its `duration_s`.
    pub fn run_scene(&self, scene: Scene, progress: impl FnMut(f64)) -> Result<RunReport, LoopError> {
        let duration = scene.spec.duration_s;
        let closed_loop = ClosedLoop::new(scene.clone(), &self.controller)?;
        let thresholds = closed_loop.controller().config().supervisor.thresholds;
        let limits = Limits {
            eps_c_n: thresholds.contact_force_n,
            goal_tolerance_m: thresholds.goal_tolerance_m,
        };
        let mut record = closed_loop.run(duration, progress);
        record.name = self.name.clone();
        let metrics = metrics::compute(&record, &scene, limits);
        let checks = outcome::checks(&metrics, self.force_targets);
        Ok(RunReport { record, metrics, checks })
    }
}
