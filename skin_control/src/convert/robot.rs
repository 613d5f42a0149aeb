//! Robot state in: `sensor_msgs/JointState` (by name, into model order), `nav_msgs/Odometry`
//! (base x, y, yaw and their world-frame rates), `sensor_msgs/LaserScan` (points in the base
//! frame), `geometry_msgs/PoseStamped` goals, `builtin_interfaces/Time` stamps. And the same
//! messages out, for the simulation bridge (one conversion per direction, both here).
//!
//! Conventions (docs/ros.md):
//! - **Joint states** may be partial (TOMM's two arm drivers each publish their own joints on
//!   `/joint_states`, each with its own stamps): every message updates the joints it names, the
//!   others keep their last value. Each joint has its own time: the stamp of the last message
//!   that wrote it. A joint is written only with a finite position (and a finite velocity when
//!   the message has one for it) and a stamp not older than the joint's time (the order is kept
//!   per joint, so two drivers whose stamps differ are both accepted). A name that is not a model
//!   joint, or a base joint (the base comes from odometry), is ignored and counted; a repeated
//!   name uses the first occurrence. A joint with a non-finite value is not written (it keeps its
//!   value and its time, so it ages) and is counted. A message without velocities (allowed by
//!   `JointState`) writes positions and counts the missing velocities; those joints keep their
//!   last velocity (0 until one arrives). The state is complete once every joint has a time.
//! - **Odometry**: pose in the odometry (world) frame, twist in the base frame (`child_frame_id`,
//!   REP 105); the model's base joints are world x, y, yaw, so the twist is rotated by the yaw.
//! - **Scan**: ranges outside `[range_min, range_max]` or non-finite are no return; ray `k` is at
//!   `angle_min + k angle_increment` in the scanner frame, whose pose in the base frame comes
//!   from the model (the scan's `frame_id` must be a model frame on the base body).
use std::fmt;

use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector2, Vector3};
use r2r::builtin_interfaces::msg::Time;
use r2r::geometry_msgs::msg::{Point, Pose, PoseStamped, Quaternion as QuaternionMsg, Twist};
use r2r::nav_msgs::msg::Odometry;
use r2r::sensor_msgs::msg::{JointState, LaserScan};
use skin_core::model::RobotModel;

/// Seconds as a `builtin_interfaces/Time` (rounded to the nanosecond; negative times clamp to 0).
pub fn time_msg(t_s: f64) -> Time {
    let ns = (t_s.max(0.0) * 1e9).round() as u64;
    Time { sec: (ns / 1_000_000_000) as i32, nanosec: (ns % 1_000_000_000) as u32 }
}

/// A `builtin_interfaces/Time` in seconds.
pub fn time_s(t: &Time) -> f64 {
    f64::from(t.sec) + f64::from(t.nanosec) * 1e-9
}

/// A category of bad joint state input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointIssue {
    /// A name that is not a model joint (ignored).
    UnknownJoint,
    /// A base joint name (ignored: the base comes from odometry).
    BaseJoint,
    /// A name repeated within one message (the first occurrence is used).
    DuplicateJoint,
    /// A NaN or infinite position or velocity (not written).
    NonFinite,
    /// `position` shorter than `name` (those joints are not written).
    MissingPosition,
    /// `velocity` shorter than `name` (those joints keep their last velocity).
    MissingVelocity,
    /// A stamp older than the joint's time (a reordered or replayed entry: not written).
    OutOfOrder,
}

impl JointIssue {
    /// Every kind, in counter order.
    pub const ALL: [JointIssue; 7] = [
        JointIssue::UnknownJoint,
        JointIssue::BaseJoint,
        JointIssue::DuplicateJoint,
        JointIssue::NonFinite,
        JointIssue::MissingPosition,
        JointIssue::MissingVelocity,
        JointIssue::OutOfOrder,
    ];

