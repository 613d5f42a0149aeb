//! Tests of the tasks: signs, magnitudes and the composition through the hierarchy solver.

use std::path::PathBuf;

use approx::assert_relative_eq;
use nalgebra::{DMatrix, DVector, Matrix6xX, Point3, UnitQuaternion, Vector2, Vector3};

use super::avoidance::ProximityAvoidance;
use super::base_avoidance::BaseAvoidance;
use super::compliance::BodyCompliance;
use super::contact_reaction::ContactReaction;
use super::goal::{saturated_goal_force, GoalOrientation, GoalPosition};
use super::hand_force::{HandForce, HandMeasurement};
use super::params::{HandForceParams, TaskParams};
use super::position_hold::PositionHold;
use super::posture::Posture;
use super::tactile_guidance::TactileGuidance;
use super::task::WristMoments;
use super::task::{BaseReference, Task};
use super::wrist::CompliantWrist;
use crate::hierarchy::{HierarchySolver, InverseParams, TaskLevel};
use crate::model::{crba, point_jacobian, update_kinematics, ModelData, RobotModel};
use crate::param_file::ParamsError;
use crate::skin::aggregate::{aggregate_patches, PatchWrench};
use crate::skin::layout::{ResolvedLayout, SkinLayout};
use crate::skin::live::LiveCells;
use crate::skin::params::SkinParams;
use crate::skin::signals::CellReading;
use crate::skin::transforms::{patch_poses_world, sum_patch_forces_in_frame};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

struct Setup {
    model: RobotModel,
    data: ModelData,
    layout: ResolvedLayout,
    skin: SkinParams,
    params: TaskParams,
    q: Vec<f64>,
}

fn tomm() -> Setup {
    let r = root();
    let model = RobotModel::from_urdf_file(&r.join("urdf/tomm.urdf")).unwrap();
    let layout = SkinLayout::load(&r.join("config/skin/tomm.yaml")).unwrap().resolve(&model).unwrap();
    let skin = SkinParams::load(&r.join("config/skin_model.yaml")).unwrap();
    let params = TaskParams::load(&r.join("config/tasks.yaml")).unwrap();
    let mut data = ModelData::new(&model);
    // a bent, non-singular arm posture
    let q: Vec<f64> = (0..model.nv()).map(|i| if i < 3 { 0.0 } else { 0.3 + 0.1 * (i % 4) as f64 }).collect();
    update_kinematics(&model, &mut data, &q, &vec![0.0; model.nv()]).unwrap();
    Setup { model, data, layout, skin, params, q }
}

fn patch_of(layout: &ResolvedLayout, link: &str) -> usize {
    layout.patches().iter().position(|p| p.link == link).unwrap()
}

/// `M⁻¹ τ` with τ = level torque `Jᵀ F`.
fn accel_from(s: &mut Setup, tau: &DVector<f64>) -> DVector<f64> {
    let n = s.model.nv();
    let mut m = DMatrix::zeros(n, n);
    crba(&s.model, &mut s.data, &mut m).unwrap();
    m.cholesky().unwrap().solve(tau)
}

fn level_torque(level: &TaskLevel) -> DVector<f64> {
    let f = DVector::from_column_slice(level.target());
    level.jacobian_transpose() * f
}

#[test]
fn shipped_params_load_and_errors_name_file_and_key() {
    let p = TaskParams::load(&root().join("config/tasks.yaml")).unwrap();
    assert!(p.goal.v_max_m_per_s > 0.0);
    let text = std::fs::read_to_string(root().join("config/tasks.yaml")).unwrap();
    let bad = text.replace("alpha_m: 0.10", "alpha_m: -1.0");
    let e = TaskParams::from_yaml_str(&bad, "t.yaml").unwrap_err();
    assert!(matches!(e, ParamsError::Invalid { .. }));
    let msg = e.to_string();
    assert!(msg.contains("t.yaml") && msg.contains("base_avoidance.alpha_m"), "{msg}");
    let unknown = text.replace("contact_reaction:\n", "contact_reaction:\n  extra: 2.0\n");
    assert_ne!(unknown, text);
    let msg = TaskParams::from_yaml_str(&unknown, "u.yaml").unwrap_err().to_string();
    assert!(msg.contains("u.yaml") && msg.contains("extra"), "{msg}");
}

