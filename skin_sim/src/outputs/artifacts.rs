//! The run's picture and bag: `figure.png` in the style of the paper's figures and `run.mcap`, a
//! rosbag2 MCAP of the topics the ROS graph carries during the run (readable by `rosbags`).

use std::path::{Path, PathBuf};

use anyhow::Context;
use skin_core::model::BASE_JOINTS;
use skin_core::supervisor::{Blocked, Mode};

use nalgebra::{Isometry3, Quaternion as NaQuaternion, Translation3, UnitQuaternion};
use skin_core::skin::markers::{MarkerAction, MarkerShape, Rgba, SkinMarker};

use crate::outputs::plot::{
    force_tracking_figure, guidance_figure, intentional_contact_figure, intervals_where, ForceTrackingSignals,
    GuidanceSignals, IntentionalContactSignals,
};
use crate::outputs::record::{CycleRecord, RunRecord};
use crate::outputs::report::{MetricsJson, RunOutput, RunReport, SummaryText};
use crate::outputs::view::{View, ODOM_FRAME};
use crate::world::KeyFrame;
use skin_bag::msgs::{
    Arrangement, BlockedHold, Clock, ColorRgba, ControllerState, Float64MultiArray, Header, JointState, Marker,
    MarkerArray, Point, Quaternion, StringMsg, TfMessage, Time, Transform, TransformStamped, Twist, Vector3,
};
use skin_bag::{full_definition, BagWriter, RosMessage, TRANSIENT_LOCAL_QOS};

/// Every product of a run, as `skin_sim run` writes them: `metrics.json`, `summary.txt`,
/// `figure.png`, `run.mcap`, the rendered key frames.
pub const ALL: [&dyn RunOutput; 5] = [&MetricsJson, &SummaryText, &FigurePng, &RunBag, &KeyFrames { video: false }];

/// Rendered frames: `scene.xml` (the MJCF of the run) and `keyframes.json` (the run's
/// [`View`]: per frame MuJoCo's state, the link poses and the `/skin/markers` updates), rendered
/// by `scripts/render_keyframes.py` (MuJoCo's renderer through EGL) to `keyframe_<k>_<t>s.png`
/// per key frame (the start, the first switches, the end) and, with `video`, to `run.mp4` (or
/// `run.gif` without ffmpeg), with the skin, the contact arrows, the goal and an overlay. Where
/// that is not possible (no EGL, no Python with mujoco, no script beside the binary's sources)
/// `keyframes.txt` says why, and the run goes on.
pub struct KeyFrames {
    /// Also render the video (the script prints its progress on stderr).
    pub video: bool,
}

impl RunOutput for KeyFrames {
    fn write(&self, report: &RunReport, dir: &Path) -> anyhow::Result<PathBuf> {
        let r = &report.record;
        std::fs::write(dir.join("scene.xml"), &r.mjcf).context("writing scene.xml")?;
        let frames = serde_json::to_string(&r.view).context("the view as JSON")?;
        let json = dir.join("keyframes.json");
        std::fs::write(&json, frames).with_context(|| format!("writing {}", json.display()))?;
        let script = crate::scene::config_dir().join("../scripts/render_keyframes.py");
        let mut command = std::process::Command::new("python3");
        command.arg(&script).arg(dir).arg("--title").arg(&r.name);
        if self.video {
            command.arg("--video").stderr(std::process::Stdio::inherit());
        }
        let rendered = command.output().map_err(|e| format!("python3 {}: {e}", script.display())).and_then(|o| {
            if o.status.success() {
                Ok(())
            } else {
                Err(format!("{}: {}", o.status, String::from_utf8_lossy(&o.stderr).trim()))
            }
        });
        match rendered {
            Ok(()) => Ok(json),
            Err(why) => {
                let note = dir.join("keyframes.txt");
                let text = format!(
                    "key frames not rendered (the states are in keyframes.json, the scene in scene.xml): {why}\n"
                );
                std::fs::write(&note, text).with_context(|| format!("writing {}", note.display()))?;
                Ok(note)
            }
        }
    }
}

/// `figure.png`: intentional-contact paper's panels (arrangement, ee speed, proximity and contact force, torque)
/// for an intentional-contact paper scenario, interactive-force-control paper's force-tracking panels for a scene of interactive-force-control paper's phases
/// with force references, its Fig. 6 panels (hand distance, skin moments at the hand, hand and
/// base positions) for one without (Exp. 2).
pub struct FigurePng;

