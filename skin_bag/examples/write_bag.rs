//! A bag with one message of every topic type of the skin_control graph, for the rosbags interop
//! test (`test/test_bag_interop.py`, which holds the same values on its side).
//!
//! `write_bag OUT.mcap` writes it; `write_bag --check IN.mcap` reads a bag (e.g. written by
//! rosbags) and exits non-zero unless it holds exactly these messages at these times.

use std::fmt::Debug;

use anyhow::{bail, ensure, Context, Result};
use skin_bag::msgs::*;
use skin_bag::{read_bag, BagMessage, BagWriter, RosMessage};

/// Something done with each sample message: writing it, or checking a bag holds it.
trait Visit {
    fn visit<M: RosMessage + PartialEq + Debug>(&mut self, topic: &str, t_ns: u64, msg: M) -> Result<()>;
}

impl Visit for BagWriter {
    fn visit<M: RosMessage + PartialEq + Debug>(&mut self, topic: &str, t_ns: u64, msg: M) -> Result<()> {
        Ok(self.write(topic, t_ns, &msg)?)
    }
}

/// The messages of a bag, consumed as the samples are visited.
struct Check(Vec<BagMessage>);

impl Visit for Check {
    fn visit<M: RosMessage + PartialEq + Debug>(&mut self, topic: &str, t_ns: u64, want: M) -> Result<()> {
        let i = self.0.iter().position(|m| m.topic == topic).with_context(|| format!("no message on {topic}"))?;
        let found = self.0.remove(i);
        ensure!(found.log_time_ns == t_ns, "{topic}: log time {} ns, expected {t_ns}", found.log_time_ns);
        let got: M = found.decode()?;
        ensure!(got == want, "{topic}:\n got  {got:?}\n want {want:?}");
        println!("ok {topic}");
        Ok(())
    }
}

fn header(sec: i32, frame: &str) -> Header {
    Header { stamp: Time { sec, nanosec: 250_000_000 }, frame_id: frame.into() }
}

fn v3(x: f64, y: f64, z: f64) -> Vector3 {
    Vector3 { x, y, z }
}

/// Every topic, in the order written; times 1..=10 s. Floats of `float32` fields are exact in f32.
fn samples(v: &mut impl Visit) -> Result<()> {
    const S: u64 = 1_000_000_000;
    v.visit("/clock", S, Clock { clock: Time { sec: 1, nanosec: 0 } })?;
    v.visit(
        "/joint_states",
        2 * S,
        JointState {
            header: header(2, ""),
            name: vec!["shoulder_pan".into(), "elbow".into()],
            position: vec![0.1, -1.2],
            velocity: vec![0.01, 0.02],
            effort: vec![],
        },
    )?;
    v.visit(
        "/base/odom",
        3 * S,
        Odometry {
            header: header(3, "odom"),
            child_frame_id: "base_link".into(),
            pose: PoseWithCovariance {
                pose: Pose { position: v3(1.5, -0.5, 0.0), orientation: Quaternion { x: 0.0, y: 0.0, z: 0.6, w: 0.8 } },
                covariance: std::array::from_fn(|i| i as f64 * 0.5),
            },
            twist: TwistWithCovariance {
                twist: Twist { linear: v3(0.2, 0.1, 0.0), angular: v3(0.0, 0.0, 0.3) },
                covariance: std::array::from_fn(|i| if i % 7 == 0 { 0.01 } else { 0.0 }),
            },
        },
    )?;
    v.visit(
        "/scan",
        4 * S,
        LaserScan {
            header: header(4, "base_laser"),
            angle_min: -1.5,
            angle_max: 1.5,
            angle_increment: 0.75,
            time_increment: 0.0,
            scan_time: 0.03125,
            range_min: 0.0625,
            range_max: 10.0,
            ranges: vec![1.0, 2.5, f32::INFINITY, 0.5, 3.25],
            intensities: vec![],
        },
    )?;
    v.visit(
        "/skin/cells",
        5 * S,
        SkinCellArray {
            header: header(5, ""),
            cell_id: vec![7, 1042],
            force: vec![0.25, 0.5, 0.75, 0.0, 0.0, 0.0],
            proximity: vec![0.125, 1.0],
            acceleration: vec![0.0, 0.1, 9.81, 0.0, 0.0, 0.0],
            temperature: vec![31.5, 30.0],
        },
    )?;
    v.visit(
        "/skin/patches",
        6 * S,
        PatchWrenchArray {
            header: header(6, ""),
            patches: vec![PatchWrench {
                header: header(6, "patch_3"),
                patch_id: 3,
                link: "right_forearm_link".into(),
                wrench: Wrench { force: v3(0.0, 0.0, 2.0), torque: v3(0.1, -0.2, 0.0) },
                centroid: v3(0.01, 0.02, 0.0),
                active_cells: 4,
                max_force: 0.5,
                max_proximity: 0.875,
            }],
        },
    )?;
    v.visit(
        "/right_arm/forward_velocity_controller/commands",
        7 * S,
        Float64MultiArray {
            layout: MultiArrayLayout {
                dim: vec![MultiArrayDimension { label: "joints".into(), size: 6, stride: 6 }],
                data_offset: 0,
            },
            data: vec![0.1, -0.2, 0.3, -0.4, 0.5, -0.6],
        },
    )?;
    v.visit("/base/cmd_vel", 8 * S, Twist { linear: v3(0.1, -0.05, 0.0), angular: v3(0.0, 0.0, 0.2) })?;
    v.visit(
        "/supervisor/arrangement",
        9 * S,
        Arrangement {
            mode: 1,
            task_order: vec!["goal".into(), "contact_reaction".into(), "avoidance".into()],
            switch_time: Time { sec: 8, nanosec: 500_000_000 },
            smoothing_gain: 5.0,
            sensing_range: 0.05,
            fusion_weight: 0.75,
            blocked: BlockedHold {
                active: true,
                since: Time { sec: 7, nanosec: 125_000_000 },
                goal_error: 0.25,
                contact_force: 5.5,
            },
        },
    )?;
    v.visit(
        "/controller/state",
        10 * S,
        ControllerState {
            header: header(10, ""),
            mode: 2,
            blend: 0.3,
            ee_speed: 0.012,
            avoidance_force: 1.5,
            contact_force: 12.5,
            contact_advance: 0.004,
            torque_norm: 42.0,
            goal_error: -1.0,
            releasing: true,
            blocked: BlockedHold { active: false, since: Time::default(), goal_error: 0.0, contact_force: 0.0 },
            goal_count: 3,
            tasks: vec![
                TaskState { name: "contact_reaction".into(), priority: 1, error_norm: 2.5, torque_norm: 30.0 },
                TaskState { name: "goal".into(), priority: 2, error_norm: 0.2, torque_norm: 12.0 },
            ],
            input_status: 2,
            safe_stop_cycles: 3,
            idle_periods: 40,
            issue_names: vec!["/skin/cells: unknown cell id".into(), "/scan: message refused".into()],
            issue_counts: vec![5, 0],
        },
    )
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.as_slice() {
        [flag, path] if flag == "--check" => {
            let mut check = Check(read_bag(path)?);
            samples(&mut check)?;
            ensure!(check.0.is_empty(), "{path}: {} unexpected messages", check.0.len());
        }
        [path] => {
            let mut bag = BagWriter::create(path)?;
            samples(&mut bag)?;
            bag.finish()?;
        }
        _ => bail!("usage: write_bag OUT.mcap | write_bag --check IN.mcap"),
    }
    Ok(())
}
