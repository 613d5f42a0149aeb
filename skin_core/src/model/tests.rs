//! Internal consistency tests of the model: CRBA vs RNEA, Jacobians vs finite differences,
//! energy, analytic cases and numerical extremes.

use super::*;
use nalgebra::{DMatrix, DVector, Matrix6xX, Vector3, Vector6};

const TOMM: &str = include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/../urdf/tomm.urdf"));
const PLANAR7: &str = include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/../urdf/planar7.urdf"));

/// Small deterministic generator (xorshift64*), enough for test states.
struct Rng(u64);
impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let u = (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }
    fn state(&mut self, model: &RobotModel) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let n = model.nv();
        let q = (0..n)
            .map(|i| {
                let l = model.joint_limits()[i];
                self.uniform(l.lower.max(-3.0), l.upper.min(3.0))
            })
            .collect();
        let qd = (0..n).map(|_| self.uniform(-2.0, 2.0)).collect();
        let qdd = (0..n).map(|_| self.uniform(-5.0, 5.0)).collect();
        (q, qd, qdd)
    }
}

fn tomm() -> RobotModel {
    RobotModel::from_urdf_str(TOMM, "tomm.urdf").unwrap()
}
fn planar7() -> RobotModel {
    RobotModel::from_urdf_str(PLANAR7, "planar7.urdf").unwrap()
}

struct Eval {
    m: DMatrix<f64>,
    bias: DVector<f64>,
    g: DVector<f64>,
}

fn eval(model: &RobotModel, data: &mut ModelData, q: &[f64], qd: &[f64]) -> Eval {
    let n = model.nv();
    update_kinematics(model, data, q, qd).unwrap();
    let mut e = Eval { m: DMatrix::zeros(n, n), bias: DVector::zeros(n), g: DVector::zeros(n) };
    crba(model, data, &mut e.m).unwrap();
    bias_forces(model, data, &mut e.bias).unwrap();
    gravity(model, data, &mut e.g).unwrap();
    e
}

fn jac(model: &RobotModel, data: &ModelData, f: usize, p: &Vector3<f64>) -> Matrix6xX<f64> {
    let mut j = Matrix6xX::zeros(model.nv());
    point_jacobian(model, data, f, p, &mut j).unwrap();
    j
}

/// Frames to probe: every moving body's link plus the hand frames, with an off-frame point.
fn probe_frames(model: &RobotModel) -> Vec<(usize, Vector3<f64>)> {
    let mut v: Vec<(usize, Vector3<f64>)> =
        (0..model.nv()).map(|j| (model.joint_child_frame(j), Vector3::new(0.05, -0.03, 0.1))).collect();
    for name in ["left_hand", "right_hand", "ee", "laser"] {
        if let Some(f) = model.frame_index(name) {
            v.push((f, Vector3::new(0.01, 0.02, 0.03)));
        }
    }
    v
}

#[test]
fn tomm_structure() {
    let m = tomm();
    assert_eq!(m.nv(), 15);
    assert_eq!(&m.joint_names()[..4], &["base_x_joint", "base_y_joint", "base_yaw_joint", "left_shoulder_pan_joint"]);
    assert_eq!(m.joint_names()[9], "right_shoulder_pan_joint");
    assert_eq!(m.joint_kind(0), JointKind::Prismatic);
    assert_eq!(m.joint_kind(2), JointKind::Revolute);
    let world = m.frame_index("world").unwrap();
    assert_eq!(m.frame_parent_joint(world), None);
    let hand = m.frame_index("left_hand").unwrap();
    assert_eq!(m.frame_parent_joint(hand), m.joint_index("left_wrist_3_joint"));
    let torso = m.frame_index("torso").unwrap();
    assert_eq!(m.frame_parent_joint(torso), m.joint_index("base_yaw_joint"));
    assert!(!m.link_collisions(m.frame_index("left_upper_arm_link").unwrap()).is_empty());
    let lim = m.joint_limits()[m.joint_index("left_elbow_joint").unwrap()];
    assert_eq!((lim.lower, lim.upper, lim.effort), (-std::f64::consts::PI, std::f64::consts::PI, 150.0));
    // base_link + torso + 2 arm bases (4 kg) + arms + palms
    let arm = 3.7 + 8.393 + 2.33 + 1.219 + 1.219 + 0.1879 + 0.5;
    assert!((m.total_mass() - (2.0 + 60.0 + 15.0 + 2.0 * (4.0 + arm))).abs() < 1e-9);
    assert!(m.joint_supports(2, 14) && !m.joint_supports(3, 14));
}

