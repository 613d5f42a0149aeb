//! What a controller is made of: the setup file (`config/controller/<robot>.yaml`) names the
//! URDF, the skin layout and every parameter file, and the frames and patches the tasks act on;
//! [`ControllerConfig::load`] reads and validates all of them.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::hierarchy::{HierarchyError, InverseParams};
use crate::model::{ModelError, RobotModel};
use crate::param_file::yaml::{self, YamlError};
use crate::param_file::ParamsError;
use crate::resolver::{ResolverError, ResolverParams};
use crate::skin::layout::{LayoutError, ResolvedLayout, SkinLayout};
use crate::skin::params::SkinParams;
use crate::supervisor::{ParamError, Policy, SupervisorParams, SupervisorParamsError};
use crate::tasks::params::TaskParams;
use crate::tasks::TaskError;

/// The setup file: paths (relative to the setup file's directory) and the task frames.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerSetup {
    /// Robot URDF. Optional: a caller may give the robot's model instead
    /// ([`ControllerConfig::load_with_model`]; the ROS node takes it from `robot_description`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub urdf: Option<PathBuf>,
    /// Skin layout (`skin::layout::SkinLayout`).
    pub skin_layout: PathBuf,
    /// Skin model parameters (`SkinParams`).
    pub skin_model: PathBuf,
    /// Task parameters (`TaskParams`).
    pub tasks: PathBuf,
    /// Supervisor parameters: task names, arrangements, policy (`SupervisorParams`).
    pub supervisor: PathBuf,
    /// Resolver parameters (`ResolverParams`).
    pub resolver: PathBuf,
    /// Overrides the supervisor file's policy (e.g. `phases` for interactive-force-control paper's experiments with
    /// the same arrangements file).
    #[serde(default)]
    pub policy: Option<Policy>,
    /// Frame of the end effector / hand: the goal, hand force, wrist, tactile guidance and
    /// position-hold tasks act on its origin.
    pub end_effector: String,
    /// Patch ids of the hand (interactive-force-control paper eq. (9)-(10): the hand force signal and the wrist
    /// moment). Empty: those tasks see no signal.
    #[serde(default)]
    pub hand_patches: Vec<u32>,
    /// Patch ids whose touches guide the hand (interactive-force-control paper eq. (11), the arm patches).
    #[serde(default)]
    pub guidance_patches: Vec<u32>,
    /// Joints held still (e.g. TOMM's base when it is switched off, or a scene that freezes it):
    /// no task uses them, they get no torque and a zero command.
    #[serde(default)]
    pub locked_joints: Vec<String>,
    /// Desired posture `q_post` of eq. (18), model joint order; empty: all zeros.
    #[serde(default)]
    pub posture: Vec<f64>,
    /// The damped, rank-aware inverse of the hierarchy (`docs/hierarchy.md`).
    #[serde(default)]
    pub inverse: InverseParams,
    /// The dynamics the hierarchy (interactive-force-control paper eq. 19-25) is solved with.
    #[serde(default)]
    pub hierarchy_dynamics: HierarchyDynamics,
}

/// Which inertia and bias the hierarchy projects with.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HierarchyDynamics {
    /// The model's `M(q)` and `C q̇ + g`, as in interactive-force-control paper eq. (23). The resolver then executes
    /// the torque with its own `M_a`, `C_a` (eq. 26), so the executed motion is not the one the
    /// projection decoupled: intentional-contact paper's force levels are tuned with it.
    #[default]
    Model,
    /// The resolver's virtual dynamics (`Resolver::virtual_mass`, `virtual_damping`: `M_a`, `M_b`, bias
    /// `g + C_a q̇`): the executed acceleration is the hierarchy's, so strict priority holds in the
    /// motion the robot makes (interactive-force-control paper's acceleration levels: hand force, wrist).
    Admittance,
    /// The resolver's virtual inertia (`M_a`, `M_b`) with the bias `g` alone: for the force levels
    /// of the intentional-contact paper (eq. 2-9), which bring their own damping (eq. 8) and leave
    /// the resolver's `C_a` to damp the rest. The resolver executes `M_a q̈ + C_a q̇ = τ* − g`; with
    /// `C_a` proportional to `M_a` on the moving joints (as shipped: 10 / 0.5 on every arm joint)
    /// a lower level then moves nothing a higher level controls, in the acceleration and in the
    /// steady velocity (`docs/controller.md`: the projection leak). In the goal's range the bias
    /// also replaces `C_a` with the goal's own damping (`controller::goal_damping`).
    AdmittanceInertia,
}

