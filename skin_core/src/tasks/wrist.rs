//! Interactive-force-control paper eq. (10): compliant wrist, 3 angular acceleration rows driving the hand-patch
//! moment `Γ` to zero.
//!
//! `ω̇* = Λ⁻¹(−K Γ − D ω)` with the rotational rows of the hand Jacobian (world axes) and `Γ`
//! the hand patch moment (interactive-force-control paper eq. 8) rotated into world axes. The patch moment is that of
//! the outward virtual forces; a more loaded side gives a moment whose negative rotates that side
//! back, away from the surface, so the pressure evens out (the paper writes the same law in `{h}`;
//! with isotropic gains the two are identical).

use nalgebra::Vector3;

use super::error::TaskError;
use super::params::Impedance3;
use super::point_rows::{PointRows, ANGULAR};
use super::task::{Cycle, Role, Rows, Task, TaskSetup};
use super::terms::impedance_acceleration;
use crate::hierarchy::TaskLevel;
use crate::model::{ModelData, RobotModel};

/// Compliant wrist task.
#[derive(Debug, Clone)]
pub struct CompliantWrist {
    /// Hand frame.
    pub frame: usize,
    /// `Λ`, `K`, `D` diagonals (world axes).
    pub params: Impedance3,
    rows: PointRows,
}

impl CompliantWrist {
    /// The task for `frame` on a model with `nv` joints; its level needs 3 rows.
    pub fn new(nv: usize, frame: usize, params: Impedance3) -> Self {
        Self { frame, params, rows: PointRows::new(nv) }
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
        self.rows.update(model, data, self.frame, &Vector3::zeros())?;
        let w = self.rows.velocity(ANGULAR, data.qd());
        // error −Γ: the stiffness drives the moment to zero
        let xdd = impedance_acceleration(&self.params, &(-moment_world), &w);
        self.rows.set_acceleration(level, ANGULAR, &xdd)?;
        Ok(xdd)
    }
}

impl Task for CompliantWrist {
    fn name() -> &'static str {
        "wrist"
    }

    fn role() -> Role {
        Role::Level(Rows::Fixed(3))
    }

    fn build(s: &TaskSetup) -> Result<Self, TaskError> {
        Ok(Self::new(s.model.nv(), s.end_effector, s.params.wrist))
    }

    fn fill(&mut self, cx: &Cycle, level: &mut TaskLevel) -> Result<(), TaskError> {
        self.update(cx.model, cx.data, &cx.hand.moment_world, level).map(drop)
    }
}
