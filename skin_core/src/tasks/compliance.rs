//! Interactive-force-control paper eq. (13)-(14): body compliance. The virtual wrenches of the
//! body patches (outward) mapped to joint torques, `τ_skin = Σ_j J_jᵀ w_j`; `k_skin τ_skin` is a
//! term of `τ_s` in eq. (18), which subtracts it: the body yields to the touch.

use nalgebra::DVector;

use super::error::TaskError;
use super::task::{Cycle, Role, Task, TaskSetup};
use crate::model::{ModelData, RobotModel};
use crate::skin::aggregate::PatchWrench;
use crate::skin::layout::ResolvedLayout;
use crate::skin::torques::patch_wrenches_to_torques;

/// Body compliance torque.
#[derive(Debug, Clone)]
pub struct BodyCompliance {
    /// Gain `k_skin` on `τ_skin` (`posture.skin_gain`).
    pub skin_gain: f64,
    tau_skin: DVector<f64>,
}

impl BodyCompliance {
    /// The term for `nv` joints.
    pub fn new(nv: usize, skin_gain: f64) -> Self {
        Self { skin_gain, tau_skin: DVector::zeros(nv) }
    }

    /// Adds `k_skin τ_skin` of the patches selected by `include` at the state of the last
    /// `update_kinematics` to `tau_s`.
    pub fn add_to(
        &mut self,
        model: &RobotModel,
        data: &ModelData,
        layout: &ResolvedLayout,
        wrenches: &[PatchWrench],
        include: impl Fn(usize) -> bool,
        tau_s: &mut DVector<f64>,
    ) -> Result<(), TaskError> {
        if wrenches.len() < layout.patches().len() {
            let (expected, got) = (layout.patches().len(), wrenches.len());
            return Err(TaskError::Length { what: "patch wrenches", expected, got });
        }
        if tau_s.len() != self.tau_skin.len() {
            return Err(TaskError::Length { what: "τ_s", expected: self.tau_skin.len(), got: tau_s.len() });
        }
        patch_wrenches_to_torques(model, data, layout, wrenches, include, &mut self.tau_skin);
        for (t, s) in tau_s.iter_mut().zip(&self.tau_skin) {
            *t += self.skin_gain * s;
        }
        Ok(())
    }
}

impl Task for BodyCompliance {
    fn name() -> &'static str {
        "compliance"
    }

    fn role() -> Role {
        Role::PostureTerm
    }

    fn build(s: &TaskSetup) -> Result<Self, TaskError> {
        Ok(Self::new(s.model.nv(), s.params.posture.skin_gain))
    }

    fn torque(&mut self, cx: &Cycle, tau_s: &mut DVector<f64>) -> Result<(), TaskError> {
        let body = cx.body_patches;
        self.add_to(cx.model, cx.data, cx.layout, cx.wrenches, |j| body.get(j).copied().unwrap_or(false), tau_s)
    }
}
