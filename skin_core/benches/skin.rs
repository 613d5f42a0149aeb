//! Skin benchmarks on the shipped TOMM model and layout:
//! - `aggregate_700_cells`: every cell of `config/skin/tomm.yaml` (718 cells, on the order of the
//!   real robot's 700) active -> patch wrenches (interactive-force-control paper eq. (6)-(8));
//! - `cell_torques_50_active`: `J^T F` over 50 cell forces spread over all covered links
//!   (intentional-contact paper eq. (4));
//! - `repulsion_forces_and_torques_50_active`: proximity signals of all cells (50 non-zero) ->
//!   intentional-contact paper eq. (3) forces -> torques.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::DVector;
use skin_core::model::{update_kinematics, ModelData, RobotModel};
use skin_core::skin::aggregate::{aggregate_patches, PatchWrench};
use skin_core::skin::cell_forces::{cell_repulsion_forces, PointForce};
use skin_core::skin::layout::SkinLayout;
use skin_core::skin::params::SkinParams;
use skin_core::skin::signals::CellReading;
use skin_core::skin::torques::point_forces_to_torques;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn bench(c: &mut Criterion) {
    let model = RobotModel::from_urdf_file(&root().join("urdf/tomm.urdf")).unwrap();
    let layout = SkinLayout::load(&root().join("config/skin/tomm.yaml")).unwrap().resolve(&model).unwrap();
    let params = SkinParams::load(&root().join("config/skin_model.yaml")).unwrap();
    let n = layout.num_cells();
    let mut data = ModelData::new(&model);
    let q: Vec<f64> = (0..model.nv()).map(|i| 0.3 * ((i as f64) * 0.7).sin()).collect();
    let qd = vec![0.0; model.nv()];
    update_kinematics(&model, &mut data, &q, &qd).unwrap();

    // All cells active with varied signals.
    let readings: Vec<CellReading> = (0..n)
        .map(|i| {
            let x = (i as f64 * 0.618).fract();
            CellReading { force: [x, 0.5 * x, 0.2 + 0.5 * x], proximity: 0.1 + 0.8 * x }
        })
        .collect();
    let mut wrenches: Vec<PatchWrench> = Vec::with_capacity(layout.patches().len());
    c.bench_function("aggregate_700_cells", |b| {
        b.iter(|| {
            aggregate_patches(&layout, black_box(&readings), &params.fusion, &mut wrenches).unwrap();
            black_box(&wrenches);
        })
    });

    // 50 active cells spread evenly over the layout (every patch gets some).
    let mut sparse = vec![CellReading::default(); n];
    let stride = n / 50;
    for k in 0..50 {
        sparse[k * stride].proximity = 0.3 + 0.01 * k as f64;
    }
    let mut forces: Vec<PointForce> = Vec::with_capacity(n);
    cell_repulsion_forces(&layout, &sparse, &params.proximity, &params.repulsion, |f| data.frame_pose(f), &mut forces)
        .unwrap();
    assert_eq!(forces.len(), 50, "all 50 cells within repulsion range");
    let mut tau = DVector::zeros(model.nv());
    c.bench_function("cell_torques_50_active", |b| {
        b.iter(|| {
            point_forces_to_torques(&model, &data, black_box(&forces), &mut tau);
            black_box(&tau);
        })
    });
    c.bench_function(&format!("repulsion_forces_and_torques_50_active_of_{n}"), |b| {
        b.iter(|| {
            cell_repulsion_forces(
                &layout,
                black_box(&sparse),
                &params.proximity,
                &params.repulsion,
                |f| data.frame_pose(f),
                &mut forces,
            )
            .unwrap();
            point_forces_to_torques(&model, &data, &forces, &mut tau);
            black_box(&tau);
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