    /// Short name for logs.
    pub fn name(self) -> &'static str {
        match self {
            JointIssue::UnknownJoint => "unknown joint",
            JointIssue::BaseJoint => "base joint in joint states",
            JointIssue::DuplicateJoint => "duplicate joint",
            JointIssue::NonFinite => "non-finite value",
            JointIssue::MissingPosition => "missing position",
            JointIssue::MissingVelocity => "missing velocity",
            JointIssue::OutOfOrder => "joint stamp out of order",
        }
    }

    /// What the conversion did about it.
    pub fn action(self) -> &'static str {
        match self {
            JointIssue::UnknownJoint => "ignored",
            JointIssue::BaseJoint => "ignored, the base comes from odometry",
            JointIssue::DuplicateJoint => "first occurrence used",
            JointIssue::NonFinite => "joint not written, last value kept (it ages)",
            JointIssue::MissingPosition => "not written, last value kept",
            JointIssue::MissingVelocity => "last velocity kept (0 until one arrives)",
            JointIssue::OutOfOrder => "older than the joint's last value: not written",
        }
    }
}

/// One bad entry of a `JointState`, with the place it was found.
#[derive(Debug, Clone, PartialEq)]
pub struct JointStateIssue {
    /// Its category.
    pub kind: JointIssue,
    /// Index in `name`.
    pub index: usize,
    /// The joint name.
    pub joint: String,
    /// The field: `name`, `position` or `velocity`.
    pub field: &'static str,
}

impl fmt::Display for JointStateIssue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}[{}] (joint `{}`): {} ({})",
            self.field,
            self.index,
            self.joint,
            self.kind.name(),
            self.kind.action()
        )
    }
}

/// Counts per [`JointIssue`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct JointIssueCounts([u64; JointIssue::ALL.len()]);

impl JointIssueCounts {
    /// Count of `kind`.
    pub fn get(&self, kind: JointIssue) -> u64 {
        self.0[kind as usize]
    }

    /// Sum over all kinds.
    pub fn total(&self) -> u64 {
        self.0.iter().sum()
    }
}

impl fmt::Display for JointIssueCounts {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (k, kind) in JointIssue::ALL.iter().enumerate() {
            let sep = if k == 0 { "" } else { ", " };
            write!(f, "{sep}{}: {}", kind.name(), self.get(*kind))?;
        }
        Ok(())
    }
}

/// The measured state in model joint order: arm joints from joint states, base joints from
/// odometry; each joint with the time of its last value.
#[derive(Debug, Clone)]
pub struct StateBuffer {
    names: Vec<String>,
    base: Option<[usize; 3]>,
    q: Vec<f64>,
    qd: Vec<f64>,
    /// Stamp \[s\] of each joint's last value (base joints: of the odometry).
    time: Vec<Option<f64>>,
    written_by: Vec<u64>,
    messages: u64,
    issues: JointIssueCounts,
}

impl StateBuffer {
    /// A buffer for `model`'s joints, all zero and unseen.
    pub fn new(model: &RobotModel) -> Self {
        let n = model.nv();
        let base = model.planar_base();
        StateBuffer {
            names: model.joint_names().to_vec(),
            base,
            q: vec![0.0; n],
            qd: vec![0.0; n],
            time: vec![None; n],
            written_by: vec![0; n],
            messages: 0,
            issues: JointIssueCounts::default(),
        }
    }

    /// Joint positions, model order.
    pub fn q(&self) -> &[f64] {
        &self.q
    }

    /// Joint velocities, model order.
    pub fn qd(&self) -> &[f64] {
        &self.qd
    }

    /// Model indices of the base joints (x, y, yaw), when the model has a base.
    pub fn base(&self) -> Option<[usize; 3]> {
        self.base
    }

    /// Issues counted so far.
    pub fn issues(&self) -> &JointIssueCounts {
        &self.issues
    }

