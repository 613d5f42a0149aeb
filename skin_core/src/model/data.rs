//! The preallocated workspace of the kinematics and dynamics algorithms.

use nalgebra::{Isometry3, Matrix3, Vector3};

use super::robot::RobotModel;
use super::spatial::{SVec, SpatialInertia};

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

    /// Joint positions of the last [`super::update_kinematics`].
    pub fn q(&self) -> &[f64] {
        &self.q
    }

    /// Joint velocities of the last [`super::update_kinematics`].
    pub fn qd(&self) -> &[f64] {
        &self.qd
    }

    /// World pose of frame `frame` (same as [`super::frame_pose`]).
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
        let w = super::spatial::ang(v);
        (w, super::spatial::lin(v) + w.cross(&self.body_rel[j]))
    }
}
