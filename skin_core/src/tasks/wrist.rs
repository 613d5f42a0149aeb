//! Interactive-force-control paper eq. (10): compliant wrist, 3 angular acceleration rows driving the hand-patch
//! moment `Γ` to zero.
//!
//! `ω̇* = Λ⁻¹(−K Γ − D ω)` with the rotational rows of the hand Jacobian (world axes) and `Γ`
//! the hand patch moment (interactive-force-control paper eq. 8) rotated into world axes. The patch moment is that of
//! the outward virtual forces; a more loaded side gives a moment whose negative rotates that side
//! back, away from the surface, so the pressure evens out (the paper writes the same law in `{h}`;
//! with isotropic gains the two are identical).
//!
//! The two modalities of eq. (6) are read in their own units, weighted by its `w`:
//! `K Γ = (1 − w) K_p Γ_p + w K_F Γ_F`, with `Γ_p` the moment of the proximity signals (eq. 8,
//! signal units: the alignment before the touch, `w = 0` in the precontact phase) and `Γ_F` the
//! moment of the pressed cells' newtons (`skin::measured`, `F_i = f⁻¹(s_i)`: the contact phase,
//! `w = 1`). The summed force signal's moment would not do in contact: an edge of the palm touches
//! with a few cells near the saturation of the characteristic, whose signals, and so their moment,
//! barely grow with the force pressing them (the palm turned flat a few degrees per second, and
//! the hand force loop had little gain on those cells meanwhile); in newtons the moment is the
//! contact's, and the wrist's gain the same for an edge as for a flat press.

use nalgebra::Vector3;

use super::error::TaskError;
use super::params::WristParams;
use super::point_rows::{PointRows, ANGULAR};
use super::task::{Cycle, Role, Rows, Task, TaskSetup, WristMoments};
use crate::hierarchy::TaskLevel;
use crate::model::{ModelData, RobotModel};

/// Compliant wrist task.
#[derive(Debug, Clone)]
pub struct CompliantWrist {
    /// Hand frame.
    pub frame: usize,
    /// `Λ`, `K_p`, `K_F`, `D` diagonals (world axes).
    pub params: WristParams,
    rows: PointRows,
}

impl CompliantWrist {
    /// The task for `frame` on a model with `nv` joints; its level needs 3 rows.
    pub fn new(nv: usize, frame: usize, params: WristParams) -> Self {
        Self { frame, params, rows: PointRows::new(nv) }
    }

    /// Fills `level` (3 acceleration rows) for the hand moments `m`; returns `ω̇*`.
    pub fn update(
        &mut self,
        model: &RobotModel,
        data: &ModelData,
        m: &WristMoments,
        level: &mut TaskLevel,
    ) -> Result<Vector3<f64>, TaskError> {
        self.rows.update(model, data, self.frame, &Vector3::zeros())?;
        let omega = self.rows.velocity(ANGULAR, data.qd());
        let (w, p) = (m.fusion_weight, &self.params);
        let xdd = Vector3::from_fn(|i, _| {
            // error −Γ: the stiffness drives the moment to zero
            let stiffness = (1.0 - w) * p.k[i] * m.proximity_world[i] + w * p.k_force[i] * m.force_world_nm[i];
            (-stiffness - p.d[i] * omega[i]) / p.lambda[i]
        });
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
        self.update(cx.model, cx.data, &cx.hand.wrist, level).map(drop)
    }
}