    /// Oldest and newest time \[s\] of the joints that are not base joints (None: one has none).
    pub fn joint_times(&self) -> Option<(f64, f64)> {
        let arm = self.time.iter().enumerate().filter(|(j, _)| !self.base.is_some_and(|b| b.contains(j)));
        arm.map(|(_, t)| *t)
            .try_fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), t| t.map(|t| (lo.min(t), hi.max(t))))
    }

    /// The joint (not a base joint) with the oldest value and its time \[s\] (None: one has none).
    pub fn oldest_joint(&self) -> Option<(&str, f64)> {
        let arm = self.time.iter().enumerate().filter(|(j, _)| !self.base.is_some_and(|b| b.contains(j)));
        let mut oldest: Option<(usize, f64)> = None;
        for (j, t) in arm {
            let t = (*t)?;
            if oldest.is_none_or(|(_, o)| t < o) {
                oldest = Some((j, t));
            }
        }
        oldest.map(|(j, t)| (self.names[j].as_str(), t))
    }

    /// Stamp \[s\] of the last odometry message that was used.
    pub fn odom_time(&self) -> Option<f64> {
        self.base.and_then(|b| self.time[b[0]])
    }

    /// Names of the joints that have not had a value yet (empty: the state is complete).
    pub fn missing(&self) -> impl Iterator<Item = &str> + '_ {
        self.names.iter().zip(&self.time).filter(|(_, t)| t.is_none()).map(|(n, _)| n.as_str())
    }

    /// Whether every joint (base included) has a measured position.
    pub fn complete(&self) -> bool {
        self.time.iter().all(Option::is_some)
    }

    /// Writes the joints named in `msg` (rules in the module doc); `report` gets every issue. A
    /// joint time later than `void_after` \[s\] (the clock plus the allowed lead: the clock went
    /// back) does not hold back older stamps. Returns the number of joints written.
    pub fn update_joints(
        &mut self,
        msg: &JointState,
        void_after: f64,
        mut report: impl FnMut(&JointStateIssue),
    ) -> usize {
        self.messages += 1;
        let t = time_s(&msg.header.stamp);
        let mut note = |issues: &mut JointIssueCounts, kind, index, field, joint: &str| {
            issues.0[kind as usize] += 1;
            report(&JointStateIssue { kind, index, joint: joint.to_string(), field });
        };
        let mut written = 0;
        for (i, name) in msg.name.iter().enumerate() {
            let Some(j) = self.names.iter().position(|n| n == name) else {
                note(&mut self.issues, JointIssue::UnknownJoint, i, "name", name);
                continue;
            };
            if self.base.is_some_and(|b| b.contains(&j)) {
                note(&mut self.issues, JointIssue::BaseJoint, i, "name", name);
                continue;
            }
            if self.written_by[j] == self.messages {
                note(&mut self.issues, JointIssue::DuplicateJoint, i, "name", name);
                continue;
            }
            self.written_by[j] = self.messages;
            if self.time[j].is_some_and(|last| t < last && last <= void_after) {
                note(&mut self.issues, JointIssue::OutOfOrder, i, "header.stamp", name);
                continue;
            }
            let p = match msg.position.get(i) {
                None => {
                    note(&mut self.issues, JointIssue::MissingPosition, i, "position", name);
                    continue;
                }
                Some(p) if !p.is_finite() => {
                    note(&mut self.issues, JointIssue::NonFinite, i, "position", name);
                    continue;
                }
                Some(&p) => p,
            };
            match msg.velocity.get(i) {
                None => note(&mut self.issues, JointIssue::MissingVelocity, i, "velocity", name),
                Some(v) if !v.is_finite() => {
                    note(&mut self.issues, JointIssue::NonFinite, i, "velocity", name);
                    continue;
                }
                Some(&v) => self.qd[j] = v,
            }
            self.q[j] = p;
            self.time[j] = Some(t);
            written += 1;
        }
        written
    }

    /// Writes the base joints from odometry. Errors name the field (nothing is written then);
    /// without a base in the model the message is ignored.
    pub fn update_odometry(&mut self, msg: &Odometry) -> Result<(), String> {
        let Some([x, y, yaw]) = self.base else {
            return Ok(());
        };
        let base = odometry_base(msg)?;
        let t = time_s(&msg.header.stamp);
        for (k, j) in [x, y, yaw].into_iter().enumerate() {
            self.q[j] = base.q[k];
            self.qd[j] = base.qd[k];
            self.time[j] = Some(t);
        }
        Ok(())
    }
}

