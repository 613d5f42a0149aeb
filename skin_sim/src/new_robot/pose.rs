//! Where the generated scene puts the robot, the goal and the obstacle.
//!
//! The floor is [`EE_ABOVE_FLOOR_M`] below the end effector's start (the robot's fixed links may
//! reach below it: MuJoCo does not collide them with the world; a frozen mobile base stands in a
//! pit), and under a moving base ([`BASE_FLOOR_GAP_M`]).
//! The start configuration is the best of [`SAMPLES`] deterministic samples of the arm joints
//! within their limits (continuous joints in `[-pi, pi]`) that satisfy:
//! - no skin cell seeing the floor: along its normal the floor is at least [`CELL_CLEARANCE_M`]
//!   away (beyond the proximity range: the floor is sensed like any object), and every cell at
//!   least [`CELL_CLEARANCE_M`] above it;
//! - a revolute arm joint with a vertical axis (the sweep joint) at [`MIN_SWEEP_RADIUS_M`] to
//!   [`MAX_SWEEP_RADIUS_M`] from the end effector, which can turn by the sweep angle within its
//!   limits;
//! - no cell inside the obstacle's clearance, and cells of links three or more joints apart at
//!   least [`SELF_CLEARANCE_M`] apart (no self-contact at the start);
//!
//! "best": the largest position manipulability `sqrt(det(J_p J_p^T))` of the arm joints. The
//! goal is where the end effector goes when the sweep joint turns so that it moves [`CHORD_M`];
//! the obstacle, a cylinder standing on the floor and reaching above the arm near it, is at the
//! chord's middle, moved [`OBSTACLE_OFFSET_M`] away from the sweep axis: the straight path runs
//! into it, and a push from the inside slides it out of the way.

use nalgebra::{Matrix3, Matrix6xX, Vector3};
use skin_core::model::{point_jacobian, update_kinematics, JointKind, ModelData};
use skin_core::skin::layout::ResolvedLayout;

use super::Robot;

/// End-effector height above the floor at the start \[m\] (at least: see [`BASE_FLOOR_GAP_M`]).
pub const EE_ABOVE_FLOOR_M: f64 = 0.5;
/// A moving base's floor is this far below its root, or lower \[m\].
pub const BASE_FLOOR_GAP_M: f64 = 0.01;
/// Distance to the floor along every cell's normal, at least \[m\] (proximity range 0.15 m).
pub const CELL_CLEARANCE_M: f64 = 0.17;
/// Straight-line distance from the start to the goal \[m\].
pub const CHORD_M: f64 = 0.4;
/// Nearest and farthest end effector from the sweep axis \[m\].
pub const MIN_SWEEP_RADIUS_M: f64 = 0.3;
/// See [`MIN_SWEEP_RADIUS_M`].
pub const MAX_SWEEP_RADIUS_M: f64 = 0.75;
/// Obstacle radius \[m\]; with [`OBSTACLE_FRICTION`] it slides before it tips when pushed at the
/// end effector's height (tipping force `m g r / h` = 0.78 N > friction 0.49 N).
pub const OBSTACLE_RADIUS_M: f64 = 0.08;
/// Obstacle mass \[kg\].
pub const OBSTACLE_MASS_KG: f64 = 0.5;
/// Obstacle friction coefficient.
pub const OBSTACLE_FRICTION: f64 = 0.1;
/// Time constant of the obstacle's contacts \[s\]: the soft cover of the skin, as in
/// tomm_movable_obstacles (MuJoCo's default 0.02 s is a rigid surface: 40 N spikes on a Panda's
/// hand when the push starts).
pub const OBSTACLE_CONTACT_TIME_CONSTANT_S: f64 = 0.15;
/// Obstacle centre off the chord's middle, away from the sweep axis \[m\].
pub const OBSTACLE_OFFSET_M: f64 = 0.03;
/// Obstacle top above the end effector and every cell within [`OBSTACLE_NEAR_M`] of its axis \[m\].
pub const OBSTACLE_ABOVE_EE_M: f64 = 0.1;
/// See [`OBSTACLE_ABOVE_EE_M`] \[m\].
pub const OBSTACLE_NEAR_M: f64 = 0.4;
/// Smallest start distance of any cell from the obstacle's surface \[m\].
pub const OBSTACLE_CLEARANCE_M: f64 = 0.03;
/// Smallest start distance between cells of links three or more joints apart \[m\].
pub const SELF_CLEARANCE_M: f64 = 0.04;
/// Samples of the start configuration.
pub const SAMPLES: usize = 6000;
/// The best this many samples are checked for self-contact, best first.
const SELF_CHECKED: usize = 50;

