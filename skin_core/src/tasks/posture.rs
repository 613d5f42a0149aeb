//! Interactive-force-control paper eq. (18): joint compliance and posture, the torque projected into the null space of
//! all levels: `τ_c* = −K_c (q − q_post) − D_c q̇ − τ_s` with
//! `τ_s = k_skin τ_skin + τ_oca`: the body skin torque of eq. (13)-(14) (patch virtual wrenches,
//! outward, so `−τ_skin` yields to the touch) and the base avoidance torque of eq. (15)-(17)
//! ([`super::base_avoidance`], toward the obstacles, so `−τ_oca` moves away).
//!
//! A commanded base motion ([`BaseReference`], interactive-force-control paper Exp. 1's circle and swings) is this
//! level's reference: the base joints' `q_post` becomes the moving `q_d(t)` and their damping acts
//! on `q̇ − q̇_d` (the velocity feed-forward), with the gains of `posture.base_tracking`. Being the
//! lowest level, the motion only takes the null space of the hand's tasks: the arm keeps the hand.

use nalgebra::DVector;

use super::params::{BaseGains, PostureParams};
use super::TaskError;
use crate::model::{ModelData, RobotModel};
use crate::skin::aggregate::PatchWrench;
use crate::skin::layout::ResolvedLayout;
use crate::skin::torques::patch_wrenches_to_torques;

/// A commanded base pose and velocity at one instant: the moving `q_d`, `q̇_d` of the base joints
/// (world x, y \[m\], yaw \[rad\], as the base joints measure them; yaw unwrapped like the joint).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BaseReference {
    /// `q_d` of base x, y, yaw.
    pub position: [f64; 3],
    /// `q̇_d` of base x, y, yaw (world frame) \[m/s, rad/s\].
    pub velocity: [f64; 3],
}

impl BaseReference {
    /// Index of the first non-finite value (positions 0-2, velocities 3-5), if any.
    pub fn non_finite(&self) -> Option<usize> {
        self.position.iter().chain(&self.velocity).position(|v| !v.is_finite())
    }
}

/// A base reference with the base joints' model indices.
#[derive(Debug, Clone, Copy)]
struct BaseTarget {
    joints: [usize; 3],
    reference: BaseReference,
}

/// Joint compliance / posture torque.
#[derive(Debug, Clone)]
pub struct Posture {
    /// `K_c` diagonal.
    pub k_c: DVector<f64>,
    /// `D_c` diagonal.
    pub d_c: DVector<f64>,
    /// Gain on `τ_skin`.
    pub skin_gain: f64,
    /// Desired posture `q_post`.
    pub q_post: DVector<f64>,
    /// Gains of the base joints while a [`BaseReference`] is set (none: `k_c`, `d_c`).
    pub base_tracking: Option<BaseGains>,
    base: Option<BaseTarget>,
    tau_skin: DVector<f64>,
    tau: DVector<f64>,
}

fn expand(v: &[f64], nv: usize, what: &'static str) -> Result<DVector<f64>, TaskError> {
    match v.len() {
        1 => Ok(DVector::from_element(nv, v[0])),
        n if n == nv => Ok(DVector::from_column_slice(v)),
        n => Err(TaskError::Length { what, expected: nv, got: n }),
    }
}

impl Posture {
    /// The posture task for `nv` joints (gains of length 1 or nv) with the desired posture `q_post`.
    pub fn new(nv: usize, params: &PostureParams, q_post: &[f64]) -> Result<Self, TaskError> {
        Ok(Self {
            k_c: expand(&params.k_c, nv, "posture.k_c")?,
            d_c: expand(&params.d_c, nv, "posture.d_c")?,
            skin_gain: params.skin_gain,
            q_post: expand(q_post, nv, "q_post")?,
            base_tracking: params.base_tracking,
            base: None,
            tau_skin: DVector::zeros(nv),
            tau: DVector::zeros(nv),
        })
    }

    /// Gives the base joints `joints` (model indices of x, y, yaw) their own gains at rest
    /// (`posture.base`); an index out of range is refused.
    pub fn set_base_gains(&mut self, joints: [usize; 3], gains: BaseGains) -> Result<(), TaskError> {
        let nv = self.tau.len();
        if let Some(&j) = joints.iter().find(|&&j| j >= nv) {
            return Err(TaskError::Length { what: "base joint index", expected: nv, got: j });
        }
        for (k, &j) in joints.iter().enumerate() {
            self.k_c[j] = gains.k_c[k];
            self.d_c[j] = gains.d_c[k];
        }
        Ok(())
    }

