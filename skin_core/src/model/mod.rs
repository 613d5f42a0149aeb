//! Robot model (immutable, from a URDF) and its preallocated data workspace.
//!
//! [`RobotModel`] is a kinematic tree of one-degree-of-freedom joints (revolute, continuous,
//! prismatic) built from a URDF; links joined by fixed joints are merged into the moving body
//! they hang from, and every URDF link stays available as a *frame* with a constant placement in
//! that body (like pinocchio's frames). Mimic joints are independent joints (pinocchio's
//! default) or follow their leader (one generalized coordinate), see [`UrdfOptions`]; the rules
//! of loading are in docs/dynamics.md, "Loading any URDF". [`ModelData`] holds everything the algorithms compute;
//! after [`ModelData::new`] no function of this module allocates.
//!
//! Typical use:
//! ```no_run
//! use skin_core::model::*;
//! let model = RobotModel::from_urdf_file(std::path::Path::new("urdf/tomm.urdf")).unwrap();
//! let mut data = ModelData::new(&model);
//! let (q, qd) = (vec!(0.0; model.nv()), vec!(0.0; model.nv()));
//! update_kinematics(&model, &mut data, &q, &qd).unwrap();
//! let mut m = nalgebra::DMatrix::zeros(model.nv(), model.nv());
//! crba(&model, &mut data, &mut m).unwrap();
//! ```

mod crba;
mod error;
mod inertia_check;
mod kinematics;
mod rnea;
pub mod spatial;
mod urdf;
mod urdf_xml;

#[cfg(test)]
mod tests;

pub use crba::crba;
pub use error::ModelError;
pub use kinematics::{
    frame_pose, point_jacobian, point_jacobian_along, point_jacobian_dot_qdot, point_velocity, update_kinematics,
};
pub use rnea::{bias_forces, gravity, rnea};

use nalgebra::{Isometry3, Matrix3, Vector3};
use spatial::{SVec, SpatialInertia};

/// Standard gravity (m/s²); gravity acts along world -z.
pub const STANDARD_GRAVITY: f64 = 9.81;

/// Joint limits as given in the URDF `<limit>` element (continuous joints: ±∞ position).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointLimits {
    /// Lower position limit (rad or m).
    pub lower: f64,
    /// Upper position limit (rad or m).
    pub upper: f64,
    /// Velocity limit (rad/s or m/s).
    pub velocity: f64,
    /// Effort limit (N m or N).
    pub effort: f64,
}

/// Kind of a moving joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation about the joint axis (URDF `revolute` and `continuous`).
    Revolute,
    /// Translation along the joint axis (URDF `prismatic`).
    Prismatic,
}

/// Collision primitive of a link, in the link frame (URDF conventions: cylinders and capsules
/// along their local z axis, centred at their origin; box `size` is the full edge lengths).
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// Box with full edge lengths (m).
    Box {
        /// Edge lengths along local x, y, z (m).
        size: Vector3<f64>,
    },
    /// Cylinder along local z.
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Length (m).
        length: f64,
    },
    /// Sphere.
    Sphere {
        /// Radius (m).
        radius: f64,
    },
    /// Capsule along local z (`length` between the centres of the end caps).
    Capsule {
        /// Radius (m).
        radius: f64,
        /// Length of the cylindrical part (m).
        length: f64,
    },
    /// Mesh (kept for completeness; skin tiling and this project's URDFs use primitives only).
    Mesh {
        /// Mesh file name as written in the URDF.
        filename: String,
        /// Scale factors.
        scale: Vector3<f64>,
    },
}

/// One `<collision>` element of a link.
#[derive(Clone, Debug, PartialEq)]
pub struct Collision {
    /// Optional `name` attribute.
    pub name: Option<String>,
    /// Placement of the primitive in the link frame.
    pub origin: Isometry3<f64>,
    /// The primitive.
    pub shape: Shape,
}

/// How mimic joints (`<mimic joint multiplier offset>`) enter the model.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MimicMode {
    /// Every mimic joint is an independent joint with its own coordinate; the `<mimic>` element
    /// is ignored (pinocchio's default, `buildModelFromUrdf(..., mimic=False)`).
    #[default]
    Independent,
    /// A mimic joint follows its leader: `q_joint = multiplier · q_leader + offset`, no coordinate
    /// of its own; the Jacobian and mass matrix are composed accordingly (pinocchio's
    /// `mimic=True`). The leader's coordinate keeps the leader's name and limits.
    Follow,
}

/// Options of URDF loading.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UrdfOptions {
    /// Mimic joints: independent (default) or following their leader.
    pub mimic: MimicMode,
}

