//! What the Cartesian tasks share: the Jacobian of a point on a frame with its drift `J̇ q̇`, turned
//! into acceleration rows (interactive-force-control paper eq. 3), and one force row along a skin cell's inward normal
//! (intentional-contact paper eq. 4, 6).

use nalgebra::{Matrix6xX, Vector3, Vector6};

use super::{rows_times_qd, TaskError};
use crate::hierarchy::{Reference, TaskLevel};
use crate::model::{point_jacobian, point_jacobian_along, point_jacobian_dot_qdot, ModelData, RobotModel};
use crate::skin::layout::ResolvedCell;

/// Linear rows of a 6-row point Jacobian start here.
pub(crate) const LINEAR: usize = 0;
/// Angular rows of a 6-row point Jacobian start here.
pub(crate) const ANGULAR: usize = 3;

/// The 6 × nv world-aligned Jacobian of a point and its `J̇ q̇`, preallocated, refreshed per cycle.
#[derive(Debug, Clone)]
pub(crate) struct PointRows {
    pub(crate) jac: Matrix6xX<f64>,
    pub(crate) drift: Vector6<f64>,
}

impl PointRows {
    pub(crate) fn new(nv: usize) -> Self {
        Self { jac: Matrix6xX::zeros(nv), drift: Vector6::zeros() }
    }

    /// Refreshes `J` and `J̇ q̇` of `point` (in `frame`) from the last kinematics update.
    pub(crate) fn update(
        &mut self,
        model: &RobotModel,
        data: &ModelData,
        frame: usize,
        point: &Vector3<f64>,
    ) -> Result<(), TaskError> {
        point_jacobian(model, data, frame, point, &mut self.jac)?;
        point_jacobian_dot_qdot(model, data, frame, point, &mut self.drift)?;
        Ok(())
    }

    /// `J[row0..row0+3] q̇`: the point's linear (`LINEAR`) or the frame's angular (`ANGULAR`)
    /// velocity in world axes.
    pub(crate) fn velocity(&self, row0: usize, qd: &[f64]) -> Vector3<f64> {
        rows_times_qd(&self.jac, row0, qd)
    }

    /// `J̇ q̇` of rows `row0..row0+3`.
    pub(crate) fn drift(&self, row0: usize) -> Vector3<f64> {
        self.drift.fixed_rows::<3>(row0).into_owned()
    }

    /// Sets `level` to the three rows from `row0` with reference acceleration `xdd`.
    pub(crate) fn set_acceleration(
        &self,
        level: &mut TaskLevel,
        row0: usize,
        xdd: &Vector3<f64>,
    ) -> Result<(), TaskError> {
        let drift = self.drift(row0);
        level.set(
            &self.jac.fixed_rows::<3>(row0),
            Reference::Acceleration { xdd_star: xdd.as_slice(), jdot_qdot: drift.as_slice() },
        )?;
        Ok(())
    }
}

/// Pushes one force row `f` \[N\] along the inward normal `−n` of `cell` (world axes), at the cell:
/// the row `−nᵀ J_v(p)` of intentional-contact paper eq. (4) / (6), with activation `a` in the null-space
/// projector ([`TaskLevel::push_row_activated`]). `row` is scratch space (nv).
pub(crate) fn push_inward_cell_row(
    model: &RobotModel,
    data: &ModelData,
    cell: &ResolvedCell,
    (f, a): (f64, f64),
    row: &mut [f64],
    level: &mut TaskLevel,
) -> Result<(), TaskError> {
    let inward = -(data.frame_pose(cell.frame).rotation * cell.normal_link);
    point_jacobian_along(model, data, cell.frame, &cell.position_link, &inward, row)?;
    level.push_row_activated(row, f, a)?;
    Ok(())
}

/// Activation of a skin row that is `x ≥ 0` past its switching point (inside the sensing range,
/// above zero force): the smoothstep `s²(3 − 2s)`, `s = x / width` clamped to `[0, 1]`; C¹, 0 at
/// the switching point, 1 from `width` on (`width = 0`: 1 at once).
pub(crate) fn row_activation(x: f64, width: f64) -> f64 {
    if width <= 0.0 {
        return 1.0;
    }
    let s = (x / width).clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}
