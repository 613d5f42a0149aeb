//! The task controller's input health without DDS: stale inputs ramp the commands down within the
//! acceleration limits and control resumes without a jump; stamps out of order or from the future
//! are refused; every bad input is counted in `/controller/state`.
use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use r2r::sensor_msgs::msg::JointState;
use r2r::skin_msgs::msg::{ControllerState, SkinCellArray};
use skin_core::controller::ControllerConfig;

use super::*;
use crate::convert::robot::{time_msg, write_goal};
use crate::paths;

const RATE_HZ: f64 = 125.0;
/// config/resolver.yaml `arm.max_acceleration` [rad/s²].
const AMAX: f64 = 3.0;

/// planar7 on the timer with its own supervisor, a goal away from the start pose.
fn controller() -> TaskController {
    let config = ControllerConfig::load(&paths::resolve("config/controller/planar7.yaml").unwrap()).unwrap();
    let mut params = TaskControllerParams::defaults(&config);
    params.supervisor = SupervisorSource::Internal;
    params.control_rate_hz = RATE_HZ;
    let mut tc = TaskController::new(config, params, 0.0).unwrap();
    let goal = Isometry3::from_parts(Translation3::new(1.0, -0.6, 0.0), UnitQuaternion::from_euler_angles(0.0, 0.0, 1.57));
    tc.on_goal(&write_goal(&goal, &time_msg(0.0), "world")).unwrap();
    tc
}

fn joint_state(tc: &TaskController, t: f64, q: &[f64], qd: &[f64]) -> JointState {
    JointState {
        header: r2r::std_msgs::msg::Header { stamp: time_msg(t), ..Default::default() },
        name: tc.controller().config().model.joint_names().to_vec(),
        position: q.to_vec(),
        velocity: qd.to_vec(),
        ..Default::default()
    }
}

/// A `/skin/cells` message of `(id, force, proximity)` cells stamped `t`.
fn cells(t: f64, cells: &[(u32, [f32; 3], f32)]) -> SkinCellArray {
    SkinCellArray {
        header: r2r::std_msgs::msg::Header { stamp: time_msg(t), ..Default::default() },
        cell_id: cells.iter().map(|c| c.0).collect(),
        force: cells.iter().flat_map(|c| c.1).collect(),
        proximity: cells.iter().map(|c| c.2).collect(),
        ..Default::default()
    }
}

fn command(out: &Outputs) -> Vec<f64> {
    out.arms.iter().flat_map(|m| m.data.iter().copied()).collect()
}

/// Runs `n` fresh periods from `t`, the robot moving at `v0` first, then following its commands
/// exactly; returns the last command and the time after.
fn run_fresh(tc: &mut TaskController, mut t: f64, q: &mut [f64], v0: f64, n: usize) -> (Vec<f64>, f64) {
    let dt = 1.0 / RATE_HZ;
    let mut v = vec![v0; q.len()];
    for _ in 0..n {
        tc.on_joint_states(&joint_state(tc, t, q, &v), t, |_| {}).unwrap();
        tc.on_cells(&cells(t, &[]), t, |_| {}).unwrap();
        assert!(tc.input_age(t).unwrap().abs() < 1e-9);
        let out = tc.cycle(t, &time_msg(t));
        assert_eq!(out.state.unwrap().input_status, ControllerState::INPUT_FRESH as u8);
        v = command(&out);
        for (qi, vi) in q.iter_mut().zip(&v) {
            *qi += vi * dt;
        }
        t += dt;
    }
    (v, t)
}

#[test]
fn stale_inputs_ramp_the_commands_down_and_control_resumes_without_a_jump() {
    let mut tc = controller();
    let mut q = vec![1.4, -0.5, -0.5, -0.4, -0.3, -0.2, 0.1];
    // the controller starts from the measured motion: commands near 0.8 rad/s
    let (moving, t) = run_fresh(&mut tc, 0.0, &mut q, 0.8, 2);
    let peak = moving.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(peak > 0.5, "the arm moves: {moving:?}");
    let step = AMAX / RATE_HZ * (1.0 + 1e-9);

    // inputs stop: every period decelerates by at most a_max dt, down to exactly zero
    let mut last = moving.clone();
    let periods = (peak / (AMAX / RATE_HZ)).ceil() as usize + 2;
    for k in 0..periods {
        let out = tc.idle_outputs(Idle::Stale, &time_msg(t + k as f64 / RATE_HZ));
        assert_eq!(out.state.unwrap().input_status, ControllerState::INPUT_STALE as u8);
        let now = command(&out);
        for (a, b) in last.iter().zip(&now) {
            assert!((a - b).abs() <= step && b.abs() <= a.abs(), "period {k}: {a} -> {b}");
        }
        last = now;
    }
    assert!(last.iter().all(|v| *v == 0.0), "stopped after {periods} periods: {last:?}");
    assert_eq!(tc.idle_periods(), periods as u64);

    // fresh inputs again (the robot stood still): the first command is within a_max dt of zero
    let t = t + periods as f64 / RATE_HZ;
    let (resumed, _) = run_fresh(&mut tc, t, &mut q, 0.0, 1);
    assert!(resumed.iter().all(|v| v.abs() <= step), "{resumed:?}");
    let (moving_again, _) = run_fresh(&mut tc, t + 1.0 / RATE_HZ, &mut q, 0.0, 20);
    assert!(moving_again.iter().any(|v| v.abs() > 0.01), "control resumed towards the goal: {moving_again:?}");
}