/// The scene's geometry.
#[derive(Debug, Clone, PartialEq)]
pub struct Placement {
    /// Start configuration, model order.
    pub q0: Vec<f64>,
    /// End-effector start position, world \[m\].
    pub start: Vector3<f64>,
    /// Goal position, world \[m\].
    pub goal: Vector3<f64>,
    /// The sweep joint (model index) and its turn \[rad\].
    pub sweep: (usize, f64),
    /// Obstacle centre on the floor, world x and y \[m\].
    pub obstacle_xy: [f64; 2],
    /// Obstacle height \[m\].
    pub obstacle_height_m: f64,
    /// Floor height, world \[m\].
    pub floor_z_m: f64,
}

/// Deterministic uniform numbers in [0, 1) (SplitMix64).
struct Uniform(u64);

impl Uniform {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

struct Candidate {
    q: Vec<f64>,
    score: f64,
    sweep: (usize, f64),
    start: Vector3<f64>,
    obstacle_xy: [f64; 2],
    top: f64,
}

/// The floor under an end effector at height `ee_z`: [`EE_ABOVE_FLOOR_M`] below it, and for a
/// moving base at most [`BASE_FLOOR_GAP_M`] below the root (REP 105: a mobile base's root,
/// `base_footprint`, is on the ground; a floor through a moving base would hold it fast).
fn floor_z(robot: &Robot, ee_z: f64) -> f64 {
    let below_ee = ee_z - EE_ABOVE_FLOOR_M;
    if robot.base.is_empty() {
        below_ee
    } else {
        below_ee.min(-BASE_FLOOR_GAP_M)
    }
}

/// World positions and normals of the cells at the state in `data`.
fn cell_positions(layout: &ResolvedLayout, data: &ModelData) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    layout
        .cells()
        .iter()
        .map(|c| {
            let pose = data.frame_pose(c.frame);
            ((pose * nalgebra::Point3::from(c.position_link)).coords, pose.rotation * c.normal_link)
        })
        .collect()
}

