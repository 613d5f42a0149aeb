//! Inverse dynamics by the Recursive Newton-Euler Algorithm (Featherstone, RBDA Table 5.1).

use nalgebra::DVector;

use super::kinematics::check_vector;
use super::spatial::{cross_force, svec, SVec};
use super::{ModelData, ModelError, RobotModel};
use nalgebra::Vector3;

fn check_out(model: &RobotModel, out: &DVector<f64>) -> Result<(), ModelError> {
    if out.len() != model.nv() {
        return Err(ModelError::Dimension { what: "torque output", expected: model.nv(), got: out.len() });
    }
    Ok(())
}

/// Shared RNEA core. `qdd = None` means q̈ = 0; `with_velocity = false` treats q̇ as zero.
fn rnea_impl(model: &RobotModel, data: &mut ModelData, qdd: Option<&[f64]>, with_velocity: bool, tau: &mut DVector<f64>) {
    // Gravity enters as a fictitious upward acceleration of the base (RBDA Sec. 5.3).
    let a0 = svec(&Vector3::zeros(), &(-model.gravity));
    let n = model.nv();
    for i in 0..n {
        let b = &model.bodies[i];
        let ap = match b.parent {
            Some(p) => data.a[p],
            None => a0,
        };
        let mut a = ap;
        if let Some(qdd) = qdd {
            a += data.s[i] * qdd[i];
        }
        let inertia = &data.inertia_w[i];
        let f = if with_velocity {
            a += data.c[i];
            let v = &data.v[i];
            inertia.mul_motion(&a) + cross_force(v, &inertia.mul_motion(v))
        } else {
            inertia.mul_motion(&a)
        };
        data.a[i] = a;
        data.f[i] = f;
    }
    for i in (0..n).rev() {
        let f: SVec = data.f[i];
        tau[i] = data.s[i].dot(&f);
        if let Some(p) = model.bodies[i].parent {
            data.f[p] += f;
        }
    }
}

/// Inverse dynamics `τ = M(q) q̈ + C(q, q̇) q̇ + g(q)` at the state of the last
/// [`super::update_kinematics`] (gravity along world -z, see [`RobotModel::gravity`]).
///
/// RNEA (RBDA Table 5.1) in world-aligned coordinates about one reference point, reusing the
/// velocities and velocity-product terms of `update_kinematics`. `qdd` is checked for length and
/// NaN/∞ (the error names the joint); `tau_out` must have length nv. Does not allocate.
pub fn rnea(model: &RobotModel, data: &mut ModelData, qdd: &[f64], tau_out: &mut DVector<f64>) -> Result<(), ModelError> {
    check_vector(model, "qdd", qdd)?;
    check_out(model, tau_out)?;
    rnea_impl(model, data, Some(qdd), true, tau_out);
    Ok(())
}

/// Bias forces `C(q, q̇) q̇ + g(q)` (= [`rnea`] with q̈ = 0).
pub fn bias_forces(model: &RobotModel, data: &mut ModelData, out: &mut DVector<f64>) -> Result<(), ModelError> {
    check_out(model, out)?;
    rnea_impl(model, data, None, true, out);
    Ok(())
}

/// Gravity torques `g(q)` (q̇ treated as zero, q̈ = 0).
pub fn gravity(model: &RobotModel, data: &mut ModelData, out: &mut DVector<f64>) -> Result<(), ModelError> {
    check_out(model, out)?;
    rnea_impl(model, data, None, false, out);
    Ok(())
}
