//! The controller's outputs and the supervisor's messages: arm commands
//! (`std_msgs/Float64MultiArray` per arm, in that arm's joint order), the base twist
//! (`geometry_msgs/Twist`), `skin_msgs/ControllerState`, and `skin_msgs/Arrangement` <->
//! [`Imposed`] / [`Arrangement`].
//!
//! Arms: the resolver's arm joints (model order) are split into arms by joint-name prefix (TOMM:
//! `left_`, `right_`); arm `k` publishes on `<namespace k>/forward_velocity_controller/commands`
//! the velocities of its joints in model order, which for a UR5 is the driver's order
//! (shoulder_pan, shoulder_lift, elbow, wrist_1..3). Every arm joint must fall into exactly one arm.
use r2r::builtin_interfaces::msg::Time;
use r2r::geometry_msgs::msg::Twist;
use r2r::skin_msgs::msg::{Arrangement as ArrangementMsg, BlockedHold, ControllerState, TaskState};
use r2r::std_msgs::msg::{Float64MultiArray, MultiArrayDimension};
use skin_core::controller::ControllerOutput;
use skin_core::hierarchy::LevelDiagnostics;
use skin_core::supervisor::{Arrangement, Blocked, Imposed, Mode};

use super::robot::{time_msg, time_s};

/// The suffix of an arm's command topic after its namespace (ros2_control's
/// forward_velocity_controller).
pub const ARM_COMMAND_SUFFIX: &str = "/forward_velocity_controller/commands";

/// One arm's share of the resolver's joint velocities.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmCommand {
    /// Topic of its commands.
    pub topic: String,
    /// Joint names, in command order.
    pub joints: Vec<String>,
    /// Positions in `Commands::joint_velocities` of those joints.
    pub slots: Vec<usize>,
}

/// Splits the arm joints (model indices `arm_joints`, named by `names`) into arms by prefix.
/// `namespaces[k]` goes with `prefixes[k]`; errors name the parameter.
pub fn split_arms(
    names: &[String],
    arm_joints: &[usize],
    namespaces: &[String],
    prefixes: &[String],
) -> Result<Vec<ArmCommand>, String> {
    if namespaces.len() != prefixes.len() {
        return Err(format!(
            "arms.namespaces has {} entries, arms.joint_prefixes {}: they go in pairs",
            namespaces.len(),
            prefixes.len()
        ));
    }
    let mut arms: Vec<ArmCommand> = namespaces
        .iter()
        .map(|ns| ArmCommand {
            topic: format!("{}{ARM_COMMAND_SUFFIX}", ns.trim_end_matches('/')),
            joints: Vec::new(),
            slots: Vec::new(),
        })
        .collect();
    for (slot, &j) in arm_joints.iter().enumerate() {
        let name = &names[j];
        let owners: Vec<usize> = (0..prefixes.len()).filter(|&k| name.starts_with(&prefixes[k])).collect();
        // The longest matching prefix wins (an empty prefix takes what the others leave).
        let best = owners.iter().copied().max_by_key(|&k| prefixes[k].len());
        let Some(k) = best else {
            return Err(format!("arm joint `{name}` matches no entry of arms.joint_prefixes {prefixes:?}"));
        };
        if owners.iter().filter(|&&o| prefixes[o].len() == prefixes[k].len()).count() > 1 {
            return Err(format!("arm joint `{name}` matches several equal entries of arms.joint_prefixes"));
        }
        arms[k].joints.push(name.clone());
        arms[k].slots.push(slot);
    }
    if let Some(a) = arms.iter().find(|a| a.joints.is_empty()) {
        return Err(format!("{}: no arm joint matches its prefix", a.topic));
    }
    Ok(arms)
}

/// Writes arm `arm`'s command (one dimension labelled `joints`, size = its joint count).
pub fn write_arm_command(arm: &ArmCommand, joint_velocities: &[f64], msg: &mut Float64MultiArray) {
    if msg.layout.dim.len() != 1 {
        msg.layout.dim = vec![MultiArrayDimension { label: "joints".into(), size: 0, stride: 0 }];
    }
    let n = arm.slots.len() as u32;
    msg.layout.dim[0].size = n;
    msg.layout.dim[0].stride = n;
    msg.layout.data_offset = 0;
    msg.data.clear();
    msg.data.extend(arm.slots.iter().map(|&s| joint_velocities.get(s).copied().unwrap_or(0.0)));
}

/// Reads an arm command back into `joint_velocities` (the simulation's side). Errors name the
/// topic and the field.
pub fn read_arm_command(arm: &ArmCommand, msg: &Float64MultiArray, joint_velocities: &mut [f64]) -> Result<(), String> {
    if msg.data.len() != arm.slots.len() {
        return Err(format!(
            "{}: data has {} values, expected {} ({})",
            arm.topic,
            msg.data.len(),
            arm.slots.len(),
            arm.joints.join(", ")
        ));
    }
    if let Some(i) = msg.data.iter().position(|v| !v.is_finite()) {
        return Err(format!("{}: data[{i}] is not finite", arm.topic));
    }
    for (&s, &v) in arm.slots.iter().zip(&msg.data) {
        joint_velocities[s] = v;
    }
    Ok(())
}

