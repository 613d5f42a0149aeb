//! Paper 003 eq. (4), Table 1 (contact phase): Cartesian position hold of the hand at its
//! position when the phase began, `x_d = x_ef,init`: `ẍ* = Λ⁻¹(K Δx − D ẋ)`, `Δx = x_d − x`
//! (`ẍ_d = 0`, no external wrench term), 3 world-aligned linear rows.

use nalgebra::{Matrix6xX, Point3, Vector3, Vector6};

use super::params::Impedance3;
use super::{impedance_acceleration, rows_times_qd, TaskError};
use crate::hierarchy::{Reference, TaskLevel};
use crate::model::{point_jacobian, point_jacobian_dot_qdot, ModelData, RobotModel};

/// Cartesian position hold task.
#[derive(Debug, Clone)]
pub struct PositionHold {
    /// Frame whose point is held.
    pub frame: usize,
    /// Point in the frame \[m\].
    pub point: Vector3<f64>,
    /// `Λ`, `K`, `D` diagonals (world axes).
    pub params: Impedance3,
    /// Held position `x_d` (world) \[m\].
    pub target: Vector3<f64>,
    jac: Matrix6xX<f64>,
    drift: Vector6<f64>,
}

impl PositionHold {
    /// The task for `point` of `frame` on a model with `nv` joints; its level needs 3 rows.
    /// The target starts at the origin: call [`PositionHold::capture`] when the phase begins.
    pub fn new(nv: usize, frame: usize, point: Vector3<f64>, params: Impedance3) -> Self {
        Self { frame, point, params, target: Vector3::zeros(), jac: Matrix6xX::zeros(nv), drift: Vector6::zeros() }
    }

    /// Sets `x_d = x_ef,init`, the current world position of the point.
    pub fn capture(&mut self, data: &ModelData) {
        self.target = (data.frame_pose(self.frame) * Point3::from(self.point)).coords;
    }

    /// Fills `level` (3 acceleration rows); returns `ẍ*`.
    pub fn update(&mut self, model: &RobotModel, data: &ModelData, level: &mut TaskLevel) -> Result<Vector3<f64>, TaskError> {
        point_jacobian(model, data, self.frame, &self.point, &mut self.jac)?;
        point_jacobian_dot_qdot(model, data, self.frame, &self.point, &mut self.drift)?;
        let x = (data.frame_pose(self.frame) * Point3::from(self.point)).coords;
        let v = rows_times_qd(&self.jac, 0, data.qd());
        let xdd = impedance_acceleration(&self.params, &(self.target - x), &v);
        let drift = Vector3::new(self.drift[0], self.drift[1], self.drift[2]);
        level.set(
            &self.jac.fixed_rows::<3>(0),
            Reference::Acceleration { xdd_star: xdd.as_slice(), jdot_qdot: drift.as_slice() },
        )?;
        Ok(xdd)
    }
}
