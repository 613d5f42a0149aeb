//! The control loop runs at kHz rates: after setup, kinematics and dynamics, the skin's per-cycle
//! functions, the hierarchy, the resolver, the supervisor and the torque blender must not touch the
//! heap. A counting global allocator checks that (one test binary: a binary has one allocator).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::PathBuf;

use nalgebra::{DMatrix, DVector, Matrix6xX, Vector3, Vector6};
use skin_core::hierarchy::*;
use skin_core::model::*;
use skin_core::resolver::{Resolver, ResolverParams};
use skin_core::skin::aggregate::{aggregate_live_patches, aggregate_patches, PatchWrench};
use skin_core::skin::cell_forces::{cell_contact_forces, cell_repulsion_forces, PointForce};
use skin_core::skin::layout::SkinLayout;
use skin_core::skin::live::LiveCells;
use skin_core::skin::params::SkinParams;
use skin_core::skin::signals::CellReading;
use skin_core::skin::torques::{patch_wrenches_to_torques, point_forces_to_torques};
use skin_core::skin::transforms::{patch_poses_world, patch_wrench_world, sum_patch_forces_in_frame};
use skin_core::supervisor::*;

struct Counting;

thread_local! {
    // Per thread, so that the test harness's own threads do not count.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

fn allocations() -> usize {
    ALLOCATIONS.with(|c| c.get())
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn dynamics_do_not_allocate_after_setup() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../urdf/tomm.urdf");
    let model = RobotModel::from_urdf_file(std::path::Path::new(path)).unwrap();
    let n = model.nv();
    let mut data = ModelData::new(&model);
    let mut m = DMatrix::zeros(n, n);
    let mut tau = DVector::zeros(n);
    let mut j = Matrix6xX::zeros(n);
    let mut jd = Vector6::zeros();
    let frames: Vec<usize> = (0..n).map(|b| model.joint_child_frame(b)).collect();
    let q: Vec<f64> = (0..n).map(|i| 0.1 * i as f64 - 0.5).collect();
    let qd: Vec<f64> = (0..n).map(|i| 0.3 - 0.05 * i as f64).collect();
    let qdd = vec![0.7; n];
    let p = Vector3::new(0.01, 0.02, 0.03);

    let mut step = |data: &mut ModelData| {
        update_kinematics(&model, data, &q, &qd).unwrap();
        for &f in &frames {
            point_jacobian(&model, data, f, &p, &mut j).unwrap();
            point_jacobian_dot_qdot(&model, data, f, &p, &mut jd).unwrap();
        }
        crba(&model, data, &mut m).unwrap();
        rnea(&model, data, &qdd, &mut tau).unwrap();
        bias_forces(&model, data, &mut tau).unwrap();
        gravity(&model, data, &mut tau).unwrap();
        let _ = frame_pose(data, frames[3]);
    };
    step(&mut data); // warm-up
                     // the counter does see heap allocations
    let probe = allocations();
    std::hint::black_box(vec![1u8; 16]);
    assert!(allocations() > probe);
    let before = allocations();
    for _ in 0..10 {
        step(&mut data);
    }
    let after = allocations();
    assert_eq!(after - before, 0, "{} heap allocations in the dynamics loop", after - before);
}

#[test]
fn skin_cycle_does_not_allocate_after_setup() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let model = RobotModel::from_urdf_file(&root.join("urdf/tomm.urdf")).unwrap();
    let layout = SkinLayout::load(&root.join("config/skin/tomm.yaml")).unwrap().resolve(&model).unwrap();
    let params = SkinParams::load(&root.join("config/skin_model.yaml")).unwrap();
    let n = layout.num_cells();
    let mut data = ModelData::new(&model);
    let q: Vec<f64> = (0..model.nv()).map(|i| 0.2 * i as f64 - 0.4).collect();
    let qd = vec![0.0; model.nv()];
    let readings: Vec<CellReading> =
        (0..n).map(|i| CellReading::uniform((i % 7) as f64 / 7.0, (i % 5) as f64 / 5.0)).collect();
    let hand = model.frame_index("right_hand").unwrap();

    // Setup: buffers reserved once.
    let mut wrenches: Vec<PatchWrench> = Vec::with_capacity(layout.patches().len());
    let mut poses = Vec::with_capacity(layout.patches().len());
    let mut forces: Vec<PointForce> = Vec::with_capacity(n);
    let mut tau = DVector::zeros(model.nv());

    let mut cycle = |data: &mut ModelData| {
        update_kinematics(&model, data, &q, &qd).unwrap();
        aggregate_patches(&layout, &readings, &params.fusion, &mut wrenches).unwrap();
        patch_poses_world(&layout, |f| data.frame_pose(f), |_| true, &mut poses);
        let h = sum_patch_forces_in_frame(data.frame_pose(hand), &poses, &wrenches, |j| j < 6);
        let w = patch_wrench_world(&poses[0], &wrenches[0]);
        patch_wrenches_to_torques(&model, data, &layout, &wrenches, |_| true, &mut tau);
        cell_repulsion_forces(
            &layout,
            &readings,
            &params.proximity,
            &params.repulsion,
            |f| data.frame_pose(f),
            &mut forces,
        )
        .unwrap();
        point_forces_to_torques(&model, data, &forces, &mut tau);
        cell_contact_forces(&layout, &readings, &params.force, &params.fusion, |f| data.frame_pose(f), &mut forces)
            .unwrap();
        point_forces_to_torques(&model, data, &forces, &mut tau);
        std::hint::black_box((h, w, &tau));
    };
    cycle(&mut data); // first call may size the output vectors
    let before = allocations();
    for _ in 0..10 {
        cycle(&mut data);
    }
    assert_eq!(allocations() - before, 0, "skin cycle allocated");
    assert!(!forces.is_empty());
}

