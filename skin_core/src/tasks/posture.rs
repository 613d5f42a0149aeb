//! Interactive-force-control paper eq. (18): joint compliance and posture, the torque projected into the null space of
//! all levels: `τ_c* = −K_c (q − q_post) − D_c q̇ − τ_s`. This module is the joint compliance;
//! the terms of `τ_s` are tasks of their own ([`super::task::Role::PostureTerm`]): the body skin
//! torque `k_skin τ_skin` of eq. (13)-(14) ([`super::compliance`]) and the base avoidance torque
//! `τ_oca` of eq. (15)-(17) ([`super::base_avoidance`]).
//!
//! A commanded base motion ([`BaseReference`], interactive-force-control paper Exp. 1's circle and swings) is this
//! level's reference: the base joints' `q_post` becomes the moving `q_d(t)` and their damping acts
//! on `q̇ − q̇_d` (the velocity feed-forward), with the gains of `posture.base_tracking`. Being the
//! lowest level, the motion only takes the null space of the hand's tasks: the arm keeps the hand.

use nalgebra::DVector;

use super::error::TaskError;
use super::params::{BaseGains, PostureParams};
use super::task::{BaseReference, Cycle, Role, Task, TaskSetup};
use crate::model::ModelData;

/// Joint compliance / posture torque.
#[derive(Debug, Clone)]
pub struct Posture {
    /// `K_c` diagonal.
    pub k_c: DVector<f64>,
    /// `D_c` diagonal.
    pub d_c: DVector<f64>,
    /// Desired posture `q_post`.
    pub q_post: DVector<f64>,
    /// Gains of the base joints while a [`BaseReference`] is set (none: `k_c`, `d_c`).
    pub base_tracking: Option<BaseGains>,
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
            q_post: expand(q_post, nv, "q_post")?,
            base_tracking: params.base_tracking,
        })
    }

    /// Gives the base joints `joints` (model indices of x, y, yaw) their own gains at rest
    /// (`posture.base`); an index out of range is refused.
    pub fn set_base_gains(&mut self, joints: [usize; 3], gains: BaseGains) -> Result<(), TaskError> {
        let nv = self.k_c.len();
        if let Some(&j) = joints.iter().find(|&&j| j >= nv) {
            return Err(TaskError::Length { what: "base joint index", expected: nv, got: j });
        }
        for (k, &j) in joints.iter().enumerate() {
            self.k_c[j] = gains.k_c[k];
            self.d_c[j] = gains.d_c[k];
        }
        Ok(())
    }

    /// Writes the joint compliance of eq. (18) at the state of the last `update_kinematics` into
    /// `tau`, with the commanded base motion `base` (the base joints' model indices and the
    /// reference) if one is set.
    pub fn joint_torque(
        &self,
        data: &ModelData,
        base: Option<([usize; 3], BaseReference)>,
        tau: &mut DVector<f64>,
    ) -> Result<(), TaskError> {
        let nv = self.k_c.len();
        for (what, len) in [("model nv", data.q().len()), ("posture torque", tau.len())] {
            if len != nv {
                return Err(TaskError::Length { what, expected: nv, got: len });
            }
        }
        let (q, qd) = (data.q(), data.qd());
        for i in 0..nv {
            tau[i] = self.compliance(i, q[i], qd[i], base);
        }
        Ok(())
    }

    /// Joint `i`'s compliance at `q`, `q̇`: `−K_c (q − q_post) − D_c q̇`, or on a base joint with a
    /// [`BaseReference`] set `−K_c (q − q_d) − D_c (q̇ − q̇_d)` with the `base_tracking` gains.
    fn compliance(&self, i: usize, q: f64, qd: f64, base: Option<([usize; 3], BaseReference)>) -> f64 {
        let tracked = base.and_then(|(joints, r)| joints.iter().position(|&j| j == i).map(|k| (r, k)));
        match tracked {
            Some((r, k)) => {
                let (kc, dc) = self.base_tracking.map_or((self.k_c[i], self.d_c[i]), |g| (g.k_c[k], g.d_c[k]));
                -kc * (q - r.position[k]) - dc * (qd - r.velocity[k])
            }
            None => -self.k_c[i] * (q - self.q_post[i]) - self.d_c[i] * qd,
        }
    }
}

impl Task for Posture {
    fn name() -> &'static str {
        "posture"
    }

    fn role() -> Role {
        Role::Posture
    }

    fn build(s: &TaskSetup) -> Result<Self, TaskError> {
        let mut posture = Posture::new(s.model.nv(), &s.params.posture, s.posture)?;
        if let (Some(joints), Some(gains)) = (s.base_joints, s.params.posture.base) {
            posture.set_base_gains(joints, gains)?;
        }
        Ok(posture)
    }

    fn torque(&mut self, cx: &Cycle, tau: &mut DVector<f64>) -> Result<(), TaskError> {
        self.joint_torque(cx.data, cx.base_reference, tau)
    }
}
