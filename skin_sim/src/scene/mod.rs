//! Scenes: what a simulation run contains (`config/scenes/*.yaml`, schema in [`spec`], documented
//! in `docs/scenes.md`), loaded and validated against the robot model and the skin layout with
//! errors that name the file, the dotted key and the reason, e.g.
//! `config/scenes/x.yaml: objects[1].shape.box.size_m: -0.1 must be finite and > 0`.

mod check;
pub mod spec;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use skin_core::mesh::{self, PackagePath, TriMesh};
use skin_core::model::BASE_JOINTS;
use skin_core::model::{RobotModel, Shape};
use skin_core::param_file::yaml::{self, YamlError};
use skin_core::skin::layout::{ResolvedLayout, SkinLayout};
use skin_core::skin::params::SkinParams;
use thiserror::Error;

use check::{reject, Rejected};
pub use spec::*;

/// The repository's `config/` directory (scenes and controller setups).
pub fn config_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../config")
}

/// A scene file that could not be loaded.
#[derive(Debug, Error)]
pub enum SceneError {
    /// Unreadable file, invalid YAML, an unknown or missing key, a value of the wrong type.
    #[error(transparent)]
    Yaml(#[from] YamlError),
    /// A value that is invalid, or names something that does not exist.
    #[error("{file}: `{key}`: {reason}")]
    Invalid {
        /// The scene file.
        file: String,
        /// Dotted key of the value, e.g. `pushes[0].end_s`.
        key: String,
        /// Why it is invalid.
        reason: String,
    },
}

/// The skin of a scene: the layout resolved against the robot, its characteristics, and which
/// cells sense.
#[derive(Debug, Clone)]
pub struct SceneSkin {
    /// The layout; per-cell arrays of the simulation are indexed like its cells.
    pub layout: ResolvedLayout,
    /// Cell characteristics (proximity and force signals).
    pub params: SkinParams,
    /// Per cell: whether its patch is in the scene's subset (`skin.patches`).
    pub active: Vec<bool>,
}

/// Run settings that replace a scene file's ([`Scene::override_run`]); None keeps the file's.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RunOverrides {
    /// `duration_s` \[s\].
    pub duration_s: Option<f64>,
    /// `timestep_s` \[s\].
    pub timestep_s: Option<f64>,
    /// `control_rate_hz` \[Hz\].
    pub control_rate_hz: Option<f64>,
    /// `seed`.
    pub seed: Option<u64>,
}

/// A validated scene with everything it refers to loaded.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The file as written.
    pub spec: SceneSpec,
    /// The scene file (for messages).
    pub file: String,
    /// The robot model from `robot.urdf`.
    pub model: RobotModel,
    /// Per model joint: whether it moves in the simulation (else frozen at `q0`).
    pub moving: Vec<bool>,
    /// Per model joint: the initial position (kept joints) or the fixed one (frozen joints).
    pub q0: Vec<f64>,
    /// The skin, when the scene has one.
    pub skin: Option<SceneSkin>,
    /// The URDF text of the robot (what `/robot_description` carries).
    pub robot_description: String,
    /// The mesh collision elements of the robot, by (frame, collision index), read from their files.
    pub meshes: BTreeMap<(usize, usize), TriMesh>,
}

