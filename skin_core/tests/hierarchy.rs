//! The hierarchy solver against the properties interactive-force-control paper eq. (19)-(25) promise, on the project's
//! robots (planar7: 7 DoF in the plane; TOMM: base x/y/yaw + two UR5): strict priority, the
//! posture in the last null space, equivalence with operational-space control for one level,
//! rank loss (duplicated rows, dependent levels, zero and singular Jacobians), absurd inputs,
//! continuity through a singularity, and intentional-contact paper force levels composed with acceleration levels.

use nalgebra::{DMatrix, DVector, Matrix6xX, SymmetricEigen, Vector3, Vector6};
use proptest::prelude::*;
use skin_core::hierarchy::*;
use skin_core::model::*;

fn load(file: &str) -> RobotModel {
    let path = format!("{}/../urdf/{file}", env!("CARGO_MANIFEST_DIR"));
    RobotModel::from_urdf_file(std::path::Path::new(&path)).unwrap()
}

/// Model evaluated at one state: M, and point Jacobians / J̇q̇ on demand.
struct State {
    model: RobotModel,
    data: ModelData,
    m: DMatrix<f64>,
}

impl State {
    fn new(file: &str, q: &[f64], qd: &[f64]) -> State {
        let model = load(file);
        let mut data = ModelData::new(&model);
        let n = model.nv();
        update_kinematics(&model, &mut data, q, qd).unwrap();
        let mut m = DMatrix::zeros(n, n);
        crba(&model, &mut data, &mut m).unwrap();
        State { model, data, m }
    }
    fn n(&self) -> usize {
        self.model.nv()
    }
    /// (J, J̇q̇) of a point of a link as dense matrices (6 × n, 6).
    fn point(&self, link: &str, p: [f64; 3]) -> (DMatrix<f64>, DVector<f64>) {
        let f = self.model.frame_index(link).unwrap_or_else(|| panic!("no link {link}"));
        let p = Vector3::from(p);
        let mut j = Matrix6xX::zeros(self.n());
        let mut jd = Vector6::zeros();
        point_jacobian(&self.model, &self.data, f, &p, &mut j).unwrap();
        point_jacobian_dot_qdot(&self.model, &self.data, f, &p, &mut jd).unwrap();
        (DMatrix::from_column_slice(6, self.n(), j.as_slice()), DVector::from_column_slice(jd.as_slice()))
    }
    /// Rows `rows` of a point task.
    fn task(&self, link: &str, p: [f64; 3], rows: &[usize]) -> (DMatrix<f64>, DVector<f64>) {
        let (j, jd) = self.point(link, p);
        (j.select_rows(rows), jd.select_rows(rows))
    }
    fn qdd(&self, tau: &DVector<f64>) -> DVector<f64> {
        self.m.clone().cholesky().unwrap().solve(tau)
    }
    fn max_eig_m(&self) -> f64 {
        SymmetricEigen::new(self.m.clone()).eigenvalues.max()
    }
}

fn acc_level(name: &str, j: &DMatrix<f64>, jd: &DVector<f64>, xdd: &[f64]) -> TaskLevel {
    let mut l = TaskLevel::new(name, j.ncols(), j.nrows().max(1));
    l.set(j, Reference::Acceleration { xdd_star: xdd, jdot_qdot: jd.as_slice() }).unwrap();
    l
}

fn solve(s: &State, levels: &[&TaskLevel], posture: Option<&[f64]>) -> (DVector<f64>, Vec<LevelDiagnostics>) {
    let mut solver = HierarchySolver::new(s.n(), 8, 100, InverseParams::default()).unwrap();
    let mut tau = DVector::zeros(s.n());
    solver.solve(&s.m, levels.iter().copied(), posture, None, &mut tau).unwrap();
    (tau, solver.diagnostics().to_vec())
}

/// `J q̈ + J̇ q̇ − ẍ*` (max abs).
fn task_residual(j: &DMatrix<f64>, jd: &DVector<f64>, xdd: &[f64], qdd: &DVector<f64>) -> f64 {
    (j * qdd + jd - DVector::from_column_slice(xdd)).amax()
}

const XY: [usize; 2] = [0, 1];
const P7_BENT: [f64; 7] = [0.3, -0.5, 0.8, -0.6, 0.4, 0.7, -0.3];
const P7_QD: [f64; 7] = [0.2, -0.1, 0.3, 0.1, -0.2, 0.15, 0.05];

fn tomm_q(s_model_nv: usize) -> (Vec<f64>, Vec<f64>) {
    let q = (0..s_model_nv).map(|i| 0.4 * ((i as f64) * 0.9).sin() + 0.2).collect();
    let qd = (0..s_model_nv).map(|i| 0.1 * ((i as f64) * 1.3).cos()).collect();
    (q, qd)
}

#[test]
fn hierarchy_strict_priority_planar7() {
    let s = State::new("planar7.urdf", &P7_BENT, &P7_QD);
    let posture: Vec<f64> = (0..7).map(|i| 3.0 - i as f64).collect();
    let (j1, jd1) = s.task("ee", [0.0; 3], &XY);
    let x1 = [0.5, -0.3];
    let l1 = acc_level("ee", &j1, &jd1, &x1);
    // compatible level 2: the middle of the arm (2 rows, 5 DoF left)
    let (j2, jd2) = s.task("link4", [0.1, 0.0, 0.0], &XY);
    let x2 = [-0.2, 0.4];
    let l2 = acc_level("link4", &j2, &jd2, &x2);
    let (tau, diag) = solve(&s, &[&l1, &l2], Some(&posture));
    let qdd = s.qdd(&tau);
    assert!(task_residual(&j1, &jd1, &x1, &qdd) < 1e-9);
    assert!(task_residual(&j2, &jd2, &x2, &qdd) < 1e-9);
    assert_eq!((diag[0].rank, diag[0].damped, diag[1].rank, diag[1].damped), (2, 0, 2, 0));
    assert!(diag[0].task_error.unwrap() < 1e-9 && diag[1].task_error.unwrap() < 1e-9);

    // conflicting level 2: three points, 6 rows for the 5 remaining DoF
    let mut l2 = TaskLevel::new("three_points", 7, 6);
    let x2 = [1.0, -2.0, 0.5, 3.0, -1.5, 2.5];
    let mut rows = Vec::new();
    for (i, link) in ["link3", "link5", "link6"].iter().enumerate() {
        let (j, jd) = s.task(link, [0.2, 0.0, 0.0], &XY);
        l2.push(&j, Reference::Acceleration { xdd_star: &x2[2 * i..2 * i + 2], jdot_qdot: jd.as_slice() }).unwrap();
        rows.push((j, jd));
    }
    let (tau, diag) = solve(&s, &[&l1, &l2], Some(&posture));
    let qdd = s.qdd(&tau);
    assert!(task_residual(&j1, &jd1, &x1, &qdd) < 1e-9, "level 1 disturbed by a conflicting level 2");
    assert_eq!(diag[1].rank, 5, "6 rows in a 5-DoF null space");
    assert!(diag[1].task_error.unwrap() > 1e-3, "the conflict is real");
}