/// Everything a [`super::Controller`] is built from, loaded and validated.
#[derive(Debug, Clone)]
pub struct ControllerConfig {
    /// The robot model.
    pub model: RobotModel,
    /// The skin layout resolved against the model.
    pub layout: ResolvedLayout,
    /// Skin characteristics, fusion, repulsion.
    pub skin: SkinParams,
    /// Task gains.
    pub tasks: TaskParams,
    /// Task names, arrangements, thresholds.
    pub supervisor: SupervisorParams,
    /// Admittance and limits.
    pub resolver: ResolverParams,
    /// Paths and frames as in the setup file.
    pub setup: ControllerSetup,
    /// The setup file (named in errors).
    pub source: String,
}

/// Why a controller could not be set up. Every variant names the file (and key) at fault.
#[derive(Debug, Error)]
pub enum SetupError {
    /// The setup file itself.
    #[error(transparent)]
    Yaml(#[from] YamlError),
    /// The URDF.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The skin layout.
    #[error(transparent)]
    Layout(#[from] LayoutError),
    /// The skin model, task or resolver parameter file.
    #[error(transparent)]
    Params(#[from] ParamsError),
    /// The supervisor parameter file.
    #[error(transparent)]
    Supervisor(#[from] SupervisorParamsError),
    /// Supervisor parameters given in code that do not validate.
    #[error("supervisor parameters: {0}")]
    SupervisorParams(#[from] ParamError),
    /// Resolver parameters that do not fit the model.
    #[error("{file}: {error}")]
    Resolver {
        /// The resolver file.
        file: String,
        /// What does not fit.
        error: ResolverError,
    },
    /// The hierarchy's inverse parameters.
    #[error("{file}: inverse.{error}")]
    Inverse {
        /// The setup file.
        file: String,
        /// The invalid parameter.
        error: HierarchyError,
    },
    /// A task could not be built (gain vector lengths, base joints).
    #[error("{file}: {error}")]
    Task {
        /// The file at fault.
        file: String,
        /// What.
        error: TaskError,
    },
    /// A value of the setup file that does not fit the model, layout or supervisor.
    #[error("{file}: `{key}`: {reason}")]
    Invalid {
        /// The setup file.
        file: String,
        /// Dotted key.
        key: String,
        /// Why.
        reason: String,
    },
}

/// How many `base` files a setup may derive through (a cycle ends here with an error).
const MAX_BASE_DEPTH: usize = 8;

impl ControllerSetup {
    /// Reads the setup file at `path`; returns it with the file's name (for errors). A file with
    /// a `base` key (another setup file, relative to this one) holds only its differences: each
    /// of its keys replaces the base's value of that key, and the base's paths are made relative
    /// to this file's directory. An error names the file that sets the key at fault.
    pub fn load(path: &Path) -> Result<(Self, String), SetupError> {
        read_setup(path, 0)
    }
}

/// [`ControllerSetup::load`] at `depth` bases below the file the caller named.
fn read_setup(path: &Path, depth: usize) -> Result<(ControllerSetup, String), SetupError> {
    let (text, source) = yaml::read_text(path)?;
    let mut layer: serde_json::Map<String, serde_json::Value> = yaml::parse_str(&text, &source)?;
    let Some(base) = layer.remove("base") else {
        return Ok((yaml::parse_str(&text, &source)?, source));
    };
    let invalid = |key: &str, reason: String| SetupError::Invalid { file: source.clone(), key: key.into(), reason };
    let base = base.as_str().map(PathBuf::from).ok_or_else(|| invalid("base", "must be a file name".into()))?;
    if depth >= MAX_BASE_DEPTH {
        return Err(invalid("base", format!("more than {MAX_BASE_DEPTH} bases (a cycle?)")));
    }
    let (mut merged, _) = read_setup(&path.parent().unwrap_or(Path::new(".")).join(&base), depth + 1)?;
    // the base's file paths, relative to the base's directory, made relative to this one's
    let base_dir = base.parent().unwrap_or(Path::new(""));
    if let Some(urdf) = &mut merged.urdf {
        *urdf = base_dir.join(&*urdf);
    }
    for p in [
        &mut merged.skin_layout,
        &mut merged.skin_model,
        &mut merged.tasks,
        &mut merged.supervisor,
        &mut merged.resolver,
    ] {
        *p = base_dir.join(&*p);
    }
    let serde_json::Value::Object(mut merged) = serde_json::to_value(&merged).expect("a setup serializes") else {
        unreachable!("a struct serializes to an object")
    };
    // key by key over the (valid) base, so that a bad value is named by its key
    for (key, value) in layer {
        let mut one = merged.clone();
        one.insert(key.clone(), value.clone());
        serde_json::from_value::<ControllerSetup>(serde_json::Value::Object(one))
            .map_err(|e| invalid(&key, e.to_string()))?;
        merged.insert(key, value);
    }
    let setup =
        serde_json::from_value(serde_json::Value::Object(merged)).map_err(|e| invalid("base", e.to_string()))?;
    Ok((setup, source))
}

impl ControllerConfig {
    /// Reads the setup file at `path` and everything it names (paths relative to its directory);
    /// the setup must name the URDF.
    pub fn load(path: &Path) -> Result<Self, SetupError> {
        Self::load_with_model(path, None)
    }

    /// [`Self::load`] with the robot's model given by the caller (`Some`: the setup's `urdf`, if
    /// any, is not read), else the URDF the setup names (an error names the `urdf` key when there
    /// is none).
    pub fn load_with_model(path: &Path, model: Option<RobotModel>) -> Result<Self, SetupError> {
        let (setup, source) = ControllerSetup::load(path)?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let at = |p: &Path| dir.join(p);
        let model = match (model, &setup.urdf) {
            (Some(model), _) => model,
            (None, Some(urdf)) => RobotModel::from_urdf_file(&at(urdf))?,
            (None, None) => {
                let reason = "not given: name the robot's URDF file (relative to this file)".to_string();
                return Err(SetupError::Invalid { file: source, key: "urdf".into(), reason });
            }
        };
        let layout = SkinLayout::load(&at(&setup.skin_layout))?.resolve(&model)?;
        let mut supervisor = SupervisorParams::load(&at(&setup.supervisor))?;
        supervisor.policy = setup.policy.unwrap_or(supervisor.policy);
        Ok(ControllerConfig {
            skin: SkinParams::load(&at(&setup.skin_model))?,
            tasks: TaskParams::load(&at(&setup.tasks))?,
            supervisor,
            resolver: ResolverParams::load(&at(&setup.resolver))?,
            model,
            layout,
            setup,
            source,
        })
    }

    /// An [`SetupError::Invalid`] for `key` of the setup file.
    pub(crate) fn invalid(&self, key: impl Into<String>, reason: impl Into<String>) -> SetupError {
        SetupError::Invalid { file: self.source.clone(), key: key.into(), reason: reason.into() }
    }

    /// Indices into `layout.patches()` of the patch ids listed under `key`, as a per-patch mask.
    pub(crate) fn patch_mask(&self, key: &str, ids: &[u32]) -> Result<Vec<bool>, SetupError> {
        let mut mask = vec![false; self.layout.patches().len()];
        for (i, &id) in ids.iter().enumerate() {
            let k = self
                .layout
                .patch_index(id)
                .ok_or_else(|| self.invalid(format!("{key}[{i}]"), format!("patch {id} is not in the layout")))?;
            mask[k] = true;
        }
        Ok(mask)
    }
}
