//! The task controller's input health without DDS: stale inputs ramp the commands down within the
//! acceleration limits and control resumes without a jump; stamps out of order or from the future
//! are refused; every bad input is counted in `/controller/state`.
use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use r2r::sensor_msgs::msg::{JointState, LaserScan};
use r2r::skin_msgs::msg::{ControllerState, SkinCellArray};
use skin_core::controller::ControllerConfig;

use super::*;
use crate::convert::robot::{time_msg, write_goal};
use crate::paths;

const RATE_HZ: f64 = 125.0;
/// config/resolver.yaml `arm.max_acceleration` \[rad/s²\].
const AMAX: f64 = 3.0;

/// planar7 on the timer with its own supervisor, a goal away from the start pose.
fn controller() -> TaskController {
    let config = ControllerConfig::load(&paths::resolve("config/controller/planar7.yaml").unwrap()).unwrap();
    let mut params = TaskControllerParams::defaults(&config);
    params.supervisor = SupervisorSource::Internal;
    params.control_rate_hz = RATE_HZ;
    let mut tc = TaskController::new(config, params, 0.0).unwrap();
    let goal =
        Isometry3::from_parts(Translation3::new(1.0, -0.6, 0.0), UnitQuaternion::from_euler_angles(0.0, 0.0, 1.57));
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

/// Runs `n` fresh periods from `t`, the robot moving at `v0` first (NaN: the last commands),
/// then following its commands exactly; returns the last command and the time after.
fn run_fresh(tc: &mut TaskController, mut t: f64, q: &mut [f64], v0: f64, n: usize) -> (Vec<f64>, f64) {
    let dt = 1.0 / RATE_HZ;
    let last: Vec<f64> = tc.controller().output().commands.joint_velocities.clone();
    let mut v = if v0.is_nan() { last } else { vec![v0; q.len()] };
    for _ in 0..n {
        tc.on_joint_states(&joint_state(tc, t, q, &v), t, |_| {}).unwrap();
        tc.on_cells(&cells(t, &[]), t, |_| {}).unwrap();
        assert_eq!(tc.freshness(t), Freshness::Fresh);
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
    let step = AMAX / RATE_HZ * (1.0 + 1e-9);
    // a wrong measured velocity (0.8 rad/s) at start: the first command starts from zero
    let (first, t) = run_fresh(&mut tc, 0.0, &mut q, 0.8, 1);
    assert!(first.iter().all(|v| v.abs() <= step), "{first:?}");
    // on towards the goal until a joint moves faster than one step
    let (mut moving, mut t) = (first, t);
    let peak_of = |v: &[f64]| v.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for _ in 0..50 {
        (moving, t) = run_fresh(&mut tc, t, &mut q, f64::NAN, 1);
        if peak_of(&moving) > 1.5 * step {
            break;
        }
    }
    let peak = peak_of(&moving);
    assert!(peak > 1.5 * step, "the arm moves: {moving:?}");

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
    let future = cells(10.1, &[]);
    let e = tc.on_cells(&future, 10.02, |_| {}).unwrap_err();
    assert!(e.to_string().starts_with("/skin/cells: header.stamp 10.100000 s: stamp in the future"), "{e}");
    let mut p = tc.params().clone();
    p.max_stamp_lead_s = 0.1;
    tc.take_settable(&p);
    tc.on_cells(&future, 10.02, |_| {}).unwrap();
    let issues = tc.issues();
    assert_eq!(issues.by_name("/joint_states: stamp out of order"), Some(2));
    assert_eq!(issues.by_name("/skin/cells: stamp in the future"), Some(1));
    assert_eq!(issues.by_name("/joint_states: joint stamp out of order"), Some(14), "per joint entry");
    assert_eq!(issues.total(), 17);
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

/// `/joint_states` messages of planar7's joints `range` stamped `t`, at `q` (velocity 0).
fn some_joints(tc: &TaskController, t: f64, range: std::ops::Range<usize>, q: &[f64]) -> JointState {
    let mut js = joint_state(tc, t, q, &[0.0; 7]);
    js.name = js.name[range.clone()].to_vec();
    js.position = js.position[range.clone()].to_vec();
    js.velocity = js.velocity[range].to_vec();
    js
}

/// Joint health is per joint: a message that writes no joint (other joints only, unknown names,
/// NaN values) refreshes nothing, so one silent driver or one NaN encoder makes the state stale.
#[test]
fn every_joint_must_be_fresh_and_finite() {
    let q = [1.4, -0.5, -0.5, -0.4, -0.3, -0.2, 0.1];
    let start = |tc: &mut TaskController| {
        tc.on_joint_states(&joint_state(tc, 1.0, &q, &[0.0; 7]), 1.0, |_| {}).unwrap();
    };
    let stale_joint = |f: Freshness| matches!(f, Freshness::Stale { input: "/joint_states", .. });
    // one driver (joints 0-3) goes silent while the other (4-6) and the skin go on
    let mut tc = controller();
    start(&mut tc);
    for k in 1..=20 {
        let t = 1.0 + 0.01 * k as f64;
        tc.on_joint_states(&some_joints(&tc, t, 4..7, &q), t, |_| {}).unwrap();
        tc.on_cells(&cells(t, &[]), t, |_| {}).unwrap();
        if k == 9 {
            assert_eq!(tc.freshness(t), Freshness::Fresh, "joints 0-3 are 0.09 s old: within the timeout");
        }
    }
    let f = tc.freshness(1.2);
    assert!(stale_joint(f), "joints 0-3 are 0.2 s old: {f:?}");
    // a NaN position or velocity on one joint, unknown names, a base joint: that joint ages
    for bad in 0..4 {
        let mut tc = controller();
        start(&mut tc);
        for k in 1..=20 {
            let t = 1.0 + 0.01 * k as f64;
            let mut js = joint_state(&tc, t, &q, &[0.0; 7]);
            match bad {
                0 => js.position[3] = f64::NAN,
                1 => js.velocity[3] = f64::INFINITY,
                2 => js.name[3] = "gripper_joint".into(),
                _ => js.name[3] = "base_x_joint".into(),
            }
            tc.on_joint_states(&js, t, |_| {}).unwrap();
            tc.on_cells(&cells(t, &[]), t, |_| {}).unwrap();
        }
        assert!(stale_joint(tc.freshness(1.2)), "case {bad}: {:?}", tc.freshness(1.2));
        assert_eq!(tc.state.q()[3], q[3], "case {bad}: the last good value is kept, not overwritten");
    }
    // a message with only other joints' names (or none) is no news about joint 3
    let mut tc = controller();
    start(&mut tc);
    let mut empty = joint_state(&tc, 1.15, &q, &[0.0; 7]);
    (empty.name, empty.position, empty.velocity) = (vec!["gripper_joint".into()], vec![0.0], vec![0.0]);
    tc.on_joint_states(&empty, 1.15, |_| {}).unwrap();
    tc.on_cells(&cells(1.15, &[]), 1.15, |_| {}).unwrap();
    assert!(stale_joint(tc.freshness(1.2)));
}

/// Two drivers on `/joint_states`, each with its own stamps, one lagging the other by 20 ms:
/// every message of both is accepted (the order is kept per joint), the state stays fresh and
/// the lagging joints follow their driver.
#[test]
fn two_drivers_with_their_own_stamps_are_both_accepted() {
    let mut tc = controller();
    let mut q = [1.4, -0.5, -0.5, -0.4, -0.3, -0.2, 0.1];
    for k in 0..50 {
        let t = 1.0 + 0.008 * k as f64;
        q[6] = 0.1 + 0.001 * k as f64;
        tc.on_joint_states(&some_joints(&tc, t, 0..4, &q), t, |_| {}).unwrap();
        tc.on_joint_states(&some_joints(&tc, t - 0.02, 4..7, &q), t, |_| panic!("an issue with the lagging driver"))
            .unwrap();
        tc.on_cells(&cells(t, &[]), t, |_| {}).unwrap();
        assert_eq!(tc.freshness(t), Freshness::Fresh);
        assert_eq!(tc.state.q()[6], q[6], "the lagging driver's joint is written");
    }
    assert_eq!(tc.issues().total(), 0, "{}", tc.issues());
    // a replayed old message of one driver is refused (and counted), the other is unaffected
    let e = tc.on_joint_states(&some_joints(&tc, 1.0, 4..7, &[0.0; 7]), 1.4, |_| {}).unwrap_err();
    assert!(e.reason.contains("stamp out of order"), "{e}");
    assert_eq!(tc.state.q()[6], q[6]);
}

/// Honest time: a stamp ahead of the clock beyond `max_stamp_lead_s` is refused and counted and
/// holds no later honest message back; an input whose age is below `-max_stamp_lead_s` (the
/// clock went back) is stale, and honest messages on the new clock are taken again.
#[test]
fn stamps_from_the_future_are_refused_and_negative_ages_are_stale() {
    let mut tc = controller();
    let q = [1.4, -0.5, -0.5, -0.4, -0.3, -0.2, 0.1];
    let feed = |tc: &mut TaskController, stamp: f64, now: f64| {
        let js = tc.on_joint_states(&joint_state(tc, stamp, &q, &[0.0; 7]), now, |_| {});
        let c = tc.on_cells(&cells(stamp, &[]), now, |_| {});
        js.and(c)
    };
    feed(&mut tc, 10.0, 10.0).unwrap();
    let e = feed(&mut tc, 10.095, 10.0).unwrap_err();
    assert!(e.reason.contains("stamp in the future"), "{e}");
    feed(&mut tc, 10.008, 10.008).unwrap();
    assert_eq!(tc.freshness(10.01), Freshness::Fresh);
    assert_eq!(tc.issues().by_name("/joint_states: stamp in the future"), Some(1));
    // the clock steps back by 2 s: every input is from the future, so stale (not fresh for 2 s)
    let f = tc.freshness(8.01);
    assert!(matches!(f, Freshness::Stale { age_s, .. } if age_s < -1.9), "{f:?}");
    // honest messages on the new clock are accepted at once, and control may resume
    feed(&mut tc, 8.02, 8.02).unwrap();
    assert_eq!(tc.freshness(8.02), Freshness::Fresh);
}

/// Per-input timeouts and their ranges.
#[test]
fn timeouts_are_per_input_and_bounded() {
    let config = ControllerConfig::load(&paths::resolve("config/controller/planar7.yaml").unwrap()).unwrap();
    let mut p = TaskControllerParams::defaults(&config);
    p.validate().unwrap();
    for key in ["input_timeout_s", "odom_timeout_s", "cells_timeout_s", "scan_timeout_s", "max_stamp_lead_s"] {
        for v in [1e300, -1.0, f64::NAN, 2.0] {
            let mut bad = p.clone();
            match key {
                "input_timeout_s" => bad.input_timeout_s = v,
                "odom_timeout_s" => bad.odom_timeout_s = v,
                "cells_timeout_s" => bad.cells_timeout_s = v,
                "scan_timeout_s" => bad.scan_timeout_s = v,
                _ => bad.max_stamp_lead_s = v,
            }
            let e = bad.validate().unwrap_err();
            assert!(e.contains(key) && e.contains("must be in ["), "{e}");
        }
    }
    // the skin cells have their own timeout: cells 0.15 s old are stale at 0.1, fresh at 0.2
    let mut tc = controller();
    let q = [1.4, -0.5, -0.5, -0.4, -0.3, -0.2, 0.1];
    tc.on_cells(&cells(1.0, &[]), 1.0, |_| {}).unwrap();
    tc.on_joint_states(&joint_state(&tc, 1.15, &q, &[0.0; 7]), 1.15, |_| {}).unwrap();
    assert!(matches!(tc.freshness(1.15), Freshness::Stale { input: "/skin/cells", .. }));
    p.cells_timeout_s = 0.2;
    tc.take_settable(&p);
    assert_eq!(tc.freshness(1.15), Freshness::Fresh);
}

/// TOMM (a base with a LIDAR): a refused scan (a frame not on the base) does not refresh the
/// scan input: the state goes stale once the last good scan is older than `scan_timeout_s`.
#[test]
fn a_refused_scan_does_not_refresh_the_scan() {
    let config = ControllerConfig::load(&paths::resolve("config/controller/tomm.yaml").unwrap()).unwrap();
    let params = TaskControllerParams::defaults(&config);
    let mut tc = TaskController::new(config, params, 0.0).unwrap();
    let names = tc.controller().config().model.joint_names().to_vec();
    let arm: Vec<String> = names.iter().filter(|n| !n.starts_with("base_")).cloned().collect();
    let scan = |t: f64, frame: &str| LaserScan {
        header: r2r::std_msgs::msg::Header { stamp: time_msg(t), frame_id: frame.into() },
        angle_increment: 0.1,
        range_max: 5.0,
        ranges: vec![1.0; 10],
        ..Default::default()
    };
    let mut odom = r2r::nav_msgs::msg::Odometry::default();
    odom.pose.pose.orientation.w = 1.0;
    let mut feed = |tc: &mut TaskController, t: f64, frame: &str| {
        let js = JointState {
            header: r2r::std_msgs::msg::Header { stamp: time_msg(t), ..Default::default() },
            position: vec![0.0; arm.len()],
            velocity: vec![0.0; arm.len()],
            name: arm.clone(),
            ..Default::default()
        };
        tc.on_joint_states(&js, t, |_| {}).unwrap();
        odom.header.stamp = time_msg(t);
        tc.on_odometry(&odom, t).unwrap();
        tc.on_cells(&cells(t, &[]), t, |_| {}).unwrap();
        tc.on_scan(&scan(t, frame), t)
    };
    let e = feed(&mut tc, 1.0, "right_hand").unwrap_err();
    assert!(e.reason.contains("`right_hand`"), "{e}");
    assert_eq!(tc.freshness(1.0), Freshness::Waiting, "a refused scan is no scan: {:?}", tc.missing());
    feed(&mut tc, 1.01, "laser").unwrap();
    assert_eq!(tc.freshness(1.01), Freshness::Fresh);
    for k in 2..40 {
        assert!(feed(&mut tc, 1.0 + 0.01 * k as f64, "right_hand").is_err());
    }
    let f = tc.freshness(1.39);
    assert!(matches!(f, Freshness::Stale { input: "/scan", .. }), "{f:?}");
}

/// docs/ros.md's table of the node's parameters is what the declarations say (regenerate with
/// `SKIN_BLESS=1 cargo test -p skin_control parameter_table`).
#[test]
fn parameter_table_in_docs_is_current() {
    const START: &str = "<!-- task_controller parameters: generated by `SKIN_BLESS=1 cargo test -p skin_control parameter_table`; do not edit -->\n";
    const END: &str = "<!-- end of the generated table -->";
    let config = ControllerConfig::load(&paths::resolve("config/controller/tomm.yaml").unwrap()).unwrap();
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/ros.md");
    let doc = std::fs::read_to_string(&path).unwrap();
    let (a, b) = (doc.find(START).expect("start marker") + START.len(), doc.find(END).expect("end marker"));
    let table = parameter_table(&config);
    if std::env::var_os("SKIN_BLESS").is_some() {
        std::fs::write(&path, format!("{}{table}{}", &doc[..a], &doc[b..])).unwrap();
    } else {
        assert_eq!(&doc[a..b], table, "docs/ros.md is stale: SKIN_BLESS=1 cargo test -p skin_control parameter_table");
    }
}

/// A follower logs a switch and the start and end of a blocked hold, with its reason, but not
/// the sensing-range steps that republish the arrangement every cycle of a ramp.
#[test]
fn a_follower_logs_switches_and_the_blocked_hold_not_range_steps() {
    use crate::convert::control::{arrangement_msg, blocked_hold_msg};
    use skin_core::supervisor::{Blocked, Supervisor};
    let config = ControllerConfig::load(&paths::resolve("config/controller/planar7.yaml").unwrap()).unwrap();
    let sup = Supervisor::new(&config.supervisor, 0.0).unwrap();
    let mut tc = TaskController::new(config.clone(), TaskControllerParams::defaults(&config), 0.0).unwrap();
    let mut msg = arrangement_msg(sup.arrangement(), sup.tasks(), None);
    let note = tc.on_arrangement(&msg).unwrap().expect("the first arrangement");
    assert!(note.starts_with("following mode 0"), "{note}");
    msg.sensing_range *= 0.5;
    assert_eq!(tc.on_arrangement(&msg).unwrap(), None, "a range step is no news");
    msg.blocked = blocked_hold_msg(Some(Blocked { since_s: 11.0, goal_error_m: 0.17, contact_force_n: 7.35 }));
    let note = tc.on_arrangement(&msg).unwrap().expect("the hold");
    assert!(note.starts_with("blocked: the push was given up at t = 11.000 s (7.35 N"), "{note}");
    assert_eq!(tc.on_arrangement(&msg).unwrap(), None);
    msg.blocked.active = false;
    assert_eq!(tc.on_arrangement(&msg).unwrap().as_deref(), Some("the blocked hold ended"));
}