#[test]
fn hierarchy_strict_priority_tomm_three_levels() {
    let model = load("tomm.urdf");
    let (q, qd) = tomm_q(model.nv());
    let s = State::new("tomm.urdf", &q, &qd);
    let n = s.n();
    let (j1, jd1) = s.task("right_hand", [0.0; 3], &[3, 4, 5]);
    let (j2, jd2) = s.task("right_hand", [0.0; 3], &[0, 1, 2]);
    let (j3, jd3) = s.point("left_hand", [0.0; 3]);
    let (x1, x2, x3) = ([0.2, -0.1, 0.3], [0.5, 0.2, -0.4], [0.1, 0.0, -0.2, 0.3, -0.3, 0.1]);
    let (l1, l2, l3) =
        (acc_level("wrist", &j1, &jd1, &x1), acc_level("hand", &j2, &jd2, &x2), acc_level("left", &j3, &jd3, &x3));
    let posture: Vec<f64> = (0..n).map(|i| ((i as f64) * 0.37).cos() * 5.0).collect();
    let (tau, diag) = solve(&s, &[&l1, &l2, &l3], Some(&posture));
    let qdd = s.qdd(&tau);
    // level 1 to 1e-9; lower levels inherit the round-off of the projections (M's condition
    // number on TOMM is ~1e3 with the base masses), 1e-8
    for (tol, j, jd, x) in [(1e-9, &j1, &jd1, &x1[..]), (1e-8, &j2, &jd2, &x2[..]), (1e-8, &j3, &jd3, &x3[..])] {
        let res = task_residual(j, jd, x, &qdd);
        assert!(res < tol, "residual {res:e}, {diag:?}");
    }
    assert!(diag.iter().all(|d| d.damped == 0 && d.rank == d.rows));
    // the posture in N_L changes no task acceleration (interactive-force-control paper eq. 19, 24)
    let (tau0, _) = solve(&s, &[&l1, &l2, &l3], None);
    let dqdd = s.qdd(&(&tau - &tau0));
    assert!((&tau - &tau0).norm() > 1.0, "the posture does act");
    for (tol, j) in [(1e-9, &j1), (1e-8, &j2), (1e-8, &j3)] {
        assert!((j * &dqdd).amax() < tol, "{:e}", (j * &dqdd).amax());
    }
}

#[test]
fn hierarchy_posture_in_last_null_space_does_not_change_tasks_planar7() {
    let s = State::new("planar7.urdf", &P7_BENT, &P7_QD);
    let (j1, jd1) = s.task("ee", [0.0; 3], &[0, 1, 5]);
    let (j2, jd2) = s.task("link3", [0.25, 0.0, 0.0], &XY);
    let l1 = acc_level("ee_pose", &j1, &jd1, &[0.1, 0.2, -0.5]);
    let l2 = acc_level("link3", &j2, &jd2, &[0.3, 0.3]);
    let (t0, _) = solve(&s, &[&l1, &l2], None);
    let posture = [10.0, -20.0, 5.0, 30.0, -7.0, 3.0, 1.0];
    let (t1, _) = solve(&s, &[&l1, &l2], Some(&posture));
    let dqdd = s.qdd(&(&t1 - &t0));
    assert!(dqdd.norm() > 1e-2);
    assert!((&j1 * &dqdd).amax() < 1e-9 && (&j2 * &dqdd).amax() < 1e-9);
}

#[test]
fn hierarchy_one_level_equals_operational_space_control() {
    let model = load("tomm.urdf");
    let (q, qd) = tomm_q(model.nv());
    let s = State::new("tomm.urdf", &q, &qd);
    let (j, jd) = s.point("right_hand", [0.0, 0.0, 0.05]);
    let x = [0.3, -0.2, 0.1, 0.5, -0.4, 0.2];
    let (tau, _) = solve(&s, &[&acc_level("hand", &j, &jd, &x)], None);
    let minv = s.m.clone().try_inverse().unwrap();
    let lambda = (&j * &minv * j.transpose()).try_inverse().unwrap();
    let osc = j.transpose() * lambda * (DVector::from_column_slice(&x) - &jd);
    assert!((&tau - &osc).norm() < 1e-9 * osc.norm(), "|tau − J^T Λ (ẍ* − J̇q̇)| = {}", (&tau - &osc).norm());
}

#[test]
fn hierarchy_duplicated_rows_act_as_least_squares() {
    let s = State::new("planar7.urdf", &P7_BENT, &P7_QD);
    let (j, jd) = s.task("ee", [0.0; 3], &XY);
    let mut l = TaskLevel::new("stacked_cells", 7, 4);
    // two identical cells: the x references disagree (1 and 2), the y references agree
    l.push(&j, Reference::Acceleration { xdd_star: &[1.0, 0.5], jdot_qdot: jd.as_slice() }).unwrap();
    l.push(&j, Reference::Acceleration { xdd_star: &[2.0, 0.5], jdot_qdot: jd.as_slice() }).unwrap();
    let (tau, diag) = solve(&s, &[&l], None);
    assert!(tau.iter().all(|t| t.is_finite()));
    assert_eq!((diag[0].rows, diag[0].rank), (4, 2));
    let qdd = s.qdd(&tau);
    assert!(task_residual(&j, &jd, &[1.5, 0.5], &qdd) < 1e-9, "mean of the duplicated references");
}

