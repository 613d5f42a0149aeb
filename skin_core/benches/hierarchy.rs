//! Cost of one hierarchy solve on TOMM (15 DoF): 4 levels (a 1-row skin force level, the 3-row
//! wrist orientation level, the 3-row hand position level, a 6-row level on the other hand) and a
//! posture torque; the solve includes the Cholesky factorization and inverse of M.
//! `hierarchy_tomm_cycle` adds what a control cycle does around it: kinematics, CRBA, bias
//! forces, the point Jacobians and J̇q̇ terms, and filling the levels.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::{DMatrix, DVector, Matrix6xX, Vector3, Vector6};
use skin_core::hierarchy::*;
use skin_core::model::*;

struct Setup {
    model: RobotModel,
    data: ModelData,
    m: DMatrix<f64>,
    bias: DVector<f64>,
    j: Matrix6xX<f64>,
    jd: Vector6<f64>,
    levels: Vec<TaskLevel>,
    posture: Vec<f64>,
    q: Vec<f64>,
    qd: Vec<f64>,
}

fn fill(s: &mut Setup) {
    let model = &s.model;
    let n = model.nv();
    update_kinematics(model, &mut s.data, &s.q, &s.qd).unwrap();
    crba(model, &mut s.data, &mut s.m).unwrap();
    bias_forces(model, &mut s.data, &mut s.bias).unwrap();
    let forearm = model.frame_index("right_forearm_link").unwrap();
    let hand = model.frame_index("right_hand").unwrap();
    let left = model.frame_index("left_hand").unwrap();
    let p0 = Vector3::zeros();
    // 1: avoidance force along a skin cell's normal (intentional-contact paper eq. 3-4)
    let cell = Vector3::new(-0.2, 0.0, 0.05);
    point_jacobian(model, &s.data, forearm, &cell, &mut s.j).unwrap();
    s.levels[0].clear();
    s.levels[0].push_directional(&[0.0, 0.6, 0.8], &s.j.fixed_rows::<3>(0), Reference::Force { f: &[4.0] }).unwrap();
    // 2, 3: wrist orientation and hand position (interactive-force-control paper eq. 10, 12)
    point_jacobian(model, &s.data, hand, &p0, &mut s.j).unwrap();
    point_jacobian_dot_qdot(model, &s.data, hand, &p0, &mut s.jd).unwrap();
    let (jd_ang, jd_lin) = ([s.jd[3], s.jd[4], s.jd[5]], [s.jd[0], s.jd[1], s.jd[2]]);
    s.levels[1]
        .set(&s.j.fixed_rows::<3>(3), Reference::Acceleration { xdd_star: &[0.1, -0.2, 0.05], jdot_qdot: &jd_ang })
        .unwrap();
    s.levels[2]
        .set(&s.j.fixed_rows::<3>(0), Reference::Acceleration { xdd_star: &[0.3, 0.0, -0.1], jdot_qdot: &jd_lin })
        .unwrap();
    // 4: full 6-D task on the left hand
    point_jacobian(model, &s.data, left, &p0, &mut s.j).unwrap();
    point_jacobian_dot_qdot(model, &s.data, left, &p0, &mut s.jd).unwrap();
    s.levels[3]
        .set(&s.j, Reference::Acceleration { xdd_star: &[0.0, 0.1, 0.0, 0.0, 0.0, 0.2], jdot_qdot: s.jd.as_slice() })
        .unwrap();
    for (i, t) in s.posture.iter_mut().enumerate() {
        *t = -2.0 * (s.q[i] - 0.1) - 0.5 * s.qd[i];
    }
    assert_eq!(s.posture.len(), n);
}

fn hierarchy_tomm(c: &mut Criterion) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../urdf/tomm.urdf");
    let model = RobotModel::from_urdf_file(std::path::Path::new(path)).unwrap();
    let n = model.nv();
    let q: Vec<f64> = (0..n).map(|i| 0.3 * ((i as f64) * 0.7).sin() + 0.1).collect();
    let qd: Vec<f64> = (0..n).map(|i| 0.2 - 0.03 * i as f64).collect();
    let levels = ["skin_avoidance", "wrist", "hand_position", "left_hand"]
        .iter()
        .zip([1, 3, 3, 6])
        .map(|(name, rows)| TaskLevel::new(name, n, rows))
        .collect();
    let mut s = Setup {
        data: ModelData::new(&model),
        m: DMatrix::zeros(n, n),
        bias: DVector::zeros(n),
        j: Matrix6xX::zeros(n),
        jd: Vector6::zeros(),
        levels,
        posture: vec![0.0; n],
        q,
        qd,
        model,
    };
    fill(&mut s);
    let mut solver = HierarchySolver::new(n, 4, 6, InverseParams::default()).unwrap();
    let mut tau = DVector::zeros(n);

    c.bench_function("hierarchy_tomm_4_levels", |b| {
        b.iter(|| {
            solver
                .solve(
                    black_box(&s.m),
                    s.levels.iter(),
                    Some(black_box(&s.posture[..])),
                    Some(s.bias.as_slice()),
                    &mut tau,
                )
                .unwrap();
            black_box(&tau);
        })
    });
    c.bench_function("hierarchy_tomm_cycle", |b| {
        b.iter(|| {
            fill(&mut s);
            solver.solve(&s.m, s.levels.iter(), Some(&s.posture[..]), Some(s.bias.as_slice()), &mut tau).unwrap();
            black_box(&tau);
        })
    });
}

criterion_group!(benches, hierarchy_tomm);
criterion_main!(benches);