fn column(cycles: &[CycleRecord], f: impl Fn(&CycleRecord) -> f64) -> Vec<f64> {
    cycles.iter().map(f).collect()
}

impl RunOutput for FigurePng {
    fn write(&self, report: &RunReport, dir: &Path) -> anyhow::Result<PathBuf> {
        let path = dir.join("figure.png");
        let r = &report.record;
        let c = &r.cycles;
        let t = column(c, |c| c.t_s);
        let interaction: Vec<bool> = c.iter().map(|c| c.interaction).collect();
        let interactions = intervals_where(&t, &interaction);
        let scene = Path::new(&r.scene_file)
            .file_name()
            .map_or_else(|| r.scene_file.clone(), |f| f.to_string_lossy().into_owned());
        let title = format!("{} (seed {}, {})", r.name, r.seed, scene);
        // Interactive-force-control paper's phases (force tracking or the pre-contact approach) or intentional-contact paper's Table I.
        let phases = c.iter().any(|c| matches!(c.mode, Mode::PreContact | Mode::Contact));
        // a phase scene without force references: interactive-force-control paper Exp. 2 (its metrics have d_p,d)
        let guidance = report.metrics.contact_free.as_ref().filter(|_| phases);
        let figure = if let Some(g) = guidance {
            let base = |k: usize| {
                r.joint_names
                    .iter()
                    .position(|j| j == BASE_JOINTS[k])
                    .map_or_else(|| vec![f64::NAN; c.len()], |j| column(c, |c| c.q[j]))
            };
            let hand = |k: usize| column(c, |c| c.hand_position_m[k]);
            let moment = |k: usize| column(c, |c| c.hand_moment[k]);
            let distance = column(c, |c| if c.hand_distance_m.is_finite() { c.hand_distance_m } else { f64::NAN });
            guidance_figure(
                &title,
                &GuidanceSignals {
                    t: &t,
                    distance: &distance,
                    distance_desired: &vec![g.hand_distance_desired_m; c.len()],
                    moment: [&moment(0), &moment(1), &moment(2)],
                    hand: [&hand(0), &hand(1), &hand(2)],
                    base: [&base(0), &base(1)],
                    interaction: &interactions,
                },
            )
        } else if phases {
            let phase: Vec<usize> = c.iter().map(|c| usize::from(c.mode == Mode::Contact)).collect();
            let base_speed = column(c, |c| c.base_twist[0].hypot(c.base_twist[1]));
            force_tracking_figure(
                &title,
                &ForceTrackingSignals {
                    t: &t,
                    force_desired: &column(c, |c| c.force_reference_n),
                    force_measured: &column(c, |c| c.hand_force_n),
                    phase: &phase,
                    fusion_weight: &column(c, |c| c.fusion_weight),
                    base_speed: &base_speed,
                    tactile: &[],
                    interaction: &interactions,
                },
            )
        } else {
            // Table I's (a), (b), (c) are modes 0, 1, 2
            let arrangement: Vec<usize> = c.iter().map(|c| (c.mode.as_u8() as usize).min(2)).collect();
            let pushes: Vec<(f64, f64)> = r.object_pushes.iter().chain(&interactions).copied().collect();
            intentional_contact_figure(
                &title,
                &IntentionalContactSignals {
                    t: &t,
                    arrangement: &arrangement,
                    ee_speed: &column(c, |c| c.signals.ee_speed_mps),
                    eps_v: r.eps_v_mps,
                    avoidance_force: &column(c, |c| c.signals.avoidance_force_n),
                    contact_force: &column(c, |c| c.link_force_n),
                    eps_c: r.eps_c_n,
                    torque_norm: &column(c, |c| c.torque_norm),
                    pushes: &pushes,
                    blocked: &c.iter().map(|c| c.blocked.is_some()).collect::<Vec<_>>(),
                },
            )
        };
        figure.save_png(&path)?;
        Ok(path)
    }
}