/// One moving body: a 1-DoF joint and everything rigidly attached after it.
#[derive(Clone, Debug)]
pub(crate) struct Body {
    pub(crate) parent: Option<usize>,
    /// Frame index of the joint's child link.
    pub(crate) frame: usize,
    pub(crate) kind: JointKind,
    /// Unit joint axis in the joint (= body) frame.
    pub(crate) axis: Vector3<f64>,
    /// Joint frame at q = 0 in the parent body frame (or the world).
    pub(crate) placement: Isometry3<f64>,
    /// Generalized coordinate that drives the joint: joint value = `multiplier · q[coord] + offset`
    /// (coord = own index, 1, 0 unless a followed mimic joint).
    pub(crate) coord: usize,
    pub(crate) multiplier: f64,
    pub(crate) offset: f64,
    /// Merged inertia of the body: mass, centre of mass and inertia about it, body frame.
    pub(crate) mass: f64,
    pub(crate) com: Vector3<f64>,
    pub(crate) inertia_com: Matrix3<f64>,
}

/// One frame (= one URDF link).
#[derive(Clone, Debug)]
pub(crate) struct Frame {
    pub(crate) body: Option<usize>,
    pub(crate) placement: Isometry3<f64>,
    /// `placement` is exactly the identity (the joint's own child link): pose copied, not composed.
    pub(crate) placement_is_identity: bool,
    pub(crate) collisions: Vec<Collision>,
}

/// Names of the holonomic base's joints in a model: world-frame x, y (prismatic) and yaw.
/// A model has all three (a mobile robot) or none (a fixed arm).
pub const BASE_JOINTS: [&str; 3] = ["base_x_joint", "base_y_joint", "base_yaw_joint"];

/// Whether a joint called `name` is one of the holonomic base's joints, for a record that keeps
/// only the names (use [`RobotModel::is_base_joint`] with a model).
pub fn is_base_joint_name(name: &str) -> bool {
    BASE_JOINTS.contains(&name)
}

/// Immutable robot model built from a URDF. Joint order ("model order") is depth-first from the
/// root link, children in document order; it is the order of every q, q̇, τ vector.
///
/// Two index spaces: the *moving joints* of the tree (`0..njoints()`, the `joint_*` structure
/// accessors and [`ModelData`]'s per-joint poses) and the *generalized coordinates*
/// (`0..nv()`, every q, q̇, τ, Jacobian column, and [`RobotModel::joint_names`]). They are the
/// same unless mimic joints follow their leaders ([`MimicMode::Follow`]); then
/// [`RobotModel::joint_coordinate`] maps one to the other.
#[derive(Clone, Debug)]
pub struct RobotModel {
    pub(crate) name: String,
    pub(crate) source: String,
    pub(crate) bodies: Vec<Body>,
    /// Names of the generalized coordinates (their driving joints).
    pub(crate) joint_names: Vec<String>,
    /// Names of all moving joints, in tree order.
    pub(crate) moving_joint_names: Vec<String>,
    /// What loading repaired or accepted with reservations (one line each, naming the link).
    pub(crate) warnings: Vec<String>,
    pub(crate) limits: Vec<JointLimits>,
    pub(crate) frames: Vec<Frame>,
    pub(crate) frame_names: Vec<String>,
    pub(crate) gravity: Vector3<f64>,
    /// Body whose origin is the reference point of the spatial vectors: the end of the chain of
    /// single-child bodies from the root (for a mobile base, the base body).
    pub(crate) ref_body: usize,
    /// Whether a body is on the path from the root to `ref_body` (inclusive).
    pub(crate) trunk: Vec<bool>,
}

impl RobotModel {
    /// Loads and validates a URDF file (plain URDF, no xacro) with the default options.
    pub fn from_urdf_file(path: &std::path::Path) -> Result<RobotModel, ModelError> {
        Self::from_urdf_file_with(path, &UrdfOptions::default())
    }

    /// Loads and validates a URDF file with the given options.
    pub fn from_urdf_file_with(path: &std::path::Path, options: &UrdfOptions) -> Result<RobotModel, ModelError> {
        let file = path.display().to_string();
        let xml = std::fs::read_to_string(path).map_err(|io| ModelError::Io { file: file.clone(), io })?;
        Self::from_urdf_str_with(&xml, &file, options)
    }

    /// Loads and validates URDF text with the default options; `source` names it (usually the
    /// file) in error messages.
    pub fn from_urdf_str(xml: &str, source: &str) -> Result<RobotModel, ModelError> {
        Self::from_urdf_str_with(xml, source, &UrdfOptions::default())
    }

    /// Loads and validates URDF text with the given options.
    pub fn from_urdf_str_with(xml: &str, source: &str, options: &UrdfOptions) -> Result<RobotModel, ModelError> {
        urdf::build(xml, source, options)
    }

