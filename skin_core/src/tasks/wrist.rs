//! Paper 003 eq. (10): compliant wrist, 3 angular acceleration rows driving the hand-patch
//! moment `Γ` to zero.
//!
//! `ω̇* = Λ⁻¹(−K Γ − D ω)` with the rotational rows of the hand Jacobian (world axes) and `Γ`
//! the hand patch moment (paper 003 eq. 8) rotated into world axes. The patch moment is that of
//! the outward virtual forces; a more loaded side gives a moment whose negative rotates that side
//! back, away from the surface, so the pressure evens out (the paper writes the same law in `{h}`;
//! with isotropic gains the two are identical).

use nalgebra::{Matrix6xX, Vector3, Vector6};

use super::params::Impedance3;
use super::{impedance_acceleration, rows_times_qd, TaskError};
use crate::hierarchy::{Reference, TaskLevel};
use crate::model::{point_jacobian, point_jacobian_dot_qdot, ModelData, RobotModel};

/// Compliant wrist task.
#[derive(Debug, Clone)]
pub struct CompliantWrist {
    /// Hand frame.
    pub frame: usize,
    /// `Λ`, `K`, `D` diagonals (world axes).
    pub params: Impedance3,
    jac: Matrix6xX<f64>,
    drift: Vector6<f64>,
}

impl CompliantWrist {
    /// The task for `frame` on a model with `nv` joints; its level needs 3 rows.
    pub fn new(nv: usize, frame: usize, params: Impedance3) -> Self {
        Self { frame, params, jac: Matrix6xX::zeros(nv), drift: Vector6::zeros() }
    }

    /// Fills `level` (3 acceleration rows) for the hand moment `moment_world` (e.g.
    /// `skin::transforms::patch_wrench_world(..).moment`); returns `ω̇*`.
    pub fn update(
        &mut self,
        model: &RobotModel,
        data: &ModelData,
        moment_world: &Vector3<f64>,
        level: &mut TaskLevel,
    ) -> Result<Vector3<f64>, TaskError> {
        let origin = Vector3::zeros();
        point_jacobian(model, data, self.frame, &origin, &mut self.jac)?;
        point_jacobian_dot_qdot(model, data, self.frame, &origin, &mut self.drift)?;
        let w = rows_times_qd(&self.jac, 3, data.qd());
        // error −Γ: the stiffness drives the moment to zero
        let xdd = impedance_acceleration(&self.params, &(-moment_world), &w);
        let drift = Vector3::new(self.drift[3], self.drift[4], self.drift[5]);
        level.set(
            &self.jac.fixed_rows::<3>(3),
            Reference::Acceleration { xdd_star: xdd.as_slice(), jdot_qdot: drift.as_slice() },
        )?;
        Ok(xdd)
    }
}