#[test]
fn goal_force_points_to_goal_and_saturates() {
    let p = TaskParams::load(&root().join("config/tasks.yaml")).unwrap().goal;
    // small error: no saturation, F = k_p e
    let e = Vector3::new(0.01, 0.0, 0.0);
    assert!(p.kp_n_per_m / p.kv_n_s_per_m * 0.01 < p.v_max_m_per_s);
    assert_relative_eq!(saturated_goal_force(&p, &e, &Vector3::zeros()), e * p.kp_n_per_m, epsilon = 1e-12);
    // large error: |F| = k_v V_max toward the goal (eq. 9)
    let e = Vector3::new(3.0, -4.0, 0.0);
    let f = saturated_goal_force(&p, &e, &Vector3::zeros());
    assert_relative_eq!(f.norm(), p.kv_n_s_per_m * p.v_max_m_per_s, epsilon = 1e-12);
    assert_relative_eq!(f.normalize(), e.normalize(), epsilon = 1e-12);
    // moving at V_max toward the goal: no force
    let v = e.normalize() * p.v_max_m_per_s;
    assert!(saturated_goal_force(&p, &e, &v).norm() < 1e-12);

    let mut s = tomm();
    let hand = s.model.frame_index("right_hand").unwrap();
    let mut task = GoalPosition::new(s.model.nv(), hand, Vector3::zeros(), s.params.goal);
    let x = s.data.frame_pose(hand).translation.vector;
    let goal = x + Vector3::new(0.0, 0.0, 1.0);
    let mut level = TaskLevel::new("goal", s.model.nv(), 3);
    let f = task.update(&s.model, &s.data, &goal, &mut level).unwrap();
    assert_eq!(level.rows(), 3);
    assert_relative_eq!(f, Vector3::z() * p.kv_n_s_per_m * p.v_max_m_per_s, epsilon = 1e-9);
    // the torque accelerates the hand toward the goal
    let qdd = accel_from(&mut s, &level_torque(&level));
    let mut j = Matrix6xX::zeros(s.model.nv());
    point_jacobian(&s.model, &s.data, hand, &Vector3::zeros(), &mut j).unwrap();
    assert!((j.fixed_rows::<3>(0) * qdd)[2] > 0.0);

    let mut rot = GoalOrientation::new(s.model.nv(), hand, s.params.goal_orientation);
    let r = s.data.frame_pose(hand).rotation;
    let r_d = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 0.1) * r;
    let m = rot.update(&s.model, &s.data, &r_d, &mut level).unwrap();
    assert_eq!(level.rows(), 3);
    assert!(m.normalize().dot(&Vector3::x()) > 1.0 - 1e-9);
}

#[test]
fn avoidance_rows_magnitude_and_zero_range() {
    let mut s = tomm();
    let n = s.layout.num_cells();
    let mut readings = vec![CellReading::uniform(0.0, 0.0); n];
    let d = 0.04;
    readings[5].proximity = s.skin.proximity.signal(d);
    readings[9].proximity = s.skin.proximity.signal(0.12); // beyond d_range = 0.10
    let mut task = ProximityAvoidance::new(s.model.nv(), s.params.avoidance);
    let mut level = TaskLevel::new("avoid", s.model.nv(), n);
    let range = s.params.avoidance.range_m;
    let sum = task
        .update(
            &s.model,
            &s.data,
            &s.layout,
            &LiveCells::from_readings(&readings, &s.skin.proximity),
            range,
            &mut level,
        )
        .unwrap();
    assert_eq!((level.rows(), sum.rows), (1, 1));
    assert_relative_eq!(level.target()[0], s.params.avoidance.gain_n_per_m * (range - d), epsilon = 1e-9);
    assert_relative_eq!(sum.force_norm_n, level.target()[0], epsilon = 1e-12);
    // the torque pushes the cell inward (away from the obstacle along +n)
    let cell = s.layout.cells()[5].clone();
    let nw = s.data.frame_pose(cell.frame).rotation * cell.normal_link;
    let qdd = accel_from(&mut s, &level_torque(&level));
    let mut j = Matrix6xX::zeros(s.model.nv());
    point_jacobian(&s.model, &s.data, cell.frame, &cell.position_link, &mut j).unwrap();
    assert!((j.fixed_rows::<3>(0) * qdd).dot(&nw) < 0.0);
    // the supervisor's range 0 disables the task
    let sum = task
        .update(&s.model, &s.data, &s.layout, &LiveCells::from_readings(&readings, &s.skin.proximity), 0.0, &mut level)
        .unwrap();
    assert_eq!((level.rows(), sum.rows), (0, 0));
    assert_eq!(sum.force_norm_n, 0.0);
}

