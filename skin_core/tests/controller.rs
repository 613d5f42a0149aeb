//! The whole controller at the extremes (property tests on TOMM and planar7): exactly singular
//! arms, skin readings that are NaN, infinite, negative or 1e6, every cell of a patch active at
//! once, absurd goals and laser points, NaN state and time step. Every cycle's commands must be
//! finite and within the velocity and acceleration limits. And the blend across an arrangement
//! switch: no step at the switch, per-cycle change within the bound of `docs/supervisor.md`.

use std::path::PathBuf;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector2, Vector3};
use proptest::prelude::*;
use skin_core::controller::*;
use skin_core::skin::signals::CellReading;
use skin_core::supervisor::{Mode, Phase, Policy};

const DT: f64 = 0.008;

fn config(robot: &str) -> ControllerConfig {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../config/controller/{robot}.yaml"));
    ControllerConfig::load(&path).unwrap()
}

/// A reading value: mostly in range, often absurd.
fn signal() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => 0.0..=1.0f64,
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(1e6),
        1 => Just(-3.0),
    ]
}

/// One scenario: the initial state (`singular` picks an exactly singular one), a skin pattern
/// (random cells, or every cell of one patch), the goal, laser points and a few NaN events.
#[derive(Debug, Clone)]
struct Case {
    q_unit: Vec<f64>,
    qd: Vec<f64>,
    singular: bool,
    cells: Vec<(usize, [f64; 4])>,
    whole_patch: Option<usize>,
    goal: [f64; 3],
    scan: Vec<(f64, f64)>,
    nan_state_cycle: Option<usize>,
    nan_dt_cycle: Option<usize>,
    phase_switch_cycle: Option<usize>,
}

fn case(nv: usize, ncells: usize) -> impl Strategy<Value = Case> {
    (
        prop::collection::vec(0.0..1.0f64, nv),
        prop::collection::vec(-1.0..1.0f64, nv),
        any::<bool>(),
        prop::collection::vec((0..ncells, [signal(), signal(), signal(), signal()]), 0..60),
        prop::option::of(0..12usize),
        prop_oneof![Just([1e6, -1e6, 1e6]), [-2.0..2.0f64, -2.0..2.0f64, 0.0..2.0f64]],
        prop::collection::vec(
            (prop_oneof![Just(f64::NAN), Just(0.0), -2.0..2.0f64], prop_oneof![Just(1e9), -2.0..2.0f64]),
            0..40,
        ),
        (prop::option::of(0..20usize), prop::option::of(0..20usize), prop::option::of(0..20usize)),
    )
        .prop_map(
            |(
                q_unit,
                qd,
                singular,
                cells,
                whole_patch,
                goal,
                scan,
                (nan_state_cycle, nan_dt_cycle, phase_switch_cycle),
            )| Case {
                q_unit,
                qd,
                singular,
                cells,
                whole_patch,
                goal,
                scan,
                nan_state_cycle,
                nan_dt_cycle,
                phase_switch_cycle,
            },
        )
}

/// Exactly singular configurations: planar7 stretched; TOMM with both UR5 elbows stretched and
/// wrists aligned (shoulder, elbow and wrist singular at once).
fn singular_q(robot: &str, nv: usize) -> Vec<f64> {
    match robot {
        "planar7" => vec![0.0; nv],
        _ => {
            let mut q = vec![0.0; nv];
            for arm in [3, 9] {
                q[arm + 1] = -1.0;
                q[arm + 4] = 0.0; // wrist 2 at zero: wrist singular
            }
            q
        }
    }
}

