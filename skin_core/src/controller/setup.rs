//! What a controller is made of: the setup file (`config/controller/<robot>.yaml`) names the
//! URDF, the skin layout and every parameter file, and the frames and patches the tasks act on;
//! [`ControllerConfig::load`] reads and validates all of them.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::hierarchy::{HierarchyError, InverseParams};
use crate::model::{ModelError, RobotModel};
use crate::resolver::{ResolverError, ResolverParams};
use crate::skin::layout::{LayoutError, ResolvedLayout, SkinLayout};
use crate::skin::params::{ParamsError, SkinParams};
use crate::skin::yaml::{self, YamlError};
use crate::supervisor::{ParamError, Policy, SupervisorParams, SupervisorParamsError};
use crate::tasks::params::TaskParams;
use crate::tasks::TaskError;

/// The setup file: paths (relative to the setup file's directory) and the task frames.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerSetup {
    /// Robot URDF.
    pub urdf: PathBuf,
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
    /// Overrides the supervisor file's policy (e.g. `phases` for paper 003's experiments with
    /// the same arrangements file).
    #[serde(default)]
    pub policy: Option<Policy>,
    /// Frame of the end effector / hand: the goal, hand force, wrist, tactile guidance and
    /// position-hold tasks act on its origin.
    pub end_effector: String,
    /// Patch ids of the hand (paper 003 eq. (9)-(10): the hand force signal and the wrist
    /// moment). Empty: those tasks see no signal.
    #[serde(default)]
    pub hand_patches: Vec<u32>,
    /// Patch ids whose touches guide the hand (paper 003 eq. (11), the arm patches).
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

impl ControllerConfig {
    /// Reads the setup file at `path` and everything it names (paths relative to its directory).
    pub fn load(path: &Path) -> Result<Self, SetupError> {
        let (text, source) = yaml::read_text(path)?;
        let setup: ControllerSetup = yaml::parse_str(&text, &source)?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let at = |p: &Path| dir.join(p);
        let model = RobotModel::from_urdf_file(&at(&setup.urdf))?;
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
