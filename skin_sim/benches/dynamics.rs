//! The work a control cycle asks of rigid-body dynamics, on tomm.urdf (15 DoF), by skin_core and
//! by MuJoCo in the same run, so that the ratio holds whatever the machine's speed:
//! - `dynamics_tomm`: skin_core frames and velocities, one point Jacobian per moving body, CRBA
//!   (M) and RNEA (C q̇ + g);
//! - `dynamics_tomm_mujoco`: MuJoCo's nearest equivalent, `mj_kinematics`, `mj_comPos`, `mj_crb`
//!   + `mj_makeM` (dense-able M), `mj_comVel`, `mj_rne` (flg_acc = 0) and `mj_jacBody` per body.
use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion};
use mujoco_rs::mujoco_c;
use mujoco_rs::prelude::*;
use nalgebra::{DMatrix, DVector, Matrix6xX, Vector3};
use skin_core::model::{bias_forces, crba, point_jacobian, update_kinematics, ModelData, RobotModel};

fn tomm_urdf() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../urdf/tomm.urdf"))
}

/// A generic state: every joint away from zero and moving.
fn state(n: usize) -> (Vec<f64>, Vec<f64>) {
    let q = (0..n).map(|i| 0.3 * ((i as f64) * 0.7).sin() + 0.1).collect();
    let qd = (0..n).map(|i| 0.5 * ((i as f64) * 1.3).cos()).collect();
    (q, qd)
}

fn ours(c: &mut Criterion) {
    let model = RobotModel::from_urdf_file(&tomm_urdf()).expect("tomm.urdf loads");
    let mut data = ModelData::new(&model);
    let n = model.nv();
    let (q, qd) = state(n);
    let mut m = DMatrix::zeros(n, n);
    let mut bias = DVector::zeros(n);
    let mut jac = Matrix6xX::zeros(n);
    let bodies: Vec<usize> = (0..n).map(|j| model.joint_child_frame(j)).collect();
    let origin = Vector3::zeros();
    c.bench_function("dynamics_tomm", |b| {
        b.iter(|| {
            update_kinematics(&model, &mut data, &q, &qd).unwrap();
            for &f in &bodies {
                point_jacobian(&model, &data, f, &origin, &mut jac).unwrap();
            }
            crba(&model, &mut data, &mut m).unwrap();
            bias_forces(&model, &mut data, &mut bias).unwrap();
            std::hint::black_box((&m, &bias, &jac));
        })
    });
}

fn mujoco(c: &mut Criterion) {
    let mjm = MjModel::from_xml(tomm_urdf()).expect("MuJoCo loads tomm.urdf");
    let mut mjd = MjData::new(&mjm);
    let nv = mjm.ffi().nv as usize;
    let (q, qd) = state(nv);
    mjd.qpos_mut().copy_from_slice(&q[..mjm.ffi().nq as usize]);
    mjd.qvel_mut().copy_from_slice(&qd);
    let nbody = mjm.ffi().nbody as usize;
    let mut jacp = vec![0.0; 3 * nv];
    let mut jacr = vec![0.0; 3 * nv];
    let mut rne = vec![0.0; nv];
    c.bench_function("dynamics_tomm_mujoco", |b| {
        b.iter(|| {
            // SAFETY: model and data are valid and sized for each other; buffers are 3 x nv.
            unsafe {
                let (m, d) = (mjm.ffi(), mjd.ffi_mut());
                mujoco_c::mj_kinematics(m, d);
                mujoco_c::mj_comPos(m, d);
                mujoco_c::mj_crb(m, d);
                mujoco_c::mj_makeM(m, d);
                mujoco_c::mj_comVel(m, d);
                mujoco_c::mj_rne(m, d, 0, rne.as_mut_ptr());
                for body in 1..nbody {
                    mujoco_c::mj_jacBody(m, d, jacp.as_mut_ptr(), jacr.as_mut_ptr(), body as i32);
                }
            }
            std::hint::black_box((&rne, &jacp, &jacr));
        })
    });
}

criterion_group!(benches, ours, mujoco);
criterion_main!(benches);