#[test]
fn hierarchy_dependent_and_zero_levels_contribute_nothing() {
    let s = State::new("planar7.urdf", &P7_BENT, &P7_QD);
    let (j1, jd1) = s.task("ee", [0.0; 3], &XY);
    let x1 = [0.5, -0.3];
    let l1 = acc_level("ee", &j1, &jd1, &x1);
    let (t_ref, _) = solve(&s, &[&l1], None);
    // the x row of level 1 again, with another reference: linearly dependent on level 1
    let (jx, jdx) = s.task("ee", [0.0; 3], &[0]);
    let dep = acc_level("ee_x_again", &jx, &jdx, &[7.0]);
    // a world-fixed point: zero Jacobian, absurd reference
    let (j0, jd0) = s.task("base", [0.1, 0.0, 0.0], &XY);
    assert_eq!(j0.amax(), 0.0);
    let zero = acc_level("no_active_cell", &j0, &jd0, &[1e6, -1e6]);
    let empty = TaskLevel::new("empty", 7, 3);
    let (tau, diag) = solve(&s, &[&empty, &l1, &zero, &dep], None);
    assert_eq!(diag.iter().map(|d| d.rank).collect::<Vec<_>>(), vec![0, 2, 0, 0]);
    assert!((&tau - &t_ref).amax() < 1e-9 * t_ref.amax(), "dependent/zero/empty levels changed the torque");
    assert!(task_residual(&j1, &jd1, &x1, &s.qdd(&tau)) < 1e-9);
    // and the zero level leaves the null space usable: a posture still moves the arm
    let (tp, _) = solve(&s, &[&l1, &zero], Some(&[1.0; 7]));
    assert!((&tp - &t_ref).norm() > 1e-3);
}

/// `‖τ̄‖ ≤ 1.03 √(λ_max(M)/damping) ‖r‖`, the bound of the filtered inverse (docs/hierarchy.md).
fn torque_bound(s: &State, r_norm: f64) -> f64 {
    1.03 * (s.max_eig_m() / InverseParams::default().damping).sqrt() * r_norm
}

#[test]
fn hierarchy_planar7_stretched_is_finite_and_bounded() {
    let qd = [0.0; 7];
    let s = State::new("planar7.urdf", &[0.0; 7], &qd);
    let (j, jd) = s.task("ee", [0.0; 3], &XY);
    assert!(j.row(0).amax() < 1e-12, "stretched along x: no radial velocity");
    let x = [1.0, 1.0];
    let (tau, diag) = solve(&s, &[&acc_level("ee", &j, &jd, &x)], None);
    assert!(tau.iter().all(|t| t.is_finite()));
    assert_eq!(diag[0].rank, 1);
    let r = (DVector::from_column_slice(&x) - &jd).norm();
    assert!(tau.norm() <= torque_bound(&s, r), "{} > {}", tau.norm(), torque_bound(&s, r));
    eprintln!("planar7 stretched: |tau| = {:.3}, bound {:.3}, {:?}", tau.norm(), torque_bound(&s, r), diag[0]);
    // the tangential direction is still achieved exactly
    let qdd = s.qdd(&tau);
    assert!(((&j * &qdd)[1] + jd[1] - 1.0).abs() < 1e-9);
}

#[test]
fn hierarchy_tomm_ur5_elbow_and_wrist_singular_is_finite_and_bounded() {
    let model = load("tomm.urdf");
    let n = model.nv();
    let mut q = vec![0.0; n];
    for (name, v) in [
        ("right_shoulder_lift_joint", -1.0),
        ("right_elbow_joint", 0.0),
        ("right_wrist_1_joint", -0.5),
        ("right_wrist_2_joint", 0.0),
    ] {
        q[model.joint_index(name).unwrap()] = v;
    }
    let qd = vec![0.0; n];
    let s = State::new("tomm.urdf", &q, &qd);
    // level 1 locks the base joints (q̈ = 0), level 2 is the 6-D hand task of the right UR5
    let base: Vec<usize> =
        ["base_x_joint", "base_y_joint", "base_yaw_joint"].iter().map(|j| model.joint_index(j).unwrap()).collect();
    let mut jb = DMatrix::zeros(3, n);
    for (r, &c) in base.iter().enumerate() {
        jb[(r, c)] = 1.0;
    }
    let lock = acc_level("base_lock", &jb, &DVector::zeros(3), &[0.0; 3]);
    let (j, jd) = s.point("right_hand", [0.0; 3]);
    let x = [0.5, -0.5, 0.5, 1.0, -1.0, 1.0];
    let hand = acc_level("hand", &j, &jd, &x);
    let (t1, _) = solve(&s, &[&lock], None);
    let (tau, diag) = solve(&s, &[&lock, &hand], None);
    assert!(tau.iter().all(|t| t.is_finite()));
    assert!(diag[1].rank <= 5, "elbow and wrist singular: rank {}", diag[1].rank);
    // level 2's reference as the solver sees it: ẍ* − J̇q̇ − J M⁻¹ τ̄_1
    let r = DVector::from_column_slice(&x) - &jd - &j * s.qdd(&t1);
    let tau2 = &tau - &t1;
    assert!(tau2.norm() <= torque_bound(&s, r.norm()), "{} > {}", tau2.norm(), torque_bound(&s, r.norm()));
    eprintln!("UR5 singular: |tau_2| = {:.3}, bound {:.3}, {:?}", tau2.norm(), torque_bound(&s, r.norm()), diag[1]);
    // the base stays locked
    let qdd = s.qdd(&tau);
    assert!(base.iter().all(|&b| qdd[b].abs() < 1e-9));
}

