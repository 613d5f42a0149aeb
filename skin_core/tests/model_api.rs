//! Public model API: loading the project's URDFs and the error messages for bad URDFs.

use skin_core::model::{ModelError, RobotModel, Shape};

const TOMM: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../urdf/tomm.urdf");
const PLANAR7: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../urdf/planar7.urdf");

#[test]
fn project_urdfs_load() {
    let tomm = RobotModel::from_urdf_file(std::path::Path::new(TOMM)).unwrap();
    assert_eq!(tomm.nv(), 15);
    assert_eq!(tomm.name(), "tomm");
    for side in ["left", "right"] {
        for link in ["base_link", "shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link"] {
            let f = tomm.frame_index(&format!("{side}_{link}")).unwrap();
            assert!(!tomm.link_collisions(f).is_empty(), "{side}_{link} has no collision");
        }
        let palm = tomm.frame_index(&format!("{side}_palm")).unwrap();
        assert!(matches!(tomm.link_collisions(palm)[0].shape, Shape::Box { .. }));
        assert!(tomm.frame_index(&format!("{side}_hand")).is_some());
    }
    assert!(tomm.frame_index("laser").is_some());
    let limits = tomm.joint_limits();
    let efforts: Vec<f64> = limits[3..9].iter().map(|l| l.effort).collect();
    assert_eq!(efforts, [150.0, 150.0, 150.0, 28.0, 28.0, 28.0]);
    assert!(limits[3..].iter().all(|l| (l.velocity - std::f64::consts::PI).abs() < 1e-12));

    let planar = RobotModel::from_urdf_file(std::path::Path::new(PLANAR7)).unwrap();
    assert_eq!(planar.nv(), 7);
    assert_eq!(planar.joint_names()[6], "joint7");
    assert_eq!(planar.frame_parent_joint(planar.frame_index("ee").unwrap()), Some(6));
    assert!(planar.joint_limits().iter().all(|l| l.lower == -2.9 && l.upper == 2.9 && l.velocity == 2.0));
}

/// A two-link URDF with pieces replaceable by the tests.
fn urdf(link2_inertial: &str, axis: &str, extra: &str) -> String {
    format!(
        r#"<?xml version="1.0"?>
<robot name="bad">
  <link name="world"/>
  <link name="link1">
    <inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
  </link>
  <link name="link2">{link2_inertial}</link>
  <joint name="j1" type="revolute">
    <parent link="world"/><child link="link1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
  <joint name="j2" type="revolute">
    <parent link="link1"/><child link="link2"/><axis xyz="{axis}"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
  {extra}
</robot>"#
    )
}

const GOOD_INERTIAL: &str =
    r#"<inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>"#;

fn err(xml: &str) -> String {
    let e = RobotModel::from_urdf_str(xml, "robots/bad_robot.urdf").unwrap_err();
    e.to_string()
}

fn assert_names(msg: &str, parts: &[&str]) {
    for p in parts {
        assert!(msg.contains(p), "`{msg}` does not contain `{p}`");
    }
}

#[test]
fn valid_reference_urdf_loads() {
    let m = RobotModel::from_urdf_str(&urdf(GOOD_INERTIAL, "0 1 0", ""), "ok.urdf").unwrap();
    assert_eq!(m.joint_names(), ["j1", "j2"]);
}

#[test]
fn missing_file_names_the_file() {
    let e = RobotModel::from_urdf_file(std::path::Path::new("no/such/robot_file.urdf")).unwrap_err();
    assert!(matches!(e, ModelError::Io { .. }));
    assert_names(&e.to_string(), &["no/such/robot_file.urdf"]);
}

#[test]
fn malformed_xml_names_the_file() {
    let msg = err("<robot name=\"x\"><link name=\"a\"></robot>");
    assert_names(&msg, &["bad_robot.urdf", "malformed"]);
}

#[test]
fn moving_leaf_without_mass_makes_m_singular_and_is_rejected() {
    // nothing moves with j2: M would have a zero row; the error names the joint
    let msg = err(&urdf("", "0 1 0", ""));
    assert_names(&msg, &["bad_robot.urdf", "joint \"j2\"", "mass matrix is singular"]);
    let zero_all =
        r#"<inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>"#;
    assert_names(&err(&urdf(zero_all, "0 1 0", "")), &["bad_robot.urdf", "joint \"j2\"", "singular"]);
    let neg =
        r#"<inertial><mass value="-2"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>"#;
    assert_names(&err(&urdf(neg, "0 1 0", "")), &["bad_robot.urdf", "link \"link2\"", "negative mass"]);
}

#[test]
fn indefinite_inertia_is_rejected_and_inconsistent_one_kept_with_a_warning() {
    let not_psd =
        r#"<inertial><mass value="1"/><inertia ixx="0.1" ixy="0.5" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>"#;
    assert_names(
        &err(&urdf(not_psd, "0 1 0", "")),
        &["bad_robot.urdf", "link \"link2\"", "line 7", "<inertial>", "not positive semi-definite"],
    );
    // principal moments 0.1, 0.1, 0.5: no real body, but a positive definite spatial inertia
    let triangle =
        r#"<inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.5"/></inertial>"#;
    let m = RobotModel::from_urdf_str(&urdf(triangle, "0 1 0", ""), "t.urdf").unwrap();
    assert_eq!(m.warnings().len(), 1, "{:?}", m.warnings());
    assert_names(&m.warnings()[0], &["link \"link2\"", "triangle inequality", "3.000e-1", "kept as given"]);
    assert_eq!(m.body_inertia(1)[(2, 2)], 0.5);
}

#[test]
fn zero_axis_is_rejected() {
    assert_names(&err(&urdf(GOOD_INERTIAL, "0 0 0", "")), &["bad_robot.urdf", "joint \"j2\"", "axis"]);
}

#[test]
fn unsupported_joints_and_structure_errors_name_the_element() {
    let floating =
        urdf(GOOD_INERTIAL, "0 1 0", "").replace(r#"name="j2" type="revolute""#, r#"name="j2" type="floating""#);
    assert_names(&err(&floating), &["bad_robot.urdf", "joint \"j2\"", "Floating"]);
    let two_roots = urdf(GOOD_INERTIAL, "0 1 0", r#"<link name="orphan"/>"#);
    assert_names(&err(&two_roots), &["bad_robot.urdf", "multiple root links", "\"orphan\""]);
    let dangling = urdf(
        GOOD_INERTIAL,
        "0 1 0",
        r#"<joint name="j3" type="fixed"><parent link="link2"/><child link="nowhere"/></joint>"#,
    );
    assert_names(&err(&dangling), &["bad_robot.urdf", "joint \"j3\"", "\"nowhere\" does not exist"]);
    let unknown_type = urdf(GOOD_INERTIAL, "0 1 0", "").replace(r#"type="revolute""#, r#"type="hinge""#);
    assert_names(&err(&unknown_type), &["bad_robot.urdf", "joint \"j1\"", "unknown joint type", "hinge"]);
}
