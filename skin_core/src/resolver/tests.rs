//! Tests of the resolver on the shipped TOMM and planar7 models.

use std::path::PathBuf;

use nalgebra::DVector;
use proptest::prelude::*;

use super::*;
use crate::model::{gravity, update_kinematics, ModelData, RobotModel};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn model(name: &str) -> RobotModel {
    RobotModel::from_urdf_file(&root().join(format!("urdf/{name}.urdf"))).unwrap()
}

const ARM_DT: f64 = 1.0 / 125.0;
const BASE_DT: f64 = 1.0 / 1000.0;

/// Relative tolerance of the limit checks (round-off only).
fn within(x: f64, limit: f64) -> bool {
    x.abs() <= limit * (1.0 + 1e-12) + 1e-15
}

#[test]
fn resolver_shipped_params_equal_default() {
    let p = ResolverParams::load(&root().join("config/resolver.yaml")).unwrap();
    assert_eq!(p, ResolverParams::default());
}

#[test]
fn resolver_invalid_param_names_file_and_key() {
    let text = std::fs::read_to_string(root().join("config/resolver.yaml")).unwrap();
    let bad = text.replace("max_acceleration: 3.0", "max_acceleration: -3.0");
    assert_ne!(bad, text);
    let e = ResolverParams::from_yaml_str(&bad, "bad.yaml").unwrap_err().to_string();
    assert!(e.contains("bad.yaml") && e.contains("arm.max_acceleration"), "{e}");
    let bad = text.replace("damping: [100.0, 100.0, 25.0]", "damping: [100.0, .nan, 25.0]");
    let e = ResolverParams::from_yaml_str(&bad, "b.yaml").unwrap_err().to_string();
    assert!(e.contains("base.damping[1]"), "{e}");
    let bad = text.replace("rate_hz: 125.0", "rate_hz: 125.0\n  bogus: 1");
    let e = ResolverParams::from_yaml_str(&bad, "c.yaml").unwrap_err().to_string();
    assert!(e.starts_with("c.yaml:") && e.contains("bogus"), "{e}");
    let bad = text.replace("push_speed_max_mps: 0.1 ", "push_speed_max_mps: 0.01 ");
    assert_ne!(bad, text);
    let e = ResolverParams::from_yaml_str(&bad, "d.yaml").unwrap_err().to_string();
    assert!(e.contains("d.yaml") && e.contains("approach.push_speed_max_mps"), "{e}");
}

#[test]
fn resolver_overrides_are_checked_against_the_model() {
    let m = model("tomm");
    let mut p = ResolverParams::default();
    p.arm.joints.insert("base_x_joint".into(), JointOverride { inertia: Some(1.0), ..Default::default() });
    let e = Resolver::new(&m, p.clone()).unwrap_err();
    assert!(e.to_string().contains("arm.joints.base_x_joint"), "{e}");
    p.arm.joints.clear();
    p.arm.joints.insert("left_wrist_3_joint".into(), JointOverride { inertia: Some(-1.0), ..Default::default() });
    let e = Resolver::new(&m, p).unwrap_err();
    assert!(e.to_string().contains("arm.joints.left_wrist_3_joint.inertia"), "{e}");
}

#[test]
fn resolver_classifies_base_and_arm_joints() {
    let m = model("tomm");
    let r = Resolver::new(&m, ResolverParams::default()).unwrap();
    assert_eq!(r.base_joints(), Some([0, 1, 2]));
    assert_eq!(r.arm_joints().len(), 12);
    assert!(r.arm_joints().iter().all(|&j| j >= 3));
    let p7 = Resolver::new(&model("planar7"), ResolverParams::default()).unwrap();
    assert_eq!(p7.base_joints(), None);
    assert_eq!(p7.arm_joints(), &[0, 1, 2, 3, 4, 5, 6]);
}