/// Searches the placement (see the module documentation); `fixed` arm joints keep their
/// `q_default` value. The error says which condition no sample met.
pub fn place(robot: &Robot, layout: &ResolvedLayout, fixed: &[usize]) -> Result<Placement, String> {
    let model = &robot.model;
    let mut data = ModelData::new(model);
    let zero = vec![0.0; model.nv()];
    let mut jac = Matrix6xX::zeros(model.nv());
    let mut rng = Uniform(1);
    let mut counts = [0usize; 3];
    let mut candidates: Vec<Candidate> = Vec::new();
    for _ in 0..SAMPLES {
        let mut q = robot.q_default.clone();
        for &j in robot.arm.iter().filter(|j| !fixed.contains(j)) {
            let l = model.joint_limits()[j];
            let (lo, hi) = (l.lower.max(-std::f64::consts::PI), l.upper.min(std::f64::consts::PI));
            q[j] = lo + rng.next() * (hi - lo);
        }
        update_kinematics(model, &mut data, &q, &zero).expect("nv entries");
        let ee = data.frame_pose(robot.ee).translation.vector;
        let floor = floor_z(robot, ee.z);
        let cells = cell_positions(layout, &data);
        if cells
            .iter()
            .any(|(p, n)| p.z - floor < CELL_CLEARANCE_M || n.z < 0.0 && (p.z - floor) / -n.z < CELL_CLEARANCE_M)
        {
            counts[0] += 1;
            continue;
        }
        // The sweep joint: the first revolute arm joint with a vertical axis.
        let Some(&s) = robot
            .arm
            .iter()
            .find(|&&j| model.joint_kind(j) == JointKind::Revolute && data.joint_axis_world(j).z.abs() > 0.99)
        else {
            counts[1] += 1;
            continue;
        };
        let axis_xy = data.joint_pose(s).translation.vector.xy();
        let radial = ee.xy() - axis_xy;
        let r = radial.norm();
        if !(MIN_SWEEP_RADIUS_M..=MAX_SWEEP_RADIUS_M).contains(&r) {
            counts[1] += 1;
            continue;
        }
        let turn = 2.0 * (CHORD_M / 2.0 / r).asin();
        let l = model.joint_limits()[s];
        let Some(sign) = [1.0, -1.0].into_iter().find(|&d| (l.lower..=l.upper).contains(&(q[s] + d * turn))) else {
            counts[1] += 1;
            continue;
        };
        let axis = data.joint_axis_world(s);
        let turn = sign * turn * axis.z.signum();
        let rot = nalgebra::Rotation2::new(turn);
        let goal_xy = axis_xy + rot * radial;
        let mid = (ee.xy() + goal_xy) / 2.0;
        let out = (mid - axis_xy).normalize();
        let obstacle = mid + out * OBSTACLE_OFFSET_M;
        // Taller than every cell around it: a link riding on its top edge presses where no
        // cell faces (a Panda's link 7 did, 37 N).
        let near = cells.iter().filter(|(p, _)| (p.xy() - obstacle).norm() < OBSTACLE_NEAR_M).map(|(p, _)| p.z);
        let top = near.fold(ee.z, f64::max) + OBSTACLE_ABOVE_EE_M;
        if cells.iter().any(|(p, _)| p.z < top && (p.xy() - obstacle).norm() < OBSTACLE_RADIUS_M + OBSTACLE_CLEARANCE_M)
        {
            counts[2] += 1;
            continue;
        }
        point_jacobian(model, &data, robot.ee, &Vector3::zeros(), &mut jac).expect("valid frame");
        let jp = Matrix3::from_fn(|a, b| robot.arm.iter().map(|&j| jac[(a, j)] * jac[(b, j)]).sum::<f64>());
        candidates.push(Candidate {
            score: jp.determinant().max(0.0).sqrt(),
            sweep: (s, sign * turn.abs()),
            start: ee,
            obstacle_xy: [obstacle.x, obstacle.y],
            top,
            q,
        });
    }
    candidates.sort_by(|a, b| b.score.total_cmp(&a.score));
    let best = candidates.into_iter().take(SELF_CHECKED).find(|c| {
        update_kinematics(model, &mut data, &c.q, &zero).expect("nv entries");
        self_clear(robot, layout, &cell_positions(layout, &data))
    });
    let Some(c) = best else {
        return Err(format!(
            "no start configuration in {SAMPLES} samples: a cell seeing the floor {EE_ABOVE_FLOOR_M} m below the end \
             effector in {}, no vertical arm joint {MIN_SWEEP_RADIUS_M}-{MAX_SWEEP_RADIUS_M} m away that can turn the end \
             effector by {CHORD_M} m in {}, the obstacle on the arm in {}, the rest in self-contact (give --initial for \
             some arm joints, or other --arm-joints)",
            counts[0], counts[1], counts[2]
        ));
    };
    let mut q1 = c.q.clone();
    q1[c.sweep.0] += c.sweep.1;
    update_kinematics(model, &mut data, &q1, &zero).expect("nv entries");
    let goal = data.frame_pose(robot.ee).translation.vector;
    Ok(Placement {
        q0: c.q,
        start: c.start,
        goal,
        sweep: c.sweep,
        obstacle_xy: c.obstacle_xy,
        obstacle_height_m: c.top - floor_z(robot, c.start.z),
        floor_z_m: floor_z(robot, c.start.z),
    })
}

/// Whether cells of bodies three or more arm joints apart, or on different branches, keep
/// [`SELF_CLEARANCE_M`]. Bodies are told apart by their nearest arm joint (frozen joints weld
/// their bodies to it: MuJoCo does not collide welded bodies; the generated model excludes a
/// body's contacts with its parent and grandparent).
fn self_clear(robot: &Robot, layout: &ResolvedLayout, cells: &[(Vector3<f64>, Vector3<f64>)]) -> bool {
    let model = &robot.model;
    // Nearest arm joint at or above the cell's body, and the number of arm joints above it.
    let weld = |f: usize| {
        let mut k = model.frame_parent_joint(f);
        while let Some(i) = k {
            if robot.arm.contains(&i) {
                break;
            }
            k = model.joint_parent(i);
        }
        k
    };
    let depth = |w: Option<usize>| w.map_or(0, |w| robot.arm.iter().filter(|&&a| model.joint_supports(a, w)).count());
    let welds: Vec<Option<usize>> = layout.cells().iter().map(|c| weld(c.frame)).collect();
    for i in 0..cells.len() {
        for k in i + 1..cells.len() {
            let (a, b) = (welds[i], welds[k]);
            let related = match (a, b) {
                (Some(x), Some(y)) => model.joint_supports(x, y) || model.joint_supports(y, x),
                _ => true,
            };
            if (!related || depth(a).abs_diff(depth(b)) >= 3) && (cells[i].0 - cells[k].0).norm() < SELF_CLEARANCE_M {
                return false;
            }
        }
    }
    true
}