/// The base's joint values from odometry: `q` = (x, y, yaw) in the odometry frame, `qd` their
/// world-frame rates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaseState {
    /// x \[m\], y \[m\], yaw \[rad\].
    pub q: [f64; 3],
    /// ẋ, ẏ \[m/s\] in the world frame, yaw rate \[rad/s\].
    pub qd: [f64; 3],
}

/// Yaw of a quaternion message (rotation about z; a tilt is ignored).
fn yaw_of(q: &QuaternionMsg) -> f64 {
    (2.0 * (q.w * q.z + q.x * q.y)).atan2(1.0 - 2.0 * (q.y * q.y + q.z * q.z))
}

/// Reads [`BaseState`] from `msg` (twist in the base frame, REP 105).
pub fn odometry_base(msg: &Odometry) -> Result<BaseState, String> {
    let p = &msg.pose.pose;
    let o = &p.orientation;
    let t = &msg.twist.twist;
    let fields = [
        ("pose.pose.position.x", p.position.x),
        ("pose.pose.position.y", p.position.y),
        ("pose.pose.orientation.x", o.x),
        ("pose.pose.orientation.y", o.y),
        ("pose.pose.orientation.z", o.z),
        ("pose.pose.orientation.w", o.w),
        ("twist.twist.linear.x", t.linear.x),
        ("twist.twist.linear.y", t.linear.y),
        ("twist.twist.angular.z", t.angular.z),
    ];
    if let Some((field, v)) = fields.iter().find(|(_, v)| !v.is_finite()) {
        return Err(format!("{field} = {v}: not finite"));
    }
    let norm = (o.x * o.x + o.y * o.y + o.z * o.z + o.w * o.w).sqrt();
    if !(0.5..=1.5).contains(&norm) {
        return Err(format!("pose.pose.orientation: norm {norm}, not a unit quaternion"));
    }
    let yaw = yaw_of(o);
    let (s, c) = yaw.sin_cos();
    let (vx, vy) = (t.linear.x, t.linear.y);
    Ok(BaseState { q: [p.position.x, p.position.y, yaw], qd: [c * vx - s * vy, s * vx + c * vy, t.angular.z] })
}

/// Writes the base state into an odometry message (the inverse of [`odometry_base`]): pose in
/// `odom`, twist in `base_frame`.
pub fn write_odometry(base: &BaseState, stamp: &Time, odom_frame: &str, base_frame: &str, msg: &mut Odometry) {
    msg.header.stamp = stamp.clone();
    msg.header.frame_id = odom_frame.to_string();
    msg.child_frame_id = base_frame.to_string();
    let [x, y, yaw] = base.q;
    let (s2, c2) = (yaw / 2.0).sin_cos();
    msg.pose.pose =
        Pose { position: Point { x, y, z: 0.0 }, orientation: QuaternionMsg { x: 0.0, y: 0.0, z: s2, w: c2 } };
    let (s, c) = yaw.sin_cos();
    let [vxw, vyw, wz] = base.qd;
    msg.twist.twist = Twist::default();
    msg.twist.twist.linear.x = c * vxw + s * vyw;
    msg.twist.twist.linear.y = -s * vxw + c * vyw;
    msg.twist.twist.angular.z = wz;
}

/// Writes the named joints' state (positions and velocities picked from model-order vectors).
pub fn write_joint_state(
    names: &[String],
    indices: &[usize],
    q: &[f64],
    qd: &[f64],
    stamp: &Time,
    msg: &mut JointState,
) {
    msg.header.stamp = stamp.clone();
    if msg.name.len() != names.len() {
        msg.name = names.to_vec();
    }
    msg.position.clear();
    msg.position.extend(indices.iter().map(|&j| q[j]));
    msg.velocity.clear();
    msg.velocity.extend(indices.iter().map(|&j| qd[j]));
    msg.effort.clear();
}

/// Converts laser scans to points in the base frame for one model.
#[derive(Debug, Clone)]
pub struct ScanConverter {
    /// (frame name, base-from-scanner pose) of the model frames a scan may come from.
    frames: Vec<(String, Isometry3<f64>)>,
    points: Vec<Vector2<f64>>,
}

