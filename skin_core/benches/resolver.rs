//! Cost of one resolver step on TOMM (15 joints, 12 arm joints, base):
//! `resolver_update_tomm` = `update_arms` + `update_base` with varying torques (so the limits
//! are exercised) and the nominal arm period (cached exact-step coefficients).

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion};
use skin_core::model::RobotModel;
use skin_core::resolver::{Resolver, ResolverParams};

fn bench(c: &mut Criterion) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let model = RobotModel::from_urdf_file(&root.join("urdf/tomm.urdf")).unwrap();
    let params = ResolverParams::load(&root.join("config/resolver.yaml")).unwrap();
    let mut r = Resolver::new(&model, params).unwrap();
    let n = model.nv();
    let q: Vec<f64> = (0..n).map(|i| 0.1 * i as f64 - 0.5).collect();
    let qd: Vec<f64> = (0..n).map(|i| 0.05 * i as f64 - 0.3).collect();
    let g: Vec<f64> = (0..n).map(|i| 2.0 * i as f64).collect();
    let mut tau: Vec<f64> = g.iter().map(|x| x + 5.0).collect();
    r.reset(&q, &qd).unwrap();
    let mut k = 0usize;
    c.bench_function("resolver_update_tomm", |b| {
        b.iter(|| {
            k = k.wrapping_add(1);
            tau[k % n] = if k % 2 == 0 { 40.0 } else { -40.0 };
            let c = r.update_arms(black_box(&tau), &g, &q, &qd, 1.0 / 125.0).unwrap();
            black_box(c.joint_velocities[0]);
            let c = r.update_base(black_box(&tau), &q, &qd, 1.0 / 1000.0).unwrap();
            black_box(c.base_twist);
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