#[test]
fn hierarchy_absurd_inputs() {
    let s = State::new("planar7.urdf", &P7_BENT, &P7_QD);
    let (j1, jd1) = s.task("ee", [0.0; 3], &XY);
    let big = acc_level("big", &j1, &jd1, &[1e12, -1e12]);
    let (tau, _) = solve(&s, &[&big], Some(&[1e12; 7]));
    assert!(tau.iter().all(|t| t.is_finite()));

    let (j2, jd2) = s.task("link3", [0.0; 3], &XY);
    let nan = acc_level("link3_nan", &j2, &jd2, &[0.0, f64::NAN]);
    let mut solver = HierarchySolver::new(7, 4, 4, InverseParams::default()).unwrap();
    let mut out = DVector::from_element(7, 42.0);
    let err = solver.solve(&s.m, [&big, &nan], None, None, &mut out).unwrap_err();
    assert!(
        matches!(&err, HierarchyError::NonFiniteLevel { level: 1, name, what: "xdd_star", index: 1, value } if name == "link3_nan" && value.is_nan())
    );
    assert!(err.to_string().contains("level 1 (`link3_nan`): xdd_star[1]"), "{err}");
    assert!(out.iter().all(|&t| t == 42.0), "output untouched on error");

    let mut m = s.m.clone();
    m[(2, 3)] = f64::INFINITY;
    let err = solver.solve(&m, [&big], None, None, &mut out).unwrap_err();
    assert!(matches!(err, HierarchyError::NonFiniteMassMatrix { row: 2, col: 3, .. }), "{err}");
    let err = solver.solve(&s.m, [&big], Some(&[0.0; 6]), None, &mut out).unwrap_err();
    assert!(matches!(err, HierarchyError::Dimension { what: "posture torque", expected: 7, got: 6 }), "{err}");
    let mut bias = [0.0; 7];
    bias[4] = f64::NAN;
    let err = solver.solve(&s.m, [&big], None, Some(&bias), &mut out).unwrap_err();
    assert!(matches!(err, HierarchyError::NonFinite { what: "bias", index: 4, .. }), "{err}");
    let err = solver.solve(&-s.m.clone(), [&big], None, None, &mut out).unwrap_err();
    assert!(matches!(err, HierarchyError::NotPositiveDefinite { index: 0, .. }), "{err}");
    // finite inputs whose torque overflows: Λ = 4 kg on a unit mass, ẍ* = f64::MAX
    let mut jh = DMatrix::zeros(1, 7);
    jh[(0, 0)] = 0.5;
    let huge = acc_level("huge", &jh, &DVector::zeros(1), &[f64::MAX]);
    let err = solver.solve(&DMatrix::identity(7, 7), [&huge], None, None, &mut out).unwrap_err();
    assert!(matches!(err, HierarchyError::Overflow { level: 0 }), "{err}");
    assert!(InverseParams { damping: -1.0, ..Default::default() }.validate().is_err());
}

#[test]
fn hierarchy_torque_is_continuous_through_the_singularity() {
    // planar7 bent only at joint 4, swept from 0.1 rad to exactly 0 (stretched); EE xy level
    // with a fixed reference that has a radial component, plus a posture torque
    let model = load("planar7.urdf");
    let mut data = ModelData::new(&model);
    let ee = model.frame_index("ee").unwrap();
    let sweep = |steps: usize, params: InverseParams, data: &mut ModelData| -> Vec<DVector<f64>> {
        let mut solver = HierarchySolver::new(7, 1, 2, params).unwrap();
        let (mut m, mut j, mut jd) = (DMatrix::zeros(7, 7), Matrix6xX::zeros(7), Vector6::zeros());
        let mut level = TaskLevel::new("ee", 7, 2);
        (0..=steps)
            .map(|i| {
                let mut q = [0.0; 7];
                q[3] = 0.1 * (1.0 - i as f64 / steps as f64);
                update_kinematics(&model, data, &q, &[0.0; 7]).unwrap();
                crba(&model, data, &mut m).unwrap();
                point_jacobian(&model, data, ee, &Vector3::zeros(), &mut j).unwrap();
                point_jacobian_dot_qdot(&model, data, ee, &Vector3::zeros(), &mut jd).unwrap();
                let jd_xy = [jd[0], jd[1]];
                level.set(&j.rows(0, 2), Reference::Acceleration { xdd_star: &[1.0, 0.5], jdot_qdot: &jd_xy }).unwrap();
                let mut tau = DVector::zeros(7);
                solver.solve(&m, [&level], Some(&[0.5, -0.5, 0.5, -0.5, 0.5, -0.5, 0.5]), None, &mut tau).unwrap();
                tau
            })
            .collect()
    };
    let stats = |taus: &[DVector<f64>]| {
        let max_norm = taus.iter().map(|t| t.norm()).fold(0.0, f64::max);
        let max_jump = taus.windows(2).map(|w| (&w[1] - &w[0]).norm()).fold(0.0, f64::max);
        (max_norm, max_jump)
    };
    let (max_norm, jump_1000) = stats(&sweep(1000, InverseParams::default(), &mut data));
    let (_, jump_4000) = stats(&sweep(4000, InverseParams::default(), &mut data));
    // 1e-4 rad per step: the torque moves by at most 2 % of its scale per step ...
    assert!(jump_1000 < 0.02 * max_norm, "jump {jump_1000} vs scale {max_norm}");
    // ... and the largest jump shrinks with the step (Lipschitz, no jump at the rank change)
    assert!(jump_4000 < 0.35 * jump_1000, "jumps {jump_1000} (1e-4 rad) vs {jump_4000} (2.5e-5 rad)");
    // without damping the plain (thresholded) inverse blows up near the singularity
    let (plain_max, _) = stats(&sweep(1000, InverseParams { damping: 0.0, ..Default::default() }, &mut data));
    assert!(plain_max > 20.0 * max_norm, "plain {plain_max} vs damped {max_norm}");
    eprintln!(
        "sweep: damped max |tau| = {max_norm:.3}, max jump {jump_1000:.3e} (1e-4 rad steps), {jump_4000:.3e} (2.5e-5 rad); plain max |tau| = {plain_max:.3e}"
    );
}

