//! Shared helpers of the skin_sim integration tests (real MuJoCo, the project's URDFs).
#![allow(dead_code)] // each test binary uses its own subset

use std::path::{Path, PathBuf};

use skin_sim::{Scene, World};

/// `config/scenes/`: scene texts in tests resolve their paths from there, like the files.
pub fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/scenes")
}

/// A scene from YAML text, as if it were a file in `config/scenes/`.
pub fn scene(yaml: &str) -> Scene {
    Scene::from_yaml_str(yaml, "test.yaml", &scenes_dir()).unwrap_or_else(|e| panic!("{e}"))
}

/// A world from YAML text.
pub fn world(yaml: &str) -> World {
    World::from_scene(scene(yaml)).unwrap_or_else(|e| panic!("{e}"))
}

/// The planar arm, stretched along x, with its skin; `extra` is appended (objects, ...).
pub fn planar7(extra: &str) -> String {
    format!(
        "robot: {{urdf: ../../urdf/planar7.urdf}}\n\
         skin: {{layout: ../skin/planar7.yaml, params: ../skin_model.yaml}}\n\
         duration_s: 1.0\nfloor_z_m: -0.3\n{extra}"
    )
}

/// TOMM with its right arm and base moving, the right hand over the front (as in the scenes);
/// `initial` adds initial joint positions (`, name: value`), `extra` top-level keys.
pub fn tomm_right_and_base(initial: &str, extra: &str) -> String {
    format!(
        "robot:\n  urdf: ../../urdf/tomm.urdf\n  joints: [base_x_joint, base_y_joint, base_yaw_joint, \
         right_shoulder_pan_joint, right_shoulder_lift_joint, right_elbow_joint, right_wrist_1_joint, \
         right_wrist_2_joint, right_wrist_3_joint]\n  initial: {{right_shoulder_pan_joint: 2.598, \
         right_shoulder_lift_joint: 0.602, right_elbow_joint: -0.924, right_wrist_1_joint: -1.642, \
         right_wrist_2_joint: 2.288, right_wrist_3_joint: 0.984{initial}}}\nduration_s: 1.0\n{extra}"
    )
}

/// Runs `world` for `seconds`.
pub fn run(world: &mut World, seconds: f64) {
    let steps = (seconds / world.scene().spec.timestep_s).round() as usize;
    for _ in 0..steps {
        world.step();
    }
}
