//! Costs of the simulation loop on TOMM (all 15 joints, 718 skin cells, a table under the right
//! hand, a 360-ray LIDAR):
//! - `world_step_tomm`: one `World::step` at 1 kHz with the sensors sampled at their rates
//!   (skin every 4th step, LIDAR every 25th);
//! - `skin_sample_tomm_718`: one skin sample (718 rays plus the contact forces);
//! - `skin_and_lidar_sample_tomm`: the same plus one 360-ray scan.
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use skin_sim::{Scene, World};

const SCENE: &str = "
robot:
  urdf: ../../urdf/tomm.urdf
  initial: {right_shoulder_pan_joint: 2.598, right_shoulder_lift_joint: 0.602, right_elbow_joint: -0.924,
            right_wrist_1_joint: -1.642, right_wrist_2_joint: 2.288, right_wrist_3_joint: 0.984}
skin: {layout: ../skin/tomm.yaml, params: ../skin_model.yaml}
lidar: {rays: 360}
objects:
  - {name: table, shape: {table: {top_m: [0.8, 1.2, 0.04], height_m: 0.85}}, xyz: [0.95, -0.45, 0.0]}
duration_s: 1.0
";

fn tomm() -> World {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/scenes");
    World::from_scene(Scene::from_yaml_str(SCENE, "bench", &dir).expect("scene")).expect("world")
}

fn bench(c: &mut Criterion) {
    let mut w = tomm();
    w.set_base_twist([0.05, 0.0, 0.05]);
    c.bench_function("world_step_tomm", |b| b.iter(|| w.step()));
    let mut w = tomm();
    let no_lidar = Scene::from_yaml_str(
        &SCENE.replace("lidar: {rays: 360}\n", ""),
        "bench",
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/scenes"),
    )
    .expect("scene");
    let mut skin_only = World::from_scene(no_lidar).expect("world");
    c.bench_function("skin_sample_tomm_718", |b| b.iter(|| skin_only.sample_sensors()));
    c.bench_function("skin_and_lidar_sample_tomm", |b| b.iter(|| w.sample_sensors()));
}

criterion_group!(benches, bench);
criterion_main!(benches);
