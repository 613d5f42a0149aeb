//! A force reference in newtons as a reference for the summed skin signal of eq. (7) of the
//! interactive-force-control paper, read with the contact's measured distribution over the cells.
//!
//! The paper's eq. (9) regulates `f_c = Σ_i c_i s_i`, the hand patches' summed force signals along
//! the hand's z axis (`c_i = n_i · z_h`, `s_i` the cell's force signal). The force characteristic
//! `s = f(F)` is nonlinear (high sensitivity at low forces), so that sum reads a contact of `F`
//! newtons lower the fewer cells share it: a reference computed for an even press of the palm
//! (`n f(F / n)`) made the hand push 14 N for 5 N on a board tilted by a few degrees, where the
//! palm touches with an edge. Each pressed cell's newtons are known through the inverse
//! characteristic, `F_i = f⁻¹(s_i)`; with the contact's measured shares `F_i / F`,
//! `F = Σ_i c_i F_i`, the reference for `F_d` newtons is what the same contact reads scaled to
//! `F_d`:
//!
//! ```text
//! f_c,d = Σ_i c_i f(F_d F_i / F)
//! ```
//!
//! `f_c = f_c,d` exactly when `F = F_d` (both sums scale the same shares, `f` is increasing), so
//! the loop settles at the reference in newtons whatever the distribution, and it keeps the
//! paper's signal space and its tuned gain: near `F_d` the error is that of the signal, saturation
//! and all (an edge cell near its saturation reads little change and is regulated gently). Up to
//! each cell's saturation `max_n` of the characteristic: beyond it a cell reads `max_n`.

use nalgebra::{Isometry3, Vector3};

use super::aggregate::FusionParams;
use super::characteristic::PreparedForce;
use super::layout::ResolvedLayout;
use super::live::LiveCells;

/// Calls `visit(c_i, F_i)` for every pressed cell (force signal above
/// `fusion.activity_threshold`, reduced per `fusion.force_reduction`) of the patches `include(j)`
/// selects: `c_i` the cell's outward normal along `axis` (world coordinates), `F_i` its newtons.
/// `patch_poses` as from [`super::transforms::patch_poses_world`] (those of the included patches
/// up to date).
#[allow(clippy::too_many_arguments)]
fn pressed_cells(
    layout: &ResolvedLayout,
    live: &LiveCells,
    force: &PreparedForce,
    fusion: &FusionParams,
    axis: &Vector3<f64>,
    patch_poses: &[Isometry3<f64>],
    include: impl Fn(usize) -> bool,
    mut visit: impl FnMut(f64, f64),
) {
    for (j, (patch, pose)) in layout.patches().iter().zip(patch_poses).enumerate() {
        if !include(j) {
            continue;
        }
        let axis_in_patch = pose.rotation.inverse_transform_vector(axis);
        let geometry = &layout.patch_geometry[patch.cells.clone()];
        for (i, r) in live.in_range(patch.cells.clone()) {
            let s = r.force_signal(fusion.force_reduction);
            if s > fusion.activity_threshold {
                visit(geometry[i - patch.cells.start].normal.dot(&axis_in_patch), force.force_n(s));
            }
        }
    }
}

/// The hand's contact as the force sensing reads it along `axis` (world coordinates, unit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasuredContact {
    /// `F = Σ_i c_i F_i` \[N\]: the pressed cells' newtons along `axis`.
    pub force_n: f64,
    /// `f_c,d = Σ_i c_i f(F_d F_i / F)`: the summed signal the same contact reads at `F_d`
    /// newtons; `None` when nothing presses along `axis` (`F <= 0`: no distribution to read
    /// the reference with).
    pub reference_signal: Option<f64>,
}

