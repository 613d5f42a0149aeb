//! Cost of one whole control cycle, `Controller::update`: kinematics, the supervisor's signals
//! and arrangement, skin aggregation of every cell, the tasks, the hierarchy (with CRBA, RNEA,
//! the Cholesky inverse of M), the blend and the resolver.
//!
//! - `controller_update_tomm`: TOMM (15 DoF), 718 cells aggregated, four task levels (skin
//!   avoidance with 12 cells in range, hand distance, wrist, tactile guidance) plus the posture
//!   torque with body compliance and base avoidance from a 360-point scan.
//! - `controller_update_planar7`: planar7 (7 DoF), 405 cells, intentional-contact paper Table I (a): avoidance
//!   (8 cells in range) > goal > contact reaction (2 contact cells).

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::{Isometry3, Vector2};
use skin_core::controller::{Controller, ControllerConfig, ControllerInput};
use skin_core::skin::signals::CellReading;
use skin_core::supervisor::Policy;

fn config(robot: &str) -> ControllerConfig {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../config/controller/{robot}.yaml"));
    ControllerConfig::load(&path).unwrap()
}

fn names(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| s.to_string()).collect()
}

fn bench(
    c: &mut Criterion,
    id: &str,
    mut ctl: Controller,
    q: Vec<f64>,
    cells: Vec<CellReading>,
    scan: Vec<Vector2<f64>>,
) {
    let qd: Vec<f64> = (0..q.len()).map(|i| 0.02 * ((i as f64) * 0.7).sin()).collect();
    let mut t = 0.0;
    c.bench_function(id, |b| {
        b.iter(|| {
            t += 0.008;
            let out = ctl.update(&ControllerInput { t_s: t, dt_s: 0.008, q: &q, qd: &qd, cells: &cells, scan: &scan });
            assert!(out.fault.is_none());
            black_box(out.commands.joint_velocities[0]);
        })
    });
}

fn controller(c: &mut Criterion) {
    let mut cfg = config("tomm");
    cfg.supervisor.policy = Policy::Phases;
    cfg.supervisor.arrangements.precontact =
        names(&["avoidance", "hand_distance", "wrist", "tactile_guidance", "base_avoidance", "compliance", "posture"]);
    let n = cfg.layout.num_cells();
    let mut cells = vec![CellReading::default(); n];
    for i in (0..n).step_by(n / 12) {
        cells[i] = CellReading::uniform(0.0, 0.6); // obstacles in range
    }
    for patch in cfg.layout.patches().iter().filter(|p| [8, 12].contains(&p.id)) {
        for i in patch.cells.clone().step_by(7) {
            cells[i] = CellReading::uniform(0.3, 1.0); // touches on the forearm and the palm
        }
    }
    let scan = (0..360)
        .map(|k| {
            let a = (k as f64).to_radians();
            Vector2::new(a.cos(), a.sin()) * (0.6 + 0.2 * (3.0 * a).cos())
        })
        .collect();
    let q = cfg.setup.posture.clone();
    let ctl = Controller::new(cfg, 0.0).unwrap();
    assert_eq!(ctl.arrangement().task_order().len(), 7);
    bench(c, "controller_update_tomm", ctl, q, cells, scan);

    let cfg = config("planar7");
    let n = cfg.layout.num_cells();
    let mut cells = vec![CellReading::default(); n];
    for i in (0..n).step_by(n / 8) {
        cells[i] = CellReading::uniform(0.0, 0.7);
    }
    cells[100] = CellReading::uniform(0.5, 1.0);
    cells[101] = CellReading::uniform(0.5, 1.0);
    let q = cfg.setup.posture.clone();
    let mut ctl = Controller::new(cfg, 0.0).unwrap();
    ctl.set_goal(Some(Isometry3::translation(0.8, 0.9, 0.0))).unwrap();
    bench(c, "controller_update_planar7", ctl, q, cells, Vec::new());
}

criterion_group!(benches, controller);
criterion_main!(benches);
