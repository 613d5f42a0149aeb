//! URDF loading rules (docs/dynamics.md, "Loading any URDF"): what the URDF format allows loads,
//! inertias within tolerance are repaired, massless links are carried by their children, mimic
//! joints are independent or follow their leader; and each rule's refusal names file, element
//! and reason. Small inline URDFs, one per rule.

use nalgebra::{DMatrix, DVector, Matrix6xX, Vector3, Vector6};
use skin_core::model::{
    bias_forces, crba, gravity, point_jacobian, point_jacobian_dot_qdot, update_kinematics, MimicMode, ModelData,
    RobotModel, UrdfOptions,
};

fn load(xml: &str) -> RobotModel {
    RobotModel::from_urdf_str(xml, "robots/test.urdf").unwrap_or_else(|e| panic!("{e}"))
}

fn err(xml: &str, mimic: MimicMode) -> String {
    RobotModel::from_urdf_str_with(xml, "robots/test.urdf", &UrdfOptions { mimic }).unwrap_err().to_string()
}

fn assert_names(msg: &str, parts: &[&str]) {
    for p in parts {
        assert!(msg.contains(p), "`{msg}` does not contain `{p}`");
    }
}

fn inertial(mass: f64, [xx, yy, zz]: [f64; 3], com: &str) -> String {
    format!(
        r#"<inertial><origin xyz="{com}"/><mass value="{mass}"/><inertia ixx="{xx}" ixy="0" ixz="0" iyy="{yy}" iyz="0" izz="{zz}"/></inertial>"#
    )
}

/// world -> j1 (revolute z) -> link1 -> j2 (revolute y) -> link2, with link2's inertial given.
fn two_links(link2: &str) -> String {
    format!(
        r#"<robot name="t">
  <link name="world"/>
  <link name="link1">{}</link>
  <link name="link2">{link2}</link>
  <joint name="j1" type="revolute"><parent link="world"/><child link="link1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
  <joint name="j2" type="revolute"><parent link="link1"/><child link="link2"/><origin xyz="0.3 0 0"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
</robot>"#,
        inertial(2.0, [0.1, 0.1, 0.1], "0.1 0 0")
    )
}

fn mass_matrix(model: &RobotModel, q: &[f64]) -> DMatrix<f64> {
    let mut d = ModelData::new(model);
    update_kinematics(model, &mut d, q, &vec![0.0; model.nv()]).unwrap();
    let mut m = DMatrix::zeros(model.nv(), model.nv());
    crba(model, &mut d, &mut m).unwrap();
    m
}

#[test]
fn format_extras_the_model_does_not_use_are_ignored() {
    // icub's empty <texture/>, gazebo and transmission blocks, a DOCTYPE, a mesh without scale
    // and with a package:// path, a continuous joint without <limit>, xacro-namespaced elements
    let xml = r#"<?xml version="1.0"?>
<!DOCTYPE robot>
<robot name="extras" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <material name="grey"><color rgba="0.5 0.5 0.5 1"/><texture/></material>
  <link name="base"><visual><geometry><mesh filename="package://x/base.dae"/></geometry>
    <material name="m"><texture/></material></visual></link>
  <link name="wheel">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.02"/></inertial>
    <collision><geometry><mesh filename="package://x/meshes/wheel.stl"/></geometry></collision>
  </link>
  <joint name="spin" type="continuous"><parent link="base"/><child link="wheel"/><axis xyz="0 0 1"/>
    <dynamics damping="0.1"/><safety_controller k_velocity="1"/></joint>
  <gazebo reference="wheel"><mu1>0.5</mu1><plugin name="p" filename="libp.so"/></gazebo>
  <transmission name="t"><type>transmission_interface/SimpleTransmission</type>
    <joint name="spin"><hardwareInterface>EffortJointInterface</hardwareInterface></joint>
    <actuator name="m"><mechanicalReduction>1</mechanicalReduction></actuator></transmission>
  <xacro:property name="unused" value="1"/>
</robot>"#;
    let m = load(xml);
    assert_eq!(m.joint_names(), ["spin"]);
    let l = m.joint_limits()[0];
    assert!(l.lower == f64::NEG_INFINITY && l.upper == f64::INFINITY && l.velocity == f64::INFINITY);
    let wheel = m.frame_index("wheel").unwrap();
    match &m.link_collisions(wheel)[0].shape {
        skin_core::model::Shape::Mesh { filename, scale } => {
            assert_eq!(filename, "package://x/meshes/wheel.stl");
            assert_eq!(*scale, Vector3::repeat(1.0));
        }
        s => panic!("expected a mesh, got {s:?}"),
    }
    assert!(m.warnings().is_empty(), "{:?}", m.warnings());
}

