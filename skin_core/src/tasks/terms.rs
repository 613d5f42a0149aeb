//! Terms the task references share: `J q̇` of a Jacobian's three rows, and the impedance
//! acceleration of interactive-force-control paper eq. (4)/(5).

use nalgebra::{Matrix6xX, Vector3};

use super::params;

/// `J[row0..row0+3] q̇` of a 6 × nv Jacobian (linear rows: 0, angular rows: 3), no allocation.
pub(crate) fn rows_times_qd(jac: &Matrix6xX<f64>, row0: usize, qd: &[f64]) -> Vector3<f64> {
    let mut v = Vector3::zeros();
    for (c, q) in qd.iter().enumerate().take(jac.ncols()) {
        for r in 0..3 {
            v[r] += jac[(row0 + r, c)] * q;
        }
    }
    v
}

/// Reference acceleration of interactive-force-control paper eq. (4)/(5) per axis: `(k e − d ẋ) / λ`.
pub(crate) fn impedance_acceleration(
    imp: &params::Impedance3,
    error: &Vector3<f64>,
    velocity: &Vector3<f64>,
) -> Vector3<f64> {
    Vector3::from_fn(|i, _| (imp.k[i] * error[i] - imp.d[i] * velocity[i]) / imp.lambda[i])
}