#[test]
fn resolver_gravity_compensated_rest_stays_at_rest() {
    let m = model("tomm");
    let n = m.nv();
    let mut data = ModelData::new(&m);
    let q: Vec<f64> = (0..n).map(|i| 0.3 * (i as f64).sin()).collect();
    let qd = vec![0.0; n];
    update_kinematics(&m, &mut data, &q, &qd).unwrap();
    let mut g = DVector::zeros(n);
    gravity(&m, &mut data, &mut g).unwrap();
    assert!(g.amax() > 1.0, "gravity must matter in this test");
    let mut r = Resolver::new(&m, ResolverParams::default()).unwrap();
    r.reset(&q, &qd).unwrap();
    for _ in 0..200 {
        // τ* = 0 task torque + g (eq. 19 with the bias)
        r.update_arms(g.as_slice(), g.as_slice(), &q, &qd, ARM_DT).unwrap();
        for _ in 0..8 {
            r.update_base(g.as_slice(), &q, &qd, BASE_DT).unwrap();
        }
    }
    let c = r.commands();
    assert!(c.joint_velocities.iter().all(|v| v.abs() < 1e-12), "{:?}", c.joint_velocities);
    assert!(c.base_twist.iter().all(|v| v.abs() < 1e-12), "{:?}", c.base_twist);
}

/// Planar7 with M = 2, C = 8 on every joint and limits far away.
fn first_order_setup() -> (RobotModel, Resolver) {
    let m = model("planar7");
    let mut p = ResolverParams::default();
    p.arm.inertia = 2.0;
    p.arm.damping = 8.0;
    p.arm.velocity_limit_scale = 1.0;
    p.arm.max_acceleration = 100.0;
    p.arm.subtract_gravity = false;
    let r = Resolver::new(&m, p).unwrap();
    (m, r)
}

#[test]
fn resolver_constant_torque_gives_first_order_response() {
    let (m, mut r) = first_order_setup();
    let n = m.nv();
    let (mass, c, tau3) = (2.0, 8.0, 3.0);
    let mut tau = vec![0.0; n];
    tau[3] = tau3;
    let zeros = vec![0.0; n];
    let mut qd = vec![0.0; n];
    r.reset(&zeros, &qd).unwrap();
    for k in 1..=500 {
        // an ideal velocity-controlled robot: the measured velocity is the last command
        let v = r.update_arms(&tau, &zeros, &zeros, &qd, ARM_DT).unwrap().joint_velocities[3];
        qd.copy_from_slice(&r.commands().joint_velocities);
        let t = k as f64 * ARM_DT;
        let exact = tau3 / c * (1.0 - (-c * t / mass).exp());
        assert!((v - exact).abs() < 1e-12, "step {k}: {v} vs {exact}");
    }
    assert!((qd[3] - tau3 / c).abs() < 1e-6);
    assert!(qd.iter().enumerate().all(|(i, v)| i == 3 || *v == 0.0));
}

#[test]
fn resolver_zero_damping_integrates_torque() {
    let (m, mut r) = first_order_setup();
    let mut p = r.params().clone();
    p.arm.damping = 0.0;
    r.set_params(&m, p).unwrap();
    let n = m.nv();
    let mut tau = vec![0.0; n];
    tau[0] = 0.5;
    let zeros = vec![0.0; n];
    let mut qd = vec![0.0; n];
    for _ in 0..100 {
        r.update_arms(&tau, &zeros, &zeros, &qd, ARM_DT).unwrap();
        qd.copy_from_slice(&r.commands().joint_velocities);
    }
    assert!((qd[0] - 0.5 / 2.0 * 100.0 * ARM_DT).abs() < 1e-12, "{}", qd[0]);
}

