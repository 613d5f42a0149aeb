use std::path::PathBuf;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use super::*;
use crate::controller::ControllerConfig;
use crate::skin::signals::CellReading;
use crate::supervisor::Mode;

fn setup(robot: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../config/controller/{robot}.yaml"))
}

fn controller(robot: &str) -> Controller {
    Controller::from_setup_file(&setup(robot), 0.0).unwrap()
}

/// Writes a modified copy of a shipped setup next to it (so its relative paths still resolve).
fn setup_error(robot: &str, from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(setup(robot)).unwrap().replace(from, to);
    assert!(text.contains(to));
    let path = setup(robot).with_file_name(format!(".test_{robot}_{}.yaml", std::process::id()));
    std::fs::write(&path, text).unwrap();
    let err = Controller::from_setup_file(&path, 0.0).unwrap_err().to_string();
    std::fs::remove_file(&path).unwrap();
    err
}

/// Moves the state as a perfect velocity-controlled robot would: q̇ = command, q += q̇ dt.
fn follow(c: &Controller, q: &mut [f64], qd: &mut [f64], dt: f64) {
    let cmd = &c.output().commands;
    for (&j, &v) in c.resolver().arm_joints().iter().zip(&cmd.joint_velocities) {
        qd[j] = v;
        q[j] += v * dt;
    }
}

#[test]
fn shipped_setups_load_and_run_a_quiet_cycle() {
    for robot in ["tomm", "planar7"] {
        let mut c = controller(robot);
        let nv = c.config().model.nv();
        let q = if c.config().setup.posture.is_empty() { vec![0.0; nv] } else { c.config().setup.posture.clone() };
        let cells = vec![CellReading::default(); c.config().layout.num_cells()];
        let out =
            c.update(&ControllerInput { t_s: 0.0, dt_s: 0.008, q: &q, qd: &vec![0.0; nv], cells: &cells, scan: &[] });
        assert_eq!(out.fault, None, "{robot}");
        assert_eq!(out.mode, Mode::Avoidance, "{robot}");
        assert!(out.signals.goal_error_m.is_nan(), "no goal: NaN goal error");
        assert!(
            out.commands.joint_velocities.iter().all(|v| v.abs() < 1e-6),
            "{robot}: at rest without tasks: {:?}",
            out.commands
        );
    }
}

#[test]
fn planar7_reaches_its_goal_through_the_whole_chain() {
    let mut c = controller("planar7");
    let mut q = c.config().setup.posture.clone();
    let mut qd = vec![0.0; 7];
    let cells = vec![CellReading::default(); c.config().layout.num_cells()];
    let goal = Vector3::new(0.9, 0.8, 0.0);
    c.set_goal(Some(Isometry3::from_parts(Translation3::from(goal), UnitQuaternion::identity()))).unwrap();
    let dt = 0.008;
    let mut first_error = None;
    for k in 0..1500 {
        let out = c.update(&ControllerInput { t_s: k as f64 * dt, dt_s: dt, q: &q, qd: &qd, cells: &cells, scan: &[] });
        assert_eq!(out.fault, None);
        first_error.get_or_insert(out.signals.goal_error_m);
        follow(&c, &mut q, &mut qd, dt);
    }
    let e = c.output().signals.goal_error_m;
    assert!(first_error.unwrap() > 0.3, "the goal starts far away");
    assert!(e < 0.01, "goal error after 12 s: {e} m");
}

#[test]
fn bad_inputs_make_safe_stop_steps() {
    let mut c = controller("planar7");
    let q = c.config().setup.posture.clone();
    let cells = vec![CellReading::default(); c.config().layout.num_cells()];
    c.set_goal(Some(Isometry3::translation(0.0, 1.2, 0.0))).unwrap();
    let mut qd = vec![0.0; 7];
    let dt = 0.008;
    for k in 0..50 {
        c.update(&ControllerInput { t_s: k as f64 * dt, dt_s: dt, q: &q, qd: &qd, cells: &cells, scan: &[] });
    }
    let moving: f64 = c.output().commands.joint_velocities.iter().map(|v| v.abs()).sum();
    assert!(moving > 0.05, "moving toward the goal");
    qd[3] = f64::NAN;
    let inputs = [
        (
            Fault::NonFinite { input: "qd", index: 3 },
            ControllerInput { t_s: 1.0, dt_s: dt, q: &q, qd: &qd, cells: &cells, scan: &[] },
        ),
        (
            Fault::Length { input: "q", expected: 7, got: 6 },
            ControllerInput { t_s: 1.0, dt_s: dt, q: &q[..6], qd: &q, cells: &cells, scan: &[] },
        ),
        (
            Fault::Length { input: "cells", expected: cells.len(), got: 3 },
            ControllerInput { t_s: 1.0, dt_s: dt, q: &q, qd: &q, cells: &cells[..3], scan: &[] },
        ),
        (Fault::BadTimeStep, ControllerInput { t_s: 1.0, dt_s: 0.0, q: &q, qd: &q, cells: &cells, scan: &[] }),
    ];
    for (fault, input) in &inputs {
        let before: Vec<f64> = c.output().commands.joint_velocities.clone();
        let out = c.update(input);
        assert_eq!(out.fault, Some(*fault));
        for (a, b) in before.iter().zip(&out.commands.joint_velocities) {
            assert!(b.abs() <= a.abs() + 1e-12, "a safe-stop step never speeds up: {a} -> {b}");
        }
    }
    assert!(c.set_goal(Some(Isometry3::translation(f64::NAN, 0.0, 0.0))).is_err());
    assert!(c.set_hand_force_reference(f64::NAN).is_err());
    // Only a changed goal counts as new (a priority supervisor elsewhere ends its blocked hold on it).
    assert_eq!(c.output().goal_count, 1, "the goal set once; the refused one does not count");
    c.set_goal(Some(Isometry3::translation(0.0, 1.2, 0.0))).unwrap();
    assert_eq!(c.output().goal_count, 1, "the same goal again");
    c.set_goal(None).unwrap();
    assert_eq!(c.output().goal_count, 2);
}