fn run_case(robot: &str, policy: Policy, c: &Case) -> Result<(), TestCaseError> {
    let mut cfg = config(robot);
    cfg.supervisor.policy = policy;
    let mut ctl = Controller::new(cfg, 0.0).unwrap();
    let model = ctl.config().model.clone();
    let layout = ctl.config().layout.clone();
    let nv = model.nv();
    let mut q: Vec<f64> = if c.singular {
        singular_q(robot, nv)
    } else {
        let lim = model.joint_limits();
        c.q_unit
            .iter()
            .zip(lim)
            .map(|(u, l)| {
                let (lo, hi) = (l.lower.max(-3.0), l.upper.min(3.0));
                lo + u * (hi - lo)
            })
            .collect()
    };
    let vmax = ctl.resolver().arm_velocity_limits().to_vec();
    let arm = ctl.resolver().arm_joints().to_vec();
    // moving at up to 90 % of the velocity limits (base: 0.3 m/s, rad/s)
    let mut qd: Vec<f64> = c.qd.iter().map(|u| 0.3 * u).collect();
    for (&j, v) in arm.iter().zip(&vmax) {
        qd[j] = 0.9 * v * c.qd[j];
    }
    let mut cells = vec![CellReading::default(); layout.num_cells()];
    for &(i, [a, b, c3, p]) in &c.cells {
        cells[i] = CellReading { force: [a, b, c3], proximity: p };
    }
    if let Some(p) = c.whole_patch {
        let patch = &layout.patches()[p % layout.patches().len()];
        for i in patch.cells.clone() {
            cells[i] = CellReading::uniform(0.9, 0.95);
        }
    }
    let goal = Isometry3::from_parts(Translation3::new(c.goal[0], c.goal[1], c.goal[2]), UnitQuaternion::identity());
    ctl.set_goal(Some(goal)).unwrap();
    let scan: Vec<Vector2<f64>> = c.scan.iter().map(|&(x, y)| Vector2::new(x, y)).collect();
    let amax: Vec<f64> = ctl.resolver().arm_acceleration_limits().collect();
    let base = ctl.config().resolver.base;
    // the first command continues from zero (the last command sent), whatever the robot's motion
    let mut prev = ctl.output().commands.clone();
    for k in 0..20 {
        if Some(k) == c.phase_switch_cycle {
            let _ = ctl.request_phase(Phase::Contact);
        }
        let mut qd_in = qd.clone();
        if Some(k) == c.nan_state_cycle {
            qd_in[k % nv] = f64::NAN;
        }
        let dt = if Some(k) == c.nan_dt_cycle { f64::NAN } else { DT };
        let input = ControllerInput { t_s: k as f64 * DT, dt_s: dt, q: &q, qd: &qd_in, cells: &cells, scan: &scan };
        let out = ctl.update(&input).clone();
        let cmd = &out.commands;
        prop_assert!(ctl.torque().iter().all(|t| t.is_finite()) || out.fault.is_some());
        for (i, &v) in cmd.joint_velocities.iter().enumerate() {
            prop_assert!(v.is_finite(), "{robot}: joint {i} command {v} at cycle {k}");
            prop_assert!(v.abs() <= vmax[i] * (1.0 + 1e-12), "{robot}: joint {i}: {v} over {}", vmax[i]);
            let dv = (v - prev.joint_velocities[i]).abs();
            prop_assert!(
                dv <= amax[i] * DT * (1.0 + 1e-9) + 1e-12,
                "{robot}: joint {i} step {dv} over {}",
                amax[i] * DT
            );
        }
        let [vx, vy, wz] = cmd.base_twist;
        prop_assert!([vx, vy, wz].iter().all(|v| v.is_finite()));
        prop_assert!(vx.hypot(vy) <= base.max_linear_m_s * (1.0 + 1e-12));
        prop_assert!(wz.abs() <= base.max_angular_rad_s * (1.0 + 1e-12));
        // the rate limit holds in the base frame, the frame of the command
        let dv = (vx - prev.base_twist[0]).hypot(vy - prev.base_twist[1]);
        prop_assert!(dv <= base.max_linear_accel_m_s2 * DT * (1.0 + 1e-9) + 1e-12, "base acceleration {dv}");
        let dw = (wz - prev.base_twist[2]).abs();
        prop_assert!(dw <= base.max_angular_accel_rad_s2 * DT * (1.0 + 1e-9) + 1e-12, "base angular acceleration {dw}");
        prev = out.commands.clone();
        // the robot follows its commands
        for (&j, &v) in arm.iter().zip(&cmd.joint_velocities) {
            qd[j] = v;
            q[j] += v * DT;
        }
        if let Some([x, y, yaw]) = ctl.resolver().base_joints() {
            let (s, co) = q[yaw].sin_cos();
            let world = [co * vx - s * vy, s * vx + co * vy, wz];
            for (j, v) in [x, y, yaw].into_iter().zip(world) {
                qd[j] = v;
                q[j] += v * DT;
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(150))]

    #[test]
    fn planar7_commands_stay_finite_and_limited(c in case(7, 405)) {
        run_case("planar7", Policy::IntentionalContact, &c)?;
    }

    #[test]
    fn tomm_commands_stay_finite_and_limited_table_i(c in case(15, 718)) {
        run_case("tomm", Policy::IntentionalContact, &c)?;
    }

    #[test]
    fn tomm_commands_stay_finite_and_limited_phases(c in case(15, 718)) {
        run_case("tomm", Policy::Phases, &c)?;
    }
}

/// Interactive-force-control paper Table 1 precontact -> contact on TOMM with a frozen state: the new arrangement's
/// torque `τ_k` is constant, so by `docs/supervisor.md` the blended torque may change per cycle
/// by at most `δ_t dt ‖τ_{k-1} − τ_k‖`, and the first torque after the switch is the held one.
#[test]
fn arrangement_switch_blends_without_step_within_the_bound() {
    let mut cfg = config("tomm");
    cfg.supervisor.policy = Policy::Phases;
    let delta = cfg.supervisor.smoothing_gain_per_s;
    let q = cfg.setup.posture.iter().enumerate().map(|(i, p)| p + 0.05 * (i as f64).sin()).collect::<Vec<_>>();
    let qd: Vec<f64> = (0..q.len()).map(|i| 0.02 * (i as f64).cos()).collect();
    let mut cells = vec![CellReading::default(); cfg.layout.num_cells()];
    let palm = cfg.layout.patches().iter().find(|p| p.id == 12).unwrap().cells.clone();
    for i in palm.clone().step_by(3) {
        cells[i] = CellReading::uniform(0.4, 0.8);
    }
    let mut ctl = Controller::new(cfg, 0.0).unwrap();
    let input = |k: usize| ControllerInput { t_s: k as f64 * DT, dt_s: DT, q: &q, qd: &qd, cells: &cells, scan: &[] };
    let mut k = 0;
    for _ in 0..10 {
        ctl.update(&input(k));
        k += 1;
    }
    let before = ctl.torque().clone();
    ctl.request_phase(Phase::Contact).unwrap();
    let mut torques = vec![before.clone()];
    // the fusion weight shifts over 1 s (the hand signal changes); after it, τ_k is constant
    for _ in 0..400 {
        let out = ctl.update(&input(k));
        assert_eq!(out.fault, None);
        torques.push(ctl.torque().clone());
        k += 1;
    }
    assert_eq!(ctl.output().mode, Mode::Contact);
    let after = torques.last().unwrap().clone();
    let gap = (&before - &after).norm();
    assert!(gap > 1.0, "the arrangements differ: gap {gap} N m");
    assert_eq!(torques[1], before, "no step at the switch instant: the held torque comes first");
    let steps: Vec<f64> = torques.windows(2).map(|w| (&w[1] - &w[0]).norm()).collect();
    let largest = steps.iter().cloned().fold(0.0, f64::max);
    // bound with Δτ_k = 0 after the weight shift (t > 1 s): δ dt ‖τ_{k-1} − τ_k‖
    for (i, s) in steps.iter().enumerate().skip(130) {
        assert!(*s <= delta * DT * gap * (1.0 + 1e-9) + 1e-12, "cycle {i}: step {s} over {}", delta * DT * gap);
    }
    // and overall the blend spreads the gap over many cycles
    assert!(largest < 0.2 * gap, "largest per-cycle change {largest} of a gap {gap}");
}

/// 1e6 m goals and 1e6 N-scale task forces reach the resolver as finite torques; its limits hold.
#[test]
fn absurd_goal_gives_saturated_motion() {
    let mut ctl = Controller::new(config("planar7"), 0.0).unwrap();
    let q = ctl.config().setup.posture.clone();
    let cells = vec![CellReading::default(); ctl.config().layout.num_cells()];
    ctl.set_goal(Some(Isometry3::translation(1e6, -1e6, 0.0))).unwrap();
    for k in 0..50 {
        let out = ctl.update(&ControllerInput {
            t_s: k as f64 * DT,
            dt_s: DT,
            q: &q,
            qd: &[0.0; 7],
            cells: &cells,
            scan: &[],
        });
        assert_eq!(out.fault, None);
    }
    let v = Vector3::new(ctl.torque()[0], ctl.torque()[1], ctl.torque()[2]);
    assert!(v.iter().all(|t| t.is_finite()));
    // goal speed saturation (intentional-contact paper eq. 8-9): the task force is bounded by k_v V_max
    assert!(ctl.output().torque_norm < 1e3, "torque {}", ctl.output().torque_norm);
}