#[test]
fn resolver_arms_and_base_run_at_their_own_rates() {
    let m = model("tomm");
    let n = m.nv();
    let mut p = ResolverParams::default();
    p.arm.velocity_limit_scale = 1.0;
    p.arm.max_acceleration = 1000.0;
    p.base.max_linear_m_s = 10.0;
    p.base.max_linear_accel_m_s2 = 1000.0;
    let (ma, ca) = (p.arm.inertia, p.arm.damping);
    let (mb, db) = (p.base.inertia[0], p.base.damping[0]);
    p.arm.subtract_gravity = false;
    let mut r = Resolver::new(&m, p).unwrap();
    let mut tau = vec![0.0; n];
    tau[0] = 20.0; // world x force on the base (yaw 0: base x)
    let ja = r.arm_joints()[2];
    tau[ja] = 5.0;
    let zeros = vec![0.0; n];
    let mut qd = vec![0.0; n];
    // 1 s: 125 arm steps and 1000 base steps, interleaved like the two timers
    for k in 0..1000 {
        r.update_base(&tau, &zeros, &qd, BASE_DT).unwrap();
        qd[0] = r.commands().base_twist[0];
        if k % 8 == 7 {
            r.update_arms(&tau, &zeros, &zeros, &qd, ARM_DT).unwrap();
            qd[ja] = r.commands().joint_velocities[2];
        }
    }
    let arm = 5.0 / ca * (1.0 - (-ca / ma).exp());
    let base = 20.0 / db * (1.0 - (-db / mb).exp());
    assert!((r.commands().joint_velocities[2] - arm).abs() < 1e-9);
    assert!((r.commands().base_twist[0] - base).abs() < 1e-9);
    // the arm torque does not move the base, the base force does not move the arm
    assert_eq!(r.commands().base_twist[1], 0.0);
    assert!(r.commands().joint_velocities.iter().enumerate().all(|(i, v)| i == 2 || *v == 0.0));
}

#[test]
fn resolver_base_twist_is_in_the_base_frame() {
    let m = model("tomm");
    let n = m.nv();
    let mut r = Resolver::new(&m, ResolverParams::default()).unwrap();
    let mut q = vec![0.0; n];
    q[2] = std::f64::consts::FRAC_PI_2; // base x axis = world y
    let mut tau = vec![0.0; n];
    tau[0] = 30.0; // push along world +x = base -y
    let zeros = vec![0.0; n];
    r.reset(&q, &zeros).unwrap();
    let mut qd = vec![0.0; n];
    for _ in 0..500 {
        let t = r.update_base(&tau, &q, &qd, BASE_DT).unwrap().base_twist;
        // the measured world velocity of an ideal base
        qd[0] = -t[1];
        qd[1] = t[0];
    }
    let t = r.commands().base_twist;
    assert!(t[0].abs() < 1e-12 && t[1] < -0.05 && t[2] == 0.0, "{t:?}");
}

/// An odometry reset or a localisation correction turns the measured yaw by 90 degrees in one
/// message: the twist, sent in the base frame, changes within the acceleration limits (the rate
/// limit holds in the frame of the command, not in the world frame).
#[test]
fn resolver_base_rate_limit_holds_in_the_base_frame_across_a_yaw_jump() {
    let m = model("tomm");
    let n = m.nv();
    let p = ResolverParams::default();
    let mut r = Resolver::new(&m, p.clone()).unwrap();
    let mut q = vec![0.0; n];
    let mut qd = vec![0.0; n];
    let mut tau = vec![0.0; n];
    let mut prev = r.commands().base_twist;
    let step_ok = |a: [f64; 3], b: [f64; 3]| {
        (a[0] - b[0]).hypot(a[1] - b[1]) <= p.base.max_linear_accel_m_s2 * BASE_DT * (1.0 + 1e-12)
            && (a[2] - b[2]).abs() <= p.base.max_angular_accel_rad_s2 * BASE_DT * (1.0 + 1e-12)
    };
    for k in 0..3000 {
        if k == 1500 {
            q[2] += std::f64::consts::FRAC_PI_2; // the jump
        }
        // a constant push along the base's x axis, and the ideal base's measured world velocity
        let (s, c) = q[2].sin_cos();
        (tau[0], tau[1]) = (30.0 * c, 30.0 * s);
        let t = r.update_base(&tau, &q, &qd, BASE_DT).unwrap().base_twist;
        assert!(step_ok(prev, t), "step {k}: {prev:?} -> {t:?}");
        prev = t;
        (qd[0], qd[1]) = (c * t[0] - s * t[1], s * t[0] + c * t[1]);
    }
    assert!(prev[0] > 0.05 && prev[1].abs() < 1e-3, "still along base x: {prev:?}");
    // and the safe stop keeps the direction in the base frame
    let before = r.commands().base_twist;
    let after = r.safe_stop_base(BASE_DT).base_twist;
    assert!(step_ok(before, after) && after[0] < before[0]);
    assert!((after[1] * before[0] - after[0] * before[1]).abs() < 1e-15, "{before:?} -> {after:?}");
}

