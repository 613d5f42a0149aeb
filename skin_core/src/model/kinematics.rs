//! Forward kinematics (poses, spatial velocities, velocity-product accelerations), frame poses
//! and point Jacobians.

use nalgebra::{Isometry3, Matrix3, Matrix6xX, Point3, Translation3, Unit, UnitQuaternion, Vector3, Vector6};

use super::data::ModelData;
use super::error::ModelError;
use super::robot::{JointKind, RobotModel};
use super::spatial::{ang, cross_motion, lin, svec, SVec, SpatialInertia};

/// Checks length and finiteness of a joint-space vector; errors name the joint.
pub(crate) fn check_vector(model: &RobotModel, what: &'static str, x: &[f64]) -> Result<(), ModelError> {
    if x.len() != model.nv() {
        return Err(ModelError::Dimension { what, expected: model.nv(), got: x.len() });
    }
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        return Err(ModelError::NonFinite { what, index: i, joint: model.joint_names[i].clone(), value: x[i] });
    }
    Ok(())
}

/// Forward kinematics of position and velocity (first two passes of RBDA Table 5.1).
///
/// Fills the world pose of every joint frame and every link frame, the spatial velocity of every
/// body, the joint motion subspaces, the body inertias in world orientation, and the
/// velocity-product accelerations `c_i = v_i ×m S_i q̇_i` that [`point_jacobian_dot_qdot`] and
/// [`super::rnea`] reuse. Rejects `q`/`qd` of the wrong length and NaN/∞ entries (the error names
/// the joint), leaving `data` unchanged in that case. Does not allocate.
pub fn update_kinematics(model: &RobotModel, data: &mut ModelData, q: &[f64], qd: &[f64]) -> Result<(), ModelError> {
    check_vector(model, "q", q)?;
    check_vector(model, "qd", qd)?;
    data.q.copy_from_slice(q);
    data.qd.copy_from_slice(qd);

    // Spatial vectors about a reference point on the robot keep the numbers small when the base
    // is far from the world origin. The trunk (bodies 0..=ref_body, a single chain) is posed
    // first to find that point; positions relative to it are then accumulated from the reference
    // body outwards, so they do not carry the rounding of large world coordinates.
    if model.njoints() == 0 {
        return Ok(());
    }
    for i in 0..=model.ref_body {
        pose_body(model, data, i, joint_value(&model.bodies[i], q));
    }
    data.ref_point = data.body_pos[model.ref_body];
    let r0 = data.ref_point;
    for (i, b) in model.bodies.iter().enumerate() {
        let qi = joint_value(b, q);
        if i > model.ref_body {
            pose_body(model, data, i, qi);
        }
        let a = data.axis_w[i];
        let rel = match b.parent {
            Some(p) if !model.trunk[i] => {
                let mut rel = data.body_rel[p] + data.body_rot[p] * b.placement.translation.vector;
                if b.kind == JointKind::Prismatic {
                    rel += a * qi;
                }
                rel
            }
            _ => data.body_pos[i] - r0,
        };
        data.body_rel[i] = rel;
        // motion subspace per unit of the driving coordinate (a followed mimic joint moves
        // `multiplier` times its leader's rate)
        let s = match b.kind {
            JointKind::Revolute => svec(&a, &rel.cross(&a)),
            JointKind::Prismatic => svec(&Vector3::zeros(), &a),
        } * b.multiplier;
        let vj = s * qd[b.coord];
        let (vp, ap) = match b.parent {
            Some(p) => (data.v[p], data.a_bias[p]),
            None => (SVec::zeros(), SVec::zeros()),
        };
        let v = vp + vj;
        let c = cross_motion(&v, &vj);
        data.s[i] = s;
        data.v[i] = v;
        data.c[i] = c;
        data.a_bias[i] = ap + c;
        let r = &data.body_rot[i];
        let com_w = r * b.com + rel;
        data.inertia_w[i] = SpatialInertia::from_com(b.mass, &com_w, &rotate_symmetric(r, &b.inertia_com));
    }

    for (f, fr) in model.frames.iter().enumerate() {
        if let Some(b) = fr.body {
            data.frame_pose[f] =
                if fr.placement_is_identity { data.body_pose[b] } else { data.body_pose[b] * fr.placement };
        }
    }
    Ok(())
}