#[test]
fn hierarchy_does_not_allocate_after_setup() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../urdf/tomm.urdf");
    let model = RobotModel::from_urdf_file(std::path::Path::new(path)).unwrap();
    let n = model.nv();
    let mut data = ModelData::new(&model);
    let mut m = DMatrix::zeros(n, n);
    let mut bias = DVector::zeros(n);
    let mut j = Matrix6xX::zeros(n);
    let mut jd = Vector6::zeros();
    let hand = model.frame_index("right_hand").unwrap();
    let forearm = model.frame_index("right_forearm_link").unwrap();
    let left = model.frame_index("left_hand").unwrap();
    let mut levels: Vec<TaskLevel> = [("cells", 8), ("wrist", 3), ("hand", 3), ("left", 6)]
        .iter()
        .map(|&(name, rows)| TaskLevel::new(name, n, rows))
        .collect();
    let mut solver = HierarchySolver::new(n, 4, 8, InverseParams::default()).unwrap();
    let mut tau = DVector::zeros(n);
    let posture = vec![0.3; n];
    let q: Vec<f64> = (0..n).map(|i| 0.1 * i as f64 - 0.5).collect();
    let qd: Vec<f64> = (0..n).map(|i| 0.3 - 0.05 * i as f64).collect();
    let p0 = Vector3::zeros();
    let order = [0usize, 1, 2, 3];

    let mut cycle = |active_cells: usize| {
        update_kinematics(&model, &mut data, &q, &qd).unwrap();
        crba(&model, &mut data, &mut m).unwrap();
        bias_forces(&model, &mut data, &mut bias).unwrap();
        levels[0].clear();
        for c in 0..active_cells {
            let cell = Vector3::new(-0.05 * c as f64, 0.0, 0.05);
            point_jacobian(&model, &data, forearm, &cell, &mut j).unwrap();
            levels[0]
                .push_directional(&[0.0, 0.6, 0.8], &j.fixed_rows::<3>(0), Reference::Force { f: &[2.0] })
                .unwrap();
        }
        point_jacobian(&model, &data, hand, &p0, &mut j).unwrap();
        point_jacobian_dot_qdot(&model, &data, hand, &p0, &mut jd).unwrap();
        let (ang, lin) = ([jd[3], jd[4], jd[5]], [jd[0], jd[1], jd[2]]);
        levels[1]
            .set(&j.fixed_rows::<3>(3), Reference::Acceleration { xdd_star: &[0.1, 0.0, 0.0], jdot_qdot: &ang })
            .unwrap();
        levels[2]
            .set(&j.fixed_rows::<3>(0), Reference::Acceleration { xdd_star: &[0.0, 0.2, 0.0], jdot_qdot: &lin })
            .unwrap();
        point_jacobian(&model, &data, left, &p0, &mut j).unwrap();
        point_jacobian_dot_qdot(&model, &data, left, &p0, &mut jd).unwrap();
        levels[3].set(&j, Reference::Acceleration { xdd_star: &[0.0; 6], jdot_qdot: jd.as_slice() }).unwrap();
        solver.solve(&m, order.iter().map(|&i| &levels[i]), Some(&posture), Some(bias.as_slice()), &mut tau).unwrap();
        assert!(solver.diagnostics().len() == 4);
        solver.solve_model(&model, &mut data, &levels, Some(&posture), true, &mut tau).unwrap();
    };
    cycle(3); // warm-up
    let probe = allocations();
    std::hint::black_box(vec![1u8; 16]);
    assert!(allocations() > probe, "the counter sees heap allocations");
    let before = allocations();
    for k in 0..10 {
        cycle(k % 9); // 0..8 active cells, including an empty level
    }
    let after = allocations();
    assert_eq!(after - before, 0, "{} heap allocations in the hierarchy loop", after - before);
}