#[test]
fn resolver_position_limit_blocks_outward_allows_inward() {
    let (m, mut r) = first_order_setup();
    let n = m.nv();
    let upper = m.joint_limits()[1].upper;
    let mut q = vec![0.0; n];
    q[1] = upper;
    let zeros = vec![0.0; n];
    let mut tau = vec![0.0; n];
    tau[1] = 10.0;
    for _ in 0..50 {
        let v = r.update_arms(&tau, &zeros, &q, &zeros, ARM_DT).unwrap().joint_velocities[1];
        assert_eq!(v, 0.0);
    }
    tau[1] = -10.0;
    let v = r.update_arms(&tau, &zeros, &q, &zeros, ARM_DT).unwrap().joint_velocities[1];
    assert!(v < 0.0, "{v}");
    // approaching the limit: the joint stops before it
    r.reset(&zeros, &zeros).unwrap();
    tau[1] = 10.0;
    let mut qd = vec![0.0; n];
    let mut q = vec![0.0; n];
    q[1] = upper - 0.3;
    let mut max_q: f64 = f64::MIN;
    for _ in 0..300 {
        let v = r.update_arms(&tau, &zeros, &q, &qd, ARM_DT).unwrap().joint_velocities[1];
        qd[1] = v;
        q[1] += v * ARM_DT;
        max_q = max_q.max(q[1]);
    }
    assert!(max_q <= upper + 1e-9 && max_q > upper - 1e-3, "{max_q} vs {upper}");
}

#[test]
fn resolver_non_finite_input_errors_then_safe_stop_ramps_down() {
    let m = model("tomm");
    let n = m.nv();
    let mut r = Resolver::new(&m, ResolverParams::default()).unwrap();
    let zeros = vec![0.0; n];
    let qd: Vec<f64> = (0..n).map(|i| if i < 3 { 0.3 } else { 1.0 - 0.15 * i as f64 }).collect();
    r.reset(&zeros, &qd).unwrap();
    let mut tau = vec![0.0; n];
    tau[5] = f64::NAN;
    let e = r.update_arms(&tau, &zeros, &zeros, &qd, ARM_DT).unwrap_err();
    assert!(matches!(e, ResolverError::NonFinite { what: "tau", index: 5, value } if value.is_nan()), "{e}");
    assert!(e.to_string().starts_with("tau[5] is not finite"), "{e}");
    let mut qdi = qd.clone();
    qdi[7] = f64::INFINITY;
    let e = r.update_base(&zeros, &zeros, &qdi, BASE_DT).unwrap_err();
    assert!(e.to_string().starts_with("qd_measured[7] is not finite"), "{e}");
    let e = r.update_arms(&zeros, &zeros, &zeros, &zeros[..3], ARM_DT).unwrap_err();
    assert!(matches!(e, ResolverError::Dimension { what: "qd_measured", .. }), "{e}");
    // the failed updates already stepped the safe stop; keep stopping
    let amax: Vec<f64> = r.arm_acceleration_limits().collect();
    let p = r.params().base;
    let mut prev = r.commands().clone();
    for _ in 0..500 {
        let c = r.safe_stop(ARM_DT).clone();
        for ((&a, &b), &amax) in prev.joint_velocities.iter().zip(&c.joint_velocities).zip(&amax) {
            assert!(within(b - a, amax * ARM_DT) && b.abs() <= a.abs() && b * a >= 0.0);
        }
        let dl = (c.base_twist[0] - prev.base_twist[0]).hypot(c.base_twist[1] - prev.base_twist[1]);
        assert!(within(dl, p.max_linear_accel_m_s2 * ARM_DT));
        prev = c;
    }
    assert!(prev.joint_velocities.iter().chain(&prev.base_twist).all(|v| *v == 0.0));
    // a NaN dt stops with the nominal period
    r.reset(&zeros, &qd).unwrap();
    let e = r.update_arms(&zeros, &zeros, &zeros, &zeros, f64::NAN).unwrap_err();
    assert!(matches!(e, ResolverError::InvalidDt(dt) if dt.is_nan()), "{e}");
    let k = r.arm_joints()[0];
    assert!((r.commands().joint_velocities[0] - (qd[k] - amax[0] * ARM_DT)).abs() < 1e-12);
}

