//! The parts of a control cycle's model evaluation on TOMM (15 DoF), one by one: forward
//! kinematics, the mass matrix (CRBA) and inverse dynamics (RNEA). The whole cycle, side by side
//! with MuJoCo doing the same work, is `dynamics_tomm` in skin_sim's `dynamics` bench.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::{DMatrix, DVector};
use skin_core::model::*;

fn dynamics_parts_tomm(c: &mut Criterion) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../urdf/tomm.urdf");
    let model = RobotModel::from_urdf_file(std::path::Path::new(path)).unwrap();
    let n = model.nv();
    let mut data = ModelData::new(&model);
    let mut m = DMatrix::zeros(n, n);
    let mut tau = DVector::zeros(n);
    let q: Vec<f64> = (0..n).map(|i| 0.1 * i as f64 - 0.5).collect();
    let qd: Vec<f64> = (0..n).map(|i| 0.3 - 0.05 * i as f64).collect();
    let qdd = vec![0.7; n];

    c.bench_function("update_kinematics_tomm", |b| {
        b.iter(|| update_kinematics(&model, &mut data, black_box(&q), black_box(&qd)).unwrap())
    });
    c.bench_function("crba_tomm", |b| b.iter(|| crba(&model, &mut data, black_box(&mut m)).unwrap()));
    c.bench_function("rnea_tomm", |b| b.iter(|| rnea(&model, &mut data, black_box(&qdd), &mut tau).unwrap()));
}

criterion_group!(benches, dynamics_parts_tomm);
criterion_main!(benches);