impl ScanConverter {
    /// A converter for the frames of `model` that ride on the base (the body of the yaw joint);
    /// a model without a base has none.
    pub fn new(model: &RobotModel) -> Self {
        let mut frames = Vec::new();
        if let Some([_, _, yaw]) = model.planar_base() {
            let base_frame = model.joint_child_frame(yaw);
            let base_inv = model.frame_placement(base_frame).inverse();
            for (f, name) in model.frame_names().iter().enumerate() {
                if model.frame_parent_joint(f) == Some(yaw) {
                    frames.push((name.clone(), base_inv * model.frame_placement(f)));
                }
            }
        }
        ScanConverter { frames, points: Vec::new() }
    }

    /// The points of the last converted scan \[m\], base frame.
    pub fn points(&self) -> &[Vector2<f64>] {
        &self.points
    }

    /// Converts `msg`; errors name the field (the points are then empty: nothing seen).
    pub fn update(&mut self, msg: &LaserScan) -> Result<(), String> {
        self.points.clear();
        let frame = &msg.header.frame_id;
        let Some((_, pose)) = self.frames.iter().find(|(n, _)| n == frame) else {
            return Err(format!("header.frame_id `{frame}` is not a frame on the robot base of the model"));
        };
        for (field, v) in [
            ("angle_min", msg.angle_min),
            ("angle_increment", msg.angle_increment),
            ("range_min", msg.range_min),
            ("range_max", msg.range_max),
        ] {
            if !v.is_finite() {
                return Err(format!("{field} = {v}: not finite"));
            }
        }
        let (lo, hi) = (f64::from(msg.range_min), f64::from(msg.range_max));
        let (a0, da) = (f64::from(msg.angle_min), f64::from(msg.angle_increment));
        for (k, &r) in msg.ranges.iter().enumerate() {
            let r = f64::from(r);
            if !(r.is_finite() && r >= lo && r <= hi) {
                continue;
            }
            let a = a0 + da * k as f64;
            let p = pose * Point3::from(Vector3::new(a.cos(), a.sin(), 0.0) * r);
            self.points.push(Vector2::new(p.x, p.y));
        }
        Ok(())
    }
}

/// The pose of a goal message (position and orientation; a zero quaternion reads as identity).
/// Errors name the field.
pub fn goal_pose(msg: &PoseStamped) -> Result<Isometry3<f64>, String> {
    let p = &msg.pose.position;
    let o = &msg.pose.orientation;
    let all = [
        ("x", p.x),
        ("y", p.y),
        ("z", p.z),
        ("orientation.x", o.x),
        ("orientation.y", o.y),
        ("orientation.z", o.z),
        ("orientation.w", o.w),
    ];
    if let Some((field, v)) = all.iter().find(|(_, v)| !v.is_finite()) {
        let field = if field.starts_with('o') { format!("pose.{field}") } else { format!("pose.position.{field}") };
        return Err(format!("{field} = {v}: not finite"));
    }
    let q = Quaternion::new(o.w, o.x, o.y, o.z);
    let rotation = if q.norm() < 1e-9 { UnitQuaternion::identity() } else { UnitQuaternion::from_quaternion(q) };
    Ok(Isometry3::from_parts(Translation3::new(p.x, p.y, p.z), rotation))
}