#[test]
fn resolver_reset_starts_without_jump() {
    let m = model("tomm");
    let n = m.nv();
    let p = ResolverParams::default();
    let mut r = Resolver::new(&m, p.clone()).unwrap();
    let q = vec![0.1; n];
    let mut qd = vec![0.0; n];
    qd[0] = 0.2;
    qd[1] = -0.1;
    qd[2] = 0.3;
    for (k, &j) in r.arm_joints().to_vec().iter().enumerate() {
        qd[j] = 0.1 * (k as f64 - 5.0);
    }
    r.reset(&q, &qd).unwrap();
    let zeros = vec![0.0; n];
    let c = r.update(&zeros, &zeros, &q, &qd, ARM_DT).unwrap().clone();
    for (k, &j) in r.arm_joints().iter().enumerate() {
        assert!(within(c.joint_velocities[k] - qd[j], p.arm.max_acceleration * ARM_DT));
        // zero task torque: the virtual damping slows the joint by its first-order step, at most
        // at the acceleration limit
        let free = qd[j] * (-p.arm.damping / p.arm.inertia * ARM_DT).exp();
        let step = p.arm.max_acceleration * ARM_DT;
        let expected = qd[j] + (free - qd[j]).clamp(-step, step);
        assert!((c.joint_velocities[k] - expected).abs() < 1e-12, "{} vs {expected}", c.joint_velocities[k]);
    }
    // base: (0.2, -0.1) world at yaw 0.1, slowed by damping within the acceleration limit
    let (s, co) = 0.1f64.sin_cos();
    let vb = [co * 0.2 - s * 0.1, -s * 0.2 - co * 0.1];
    let d = (c.base_twist[0] - vb[0]).hypot(c.base_twist[1] - vb[1]);
    assert!(within(d, p.base.max_linear_accel_m_s2 * ARM_DT), "{d}");
}

#[test]
fn resolver_gain_change_causes_no_jump() {
    let (m, mut r) = first_order_setup();
    let n = m.nv();
    let mut tau = vec![0.0; n];
    tau[2] = 3.0;
    let zeros = vec![0.0; n];
    let mut qd = vec![0.0; n];
    for _ in 0..50 {
        r.update_arms(&tau, &zeros, &zeros, &qd, ARM_DT).unwrap();
        qd.copy_from_slice(&r.commands().joint_velocities);
    }
    let before = qd[2];
    let mut p = r.params().clone();
    p.arm.inertia = 0.1;
    p.arm.damping = 30.0;
    r.set_params(&m, p).unwrap();
    let after = r.update_arms(&tau, &zeros, &zeros, &qd, ARM_DT).unwrap().joint_velocities[2];
    // the velocity moves continuously from where it was towards the new steady state 3/30
    assert!(after < before && after > 0.1 - 1e-12, "{before} -> {after}");
    assert!((after - before).abs() <= 100.0 * ARM_DT);
}

