//! Cost of the priority supervisor per control cycle: `supervisor_update` runs one intentional-contact paper
//! Table I update (cycling through (a), (b), (c) so every branch is exercised), `blend_15dof`
//! one intentional-contact paper eq. (10) torque blend for TOMM's 15 DoF during a switch.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use skin_core::supervisor::*;

fn params() -> SupervisorParams {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../config/supervisor.yaml");
    SupervisorParams::load(std::path::Path::new(path)).expect("config/supervisor.yaml")
}

fn bench_update(c: &mut Criterion) {
    let p = params();
    let mut sup = Supervisor::new(&p, 0.0).unwrap();
    // A 4 s scenario at 250 Hz: stuck -> (b), over-limit contact -> (c), release, goal reached.
    let inputs: Vec<SupervisorInput> = (0..1000)
        .map(|k| {
            let s = k as f64 / 1000.0;
            SupervisorInput {
                ee_speed_mps: if s < 0.3 { 0.0 } else { 0.05 },
                avoidance_force_n: 3.0,
                contact_force_n: if (0.4..0.5).contains(&s) { 8.0 } else { 0.0 },
                goal_error_m: if s < 0.8 { 0.2 } else { 0.0 },
                contact_advance_mps: f64::NAN,
            }
        })
        .collect();
    let mut k = 0usize;
    let mut t = 0.0;
    c.bench_function("supervisor_update", |b| {
        b.iter(|| {
            t += 0.004;
            let a = sup.update(black_box(t), black_box(&inputs[k]));
            k = (k + 1) % inputs.len();
            black_box(a.mode)
        })
    });
}

fn bench_blend(c: &mut Criterion) {
    let n = 15;
    let mut blender = TorqueBlender::new(n);
    let old: Vec<f64> = (0..n).map(|i| i as f64 * 0.7 - 3.0).collect();
    let new: Vec<f64> = (0..n).map(|i| 2.0 - i as f64 * 0.3).collect();
    let mut out = vec![0.0; n];
    blender.apply(0.0, &old, &mut out);
    blender.start(0.0, 1e-6); // a very slow blend: every iteration blends
    let mut t = 0.0;
    c.bench_function("blend_15dof", |b| {
        b.iter(|| {
            t += 0.008;
            blender.apply(black_box(t), black_box(&new), &mut out);
            black_box(out[0])
        })
    });
}

criterion_group!(benches, bench_update, bench_blend);
criterion_main!(benches);