#[test]
fn hierarchy_force_level_composes_with_acceleration_levels() {
    let s = State::new("planar7.urdf", &P7_BENT, &P7_QD);
    let n = 7;
    // intentional-contact paper eq. 3-4: a repulsive force along a skin cell normal on link 3
    let (jc, _) = s.point("link3", [0.15, 0.02, 0.0]);
    let normal = [0.0, 1.0, 0.0];
    let mut avoid = TaskLevel::new("avoidance", n, 4);
    avoid.push_directional(&normal, &jc.rows(0, 3), Reference::Force { f: &[5.0] }).unwrap();
    let jn = jc.rows(0, 3).transpose() * DVector::from_column_slice(&normal); // J_cᵀ n (n × 1)
    let (j1, jd1) = s.task("ee", [0.0; 3], &XY);
    let x1 = [0.5, -0.3];
    let goal = acc_level("goal", &j1, &jd1, &x1);

    // force on top: its torque is J_cᵀ F unprojected, the goal compensates its acceleration
    let (tau, diag) = solve(&s, &[&avoid, &goal], None);
    assert!((diag[0].torque_norm - 5.0 * jn.norm()).abs() < 1e-12);
    assert_eq!(diag[0].task_error, None);
    assert!(task_residual(&j1, &jd1, &x1, &s.qdd(&tau)) < 1e-9);
    // the goal's torque does not change the acceleration along the cell normal (N_1 projection)
    let tau_goal = &tau - &jn * 5.0;
    assert!((jn.transpose() * s.qdd(&tau_goal))[0].abs() < 1e-9);

    // goal on top: the force torque is N_1 J_cᵀ F (augmented projection, intentional-contact paper / Dietrich)
    let (t_goal, _) = solve(&s, &[&goal], None);
    let (tau, _) = solve(&s, &[&goal, &avoid], None);
    let minv = s.m.clone().try_inverse().unwrap();
    let lam1 = (&j1 * &minv * j1.transpose()).try_inverse().unwrap();
    let n1 = DMatrix::identity(n, n) - j1.transpose() * lam1 * &j1 * &minv;
    let expected = &n1 * &jn * 5.0;
    assert!((&tau - &t_goal - &expected).norm() < 1e-9 * expected.norm().max(1.0));
    assert!(task_residual(&j1, &jd1, &x1, &s.qdd(&tau)) < 1e-9, "the force does not disturb the goal");
    // the same levels through an arrangement order (indices), no reordering of storage
    let levels = [avoid, goal];
    let order = [1usize, 0];
    let mut solver = HierarchySolver::new(n, 2, 4, InverseParams::default()).unwrap();
    let mut t2 = DVector::zeros(n);
    solver.solve(&s.m, order.iter().map(|&i| &levels[i]), None, None, &mut t2).unwrap();
    assert!((&t2 - &tau).norm() < 1e-12);
}

#[test]
fn hierarchy_bias_is_added_when_asked() {
    let s = State::new("planar7.urdf", &P7_BENT, &P7_QD);
    let (j1, jd1) = s.task("ee", [0.0; 3], &XY);
    let l1 = acc_level("ee", &j1, &jd1, &[0.5, -0.3]);
    let mut solver = HierarchySolver::new(7, 1, 2, InverseParams::default()).unwrap();
    let (mut a, mut b) = (DVector::zeros(7), DVector::zeros(7));
    let bias: Vec<f64> = (0..7).map(|i| i as f64).collect();
    solver.solve(&s.m, [&l1], None, None, &mut a).unwrap();
    solver.solve(&s.m, [&l1], None, Some(&bias), &mut b).unwrap();
    assert!((&b - &a - DVector::from_vec(bias)).amax() < 1e-12);
    // levels with the wrong column count or too many rows are rejected with their name
    let wrong = TaskLevel::new("wrong", 6, 2);
    assert!(matches!(
        solver.solve(&s.m, [&wrong], None, None, &mut a),
        Err(HierarchyError::LevelColumns { level: 0, .. })
    ));
    let mut l = TaskLevel::new("small", 7, 1);
    let err = l.push(&j1, Reference::Force { f: &[1.0, 2.0] }).unwrap_err();
    assert!(err.to_string().contains("small"), "{err}");
    let err = l.push(&j1, Reference::Force { f: &[1.0] }).unwrap_err();
    assert!(err.to_string().contains("reference lengths"), "{err}");
}

#[test]
fn hierarchy_solve_model_matches_solve() {
    let model = load("tomm.urdf");
    let (q, qd) = tomm_q(model.nv());
    let s = State::new("tomm.urdf", &q, &qd);
    let n = s.n();
    let (j, jd) = s.point("right_hand", [0.0; 3]);
    let level = acc_level("hand", &j, &jd, &[0.1, 0.2, 0.3, 0.0, 0.0, 0.1]);
    let mut bias = DVector::zeros(n);
    let mut data = ModelData::new(&model);
    update_kinematics(&model, &mut data, &q, &qd).unwrap();
    bias_forces(&model, &mut data, &mut bias).unwrap();
    let posture = vec![1.0; n];
    let mut solver = HierarchySolver::new(n, 1, 6, InverseParams::default()).unwrap();
    let (mut a, mut b) = (DVector::zeros(n), DVector::zeros(n));
    solver.solve(&s.m, [&level], Some(&posture), Some(bias.as_slice()), &mut a).unwrap();
    solver.solve_model(&model, &mut data, [&level], Some(&posture), true, &mut b).unwrap();
    assert!((&a - &b).amax() < 1e-12);
    solver.solve_model(&model, &mut data, [&level], Some(&posture), false, &mut b).unwrap();
    assert!((&a - &b - &bias).amax() < 1e-12);
}

/// Interactive-force-control paper eq. (19)-(25) written literally with nalgebra (m × m inverses by `SymmetricEigen`
/// and the same eigenvalue filter): the reference for the solver's fast paths.
fn reference_solve(m: &DMatrix<f64>, levels: &[(DMatrix<f64>, DVector<f64>, bool)], p: &InverseParams) -> DVector<f64> {
    let n = m.nrows();
    let minv = m.clone().try_inverse().unwrap();
    let mut nproj = DMatrix::<f64>::identity(n, n);
    let mut tau = DVector::zeros(n);
    for (j, x, is_force) in levels {
        let jb = j * nproj.transpose();
        let a = &jb * &minv * jb.transpose();
        let a = (&a + a.transpose()) * 0.5;
        let eig = SymmetricEigen::new(a);
        let thr = p.threshold(eig.eigenvalues.max());
        let f = DMatrix::from_diagonal(&eig.eigenvalues.map(|e| p.filter(e, thr)));
        let lam = &eig.eigenvectors * f * eig.eigenvectors.transpose();
        let s = if *is_force { x.clone() } else { &lam * (x - j * &minv * &tau) };
        tau += jb.transpose() * s;
        nproj = &nproj * (DMatrix::identity(n, n) - jb.transpose() * &lam * &jb * &minv);
    }
    tau
}