#[test]
fn supervisor_and_blend_do_not_allocate() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../config/supervisor.yaml");
    let params = SupervisorParams::load(std::path::Path::new(path)).unwrap();
    let mut sup = Supervisor::new(&params, 0.0).unwrap();
    let mut blender = TorqueBlender::new(15);
    let tau_a = [1.0; 15];
    let tau_b = [-2.0; 15];
    let mut out = [0.0; 15];
    let before = allocations();
    let mut t = 0.0;
    for k in 0..5000 {
        t += 0.004;
        let s = (k % 1000) as f64 / 1000.0;
        let u = SupervisorInput {
            ee_speed_mps: if s < 0.3 { 0.0 } else { 0.05 },
            avoidance_force_n: 3.0,
            contact_force_n: if (0.4..0.5).contains(&s) { 8.0 } else { 0.0 },
            goal_error_m: if s < 0.8 { 0.2 } else { 0.0 },
            contact_advance_mps: f64::NAN,
        };
        let a = sup.update(t, &u);
        blender.sync(a);
        let tau = if a.mode == Mode::Avoidance { &tau_a } else { &tau_b };
        blender.apply(t, tau, &mut out);
    }
    let after = allocations();
    assert!(sup.log().total() >= 10, "the scenario must switch: {}", sup.log().total());
    assert_eq!(after - before, 0, "allocations during updates");
}

#[test]
fn resolver_cycle_does_not_allocate_after_setup() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let model = RobotModel::from_urdf_file(&root.join("urdf/tomm.urdf")).unwrap();
    let params = ResolverParams::load(&root.join("config/resolver.yaml")).unwrap();
    let mut r = Resolver::new(&model, params).unwrap();
    let n = model.nv();
    let q: Vec<f64> = (0..n).map(|i| 0.1 * i as f64 - 0.5).collect();
    let qd: Vec<f64> = (0..n).map(|i| 0.05 * i as f64 - 0.3).collect();
    let mut tau: Vec<f64> = (0..n).map(|i| 1e3 * i as f64).collect();
    let g = vec![1.0; n];
    let mut cycle = |r: &mut Resolver, k: usize| {
        r.reset(&q, &qd).unwrap();
        tau[k % n] = -tau[k % n];
        r.update_arms(&tau, &g, &q, &qd, 0.008).unwrap();
        r.update_base(&tau, &q, &qd, 0.001).unwrap();
        r.update(&tau, &g, &q, &qd, 0.002 + 1e-4 * k as f64).unwrap();
        // the error path too (its error carries no heap data)
        let bad = tau[3];
        tau[3] = f64::NAN;
        assert!(r.update(&tau, &g, &q, &qd, 0.008).is_err());
        tau[3] = bad;
        r.safe_stop(0.008);
    };
    cycle(&mut r, 0); // warm-up
    let probe = allocations();
    std::hint::black_box(vec![1u8; 16]);
    assert!(allocations() > probe, "the counter sees heap allocations");
    let before = allocations();
    for k in 1..20 {
        cycle(&mut r, k);
    }
    assert_eq!(allocations() - before, 0, "heap allocations in the resolver cycle");
}

