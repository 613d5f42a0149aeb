//! Robot model (immutable, from a URDF) and its preallocated data workspace.
//!
//! [`RobotModel`] is a kinematic tree of one-degree-of-freedom joints (revolute, continuous,
//! prismatic) built from a URDF; links joined by fixed joints are merged into the moving body
//! they hang from, and every URDF link stays available as a *frame* with a constant placement in
//! that body (like pinocchio's frames). [`ModelData`] holds everything the algorithms compute;
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
mod kinematics;
mod rnea;
pub mod spatial;
mod urdf;

#[cfg(test)]
mod tests;

pub use crba::crba;
pub use error::ModelError;
pub use kinematics::{frame_pose, point_jacobian, point_jacobian_along, point_jacobian_dot_qdot, point_velocity, update_kinematics};
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

/// Immutable robot model built from a URDF. Joint order ("model order") is depth-first from the
/// root link, children in document order; it is the order of every q, q̇, τ vector.
#[derive(Clone, Debug)]
pub struct RobotModel {
    pub(crate) name: String,
    pub(crate) source: String,
    pub(crate) bodies: Vec<Body>,
    pub(crate) joint_names: Vec<String>,
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
    /// Loads and validates a URDF file (plain URDF, no xacro).
    pub fn from_urdf_file(path: &std::path::Path) -> Result<RobotModel, ModelError> {
        let file = path.display().to_string();
        let xml = std::fs::read_to_string(path).map_err(|io| ModelError::Io { file: file.clone(), io })?;
        Self::from_urdf_str(&xml, &file)
    }

    /// Loads and validates URDF text; `source` names it (usually the file) in error messages.
    pub fn from_urdf_str(xml: &str, source: &str) -> Result<RobotModel, ModelError> {
        urdf::build(xml, source)
    }

    /// Robot name from the URDF.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The source the model was loaded from (file name).
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Number of velocity variables = number of moving joints (= nq for this model class).
    pub fn nv(&self) -> usize {
        self.bodies.len()
    }

    /// Moving joint names in model order.
    pub fn joint_names(&self) -> &[String] {
        &self.joint_names
    }

    /// Index of a moving joint by name.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joint_names.iter().position(|n| n == name)
    }

    /// Joint limits in model order.
    pub fn joint_limits(&self) -> &[JointLimits] {
        &self.limits
    }

    /// Kind of joint `j`.
    pub fn joint_kind(&self, j: usize) -> JointKind {
        self.bodies[j].kind
    }

    /// Unit axis of joint `j` in its own frame.
    pub fn joint_axis(&self, j: usize) -> &Vector3<f64> {
        &self.bodies[j].axis
    }

    /// Parent moving joint of joint `j` (None: attached to the world).
    pub fn joint_parent(&self, j: usize) -> Option<usize> {
        self.bodies[j].parent
    }

    /// Whether joint `ancestor` moves joint `j` (a joint supports itself).
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

    /// The joint that moves frame `frame` (None: attached to the world).
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

    /// For every moving joint, the frame of the link it moves directly (its child link).
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
        let n = model.nv();
        Self {
            q: vec![0.0; n],
            qd: vec![0.0; n],
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