#[test]
fn zero_configuration_hand_pose_matches_hand_computation() {
    // Planar arm stretched along x: the end effector is at 7 * 0.25 m.
    let m = planar7();
    let mut d = ModelData::new(&m);
    update_kinematics(&m, &mut d, &[0.0; 7], &[0.0; 7]).unwrap();
    let ee = frame_pose(&d, m.frame_index("ee").unwrap());
    assert!((ee.translation.vector - Vector3::new(1.75, 0.0, 0.0)).norm() < 1e-15);
    // All joints at pi/2 / 7 * ... : rotate the first joint by 90 degrees: the tip is on +y.
    let mut q = [0.0; 7];
    q[0] = std::f64::consts::FRAC_PI_2;
    update_kinematics(&m, &mut d, &q, &[0.0; 7]).unwrap();
    let ee = frame_pose(&d, m.frame_index("ee").unwrap());
    assert!((ee.translation.vector - Vector3::new(0.0, 1.75, 0.0)).norm() < 1e-14);
}

#[test]
fn mass_matrix_symmetric_positive_definite() {
    for model in [tomm(), planar7()] {
        let mut d = ModelData::new(&model);
        let mut rng = Rng(7);
        for _ in 0..50 {
            let (q, qd, _) = rng.state(&model);
            let e = eval(&model, &mut d, &q, &qd);
            assert_eq!(e.m, e.m.transpose());
            let eig = e.m.clone().symmetric_eigenvalues();
            assert!(eig.min() > 0.0, "min eigenvalue {}", eig.min());
        }
    }
}

#[test]
fn rnea_equals_mass_matrix_times_qdd_plus_bias() {
    for model in [tomm(), planar7()] {
        let n = model.nv();
        let mut d = ModelData::new(&model);
        let mut rng = Rng(11);
        let mut tau = DVector::zeros(n);
        for _ in 0..100 {
            let (q, qd, qdd) = rng.state(&model);
            let e = eval(&model, &mut d, &q, &qd);
            rnea(&model, &mut d, &qdd, &mut tau).unwrap();
            let expected = &e.m * DVector::from_column_slice(&qdd) + &e.bias;
            let err = (&tau - &expected).amax();
            assert!(err < 1e-9 * (1.0 + expected.amax()), "err {err}");
        }
    }
}

#[test]
fn bias_at_rest_equals_gravity() {
    let model = tomm();
    let n = model.nv();
    let mut d = ModelData::new(&model);
    let mut rng = Rng(3);
    for _ in 0..20 {
        let (q, qd, _) = rng.state(&model);
        let e0 = eval(&model, &mut d, &q, &vec![0.0; n]);
        assert!((&e0.bias - &e0.g).amax() < 1e-12);
        // gravity ignores the velocity stored in the data
        let e1 = eval(&model, &mut d, &q, &qd);
        assert!((&e1.g - &e0.g).amax() < 1e-12);
        // the base translation joints carry no gravity load; the yaw axis is vertical
        assert!(e0.g[0].abs() < 1e-12 && e0.g[1].abs() < 1e-12 && e0.g[2].abs() < 1e-9);
    }
}

#[test]
fn planar_arm_has_exactly_zero_gravity() {
    let model = planar7();
    let mut d = ModelData::new(&model);
    let mut rng = Rng(5);
    for _ in 0..20 {
        let (q, qd, _) = rng.state(&model);
        let e = eval(&model, &mut d, &q, &qd);
        assert!(e.g.iter().all(|x| *x == 0.0), "{:?}", e.g);
    }
}

