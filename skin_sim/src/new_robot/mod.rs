//! A new robot from its URDF (`skin_setup`): from a few choices (the end-effector link, the arm
//! joints, the skinned links) the files to run it: a skin layout on the skinned links' collision
//! geometry, a controller setup, and a scene in which the end effector reaches a goal past a
//! movable obstacle (intentional-contact paper Sec. V on any arm). `docs/new-robot.md` walks
//! through it.
//!
//! The scene is placed by [`pose`]: a start configuration with the end effector low over the
//! floor and the arm well conditioned, a goal swept about a vertical arm joint, and a light
//! cylinder standing between them, a little off the straight path so that a push slides it aside.

pub mod base;
pub mod pose;
mod write;

use std::collections::BTreeMap;
use std::path::PathBuf;

use skin_core::mesh::{MeshMode, PackagePath};
use skin_core::model::RobotModel;
use skin_core::model::BASE_JOINTS;
use skin_core::skin::generate::{generate_layout, GeneratorSpec, LinkSelection, PatchFrame};
use skin_core::skin::layout::SkinLayout;
use thiserror::Error;

pub use write::{write_files, Written};

/// What the user chooses about a new robot.
#[derive(Debug, Clone, PartialEq)]
pub struct Choices {
    /// The URDF file.
    pub urdf: PathBuf,
    /// Name of the generated files (`<name>_controller.yaml`, `<name>_skin.yaml`, `<name>_scene.yaml`).
    pub name: String,
    /// The link whose origin reaches the goal.
    pub end_effector: String,
    /// The joints that move (none: every moving joint between the root and the end effector).
    pub arm_joints: Vec<String>,
    /// Keep the mobile base moving: the URDF's planar base joints (`skin_core::model::BASE_JOINTS`;
    /// `skin_setup` adds them with [`base::with_planar_base`] when the URDF has none) join the
    /// moving joints (never the arm's: the start configuration is searched with the base at 0).
    /// Without it a base is frozen.
    pub mobile_base: bool,
    /// Links to cover with skin (none: every link with collision geometry that an arm joint
    /// moves, fingers included, whatever touches the obstacle must feel it; those on which no
    /// cell fits are left out).
    pub skin_links: Vec<String>,
    /// Cell pitch \[m\].
    pub pitch_m: f64,
    /// Mesh collision elements: surfaces or fitted boxes, for the skin and the simulation alike.
    pub meshes: MeshMode,
    /// Directories searched for `package://` URIs (before ROS_PACKAGE_PATH, AMENT_PREFIX_PATH).
    pub package_path: Vec<PathBuf>,
    /// Start positions of joints by name (arm joints: the search keeps them; others: where they
    /// are frozen, default 0 clamped into their limits).
    pub initial: BTreeMap<String, f64>,
    /// The repository's `config/` directory (skin model, task, supervisor, resolver files).
    pub config_dir: PathBuf,
    /// Scene duration \[s\].
    pub duration_s: f64,
}

