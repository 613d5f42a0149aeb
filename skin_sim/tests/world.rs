//! The generated worlds load and move as commanded; scene files validate; errors name the key.

mod common;

use common::{planar7, run, scene, scenes_dir, tomm_right_and_base, world};
use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::mj_model::MjtGeomBase;
use skin_sim::world::mjcf::ROBOT_GROUP;
use skin_sim::{Scene, SceneError, World};

fn actuators(w: &World) -> usize {
    w.mj_model().ffi().nu as usize
}

/// Contacts between two robot geoms at the world's current state.
fn robot_self_contacts(w: &World) -> Vec<(String, String)> {
    let m = w.mj_model();
    let name = |g: i32| {
        let b = m.geom_bodyid()[g as usize];
        m.id_to_name(MjtObjBase::mjOBJ_BODY, b as usize).unwrap_or("?").to_string()
    };
    w.mj_data()
        .contact()
        .iter()
        .filter(|c| [c.geom1, c.geom2].iter().all(|&g| m.geom_group()[g as usize] == ROBOT_GROUP as i32))
        .map(|c| (name(c.geom1), name(c.geom2)))
        .collect()
}

#[test]
fn tomm_full_subset_and_planar7_load_with_one_servo_per_moving_joint() {
    let full = world("robot: {urdf: ../../urdf/tomm.urdf}\nduration_s: 1.0\n");
    assert_eq!(actuators(&full), 15);
    assert_eq!(full.q().len(), 15);
    let subset = world(&tomm_right_and_base("", ""));
    assert_eq!(actuators(&subset), 9);
    // Frozen joints report their fixed value; kept ones their initial value.
    let m = &subset.scene().model;
    assert_eq!(subset.q()[m.joint_index("left_elbow_joint").unwrap()], 0.0);
    let elbow = subset.q()[m.joint_index("right_elbow_joint").unwrap()];
    assert!((elbow + 0.924).abs() < 1e-12, "{elbow}");
    let planar = world(&planar7(""));
    assert_eq!(actuators(&planar), 7);
}

#[test]
fn every_scene_file_loads_without_robot_self_contact() {
    let mut n = 0;
    for entry in std::fs::read_dir(scenes_dir()).unwrap() {
        let path = entry.unwrap().path();
        let w = World::from_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(robot_self_contacts(&w), Vec::<(String, String)>::new(), "{}", path.display());
        n += 1;
    }
    assert!(n >= 7, "only {n} scene files");
}

#[test]
fn a_joint_velocity_command_is_tracked_within_3_control_periods() {
    let mut w = world(&tomm_right_and_base("", ""));
    let m = w.scene().model.clone();
    let elbow = m.joint_index("right_elbow_joint").unwrap();
    let lift = m.joint_index("right_shoulder_lift_joint").unwrap();
    let mut cmd = vec![0.0; w.arm_joints().len()];
    let pos = |j: usize, w: &World| w.arm_joints().iter().position(|&a| a == j).unwrap();
    cmd[pos(elbow, &w)] = 0.5;
    cmd[pos(lift, &w)] = -0.3;
    w.set_arm_velocity_commands(&cmd).unwrap();
    // 3 periods of the 125 Hz arm interface = 24 ms.
    run(&mut w, 0.024);
    assert!((w.qd()[elbow] - 0.5).abs() < 0.025, "elbow {}", w.qd()[elbow]);
    assert!((w.qd()[lift] + 0.3).abs() < 0.015, "lift {}", w.qd()[lift]);
    let pan = m.joint_index("right_shoulder_pan_joint").unwrap();
    assert!(w.qd()[pan].abs() < 0.02, "pan {}", w.qd()[pan]);
    assert!(w.set_arm_velocity_commands(&[0.0; 3]).is_err());
}

