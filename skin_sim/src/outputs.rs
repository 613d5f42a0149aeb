//! The run's picture and bag: `figure.png` in the style of the paper's figures and `run.mcap`, a
//! rosbag2 MCAP of the topics the ROS graph carries during the run (readable by `rosbags`).

use std::path::{Path, PathBuf};

use anyhow::Context;
use skin_core::resolver::BASE_JOINTS;
use skin_core::supervisor::Mode;

use skin_bag::msgs::{
    Arrangement, Clock, ControllerState, Float64MultiArray, Header, JointState, Time, Twist, Vector3,
};
use skin_bag::BagWriter;
use crate::plot::{guidance_figure, intervals_where, paper000_figure, paper003_figure, GuidanceSignals, Paper000Signals, Paper003Signals};
use crate::record::{CycleRecord, RunRecord};
use crate::report::{MetricsJson, RunOutput, RunReport, SummaryText};

/// Every product of a run, as `skin_sim run` writes them: `metrics.json`, `summary.txt`,
/// `figure.png`, `run.mcap`.
pub const ALL: [&dyn RunOutput; 5] = [&MetricsJson, &SummaryText, &FigurePng, &RunBag, &KeyFrames];

/// Rendered key frames: `scene.xml` (the MJCF of the run) and `keyframes.json` (MuJoCo's state at
/// the start, at the first switches and at the end), rendered to `keyframe_<k>_<t>s.png` by
/// `scripts/render_keyframes.py` (MuJoCo's renderer through EGL). Where that is not possible (no
/// EGL, no Python with mujoco, no script beside the binary's sources) `keyframes.txt` says why,
/// and the run goes on.
pub struct KeyFrames;

impl RunOutput for KeyFrames {
    fn write(&self, report: &RunReport, dir: &Path) -> anyhow::Result<PathBuf> {
        let r = &report.record;
        std::fs::write(dir.join("scene.xml"), &r.mjcf).context("writing scene.xml")?;
        let frames = serde_json::to_string(&r.key_frames).context("key frames as JSON")?;
        let json = dir.join("keyframes.json");
        std::fs::write(&json, frames).with_context(|| format!("writing {}", json.display()))?;
        let script = crate::scenario::config_dir().join("../scripts/render_keyframes.py");
        let rendered = std::process::Command::new("python3")
            .arg(&script)
            .arg(dir)
            .output()
            .map_err(|e| format!("python3 {}: {e}", script.display()))
            .and_then(|o| if o.status.success() { Ok(()) } else { Err(String::from_utf8_lossy(&o.stderr).trim().to_string()) });
        match rendered {
            Ok(()) => Ok(json),
            Err(why) => {
                let note = dir.join("keyframes.txt");
                let text = format!("key frames not rendered (the states are in keyframes.json, the scene in scene.xml): {why}\n");
                std::fs::write(&note, text).with_context(|| format!("writing {}", note.display()))?;
                Ok(note)
            }
        }
    }
}

/// `figure.png`: paper 000's panels (arrangement, ee speed, proximity and contact force, torque)
/// for a paper 000 scenario, paper 003's force-tracking panels for a scene of paper 003's phases
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
        let scene = Path::new(&r.scene_file).file_name().map_or_else(|| r.scene_file.clone(), |f| f.to_string_lossy().into_owned());
        let title = format!("{} (seed {}, {})", r.name, r.seed, scene);
        // Paper 003's phases (force tracking or the pre-contact approach) or paper 000's Table I.
        let phases = c.iter().any(|c| matches!(c.mode, Mode::PreContact | Mode::Contact));
        // a phase scene without force references: paper 003 Exp. 2 (its metrics have d_p,d)
        let guidance = report.metrics.contact_free.as_ref().filter(|_| phases);
        let figure = if let Some(g) = guidance {
            let base = |k: usize| r.joint_names.iter().position(|j| j == BASE_JOINTS[k]).map_or_else(|| vec![f64::NAN; c.len()], |j| column(c, |c| c.q[j]));
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
            paper003_figure(
                &title,
                &Paper003Signals {
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
            paper000_figure(
                &title,
                &Paper000Signals {
                    t: &t,
                    arrangement: &arrangement,
                    ee_speed: &column(c, |c| c.signals.ee_speed_mps),
                    eps_v: r.eps_v_mps,
                    avoidance_force: &column(c, |c| c.signals.avoidance_force_n),
                    contact_force: &column(c, |c| c.link_force_n),
                    eps_c: r.eps_c_n,
                    torque_norm: &column(c, |c| c.torque_norm),
                    pushes: &interactions,
                },
            )
        };
        figure.save_png(&path)?;
        Ok(path)
    }
}

/// `run.mcap`: per control cycle `/clock`, `/joint_states`, the arm command topics (one per arm:
/// `/<side>_arm/forward_velocity_controller/commands` for TOMM's `left_`/`right_` joints,
/// `/arm/...` otherwise), `/base/cmd_vel` (a model with a base), `/controller/state`; and
/// `/supervisor/arrangement` at the start and at every switch. The skin cells, odometry and scan
/// are not in the run record, so not in the bag.
pub struct RunBag;

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

fn arrangement_msg(mode: Mode, t_s: f64) -> Arrangement {
    Arrangement { mode: mode.as_u8(), switch_time: Time::from_nanos(nanos(t_s)), ..Default::default() }
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
            bag.write("/supervisor/arrangement", nanos(first.t_s), &arrangement_msg(first.mode, first.t_s))?;
        }
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
                let data = topics.iter().zip(&c.joint_velocities).filter(|(t, _)| *t == topic).map(|(_, v)| *v).collect();
                bag.write(topic, ns, &Float64MultiArray { data, ..Default::default() })?;
            }
            if has_base {
                let [vx, vy, wz] = c.base_twist;
                let twist = Twist { linear: Vector3 { x: vx, y: vy, z: 0.0 }, angular: Vector3 { x: 0.0, y: 0.0, z: wz } };
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
                torque_norm: c.torque_norm,
                goal_error: if s.goal_error_m.is_nan() { -1.0 } else { s.goal_error_m },
                tasks: Vec::new(),
                // in process every cycle runs on fresh inputs, no input is ever bad
                safe_stop_cycles: safe_stops,
                ..Default::default()
            };
            bag.write("/controller/state", ns, &state)?;
            while let Some(sw) = switches.next_if(|sw| sw.t_s <= c.t_s) {
                bag.write("/supervisor/arrangement", ns, &arrangement_msg(sw.to, sw.t_s))?;
            }
        }
        bag.finish().with_context(|| format!("finishing {}", path.display()))?;
        Ok(path)
    }
}