#[test]
fn setup_errors_name_file_and_key() {
    let e = setup_error("tomm", "end_effector: right_hand", "end_effector: right_hnad");
    assert!(e.contains("end_effector") && e.contains("right_hnad") && e.contains(".yaml"), "{e}");
    let e = setup_error("tomm", "hand_patches: [12]", "hand_patches: [99]");
    assert!(e.contains("hand_patches[0]") && e.contains("99"), "{e}");
    let e = setup_error("planar7", "posture: [0.6, -0.5,", "posture: [");
    assert!(e.contains("posture") && e.contains("5 values"), "{e}");
    let e = setup_error("planar7", "damping: 1.0e-3", "damping: -1.0");
    assert!(e.contains("inverse.") && e.contains("damping"), "{e}");
    let e =
        setup_error("tomm", "hand_patches: [12]", "hand_patches: [12]\nlocked_joints: [base_x_joint, base_z_joint]");
    assert!(e.contains("locked_joints[1]") && e.contains("base_z_joint"), "{e}");
    let e = setup_error("tomm", "end_effector:", "end_efector:");
    assert!(e.contains("end_efector"), "unknown keys are errors: {e}");
}

#[test]
fn a_setup_without_urdf_takes_the_callers_model() {
    let text = std::fs::read_to_string(setup("planar7")).unwrap();
    let urdf_line = text.lines().find(|l| l.starts_with("urdf:")).unwrap();
    let path = setup("planar7").with_file_name(format!(".test_no_urdf_{}.yaml", std::process::id()));
    std::fs::write(&path, text.replace(urdf_line, "")).unwrap();
    let e = ControllerConfig::load(&path).unwrap_err().to_string();
    let urdf = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../urdf/planar7.urdf");
    let model = crate::model::RobotModel::from_urdf_str(&std::fs::read_to_string(urdf).unwrap(), "given").unwrap();
    let given = ControllerConfig::load_with_model(&path, Some(model.clone()));
    // a setup that names a URDF: the caller's model wins
    let both = ControllerConfig::load_with_model(&setup("planar7"), Some(model)).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert!(e.contains("`urdf`") && e.contains("not given"), "{e}");
    assert_eq!(given.unwrap().model.nv(), 7);
    assert_eq!(both.model.source(), "given");
}

