//! Interactive-force-control paper eq. (11)-(12): tactile guidance, 3 linear acceleration rows at the hand.
//!
//! `ʰF_arm = Σ_j ʰR_{p_j} ᵖʲF` (eq. 11, `skin::transforms::sum_patch_forces_in_frame` over the
//! arm patches) and `ʰẍ* = Λ⁻¹(−K ʰF_arm − D ʰẋ)` (eq. 12), evaluated in `{h}` and rotated to
//! world axes for the world-aligned linear rows of the hand Jacobian. The patch forces are the
//! outward virtual forces: a push on the forearm ALONG `d` activates cells whose outward normal
//! is `−d`, so `ʰF_arm ∥ −d` and `−K ʰF_arm ∥ d`: the hand follows the push.

use nalgebra::Vector3;

use super::error::TaskError;
use super::params::Impedance3;
use super::point_rows::{PointRows, LINEAR};
use super::task::{Cycle, Role, Rows, Task, TaskSetup};
use super::terms::impedance_acceleration;
use crate::hierarchy::TaskLevel;
use crate::model::{ModelData, RobotModel};

/// Tactile guidance task.
#[derive(Debug, Clone)]
pub struct TactileGuidance {
    /// Hand frame `{h}`.
    pub frame: usize,
    /// `Λ`, `K`, `D` diagonals in `{h}`.
    pub params: Impedance3,
    rows: PointRows,
}

impl TactileGuidance {
    /// The task for `frame` on a model with `nv` joints; its level needs 3 rows.
    pub fn new(nv: usize, frame: usize, params: Impedance3) -> Self {
        Self { frame, params, rows: PointRows::new(nv) }
    }

    /// Fills `level` (3 acceleration rows) for the arm force `arm_force_hand` (`ʰF_arm`, eq. 11);
    /// returns `ẍ*` in world axes.
    pub fn update(
        &mut self,
        model: &RobotModel,
        data: &ModelData,
        arm_force_hand: &Vector3<f64>,
        level: &mut TaskLevel,
    ) -> Result<Vector3<f64>, TaskError> {
        self.rows.update(model, data, self.frame, &Vector3::zeros())?;
        let r = data.frame_pose(self.frame).rotation;
        let v_h = r.inverse_transform_vector(&self.rows.velocity(LINEAR, data.qd()));
        let xdd = r * impedance_acceleration(&self.params, &(-arm_force_hand), &v_h);
        self.rows.set_acceleration(level, LINEAR, &xdd)?;
        Ok(xdd)
    }
}

impl Task for TactileGuidance {
    fn name() -> &'static str {
        "tactile_guidance"
    }

    fn role() -> Role {
        Role::Level(Rows::Fixed(3))
    }

    fn build(s: &TaskSetup) -> Result<Self, TaskError> {
        Ok(Self::new(s.model.nv(), s.end_effector, s.params.tactile_guidance))
    }

    fn fill(&mut self, cx: &Cycle, level: &mut TaskLevel) -> Result<(), TaskError> {
        self.update(cx.model, cx.data, &cx.hand.guidance_force, level).map(drop)
    }
}
