//! Joint torques `J^T F` of skin forces: per cell (intentional-contact paper eq. (4), (6)) and per patch
//! (interactive-force-control paper eq. (14)).
//!
//! Instead of building a 6×n Jacobian per force, each force is pushed down the chain of joints
//! that support its link: for a revolute joint `j` with world axis `a_j` through `o_j`,
//! `tau_j += a_j · ((p - o_j) × F) + a_j · Γ`; for a prismatic joint `tau_j += a_j · F`. This is
//! exactly `J_v(p)^T F + J_w^T Γ` with the world-aligned Jacobian of the point `p`, and costs
//! O(depth) per force with no allocation. Kinematics must be up to date
//! ([`crate::model::update_kinematics`]).

use nalgebra::{DVector, Isometry3, Vector3};

use super::aggregate::PatchWrench;
use super::cell_forces::PointForce;
use super::layout::ResolvedLayout;
use crate::model::{JointKind, ModelData, RobotModel};

/// Adds `J(p)^T [F; Γ]` for a force `force` at world point `point` plus a moment `moment`, all in
/// world coordinates, on the link `frame`, into `tau` (length `model.nv()`).
#[inline]
pub fn add_wrench_torques(
    model: &RobotModel,
    data: &ModelData,
    frame: usize,
    point: &Vector3<f64>,
    force: &Vector3<f64>,
    moment: &Vector3<f64>,
    tau: &mut DVector<f64>,
) {
    let mut joint = model.frame_parent_joint(frame);
    while let Some(j) = joint {
        let axis = data.joint_axis_world(j);
        tau[j] += match model.joint_kind(j) {
            JointKind::Revolute => {
                let r = point - data.joint_pose(j).translation.vector;
                axis.dot(&(r.cross(force) + moment))
            }
            JointKind::Prismatic => axis.dot(force),
        };
        joint = model.joint_parent(j);
    }
}

/// Intentional-contact paper eq. (4) / (6): `tau = sum_i J_v(p_i)^T F_i` over the point forces (linear part
/// only). Overwrites `tau` (length `model.nv()`). No allocation.
///
/// # Panics
/// If `tau.len() != model.nv()`.
pub fn point_forces_to_torques(model: &RobotModel, data: &ModelData, forces: &[PointForce], tau: &mut DVector<f64>) {
    assert_eq!(tau.len(), model.nv(), "tau must have model.nv() entries");
    tau.fill(0.0);
    let zero = Vector3::zeros();
    for f in forces {
        add_wrench_torques(model, data, f.frame, &f.point, &f.force, &zero, tau);
    }
}

/// Interactive-force-control paper eq. (13)-(14): `tau = sum_j J_{p_j}^T w_W_{p_j}` over the patches `j` with
/// `include(j)`; each patch wrench ([`PatchWrench`], patch frame, moment about the patch origin)
/// is rotated to world (eq. (13)) and applied at the patch origin. `frame_pose` is not needed:
/// patch poses come from `data`. Overwrites `tau` (length `model.nv()`). No allocation.
///
/// Note the sign convention of [`PatchWrench`] (virtual force along the outward normals).
///
/// # Panics
/// If `tau.len() != model.nv()` or `wrenches` is shorter than `layout.patches()`.
pub fn patch_wrenches_to_torques(
    model: &RobotModel,
    data: &ModelData,
    layout: &ResolvedLayout,
    wrenches: &[PatchWrench],
    include: impl Fn(usize) -> bool,
    tau: &mut DVector<f64>,
) {
    assert_eq!(tau.len(), model.nv(), "tau must have model.nv() entries");
    assert!(wrenches.len() >= layout.patches().len(), "one wrench per patch");
    tau.fill(0.0);
    for (j, (patch, w)) in layout.patches().iter().zip(wrenches).enumerate() {
        if !include(j) || w.active_cells == 0 {
            continue;
        }
        let pose: Isometry3<f64> = data.frame_pose(patch.frame) * patch.link_from_patch;
        let force = pose.rotation * w.force;
        let moment = pose.rotation * w.moment;
        add_wrench_torques(model, data, patch.frame, &pose.translation.vector, &force, &moment, tau);
    }
}