#[test]
fn avoidance_row_fades_in_at_the_range_boundary() {
    // a cell entering the range: force 0 and activation 0 at d_range, full activation from
    // d_range − band on, smooth in between (the projector of the lower levels has no step)
    let s = tomm();
    let n = s.layout.num_cells();
    let mut task = ProximityAvoidance::new(s.model.nv(), s.params.avoidance);
    let mut level = TaskLevel::new("avoid", s.model.nv(), n);
    let (range, band) = (s.params.avoidance.range_m, s.params.avoidance.activation_band_m);
    assert!(band > 0.0 && band < range);
    let mut prev = 0.0;
    for k in 1..=100 {
        let d = range - k as f64 * 1e-3;
        let mut readings = vec![CellReading::uniform(0.0, 0.0); n];
        readings[5].proximity = s.skin.proximity.signal(d);
        task.update(
            &s.model,
            &s.data,
            &s.layout,
            &LiveCells::from_readings(&readings, &s.skin.proximity),
            range,
            &mut level,
        )
        .unwrap();
        assert!(level.is_activated());
        let a = level.activation()[0];
        assert!(a >= prev && a - prev < 0.05, "activation {a} after {prev} at d = {d}");
        if range - d >= band + 1e-6 {
            assert_eq!(a, 1.0);
        }
        prev = a;
    }
}

#[test]
fn contact_reaction_moves_touched_cell_along_minus_n() {
    let mut s = tomm();
    let n = s.layout.num_cells();
    let forearm = patch_of(&s.layout, "right_forearm_link");
    let c = s.layout.patches()[forearm].cells.start + 3;
    let mut readings = vec![CellReading::uniform(0.0, 0.0); n];
    readings[c] = CellReading::uniform(0.5, 1.0);
    let mut task = ContactReaction::new(s.model.nv(), s.model.nframes(), s.params.contact_reaction, &s.skin.force);
    let mut level = TaskLevel::new("contact", s.model.nv(), n);
    let sum = task
        .update(
            &s.model,
            &s.data,
            &s.layout,
            &LiveCells::from_readings(&readings, &s.skin.proximity),
            &s.skin.fusion,
            &mut level,
        )
        .unwrap();
    assert_eq!(level.rows(), 1);
    // eq. (6): the measured force times the gain, uncapped
    let expected = s.params.contact_reaction.gain * s.skin.force.force_n(0.5);
    assert_relative_eq!(sum.max_force_n, expected, epsilon = 1e-9);
    let cell = s.layout.cells()[c].clone();
    let nw = s.data.frame_pose(cell.frame).rotation * cell.normal_link;
    let qdd = accel_from(&mut s, &level_torque(&level));
    let mut j = Matrix6xX::zeros(s.model.nv());
    point_jacobian(&s.model, &s.data, cell.frame, &cell.position_link, &mut j).unwrap();
    assert!((j.fixed_rows::<3>(0) * qdd).dot(&nw) < 0.0);
}

/// Table I's `‖F_c‖` is the force on a link, not on one cell: two pressed cells of one link add
/// as vectors along their normals, a pressed cell of another link does not add to them.
#[test]
fn contact_force_is_the_largest_link_force_summed_over_its_cells() {
    let s = tomm();
    let n = s.layout.num_cells();
    let forearm = s.layout.patches()[patch_of(&s.layout, "right_forearm_link")].cells.start;
    let upper = s.layout.patches()[patch_of(&s.layout, "right_upper_arm_link")].cells.start;
    let (a, b) = (forearm + 3, forearm + 4);
    let mut readings = vec![CellReading::uniform(0.0, 0.0); n];
    for c in [a, b, upper] {
        readings[c] = CellReading::uniform(0.5, 1.0);
    }
    let mut task = ContactReaction::new(s.model.nv(), s.model.nframes(), s.params.contact_reaction, &s.skin.force);
    let live = LiveCells::from_readings(&readings, &s.skin.proximity);
    let sum = task.summarize(&s.layout, &live, &s.skin.fusion).unwrap();
    let f = s.skin.force.force_n(0.5);
    let cells = s.layout.cells();
    let forearm_n = (cells[a].normal_link + cells[b].normal_link).norm() * f;
    assert!(forearm_n > 1.5 * f, "neighbouring cells face nearly the same way");
    // the link pressed hardest: its frame, its force and the point between its two cells
    let pressed = sum.pressed.expect("cells in contact");
    assert_relative_eq!(pressed.force.norm(), forearm_n, epsilon = 1e-9);
    assert_eq!(pressed.frame, cells[a].frame);
    assert_relative_eq!(pressed.force, (cells[a].normal_link + cells[b].normal_link) * f, epsilon = 1e-9);
    assert_relative_eq!(pressed.point, (cells[a].position_link + cells[b].position_link) / 2.0, epsilon = 1e-9);
    let none = LiveCells::from_readings(&vec![CellReading::uniform(0.0, 0.0); n], &s.skin.proximity);
    assert_eq!(task.summarize(&s.layout, &none, &s.skin.fusion).unwrap().pressed, None);
}