/// The base twist `(vx, vy, wz)` (base frame) as a message.
pub fn twist_msg(twist: [f64; 3]) -> Twist {
    let mut t = Twist::default();
    t.linear.x = twist[0];
    t.linear.y = twist[1];
    t.angular.z = twist[2];
    t
}

/// A twist message as `(vx, vy, wz)`; the other components must be 0 (a holonomic planar base),
/// errors name the field.
pub fn twist_of(msg: &Twist) -> Result<[f64; 3], String> {
    let v = [msg.linear.x, msg.linear.y, msg.angular.z];
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(format!("{}: not finite", ["linear.x", "linear.y", "angular.z"][i]));
    }
    Ok(v)
}

/// Fills `msg` from the controller's last cycle: `tasks` are the configured task names, `order`
/// the active arrangement's task indices, `levels` the level diagnostics in that order.
pub fn write_controller_state(
    out: &ControllerOutput,
    tasks: &[String],
    order: &[usize],
    levels: &[LevelDiagnostics],
    stamp: &Time,
    msg: &mut ControllerState,
) {
    msg.header.stamp = stamp.clone();
    msg.mode = out.mode.as_u8();
    msg.blend = out.blend;
    msg.ee_speed = out.signals.ee_speed_mps;
    msg.avoidance_force = out.signals.avoidance_force_n;
    msg.contact_force = out.signals.contact_force_n;
    msg.contact_advance = out.signals.contact_advance_mps;
    msg.torque_norm = out.torque_norm;
    let ge = out.signals.goal_error_m;
    msg.goal_error = if ge.is_nan() { -1.0 } else { ge };
    msg.releasing = out.releasing;
    msg.blocked = blocked_hold_msg(out.blocked);
    msg.goal_count = out.goal_count;
    msg.tasks.resize_with(tasks.len(), TaskState::default);
    for (state, name) in msg.tasks.iter_mut().zip(tasks) {
        if state.name != *name {
            state.name.clone_from(name);
        }
        state.priority = 0;
        state.error_norm = 0.0;
        state.torque_norm = 0.0;
    }
    let mut level = levels.iter();
    for (p, &i) in order.iter().enumerate() {
        let state = &mut msg.tasks[i];
        state.priority = p as u32 + 1;
        if skin_core::tasks::lookup(&tasks[i]).is_some_and(|e| e.role.is_level()) {
            if let Some(d) = level.next() {
                state.torque_norm = d.torque_norm;
                state.error_norm = d.task_error.unwrap_or(0.0);
            }
        }
    }
}

/// The supervisor's input read back from a `ControllerState` (goal error < 0: no goal, NaN).
pub fn supervisor_input(msg: &ControllerState) -> (f64, skin_core::supervisor::SupervisorInput) {
    let ge = if msg.goal_error < 0.0 { f64::NAN } else { msg.goal_error };
    (
        time_s(&msg.header.stamp),
        skin_core::supervisor::SupervisorInput {
            ee_speed_mps: msg.ee_speed,
            avoidance_force_n: msg.avoidance_force,
            contact_force_n: msg.contact_force,
            goal_error_m: ge,
            contact_advance_mps: msg.contact_advance,
        },
    )
}

/// The blocked hold as a message (inactive and zero: not blocked).
pub fn blocked_hold_msg(b: Option<Blocked>) -> BlockedHold {
    b.map_or_else(BlockedHold::default, |b| BlockedHold {
        active: true,
        since: time_msg(b.since_s),
        goal_error: b.goal_error_m,
        contact_force: b.contact_force_n,
    })
}

/// The blocked hold of a message (`None`: inactive). Its values are reported, never decided
/// on, so NaN (a NaN contact force ends a push as over `ε_c`) passes through.
pub fn blocked_of(msg: &BlockedHold) -> Option<Blocked> {
    msg.active.then(|| Blocked {
        since_s: time_s(&msg.since),
        goal_error_m: msg.goal_error,
        contact_force_n: msg.contact_force,
    })
}

/// The message of an arrangement (`tasks`: the configured task names; `blocked`:
/// [`skin_core::supervisor::Supervisor::blocked`]).
pub fn arrangement_msg(a: &Arrangement, tasks: &[String], blocked: Option<Blocked>) -> ArrangementMsg {
    ArrangementMsg {
        mode: a.mode.as_u8(),
        task_order: a.task_names(tasks).map(str::to_string).collect(),
        switch_time: time_msg(a.switch_time_s),
        smoothing_gain: a.smoothing_gain_per_s,
        sensing_range: a.sensing_range_m,
        fusion_weight: a.fusion_weight_target,
        blocked: blocked_hold_msg(blocked),
    }
}