#[test]
fn a_derived_setup_is_its_base_with_its_keys_replaced() {
    let (phases, _) = ControllerSetup::load(&setup("tomm_phases")).unwrap();
    let (tomm, _) = ControllerSetup::load(&setup("tomm")).unwrap();
    // a file two bases down (in another directory: the bases' relative paths must follow)
    let dir = std::env::temp_dir().join(format!("skin_core_setup_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let derived = dir.join("derived.yaml");
    let posture: Vec<String> = (0..15).map(|j| format!("{}", 0.01 * j as f64)).collect();
    let text = format!("base: {}\nposture: [{}]\n", setup("tomm_phases").display(), posture.join(", "));
    std::fs::write(&derived, text).unwrap();
    let (table, _) = ControllerSetup::load(&derived).unwrap();
    // what the derived file sets differs; everything else comes through two bases (the file
    // paths rebased to the derived file's directory)
    assert_ne!(table.posture, phases.posture);
    let rebased = ControllerSetup {
        urdf: table.urdf.clone(),
        skin_layout: table.skin_layout.clone(),
        skin_model: table.skin_model.clone(),
        tasks: table.tasks.clone(),
        supervisor: table.supervisor.clone(),
        resolver: table.resolver.clone(),
        ..phases.clone()
    };
    assert_eq!(ControllerSetup { posture: phases.posture.clone(), ..table.clone() }, rebased);
    assert_eq!(phases.policy, Some(crate::supervisor::Policy::Phases));
    let resolver = tomm.resolver.clone();
    assert_eq!(
        ControllerSetup {
            posture: tomm.posture.clone(),
            policy: None,
            hierarchy_dynamics: tomm.hierarchy_dynamics,
            resolver,
            ..phases
        },
        tomm
    );
    Controller::from_setup_file(&derived, 0.0).expect("the bases' relative paths resolve");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn derived_setup_errors_name_the_file_and_key() {
    let e = setup_error("tomm_phases", "policy: phases", "policy: phasse");
    assert!(e.contains(".test_tomm_phases") && e.contains("`policy`") && e.contains("phasse"), "{e}");
    let e = setup_error("tomm_phases", "policy: phases", "policy: phases\nend_efector: x");
    assert!(e.contains("`end_efector`"), "unknown keys are errors: {e}");
    let e = setup_error("tomm_phases", "base: tomm.yaml", "base: tomm_missing.yaml");
    assert!(e.contains("tomm_missing.yaml"), "{e}");
    let e = setup_error("tomm_phases", "policy: phases", "policy: phases\nend_effector: right_hnad");
    assert!(e.contains("end_effector") && e.contains("right_hnad"), "checks after the merge: {e}");
}

#[test]
fn every_registered_task_is_found_by_its_own_name() {
    for entry in crate::tasks::REGISTRY.iter() {
        assert_eq!(crate::tasks::lookup(entry.name).map(|e| e.name), Some(entry.name), "names are unique");
    }
    assert!(crate::tasks::lookup("levitate").is_none());
    let role = |name| crate::tasks::lookup(name).unwrap().role;
    assert!(!role("posture").is_level() && !role("compliance").is_level() && role("goal").is_level());
}

#[test]
fn locked_base_stays_still_while_the_arm_reaches() {
    let mut config = ControllerConfig::load(&setup("tomm")).unwrap();
    config.setup.locked_joints = ["base_x_joint", "base_y_joint", "base_yaw_joint"].map(String::from).to_vec();
    let mut c = Controller::new(config, 0.0).unwrap();
    let mut q = c.config().setup.posture.clone();
    let mut qd = vec![0.0; q.len()];
    let cells = vec![CellReading::default(); c.config().layout.num_cells()];
    let hand = c.config().model.frame_index("right_hand").unwrap();
    let mut data = crate::model::ModelData::new(&c.config().model);
    crate::model::update_kinematics(&c.config().model, &mut data, &q, &qd).unwrap();
    let goal = data.frame_pose(hand).translation.vector + Vector3::new(0.1, -0.1, 0.05);
    c.set_goal(Some(Isometry3::from_parts(Translation3::from(goal), UnitQuaternion::identity()))).unwrap();
    let dt = 0.008;
    for k in 0..1000 {
        let out = c.update(&ControllerInput { t_s: k as f64 * dt, dt_s: dt, q: &q, qd: &qd, cells: &cells, scan: &[] });
        assert_eq!(out.fault, None);
        assert_eq!(out.commands.base_twist, [0.0; 3], "cycle {k}: the locked base gets a zero command");
        assert!(c.torque().rows(0, 3).iter().all(|&t| t == 0.0));
        follow(&c, &mut q, &mut qd, dt);
    }
    let e = c.output().signals.goal_error_m;
    assert!(e < 0.005, "the arm alone reaches the goal in 8 s: error {e} m");
}

#[test]
fn a_base_reference_is_validated_and_cleared() {
    let mut c = controller("tomm");
    let ok = BaseReference { position: [0.1, -0.2, 0.3], velocity: [0.05, 0.0, 0.0] };
    c.set_base_reference(Some(ok)).unwrap();
    assert_eq!(c.base_reference(), Some(ok));
    let bad = BaseReference { velocity: [0.0, f64::NAN, 0.0], ..ok };
    assert_eq!(c.set_base_reference(Some(bad)), Err(Fault::NonFinite { input: "base reference", index: 4 }));
    assert_eq!(c.base_reference(), Some(ok), "a refused reference leaves the last one");
    c.set_base_reference(None).unwrap();
    assert_eq!(c.base_reference(), None);
    let mut arm = controller("planar7");
    assert!(arm.set_base_reference(Some(ok)).is_err(), "no base joints");
    arm.set_base_reference(None).unwrap();
}

#[test]
fn hand_moment_is_the_palm_patch_moment_in_the_hand_frame() {
    let mut c = controller("tomm");
    let nv = c.config().model.nv();
    let q = c.config().setup.posture.clone();
    let layout = &c.config().layout;
    let (palm, patch) = layout.patches().iter().enumerate().find(|(_, p)| p.id == 12).unwrap();
    let mut cells = vec![CellReading::default(); layout.num_cells()];
    // one off-centre cell of the palm: a moment about the patch origin
    cells[patch.cells.start] = CellReading::uniform(0.5, 1.0);
    let out = c
        .update(&ControllerInput { t_s: 0.0, dt_s: 0.008, q: &q, qd: &vec![0.0; nv], cells: &cells, scan: &[] })
        .clone();
    let patch_moment = c.patch_wrenches()[palm].moment;
    assert!(patch_moment.norm() > 1e-4, "an off-centre cell gives a moment: {patch_moment}");
    // one patch: the same moment, rotated from the patch into the hand frame
    assert!((out.hand_moment.norm() - patch_moment.norm()).abs() < 1e-12, "{} vs {patch_moment}", out.hand_moment);
    let cells = vec![CellReading::default(); c.config().layout.num_cells()];
    let out =
        c.update(&ControllerInput { t_s: 0.008, dt_s: 0.008, q: &q, qd: &vec![0.0; nv], cells: &cells, scan: &[] });
    assert_eq!(out.hand_moment, Vector3::zeros(), "no touch, no moment");
}

/// One wrong velocity reading at start (every joint at its limit, the base at 0.5 m/s) must not
/// become the first command: commands start from zero, the last command sent, within the
/// acceleration limits.
#[test]
fn the_first_command_starts_from_zero_whatever_the_measured_velocity() {
    let mut c = controller("tomm");
    let nv = c.config().model.nv();
    let q = c.config().setup.posture.clone();
    let mut qd = vec![std::f64::consts::FRAC_PI_2; nv];
    let [bx, by, _] = c.resolver().base_joints().unwrap();
    (qd[bx], qd[by]) = (0.5, 0.0);
    let cells = vec![CellReading::default(); c.config().layout.num_cells()];
    let dt = 0.008;
    let out = c.update(&ControllerInput { t_s: 0.0, dt_s: dt, q: &q, qd: &qd, cells: &cells, scan: &[] }).clone();
    assert_eq!(out.fault, None);
    let amax: Vec<f64> = c.resolver().arm_acceleration_limits().collect();
    for (v, a) in out.commands.joint_velocities.iter().zip(&amax) {
        assert!(v.abs() <= a * dt * (1.0 + 1e-12), "{v} from a measured {}", qd[0]);
    }
    let b = &c.config().resolver.base;
    let [vx, vy, wz] = out.commands.base_twist;
    assert!(vx.hypot(vy) <= b.max_linear_accel_m_s2 * dt * (1.0 + 1e-12), "{vx} {vy}");
    assert!(wz.abs() <= b.max_angular_accel_rad_s2 * dt * (1.0 + 1e-12));
}

/// Stage timing: off by default; on, every stage of a cycle is charged, the shares add up to 1,
/// and the commands are the same as without timing.
#[test]
fn stage_timing_charges_every_stage_without_changing_the_commands() {
    let (mut timed, mut plain) = (controller("tomm"), controller("tomm"));
    assert!(timed.stage_times().is_none());
    timed.set_stage_timing(true);
    let q = timed.config().setup.posture.clone();
    let nv = q.len();
    let mut cells = vec![CellReading::default(); timed.config().layout.num_cells()];
    cells[3] = CellReading::uniform(0.2, 0.8);
    for k in 0..3 {
        let input = ControllerInput {
            t_s: 0.008 * k as f64,
            dt_s: 0.008,
            q: &q,
            qd: &vec![0.01; nv],
            cells: &cells,
            scan: &[],
        };
        let a = timed.update(&input).commands.joint_velocities.clone();
        assert_eq!(a, plain.update(&input).commands.joint_velocities);
    }
    let times = *timed.stage_times().unwrap();
    assert_eq!(times.cycles(), 3);
    for s in Stage::ALL {
        assert!(times.total_ns(s) > 0, "{} not charged", s.name());
    }
    let sum: f64 = Stage::ALL.iter().map(|&s| times.share(s)).sum();
    assert!((sum - 1.0).abs() < 1e-12, "{sum}");
    timed.set_stage_timing(false);
    assert!(timed.stage_times().is_none());
}

/// Largest closing speed `nᵀ v(p)` over the cells, and its excess over the approach bound at
/// the sensed distance `d` (positive: too fast), at the state `q`, `qd`.
fn closing_speeds(c: &Controller, q: &[f64], qd: &[f64], d: f64, touch_mps: f64) -> (f64, f64) {
    let model = &c.config().model;
    let mut data = crate::model::ModelData::new(model);
    crate::model::update_kinematics(model, &mut data, q, qd).unwrap();
    let approach = c.config().resolver.approach;
    let mut worst = (0.0f64, f64::NEG_INFINITY);
    for cell in c.config().layout.cells() {
        let v = crate::model::point_velocity(model, &data, cell.frame, &cell.position_link).unwrap();
        let closing = (data.frame_pose(cell.frame).rotation * cell.normal_link).dot(&v);
        worst.0 = worst.0.max(closing);
        worst.1 = worst.1.max(closing - (touch_mps + d / approach.time_s));
    }
    worst
}

/// Drives planar7 toward a far goal for 2 s while every cell senses a surface 1 cm away (every
/// direction of motion closes on one): per cycle, the fastest closing speed and the largest
/// excess over the bound.
fn drive_among_surfaces(mut c: Controller) -> Vec<(f64, f64)> {
    let (d, dt) = (0.01, 0.008);
    let signal = c.config().skin.proximity.signal(d);
    let cells = vec![CellReading::uniform(0.0, signal); c.config().layout.num_cells()];
    let mut q = c.config().setup.posture.clone();
    let mut qd = vec![0.0; 7];
    c.set_goal(Some(Isometry3::from_parts(Translation3::new(0.9, 0.8, 0.0), UnitQuaternion::identity()))).unwrap();
    let touch = c.config().resolver.approach.speed_min_mps;
    (0..250)
        .map(|k| {
            let out =
                c.update(&ControllerInput { t_s: k as f64 * dt, dt_s: dt, q: &q, qd: &qd, cells: &cells, scan: &[] });
            assert_eq!(out.fault, None);
            follow(&c, &mut q, &mut qd, dt);
            closing_speeds(&c, &q, &qd, d, touch)
        })
        .collect()
}

#[test]
fn no_skin_point_closes_on_a_sensed_surface_faster_than_the_approach_bound() {
    let max = |v: &[(f64, f64)], f: fn(&(f64, f64)) -> f64| v.iter().map(f).fold(f64::NEG_INFINITY, f64::max);
    let shipped = ControllerConfig::load(&setup("planar7")).unwrap();
    let touch = shipped.resolver.approach.speed_min_mps;
    // the bound itself, without the per-joint acceleration limit that follows it
    let mut free = shipped.clone();
    free.resolver.arm.max_acceleration = 1e3;
    let bounded = drive_among_surfaces(Controller::new(free.clone(), 0.0).unwrap());
    assert!(max(&bounded, |c| c.0) > 0.5 * touch, "the arm moves toward the surfaces");
    assert!(max(&bounded, |c| c.1) < 1e-3, "a cell closed {} m/s faster than its bound", max(&bounded, |c| c.1));
    free.resolver.approach.enabled = false;
    let unbounded = max(&drive_among_surfaces(Controller::new(free, 0.0).unwrap()), |c| c.1);
    assert!(unbounded > 0.01, "without the bound the goal closes faster: {unbounded} m/s over");
    // shipped limits: the per-joint rate limit of the start (docs/resolver.md) is the one exception
    let runs = drive_among_surfaces(Controller::new(shipped, 0.0).unwrap());
    assert!(max(&runs[10..], |c| c.1) < 1e-3, "after the start: {} m/s over", max(&runs[10..], |c| c.1));
}

/// The speed at contact of a link's cells (the limit at `d = 0`) in a push (b), regulated by the
/// link's force `F = ‖Σ F_i n_i‖` about its push force `F_p = ε_c − push_margin_n`: from the
/// touch speed, growing by the push acceleration while `F` is far under `F_p` and by the gain
/// times `F_p − F` near it, up to the fastest push; over `F_p` at once the touch speed, falling
/// by the gain times the excess down to 0 (a push that does not give way holds `F_p`), unless
/// the excess is a stick-slip peak (over `F_p` for at most `push_peak_s`, under `ε_c`), which
/// only slows the push by the gain; the link's
/// force, not its hardest cell; falling back by the acceleration out of contact; the touch speed
/// in any other arrangement; 0 for a cell at `ε_c` and when the contact is to be released.
#[test]
fn a_push_regulates_its_links_force_under_eps_c() {
    use super::approach::{ApproachBound, ContactIntent, ContactLevels};
    use super::press::Press;
    use crate::skin::live::LiveCells;
    let config = ControllerConfig::load(&setup("planar7")).unwrap();
    let (model, layout, skin) = (&config.model, &config.layout, &config.skin);
    let (p, th) = (config.resolver.approach, config.supervisor.thresholds);
    let levels = ContactLevels::of(&th);
    let push_n = levels.push_n;
    assert!(push_n < th.contact_force_n && push_n > th.contact_zero_n, "{push_n}");
    let cells = layout.num_cells();
    let mut bound = ApproachBound::new(p, levels, model.nv(), model.nframes(), layout);
    let mut press = Press::new(skin.force.prepared(), layout, model.nframes());
    let mut limits = bound.limits();
    let mut data = crate::model::ModelData::new(model);
    crate::model::update_kinematics(model, &mut data, &config.setup.posture, &vec![0.0; model.nv()]).unwrap();
    let pressed = 0;
    let cell = |i: usize| &layout.cells()[i];
    let frame = cell(pressed).frame;
    // the cell of the same link facing most nearly the same way: two cells of one contact
    let beside = (1..cells)
        .filter(|&i| cell(i).frame == frame)
        .max_by(|&i, &j| {
            let d = |k: usize| cell(k).normal_link.dot(&cell(pressed).normal_link);
            d(i).total_cmp(&d(j))
        })
        .unwrap();
    let elsewhere = (0..cells).find(|&i| cell(i).frame != frame).unwrap();
    let dt = 0.01;
    // every cell touches a surface (d = 0), the first one pressed with `force_n` and the one
    // beside it with `beside_n`: the speeds at contact of these two and of a cell of another link
    let mut step2 = |force_n: f64, beside_n: f64, intent: ContactIntent| {
        let readings: Vec<CellReading> = (0..cells)
            .map(|i| {
                let f = [(pressed, force_n), (beside, beside_n)].iter().find(|(c, _)| *c == i).map_or(0.0, |x| x.1);
                CellReading::uniform(if f > 0.0 { skin.force.signal(f) } else { 0.0 }, 1.0)
            })
            .collect();
        let live = LiveCells::from_readings(&readings, &skin.proximity);
        press.update(layout, &live, &skin.fusion);
        bound.update(model, &data, layout, &live, &press, intent, dt, &mut limits).unwrap();
        let speeds: Vec<f64> = limits.iter().map(|(_, b)| b).collect();
        assert_eq!(speeds.len(), cells, "every touching cell has a limit");
        (speeds[pressed], speeds[beside], speeds[elsewhere])
    };
    let (touch, fastest, a, k) =
        (p.speed_min_mps, p.push_speed_max_mps, p.push_accel_mps2, p.push_force_gain_mps2_per_n);
    let far = push_n - 2.0 * a / k; // the rise is the acceleration's
    assert!(far > th.contact_zero_n && touch + 10.0 * a * dt < fastest, "the ramp is seen before it saturates");
    let close = |x: f64, y: f64| (x - y).abs() < 1e-9;
    let mut v = touch;
    for n in 1..=10 {
        let got = step2(far, 0.0, ContactIntent::Push);
        v += a * dt;
        assert!(close(got.0, v) && close(got.1, v), "step {n}: {got:?}, expected {v}");
        assert_eq!(got.2, touch, "another link touches");
    }
    let near = push_n - 0.5 * a / k; // the rise is the gain's: half the acceleration
    v += 0.5 * a * dt;
    assert!(close(step2(near, 0.0, ContactIntent::Push).0, v), "near the push force: slower");
    for _ in 0..((fastest / (a * dt)) as usize) {
        v = step2(far, 0.0, ContactIntent::Push).0;
    }
    assert_eq!(v, fastest, "the fastest push");
    assert!(close(step2(0.0, 0.0, ContactIntent::Push).0, fastest - a * dt), "out of contact: falls back");
    let over = 0.5 * (th.contact_force_n - push_n); // under eps_c: no cell at the limit
    let held = (p.push_peak_s / dt + 0.5).floor() as usize + 1; // the first step over it longer than push_peak_s
    for _ in 1..held {
        step2(push_n + over, 0.0, ContactIntent::Push);
    }
    v = touch;
    for n in 1..=3 {
        v -= k * over * dt;
        let got = step2(push_n + over, 0.0, ContactIntent::Push).0;
        assert!(
            close(got, v),
            "over the push force past push_peak_s, step {n}: {got}, expected {v} (the touch speed, then less)"
        );
    }
    for _ in 0..((touch / (k * over * dt)) as usize + 2) {
        v = step2(push_n + over, 0.0, ContactIntent::Push).0;
    }
    assert_eq!(v, 0.0, "a push that does not give way holds its force: nothing closes");
    assert!(close(step2(far, 0.0, ContactIntent::Push).0, a * dt), "under the push force again: the push resumes");
    // a fast push whose force goes over F_p: a peak, then, held, a stop; and a strike at eps_c
    for _ in 0..((fastest / (a * dt)) as usize) {
        step2(far, 0.0, ContactIntent::Push);
    }
    let margin = th.contact_force_n - push_n;
    let mut v = step2(push_n - 0.1 * margin, 0.0, ContactIntent::Push).0;
    assert!(v > 2.0 * touch, "a fast push ({v} m/s)");
    for n in 1..=((p.push_peak_s / dt) as usize + 2) {
        let got = step2(push_n + over, 0.0, ContactIntent::Push).0;
        let held_s = n as f64 * dt;
        if held_s < p.push_peak_s - 0.5 * dt {
            assert!(close(got, v - k * over * dt), "a peak over the push force, {held_s} s: {got}, from {v}");
        } else if held_s > p.push_peak_s + 0.5 * dt {
            assert!(got <= touch, "over the push force for {held_s} s: a stop, {got} m/s");
        }
        v = got;
    }
    step2(push_n - 0.1 * margin, 0.0, ContactIntent::Push);
    for _ in 0..((fastest / (a * dt)) as usize) {
        step2(far, 0.0, ContactIntent::Push);
    }
    assert_eq!(step2(th.contact_force_n, 0.0, ContactIntent::Push).0, 0.0, "a strike at eps_c");
    let got = step2(push_n - 0.1 * margin, 0.0, ContactIntent::Push).0;
    assert!(got <= touch + a * dt, "under the push force after a strike: the push was set back, {got} m/s");
    step2(0.0, 0.0, ContactIntent::Push);
    // two cells of one contact, each under the push force: their link's force is over it
    let f = 0.6 * push_n;
    let link_n = (f * (cell(pressed).normal_link + cell(beside).normal_link)).norm();
    assert!(link_n > push_n, "the two cells face the same way ({link_n} N)");
    let got = step2(f, f, ContactIntent::Push).0;
    assert!(got <= touch, "the link's force, not its hardest cell: {got}");
    step2(far, 0.0, ContactIntent::Push);
    assert_eq!(step2(far, 0.0, ContactIntent::Touch).0, touch, "no push outside (b)");
    assert_eq!(step2(far, 0.0, ContactIntent::Release), (0.0, 0.0, 0.0), "releasing: nothing closes");
    assert_eq!(step2(th.contact_force_n, 0.0, ContactIntent::Push).0, 0.0, "no cell is pushed into eps_c");
}

/// A link's contacts ([`crate::skin::contacts::LinkContacts`]): neighbouring pressed cells are
/// one contact, the norm of their vector sum; cells on opposite sides of a link are two, the sum
/// of their forces (a link squeezed between two obstacles, whose vector sum nearly cancels);
/// cells of two links are apart, and unpressed cells are no contact.
#[test]
fn a_link_squeezed_from_two_sides_has_two_contacts() {
    use crate::skin::contacts::LinkContacts;
    use approx::assert_relative_eq;
    let config = ControllerConfig::load(&setup("planar7")).unwrap();
    let layout = &config.layout;
    let mut contacts = LinkContacts::new(layout, config.model.nframes());
    let cells = layout.cells();
    let a = 0;
    let frame = cells[a].frame;
    let on_link = || (0..cells.len()).filter(move |&i| i != a && cells[i].frame == frame);
    let by = |key: &dyn Fn(usize) -> f64| on_link().min_by(|&i, &j| key(i).total_cmp(&key(j))).unwrap();
    let near = by(&|i| (cells[i].position_link - cells[a].position_link).norm());
    let opposite = by(&|i| cells[i].normal_link.dot(&cells[a].normal_link));
    let other = (0..cells.len()).find(|&i| cells[i].frame != frame).unwrap();
    let (f, g) = (2.0, 3.0);
    let one = (f * cells[a].normal_link + g * cells[near].normal_link).norm();
    assert_relative_eq!(
        contacts.update(layout, [(a, f), (near, g)].into_iter())[frame].contact_n,
        one,
        epsilon = 1e-12
    );
    let squeezed = (f * cells[a].normal_link + g * cells[opposite].normal_link).norm();
    assert!(squeezed < 0.5 * (f + g), "the two cells face apart: {squeezed}");
    let squeeze = contacts.update(layout, [(a, f), (opposite, g)].into_iter())[frame];
    assert_relative_eq!(squeeze.contact_n, f + g, epsilon = 1e-12);
    assert_relative_eq!(squeeze.pressed_n, f + g, epsilon = 1e-12);
    let apart = contacts.update(layout, [(a, f), (other, g), (near, 0.0)].into_iter()).to_vec();
    assert_relative_eq!(apart[frame].contact_n, f, epsilon = 1e-12);
    assert_relative_eq!(apart[cells[other].frame].contact_n, g, epsilon = 1e-12);
}

/// The supervisor's `‖F_c‖` is the force on the link pressed hardest, the sum of its contacts:
/// a link squeezed from opposite sides carries both forces, where the vector sum of its cells
/// nearly cancels (TOMM's wrist pinched between two obstacles read 4.5 N of MuJoCo's 6.3 N).
#[test]
fn the_supervisors_contact_force_sums_a_squeezed_links_contacts() {
    let mut c = controller("planar7");
    let config = c.config().clone();
    let (layout, skin) = (&config.layout, &config.skin);
    let cells = layout.cells();
    let a = 0;
    let on_link = (0..cells.len()).filter(|&i| i != a && cells[i].frame == cells[a].frame);
    let opposite = on_link
        .min_by(|&i, &j| {
            cells[i].normal_link.dot(&cells[a].normal_link).total_cmp(&cells[j].normal_link.dot(&cells[a].normal_link))
        })
        .unwrap();
    let (f, g) = (3.0, 2.5);
    assert!((f * cells[a].normal_link + g * cells[opposite].normal_link).norm() < 0.5 * (f + g), "opposite cells");
    let mut readings = vec![CellReading::default(); layout.num_cells()];
    readings[a] = CellReading::uniform(skin.force.signal(f), 1.0);
    readings[opposite] = CellReading::uniform(skin.force.signal(g), 1.0);
    let q = config.setup.posture.clone();
    let qd = vec![0.0; config.model.nv()];
    let input = ControllerInput { t_s: 0.0, dt_s: 0.008, q: &q, qd: &qd, cells: &readings, scan: &[] };
    let fc = c.update(&input).signals.contact_force_n;
    assert!((fc - (f + g)).abs() < 1e-6, "the link carries {} N, the supervisor read {fc} N", f + g);
}

/// The supervisor's `contact_advance_mps`: the point where the link pressed hardest is pressed,
/// moving along the link's force: as fast as a lone pressed cell closes on what it touches,
/// negative when it backs away, NaN without contact.
#[test]
fn contact_advance_is_the_pressed_points_speed_into_its_contact() {
    let mut c = controller("planar7");
    let config = c.config().clone();
    let (model, layout, skin) = (&config.model, &config.layout, &config.skin);
    let q = config.setup.posture.clone();
    let mut data = crate::model::ModelData::new(model);
    crate::model::update_kinematics(model, &mut data, &q, &vec![0.0; model.nv()]).unwrap();
    let cell = &layout.cells()[3];
    let outward = data.frame_pose(cell.frame).rotation * cell.normal_link;
    let mut row = vec![0.0; model.nv()];
    crate::model::point_jacobian_along(model, &data, cell.frame, &cell.position_link, &outward, &mut row).unwrap();
    let norm2: f64 = row.iter().map(|r| r * r).sum();
    let mut readings = vec![CellReading::default(); layout.num_cells()];
    readings[3] = CellReading::uniform(skin.force.signal(2.0), 1.0);
    let quiet = vec![CellReading::default(); layout.num_cells()];
    for (k, speed) in [0.02, -0.01].into_iter().enumerate() {
        let qd: Vec<f64> = row.iter().map(|r| r * speed / norm2).collect();
        let input = ControllerInput { t_s: k as f64 * 0.008, dt_s: 0.008, q: &q, qd: &qd, cells: &readings, scan: &[] };
        let advance = c.update(&input).signals.contact_advance_mps;
        assert!((advance - speed).abs() < 1e-9, "{advance} m/s, the cell closes at {speed}");
    }
    let input = ControllerInput { t_s: 0.016, dt_s: 0.008, q: &q, qd: &row, cells: &quiet, scan: &[] };
    assert!(c.update(&input).signals.contact_advance_mps.is_nan(), "no contact");
}

/// Near TOMM's reach the goal of intentional-contact paper eq. (7)-(9) moves the hand as the
/// paper's law does: at most `V_max`, into the tolerance without overshoot. The resolver's joint
/// damping `C_a` held it there to a crawl of millimetres per second, 5.7 cm short after 12 s
/// (`controller::goal_damping`). From the `tomm_movable_obstacles` start, its goal 0.5 m away at
/// the edge of the right arm's reach; a perfectly tracking arm, no skin contact.
#[test]
fn tomm_reaches_a_goal_at_its_reach_at_the_goals_speed() {
    let mut c = controller("tomm");
    let model = c.config().model.clone();
    let goal_params = c.config().tasks.goal;
    let mut q = c.config().setup.posture.clone();
    let start = [
        ("right_shoulder_pan_joint", 2.598),
        ("right_shoulder_lift_joint", 0.602),
        ("right_elbow_joint", -0.924),
        ("right_wrist_1_joint", -1.642),
        ("right_wrist_2_joint", 2.288),
        ("right_wrist_3_joint", 0.984),
    ];
    for (name, value) in start {
        q[model.joint_index(name).unwrap()] = value;
    }
    let mut qd = vec![0.0; model.nv()];
    let cells = vec![CellReading::default(); c.config().layout.num_cells()];
    let goal = Vector3::new(0.75, -0.85, 0.9);
    c.set_goal(Some(Isometry3::from_parts(Translation3::from(goal), UnitQuaternion::identity()))).unwrap();
    let dt = 0.008;
    let (mut fastest, mut closest) = (0.0_f64, f64::INFINITY);
    for k in 0..1500 {
        let out = c.update(&ControllerInput { t_s: k as f64 * dt, dt_s: dt, q: &q, qd: &qd, cells: &cells, scan: &[] });
        assert_eq!(out.fault, None);
        fastest = fastest.max(out.signals.ee_speed_mps);
        closest = closest.min(out.signals.goal_error_m);
        follow(&c, &mut q, &mut qd, dt);
    }
    let e = c.output().signals.goal_error_m;
    let tolerance = c.config().supervisor.thresholds.goal_tolerance_m;
    assert!(fastest <= 1.05 * goal_params.v_max_m_per_s, "at most V_max: {fastest} m/s");
    assert!(e <= tolerance, "within the goal tolerance after 12 s: {e} m");
    assert!(e <= closest + 5e-4, "no overshoot: {e} m at the end, {closest} m at the closest");
}