#[test]
fn resolver_velocity_scaling_keeps_the_arm_direction() {
    let m = model("tomm");
    let n = m.nv();
    let mut r = Resolver::new(&m, ResolverParams::default()).unwrap();
    let zeros = vec![0.0; n];
    let mut tau = vec![0.0; n];
    let arm = r.arm_joints().to_vec();
    tau[arm[0]] = 1e6; // left arm
    tau[arm[1]] = 5e5;
    tau[arm[6]] = 2.0; // right arm: small, unaffected by the left arm's saturation
    let mut p = ResolverParams::default();
    p.arm.subtract_gravity = false;
    p.arm.max_acceleration = 1e6;
    r.set_params(&m, p).unwrap();
    let c = r.update_arms(&tau, &zeros, &zeros, &zeros, ARM_DT).unwrap();
    let v = &c.joint_velocities;
    let vmax = std::f64::consts::PI * 0.5;
    assert!((v[0] - vmax).abs() < 1e-12 && (v[1] / v[0] - 0.5).abs() < 1e-6, "{v:?}");
    let free = 2.0 / 10.0 * (1.0 - (-10.0 / 0.5 * ARM_DT).exp());
    assert!((v[6] - free).abs() < 1e-12, "{v:?}");
}

fn torque() -> impl Strategy<Value = f64> {
    prop_oneof![Just(1e6), Just(-1e6), Just(0.0), -300.0..300.0f64, -1e7..1e7f64]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn resolver_limits_hold_for_random_torques(
        seq in prop::collection::vec(prop::collection::vec(torque(), 15), 1..25),
        measured in prop::collection::vec(-5.0..5.0f64, 15),
        yaw in -4.0..4.0f64,
    ) {
        let m = model("tomm");
        let n = m.nv();
        prop_assert_eq!(n, 15);
        let mut r = Resolver::new(&m, ResolverParams::default()).unwrap();
        let p = r.params().clone();
        let vmax = r.arm_velocity_limits().to_vec();
        let amax: Vec<f64> = r.arm_acceleration_limits().collect();
        let mut q = vec![0.0; n];
        q[2] = yaw;
        for (k, &j) in r.arm_joints().to_vec().iter().enumerate() {
            q[j] = if k % 3 == 0 { m.joint_limits()[j].upper - 0.01 } else { 0.2 };
        }
        let zeros = vec![0.0; n];
        let mut prev = r.commands().clone();
        for tau in &seq {
            for _ in 0..8 {
                let c = r.update_base(tau, &q, &measured, BASE_DT).unwrap();
                let (l, dl) = (c.base_twist[0].hypot(c.base_twist[1]),
                    (c.base_twist[0] - prev.base_twist[0]).hypot(c.base_twist[1] - prev.base_twist[1]));
                prop_assert!(within(l, p.base.max_linear_m_s), "{}", l);
                prop_assert!(within(c.base_twist[2], p.base.max_angular_rad_s));
                prop_assert!(within(dl, p.base.max_linear_accel_m_s2 * BASE_DT), "{}", dl);
                prop_assert!(within(c.base_twist[2] - prev.base_twist[2], p.base.max_angular_accel_rad_s2 * BASE_DT));
                prev.base_twist = c.base_twist;
            }
            let c = r.update_arms(tau, &zeros, &q, &measured, ARM_DT).unwrap();
            for (i, &v) in c.joint_velocities.iter().enumerate() {
                prop_assert!(v.is_finite());
                prop_assert!(within(v, vmax[i]), "joint {}: {} > {}", i, v, vmax[i]);
                prop_assert!(within(v - prev.joint_velocities[i], amax[i] * ARM_DT), "joint {}: step {}", i, v - prev.joint_velocities[i]);
            }
            prev.joint_velocities.copy_from_slice(&c.joint_velocities);
        }
    }
}