/// Value of a moving joint from the generalized coordinates.
#[inline(always)]
fn joint_value(b: &super::robot::Body, q: &[f64]) -> f64 {
    b.multiplier * q[b.coord] + b.offset
}

/// World pose, rotation matrix and axis of body `i` from its parent's (parents come first).
#[inline(always)]
fn pose_body(model: &RobotModel, data: &mut ModelData, i: usize, q: f64) {
    let b = &model.bodies[i];
    // joint frame at q = 0 in the world: parent pose * constant placement
    let pose_j = match b.parent {
        Some(p) => data.body_pose[p] * b.placement,
        None => b.placement,
    };
    let pose = match b.kind {
        // one sin/cos of q/2 gives the quaternion; the matrix follows from it
        JointKind::Revolute => Isometry3::from_parts(
            pose_j.translation,
            pose_j.rotation * UnitQuaternion::from_axis_angle(&Unit::new_unchecked(b.axis), q),
        ),
        JointKind::Prismatic => Isometry3::from_parts(
            Translation3::from(pose_j.translation.vector + pose_j.rotation * (b.axis * q)),
            pose_j.rotation,
        ),
    };
    let rot = *pose.rotation.to_rotation_matrix().matrix();
    // the joint's own motion leaves its axis unchanged
    data.axis_w[i] = rot * b.axis;
    data.body_rot[i] = rot;
    data.body_pos[i] = pose.translation.vector;
    data.body_pose[i] = pose;
}

/// `R I Rᵀ` for a symmetric `I`, computing only the upper triangle of the product.
#[inline(always)]
fn rotate_symmetric(r: &Matrix3<f64>, i: &Matrix3<f64>) -> Matrix3<f64> {
    let a = r * i;
    let e = |row: usize, col: usize| a[(row, 0)] * r[(col, 0)] + a[(row, 1)] * r[(col, 1)] + a[(row, 2)] * r[(col, 2)];
    let (xx, xy, xz, yy, yz, zz) = (e(0, 0), e(0, 1), e(0, 2), e(1, 1), e(1, 2), e(2, 2));
    Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz)
}

/// World pose of frame `frame` after [`update_kinematics`].
pub fn frame_pose(data: &ModelData, frame: usize) -> &Isometry3<f64> {
    &data.frame_pose[frame]
}

fn check_point(model: &RobotModel, frame: usize, point: &Vector3<f64>) -> Result<(), ModelError> {
    if frame >= model.nframes() {
        return Err(ModelError::FrameIndex { index: frame, count: model.nframes() });
    }
    if let Some(i) = point.iter().position(|v| !v.is_finite()) {
        return Err(ModelError::NonFinite {
            what: "point",
            index: i,
            joint: model.frame_names[frame].clone(),
            value: point[i],
        });
    }
    Ok(())
}

/// Geometric Jacobian (6 × nv, world-aligned axes) of the point `point_in_frame` (coordinates in
/// frame `frame`): rows 0..3 map q̇ to the point's linear velocity, rows 3..6 to the angular
/// velocity of the frame. Columns of joints that do not move the frame are zero. Equals
/// pinocchio's `getFrameJacobian(..., LOCAL_WORLD_ALIGNED)` with the frame moved to the point.
///
/// Uses the data of the last [`update_kinematics`]; only the supporting chain is visited.
pub fn point_jacobian(
    model: &RobotModel,
    data: &ModelData,
    frame: usize,
    point_in_frame: &Vector3<f64>,
    out: &mut Matrix6xX<f64>,
) -> Result<(), ModelError> {
    check_point(model, frame, point_in_frame)?;
    if out.ncols() != model.nv() {
        return Err(ModelError::Dimension { what: "jacobian output columns", expected: model.nv(), got: out.ncols() });
    }
    let p = (data.frame_pose[frame] * Point3::from(*point_in_frame)).coords;
    // column-major 6 x nv storage: column j is out[6j..6j+6]
    let o = out.as_mut_slice();
    o.fill(0.0);
    let mut k = model.frames[frame].body;
    while let Some(j) = k {
        let b = &model.bodies[j];
        let a = data.axis_w[j] * b.multiplier;
        let col = &mut o[6 * b.coord..6 * b.coord + 6];
        // accumulated: the joints that follow one coordinate add up
        let add = |col: &mut [f64], v: [f64; 6]| col.iter_mut().zip(v).for_each(|(c, v)| *c += v);
        match b.kind {
            JointKind::Revolute => {
                let l = a.cross(&(p - data.body_pos[j]));
                add(col, [l[0], l[1], l[2], a[0], a[1], a[2]]);
            }
            JointKind::Prismatic => add(col, [a[0], a[1], a[2], 0.0, 0.0, 0.0]),
        }
        k = b.parent;
    }
    Ok(())
}