    /// Sets the commanded base motion of the base joints `joints` (model indices of x, y, yaw),
    /// or clears it (`None`: back to `q_post`). A non-finite value or a joint index out of range
    /// is refused (the previous reference stays).
    pub fn set_base_reference(
        &mut self,
        joints: [usize; 3],
        reference: Option<BaseReference>,
    ) -> Result<(), TaskError> {
        let nv = self.tau.len();
        if let Some(&j) = joints.iter().find(|&&j| j >= nv) {
            return Err(TaskError::Length { what: "base joint index", expected: nv, got: j });
        }
        if let Some(index) = reference.and_then(|r| r.non_finite()) {
            return Err(TaskError::NonFinite { what: "base reference", index });
        }
        self.base = reference.map(|reference| BaseTarget { joints, reference });
        Ok(())
    }

    /// The commanded base motion in use.
    pub fn base_reference(&self) -> Option<BaseReference> {
        self.base.map(|b| b.reference)
    }

    /// Computes `τ_c*` at the state of the last `update_kinematics` from the patch wrenches of the
    /// body patches selected by `include` and the optional `τ_oca`; `joint = false` leaves out the
    /// joint compliance `−K_c (q − q_post) − D_c q̇` (an arrangement with body compliance or base
    /// avoidance but no posture). Returns it (pass `Some(posture.update(..)?.as_slice())` to the
    /// solver).
    #[allow(clippy::too_many_arguments)]
    pub fn update(
        &mut self,
        model: &RobotModel,
        data: &ModelData,
        layout: &ResolvedLayout,
        wrenches: &[PatchWrench],
        include: impl Fn(usize) -> bool,
        tau_oca: Option<&DVector<f64>>,
        joint: bool,
    ) -> Result<&DVector<f64>, TaskError> {
        let nv = self.tau.len();
        if data.q().len() != nv {
            return Err(TaskError::Length { what: "model nv", expected: nv, got: data.q().len() });
        }
        if wrenches.len() < layout.patches().len() {
            return Err(TaskError::Length {
                what: "patch wrenches",
                expected: layout.patches().len(),
                got: wrenches.len(),
            });
        }
        patch_wrenches_to_torques(model, data, layout, wrenches, include, &mut self.tau_skin);
        let (q, qd) = (data.q(), data.qd());
        let joint = if joint { 1.0 } else { 0.0 };
        for i in 0..nv {
            let oca = tau_oca.map_or(0.0, |t| t[i]);
            self.tau[i] = joint * self.compliance(i, q[i], qd[i]) - (self.skin_gain * self.tau_skin[i] + oca);
        }
        Ok(&self.tau)
    }

    /// Joint `i`'s compliance at `q`, `q̇`: `−K_c (q − q_post) − D_c q̇`, or on a base joint with a
    /// [`BaseReference`] set `−K_c (q − q_d) − D_c (q̇ − q̇_d)` with the `base_tracking` gains.
    fn compliance(&self, i: usize, q: f64, qd: f64) -> f64 {
        let tracked = self.base.and_then(|b| b.joints.iter().position(|&j| j == i).map(|k| (b.reference, k)));
        match tracked {
            Some((r, k)) => {
                let (kc, dc) = self.base_tracking.map_or((self.k_c[i], self.d_c[i]), |g| (g.k_c[k], g.d_c[k]));
                -kc * (q - r.position[k]) - dc * (qd - r.velocity[k])
            }
            None => -self.k_c[i] * (q - self.q_post[i]) - self.d_c[i] * qd,
        }
    }

    /// Zeroes the last update's torque on the joints marked in `locked` (joints held still).
    pub fn lock_joints(&mut self, locked: &[bool]) {
        for (t, &l) in self.tau.iter_mut().zip(locked) {
            if l {
                *t = 0.0;
            }
        }
    }

    /// `τ_c*` of the last update.
    pub fn torque(&self) -> &DVector<f64> {
        &self.tau
    }
}
