//! Moving patch wrenches between frames: patch world poses, interactive-force-control paper eq. (11) (patch forces
//! summed in a hand frame) and eq. (13) (patch wrench in world coordinates).

use nalgebra::{Isometry3, Vector3};

use super::aggregate::PatchWrench;
use super::layout::ResolvedLayout;

/// A wrench: force and moment (about a stated point) in one frame's coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Wrench {
    /// Force.
    pub force: Vector3<f64>,
    /// Moment.
    pub moment: Vector3<f64>,
}

/// World poses of the patch frames `wanted(j)` selects, `w_T_p = w_T_link * link_T_p`, into
/// `out` (indexed like `layout.patches()`, the other entries left as they are; resized,
/// allocating only when its capacity is too small). `frame_pose(frame)` gives a link's world
/// pose (kinematics already updated).
pub fn patch_poses_world<'a>(
    layout: &ResolvedLayout,
    frame_pose: impl Fn(usize) -> &'a Isometry3<f64>,
    wanted: impl Fn(usize) -> bool,
    out: &mut Vec<Isometry3<f64>>,
) {
    out.resize(layout.patches().len(), Isometry3::identity());
    for (j, (pose, patch)) in out.iter_mut().zip(layout.patches()).enumerate() {
        if wanted(j) {
            *pose = frame_pose(patch.frame) * patch.link_from_patch;
        }
    }
}

/// Interactive-force-control paper eq. (13): the patch wrench rotated into world coordinates,
/// `[w_R_p 0; 0 w_R_p] p_W`. The moment stays about the patch frame origin.
#[inline]
pub fn patch_wrench_world(world_from_patch: &Isometry3<f64>, wrench: &PatchWrench) -> Wrench {
    Wrench { force: world_from_patch.rotation * wrench.force, moment: world_from_patch.rotation * wrench.moment }
}

/// Interactive-force-control paper eq. (11): `h_F = sum_j h_R_{p_j} p_j_F` over the patches `j` with
/// `include(j)` true, with `h_R_p = w_R_h^T w_R_p`. `patch_poses` as from
/// [`patch_poses_world`], `wrenches` as from [`super::aggregate::aggregate_patches`].
pub fn sum_patch_forces_in_frame(
    world_from_hand: &Isometry3<f64>,
    patch_poses: &[Isometry3<f64>],
    wrenches: &[PatchWrench],
    include: impl Fn(usize) -> bool,
) -> Vector3<f64> {
    let mut sum_world = Vector3::zeros();
    for (j, (pose, w)) in patch_poses.iter().zip(wrenches).enumerate() {
        if include(j) {
            sum_world += pose.rotation * w.force;
        }
    }
    world_from_hand.rotation.inverse_transform_vector(&sum_world)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skin::layout::SkinLayout;
    use approx::assert_relative_eq;
    use nalgebra::{Translation3, UnitQuaternion};

    #[test]
    fn eq13_rotates_force_and_moment() {
        let pose = Isometry3::from_parts(
            Translation3::new(1.0, 2.0, 3.0),
            UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
        );
        let w = PatchWrench {
            force: Vector3::new(1.0, 0.0, 0.5),
            moment: Vector3::new(0.0, 2.0, 0.0),
            ..Default::default()
        };
        let ww = patch_wrench_world(&pose, &w);
        // Rz(90deg): x -> y, y -> -x; translation does not matter.
        assert_relative_eq!(ww.force, Vector3::new(0.0, 1.0, 0.5), epsilon = 1e-12);
        assert_relative_eq!(ww.moment, Vector3::new(-2.0, 0.0, 0.0), epsilon = 1e-12);
        assert_relative_eq!(ww.force.norm(), w.force.norm(), epsilon = 1e-12);
    }

    #[test]
    fn eq11_sum_in_hand_frame() {
        let text = "patches:\n  - {id: 1, link: a, rpy: [0, 0, 1.5707963267948966]}\n  - {id: 2, link: b}\n  - {id: 3, link: b}\ncells:\n  - {id: 1, patch: 1, position: [0, 0, 0], normal: [1, 0, 0]}\n";
        let l = SkinLayout::from_yaml_str(text, "t.yaml")
            .unwrap()
            .resolve_with(|n| Some(if n == "a" { 0 } else { 1 }))
            .unwrap();
        let frames = [
            Isometry3::from_parts(Translation3::new(0.3, 0.0, 0.0), UnitQuaternion::identity()),
            Isometry3::from_parts(
                Translation3::new(0.0, 0.0, 1.0),
                UnitQuaternion::from_euler_angles(std::f64::consts::FRAC_PI_2, 0.0, 0.0),
            ),
        ];
        let mut poses = Vec::new();
        patch_poses_world(&l, |f| &frames[f], |_| true, &mut poses);
        assert_relative_eq!(poses[0].translation.vector, Vector3::new(0.3, 0.0, 0.0));
        let w = |x: f64, y: f64, z: f64| PatchWrench { force: Vector3::new(x, y, z), ..Default::default() };
        let wrenches = [w(1.0, 0.0, 0.0), w(0.0, 1.0, 0.0), w(0.0, 0.0, 7.0)];
        // Patch 1: Rz(90) x -> world y. Patch 2: Rx(90) y -> world z. Patch 3 excluded.
        // Hand frame = Rz(90): world (0, 1, 1) -> hand (1, 0, 1).
        let hand = Isometry3::from_parts(
            Translation3::new(5.0, 5.0, 5.0),
            UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
        );
        let h = sum_patch_forces_in_frame(&hand, &poses, &wrenches, |j| j != 2);
        assert_relative_eq!(h, Vector3::new(1.0, 0.0, 1.0), epsilon = 1e-12);
    }
}
