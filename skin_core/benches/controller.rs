//! Cost of one whole control cycle, `Controller::update`: kinematics, the supervisor's signals
//! and arrangement, skin aggregation of every cell, the tasks, the hierarchy (with CRBA, RNEA,
//! the Cholesky inverse of M), the blend and the resolver. Each point's stage shares go to
//! `out/bench/stages.json` (`support::bench`).
//!
//! - `controller_update_tomm`: TOMM (15 DoF), its 1082 cells aggregated, four task levels (skin
//!   avoidance with 12 cells in range, hand distance, wrist, tactile guidance) plus the posture
//!   torque with body compliance and base avoidance from a 360-point scan.
//! - `controller_update_planar7`: planar7 (7 DoF), 563 cells, intentional-contact paper Table I (a): avoidance
//!   (8 cells in range) > goal > contact reaction (2 contact cells).
//! - `controller_update_humanoid`: the 29-joint humanoid with its generated whole-body skin
//!   (`support::humanoid_config`, over 3 000 cells), 50 live cells (40 in range over the whole
//!   body, 10 touches on the right arm and hand), TOMM's four levels plus posture.

mod support;

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::Isometry3;
use skin_core::controller::{Controller, ControllerConfig};
use skin_core::model::RobotModel;
use skin_core::skin::generate::{generate_layout, GeneratorSpec, PatchFrame};
use skin_core::skin::signals::CellReading;
use support::{bench, config, names, readings, root, scan, tomm_config, Point};

/// Cell pitch of the humanoid's whole-body skin \[m\].
const HUMANOID_PITCH_M: f64 = 0.024;

/// The 29-joint humanoid (`urdf/humanoid29.urdf`) with every body link covered at
/// [`HUMANOID_PITCH_M`], TOMM's parameter files, the right hand as end effector and the same
/// four levels plus posture as [`tomm_config`] (no base: no base avoidance).
fn humanoid_config() -> ControllerConfig {
    let mut cfg = tomm_config();
    let model = RobotModel::from_urdf_file(&root().join("urdf/humanoid29.urdf")).unwrap();
    let mut links = Vec::new();
    for side in ["left", "right"] {
        for link in ["thigh", "shin", "foot", "upper_arm", "forearm", "hand"] {
            links.push(format!("{side}_{link}_link"));
        }
    }
    links.extend(["pelvis", "torso_link", "head_link"].map(String::from));
    let spec = GeneratorSpec {
        links: links.iter().map(|l| l.parse().unwrap()).collect(),
        pitch_m: HUMANOID_PITCH_M,
        faces: Vec::new(),
        spheres: false,
        patch_frame: PatchFrame::Primitive,
        ..Default::default()
    };
    let layout = generate_layout(&model, &spec).unwrap().resolve(&model).unwrap();
    let patch_id = |link: &str| layout.patches().iter().find(|p| p.link == link).unwrap().id;
    cfg.setup.end_effector = "right_hand_link".into();
    cfg.setup.hand_patches = vec![patch_id("right_hand_link")];
    cfg.setup.guidance_patches = ["right_upper_arm_link", "right_forearm_link"].map(patch_id).to_vec();
    cfg.setup.locked_joints.clear();
    // arms bent forward, knees slightly bent: away from the joints' limits and singularities
    cfg.setup.posture = model
        .joint_names()
        .iter()
        .map(|j| match j.as_str() {
            n if n.ends_with("shoulder_pitch_joint") => -0.6,
            n if n.ends_with("elbow_joint") => 1.2,
            n if n.ends_with("knee_joint") => 0.4,
            n if n.ends_with("hip_pitch_joint") || n.ends_with("ankle_pitch_joint") => -0.2,
            "left_shoulder_roll_joint" => 0.3,
            "right_shoulder_roll_joint" => -0.3,
            _ => 0.1,
        })
        .collect();
    cfg.supervisor.arrangements.precontact =
        names(&["avoidance", "hand_distance", "wrist", "tactile_guidance", "compliance", "posture"]);
    cfg.layout = layout;
    cfg.model = model;
    cfg
}

fn controller(c: &mut Criterion) {
    let cfg = tomm_config();
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
    let ctl = Controller::new(cfg, 0.0).unwrap();
    assert_eq!(ctl.arrangement().task_order().len(), 7);
    bench(c, Point::new("controller_update_tomm", ctl, cells, scan()));

    let cfg = config("planar7");
    let n = cfg.layout.num_cells();
    let mut cells = vec![CellReading::default(); n];
    for i in (0..n).step_by(n / 8) {
        cells[i] = CellReading::uniform(0.0, 0.7);
    }
    cells[100] = CellReading::uniform(0.5, 1.0);
    cells[101] = CellReading::uniform(0.5, 1.0);
    let mut ctl = Controller::new(cfg, 0.0).unwrap();
    ctl.set_goal(Some(Isometry3::translation(0.8, 0.9, 0.0))).unwrap();
    bench(c, Point::new("controller_update_planar7", ctl, cells, Vec::new()));

    let cfg = humanoid_config();
    assert!(cfg.layout.num_cells() >= 3000, "humanoid skin: {} cells", cfg.layout.num_cells());
    let hand: Vec<u32> = cfg.setup.hand_patches.iter().chain(&cfg.setup.guidance_patches).copied().collect();
    let cells = readings(&cfg.layout, 40, 10, &hand);
    let ctl = Controller::new(cfg, 0.0).unwrap();
    assert_eq!(ctl.arrangement().task_order().len(), 6);
    bench(c, Point::new("controller_update_humanoid", ctl, cells, Vec::new()));
}

criterion_group!(benches, controller);
criterion_main!(benches);