#[test]
fn a_base_twist_moves_the_base_in_its_own_frame_when_yawed() {
    let mut w = world(&tomm_right_and_base(", base_yaw_joint: 1.5707963267948966", ""));
    w.set_base_twist([0.2, 0.0, 0.0]);
    run(&mut w, 1.0);
    let m = w.scene().model.clone();
    let (x, y) = (m.joint_index("base_x_joint").unwrap(), m.joint_index("base_y_joint").unwrap());
    // Facing +y, forward is +y: 0.2 m after 1 s, less the servo's lag (~12 ms).
    assert!(w.q()[x].abs() < 2e-3, "x {}", w.q()[x]);
    assert!((w.q()[y] - 0.2).abs() < 5e-3, "y {}", w.q()[y]);
    w.set_base_twist([0.0, 0.0, 0.5]);
    run(&mut w, 1.0);
    let yaw = w.q()[m.joint_index("base_yaw_joint").unwrap()];
    assert!((yaw - (std::f64::consts::FRAC_PI_2 + 0.5)).abs() < 0.02, "yaw {yaw}");
}

#[test]
fn the_person_follows_its_path() {
    let mut w = world(&planar7(
        "persons:\n  - name: p\n    path: [{t_s: 0.0, xy_m: [3.0, 0.0]}, {t_s: 2.0, xy_m: [1.0, 1.0]}]\n",
    ));
    run(&mut w, 1.0);
    let [x, y, z] = w.body_position("p").unwrap();
    // Mocap positions are set before each step: at most one step (1 ms at 1.1 m/s) behind.
    assert!((x - 2.0).abs() < 2e-3 && (y - 0.5).abs() < 2e-3, "({x}, {y})");
    assert_eq!(z, -0.3);
    run(&mut w, 2.0);
    assert_eq!(w.body_position("p").unwrap(), [1.0, 1.0, -0.3]);
}

/// An object pushed by a hand of `max_speed_mps` (none: a bare force): its speed along the push
/// after `t` s of a 12 N push on 0.5 kg with 1 N of friction, away from the arm.
fn pushed_speed(max_speed_mps: Option<f64>, t: f64) -> f64 {
    let hand = max_speed_mps.map_or(String::new(), |v| format!(", max_speed_mps: {v}"));
    let mut w = world(&planar7(&format!(
        "objects:\n  - {{name: b, shape: {{cylinder: {{radius_m: 0.1, length_m: 0.6}}}}, xyz: [0.0, -1.0, 0.0], \
         mass_kg: 0.5, friction: 0.2}}\npushes: [{{object: b, force_n: [0.0, -12.0, 0.0], start_s: 0.0, end_s: 2.0{hand}}}]\n"
    )));
    run(&mut w, t);
    let y0 = w.body_position("b").unwrap()[1];
    run(&mut w, 0.1);
    (y0 - w.body_position("b").unwrap()[1]) / 0.1
}

#[test]
fn a_push_follows_its_object_at_the_hands_speed() {
    // 22 m/s² bare: 10 m/s after half a second.
    assert!(pushed_speed(None, 0.4) > 8.0);
    for v in [0.3, 1.0] {
        let s = pushed_speed(Some(v), 0.4);
        // The hand keeps up against the friction, and lets go within a step (12 N on 0.5 kg: 0.024 m/s).
        assert!(s > 0.9 * v && s < v + 0.03, "hand at {v} m/s: the object at {s} m/s");
    }
}

fn invalid(yaml: &str) -> String {
    match Scene::from_yaml_str(yaml, "bad.yaml", &scenes_dir()) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("accepted:\n{yaml}"),
    }
}