/// The closing speed bound of the hand task: a hand moving into a surface faster than
/// `v_0 + d / T_a` brakes whatever eq. (9) asks for, the bound falls with the sensed distance, and
/// a hand slower than it gets eq. (9) unchanged.
#[test]
fn hand_approach_speed_is_bounded_by_the_sensed_distance() {
    let mut s = tomm();
    let hand = s.model.frame_index("right_hand").unwrap();
    // undamped eq. (9), so that only the bound can brake
    let h = HandForceParams { d_n_s_per_m: 0.0, ..s.params.hand_force };
    let mut task = HandForce::new(s.model.nv(), hand, h);
    task.force_desired_n = 3.0;
    let mut level = TaskLevel::new("hand", s.model.nv(), 1);
    let mut j = Matrix6xX::zeros(s.model.nv());
    point_jacobian(&s.model, &s.data, hand, &Vector3::zeros(), &mut j).unwrap();
    let z = s.data.frame_pose(hand).rotation * Vector3::z();
    // joint velocities that move the hand along +z_h at `speed` (least squares through J_v^T)
    let row = (z.transpose() * j.fixed_rows::<3>(0)).transpose();
    let moving = |speed: f64| row.clone() * (speed / row.norm_squared());
    let far = HandMeasurement::Force { force_n: 0.0 };
    let near = s.skin.proximity.signal(0.01);
    let limit_near = super::hand_force::approach_speed_limit(&h, 0.01);
    assert_relative_eq!(limit_near, h.approach_speed_min_mps + 0.01 / h.approach_time_s, epsilon = 1e-9);
    // faster than the bound at 1 cm: brakes although the force error pushes
    let qd = moving(2.0 * limit_near);
    update_kinematics(&s.model, &mut s.data, &s.q, qd.as_slice()).unwrap();
    let xdd = task.update(&s.model, &s.data, far, near, &s.skin.proximity, &mut level).unwrap();
    assert!(xdd < 0.0, "braking expected, got {xdd}");
    assert_relative_eq!(xdd, -limit_near / super::hand_force::APPROACH_BRAKE_S, max_relative = 1e-6);
    // untouched and at rest with a surface in range: closes at the bound, whatever the reference
    update_kinematics(&s.model, &mut s.data, &s.q, &vec![0.0; s.model.nv()]).unwrap();
    let xdd = task.update(&s.model, &s.data, far, near, &s.skin.proximity, &mut level).unwrap();
    assert_relative_eq!(xdd, limit_near / super::hand_force::APPROACH_BRAKE_S, max_relative = 1e-6);
    let qd = moving(2.0 * limit_near);
    update_kinematics(&s.model, &mut s.data, &s.q, qd.as_slice()).unwrap();
    // the same speed with nothing in range is below the bound: eq. (9) as it is
    let xdd = task.update(&s.model, &s.data, far, 0.0, &s.skin.proximity, &mut level).unwrap();
    assert_relative_eq!(xdd, h.k_force_n_per_n * task.force_desired_n / h.lambda_kg, max_relative = 1e-6);
    // retreating is never bounded
    let qd = moving(-0.2);
    update_kinematics(&s.model, &mut s.data, &s.q, qd.as_slice()).unwrap();
    let xdd = task.update(&s.model, &s.data, far, 1.0, &s.skin.proximity, &mut level).unwrap();
    assert!(xdd > 0.0);
}