    /// What loading repaired or accepted with reservations (inertias within the repair
    /// tolerance, inconsistent but usable inertias), one message per link.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Robot name from the URDF.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The source the model was loaded from (file name).
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Number of generalized coordinates (= velocity variables = nq for this model class): the
    /// moving joints, less the mimic joints that follow their leader.
    pub fn nv(&self) -> usize {
        self.joint_names.len()
    }

    /// Number of moving joints of the tree (≥ [`Self::nv`]).
    pub fn njoints(&self) -> usize {
        self.bodies.len()
    }

    /// Names of the generalized coordinates in model order (each is its driving joint's name).
    pub fn joint_names(&self) -> &[String] {
        &self.joint_names
    }

    /// Names of all moving joints of the tree, index = joint index.
    pub fn moving_joint_names(&self) -> &[String] {
        &self.moving_joint_names
    }

    /// Generalized coordinate of a joint name (None for unknown names and followed mimic joints).
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joint_names.iter().position(|n| n == name)
    }

    /// Generalized coordinates of the holonomic base's x, y, yaw joints ([`BASE_JOINTS`]), if the
    /// robot has all three.
    pub fn planar_base(&self) -> Option<[usize; 3]> {
        let [x, y, yaw] = BASE_JOINTS.map(|n| self.joint_index(n));
        Some([x?, y?, yaw?])
    }

    /// Whether moving joint `j` is one of the holonomic base's joints ([`BASE_JOINTS`]); every
    /// other moving joint belongs to an arm (or a torso, a head).
    pub fn is_base_joint(&self, j: usize) -> bool {
        is_base_joint_name(&self.joint_names[j])
    }

    /// Limits of the generalized coordinates in model order.
    pub fn joint_limits(&self) -> &[JointLimits] {
        &self.limits
    }

    /// Coordinate, multiplier and offset driving moving joint `j`: its value is
    /// `multiplier · q[coordinate] + offset` (`(j, 1, 0)` without followed mimic joints).
    pub fn joint_coordinate(&self, j: usize) -> (usize, f64, f64) {
        let b = &self.bodies[j];
        (b.coord, b.multiplier, b.offset)
    }

    /// Kind of moving joint `j` (`j < njoints()`).
    pub fn joint_kind(&self, j: usize) -> JointKind {
        self.bodies[j].kind
    }

    /// Unit axis of moving joint `j` in its own frame.
    pub fn joint_axis(&self, j: usize) -> &Vector3<f64> {
        &self.bodies[j].axis
    }

    /// Parent moving joint of moving joint `j` (None: attached to the world).
    pub fn joint_parent(&self, j: usize) -> Option<usize> {
        self.bodies[j].parent
    }

    /// Whether moving joint `ancestor` moves moving joint `j` (a joint supports itself).
    pub fn joint_supports(&self, ancestor: usize, j: usize) -> bool {
        let mut k = Some(j);
        while let Some(i) = k {
            if i == ancestor {
                return true;
            }
            k = self.bodies[i].parent;
        }
        false
    }

    /// Merged mass of the body moved by joint `j` (its link and all links fixed to it) (kg).
    pub fn body_mass(&self, j: usize) -> f64 {
        self.bodies[j].mass
    }

    /// Centre of mass of body `j` in its joint frame (m).
    pub fn body_com(&self, j: usize) -> &Vector3<f64> {
        &self.bodies[j].com
    }

    /// Rotational inertia of body `j` about its centre of mass, joint-frame axes (kg m²).
    pub fn body_inertia(&self, j: usize) -> &Matrix3<f64> {
        &self.bodies[j].inertia_com
    }

    /// Total mass of the moving bodies (kg).
    pub fn total_mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.mass).sum()
    }

    /// Gravity acceleration vector in the world frame (default `[0, 0, -9.81]`).
    pub fn gravity(&self) -> &Vector3<f64> {
        &self.gravity
    }

    /// Number of frames (URDF links).
    pub fn nframes(&self) -> usize {
        self.frames.len()
    }

    /// Frame (URDF link) names; index = frame index.
    pub fn frame_names(&self) -> &[String] {
        &self.frame_names
    }

    /// Frame index of a URDF link.
    pub fn frame_index(&self, link_name: &str) -> Option<usize> {
        self.frame_names.iter().position(|n| n == link_name)
    }

    /// The moving joint that moves frame `frame` (None: attached to the world).
    pub fn frame_parent_joint(&self, frame: usize) -> Option<usize> {
        self.frames[frame].body
    }

    /// Constant placement of frame `frame` in the frame of its parent joint (or the world).
    pub fn frame_placement(&self, frame: usize) -> &Isometry3<f64> {
        &self.frames[frame].placement
    }

    /// Collision primitives of a link, in the link's own frame.
    pub fn link_collisions(&self, frame: usize) -> &[Collision] {
        &self.frames[frame].collisions
    }

    /// For moving joint `j`, the frame of the link it moves directly (its child link).
    pub fn joint_child_frame(&self, j: usize) -> usize {
        self.bodies[j].frame
    }
}