#[test]
fn what_the_specification_requires_is_required() {
    let no_limit = two_links(&inertial(1.0, [0.1, 0.1, 0.1], "0 0 0.2")).replace(
        r#"<limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
</robot>"#,
        "</joint>\n</robot>",
    );
    assert_names(
        &err(&no_limit, MimicMode::Independent),
        &["robots/test.urdf", "joint \"j2\" (line 7)", "missing <limit>"],
    );
    let bad_number =
        two_links(&inertial(1.0, [0.1, 0.1, 0.1], "0 0 0.2")).replace(r#"xyz="0.3 0 0""#, r#"xyz="0.3 0""#);
    assert_names(
        &err(&bad_number, MimicMode::Independent),
        &["joint \"j2\" <origin> (line 7)", "xyz=\"0.3 0\"", "3 finite"],
    );
    let mesh = two_links(r#"<collision><geometry><mesh scale="1 1 1"/></geometry></collision>"#);
    assert_names(
        &err(&mesh, MimicMode::Independent),
        &["link \"link2\" <mesh> (line 4)", "missing attribute `filename`"],
    );
    let no_mass = two_links(r#"<inertial><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>"#);
    assert_names(&err(&no_mass, MimicMode::Independent), &["link \"link2\" <inertial> (line 4)", "missing <mass>"]);
    let planar = two_links(&inertial(1.0, [0.1, 0.1, 0.1], "0 0 0.2"))
        .replace(r#"name="j2" type="revolute""#, r#"name="j2" type="planar""#);
    assert_names(
        &err(&planar, MimicMode::Independent),
        &["unsupported", "joint \"j2\"", "Planar joints are not supported"],
    );
}

#[test]
fn inertia_noise_below_positive_semi_definiteness_is_clipped_with_a_warning() {
    // tolerance: 1e-6 of the largest link inertia of the URDF (link1's, Frobenius norm 0.1·√3)
    let m = load(&two_links(&inertial(1.0, [0.1, 0.1, -4e-8], "0 0 0.2")));
    assert_eq!(m.warnings().len(), 1, "{:?}", m.warnings());
    assert_names(&m.warnings()[0], &["link \"link2\"", "repaired", "change 4.000e-8", "tolerance 1.732e-7"]);
    let i = m.body_inertia(1);
    assert!(i[(2, 2)].abs() < 1e-15 && (i[(0, 0)] - 0.1).abs() < 1e-15, "{i}");
    // beyond the tolerance: refused, naming link, line and the moments
    let e = err(&two_links(&inertial(1.0, [0.1, 0.1, -2e-7], "0 0 0.2")), MimicMode::Independent);
    assert_names(
        &e,
        &["robots/test.urdf", "link \"link2\" (line 4) <inertial>", "not positive semi-definite", "-2.0000e-7"],
    );
}

#[test]
fn small_triangle_inequality_violation_is_projected_and_large_one_kept() {
    // moments 0.1, 0.1, 0.2 + 3e-8: the nearest valid moments move along (-1, -1, 1) by 1e-8 each
    let m = load(&two_links(&inertial(1.0, [0.1, 0.1, 0.2 + 3e-8], "0 0 0.2")));
    assert_names(&m.warnings()[0], &["link \"link2\"", "repaired", "change 1.732e-8"]);
    let i = m.body_inertia(1);
    for (k, want) in [(0, 0.1 + 1e-8), (1, 0.1 + 1e-8), (2, 0.2 + 2e-8)] {
        assert!((i[(k, k)] - want).abs() < 1e-15, "{k}: {} vs {want}", i[(k, k)]);
    }
    assert!((i[(2, 2)] - i[(0, 0)] - i[(1, 1)]).abs() < 1e-15);
    // a violation beyond the tolerance with non-negative moments: kept as given (pinocchio's M)
    let m = load(&two_links(&inertial(1.0, [0.01, 0.01, 0.2], "0 0 0.2")));
    assert_names(&m.warnings()[0], &["link \"link2\"", "triangle inequality by 1.800e-1", "kept as given"]);
    assert_eq!(m.body_inertia(1)[(2, 2)], 0.2);
}

#[test]
fn point_mass_links_are_valid_inertias() {
    // a mass with zero rotational inertia (icub's head, so101's frames) is a point mass
    let m = load(&two_links(&inertial(1.3, [0.0, 0.0, 0.0], "0 0 0.2")));
    assert!(m.warnings().is_empty(), "{:?}", m.warnings());
    assert_eq!(m.body_mass(1), 1.3);
}

/// Hip as a spherical joint: three revolute joints with massless links in between (human.urdf).
fn spherical_hip(thigh: &str) -> String {
    format!(
        r#"<robot name="hip">
  <link name="pelvis"/><link name="hip_x"/><link name="hip_y"/>
  <link name="thigh">{thigh}</link>
  <joint name="hx" type="revolute"><parent link="pelvis"/><child link="hip_x"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
  <joint name="hy" type="revolute"><parent link="hip_x"/><child link="hip_y"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
  <joint name="hz" type="revolute"><parent link="hip_y"/><child link="thigh"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
</robot>"#
    )
}

#[test]
fn massless_links_are_carried_by_their_children() {
    let m = load(&spherical_hip(&inertial(5.0, [0.1, 0.1, 0.02], "0 0 -0.2")));
    assert_eq!(m.nv(), 3);
    assert_eq!((m.body_mass(0), m.body_mass(1)), (0.0, 0.0));
    for q in [[0.0, 0.0, 0.0], [0.3, -0.7, 0.9]] {
        let mm = mass_matrix(&m, &q);
        assert!(mm.clone().cholesky().is_some(), "M not positive definite at {q:?}: {mm}");
    }
    // a thigh that is a point mass on the z axis gives hz nothing to move: refused, naming hz
    let e = err(&spherical_hip(&inertial(5.0, [0.0, 0.0, 0.0], "0 0 -0.2")), MimicMode::Independent);
    assert_names(&e, &["robots/test.urdf", "joint \"hz\" (line 8)", "mass matrix is singular"]);
}

/// A branch with a mimic chain: j2 (prismatic) mimics j1, j3 mimics j2; j4 is independent.
fn mimic_chain(m2: f64) -> String {
    let link = |n: &str, com: &str| format!(r#"<link name="{n}">{}</link>"#, inertial(1.0, [0.02, 0.03, 0.04], com));
    format!(
        r#"<robot name="mimic">
  <link name="base"/>{}{}{}{}
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
  <joint name="j2" type="prismatic"><parent link="l1"/><child link="l2"/><origin xyz="0.2 0 0.1" rpy="0.3 0 0"/>
    <axis xyz="1 0 0"/><limit lower="-1" upper="1" velocity="1" effort="1"/>
    <mimic joint="j1" multiplier="{m2}" offset="0.2"/></joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/><origin xyz="0 0.3 0"/>
    <axis xyz="0 1 1"/><limit lower="-2" upper="2" velocity="1" effort="1"/>
    <mimic joint="j2" multiplier="1.5" offset="-0.1"/></joint>
  <joint name="j4" type="revolute"><parent link="l1"/><child link="l4"/><origin xyz="0 0 0.4"/>
    <axis xyz="1 0 0"/><limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
</robot>"#,
        link("l1", "0.1 0 0"),
        link("l2", "0 0.1 0.05"),
        link("l3", "0.05 0.1 0"),
        link("l4", "0 0 0.1")
    )
}

struct Eval {
    m: DMatrix<f64>,
    bias: DVector<f64>,
    g: DVector<f64>,
    j: Matrix6xX<f64>,
    jdqd: Vector6<f64>,
}

fn eval(model: &RobotModel, q: &[f64], qd: &[f64], frame: &str) -> Eval {
    let n = model.nv();
    let mut d = ModelData::new(model);
    update_kinematics(model, &mut d, q, qd).unwrap();
    let mut e = Eval {
        m: DMatrix::zeros(n, n),
        bias: DVector::zeros(n),
        g: DVector::zeros(n),
        j: Matrix6xX::zeros(n),
        jdqd: Vector6::zeros(),
    };
    crba(model, &mut d, &mut e.m).unwrap();
    bias_forces(model, &mut d, &mut e.bias).unwrap();
    gravity(model, &mut d, &mut e.g).unwrap();
    let f = model.frame_index(frame).unwrap();
    let p = Vector3::new(0.05, -0.02, 0.07);
    point_jacobian(model, &d, f, &p, &mut e.j).unwrap();
    point_jacobian_dot_qdot(model, &d, f, &p, &mut e.jdqd).unwrap();
    e
}

/// Largest disagreement between a followed-mimic model and the independent one restricted to
/// `q_ind = G q + o`: M = Gᵀ M_ind G, τ = Gᵀ τ_ind, J = J_ind G, J̇q̇ equal.
fn follow_vs_independent(follow: &RobotModel, independent: &RobotModel) -> f64 {
    // columns of G: independent joints j1..j4 against coordinates j1, j4
    let (m2, m3) = (-0.7, 1.5);
    let g = DMatrix::from_row_slice(4, 2, &[1.0, 0.0, m2, 0.0, m3 * m2, 0.0, 0.0, 1.0]);
    let o = DVector::from_column_slice(&[0.0, 0.2, 1.5 * 0.2 - 0.1, 0.0]);
    let mut worst: f64 = 0.0;
    for (q, qd) in [([0.4, -0.3], [0.9, -1.2]), ([-1.1, 0.8], [-0.5, 2.0])] {
        let (qv, qdv) = (DVector::from_column_slice(&q), DVector::from_column_slice(&qd));
        let qi = &g * qv + &o;
        let qdi = &g * qdv;
        for frame in ["l3", "l4"] {
            let a = eval(follow, &q, &qd, frame);
            let b = eval(independent, qi.as_slice(), qdi.as_slice(), frame);
            let diffs = [
                (a.m - g.transpose() * &b.m * &g).amax(),
                (a.bias - g.transpose() * &b.bias).amax(),
                (a.g - g.transpose() * &b.g).amax(),
                (a.j - &b.j * &g).amax(),
                (a.jdqd - b.jdqd).amax(),
            ];
            worst = diffs.iter().fold(worst, |w, d| w.max(*d));
        }
    }
    worst
}

#[test]
fn followed_mimic_joints_compose_jacobian_and_mass_matrix() {
    let independent = load(&mimic_chain(-0.7));
    assert_eq!(independent.joint_names(), ["j1", "j2", "j3", "j4"]);
    let opts = UrdfOptions { mimic: MimicMode::Follow };
    let follow = RobotModel::from_urdf_str_with(&mimic_chain(-0.7), "m.urdf", &opts).unwrap();
    assert_eq!(follow.joint_names(), ["j1", "j4"]);
    assert_eq!(follow.njoints(), 4);
    assert_eq!(follow.moving_joint_names(), ["j1", "j2", "j3", "j4"]);
    let (c, mult, off) = follow.joint_coordinate(2);
    assert_eq!(c, 0);
    assert!((mult - 1.5 * -0.7).abs() < 1e-15 && (off - (1.5 * 0.2 - 0.1)).abs() < 1e-15);
    let err = follow_vs_independent(&follow, &independent);
    assert!(err < 1e-12, "followed mimic model disagrees with the composed one by {err}");
    // the comparison can fail: a multiplier off by 1e-6 is seen
    let wrong = RobotModel::from_urdf_str_with(&mimic_chain(-0.7 + 1e-6), "m.urdf", &opts).unwrap();
    let err = follow_vs_independent(&wrong, &independent);
    assert!(err > 1e-7, "a wrong multiplier went unnoticed ({err})");
}

#[test]
fn mimic_errors_name_the_joint_in_follow_mode_only() {
    let unknown = mimic_chain(-0.7).replace(r#"<mimic joint="j1""#, r#"<mimic joint="nope""#);
    assert_eq!(load(&unknown).nv(), 4, "independent mode ignores <mimic>");
    assert_names(
        &err(&unknown, MimicMode::Follow),
        &["joint \"j2\" (line 5) <mimic>", "\"nope\", which is not a moving joint"],
    );
    let cycle = mimic_chain(-0.7).replace(
        r#"<limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
  <joint name="j2""#,
        r#"<limit lower="-2" upper="2" velocity="1" effort="1"/><mimic joint="j3"/></joint>
  <joint name="j2""#,
    );
    assert_names(&err(&cycle, MimicMode::Follow), &["<mimic>", "cycle"]);
}

#[test]
fn links_fixed_to_the_world_do_not_enter_the_dynamics() {
    // romeo_laas_small's root "body": an indefinite inertia on a link that never moves
    let bad = r#"<link name="world"><inertial><mass value="3"/><inertia ixx="0.1" ixy="0.5" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>"#;
    let xml = two_links(&inertial(1.0, [0.1, 0.1, 0.1], "0 0 0.2")).replace(r#"<link name="world"/>"#, bad);
    let m = load(&xml);
    assert_eq!(m.warnings().len(), 1, "{:?}", m.warnings());
    assert_names(&m.warnings()[0], &["link \"world\" is fixed to the world", "not positive semi-definite"]);
    let reference = load(&two_links(&inertial(1.0, [0.1, 0.1, 0.1], "0 0 0.2")));
    assert_eq!(mass_matrix(&m, &[0.3, 0.4]), mass_matrix(&reference, &[0.3, 0.4]));
}