#[test]
fn hand_force_sign_and_row() {
    let s = tomm();
    let hand = s.model.frame_index("right_hand").unwrap();
    let mut task = HandForce::new(s.model.nv(), hand, s.params.hand_force);
    task.force_desired_n = 3.0;
    let mut level = TaskLevel::new("hand", s.model.nv(), 1);
    // force below the reference: accelerate into the surface (+z_h)
    let xdd = task
        .update(&s.model, &s.data, HandMeasurement::Force { force_n: 0.0 }, 0.0, &s.skin.proximity, &mut level)
        .unwrap();
    assert!(xdd > 0.0);
    let h = s.params.hand_force;
    assert_relative_eq!(xdd, h.k_force_n_per_n * task.force_desired_n / h.lambda_kg, epsilon = 1e-12);
    // too much force: back off
    let xdd = task
        .update(&s.model, &s.data, HandMeasurement::Force { force_n: 9.0 }, 0.0, &s.skin.proximity, &mut level)
        .unwrap();
    assert!(xdd < 0.0);
    // far away in distance mode: approach
    let xdd = task
        .update(
            &s.model,
            &s.data,
            HandMeasurement::Distance { proximity_signal: 0.05 },
            0.05,
            &s.skin.proximity,
            &mut level,
        )
        .unwrap();
    assert!(xdd > 0.0);
    // the row is z_hᵀ J_v
    let mut j = Matrix6xX::zeros(s.model.nv());
    point_jacobian(&s.model, &s.data, hand, &Vector3::zeros(), &mut j).unwrap();
    let z = s.data.frame_pose(hand).rotation * Vector3::z();
    let row = z.transpose() * j.fixed_rows::<3>(0);
    for (a, b) in level.jacobian_row(0).iter().zip(row.iter()) {
        assert_relative_eq!(a, b, epsilon = 1e-12);
    }
}

/// The integral of the force error while pressed: it grows with a lasting error (the servo's
/// offset), up to its share of the reference, and starts again from zero after the hand lets go
/// and after an arrangement switch.
#[test]
fn hand_force_integral_makes_up_a_lasting_offset_within_its_share() {
    let s = tomm();
    let hand = s.model.frame_index("right_hand").unwrap();
    let h = HandForceParams { integral_time_s: 1.0, reference_lead_s: 0.0, ..s.params.hand_force };
    let mut task = HandForce::new(s.model.nv(), hand, h);
    task.force_desired_n = 6.0;
    let under = HandMeasurement::Force { force_n: 5.9 };
    let p = |task: &HandForce| task.error(under, &s.skin.proximity);
    let proportional = p(&task);
    assert_relative_eq!(proportional, h.k_force_n_per_n * 0.1, epsilon = 1e-12);
    for _ in 0..125 {
        task.integrate(5.9, 0.008); // 1 s of 0.1 N under the reference (settled: within the band)
    }
    assert_relative_eq!(p(&task), 2.0 * proportional, epsilon = 1e-9);
    for _ in 0..5000 {
        task.integrate(5.9, 0.008);
    }
    let share = super::hand_force::INTEGRAL_SHARE;
    assert_relative_eq!(p(&task), proportional + h.k_force_n_per_n * share * 6.0, epsilon = 1e-9);
    task.integrate(0.0, 0.008); // let go
    assert_relative_eq!(p(&task), proportional, epsilon = 1e-12);
    task.integrate(5.9, 0.8);
    task.on_switch(&s.data);
    assert_relative_eq!(p(&task), proportional, epsilon = 1e-12);
}

/// During the rise (the force not yet within the band of its reference) the integral's term
/// stays within the small rise share; once the force has come near, the settled share applies.
#[test]
fn hand_force_integral_is_small_during_the_rise() {
    let s = tomm();
    let hand = s.model.frame_index("right_hand").unwrap();
    let h = HandForceParams { integral_time_s: 1.0, reference_lead_s: 0.0, ..s.params.hand_force };
    let mut task = HandForce::new(s.model.nv(), hand, h);
    task.force_desired_n = 6.0;
    let integral =
        |task: &HandForce| task.error(HandMeasurement::Force { force_n: 6.0 }, &s.skin.proximity) / h.k_force_n_per_n;
    for _ in 0..1000 {
        task.integrate(3.0, 0.008); // 8 s at half the reference
    }
    assert_relative_eq!(integral(&task), super::hand_force::RISE_INTEGRAL_SHARE * 6.0, epsilon = 1e-9);
    let band = super::hand_force::INTEGRAL_BAND;
    task.integrate(6.0 * (1.0 - 0.5 * band), 0.008); // within the band: settled
    for _ in 0..1000 {
        task.integrate(3.0, 0.008); // a base pushes the hand off: the large share
    }
    assert_relative_eq!(integral(&task), super::hand_force::INTEGRAL_SHARE * 6.0, epsilon = 1e-9);
}