#[test]
fn waiting_for_inputs_sends_zero_commands_with_the_reason() {
    let mut tc = controller();
    assert_eq!(tc.missing().len(), 8, "seven joints and the skin: {:?}", tc.missing());
    let out = tc.idle_outputs(Idle::Waiting, &time_msg(0.0));
    assert!(command(&out).iter().all(|v| *v == 0.0));
    assert_eq!(out.state.unwrap().input_status, ControllerState::INPUT_WAITING as u8);
}

#[test]
fn stamps_out_of_order_or_from_the_future_are_refused_and_counted() {
    let mut tc = controller();
    let q = [1.4, -0.5, -0.5, -0.4, -0.3, -0.2, 0.1];
    let zero = [0.0; 7];
    tc.on_joint_states(&joint_state(&tc, 10.0, &q, &zero), 10.0, |_| {}).unwrap();
    let old = joint_state(&tc, 9.9, &[0.0; 7], &zero);
    let e = tc.on_joint_states(&old, 10.01, |_| {}).unwrap_err();
    assert_eq!((e.topic, e.first), ("/joint_states", true));
    assert!(e.reason.contains("stamp out of order"), "{e}");
    assert_eq!(tc.state.q()[0], 1.4, "the refused message wrote nothing");
    assert!(!tc.on_joint_states(&old, 10.01, |_| {}).unwrap_err().first, "logged once, counted always");
    let future = cells(10.5, &[]);
    let e = tc.on_cells(&future, 10.02, |_| {}).unwrap_err();
    assert!(e.to_string().starts_with("/skin/cells: header.stamp 10.500000 s: stamp in the future"), "{e}");
    tc.set_freshness(0.1, 1.0);
    tc.on_cells(&future, 10.02, |_| {}).unwrap();
    let issues = tc.issues();
    assert_eq!(issues.by_name("/joint_states: stamp out of order"), Some(2));
    assert_eq!(issues.by_name("/skin/cells: stamp in the future"), Some(1));
    assert_eq!(issues.total(), 3);
}

#[test]
fn every_bad_input_is_counted_in_the_controller_state() {
    let mut tc = controller();
    let q = [1.4, -0.5, -0.5, -0.4, -0.3, -0.2, 0.1];
    let mut js = joint_state(&tc, 1.0, &q, &[0.0; 7]);
    js.name.push("bogus".into());
    js.position.push(0.0);
    let mut reported = Vec::new();
    tc.on_joint_states(&js, 1.0, |i| reported.push(i.kind)).unwrap();
    let id = tc.controller().config().layout.cells()[0].id;
    let bad = cells(1.0, &[(id, [f32::NAN, 0.0, 0.0], 2.0), (999_999, [0.0; 3], 0.0)]);
    let mut cell_reports = 0;
    tc.on_cells(&bad, 1.0, |_| cell_reports += 1).unwrap();
    tc.on_cells(&bad, 1.0, |_| cell_reports += 1).unwrap();
    assert_eq!(cell_reports, 3, "the first of each kind is reported, the repeats only counted");
    let disagreeing = SkinCellArray { proximity: vec![0.0], ..bad };
    let e = tc.on_cells(&disagreeing, 1.0, |_| panic!("no cell is read")).unwrap_err();
    assert!(e.reason.contains("proximity has 1 values for 2 cells"), "{}", e.reason);
    let mut goal = write_goal(&Isometry3::identity(), &time_msg(1.0), "world");
    goal.pose.position.x = f64::NAN;
    assert!(tc.on_goal(&goal).unwrap_err().reason.contains("pose.position.x = NaN"));
    assert!(tc.on_force_reference(f64::INFINITY).is_err(), "planar7 has no hand: refused");
    let out = tc.cycle(1.0, &time_msg(1.0));
    assert!(command(&out).iter().all(|v| v.is_finite()));
    let state = out.state.unwrap();
    let count = |name: &str| state.issue_names.iter().position(|n| n == name).map(|k| state.issue_counts[k]);
    assert_eq!(reported, [JointIssue::UnknownJoint]);
    assert_eq!(count("/joint_states: unknown joint"), Some(1));
    assert_eq!(count("/skin/cells: non-finite signal"), Some(2));
    assert_eq!(count("/skin/cells: signal outside [0, 1]"), Some(2));
    assert_eq!(count("/skin/cells: unknown cell id"), Some(2));
    assert_eq!(count("/skin/cells: message refused"), Some(1));
    assert_eq!(count("/goal: message refused"), Some(1));
    assert_eq!(count("/hand_force_reference: message refused"), Some(1));
    assert_eq!(state.issue_counts.iter().sum::<u64>(), 10);
    assert_eq!(state.safe_stop_cycles, 0);
}
