//! The goal's executed damping with `hierarchy_dynamics: admittance_inertia` (`docs/controller.md`).
//!
//! The resolver integrates `τ* − g` through `M_a q̈ + C_a q̇` (interactive-force-control paper
//! eq. 26), so the goal's force `F_g` of intentional-contact paper eq. (7)-(9) moves the hand at
//! `J C_a⁻¹ Jᵀ F_g` once steady: its damping is `k_v` plus the joints' `C_a` seen at the hand,
//! which near the arm's reach is most of it (TOMM: 2 mm/s at 2.5 N). In the goal's range the
//! hierarchy's bias cancels `C_a` and puts in its place the damping of eq. (8), `k_v`, raised to
//! critical for the goal's task inertia `Λ_a = (J M_a⁻¹ Jᵀ)⁻¹` where `k_v` alone would leave the
//! spring `k_p` underdamped: `D = max(k_v, 2 √(k_p Λ_a))` along each principal axis of `Λ_a`. The
//! lower levels' motion keeps `C_a`, which with `C_a ∝ M_a` moves nothing in the goal's range.

use nalgebra::{Cholesky, DMatrix, DMatrixSlice, DVector, Matrix3, Vector3};

use crate::tasks::params::GoalParams;

/// Regularization of `J M_a⁻¹ Jᵀ` before its inverse, relative to its trace: near a singularity
/// `Λ_a` stays finite along the direction the arm cannot move.
const REGULARIZATION: f64 = 1e-6;

/// Scratch for the bias term, sized once (nothing allocates per cycle).
#[derive(Debug, Clone)]
pub(crate) struct GoalDamping {
    /// `M_a`, factored in place.
    factor: DMatrix<f64>,
    /// `M_a⁻¹ Jᵀ`.
    y: DMatrix<f64>,
    /// The resolver's damping torque `C_a v`, then `M_a⁻¹ C_a v`.
    w: DVector<f64>,
}

impl GoalDamping {
    /// Scratch for a model with `nv` joints.
    pub(crate) fn new(nv: usize) -> Self {
        Self { factor: DMatrix::zeros(nv, nv), y: DMatrix::zeros(nv, 3), w: DVector::zeros(nv) }
    }

    /// The resolver's damping torque `C_a v` to fill before [`Self::add`].
    pub(crate) fn damping_torque_mut(&mut self) -> &mut DVector<f64> {
        &mut self.w
    }

    /// Adds to `bias` the goal's damping change `Jᵀ Λ_a J M_a⁻¹ C_a v − Jᵀ (D − k_v) J q̇` for the
    /// goal's rows `jt` (`Jᵀ`, 3 columns), the inertia `mass` (`M_a`), the damping torque set
    /// through [`Self::damping_torque_mut`] and the measured `qd`. Leaves `bias` alone and returns
    /// false when `mass` is not positive definite.
    pub(crate) fn add(
        &mut self,
        jt: DMatrixSlice<'_, f64>,
        mass: &DMatrix<f64>,
        qd: &[f64],
        goal: &GoalParams,
        bias: &mut DVector<f64>,
    ) -> bool {
        debug_assert_eq!(jt.ncols(), 3);
        self.factor.copy_from(mass);
        let matrix = std::mem::replace(&mut self.factor, DMatrix::zeros(0, 0)); // no allocation
        let Some(chol) = Cholesky::new(matrix) else {
            self.factor = DMatrix::zeros(mass.nrows(), mass.ncols()); // the faulted cycle's, for the next one
            return false;
        };
        self.y.copy_from(&jt);
        chol.solve_mut(&mut self.y);
        chol.solve_mut(&mut self.w);
        self.factor = chol.unpack();
        let mut a = Matrix3::zeros();
        for r in 0..3 {
            for c in 0..3 {
                a[(r, c)] = jt.column(r).dot(&self.y.column(c));
            }
        }
        let a = 0.5 * (a + a.transpose()) + Matrix3::identity() * (REGULARIZATION * a.trace().max(f64::MIN_POSITIVE));
        let Some(lambda) = a.try_inverse() else { return false };
        let lambda = 0.5 * (lambda + lambda.transpose());
        let jw = Vector3::from_fn(|r, _| jt.column(r).dot(&self.w));
        let xd = Vector3::from_fn(|r, _| jt.column(r).iter().zip(qd).map(|(j, v)| j * v).sum::<f64>());
        let eig = lambda.symmetric_eigen();
        let extra = eig.eigenvalues.map(|l| (2.0 * (goal.kp_n_per_m * l.max(0.0)).sqrt() - goal.kv_n_s_per_m).max(0.0));
        let damping = eig.eigenvectors * Matrix3::from_diagonal(&extra) * eig.eigenvectors.transpose();
        let f = lambda * jw - damping * xd;
        for (r, fr) in f.iter().enumerate() {
            bias.axpy(*fr, &jt.column(r), 1.0);
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At rest the added bias cancels the resolver's damping torque in the goal's range, and only
    /// there: `J M_a⁻¹ (b − C_a v) = 0`, and `b` is a force on the goal's rows (`b = Jᵀ f`).
    #[test]
    fn the_goal_sees_no_joint_damping_and_the_rest_keeps_it() {
        let n = 6;
        let mass = DMatrix::from_diagonal(&DVector::from_fn(n, |i, _| 0.3 + 0.1 * i as f64));
        let jt = DMatrix::from_fn(n, 3, |i, j| (1.9 * (i as f64 + 1.3) * (j as f64 + 0.7)).sin() * 0.4);
        let damping = DVector::from_fn(n, |i, _| (i as f64 - 2.5) * 0.8);
        let goal = GoalParams { kp_n_per_m: 250.0, kv_n_s_per_m: 40.0, v_max_m_per_s: 0.12 };
        let mut g = GoalDamping::new(n);
        g.damping_torque_mut().copy_from(&damping);
        let mut bias = DVector::zeros(n);
        assert!(g.add(jt.columns(0, 3), &mass, &vec![0.0; n], &goal, &mut bias));
        let minv = mass.clone().try_inverse().unwrap();
        let in_range = jt.transpose() * &minv * (&bias - &damping);
        assert!(in_range.norm() < 1e-5 * damping.norm(), "the goal's range (up to the regularization): {in_range}");
        let f = (jt.transpose() * &jt).try_inverse().unwrap() * jt.transpose() * &bias;
        assert!((&jt * f - &bias).norm() < 1e-9 * bias.norm(), "a force on the goal's rows");
        let before = (jt.transpose() * &minv * &damping).norm();
        assert!(before > 0.1 * damping.norm(), "the damping had a part in the goal's range: {before}");
    }
}