/// The force error is taken against the led reference `f_c,d + T_l ḟ_c,d`, the rate from the
/// references of consecutive cycles; an arrangement switch forgets the last one.
#[test]
fn hand_force_leads_a_moving_reference() {
    let s = tomm();
    let hand = s.model.frame_index("right_hand").unwrap();
    let h = HandForceParams { integral_time_s: 0.0, reference_lead_s: 0.1, ..s.params.hand_force };
    let mut task = HandForce::new(s.model.nv(), hand, h);
    let cycle = |task: &mut HandForce, reference: f64| {
        task.set_reference(reference, 0.008);
        task.error(HandMeasurement::Force { force_n: 4.0 }, &s.skin.proximity) / h.k_force_n_per_n
    };
    assert_relative_eq!(cycle(&mut task, 4.0), 0.0, epsilon = 1e-12); // no rate yet
                                                                      // rising at 1 N/s: led by 0.1 N
    assert_relative_eq!(cycle(&mut task, 4.008), 0.008 + 0.1, epsilon = 1e-9);
    task.on_switch(&s.data);
    assert_relative_eq!(cycle(&mut task, 5.0), 1.0, epsilon = 1e-12);
}

#[test]
fn wrist_drives_moment_to_zero() {
    let s = tomm();
    let hand = s.model.frame_index("right_hand").unwrap();
    let mut task = CompliantWrist::new(s.model.nv(), hand, s.params.wrist);
    let mut level = TaskLevel::new("wrist", s.model.nv(), 3);
    let gamma = Vector3::new(0.0, 0.4, -0.1);
    let proximity = WristMoments { proximity_world: gamma, ..WristMoments::default() };
    let a = task.update(&s.model, &s.data, &proximity, &mut level).unwrap();
    assert_eq!(level.rows(), 3);
    assert!(a.dot(&gamma) < 0.0);
    assert!(task.update(&s.model, &s.data, &WristMoments::default(), &mut level).unwrap().norm() < 1e-12);
    // in contact (w = 1) the newtons' moment drives it, the proximity's no longer
    let contact = WristMoments { proximity_world: gamma, force_world_nm: -gamma, fusion_weight: 1.0 };
    let b = task.update(&s.model, &s.data, &contact, &mut level).unwrap();
    assert!(b.dot(&gamma) > 0.0);
    let k = s.params.wrist.k_force;
    assert_relative_eq!(b, Vector3::from_fn(|i, _| k[i] * gamma[i] / s.params.wrist.lambda[i]), epsilon = 1e-12);
}

#[test]
fn tactile_guidance_hand_follows_forearm_push() {
    let s = tomm();
    let hand = s.model.frame_index("right_hand").unwrap();
    let forearm = patch_of(&s.layout, "right_forearm_link");
    let c = s.layout.patches()[forearm].cells.start + 7;
    let mut readings = vec![CellReading::uniform(0.0, 0.0); s.layout.num_cells()];
    readings[c] = CellReading::uniform(0.6, 1.0);
    let mut wrenches: Vec<PatchWrench> = Vec::new();
    aggregate_patches(&s.layout, &readings, &s.skin.fusion, &mut wrenches).unwrap();
    let mut poses = Vec::new();
    patch_poses_world(&s.layout, |f| s.data.frame_pose(f), |_| true, &mut poses);
    let h_f = sum_patch_forces_in_frame(s.data.frame_pose(hand), &poses, &wrenches, |j| j == forearm);
    // the pushing object moves into the arm: along the cell's inward normal
    let cell = &s.layout.cells()[c];
    let push = -(s.data.frame_pose(cell.frame).rotation * cell.normal_link);
    let mut task = TactileGuidance::new(s.model.nv(), hand, s.params.tactile_guidance);
    let mut level = TaskLevel::new("guide", s.model.nv(), 3);
    let a = task.update(&s.model, &s.data, &h_f, &mut level).unwrap();
    assert!(a.norm() > 0.0);
    assert!(a.normalize().dot(&push) > 0.9, "{a} vs {push}");
}