#[test]
fn tasks_do_not_allocate_after_setup() {
    use nalgebra::{UnitQuaternion, Vector2};
    use skin_core::tasks::avoidance::ProximityAvoidance;
    use skin_core::tasks::base_avoidance::BaseAvoidance;
    use skin_core::tasks::compliance::BodyCompliance;
    use skin_core::tasks::contact_reaction::ContactReaction;
    use skin_core::tasks::goal::{GoalOrientation, GoalPosition};
    use skin_core::tasks::hand_force::{HandForce, HandMeasurement};
    use skin_core::tasks::params::TaskParams;
    use skin_core::tasks::position_hold::PositionHold;
    use skin_core::tasks::posture::Posture;
    use skin_core::tasks::tactile_guidance::TactileGuidance;
    use skin_core::tasks::wrist::CompliantWrist;
    use skin_core::tasks::WristMoments;

    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let model = RobotModel::from_urdf_file(&root.join("urdf/tomm.urdf")).unwrap();
    let layout = SkinLayout::load(&root.join("config/skin/tomm.yaml")).unwrap().resolve(&model).unwrap();
    let skin = SkinParams::load(&root.join("config/skin_model.yaml")).unwrap();
    let p = TaskParams::load(&root.join("config/tasks.yaml")).unwrap();
    let nv = model.nv();
    let n = layout.num_cells();
    let hand = model.frame_index("right_hand").unwrap();
    let joints = ["base_x_joint", "base_y_joint", "base_yaw_joint"].map(|j| model.joint_index(j).unwrap());
    let mut data = ModelData::new(&model);
    let q: Vec<f64> = (0..nv).map(|i| 0.2 * i as f64 - 0.4).collect();
    let qd: Vec<f64> = (0..nv).map(|i| 0.01 * i as f64).collect();
    let readings: Vec<CellReading> =
        (0..n).map(|i| CellReading::uniform((i % 7) as f64 / 7.0, (i % 5) as f64 / 5.0)).collect();
    let laser: Vec<Vector2<f64>> = (0..360)
        .map(|k| {
            let a = (k as f64).to_radians();
            Vector2::new(a.cos(), a.sin()) * 0.6
        })
        .collect();

    let mut goal = GoalPosition::new(nv, hand, Vector3::zeros(), p.goal);
    let mut orient = GoalOrientation::new(nv, hand, p.goal_orientation);
    let mut avoid = ProximityAvoidance::new(nv, p.avoidance);
    let mut contact = ContactReaction::new(nv, model.nframes(), p.contact_reaction, &skin.force);
    let mut hand_task = HandForce::new(nv, hand, p.hand_force);
    let mut wrist = CompliantWrist::new(nv, hand, p.wrist);
    let mut guide = TactileGuidance::new(nv, hand, p.tactile_guidance);
    let mut hold = PositionHold::new(nv, hand, Vector3::zeros(), p.position_hold);
    let mut base = BaseAvoidance::new(nv, joints, p.base_avoidance).unwrap();
    let posture = Posture::new(nv, &p.posture, &vec![0.0; nv]).unwrap();
    let mut compliance = BodyCompliance::new(nv, p.posture.skin_gain);
    let (mut tau_s, mut tau) = (nalgebra::DVector::zeros(nv), nalgebra::DVector::zeros(nv));
    let mut levels = [
        TaskLevel::new("goal", nv, 3),
        TaskLevel::new("orient", nv, 3),
        TaskLevel::new("avoid", nv, n),
        TaskLevel::new("contact", nv, n),
        TaskLevel::new("hand", nv, 1),
        TaskLevel::new("wrist", nv, 3),
        TaskLevel::new("guide", nv, 3),
        TaskLevel::new("hold", nv, 3),
    ];
    let mut wrenches: Vec<PatchWrench> = Vec::with_capacity(layout.patches().len());
    let mut poses = Vec::with_capacity(layout.patches().len());
    let mut live = LiveCells::with_capacity(n, &skin.proximity);
    let goal_x = Vector3::new(0.5, -0.3, 1.0);
    let goal_r = UnitQuaternion::identity();

    let mut cycle = |data: &mut ModelData| {
        update_kinematics(&model, data, &q, &qd).unwrap();
        live.collect(&readings);
        aggregate_live_patches(&layout, &live, &skin.fusion, &mut wrenches).unwrap();
        patch_poses_world(&layout, |f| data.frame_pose(f), |_| true, &mut poses);
        let h_f = sum_patch_forces_in_frame(data.frame_pose(hand), &poses, &wrenches, |j| j < 6);
        let gamma = patch_wrench_world(&poses[5], &wrenches[5]).moment;
        let [l0, l1, l2, l3, l4, l5, l6, l7] = &mut levels;
        goal.update(&model, data, &goal_x, l0).unwrap();
        orient.update(&model, data, &goal_r, l1).unwrap();
        avoid.update(&model, data, &layout, &live, 0.08, l2).unwrap();
        contact.update(&model, data, &layout, &live, &skin.fusion, l3).unwrap();
        hand_task.update(&model, data, HandMeasurement::Force { force_n: 1.0 }, 0.0, &skin.proximity, l4).unwrap();
        let moments = WristMoments { proximity_world: gamma, force_world_nm: gamma, fusion_weight: 0.5 };
        wrist.update(&model, data, &moments, l5).unwrap();
        guide.update(&model, data, &h_f, l6).unwrap();
        hold.update(&model, data, l7).unwrap();
        base.update(&q, &laser).unwrap();
        tau_s.fill(0.0);
        compliance.add_to(&model, data, &layout, &wrenches, |j| j >= 6, &mut tau_s).unwrap();
        tau_s += base.torque();
        posture.joint_torque(data, None, &mut tau).unwrap();
        tau -= &tau_s;
        std::hint::black_box(&tau);
    };
    cycle(&mut data); // first call may size the skin output vectors
    let before = allocations();
    for _ in 0..10 {
        cycle(&mut data);
    }
    assert_eq!(allocations() - before, 0, "tasks allocated");
    assert!(levels[2].rows() > 0 && levels[3].rows() > 0);
}