#[test]
fn scene_errors_name_the_file_and_the_key() {
    let e = invalid(&planar7("objects:\n  - {name: b, shape: {box: {size_m: [0.1, -0.2, 0.1]}}, xyz: [1, 0, 0]}\n"));
    assert!(e.starts_with("bad.yaml: `objects[0].shape.box.size_m`"), "{e}");
    let e = invalid(&planar7("objectz: []\n"));
    assert!(e.contains("bad.yaml") && e.contains("objectz"), "{e}");
    let e = invalid("robot: {urdf: ../../urdf/planar7.urdf, joints: [joint1, elbow]}\nduration_s: 1\n");
    assert!(e.contains("`robot.joints[1]`") && e.contains("elbow"), "{e}");
    let e = invalid("robot: {urdf: ../../urdf/planar7.urdf, initial: {joint2: 4.0}}\nduration_s: 1\n");
    assert!(e.contains("`robot.initial.joint2`") && e.contains("limits"), "{e}");
    let e = invalid(
        "robot: {urdf: ../../urdf/planar7.urdf}\nduration_s: 1\n\
         skin: {layout: ../skin/planar7.yaml, params: ../skin_model.yaml, patches: [1, 99]}\n",
    );
    assert!(e.contains("`skin.patches[1]`"), "{e}");
    let e = invalid(&planar7("control_rate_hz: 300\n"));
    assert!(e.contains("`control_rate_hz`") && e.contains("whole number"), "{e}");
    let e = invalid(&planar7("pushes: [{link: link3, object: b, force_n: [1, 0, 0], start_s: 0, end_s: 1}]\n"));
    assert!(e.contains("`pushes[0]`"), "{e}");
    let e = invalid(&planar7("pushes: [{link: link3, force_n: [1, 0, 0], start_s: 0, end_s: 1, ramp_s: 0.6}]\n"));
    assert!(e.contains("`pushes[0].ramp_s`"), "{e}");
    let e = invalid(&planar7("pushes: [{link: link3, force_n: [1, 0, 0], start_s: 0, end_s: 1, max_speed_mps: 0}]\n"));
    assert!(e.contains("`pushes[0].max_speed_mps`"), "{e}");
    let circle = "{start_s: 1, end_s: 19, circle: {radius_m: 0.2, period_s: 5}}";
    let e = invalid(&planar7(&format!("base_motions: [{circle}]\n")));
    assert!(e.contains("`base_motions`") && e.contains("does not move"), "{e}");
    let e = invalid(&planar7("base_motions: [{start_s: 1, end_s: 19, circle: {radius_m: 0.2, period_s: 5}, swing: {amplitude_m: 0.3, period_s: 9, axis: [0, 1]}}]\n"));
    assert!(e.contains("`base_motions[0]`") && e.contains("exactly one"), "{e}");
    let e =
        invalid(&planar7("base_motions: [{start_s: 1, end_s: 9, ramp_s: 5, circle: {radius_m: 0.2, period_s: 5}}]\n"));
    assert!(e.contains("`base_motions[0].ramp_s`"), "{e}");
    let e = invalid(&planar7(&format!("base_motions: [{circle}, {{start_s: 20, end_s: 40, swing: {{amplitude_m: 0.3, period_s: 9, axis: [0, 0]}}}}]\n")));
    assert!(e.contains("`base_motions[1].swing.axis`"), "{e}");
    let e = invalid(&planar7(&format!("base_motions: [{circle}, {{start_s: 15, end_s: 40, swing: {{amplitude_m: 0.3, period_s: 9, axis: [0, 1]}}}}]\n")));
    assert!(e.contains("`base_motions[1].start_s`"), "{e}");
    let e = invalid("robot: {urdf: ../../urdf/nope.urdf}\nduration_s: 1\n");
    assert!(e.contains("`robot.urdf`"), "{e}");
    let e = invalid(&planar7("view: {fps: 0}\n"));
    assert!(e.contains("`view.fps`"), "{e}");
    let e = invalid(&planar7("view: {fps: 1000}\n"));
    assert!(e.contains("`view.fps`") && e.contains("control_rate_hz"), "{e}");
    let e = invalid(&planar7("view: {elevation_deg: -95}\n"));
    assert!(e.contains("`view.elevation_deg`"), "{e}");
    let e = invalid(&planar7("view: {distance_m: -1}\n"));
    assert!(e.contains("`view.distance_m`"), "{e}");
    let e = invalid(&planar7("expect: {goal_tolerance_m: 0.01}\n"));
    assert!(e.contains("`expect.goal_tolerance_m`") && e.contains("no goals"), "{e}");
    let e = invalid(&planar7("expect: {safety: true}\n"));
    assert!(e.contains("`expect.safety`"), "{e}");
    let e = invalid(&planar7("expect: {force_targets: {rms_without_n: 0.2, rms_with_n: 0.5}}\n"));
    assert!(e.contains("`expect.force_targets`") && e.contains("force_references"), "{e}");
    let goal = "goals: [{frame: ee, position_m: [1, 0, 0]}]\n";
    let e = invalid(&planar7(&format!("{goal}expect: {{eps_c_n: .nan}}\n")));
    assert!(e.contains("`expect.eps_c_n`"), "{e}");
    let e = invalid(&planar7("expect: {goal: 1}\n"));
    assert!(e.contains("bad.yaml") && e.contains("goal"), "{e}");
    assert!(matches!(Scene::from_yaml_str("robot: {urdf: x}\n", "bad.yaml", &scenes_dir()), Err(SceneError::Yaml(_))));
    // A valid scene text passes.
    scene(&planar7(""));
}