/// Preallocated workspace of the kinematics and dynamics algorithms for one [`RobotModel`].
///
/// Spatial quantities are kept in world orientation about one reference point (the origin of the
/// base body at the current configuration, so that numbers stay small and accurate when a mobile
/// base is far from the world origin).
#[derive(Clone, Debug)]
pub struct ModelData {
    pub(crate) q: Vec<f64>,
    pub(crate) qd: Vec<f64>,
    /// World pose of each joint frame.
    pub(crate) body_pose: Vec<Isometry3<f64>>,
    /// World rotation matrix of each joint frame.
    pub(crate) body_rot: Vec<Matrix3<f64>>,
    /// World position of each joint frame origin.
    pub(crate) body_pos: Vec<Vector3<f64>>,
    /// Position of each joint frame origin relative to the reference point, accumulated along
    /// the tree from the reference body so that it carries no rounding of large coordinates.
    pub(crate) body_rel: Vec<Vector3<f64>>,
    /// World joint axis.
    pub(crate) axis_w: Vec<Vector3<f64>>,
    /// World pose of each frame.
    pub(crate) frame_pose: Vec<Isometry3<f64>>,
    /// Reference point of the spatial vectors (world coordinates).
    pub(crate) ref_point: Vector3<f64>,
    /// Motion subspace of each joint (spatial, reference point).
    pub(crate) s: Vec<SVec>,
    /// Spatial velocity of each body.
    pub(crate) v: Vec<SVec>,
    /// Velocity-product acceleration of each joint `v_i ×m S_i q̇_i`.
    pub(crate) c: Vec<SVec>,
    /// Spatial acceleration of each body for q̈ = 0, without gravity.
    pub(crate) a_bias: Vec<SVec>,
    /// Body inertias in world orientation about the reference point.
    pub(crate) inertia_w: Vec<SpatialInertia>,
    /// Composite-rigid-body inertias (CRBA workspace).
    pub(crate) composite: Vec<SpatialInertia>,
    /// Body forces and accelerations (RNEA workspace).
    pub(crate) f: Vec<SVec>,
    pub(crate) a: Vec<SVec>,
}

impl ModelData {
    /// Allocates the workspace for `model`.
    pub fn new(model: &RobotModel) -> Self {
        let n = model.njoints();
        Self {
            q: vec![0.0; model.nv()],
            qd: vec![0.0; model.nv()],
            body_pose: vec![Isometry3::identity(); n],
            body_rot: vec![Matrix3::identity(); n],
            body_pos: vec![Vector3::zeros(); n],
            body_rel: vec![Vector3::zeros(); n],
            axis_w: vec![Vector3::zeros(); n],
            frame_pose: model.frames.iter().map(|f| f.placement).collect(),
            ref_point: Vector3::zeros(),
            s: vec![SVec::zeros(); n],
            v: vec![SVec::zeros(); n],
            c: vec![SVec::zeros(); n],
            a_bias: vec![SVec::zeros(); n],
            inertia_w: vec![SpatialInertia::zero(); n],
            composite: vec![SpatialInertia::zero(); n],
            f: vec![SVec::zeros(); n],
            a: vec![SVec::zeros(); n],
        }
    }

    /// Joint positions of the last [`update_kinematics`].
    pub fn q(&self) -> &[f64] {
        &self.q
    }

    /// Joint velocities of the last [`update_kinematics`].
    pub fn qd(&self) -> &[f64] {
        &self.qd
    }

    /// World pose of frame `frame` (same as [`frame_pose`]).
    pub fn frame_pose(&self, frame: usize) -> &Isometry3<f64> {
        &self.frame_pose[frame]
    }

    /// World pose of the frame of joint `j` (its child link frame).
    pub fn joint_pose(&self, j: usize) -> &Isometry3<f64> {
        &self.body_pose[j]
    }

    /// World joint axis of joint `j`.
    pub fn joint_axis_world(&self, j: usize) -> &Vector3<f64> {
        &self.axis_w[j]
    }

    /// Twist of the body of joint `j`: (angular velocity, linear velocity of the joint frame
    /// origin), both in world coordinates.
    pub fn joint_twist(&self, j: usize) -> (Vector3<f64>, Vector3<f64>) {
        let v = &self.v[j];
        let w = spatial::ang(v);
        (w, spatial::lin(v) + w.cross(&self.body_rel[j]))
    }
}