/// The contact the patches `include(j)` selects measure along `axis`, and the signal reference
/// for `reference_n` newtons with its distribution (module doc). No allocation.
#[allow(clippy::too_many_arguments)]
pub fn measured_contact(
    layout: &ResolvedLayout,
    live: &LiveCells,
    force: &PreparedForce,
    fusion: &FusionParams,
    axis: &Vector3<f64>,
    patch_poses: &[Isometry3<f64>],
    include: impl Fn(usize) -> bool + Copy,
    reference_n: f64,
) -> MeasuredContact {
    let mut force_n = 0.0;
    pressed_cells(layout, live, force, fusion, axis, patch_poses, include, |c, f| force_n += c * f);
    if force_n <= 0.0 {
        return MeasuredContact { force_n, reference_signal: None };
    }
    let scale = reference_n / force_n;
    let mut signal = 0.0;
    pressed_cells(layout, live, force, fusion, axis, patch_poses, include, |c, f| {
        signal += c * force.signal(scale * f)
    });
    MeasuredContact { force_n, reference_signal: Some(signal) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skin::aggregate::aggregate_live_patches;
    use crate::skin::characteristic::{ForceCharacteristic, ProximityCharacteristic};
    use crate::skin::layout::SkinLayout;
    use crate::skin::signals::{CellReading, ForceReduction};
    use crate::skin::transforms::sum_patch_forces_in_frame;
    use approx::assert_relative_eq;

    const FORCE: ForceCharacteristic = ForceCharacteristic { scale_n: 2.0, max_n: 10.0 };

    /// One flat patch of `n` cells, all facing +z of the link (and patch) frame.
    fn flat_patch(n: usize) -> ResolvedLayout {
        let cells: String = (0..n)
            .map(|i| {
                format!(
                    "  - {{id: {}, patch: 1, position: [{:.3}, 0, 0], normal: [0, 0, 1]}}\n",
                    i + 1,
                    0.02 * i as f64
                )
            })
            .collect();
        let yaml = format!("patches:\n  - {{id: 1, link: palm}}\ncells:\n{cells}");
        SkinLayout::from_yaml_str(&yaml, "flat.yaml").unwrap().resolve_with(|_| Some(0)).unwrap()
    }

    fn pressed(layout: &ResolvedLayout, newtons: &[f64]) -> LiveCells {
        let f = FORCE.prepared();
        let mut readings = vec![CellReading::default(); layout.num_cells()];
        for (r, &n) in readings.iter_mut().zip(newtons) {
            r.force = [f.signal(n); 3];
        }
        LiveCells::from_readings(&readings, &ProximityCharacteristic { range_m: 0.15, decay_m: 0.03 })
    }

    fn fusion() -> FusionParams {
        FusionParams { weight_force: 1.0, activity_threshold: 0.02, force_reduction: ForceReduction::Mean }
    }

    /// eq. (7)'s summed signal along z, as the hand task reads it.
    fn summed_signal(layout: &ResolvedLayout, live: &LiveCells) -> f64 {
        let mut w = Vec::new();
        aggregate_live_patches(layout, live, &fusion(), &mut w).unwrap();
        sum_patch_forces_in_frame(&Isometry3::identity(), &[Isometry3::identity()], &w, |_| true).z
    }

    fn contact(layout: &ResolvedLayout, live: &LiveCells, reference_n: f64) -> MeasuredContact {
        let poses = [Isometry3::identity()];
        measured_contact(layout, live, &FORCE.prepared(), &fusion(), &Vector3::z(), &poses, |_| true, reference_n)
    }

    /// 5 N on one edge cell or spread over six: the summed signal reads the edge contact far
    /// lower, the newtons read 5 N either way, and the reference for 5 N is exactly what each
    /// contact reads (the loop settles there), for 3 N below it.
    #[test]
    fn the_reference_is_met_at_the_force_in_newtons_whatever_the_distribution() {
        let layout = flat_patch(6);
        let (edge, even) = (pressed(&layout, &[5.0]), pressed(&layout, &[5.0 / 6.0; 6]));
        assert!(summed_signal(&layout, &edge) < 0.5 * summed_signal(&layout, &even));
        for live in [&edge, &even] {
            let c = contact(&layout, live, 5.0);
            assert_relative_eq!(c.force_n, 5.0, epsilon = 1e-9);
            assert_relative_eq!(c.reference_signal.unwrap(), summed_signal(&layout, live), epsilon = 1e-9);
            assert!(contact(&layout, live, 3.0).reference_signal.unwrap() < summed_signal(&layout, live) - 0.05);
        }
        // an uneven press, 4 N + 1 N: the same
        let uneven = pressed(&layout, &[4.0, 1.0]);
        assert_relative_eq!(
            contact(&layout, &uneven, 5.0).reference_signal.unwrap(),
            summed_signal(&layout, &uneven),
            epsilon = 1e-9
        );
    }

    /// A contact of half the reference is read at twice its newtons, cell by cell.
    #[test]
    fn the_reference_scales_each_cell_s_share() {
        let layout = flat_patch(3);
        let live = pressed(&layout, &[2.0, 0.5, 0.0]);
        let f = FORCE.prepared();
        let want = f.signal(4.0) + f.signal(1.0);
        assert_relative_eq!(contact(&layout, &live, 5.0).reference_signal.unwrap(), want, epsilon = 1e-9);
    }

    /// Nothing pressed: no distribution, no reference; a patch turned away (normal along -z)
    /// presses nothing along z either; an excluded patch is not read.
    #[test]
    fn without_a_press_along_the_axis_there_is_no_reference() {
        let layout = flat_patch(2);
        assert_eq!(contact(&layout, &pressed(&layout, &[0.0, 0.0]), 5.0).reference_signal, None);
        let live = pressed(&layout, &[3.0, 1.0]);
        let poses = [Isometry3::identity()];
        let down = -Vector3::z();
        let turned = measured_contact(&layout, &live, &FORCE.prepared(), &fusion(), &down, &poses, |_| true, 5.0);
        assert_relative_eq!(turned.force_n, -4.0, epsilon = 1e-9);
        assert_eq!(turned.reference_signal, None);
        let none =
            measured_contact(&layout, &live, &FORCE.prepared(), &fusion(), &Vector3::z(), &poses, |_| false, 5.0);
        assert_eq!(none, MeasuredContact { force_n: 0.0, reference_signal: None });
    }
}