/// A level with more rows than joints (50 stacked cell rows of rank 1, then 40 random rows)
/// takes the joint-space path; it must equal the literal m × m formulation, for force and
/// acceleration references, below a narrow level, and stay within the torque bound for 1e6 N.
#[test]
fn hierarchy_wide_levels_match_the_literal_formulation() {
    let model = load("tomm.urdf");
    let (q, qd) = tomm_q(model.nv());
    let s = State::new("tomm.urdf", &q, &qd);
    let n = s.n();
    let (j1, jd1) = s.task("right_hand", [0.0; 3], &[0, 1, 2]);
    let x1 = [0.3, -0.2, 0.1];
    let l1 = acc_level("hand", &j1, &jd1, &x1);
    let (jc, _) = s.task("right_forearm_link", [-0.1, 0.05, 0.02], &[0, 1, 2]);
    let row = jc.row(1).into_owned();
    let mut rng = 7u64;
    let mut rand = move || {
        rng = rng.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((rng >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    };
    for (force, rows, scale) in [(true, 50, 1e6), (true, 90, 5.0), (false, 90, 1.0)] {
        let mut j2 = DMatrix::zeros(rows, n);
        for r in 0..rows {
            if r < 50 {
                j2.set_row(r, &row); // rank 1: the same cell row 50 times
            } else {
                j2.set_row(r, &DMatrix::from_fn(1, n, |_, _| rand()).row(0));
            }
        }
        let x2 = DVector::from_fn(rows, |_, _| scale * (0.5 + rand()));
        let mut l2 = TaskLevel::new("cells", n, rows);
        let reference = if force {
            Reference::Force { f: x2.as_slice() }
        } else {
            Reference::Acceleration { xdd_star: x2.as_slice(), jdot_qdot: &vec![0.0; rows] }
        };
        l2.set(&j2, reference).unwrap();
        let (tau, diag) = solve(&s, &[&l1, &l2], None);
        assert!(tau.iter().all(|t| t.is_finite()));
        let x1v = DVector::from_column_slice(&x1) - &jd1;
        let want = reference_solve(
            &s.m,
            &[(j1.clone(), x1v, false), (j2.clone(), x2.clone(), force)],
            &InverseParams::default(),
        );
        let err = (&tau - &want).amax() / want.amax().max(1.0);
        assert!(err < 1e-8, "rows {rows}, force {force}: relative difference {err:e}");
        if rows == 50 {
            assert_eq!(diag[1].rank, 1, "50 copies of one row have rank 1");
        }
    }
    // two wide levels in one solve (they share this solve's L and L⁻¹): 30 rows of rank 5, then
    // 40 random rows that get the directions left
    let basis = DMatrix::from_fn(5, n, |_, _| rand());
    let ja = DMatrix::from_fn(30, 5, |_, _| rand()) * &basis;
    let jb = DMatrix::from_fn(40, n, |_, _| rand());
    let (fa, fb) = (DVector::from_fn(30, |_, _| rand()), DVector::from_fn(40, |_, _| rand()));
    let (mut la, mut lb) = (TaskLevel::new("wide a", n, 30), TaskLevel::new("wide b", n, 40));
    la.set(&ja, Reference::Force { f: fa.as_slice() }).unwrap();
    lb.set(&jb, Reference::Force { f: fb.as_slice() }).unwrap();
    let (tau, diag) = solve(&s, &[&l1, &la, &lb], None);
    let x1v = DVector::from_column_slice(&x1) - &jd1;
    let want =
        reference_solve(&s.m, &[(j1.clone(), x1v, false), (ja, fa, true), (jb, fb, true)], &InverseParams::default());
    let err = (&tau - &want).amax() / want.amax().max(1.0);
    assert!(err < 1e-8, "two wide levels: relative difference {err:e}");
    assert_eq!((diag[1].rank, diag[2].rank), (5, n - 8), "rank 5, then what the hand and the first level left");
}

/// Levels of the strict-priority property: (link, point, Jacobian rows) per level.
const P7_LEVELS: [(&str, [f64; 3], &[usize]); 3] =
    [("ee", [0.0; 3], &[0, 1]), ("link4", [0.1, 0.0, 0.0], &[0, 1]), ("link2", [0.2, 0.0, 0.0], &[1])];
const TOMM_LEVELS: [(&str, [f64; 3], &[usize]); 4] = [
    ("right_hand", [0.0; 3], &[3, 4, 5]),
    ("right_hand", [0.0; 3], &[0, 1, 2]),
    ("left_hand", [0.0; 3], &[0, 1, 2]),
    ("right_forearm_link", [-0.2, 0.0, 0.05], &[2]),
];

/// Strict priority (interactive-force-control paper eq. 19-25): the acceleration `J_i q̈ + J̇_i q̇` level `i` gets is the
/// same (to 1e-9 relative to the round-off scale below) whether the levels below it (and the posture) are there or not. Random non-singular
/// states (states where a level loses rank or enters the damping band are skipped: there the
/// hierarchy deliberately trades accuracy for boundedness) and random references.
fn strict_priority_case(
    file: &str,
    spec: &[(&str, [f64; 3], &[usize])],
    u: &[f64],
    refs: &[f64],
) -> Result<(), TestCaseError> {
    let model = load(file);
    let n = model.nv();
    let q: Vec<f64> = model
        .joint_limits()
        .iter()
        .zip(u)
        .map(|(l, u)| {
            let (lo, hi) = (l.lower.max(-3.1), l.upper.min(3.1));
            lo + u * (hi - lo)
        })
        .collect();
    let qd: Vec<f64> = u[n..2 * n].iter().map(|v| v - 0.5).collect();
    let s = State::new(file, &q, &qd);
    let mut levels = Vec::new();
    let mut tasks = Vec::new();
    let mut r = refs.iter();
    for (k, (link, p, rows)) in spec.iter().enumerate() {
        let (j, jd) = s.task(link, *p, rows);
        let x: Vec<f64> = rows.iter().map(|_| 4.0 * r.next().unwrap()).collect();
        levels.push(acc_level(&format!("level{k}"), &j, &jd, &x));
        tasks.push((j, jd));
    }
    let posture: Vec<f64> = (0..n).map(|_| 20.0 * r.next().unwrap()).collect();
    let refs: Vec<&TaskLevel> = levels.iter().collect();
    let (full, diag) = solve(&s, &refs, Some(&posture));
    // proptest counts the skipped states and fails if they exceed its reject limit
    prop_assume!(diag.iter().all(|d| d.damped == 0 && d.rank == d.rows));
    let qdd_full = s.qdd(&full);
    for i in 0..levels.len() {
        let (upper, _) = solve(&s, &refs[..=i], None);
        let qdd_upper = s.qdd(&upper);
        let (j, _) = &tasks[i];
        let diff = (j * (&qdd_full - &qdd_upper)).amax();
        // Round-off scale: the acceleration the lower levels' torque Δτ could give level i
        // without the projection, ‖J_i M⁻¹‖ ‖Δτ‖ (large for TOMM's light wrists: M⁻¹ ~ 1e4),
        // and the level's own acceleration; floor 1.
        let minv = s.m.clone().try_inverse().unwrap();
        let reach = (j * minv).norm() * (&full - &upper).norm();
        let scale = (j * &qdd_full).amax().max(reach).max(1.0);
        prop_assert!(
            diff <= 1e-9 * scale,
            "{file}: level {i} acceleration changed by {diff:e} (scale {scale:e}) by the levels below"
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    #[test]
    fn hierarchy_strict_priority_property_planar7(
        u in prop::collection::vec(0.0..1.0f64, 14),
        refs in prop::collection::vec(-1.0..1.0f64, 5 + 7),
    ) {
        strict_priority_case("planar7.urdf", &P7_LEVELS, &u, &refs)?;
    }

    #[test]
    fn hierarchy_strict_priority_property_tomm(
        u in prop::collection::vec(0.0..1.0f64, 30),
        refs in prop::collection::vec(-1.0..1.0f64, 10 + 15),
    ) {
        strict_priority_case("tomm.urdf", &TOMM_LEVELS, &u, &refs)?;
    }
}

/// Two skin force rows on links 3 and 5 of planar7 (activations `a`) above an acceleration goal.
fn activated_case(s: &State, a: [f64; 2]) -> (DVector<f64>, DMatrix<f64>) {
    let n = s.n();
    let mut skin = TaskLevel::new("avoidance", n, 2);
    for ((link, f), a) in [("link3", 4.0), ("link5", 2.0)].into_iter().zip(a) {
        let (jc, _) = s.point(link, [0.1, 0.02, 0.0]);
        skin.push_row_activated(jc.row(1).transpose().as_slice(), f, a).unwrap();
        // direction +y
    }
    let (j1, jd1) = s.task("ee", [0.0; 3], &XY);
    let goal = acc_level("goal", &j1, &jd1, &[0.5, -0.3]);
    let mut solver = HierarchySolver::new(n, 2, 2, InverseParams::default()).unwrap();
    let mut tau = DVector::zeros(n);
    solver.solve(&s.m, [&skin, &goal], None, None, &mut tau).unwrap();
    (tau, solver.null_space())
}

#[test]
fn hierarchy_activated_rows_are_exact_at_the_ends_and_continuous_between() {
    let s = State::new("planar7.urdf", &P7_BENT, &P7_QD);
    let n = s.n();
    // a = 1 for both: the plain force level (augmented projector of both rows)
    let (t_on, _) = activated_case(&s, [1.0, 1.0]);
    let mut plain = TaskLevel::new("avoidance", n, 2);
    for (link, f) in [("link3", 4.0), ("link5", 2.0)] {
        let (jc, _) = s.point(link, [0.1, 0.02, 0.0]);
        plain.push_directional(&[0.0, 1.0, 0.0], &jc.rows(0, 3), Reference::Force { f: &[f] }).unwrap();
    }
    let (j1, jd1) = s.task("ee", [0.0; 3], &XY);
    let goal = acc_level("goal", &j1, &jd1, &[0.5, -0.3]);
    let (t_plain, _) = solve(&s, &[&plain, &goal], None);
    assert!((&t_on - &t_plain).norm() < 1e-9 * t_plain.norm(), "{t_on} vs {t_plain}");
    // a = 0 for the second row: the projector is that of the first row alone (its force acts)
    let skin_only = |a: [f64; 2]| {
        let mut skin = TaskLevel::new("avoidance", n, 2);
        for ((link, f), a) in [("link3", 4.0), ("link5", 2.0)].into_iter().zip(a) {
            let (jc, _) = s.point(link, [0.1, 0.02, 0.0]);
            skin.push_row_activated(jc.row(1).transpose().as_slice(), f, a).unwrap();
            // direction +y
        }
        let mut solver = HierarchySolver::new(n, 1, 2, InverseParams::default()).unwrap();
        let mut tau = DVector::zeros(n);
        solver.solve(&s.m, [&skin], None, None, &mut tau).unwrap();
        (tau, solver.null_space())
    };
    let (t_skin, n_half) = skin_only([1.0, 0.0]);
    let mut one = TaskLevel::new("avoidance", n, 2);
    let (jc3, _) = s.point("link3", [0.1, 0.02, 0.0]);
    one.push_directional(&[0.0, 1.0, 0.0], &jc3.rows(0, 3), Reference::Force { f: &[4.0] }).unwrap();
    let mut solver = HierarchySolver::new(n, 1, 2, InverseParams::default()).unwrap();
    let mut t_one = DVector::zeros(n);
    solver.solve(&s.m, [&one], None, None, &mut t_one).unwrap();
    assert!((&n_half - solver.null_space()).norm() < 1e-9);
    let (jc5, _) = s.point("link5", [0.1, 0.02, 0.0]);
    let jn5 = jc5.rows(0, 3).transpose() * DVector::from_column_slice(&[0.0, 1.0, 0.0]);
    assert!((&t_skin - (&t_one + &jn5 * 2.0)).norm() < 1e-9 * t_one.norm(), "the force acts whatever a is");
    let (t_half, _) = activated_case(&s, [1.0, 0.0]);
    // the goal is met exactly at the ends (inside the fade a projector is not idempotent, so the
    // lower level is met only approximately there: the sweep below checks continuity)
    for a in [[1.0, 1.0], [1.0, 0.0], [0.0, 0.0]] {
        let (t, _) = activated_case(&s, a);
        assert!(task_residual(&j1, &jd1, &[0.5, -0.3], &s.qdd(&t)) < 1e-9);
    }
    // sweeping a_2 from 1 to 0: the projector moves linearly in a_2 (equal steps), the torque in
    // steps of the order of the whole change over the number of steps: no jump
    let steps = 200;
    let (t_end, _) = activated_case(&s, [1.0, 0.0]);
    let (n_one, n_end) = (skin_only([1.0, 1.0]).1, skin_only([1.0, 0.0]).1);
    let (dt_total, dn_total) = ((&t_end - &t_on).norm(), (&n_end - &n_one).norm());
    assert!(dn_total > 1e-3, "the second row does change the projector");
    let (mut t_prev, mut n_prev) = (t_on, n_one);
    for k in 1..=steps {
        let a2 = 1.0 - k as f64 / steps as f64;
        let (t, _) = activated_case(&s, [1.0, a2]);
        let np = skin_only([1.0, a2]).1;
        assert!((&np - &n_prev).norm() <= 1.000001 * dn_total / steps as f64, "projector step at a = {a2}");
        assert!((&t - &t_prev).norm() <= 5.0 * dt_total / steps as f64 + 1e-9, "torque step at a = {a2}");
        (t_prev, n_prev) = (t, np);
    }
    assert!((&t_prev - &t_half).norm() < 1e-12);
}

/// Locked joints (TOMM's base switched off): the solve equals the literal hierarchy on the free
/// joints' dynamics `M_ff` and Jacobian columns, and the locked joints get no torque.
#[test]
fn hierarchy_locked_joints_solve_the_free_joints_exactly() {
    let model = load("tomm.urdf");
    let n = model.nv();
    let (q, qd) = tomm_q(n);
    let mut data = ModelData::new(&model);
    update_kinematics(&model, &mut data, &q, &qd).unwrap();
    let s = State::new("tomm.urdf", &q, &qd);
    let locked: Vec<bool> = (0..n).map(|j| j < 3).collect(); // base x, y, yaw
    let free: Vec<usize> = (3..n).collect();
    let (j1, jd1) = s.task("right_hand", [0.0; 3], &[0, 1, 2]);
    let (j2, jd2) = s.task("left_hand", [0.0; 3], &[3, 4, 5]);
    let (x1, x2) = ([0.3, -0.1, 0.2], [0.1, 0.2, -0.3]);
    let mut l1 = acc_level("right", &j1, &jd1, &x1);
    let mut l2 = acc_level("left", &j2, &jd2, &x2);
    l1.lock_joints(&locked);
    l2.lock_joints(&locked);
    let mut solver = HierarchySolver::new(n, 4, 6, InverseParams::default()).unwrap();
    solver.set_locked_joints(&locked).unwrap();
    let mut tau = DVector::zeros(n);
    solver.solve_model(&model, &mut data, [&l1, &l2], None, false, &mut tau).unwrap();
    assert!(tau.rows(0, 3).iter().all(|&t| t == 0.0), "no torque on locked joints: {tau}");
    let m_ff = s.m.select_rows(&free).select_columns(&free);
    let want = reference_solve(
        &m_ff,
        &[
            (j1.select_columns(&free), DVector::from_column_slice(&x1) - &jd1, false),
            (j2.select_columns(&free), DVector::from_column_slice(&x2) - &jd2, false),
        ],
        &InverseParams::default(),
    );
    let err = (tau.rows(3, n - 3) - &want).amax() / want.amax();
    assert!(err < 1e-9, "relative difference to the reduced hierarchy {err:e}");
}

/// The projection leak (docs/controller.md, `hierarchy_dynamics`): the resolver executes a
/// torque as `C_a q̇ = τ* − g` (steady velocity of eq. 26) with `C_a ∝ M_a`. A force level below
/// the intentional-contact goal, projected with the model's `M(q)`, moves the goal point in that
/// executed motion; projected with the resolver's inertia `M_a` (`admittance_inertia`) it does not.
#[test]
fn a_lower_force_level_moves_the_goal_only_when_projected_with_another_inertia_than_executed() {
    let s = State::new("planar7.urdf", &P7_BENT, &P7_QD);
    let n = 7;
    let (j1, _) = s.task("ee", [0.0; 3], &XY);
    let mut goal = TaskLevel::new("goal", n, 2);
    goal.set(&j1, Reference::Force { f: &[3.0, -2.0] }).unwrap();
    let (jc, _) = s.point("link3", [0.15, 0.02, 0.0]);
    let mut contact = TaskLevel::new("contact_reaction", n, 4);
    contact.push_directional(&[0.0, -1.0, 0.0], &jc.rows(0, 3), Reference::Force { f: &[10.0] }).unwrap();
    let damping = 10.0; // C_a, and M_a = C_a / 20 as in config/resolver.yaml
    let m_a = DMatrix::identity(n, n) * (damping / 20.0);
    // the goal point's steady velocity J_1 C_a⁻¹ τ due to the lower level alone
    let leak = |m: &DMatrix<f64>| {
        let mut solver = HierarchySolver::new(n, 2, 4, InverseParams::default()).unwrap();
        let (mut both, mut top) = (DVector::zeros(n), DVector::zeros(n));
        solver.solve(m, [&goal, &contact], None, None, &mut both).unwrap();
        solver.solve(m, [&goal], None, None, &mut top).unwrap();
        (&j1 * (both - top) / damping).norm()
    };
    let goal_speed = (&j1 * j1.transpose() * DVector::from_column_slice(&[3.0, -2.0]) / damping).norm();
    assert!(leak(&s.m) > 0.05 * goal_speed, "with M(q): {} vs {goal_speed} m/s", leak(&s.m));
    assert!(leak(&m_a) < 1e-9 * goal_speed, "with M_a: {} m/s", leak(&m_a));
}