/// A goal message for `pose` in `frame`.
pub fn write_goal(pose: &Isometry3<f64>, stamp: &Time, frame: &str) -> PoseStamped {
    let mut msg = PoseStamped::default();
    msg.header.stamp = stamp.clone();
    msg.header.frame_id = frame.to_string();
    let t = pose.translation.vector;
    let r = pose.rotation.coords; // (i, j, k, w)
    msg.pose.position = Point { x: t.x, y: t.y, z: t.z };
    msg.pose.orientation = QuaternionMsg { x: r.x, y: r.y, z: r.z, w: r.w };
    msg
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn tomm() -> RobotModel {
        RobotModel::from_urdf_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../urdf/tomm.urdf")).unwrap()
    }

    #[test]
    fn time_round_trip() {
        let t = time_msg(12.345_678_901);
        assert_eq!((t.sec, t.nanosec), (12, 345_678_901));
        assert!((time_s(&t) - 12.345_678_901).abs() < 1e-12);
        assert_eq!(time_msg(-1.0), Time::default());
    }

    #[test]
    fn joint_states_map_by_name_and_count_issues() {
        let model = tomm();
        let mut buf = StateBuffer::new(&model);
        let mut issues = Vec::new();
        let msg = JointState {
            name: vec![
                "right_elbow_joint".into(),
                "bogus".into(),
                "base_x_joint".into(),
                "right_elbow_joint".into(),
                "left_elbow_joint".into(),
                "right_wrist_1_joint".into(),
            ],
            position: vec![1.0, 2.0, 3.0, 4.0, f64::NAN, 0.5],
            velocity: vec![0.1, 0.0, 0.0, 0.0, 0.2],
            ..Default::default()
        };
        assert_eq!(buf.update_joints(&msg, f64::INFINITY, |i| issues.push(i.clone())), 2);
        let re = model.joint_index("right_elbow_joint").unwrap();
        let le = model.joint_index("left_elbow_joint").unwrap();
        let rw = model.joint_index("right_wrist_1_joint").unwrap();
        assert_eq!((buf.q()[re], buf.qd()[re]), (1.0, 0.1));
        assert_eq!((buf.q()[le], buf.qd()[le]), (0.0, 0.0), "NaN position: the joint is not written at all");
        assert_eq!((buf.q()[rw], buf.qd()[rw]), (0.5, 0.0), "missing velocity keeps 0");
        let c = buf.issues();
        for (kind, n) in [
            (JointIssue::UnknownJoint, 1),
            (JointIssue::BaseJoint, 1),
            (JointIssue::DuplicateJoint, 1),
            (JointIssue::NonFinite, 1),
            (JointIssue::MissingVelocity, 1),
        ] {
            assert_eq!(c.get(kind), n, "{kind:?}");
        }
        assert_eq!(issues[0].to_string(), "name[1] (joint `bogus`): unknown joint (ignored)");
        assert!(!buf.complete());
        assert!(buf.missing().any(|n| n == "base_x_joint"));
        assert!(buf.missing().any(|n| n == "left_elbow_joint"), "a NaN position gives the joint no time");
    }

    /// Two arm drivers, each with its own stamps (one lagging): both are written, each joint
    /// keeps its own time; an older entry, a NaN entry or a message about other joints does not
    /// refresh a joint.
    #[test]
    fn joints_have_their_own_times_and_order() {
        let model = tomm();
        let mut buf = StateBuffer::new(&model);
        let arm = |side: &str, t: f64, v: f64| {
            let name: Vec<String> = model.joint_names().iter().filter(|n| n.starts_with(side)).cloned().collect();
            JointState {
                header: r2r::std_msgs::msg::Header { stamp: time_msg(t), ..Default::default() },
                position: vec![v; name.len()],
                velocity: vec![0.0; name.len()],
                name,
                ..Default::default()
            }
        };
        let mut none = |_: &JointStateIssue| panic!("no issue");
        assert_eq!(buf.update_joints(&arm("left_", 10.0, 0.1), f64::INFINITY, &mut none), 6);
        assert_eq!(
            buf.update_joints(&arm("right_", 9.98, 0.2), f64::INFINITY, &mut none),
            6,
            "the lagging driver is accepted"
        );
        assert_eq!(buf.joint_times().unwrap(), (9.98, 10.0));
        assert_eq!(buf.update_joints(&arm("right_", 9.99, 0.3), f64::INFINITY, &mut none), 6);
        assert_eq!(buf.update_joints(&arm("left_", 10.01, 0.4), f64::INFINITY, &mut none), 6);
        assert_eq!(buf.joint_times().unwrap(), (9.99, 10.01));
        let mut kinds = Vec::new();
        assert_eq!(
            buf.update_joints(&arm("left_", 10.0, 9.0), f64::INFINITY, |i| kinds.push(i.kind)),
            0,
            "older than the left joints"
        );
        assert_eq!(kinds, [JointIssue::OutOfOrder; 6]);
        let le = model.joint_index("left_elbow_joint").unwrap();
        assert_eq!(buf.q()[le], 0.4);
        let mut nan = arm("right_", 10.5, 0.5);
        nan.velocity[2] = f64::NAN;
        assert_eq!(buf.update_joints(&nan, f64::INFINITY, |_| {}), 5, "the NaN joint is not refreshed");
        assert_eq!(buf.joint_times().unwrap(), (9.99, 10.5));
        let right: Vec<&String> = model.joint_names().iter().filter(|n| n.starts_with("right_")).collect();
        assert_eq!(buf.oldest_joint(), Some((right[2].as_str(), 9.99)), "the joint the NaN kept old");
        // the clock went back below the joints' times: an older stamp is written again
        assert_eq!(buf.update_joints(&arm("left_", 5.0, 0.6), 9.0, |_| {}), 6);
        assert_eq!(buf.q()[le], 0.6);
    }

    #[test]
    fn odometry_round_trip_and_errors() {
        let model = tomm();
        let mut buf = StateBuffer::new(&model);
        let base = BaseState { q: [1.0, -2.0, 0.7], qd: [0.3, -0.1, 0.2] };
        let mut msg = Odometry::default();
        write_odometry(&base, &time_msg(1.0), "odom", "base_link", &mut msg);
        let back = odometry_base(&msg).unwrap();
        for k in 0..3 {
            assert!((back.q[k] - base.q[k]).abs() < 1e-12 && (back.qd[k] - base.qd[k]).abs() < 1e-12);
        }
        buf.update_odometry(&msg).unwrap();
        let j = model.joint_index("base_yaw_joint").unwrap();
        assert!((buf.q()[j] - 0.7).abs() < 1e-12);
        msg.twist.twist.linear.y = f64::NAN;
        assert_eq!(odometry_base(&msg).unwrap_err(), "twist.twist.linear.y = NaN: not finite");
        msg.twist.twist.linear.y = 0.0;
        msg.pose.pose.orientation.w = 0.0;
        msg.pose.pose.orientation.z = 0.0;
        assert!(odometry_base(&msg).unwrap_err().contains("not a unit quaternion"));
    }

    #[test]
    fn scan_points_in_the_base_frame() {
        let model = tomm();
        let mut conv = ScanConverter::new(&model);
        let msg = LaserScan {
            header: r2r::std_msgs::msg::Header { frame_id: "laser".into(), ..Default::default() },
            angle_min: 0.0,
            angle_increment: std::f32::consts::FRAC_PI_2,
            range_min: 0.1,
            range_max: 5.0,
            ranges: vec![1.0, f32::INFINITY, 0.05, 2.0],
            ..Default::default()
        };
        conv.update(&msg).unwrap();
        assert_eq!(conv.points().len(), 2);
        let f = model.frame_index("laser").unwrap();
        let yaw = model.joint_index("base_yaw_joint").unwrap();
        let base = model.joint_child_frame(yaw);
        let off = (model.frame_placement(base).inverse() * model.frame_placement(f)).translation.vector;
        assert!((conv.points()[0] - Vector2::new(off.x + 1.0, off.y)).norm() < 1e-6);
        let bad = LaserScan {
            header: r2r::std_msgs::msg::Header { frame_id: "right_hand".into(), ..Default::default() },
            ..msg
        };
        assert!(conv.update(&bad).unwrap_err().contains("`right_hand`"));
    }

    #[test]
    fn goal_round_trip() {
        let pose =
            Isometry3::from_parts(Translation3::new(1.0, 2.0, 3.0), UnitQuaternion::from_euler_angles(0.1, 0.2, 0.3));
        let back = goal_pose(&write_goal(&pose, &Time::default(), "world")).unwrap();
        assert!((back.to_homogeneous() - pose.to_homogeneous()).norm() < 1e-12);
        let mut msg = write_goal(&pose, &Time::default(), "world");
        msg.pose.position.y = f64::INFINITY;
        assert_eq!(goal_pose(&msg).unwrap_err(), "pose.position.y = inf: not finite");
    }
}