/// A choice the URDF cannot satisfy, or a file that could not be written.
#[derive(Debug, Error)]
pub enum SetupChoiceError {
    /// The URDF does not load.
    #[error(transparent)]
    Model(#[from] skin_core::model::ModelError),
    /// A named link or joint is not in the URDF, or cannot play its part.
    #[error("{urdf}: {option} `{name}`: {reason}")]
    Choice {
        /// The URDF.
        urdf: String,
        /// The option (`--end-effector`, `--arm-joints`, `--skin-links`, `--initial`).
        option: &'static str,
        /// The link or joint named.
        name: String,
        /// Why it does not work.
        reason: String,
    },
    /// The skin could not be generated (a mesh not found, no cell fits).
    #[error(transparent)]
    Skin(#[from] skin_core::skin::generate::GenerateError),
    /// No start configuration or goal satisfies the scene's conditions.
    #[error("{urdf}: {reason}")]
    Placement {
        /// The URDF.
        urdf: String,
        /// What could not be found.
        reason: String,
    },
    /// An output file.
    #[error("{file}: {error}")]
    Io {
        /// The file.
        file: String,
        /// Why.
        error: std::io::Error,
    },
}

/// The robot with the choices checked against it.
#[derive(Debug, Clone)]
pub struct Robot {
    /// The model (mimic joints independent, as the controller and the simulator load it).
    pub model: RobotModel,
    /// Frame of the end effector.
    pub ee: usize,
    /// Model indices of the arm joints, in model order.
    pub arm: Vec<usize>,
    /// Model indices of the base joints when the base moves (x, y, yaw), else empty.
    pub base: Vec<usize>,
    /// The generated skin layout.
    pub layout: SkinLayout,
    /// Where every joint starts or stays (the user's `initial`, else 0 clamped into the limits).
    pub q_default: Vec<f64>,
}

impl Choices {
    fn choice(&self, option: &'static str, name: &str, reason: impl Into<String>) -> SetupChoiceError {
        SetupChoiceError::Choice {
            urdf: self.urdf.display().to_string(),
            option,
            name: name.into(),
            reason: reason.into(),
        }
    }

    /// Loads the URDF, checks every choice against it and generates the skin layout.
    pub fn robot(&self) -> Result<Robot, SetupChoiceError> {
        let model = RobotModel::from_urdf_file(&self.urdf)?;
        let ee = model
            .frame_index(&self.end_effector)
            .ok_or_else(|| self.choice("--end-effector", &self.end_effector, "not a link of the URDF"))?;
        // The joints supporting the end effector, root first.
        let mut chain = Vec::new();
        let mut j = model.frame_parent_joint(ee);
        while let Some(k) = j {
            chain.push(k);
            j = model.joint_parent(k);
        }
        chain.reverse();
        let base_joint = |j: usize| BASE_JOINTS.contains(&model.joint_names()[j].as_str());
        chain.retain(|&j| !base_joint(j));
        if chain.is_empty() {
            return Err(self.choice("--end-effector", &self.end_effector, "fixed to the root: no joint moves it"));
        }
        let arm = if self.arm_joints.is_empty() {
            chain.clone()
        } else {
            let mut arm = Vec::new();
            for name in &self.arm_joints {
                let k = model
                    .joint_index(name)
                    .ok_or_else(|| self.choice("--arm-joints", name, "not a moving joint of the URDF"))?;
                if !chain.contains(&k) {
                    let link = &self.end_effector;
                    return Err(self.choice("--arm-joints", name, format!("does not move the end effector `{link}`")));
                }
                arm.push(k);
            }
            arm.sort_unstable();
            arm.dedup();
            arm
        };
        for &j in &arm {
            let l = model.joint_limits()[j];
            if !(l.velocity.is_finite() && l.velocity > 0.0 && l.effort.is_finite() && l.effort > 0.0) {
                let reason = format!(
                    "velocity limit {}, effort limit {}: the simulator's velocity servo needs both finite and > 0",
                    l.velocity, l.effort
                );
                return Err(self.choice("--arm-joints", &model.joint_names()[j], reason));
            }
        }
        let base = if self.mobile_base {
            BASE_JOINTS
                .iter()
                .map(|b| {
                    model.joint_index(b).ok_or_else(|| {
                        let reason =
                            format!("the URDF has no joint `{b}` (a mobile base is the joints {BASE_JOINTS:?})");
                        self.choice("--mobile-base", b, reason)
                    })
                })
                .collect::<Result<Vec<_>, _>>()?
        } else {
            Vec::new()
        };
        if arm.len() < 3 {
            return Err(self.choice(
                "--arm-joints",
                &self.arm_joints.join(","),
                format!("{} joint(s) move the end effector: a position goal needs at least 3", arm.len()),
            ));
        }
        let skin_links: Vec<String> = if self.skin_links.is_empty() {
            (0..model.nframes())
                .filter(|&f| !model.link_collisions(f).is_empty())
                .filter(|&f| {
                    model.frame_parent_joint(f).is_some_and(|b| arm.iter().any(|&a| model.joint_supports(a, b)))
                })
                .map(|f| model.frame_names()[f].clone())
                .collect()
        } else {
            for l in &self.skin_links {
                let f = model.frame_index(l).ok_or_else(|| self.choice("--skin-links", l, "not a link of the URDF"))?;
                if model.link_collisions(f).is_empty() {
                    return Err(self.choice("--skin-links", l, "has no collision geometry to put cells on"));
                }
                if !model.frame_parent_joint(f).is_some_and(|b| arm.iter().any(|&a| model.joint_supports(a, b))) {
                    return Err(self.choice("--skin-links", l, "no arm joint moves it"));
                }
            }
            self.skin_links.clone()
        };
        if skin_links.is_empty() {
            return Err(self.choice("--skin-links", "", "no link moved by the arm joints has collision geometry"));
        }
        let spec = GeneratorSpec {
            links: skin_links.iter().map(|l| LinkSelection { link: l.clone(), collisions: None }).collect(),
            pitch_m: self.pitch_m,
            faces: Vec::new(),
            spheres: true,
            caps: true,
            patch_frame: PatchFrame::Link,
            meshes: self.meshes,
            package_path: PackagePath::from_env(&self.package_path),
            skip_empty: self.skin_links.is_empty(),
        };
        let layout = generate_layout(&model, &spec)?;
        let mut q_default = vec![0.0; model.nv()];
        for (j, q) in q_default.iter_mut().enumerate() {
            let l = model.joint_limits()[j];
            *q = 0f64.clamp(l.lower, l.upper);
        }
        for (name, &q) in &self.initial {
            let j = model
                .joint_index(name)
                .ok_or_else(|| self.choice("--initial", name, "not a moving joint of the URDF"))?;
            let l = model.joint_limits()[j];
            if !(l.lower..=l.upper).contains(&q) {
                return Err(self.choice(
                    "--initial",
                    name,
                    format!("{q} outside the limits [{}, {}]", l.lower, l.upper),
                ));
            }
            q_default[j] = q;
        }
        Ok(Robot { model, ee, arm, base, layout, q_default })
    }
}