#[test]
fn translation_invariance_of_dynamics() {
    // Moving the holonomic base far away changes nothing in M and the bias forces.
    let model = tomm();
    let mut d = ModelData::new(&model);
    let (q, qd, _) = Rng(9).state(&model);
    let e0 = eval(&model, &mut d, &q, &qd);
    let mut q2 = q.clone();
    q2[0] += 90.0;
    q2[1] -= 75.0;
    let e1 = eval(&model, &mut d, &q2, &qd);
    assert!((&e0.m - &e1.m).amax() < 1e-12, "{}", (&e0.m - &e1.m).amax());
    assert!((&e0.bias - &e1.bias).amax() < 1e-12);
}

#[test]
fn point_jacobian_matches_finite_differences() {
    for model in [tomm(), planar7()] {
        let n = model.nv();
        let mut d = ModelData::new(&model);
        let mut rng = Rng(13);
        let h = 1e-6;
        for _ in 0..5 {
            let (q, qd, _) = rng.state(&model);
            update_kinematics(&model, &mut d, &q, &qd).unwrap();
            for (f, p) in probe_frames(&model) {
                let j = jac(&model, &d, f, &p);
                for k in 0..n {
                    let mut qp = q.clone();
                    let mut qm = q.clone();
                    qp[k] += h;
                    qm[k] -= h;
                    update_kinematics(&model, &mut d, &qp, &qd).unwrap();
                    let tp = *frame_pose(&d, f);
                    update_kinematics(&model, &mut d, &qm, &qd).unwrap();
                    let tm = *frame_pose(&d, f);
                    let dp = (tp * nalgebra::Point3::from(p) - tm * nalgebra::Point3::from(p)) / (2.0 * h);
                    let dw = (tp.rotation * tm.rotation.inverse()).scaled_axis() / (2.0 * h);
                    let col = j.column(k);
                    let fd = Vector6::new(dp[0], dp[1], dp[2], dw[0], dw[1], dw[2]);
                    let err = (col - fd).amax();
                    assert!(err < 1e-6, "{} frame {} joint {k}: {err}", model.name(), model.frame_names()[f]);
                    if model.frame_parent_joint(f).is_none_or(|b| !model.joint_supports(k, b)) {
                        assert!(col.iter().all(|x| *x == 0.0));
                    }
                }
                update_kinematics(&model, &mut d, &q, &qd).unwrap();
            }
        }
    }
}

#[test]
fn point_velocity_is_the_jacobian_times_qd() {
    for model in [tomm(), planar7()] {
        let mut d = ModelData::new(&model);
        let (q, qd, _) = Rng(31).state(&model);
        update_kinematics(&model, &mut d, &q, &qd).unwrap();
        for (f, p) in probe_frames(&model) {
            let expected = jac(&model, &d, f, &p).fixed_rows::<3>(0) * DVector::from_column_slice(&qd);
            let v = point_velocity(&model, &d, f, &p).unwrap();
            assert!(
                (v - expected).norm() <= 1e-12 * expected.norm().max(1.0),
                "{} frame {f}: {v} vs {expected}",
                model.name()
            );
        }
    }
}

#[test]
fn point_jacobian_along_is_the_linear_rows_along_the_direction() {
    for model in [tomm(), planar7()] {
        let mut d = ModelData::new(&model);
        let (q, qd, _) = Rng(29).state(&model);
        update_kinematics(&model, &mut d, &q, &qd).unwrap();
        let mut row = vec![0.0; model.nv()];
        for (f, p) in probe_frames(&model) {
            let j = jac(&model, &d, f, &p);
            for dir in [Vector3::new(0.3, -0.5, 0.8), Vector3::new(-0.6, -0.0, -0.8)] {
                point_jacobian_along(&model, &d, f, &p, &dir, &mut row).unwrap();
                for (k, x) in row.iter().enumerate() {
                    let expected: f64 = dir.iter().zip(j.column(k).iter()).map(|(d, j)| d * j).sum();
                    let scale = j.column(k).norm().max(1.0);
                    assert!(
                        (x - expected).abs() <= 1e-14 * scale,
                        "{} frame {f} joint {k}: {x} vs {expected}",
                        model.name()
                    );
                }
            }
        }
    }
    let model = planar7();
    let d = ModelData::new(&model);
    assert!(point_jacobian_along(&model, &d, 0, &Vector3::zeros(), &Vector3::x(), &mut [0.0; 3]).is_err());
}