impl Scene {
    /// Loads and validates a scene file; relative paths in it are relative to its directory.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let (text, file) = yaml::read_text(path)?;
        let dir = path.parent().unwrap_or(Path::new("."));
        Self::from_yaml_str(&text, &file, dir)
    }

    /// Parses and validates scene text; `source` names it in errors, `dir` anchors relative paths.
    pub fn from_yaml_str(text: &str, source: &str, dir: &Path) -> Result<Scene, SceneError> {
        let spec: SceneSpec = yaml::parse_str(text, source)?;
        let invalid = |r: Rejected| SceneError::Invalid { file: source.to_string(), key: r.key, reason: r.reason };
        check::check_values(&spec).map_err(invalid)?;
        let urdf = resolve(dir, &spec.robot.urdf);
        let robot_description = std::fs::read_to_string(&urdf)
            .map_err(|e| invalid(reject("robot.urdf", format!("{}: {e}", urdf.display()))))?;
        let model = RobotModel::from_urdf_str(&robot_description, &urdf.display().to_string())
            .map_err(|e| invalid(reject("robot.urdf", e.to_string())))?;
        let dirs: Vec<PathBuf> = spec.robot.package_path.iter().map(|p| resolve(dir, p)).collect();
        let meshes = load_meshes(&model, &urdf, &PackagePath::from_env(&dirs)).map_err(invalid)?;
        let (moving, q0) = joint_setup(&spec.robot, &model).map_err(invalid)?;
        check_frames(&spec, &model).map_err(invalid)?;
        let base_moves = (0..model.nv()).filter(|&j| model.is_base_joint(j)).any(|j| moving[j]);
        if !spec.base_motions.is_empty() && !base_moves {
            return Err(invalid(reject(
                "base_motions",
                "the scene's base does not move (keep the base joints in robot.joints)",
            )));
        }
        let skin = match &spec.skin {
            Some(s) => Some(load_skin(s, dir, &model).map_err(invalid)?),
            None => None,
        };
        Ok(Scene { spec, file: source.to_string(), model, moving, q0, skin, robot_description, meshes })
    }

    /// Replaces the run settings (`duration_s`, `timestep_s`, `control_rate_hz`, `seed`; None
    /// keeps the file's value) and checks the scene's values again (every rate's period must
    /// still be a whole number of steps).
    pub fn override_run(&mut self, run: &RunOverrides) -> Result<(), SceneError> {
        let spec = &mut self.spec;
        spec.duration_s = run.duration_s.unwrap_or(spec.duration_s);
        spec.timestep_s = run.timestep_s.unwrap_or(spec.timestep_s);
        spec.control_rate_hz = run.control_rate_hz.unwrap_or(spec.control_rate_hz);
        spec.seed = run.seed.unwrap_or(spec.seed);
        check::check_values(spec).map_err(|r| SceneError::Invalid {
            file: self.file.clone(),
            key: r.key,
            reason: r.reason,
        })
    }

    /// Replaces the skin layout with `layout` (e.g. fewer cells on the same patches), keeping the
    /// characteristics and the sensing patches (`skin.patches`).
    pub fn set_skin_layout(&mut self, layout: &SkinLayout) -> Result<(), SceneError> {
        let invalid = |r: Rejected| SceneError::Invalid { file: self.file.clone(), key: r.key, reason: r.reason };
        let patches = self.spec.skin.as_ref().and_then(|s| s.patches.clone());
        let skin = self.skin.as_mut().ok_or_else(|| invalid(reject("skin", "the scene has no skin to replace")))?;
        let resolved = layout.resolve(&self.model).map_err(|e| invalid(reject("skin.layout", e.to_string())))?;
        skin.active = active_cells(&resolved, patches.as_deref()).map_err(invalid)?;
        skin.layout = resolved;
        Ok(())
    }

    /// Model indices of the base joints (x, y, yaw) when the base moves in this scene.
    pub fn moving_base(&self) -> Option<[usize; 3]> {
        self.model.planar_base().filter(|[x, _, _]| self.moving[*x])
    }
}

fn resolve(dir: &Path, p: &Path) -> PathBuf {
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        dir.join(p)
    }
}

/// Every mesh collision element of `model` (the URDF file `urdf`), read.
fn load_meshes(
    model: &RobotModel,
    urdf: &Path,
    path: &PackagePath,
) -> Result<BTreeMap<(usize, usize), TriMesh>, Rejected> {
    let mut out = BTreeMap::new();
    for f in 0..model.nframes() {
        for (i, c) in model.link_collisions(f).iter().enumerate() {
            if let Shape::Mesh { filename, scale } = &c.shape {
                let m = mesh::load_uri(filename, scale, urdf, path)
                    .map_err(|e| reject("robot.urdf", format!("link `{}`: {e}", model.frame_names()[f])))?;
                out.insert((f, i), m);
            }
        }
    }
    Ok(out)
}

