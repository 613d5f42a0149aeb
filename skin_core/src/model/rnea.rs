//! Inverse dynamics by the Recursive Newton-Euler Algorithm (Featherstone, RBDA Table 5.1).

use nalgebra::DVector;

use super::data::ModelData;
use super::error::ModelError;
use super::kinematics::check_vector;
use super::robot::RobotModel;
use super::spatial::{cross_force, svec, SVec};
use nalgebra::Vector3;

fn check_out(model: &RobotModel, out: &DVector<f64>) -> Result<(), ModelError> {
    if out.len() != model.nv() {
        return Err(ModelError::Dimension { what: "torque output", expected: model.nv(), got: out.len() });
    }
    Ok(())
}

/// Shared RNEA core. `qdd = None` means q̈ = 0.
fn rnea_impl(model: &RobotModel, data: &mut ModelData, qdd: Option<&[f64]>, tau: &mut DVector<f64>) {
    // Gravity enters as a fictitious upward acceleration of the base (RBDA Sec. 5.3).
    let a0 = svec(&Vector3::zeros(), &(-model.gravity));
    for i in 0..model.njoints() {
        let b = &model.bodies[i];
        let ap = match b.parent {
            Some(p) => data.a[p],
            None => a0,
        };
        let mut a = ap;
        if let Some(qdd) = qdd {
            a += data.s[i] * qdd[b.coord];
        }
        let inertia = &data.inertia_w[i];
        a += data.c[i];
        let v = &data.v[i];
        let f = inertia.mul_motion(&a) + cross_force(v, &inertia.mul_motion(v));
        data.a[i] = a;
        data.f[i] = f;
    }
    backward_pass(model, data, tau);
}

/// RNEA's second pass: `τ_i = S_iᵀ f_i`, each body's force added to its parent's (a followed
/// mimic joint's torque adds to its leader's coordinate).
fn backward_pass(model: &RobotModel, data: &mut ModelData, tau: &mut DVector<f64>) {
    tau.fill(0.0);
    for i in (0..model.njoints()).rev() {
        let f: SVec = data.f[i];
        tau[model.bodies[i].coord] += data.s[i].dot(&f);
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
pub fn rnea(
    model: &RobotModel,
    data: &mut ModelData,
    qdd: &[f64],
    tau_out: &mut DVector<f64>,
) -> Result<(), ModelError> {
    check_vector(model, "qdd", qdd)?;
    check_out(model, tau_out)?;
    rnea_impl(model, data, Some(qdd), tau_out);
    Ok(())
}

/// Bias forces `C(q, q̇) q̇ + g(q)` (= [`rnea`] with q̈ = 0).
pub fn bias_forces(model: &RobotModel, data: &mut ModelData, out: &mut DVector<f64>) -> Result<(), ModelError> {
    check_out(model, out)?;
    rnea_impl(model, data, None, out);
    Ok(())
}

/// Gravity torques `g(q)` (q̇ treated as zero, q̈ = 0): [`rnea`] with every body at the base's
/// fictitious acceleration `a_0 = [0; −g]`, whose force `I_i a_0 = [h_i × (−g); −m_i g]`
/// (`h_i` the body's first mass moment about the reference point) needs no inertia product.
pub fn gravity(model: &RobotModel, data: &mut ModelData, out: &mut DVector<f64>) -> Result<(), ModelError> {
    check_out(model, out)?;
    let a0 = -model.gravity;
    for (f, inertia) in data.f.iter_mut().zip(&data.inertia_w) {
        *f = svec(&inertia.h.cross(&a0), &(a0 * inertia.mass));
    }
    backward_pass(model, data, out);
    Ok(())
}