#[test]
fn jacobian_dot_qdot_matches_finite_differences() {
    for model in [tomm(), planar7()] {
        let mut d = ModelData::new(&model);
        let mut rng = Rng(17);
        let h = 1e-6;
        for _ in 0..5 {
            let (q, qd, _) = rng.state(&model);
            let qdv = DVector::from_column_slice(&qd);
            for (f, p) in probe_frames(&model) {
                update_kinematics(&model, &mut d, &q, &qd).unwrap();
                let mut jdqd = Vector6::zeros();
                point_jacobian_dot_qdot(&model, &d, f, &p, &mut jdqd).unwrap();
                let qp: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a + h * b).collect();
                let qm: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a - h * b).collect();
                update_kinematics(&model, &mut d, &qp, &qd).unwrap();
                let jp = jac(&model, &d, f, &p);
                update_kinematics(&model, &mut d, &qm, &qd).unwrap();
                let jm = jac(&model, &d, f, &p);
                let fd = (jp - jm) / (2.0 * h) * &qdv;
                let err = (Vector6::from_iterator(fd.iter().copied()) - jdqd).amax();
                assert!(err < 1e-5 * (1.0 + jdqd.amax()), "{}: {err}", model.frame_names()[f]);
            }
        }
    }
}

#[test]
fn kinetic_energy_matches_sum_over_bodies() {
    for model in [tomm(), planar7()] {
        let mut d = ModelData::new(&model);
        let mut rng = Rng(19);
        for _ in 0..20 {
            let (q, qd, _) = rng.state(&model);
            let e = eval(&model, &mut d, &q, &qd);
            let qdv = DVector::from_column_slice(&qd);
            let ke_m = 0.5 * qdv.dot(&(&e.m * &qdv));
            let mut ke = 0.0;
            for j in 0..model.nv() {
                let pose = d.joint_pose(j);
                let r = pose.rotation.to_rotation_matrix();
                let (w, v_o) = d.joint_twist(j);
                let c = r * model.body_com(j);
                let v_c = v_o + w.cross(&c);
                let i_w = r.matrix() * model.body_inertia(j) * r.matrix().transpose();
                ke += 0.5 * model.body_mass(j) * v_c.norm_squared() + 0.5 * w.dot(&(i_w * w));
            }
            assert!((ke - ke_m).abs() < 1e-10 * (1.0 + ke), "{ke} vs {ke_m}");
        }
    }
}

#[test]
fn pendulum_matches_analytic_model() {
    // One link of mass m, centre of mass at distance l on the link's x axis, revolute about y.
    let (m, l, iyy) = (2.0, 0.4, 0.03);
    let xml = format!(
        r#"<robot name="pendulum">
          <link name="world"/>
          <link name="arm"><inertial><origin xyz="{l} 0 0"/><mass value="{m}"/>
            <inertia ixx="0.01" ixy="0" ixz="0" iyy="{iyy}" iyz="0" izz="0.03"/></inertial></link>
          <joint name="hinge" type="continuous"><parent link="world"/><child link="arm"/>
            <origin xyz="0 0 1"/><axis xyz="0 2 0"/></joint>
        </robot>"#
    );
    let model = RobotModel::from_urdf_str(&xml, "pendulum.urdf").unwrap();
    assert_eq!(model.joint_limits()[0].upper, f64::INFINITY);
    let mut d = ModelData::new(&model);
    for &q in &[-2.0, -0.3, 0.0, 0.7, 1.9] {
        let e = eval(&model, &mut d, &[q], &[1.3]);
        // rotation about +y by q moves x to (cos q, 0, -sin q): V = -m g l sin q
        let g_expected = -m * STANDARD_GRAVITY * l * f64::cos(q);
        assert!((e.g[0] - g_expected).abs() < 1e-12, "{} vs {}", e.g[0], g_expected);
        assert!((e.m[(0, 0)] - (iyy + m * l * l)).abs() < 1e-14);
        // single joint: no Coriolis term, bias = gravity
        assert!((e.bias[0] - g_expected).abs() < 1e-12);
    }
}