/// `run.mcap`: per control cycle `/clock`, `/joint_states`, the arm command topics (one per arm:
/// `/<side>_arm/forward_velocity_controller/commands` for TOMM's `left_`/`right_` joints,
/// `/arm/...` otherwise), `/base/cmd_vel` (a model with a base), `/controller/state`;
/// `/supervisor/arrangement` at the start and at every switch; `/robot_description` once
/// (transient local, as `robot_state_publisher` offers it); per frame of the run's view `/tf`
/// (`odom -> base_link` and every link from the joint states, [`crate::outputs::view::tf_tree`]) and
/// `/skin/markers` (the aggregator's marker updates). So Foxglove or RViz replaying the file shows
/// the robot, the skin and the contacts. The skin cells, odometry and scan are not in the run
/// record, so not in the bag.
pub struct RunBag;

fn isometry(p: &[f64; 7]) -> Isometry3<f64> {
    let q = UnitQuaternion::from_quaternion(NaQuaternion::new(p[6], p[3], p[4], p[5]));
    Isometry3::from_parts(Translation3::new(p[0], p[1], p[2]), q)
}

/// `/tf` of one view frame: every link in its parent's frame.
fn tf_message(view: &View, frame: &KeyFrame, stamp: Time) -> TfMessage {
    let transforms = view
        .links
        .iter()
        .zip(&view.parents)
        .zip(&frame.poses)
        .map(|((link, parent), pose)| {
            let (parent_frame, relative) = match parent {
                Some(p) => (view.links[*p].as_str(), isometry(&frame.poses[*p]).inv_mul(&isometry(pose))),
                None => (ODOM_FRAME, isometry(pose)),
            };
            let (t, r) = (relative.translation.vector, relative.rotation.coords);
            TransformStamped {
                header: Header { stamp, frame_id: parent_frame.to_string() },
                child_frame_id: link.clone(),
                transform: Transform {
                    translation: Vector3 { x: t.x, y: t.y, z: t.z },
                    rotation: Quaternion { x: r.x, y: r.y, z: r.z, w: r.w },
                },
            }
        })
        .collect();
    TfMessage { transforms }
}

fn color([r, g, b, a]: Rgba) -> ColorRgba {
    ColorRgba { r, g, b, a }
}

/// The `visualization_msgs/Marker` of one skin marker update, as the aggregator publishes it.
fn marker_msg(m: &SkinMarker, stamp: Time) -> Marker {
    let action = match m.action {
        MarkerAction::DeleteAll => return Marker { action: Marker::DELETEALL, ..Default::default() },
        MarkerAction::Delete => Marker::DELETE,
        MarkerAction::Add => Marker::ADD,
    };
    let mut out = Marker {
        header: Header { stamp, frame_id: String::new() },
        ns: m.ns.to_string(),
        id: m.id,
        action,
        ..Default::default()
    };
    if m.action == MarkerAction::Add {
        out.type_ = match m.shape {
            MarkerShape::SphereList => Marker::SPHERE_LIST,
            MarkerShape::Arrow => Marker::ARROW,
        };
        out.header.frame_id.clone_from(&m.frame);
        let [x, y, z] = m.scale;
        out.scale = Vector3 { x, y, z };
        out.color = color(m.color);
        out.points = m.points.iter().map(|&[x, y, z]| Point { x, y, z }).collect();
        out.colors = m.colors.iter().map(|&c| color(c)).collect();
    }
    out
}

/// The command topic of an arm joint, by its name's side prefix.
fn arm_topic(joint: &str) -> &'static str {
    if joint.starts_with("left_") {
        "/left_arm/forward_velocity_controller/commands"
    } else if joint.starts_with("right_") {
        "/right_arm/forward_velocity_controller/commands"
    } else {
        "/arm/forward_velocity_controller/commands"
    }
}

fn nanos(t_s: f64) -> u64 {
    (t_s.max(0.0) * 1e9).round() as u64
}

fn arrangement_msg(c: &CycleRecord, t_s: f64) -> Arrangement {
    Arrangement {
        mode: c.mode.as_u8(),
        switch_time: Time::from_nanos(nanos(t_s)),
        blocked: blocked_hold(c.blocked),
        ..Default::default()
    }
}

fn blocked_hold(b: Option<Blocked>) -> BlockedHold {
    b.map_or_else(BlockedHold::default, |b| BlockedHold {
        active: true,
        since: Time::from_nanos(nanos(b.since_s)),
        goal_error: b.goal_error_m,
        contact_force: b.contact_force_n,
    })
}