#[test]
fn position_hold_pulls_back() {
    let mut s = tomm();
    let hand = s.model.frame_index("right_hand").unwrap();
    let mut task = PositionHold::new(s.model.nv(), hand, Vector3::zeros(), s.params.position_hold);
    task.capture(&s.data);
    let mut level = TaskLevel::new("hold", s.model.nv(), 3);
    assert!(task.update(&s.model, &s.data, &mut level).unwrap().norm() < 1e-12);
    let x0 = task.target;
    let mut q = s.q.clone();
    q[s.model.joint_index("right_elbow_joint").unwrap()] += 0.05;
    update_kinematics(&s.model, &mut s.data, &q, &vec![0.0; s.model.nv()]).unwrap();
    let a = task.update(&s.model, &s.data, &mut level).unwrap();
    let x = (s.data.frame_pose(hand) * Point3::origin()).coords;
    assert!((x0 - x).norm() > 1e-3);
    assert!(a.normalize().dot(&(x0 - x).normalize()) > 0.99);
}

#[test]
fn posture_at_rest_posture_is_pure_damping() {
    let mut s = tomm();
    let nv = s.model.nv();
    let qd: Vec<f64> = (0..nv).map(|i| 0.1 * i as f64 - 0.5).collect();
    update_kinematics(&s.model, &mut s.data, &s.q, &qd).unwrap();
    let posture = Posture::new(nv, &s.params.posture, &s.q).unwrap();
    let mut tau = DVector::zeros(nv);
    posture.joint_torque(&s.data, None, &mut tau).unwrap();
    for i in 0..nv {
        assert_relative_eq!(tau[i], -posture.d_c[i] * qd[i], epsilon = 1e-12);
    }
}

#[test]
fn a_base_reference_replaces_q_post_on_the_base_joints_only() {
    let mut s = tomm();
    let nv = s.model.nv();
    let joints = ["base_x_joint", "base_y_joint", "base_yaw_joint"].map(|n| s.model.joint_index(n).unwrap());
    let qd: Vec<f64> = (0..nv).map(|i| 0.02 * i as f64 - 0.1).collect();
    update_kinematics(&s.model, &mut s.data, &s.q, &qd).unwrap();
    let posture = Posture::new(nv, &s.params.posture, &s.q).unwrap();
    let gains = s.params.posture.base_tracking.expect("config/tasks.yaml has base tracking gains");
    let reference = BaseReference { position: [0.1, -0.2, 0.05], velocity: [0.03, 0.01, -0.02] };
    let mut tau = DVector::zeros(nv);
    posture.joint_torque(&s.data, Some((joints, reference)), &mut tau).unwrap();
    for i in 0..nv {
        let expected = match joints.iter().position(|&j| j == i) {
            // eq. (18) with q_d(t), q̇_d(t) and the tracking gains
            Some(k) => {
                -gains.k_c[k] * (s.q[i] - reference.position[k]) - gains.d_c[k] * (qd[i] - reference.velocity[k])
            }
            None => -posture.d_c[i] * qd[i],
        };
        assert_relative_eq!(tau[i], expected, epsilon = 1e-12);
    }
    posture.joint_torque(&s.data, None, &mut tau).unwrap();
    assert_relative_eq!(tau[joints[0]], -posture.d_c[joints[0]] * qd[joints[0]], epsilon = 1e-12);
}

#[test]
fn base_avoidance_pushes_back_with_eq17_yaw_term() {
    let s = tomm();
    let nv = s.model.nv();
    let joints = ["base_x_joint", "base_y_joint", "base_yaw_joint"].map(|n| s.model.joint_index(n).unwrap());
    let p = s.params.base_avoidance;
    let mut base = BaseAvoidance::new(nv, joints, p).unwrap();
    let (dx, y) = (0.2, 0.1);
    let pt = Vector2::new(p.footprint_x_m[1] + dx, y);
    let mut q = vec![0.0; nv];
    let sum = base.update(&q, &[pt, Vector2::new(10.0, 0.0)]).unwrap();
    assert_eq!(sum.obstacles, 1);
    let f = p.f_max_n * (-dx / p.alpha_m).exp();
    // eq. (15)-(17): n = +x, [f, 0, −x̄_y f] toward the obstacle
    assert_relative_eq!(sum.base_frame, Vector3::new(f, 0.0, -y * f), epsilon = 1e-12);
    // eq. (18) subtracts τ_oca: the base is pushed backward and turned so the front corner retreats
    let mut posture = Posture::new(nv, &s.params.posture, &q).unwrap();
    posture.k_c.fill(0.0);
    let mut data = ModelData::new(&s.model);
    update_kinematics(&s.model, &mut data, &q, &vec![0.0; nv]).unwrap();
    let mut tau = DVector::zeros(nv);
    posture.joint_torque(&data, None, &mut tau).unwrap();
    tau -= base.torque();
    assert!(tau[joints[0]] < 0.0);
    assert_relative_eq!(tau[joints[2]], y * f, epsilon = 1e-12);
    // with the base turned by 90°, "backward" is world −y
    q[joints[2]] = std::f64::consts::FRAC_PI_2;
    base.update(&q, &[pt]).unwrap();
    assert_relative_eq!(base.torque()[joints[1]], f, epsilon = 1e-12);
    assert!(base.torque()[joints[0]].abs() < 1e-12);
}