/// A one-link arm whose link is an ASCII STL cube (0.1 m, in package `cube_pkg`), and a scene
/// file for it with `meshes` and the package path.
fn mesh_scene(dir: &std::path::Path, meshes: &str, package_path: &str) -> Result<Scene, SceneError> {
    let mesh_dir = dir.join("pkgs/cube_pkg/meshes");
    std::fs::create_dir_all(&mesh_dir).unwrap();
    let h = 0.05;
    let v =
        |i: usize| [if i & 1 == 0 { -h } else { h }, if i & 2 == 0 { -h } else { h }, if i & 4 == 0 { -h } else { h }];
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let mut stl = String::from("solid cube\n");
    for q in quads {
        for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
            stl += "facet normal 0 0 0\nouter loop\n";
            for i in t {
                let p = v(i);
                stl += &format!("vertex {} {} {}\n", p[0], p[1], p[2]);
            }
            stl += "endloop\nendfacet\n";
        }
    }
    stl += "endsolid cube\n";
    std::fs::write(mesh_dir.join("cube.stl"), stl).unwrap();
    let urdf = r#"<robot name="cube_arm"><link name="base"/>
      <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
        <limit lower="-3" upper="3" velocity="1" effort="10"/></joint>
      <link name="arm"><inertial><mass value="1"/><origin xyz="0.2 0 0"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
        <collision><origin xyz="0.2 0 0"/><geometry><mesh filename="package://cube_pkg/meshes/cube.stl" scale="2 1 1"/></geometry></collision></link>
    </robot>"#;
    std::fs::write(dir.join("cube.urdf"), urdf).unwrap();
    let text = format!(
        "robot: {{urdf: cube.urdf, meshes: {meshes}, package_path: [{package_path}]}}\nduration_s: 1.0\nfloor_z_m: -1.0\n"
    );
    Scene::from_yaml_str(&text, "cube.yaml", dir)
}

#[test]
fn mesh_collision_geometry_as_convex_mesh_or_fitted_box() {
    let dir = std::env::temp_dir().join(format!("skin_sim_mesh_scene_{}", std::process::id()));
    for (mode, geom_type) in [("mesh", MjtGeomBase::mjGEOM_MESH), ("box", MjtGeomBase::mjGEOM_BOX)] {
        let scene = mesh_scene(&dir, mode, "pkgs").unwrap();
        assert_eq!(scene.meshes.len(), 1);
        let w = World::from_scene(scene).unwrap();
        let m = w.mj_model();
        let robot: Vec<usize> =
            (0..m.ffi().ngeom as usize).filter(|&g| m.geom_group()[g] == ROBOT_GROUP as i32).collect();
        assert_eq!(robot.len(), 1);
        assert!(m.geom_type()[robot[0]] == geom_type, "{mode}");
        // Either way the geom spans the scaled cube: 0.2 x 0.1 x 0.1 around (0.2, 0, 0).
        let rbound = m.geom_rbound()[robot[0]];
        assert!((rbound - (0.01f64 + 0.0025 + 0.0025).sqrt()).abs() < 1e-6, "{mode}: {rbound}");
    }
    let e = mesh_scene(&dir, "mesh", "elsewhere").unwrap_err().to_string();
    assert!(
        e.contains("robot.urdf") && e.contains("package://cube_pkg/meshes/cube.stl") && e.contains("elsewhere"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