#[test]
fn virtual_dynamics_predict_what_the_resolver_executes() {
    // A torque g + M_v a + C v (virtual_mass, virtual_damping) accelerates every joint by a, the base in world
    // axes too at any yaw and with anisotropic M_b (up to the zero-order hold: C dt / 2M, 1 % on the arms).
    let m = model("tomm");
    let mut p = ResolverParams::default();
    p.base.inertia = [40.0, 20.0, 10.0];
    let mut r = Resolver::new(&m, p).unwrap();
    let n = m.nv();
    let mut q = DVector::zeros(n);
    let [bx, by, byaw] = r.base_joints().unwrap();
    q[byaw] = 0.7;
    let qd = DVector::from_fn(n, |i, _| 0.1 * (i as f64 + 1.0).sin());
    r.reset(q.as_slice(), qd.as_slice()).unwrap();
    let a = DVector::from_fn(n, |i, _| 0.5 * (i as f64 * 0.7).cos());
    let (mut mass, mut damping) = (nalgebra::DMatrix::zeros(n, n), DVector::zeros(n));
    r.virtual_mass(q.as_slice(), &mut mass);
    r.virtual_damping(q.as_slice(), qd.as_slice(), BASE_DT, &mut damping);
    let g = DVector::from_fn(n, |j, _| if [bx, by, byaw].contains(&j) { 0.0 } else { 3.0 }); // the arms' gravity
    let tau = &mass * &a + &damping + &g;
    r.update(tau.as_slice(), g.as_slice(), q.as_slice(), qd.as_slice(), BASE_DT).unwrap();
    let c = r.commands();
    for (&j, &v) in r.arm_joints().iter().zip(&c.joint_velocities) {
        let acc = (v - qd[j]) / BASE_DT;
        assert!((acc - a[j]).abs() < 0.015 * a[j].abs() + 1e-6, "joint {j}: {acc} != {}", a[j]);
    }
    let (s, co) = q[byaw].sin_cos();
    let t = c.base_twist;
    let world = [co * t[0] - s * t[1], s * t[0] + co * t[1], t[2]];
    for (k, &j) in [bx, by, byaw].iter().enumerate() {
        let acc = (world[k] - qd[j]) / BASE_DT;
        assert!((acc - a[j]).abs() < 0.015 * a[j].abs() + 1e-6, "base {k}: {acc} != {}", a[j]);
    }
}

#[test]
fn a_held_joint_needs_no_limits_and_stays_at_zero() {
    let text = std::fs::read_to_string(root().join("urdf/planar7.urdf")).unwrap();
    // the first joint without a velocity limit (a caster, a passive joint)
    let text = text.replacen(r#"velocity="2""#, r#"velocity="0""#, 1);
    let m = RobotModel::from_urdf_str(&text, "planar7 without a limit").unwrap();
    let params = ResolverParams::default();
    let e = Resolver::new(&m, params.clone()).unwrap_err().to_string();
    assert!(e.contains(&m.joint_names()[0]) && e.contains("velocity limit"), "{e}");
    let mut held = vec![false; m.nv()];
    held[0] = true;
    let mut r = Resolver::with_held(&m, params, &held).unwrap();
    let (q, qd) = (vec![0.1; m.nv()], vec![0.0; m.nv()]);
    for _ in 0..50 {
        r.update(&vec![5.0; m.nv()], &vec![0.0; m.nv()], &q, &qd, ARM_DT).unwrap();
    }
    let v = &r.commands().joint_velocities;
    assert_eq!(v[0], 0.0, "held");
    assert!(v[1].abs() > 1e-3, "the free joints move: {v:?}");
}