#[test]
fn three_tasks_and_posture_through_the_solver() {
    let mut s = tomm();
    let nv = s.model.nv();
    let n = s.layout.num_cells();
    let hand = s.model.frame_index("right_hand").unwrap();
    let qd: Vec<f64> = (0..nv).map(|i| 0.02 * i as f64).collect();
    update_kinematics(&s.model, &mut s.data, &s.q, &qd).unwrap();
    let readings: Vec<CellReading> =
        (0..n).map(|i| CellReading::uniform((i % 7) as f64 / 10.0, (i % 5) as f64 / 5.0)).collect();
    let mut wrenches = Vec::new();
    aggregate_patches(&s.layout, &readings, &s.skin.fusion, &mut wrenches).unwrap();

    let mut avoid = ProximityAvoidance::new(nv, s.params.avoidance);
    let mut hand_task = HandForce::new(nv, hand, s.params.hand_force);
    let mut hold = PositionHold::new(nv, hand, Vector3::zeros(), s.params.position_hold);
    hold.capture(&s.data);
    let posture = Posture::new(nv, &s.params.posture, &vec![0.0; nv]).unwrap();
    let mut compliance = BodyCompliance::new(nv, s.params.posture.skin_gain);
    let mut levels = [TaskLevel::new("avoid", nv, n), TaskLevel::new("hand", nv, 1), TaskLevel::new("hold", nv, 3)];
    let [l0, l1, l2] = &mut levels;
    let sum = avoid
        .update(&s.model, &s.data, &s.layout, &LiveCells::from_readings(&readings, &s.skin.proximity), 0.1, l0)
        .unwrap();
    assert!(sum.rows > 0);
    hand_task.update(&s.model, &s.data, HandMeasurement::Force { force_n: 1.0 }, 0.0, &s.skin.proximity, l1).unwrap();
    hold.update(&s.model, &s.data, l2).unwrap();
    let (mut tau_s, mut tau_c) = (DVector::zeros(nv), DVector::zeros(nv));
    compliance.add_to(&s.model, &s.data, &s.layout, &wrenches, |_| true, &mut tau_s).unwrap();
    posture.joint_torque(&s.data, None, &mut tau_c).unwrap();
    tau_c -= &tau_s;
    let mut solver = HierarchySolver::new(nv, 3, n, InverseParams::default()).unwrap();
    let mut tau = DVector::zeros(nv);
    solver.solve_model(&s.model, &mut s.data, levels.iter(), Some(tau_c.as_slice()), true, &mut tau).unwrap();
    assert!(tau.iter().all(|t| t.is_finite()));
    assert!(tau.norm() > 0.0);
}

#[test]
fn planar_goal_keeps_three_rows_and_solves() {
    let model = RobotModel::from_urdf_file(&root().join("urdf/planar7.urdf")).unwrap();
    let params = TaskParams::load(&root().join("config/tasks.yaml")).unwrap();
    let nv = model.nv();
    let mut data = ModelData::new(&model);
    let q: Vec<f64> = (0..nv).map(|i| 0.2 + 0.05 * i as f64).collect();
    update_kinematics(&model, &mut data, &q, &vec![0.0; nv]).unwrap();
    let ee = model.frame_index("ee").unwrap();
    let x = data.frame_pose(ee).translation.vector;
    let mut goal = GoalPosition::new(nv, ee, Vector3::zeros(), params.goal);
    let mut level = TaskLevel::new("goal", nv, 3);
    goal.update(&model, &data, &(x + Vector3::new(0.1, 0.1, 0.1)), &mut level).unwrap();
    assert_eq!(level.rows(), 3);
    let mut solver = HierarchySolver::new(nv, 1, 3, InverseParams::default()).unwrap();
    let mut tau = DVector::zeros(nv);
    solver.solve_model(&model, &mut data, [&level], None, false, &mut tau).unwrap();
    assert!(tau.iter().all(|t| t.is_finite()) && tau.norm() > 0.0);
}