/// The row `dᵀ J_v` of the point `point_in_frame` of frame `frame`: the linear rows of
/// [`point_jacobian`] along the world direction `d`, into `out` (length nv), without forming the
/// 6 × nv Jacobian (one skin cell's force row, intentional-contact paper eq. 4 and 6).
///
/// Entry j is the power of the unit force `d` at the point through joint j's motion subspace,
/// `s_jᵀ [r × d; d]` with `r` the point about the reference point (the force as a spatial
/// force, RBDA Sec. 2.8): one 6-vector dot product per joint of the chain, for revolute and
/// prismatic joints alike (equal to `dᵀ (a_j × (p − o_j))` and `dᵀ a_j` up to rounding).
pub fn point_jacobian_along(
    model: &RobotModel,
    data: &ModelData,
    frame: usize,
    point_in_frame: &Vector3<f64>,
    direction: &Vector3<f64>,
    out: &mut [f64],
) -> Result<(), ModelError> {
    check_point(model, frame, point_in_frame)?;
    if out.len() != model.nv() {
        return Err(ModelError::Dimension { what: "jacobian row length", expected: model.nv(), got: out.len() });
    }
    let r = (data.frame_pose[frame] * Point3::from(*point_in_frame)).coords - data.ref_point;
    let force = svec(&r.cross(direction), direction);
    // joints that do not move the frame: a zero column
    out.fill(0.0);
    let mut k = model.frames[frame].body;
    while let Some(j) = k {
        out[model.bodies[j].coord] += data.s[j].dot(&force);
        k = model.bodies[j].parent;
    }
    Ok(())
}

/// Linear velocity (world axes) of the point `point_in_frame` of frame `frame`, `J_v q̇` without
/// the Jacobian: `v_P = v_O + ω × r` from the frame's body velocity of the last
/// [`update_kinematics`] (zero for a frame attached to the world).
pub fn point_velocity(
    model: &RobotModel,
    data: &ModelData,
    frame: usize,
    point_in_frame: &Vector3<f64>,
) -> Result<Vector3<f64>, ModelError> {
    check_point(model, frame, point_in_frame)?;
    let Some(b) = model.frames[frame].body else {
        return Ok(Vector3::zeros());
    };
    let r = (data.frame_pose[frame] * Point3::from(*point_in_frame)).coords - data.ref_point;
    let v = &data.v[b];
    Ok(lin(v) + ang(v).cross(&r))
}

/// `J̇ q̇` of the point `point_in_frame` of frame `frame` (linear first, then angular): the
/// classical acceleration of the point (including the centripetal `ω × (ω × r)` term) and the
/// angular acceleration of the frame when q̈ = 0. Matches pinocchio's
/// `getFrameClassicalAcceleration(..., LOCAL_WORLD_ALIGNED)` after `forwardKinematics(q, q̇, 0)`.
pub fn point_jacobian_dot_qdot(
    model: &RobotModel,
    data: &ModelData,
    frame: usize,
    point_in_frame: &Vector3<f64>,
    out: &mut Vector6<f64>,
) -> Result<(), ModelError> {
    check_point(model, frame, point_in_frame)?;
    let Some(b) = model.frames[frame].body else {
        out.fill(0.0);
        return Ok(());
    };
    let p = (data.frame_pose[frame] * Point3::from(*point_in_frame)).coords;
    let r = p - data.ref_point;
    let (v, a) = (&data.v[b], &data.a_bias[b]);
    let (w, alpha) = (ang(v), ang(a));
    // spatial -> classical: a_P = a_O + α × r + ω × v_P, with v_P = v_O + ω × r
    let v_p = lin(v) + w.cross(&r);
    let acc = lin(a) + alpha.cross(&r) + w.cross(&v_p);
    *out = Vector6::new(acc[0], acc[1], acc[2], alpha[0], alpha[1], alpha[2]);
    Ok(())
}
