//! The hand's contact in newtons, read cell by cell through the inverse force characteristic:
//! the force of interactive-force-control paper eq. (9) and the moment of eq. (10) per newton.
//!
//! The paper's eq. (9) regulates `f_c = Σ_i c_i s_i`, the hand patches' summed force signals along
//! the hand's z axis (`c_i = n_i · z_h`, `s_i` the cell's force signal), and eq. (10) their
//! moment (eq. 8). The force characteristic `s = f(F)` is nonlinear (high sensitivity at low
//! forces, saturation at `max_n`), so those sums read a contact of `F` newtons lower the fewer
//! cells share it: on a board tilted by a few degrees, where the palm touches with an edge or a
//! corner, the touching cells sit near their saturation; a reference for an even press of the
//! palm made the hand push 14 N for 5 N; a reference read with the contact's measured
//! distribution (`Σ_i c_i f(F_d F_i / F)`) left the loop little gain on cells near saturation, and
//! the signals' moment of an edge barely grows with the force on it (the palm turned flat a few
//! degrees per second). Each pressed cell's newtons are known through
//! the inverse characteristic, `F_i = f⁻¹(s_i)`; the hand's contact is
//!
//! ```text
//! F = Σ_i c_i F_i            (eq. 7 along z_h, in newtons)
//! Γ = Σ_i t_i × n_i F_i      (eq. 8, in newtons)
//! ```
//!
//! whatever the distribution: the hand force task (`tasks::hand_force`) regulates `F` to the
//! reference in newtons, the compliant wrist (`tasks::wrist`) drives `Γ` to zero in contact. Up to
//! each cell's saturation `max_n`: beyond it a cell reads `max_n`.

use nalgebra::{Isometry3, Vector3};

use super::aggregate::FusionParams;
use super::characteristic::PreparedForce;
use super::layout::ResolvedLayout;
use super::live::LiveCells;

/// The hand's contact as the force sensing reads it (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasuredContact {
    /// `F = Σ_i c_i F_i` \[N\]: the pressed cells' newtons along `axis`.
    pub force_n: f64,
    /// `Σ_j R_j Σ_i t_i × n_i F_i` \[N m\], world axes: eq. (8) with each pressed cell's newtons
    /// instead of its signal, about each patch's origin (the moment the compliant wrist of
    /// eq. 10 drives to zero in the contact phase, `tasks::wrist`).
    pub moment_nm: Vector3<f64>,
}

/// The contact the patches `include(j)` selects measure along `axis` (module doc): every pressed
/// cell (force signal above `fusion.activity_threshold`, reduced per `fusion.force_reduction`)
/// with `c_i` along `axis` (world coordinates). `patch_poses` as from
/// [`super::transforms::patch_poses_world`] (those of the included patches up to date). No
/// allocation.
pub fn measured_contact(
    layout: &ResolvedLayout,
    live: &LiveCells,
    force: &PreparedForce,
    fusion: &FusionParams,
    axis: &Vector3<f64>,
    patch_poses: &[Isometry3<f64>],
    include: impl Fn(usize) -> bool,
) -> MeasuredContact {
    let mut c = MeasuredContact { force_n: 0.0, moment_nm: Vector3::zeros() };
    for (j, (patch, pose)) in layout.patches().iter().zip(patch_poses).enumerate() {
        if !include(j) {
            continue;
        }
        let axis_in_patch = pose.rotation.inverse_transform_vector(axis);
        let geometry = &layout.patch_geometry[patch.cells.clone()];
        for (i, r) in live.in_range(patch.cells.clone()) {
            if let Some(f_i) = fusion.cell_force_n(r, force) {
                let g = &geometry[i - patch.cells.start];
                c.force_n += g.normal.dot(&axis_in_patch) * f_i; // c_i F_i
                c.moment_nm += pose.rotation * (g.lever * f_i); // R_j (t_i × n_i) F_i
            }
        }
    }
    c
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

    fn contact(layout: &ResolvedLayout, live: &LiveCells) -> MeasuredContact {
        let poses = [Isometry3::identity()];
        measured_contact(layout, live, &FORCE.prepared(), &fusion(), &Vector3::z(), &poses, |_| true)
    }

    /// 5 N on one edge cell or spread over six or unevenly over two: the summed signal reads the
    /// edge contact far lower, the newtons read 5 N each time.
    #[test]
    fn the_force_is_read_in_newtons_whatever_the_distribution() {
        let layout = flat_patch(6);
        let (edge, even) = (pressed(&layout, &[5.0]), pressed(&layout, &[5.0 / 6.0; 6]));
        assert!(summed_signal(&layout, &edge) < 0.5 * summed_signal(&layout, &even));
        for live in [&edge, &even, &pressed(&layout, &[4.0, 1.0])] {
            assert_relative_eq!(contact(&layout, live).force_n, 5.0, epsilon = 1e-9);
        }
    }

    /// The moment is the cells' newtons times their levers (eq. 8 in newtons), whatever their
    /// signals read: 6 N on one cell near its saturation counts 6 N, twice that on two cells
    /// twice as much; it turns with the patch.
    #[test]
    fn the_moment_is_that_of_the_cells_newtons() {
        let layout = flat_patch(6);
        // cells at x = 0, 0.02, ..., 0.1, normals +z: lever t × n = (0, -x, 0)
        let one = contact(&layout, &pressed(&layout, &[0.0, 0.0, 0.0, 0.0, 0.0, 6.0]));
        assert_relative_eq!(one.moment_nm, Vector3::new(0.0, -0.6, 0.0), epsilon = 1e-9);
        let two = contact(&layout, &pressed(&layout, &[0.0, 0.0, 0.0, 0.0, 6.0, 6.0]));
        assert_relative_eq!(two.moment_nm, Vector3::new(0.0, -(0.08 + 0.1) * 6.0, 0.0), epsilon = 1e-9);
        let uneven = contact(&layout, &pressed(&layout, &[4.0, 1.0]));
        assert_relative_eq!(uneven.moment_nm, Vector3::new(0.0, -0.02, 0.0), epsilon = 1e-9);
        // the same patch rotated by 90° about z: the moment turns with it
        let live = pressed(&layout, &[0.0, 0.0, 0.0, 0.0, 0.0, 6.0]);
        let turned = [Isometry3::rotation(Vector3::z() * std::f64::consts::FRAC_PI_2)];
        let c = measured_contact(&layout, &live, &FORCE.prepared(), &fusion(), &Vector3::z(), &turned, |_| true);
        assert_relative_eq!(c.moment_nm, Vector3::new(0.6, 0.0, 0.0), epsilon = 1e-9);
    }

    /// Nothing pressed: nothing read; a patch turned away (normal along -z) reads a negative force
    /// along z; an excluded patch is not read.
    #[test]
    fn only_the_pressed_cells_of_the_included_patches_count() {
        let layout = flat_patch(2);
        let nothing = MeasuredContact { force_n: 0.0, moment_nm: Vector3::zeros() };
        assert_eq!(contact(&layout, &pressed(&layout, &[0.0, 0.0])), nothing);
        let live = pressed(&layout, &[3.0, 1.0]);
        let poses = [Isometry3::identity()];
        let down = -Vector3::z();
        let turned = measured_contact(&layout, &live, &FORCE.prepared(), &fusion(), &down, &poses, |_| true);
        assert_relative_eq!(turned.force_n, -4.0, epsilon = 1e-9);
        let none = measured_contact(&layout, &live, &FORCE.prepared(), &fusion(), &Vector3::z(), &poses, |_| false);
        assert_eq!(none, nothing);
    }
}