/// An arrangement message as an [`Imposed`] arrangement; `tasks` and `order_of` check that the
/// message's task order is the one this configuration gives its mode (the nodes must share the
/// supervisor configuration). Errors name the field.
pub fn imposed_of(msg: &ArrangementMsg, configured: impl Fn(Mode) -> Vec<String>) -> Result<Imposed, String> {
    let mode =
        Mode::from_u8(msg.mode).ok_or_else(|| format!("mode = {}: not an Arrangement.MODE_* constant", msg.mode))?;
    let expected = configured(mode);
    if msg.task_order != expected {
        return Err(format!(
            "task_order {:?}: this controller's configuration orders mode {} as {:?} (do the nodes share the supervisor file?)",
            msg.task_order, msg.mode, expected
        ));
    }
    for (field, v) in [
        ("smoothing_gain", msg.smoothing_gain),
        ("sensing_range", msg.sensing_range),
        ("fusion_weight", msg.fusion_weight),
    ] {
        if !v.is_finite() {
            return Err(format!("{field} = {v}: not finite"));
        }
    }
    Ok(Imposed {
        mode,
        switch_time_s: time_s(&msg.switch_time),
        sensing_range_m: msg.sensing_range,
        fusion_weight_target: msg.fusion_weight,
        blocked: blocked_of(&msg.blocked),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn arms_split_by_prefix_and_round_trip() {
        let joints = names(&["base_x_joint", "left_a", "left_b", "right_a", "right_b"]);
        let arms =
            split_arms(&joints, &[1, 2, 3, 4], &names(&["/left_arm", "/right_arm/"]), &names(&["left_", "right_"]))
                .unwrap();
        assert_eq!(arms[1].topic, "/right_arm/forward_velocity_controller/commands");
        assert_eq!(arms[1].joints, names(&["right_a", "right_b"]));
        assert_eq!(arms[1].slots, vec![2, 3]);
        let v = [0.1, 0.2, 0.3, 0.4];
        let mut msg = Float64MultiArray::default();
        write_arm_command(&arms[1], &v, &mut msg);
        assert_eq!(msg.data, vec![0.3, 0.4]);
        assert_eq!(msg.layout.dim[0].size, 2);
        let mut back = [0.0; 4];
        read_arm_command(&arms[1], &msg, &mut back).unwrap();
        assert_eq!(back, [0.0, 0.0, 0.3, 0.4]);
        msg.data.pop();
        let e = read_arm_command(&arms[1], &msg, &mut back).unwrap_err();
        assert!(e.contains("data has 1 values, expected 2"), "{e}");
        let e = split_arms(&joints, &[1, 2, 3, 4], &names(&["/left_arm"]), &names(&["left_"])).unwrap_err();
        assert!(e.contains("`right_a` matches no entry"), "{e}");
        let e = split_arms(&joints, &[1], &names(&["/a", "/b"]), &names(&["left_", "right_"])).unwrap_err();
        assert!(e.starts_with("/b/forward_velocity_controller/commands: no arm joint"), "{e}");
        // An empty prefix takes every joint.
        let all = split_arms(&joints, &[1, 3], &names(&["/arm"]), &names(&[""])).unwrap();
        assert_eq!(all[0].slots, vec![0, 1]);
    }

    #[test]
    fn arrangement_round_trip_and_checks() {
        let msg = ArrangementMsg {
            mode: 1,
            task_order: names(&["goal", "contact_reaction", "avoidance"]),
            switch_time: time_msg(2.5),
            smoothing_gain: 10.0,
            sensing_range: 0.05,
            fusion_weight: 0.5,
            blocked: blocked_hold_msg(Some(Blocked { since_s: 2.5, goal_error_m: 0.2, contact_force_n: f64::NAN })),
        };
        let cfg = |m: Mode| {
            if m == Mode::IntentionalContact {
                names(&["goal", "contact_reaction", "avoidance"])
            } else {
                vec![]
            }
        };
        let a = imposed_of(&msg, cfg).unwrap();
        assert_eq!((a.mode, a.switch_time_s, a.sensing_range_m), (Mode::IntentionalContact, 2.5, 0.05));
        let b = a.blocked.expect("blocked: a follower presses nothing");
        assert_eq!((b.since_s, b.goal_error_m), (2.5, 0.2));
        assert!(b.contact_force_n.is_nan());
        assert_eq!(blocked_hold_msg(None), BlockedHold::default());
        assert_eq!(blocked_of(&BlockedHold::default()), None);
        let bad = ArrangementMsg { mode: 9, ..msg.clone() };
        assert_eq!(imposed_of(&bad, cfg).unwrap_err(), "mode = 9: not an Arrangement.MODE_* constant");
        let bad = ArrangementMsg { mode: 0, ..msg };
        assert!(imposed_of(&bad, cfg).unwrap_err().contains("share the supervisor file"));
    }
}