/// The whole cycle (`Controller::update`) on TOMM with skin activity, a goal and a laser scan,
/// across arrangement switches of both policies (interactive-force-control paper phases on request; intentional-contact paper (a) -> (c)
/// on a contact force), through a safe-stop step and with a commanded base motion.
#[test]
fn controller_cycle_does_not_allocate_after_setup() {
    use nalgebra::{Isometry3, Vector2};
    use skin_core::controller::{BaseReference, Controller, ControllerConfig, ControllerInput};

    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    for policy in [Policy::Phases, Policy::IntentionalContact] {
        let mut config = ControllerConfig::load(&root.join("config/controller/tomm.yaml")).unwrap();
        config.supervisor.policy = policy;
        let q = config.setup.posture.clone();
        let nv = q.len();
        let n = config.layout.num_cells();
        let mut cells = vec![CellReading::default(); n];
        for i in (0..n).step_by(11) {
            cells[i] = CellReading::uniform(0.0, 0.7);
        }
        let scan: Vec<Vector2<f64>> = (0..360)
            .map(|k| {
                let a = (k as f64).to_radians();
                Vector2::new(a.cos(), a.sin()) * 0.7
            })
            .collect();
        let mut c = Controller::new(config, 0.0).unwrap();
        c.set_goal(Some(Isometry3::translation(0.6, -0.3, 1.1))).unwrap();
        let qd = vec![0.01; nv];
        let mut t = 0.0;
        let mut step = |c: &mut Controller, cells: &[CellReading], dt: f64| {
            t += 0.008;
            c.update(&ControllerInput { t_s: t, dt_s: dt, q: &q, qd: &qd, cells, scan: &scan })
                .commands
                .joint_velocities[0]
        };
        for _ in 0..5 {
            step(&mut c, &cells, 0.008);
        }
        let before = allocations();
        for k in 0..60 {
            if k == 10 {
                let _ = c.request_phase(Phase::Contact);
            }
            if k == 20 {
                // hard contact on many cells: (a) -> (c) under the intentional-contact paper policy
                for i in (0..n).step_by(5) {
                    cells[i] = CellReading::uniform(1.0, 1.0);
                }
            }
            if (40..50).contains(&k) {
                // a commanded base motion (interactive-force-control paper Exp. 1), then back to q_post
                let r = BaseReference { position: [0.01 * k as f64, 0.0, 0.0], velocity: [0.05, 0.0, 0.0] };
                c.set_base_reference(Some(r)).unwrap();
            } else if k == 50 {
                c.set_base_reference(None).unwrap();
            }
            let dt = if k == 30 { f64::NAN } else { 0.008 };
            std::hint::black_box(step(&mut c, &cells, dt));
        }
        assert_eq!(allocations() - before, 0, "{policy:?}: the controller cycle allocated");
        assert_ne!(c.supervisor().log().total(), 0, "{policy:?}: an arrangement switch happened");
    }
}