fn write_view_frame(bag: &mut BagWriter, view: &View, f: &KeyFrame) -> anyhow::Result<()> {
    let (ns, stamp) = (nanos(f.t_s), Time::from_nanos(nanos(f.t_s)));
    bag.write("/tf", ns, &tf_message(view, f, stamp))?;
    if !f.markers.is_empty() {
        bag.write(
            "/skin/markers",
            ns,
            &MarkerArray { markers: f.markers.iter().map(|m| marker_msg(m, stamp)).collect() },
        )?;
    }
    Ok(())
}

impl RunOutput for RunBag {
    fn write(&self, report: &RunReport, dir: &Path) -> anyhow::Result<PathBuf> {
        let path = dir.join("run.mcap");
        let r: &RunRecord = &report.record;
        let mut bag = BagWriter::create(&path)?;
        let topics: Vec<&str> = r.arm_joints.iter().map(|j| arm_topic(j)).collect();
        let mut distinct = topics.clone();
        distinct.dedup();
        let has_base = r.joint_names.iter().any(|j| j == "base_x_joint");
        if let Some(first) = r.cycles.first() {
            bag.write("/supervisor/arrangement", nanos(first.t_s), &arrangement_msg(first, first.t_s))?;
        }
        let view = &r.view;
        bag.add_topic(
            "/robot_description",
            StringMsg::TYPE_NAME,
            &full_definition(StringMsg::TYPE_NAME).map_err(anyhow::Error::msg)?,
            TRANSIENT_LOCAL_QOS,
        )?;
        bag.write("/robot_description", 0, &StringMsg { data: view.robot_description.clone() })?;
        let mut frames = view.frames.iter().peekable();
        let mut switches = r.switches.iter().peekable();
        let mut safe_stops = 0;
        for c in &r.cycles {
            safe_stops += u64::from(c.fault.is_some());
            let ns = nanos(c.t_s);
            let header = Header { stamp: Time::from_nanos(ns), frame_id: String::new() };
            bag.write("/clock", ns, &Clock { clock: header.stamp })?;
            let joints = JointState {
                header: header.clone(),
                name: r.joint_names.clone(),
                position: c.q.clone(),
                velocity: c.qd.clone(),
                effort: Vec::new(),
            };
            bag.write("/joint_states", ns, &joints)?;
            for topic in &distinct {
                let data =
                    topics.iter().zip(&c.joint_velocities).filter(|(t, _)| *t == topic).map(|(_, v)| *v).collect();
                bag.write(topic, ns, &Float64MultiArray { data, ..Default::default() })?;
            }
            if has_base {
                let [vx, vy, wz] = c.base_twist;
                let twist =
                    Twist { linear: Vector3 { x: vx, y: vy, z: 0.0 }, angular: Vector3 { x: 0.0, y: 0.0, z: wz } };
                bag.write("/base/cmd_vel", ns, &twist)?;
            }
            let s = &c.signals;
            let state = ControllerState {
                header,
                mode: c.mode.as_u8(),
                blend: c.blend,
                ee_speed: s.ee_speed_mps,
                avoidance_force: s.avoidance_force_n,
                contact_force: s.contact_force_n,
                contact_advance: s.contact_advance_mps,
                torque_norm: c.torque_norm,
                goal_error: if s.goal_error_m.is_nan() { -1.0 } else { s.goal_error_m },
                releasing: c.releasing,
                blocked: blocked_hold(c.blocked),
                tasks: Vec::new(), // and goal_count 0: the record keeps neither
                // in process every cycle runs on fresh inputs, no input is ever bad
                safe_stop_cycles: safe_stops,
                ..Default::default()
            };
            bag.write("/controller/state", ns, &state)?;
            while let Some(sw) = switches.next_if(|sw| sw.t_s <= c.t_s) {
                bag.write("/supervisor/arrangement", ns, &arrangement_msg(c, sw.t_s))?;
            }
            while let Some(f) = frames.next_if(|f| f.t_s <= c.t_s) {
                write_view_frame(&mut bag, view, f)?;
            }
        }
        // the end frame, after the last cycle
        for f in frames {
            write_view_frame(&mut bag, view, f)?;
        }
        bag.finish().with_context(|| format!("finishing {}", path.display()))?;
        Ok(path)
    }
}