/// Which joints move and where every joint starts, in model order.
fn joint_setup(robot: &RobotSpec, model: &RobotModel) -> Result<(Vec<bool>, Vec<f64>), Rejected> {
    let n = model.nv();
    let mut moving = vec![robot.joints.is_none(); n];
    for (i, name) in robot.joints.iter().flatten().enumerate() {
        let j = model.joint_index(name).ok_or_else(|| {
            reject(format!("robot.joints[{i}]"), format!("`{name}` is not a moving joint of the URDF"))
        })?;
        moving[j] = true;
    }
    let base: Vec<usize> = BASE_JOINTS.iter().filter_map(|b| model.joint_index(b)).collect();
    if base.iter().any(|&j| moving[j]) && !base.iter().all(|&j| moving[j]) {
        return Err(reject("robot.joints", format!("keep all of {BASE_JOINTS:?} or none")));
    }
    let mut q0 = vec![0.0; n];
    for (name, &q) in &robot.initial {
        let key = format!("robot.initial.{name}");
        let j = model.joint_index(name).ok_or_else(|| reject(&key, "not a moving joint of the URDF"))?;
        let lim = model.joint_limits()[j];
        if q < lim.lower || q > lim.upper {
            return Err(reject(key, format!("{q} outside the joint limits [{}, {}]", lim.lower, lim.upper)));
        }
        q0[j] = q;
    }
    Ok((moving, q0))
}

/// Every link or frame a scene names exists in the model.
fn check_frames(spec: &SceneSpec, model: &RobotModel) -> Result<(), Rejected> {
    let frame = |key: String, name: &str| match model.frame_index(name) {
        Some(_) => Ok(()),
        None => Err(reject(key, format!("`{name}` is not a link of the URDF"))),
    };
    for (i, p) in spec.pushes.iter().enumerate() {
        if let Some(link) = &p.link {
            frame(format!("pushes[{i}].link"), link)?;
        }
    }
    for (i, g) in spec.goals.iter().enumerate() {
        frame(format!("goals[{i}].frame"), &g.frame)?;
    }
    if let Some(l) = &spec.lidar {
        frame("lidar.frame".into(), &l.frame)?;
        if model.planar_base().is_none() {
            return Err(reject("lidar", "the robot has no mobile base (no base frame for the scan)"));
        }
    }
    Ok(())
}

fn load_skin(s: &SkinSpec, dir: &Path, model: &RobotModel) -> Result<SceneSkin, Rejected> {
    let layout = SkinLayout::load(&resolve(dir, &s.layout))
        .and_then(|l| l.resolve(model))
        .map_err(|e| reject("skin.layout", e.to_string()))?;
    let params = SkinParams::load(&resolve(dir, &s.params)).map_err(|e| reject("skin.params", e.to_string()))?;
    let active = active_cells(&layout, s.patches.as_deref())?;
    Ok(SceneSkin { layout, params, active })
}

/// Per cell of `layout`: whether its patch is in `patches` (None: all patches sense).
fn active_cells(layout: &ResolvedLayout, patches: Option<&[u32]>) -> Result<Vec<bool>, Rejected> {
    let mut active_patch = vec![patches.is_none(); layout.patches().len()];
    for (i, id) in patches.iter().copied().flatten().enumerate() {
        let k = layout
            .patch_index(*id)
            .ok_or_else(|| reject(format!("skin.patches[{i}]"), format!("no patch {id} in the layout")))?;
        active_patch[k] = true;
    }
    Ok(layout.cells().iter().map(|c| active_patch[c.patch]).collect())
}