fn arm_jacobian_singular_values(model: &RobotModel, d: &ModelData, side: &str) -> DVector<f64> {
    let f = model.frame_index(&format!("{side}_hand")).unwrap();
    let j = jac(model, d, f, &Vector3::zeros());
    let first = model.joint_index(&format!("{side}_shoulder_pan_joint")).unwrap();
    let sub = DMatrix::from_fn(6, 6, |r, c| j[(r, first + c)]);
    sub.svd(false, false).singular_values
}

#[test]
fn singular_configurations_stay_finite_and_lose_rank() {
    let model = tomm();
    let n = model.nv();
    let mut d = ModelData::new(&model);
    let mut q = vec![0.0; n];
    // generic arm configuration: full rank
    for (k, v) in [0.3, -1.2, 1.4, -1.0, 1.1, 0.4].iter().enumerate() {
        q[3 + k] = *v;
    }
    eval(&model, &mut d, &q, &vec![0.0; n]);
    assert!(arm_jacobian_singular_values(&model, &d, "left").min() > 1e-3);
    // aligned wrist axes (wrist_2 = 0) and stretched elbow (elbow = 0): rank drops
    for idx in [5usize, 7] {
        let mut qs = q.clone();
        qs[idx] = 0.0;
        let e = eval(&model, &mut d, &qs, &vec![0.5; n]);
        let sv = arm_jacobian_singular_values(&model, &d, "left");
        assert!(sv.min() < 1e-10, "joint {idx}: {sv}");
        assert!(e.m.iter().chain(e.bias.iter()).chain(e.g.iter()).all(|x| x.is_finite()));
    }
    // all zero: stretched arm
    let e = eval(&model, &mut d, &vec![0.0; n], &vec![0.0; n]);
    assert!(arm_jacobian_singular_values(&model, &d, "right").min() < 1e-10);
    assert!(e.m.iter().all(|x| x.is_finite()));
}

#[test]
fn huge_velocities_give_finite_results() {
    let model = tomm();
    let n = model.nv();
    let mut d = ModelData::new(&model);
    let (q, _, qdd) = Rng(23).state(&model);
    let qd = vec![1e6; n];
    let e = eval(&model, &mut d, &q, &qd);
    let mut tau = DVector::zeros(n);
    rnea(&model, &mut d, &qdd, &mut tau).unwrap();
    let mut a = Vector6::zeros();
    point_jacobian_dot_qdot(&model, &d, model.frame_index("left_hand").unwrap(), &Vector3::zeros(), &mut a).unwrap();
    assert!(e.bias.iter().chain(tau.iter()).chain(a.iter()).all(|x| x.is_finite()));
    assert!(e.bias.amax() > 1e6);
}

#[test]
fn non_finite_inputs_are_rejected_naming_the_joint() {
    let model = tomm();
    let n = model.nv();
    let mut d = ModelData::new(&model);
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut q = vec![0.0; n];
        q[4] = bad;
        let err = update_kinematics(&model, &mut d, &q, &vec![0.0; n]).unwrap_err().to_string();
        assert!(err.contains("left_shoulder_lift_joint") && err.contains("q[4]"), "{err}");
        let mut qd = vec![0.0; n];
        qd[14] = bad;
        let err = update_kinematics(&model, &mut d, &vec![0.0; n], &qd).unwrap_err().to_string();
        assert!(err.contains("right_wrist_3_joint") && err.contains("qd[14]"), "{err}");
        let mut qdd = vec![0.0; n];
        qdd[0] = bad;
        let mut tau = DVector::zeros(n);
        let err = rnea(&model, &mut d, &qdd, &mut tau).unwrap_err().to_string();
        assert!(err.contains("base_x_joint"), "{err}");
    }
    let err = update_kinematics(&model, &mut d, &[0.0; 3], &vec![0.0; n]).unwrap_err().to_string();
    assert!(err.contains("q has length 3, expected 15"), "{err}");
    let mut small = Matrix6xX::zeros(3);
    assert!(point_jacobian(&model, &d, 0, &Vector3::zeros(), &mut small).is_err());
    let mut j = Matrix6xX::zeros(n);
    let err = point_jacobian(&model, &d, 3, &Vector3::new(f64::NAN, 0.0, 0.0), &mut j).unwrap_err().to_string();
    assert!(err.contains(&model.frame_names()[3]), "{err}");
}
