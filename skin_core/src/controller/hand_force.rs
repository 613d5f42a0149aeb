//! What the summed hand signal of the interactive-force-control paper reads for a force in
//! newtons, and whether a hand can sense a contact force at all.
//!
//! The paper's eq. (9) regulates `f_c`, the z component (hand frame) of the hand patches' force of
//! eq. (7): the sum of the active cells' fused signals along their normals. In the contact phase
//! the fusion weight is 1, so a cell pressed by `F_i` newtons contributes `f(F_i)`, the force
//! characteristic of `config/skin_model.yaml` (`f(F) = (1 - e^{-F/s}) / (1 - e^{-F_max/s})`).
//! A flat contact of `F` newtons shared evenly by the `n` hand cells that face along the palm
//! normal therefore reads
//!
//! ```text
//! f_c(F) = n f(F / n)
//! ```
//!
//! and that is what this map gives for `F`. The characteristic is nonlinear, so an uneven
//! distribution (an edge of the palm on a tilted surface) reads lower for the same force: the
//! controller therefore regulates the measured newtons instead (`skin::measured`, each cell
//! inverted before the sum), and this map only tells whether a hand has cells facing along its
//! normal (no force reference without them) and what the paper's summed signal would read
//! (skin_sim records it beside the newtons).

use super::setup::ControllerConfig;
use crate::skin::characteristic::PreparedForce;
use nalgebra::Vector3;

/// A cell counts as facing along the palm normal when `n_i · z_h` exceeds this (within ~25°).
const FACING_COS: f64 = 0.9;

/// The map `F \[N\] -> n f(F / n)` (the summed signal of an even press) for one controller's hand.
#[derive(Debug, Clone, Copy)]
pub struct HandForceMap {
    /// Hand cells facing along the hand's z axis.
    cells: usize,
    force: PreparedForce,
}

impl HandForceMap {
    /// The map for the controller's hand patches and end-effector frame; None when the setup has
    /// no hand cell facing along the end effector's z axis.
    pub fn new(config: &ControllerConfig) -> Option<Self> {
        let model = &config.model;
        let ee = model.frame_index(&config.setup.end_effector)?;
        let hand_from_body = model.frame_placement(ee).inverse();
        let layout = &config.layout;
        let hand_patch = |p: usize| config.setup.hand_patches.contains(&layout.patches()[p].id);
        let cells = layout
            .cells()
            .iter()
            .filter(|c| hand_patch(c.patch) && model.frame_parent_joint(c.frame) == model.frame_parent_joint(ee))
            .filter(|c| {
                let normal = hand_from_body * model.frame_placement(c.frame) * c.normal_link;
                normal.dot(&Vector3::z()) > FACING_COS
            })
            .count();
        (cells > 0).then(|| HandForceMap { cells, force: config.skin.force.prepared() })
    }

    /// Number of hand cells facing along the palm normal (`n`).
    pub fn cells(&self) -> usize {
        self.cells
    }

    /// `n f(F / n)`: the fused hand signal of `force_n` newtons shared evenly by the facing cells.
    pub fn signal(&self, force_n: f64) -> f64 {
        let n = self.cells as f64;
        n * self.force.signal(force_n / n)
    }
}
