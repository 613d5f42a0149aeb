//! Cell fusion and patch wrenches: interactive-force-control paper eq. (6), (7), (8).
//!
//! Sign convention (interactive-force-control paper): the cell's virtual force `sF` acts along the +z axis of the cell
//! frame, i.e. along the OUTWARD normal. The physical force that a touch exerts on the robot
//! points inward; controllers react with `-K F` (interactive-force-control paper eq. (12)) to yield to it.

use crate::declare_params;
use crate::param_file::declare::{Declared, Range};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::characteristic::PreparedForce;
use super::layout::ResolvedLayout;
use super::live::LiveCells;
use super::signals::{CellReading, ForceReduction};
use crate::param_file::InvalidParam;

/// A per-cell input slice whose length does not match the layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
#[error("{what}: expected {expected} entries (one per layout cell), got {got}")]
pub struct LengthMismatch {
    /// Which input.
    pub what: &'static str,
    /// Number of cells in the layout.
    pub expected: usize,
    /// Length given.
    pub got: usize,
}

impl LengthMismatch {
    /// Checks that there is one reading per cell of `layout`.
    pub fn check_readings(layout: &ResolvedLayout, readings: &[CellReading]) -> Result<(), LengthMismatch> {
        Self::check_count(layout, readings.len())
    }

    /// Checks that `got` readings are one per cell of `layout`.
    pub fn check_count(layout: &ResolvedLayout, got: usize) -> Result<(), LengthMismatch> {
        if got == layout.cells().len() {
            Ok(())
        } else {
            Err(LengthMismatch { what: "cell readings", expected: layout.cells().len(), got })
        }
    }
}

declare_params! {
    /// Parameters of the force/proximity fusion (interactive-force-control paper eq. (6)) and of cell activity.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct FusionParams {
        /// `w` of interactive-force-control paper eq. (6): the cell's virtual force
        /// `sF = w f + (1 - w) p` (0: proximity only, 1: force only).
        pub weight_force: f64 => { unit: "", range: Range::closed(0.0, 1.0), live: true },
        /// A cell is active (enters the patch wrench, eq. 7-8) when its fused signal `sF` exceeds this.
        pub activity_threshold: f64 => { unit: "", range: Range::below(0.0, 1.0), live: true },
        /// How a cell's three force sensors make one signal.
        #[serde(default)]
        pub force_reduction: ForceReduction => { choices: "mean | max", live: true },
    }
}

impl FusionParams {
    /// The cell's measured force \[N\] (intentional-contact paper eq. (6)): its force signal,
    /// reduced per `force_reduction`, through the inverse characteristic `force`; `None` when the
    /// signal is not above `activity_threshold` (no contact).
    #[inline]
    pub fn cell_force_n(&self, reading: &CellReading, force: &PreparedForce) -> Option<f64> {
        let s = reading.force_signal(self.force_reduction);
        (s > self.activity_threshold).then(|| force.force_n(s))
    }

    /// Checks the declared ranges.
    pub fn validate(&self, prefix: &str) -> Result<(), InvalidParam> {
        self.check(prefix)
    }
}

/// Interactive-force-control paper eq. (6): the cell's virtual force `sF = w f + (1 - w) p` (signals in [0, 1]).
#[inline]
pub fn fuse(force_signal: f64, proximity_signal: f64, weight_force: f64) -> f64 {
    weight_force * force_signal + (1.0 - weight_force) * proximity_signal
}

/// Fused virtual force of one reading (sanitized signals, interactive-force-control paper eq. (6)).
#[inline]
pub fn cell_virtual_force(reading: &CellReading, fusion: &FusionParams) -> f64 {
    fuse(reading.force_signal(fusion.force_reduction), reading.proximity_signal(), fusion.weight_force)
}

/// The equivalent wrench of one patch in its patch frame {p_j}, with activity statistics.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PatchWrench {
    /// Interactive-force-control paper eq. (7): sum of the active cells' virtual forces `R sF` (outward normals),
    /// in the patch frame (units of the normalized signals).
    pub force: Vector3<f64>,
    /// Interactive-force-control paper eq. (8): sum of `t × R sF` about the patch frame origin, in the patch frame.
    pub moment: Vector3<f64>,
    /// Mean position of the active cells in the patch frame \[m\] (zero when none is active).
    pub centroid: Vector3<f64>,
    /// Number of active cells `n_{a_j}`.
    pub active_cells: usize,
    /// Largest force signal over all cells of the patch (active or not).
    pub max_force_signal: f64,
    /// Largest proximity signal over all cells of the patch (active or not).
    pub max_proximity_signal: f64,
    /// Eq. (8) of the proximity signals alone (as with `weight_force` 0), in the patch frame:
    /// the moment the compliant wrist turns the palm by before the touch (eq. 10).
    pub proximity_moment: Vector3<f64>,
}

/// Aggregates the cells of patch `patch` (index into `layout.patches()`) into its wrench
/// (interactive-force-control paper eq. (6)-(8)). `readings` is indexed like `layout.cells()`. No allocation.
pub fn aggregate_patch(
    layout: &ResolvedLayout,
    patch: usize,
    readings: &[CellReading],
    fusion: &FusionParams,
) -> Result<PatchWrench, LengthMismatch> {
    LengthMismatch::check_readings(layout, readings)?;
    Ok(aggregate_range(layout, patch, all_cells(layout, patch, readings), fusion))
}

/// Aggregates every patch (interactive-force-control paper eq. (6)-(8)) into `out`, indexed like `layout.patches()`.
/// `out` is resized to the number of patches (allocates only if its capacity is too small, i.e.
/// on the first call); `readings` is indexed like `layout.cells()`.
pub fn aggregate_patches(
    layout: &ResolvedLayout,
    readings: &[CellReading],
    fusion: &FusionParams,
    out: &mut Vec<PatchWrench>,
) -> Result<(), LengthMismatch> {
    LengthMismatch::check_readings(layout, readings)?;
    out.resize(layout.patches().len(), PatchWrench::default());
    for (k, w) in out.iter_mut().enumerate() {
        *w = aggregate_range(layout, k, all_cells(layout, k, readings), fusion);
    }
    Ok(())
}

/// [`aggregate_patches`] from the non-silent cells of the readings, collected once per cycle
/// (the same wrenches: a silent cell adds nothing).
pub fn aggregate_live_patches(
    layout: &ResolvedLayout,
    live: &LiveCells,
    fusion: &FusionParams,
    out: &mut Vec<PatchWrench>,
) -> Result<(), LengthMismatch> {
    LengthMismatch::check_count(layout, live.num_cells())?;
    out.resize(layout.patches().len(), PatchWrench::default());
    for (k, w) in out.iter_mut().enumerate() {
        let live = live.in_range(layout.patches()[k].cells.clone());
        *w = aggregate_range(layout, k, live.iter().map(|(i, r)| (*i, r)), fusion);
    }
    Ok(())
}

/// `(cell index, reading)` of the cells of patch `patch`.
fn all_cells<'a>(
    layout: &ResolvedLayout,
    patch: usize,
    readings: &'a [CellReading],
) -> impl Iterator<Item = (usize, &'a CellReading)> {
    let range = layout.patches()[patch].cells.clone();
    range.clone().zip(&readings[range])
}

/// The wrench of patch `patch` from `cells`, `(cell index, reading)` of cells of that patch.
#[inline]
fn aggregate_range<'a>(
    layout: &ResolvedLayout,
    patch: usize,
    cells: impl Iterator<Item = (usize, &'a CellReading)>,
    fusion: &FusionParams,
) -> PatchWrench {
    let geometry = &layout.patch_geometry[layout.patches()[patch].cells.clone()];
    let first = layout.patches()[patch].cells.start;
    let (wf, wp) = (fusion.weight_force, 1.0 - fusion.weight_force);
    let mut w = PatchWrench::default();
    let mut sum_t = Vector3::zeros();
    for (i, r) in cells {
        if r.is_silent() {
            continue;
        }
        let g = &geometry[i - first];
        let f = r.force_signal(fusion.force_reduction);
        let p = r.proximity_signal();
        w.max_force_signal = w.max_force_signal.max(f);
        w.max_proximity_signal = w.max_proximity_signal.max(p);
        if p > fusion.activity_threshold {
            w.proximity_moment += g.lever * p;
        }
        // Interactive-force-control paper eq. (6).
        let s = wf * f + wp * p;
        if s > fusion.activity_threshold {
            // {p}R_{s_i} [0 0 sF]^T = n_i sF (eq. 7); t_i × n_i sF = (t_i × n_i) sF (eq. 8).
            w.force += g.normal * s;
            w.moment += g.lever * s;
            sum_t += g.position;
            w.active_cells += 1;
        }
    }
    if w.active_cells > 0 {
        w.centroid = sum_t / w.active_cells as f64;
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skin::layout::SkinLayout;
    use approx::assert_relative_eq;

    fn fusion(w: f64) -> FusionParams {
        FusionParams { weight_force: w, activity_threshold: 0.01, force_reduction: ForceReduction::Mean }
    }

    fn layout(text: &str) -> ResolvedLayout {
        SkinLayout::from_yaml_str(text, "t.yaml").unwrap().resolve_with(|_| Some(0)).unwrap()
    }

    #[test]
    fn single_cell_analytic_wrench() {
        // Cell at t = (0.1, 0.02, 0.03) with normal n = (0, 0, 1) (after normalization).
        let l = layout(
            "patches:\n  - {id: 1, link: a}\ncells:\n  - {id: 1, patch: 1, position: [0.1, 0.02, 0.03], normal: [0, 0, 5]}\n",
        );
        let r = [CellReading::uniform(0.8, 0.4)];
        let w = aggregate_patch(&l, 0, &r, &fusion(0.25)).unwrap();
        let s = 0.25 * 0.8 + 0.75 * 0.4;
        assert_relative_eq!(w.force, Vector3::new(0.0, 0.0, s), epsilon = 1e-15);
        // t × (0,0,s) = (ty s, -tx s, 0)
        assert_relative_eq!(w.moment, Vector3::new(0.02 * s, -0.1 * s, 0.0), epsilon = 1e-15);
        assert_eq!(w.active_cells, 1);
        assert_relative_eq!(w.centroid, Vector3::new(0.1, 0.02, 0.03));
        assert_relative_eq!(w.max_force_signal, 0.8, epsilon = 1e-15);
        assert_eq!(w.max_proximity_signal, 0.4);
    }

    #[test]
    fn weight_selects_modality() {
        let l = layout(
            "patches:\n  - {id: 1, link: a}\ncells:\n  - {id: 1, patch: 1, position: [0, 0, 0], normal: [1, 0, 0]}\n",
        );
        let r = [CellReading::uniform(0.7, 0.2)];
        let w0 = aggregate_patch(&l, 0, &r, &fusion(0.0)).unwrap();
        let w1 = aggregate_patch(&l, 0, &r, &fusion(1.0)).unwrap();
        assert_relative_eq!(w0.force, Vector3::new(0.2, 0.0, 0.0), epsilon = 1e-15);
        assert_relative_eq!(w1.force, Vector3::new(0.7, 0.0, 0.0), epsilon = 1e-15);
        // Below threshold: inactive, no force, statistics still reported.
        let r = [CellReading::uniform(0.0, 0.005)];
        let w = aggregate_patch(&l, 0, &r, &fusion(0.0)).unwrap();
        assert_eq!(w.active_cells, 0);
        assert_eq!(w.force, Vector3::zeros());
        assert_eq!(w.max_proximity_signal, 0.005);
    }

    #[test]
    fn symmetric_pattern_has_no_moment() {
        // A flat 5x5 grid centred on the patch origin, normals +z, uniform signals; plus a ring
        // of radial cells on a cylinder about z, symmetric about the origin.
        let mut text = String::from("patches:\n  - {id: 1, link: a}\n  - {id: 2, link: b}\ncells:\n");
        let mut id = 0;
        for i in -2..=2 {
            for j in -2..=2 {
                id += 1;
                text += &format!(
                    "  - {{id: {id}, patch: 1, position: [{}, {}, 0.01], normal: [0, 0, 1]}}\n",
                    0.025 * i as f64,
                    0.025 * j as f64
                );
            }
        }
        for k in 0..8 {
            let a = k as f64 * std::f64::consts::PI / 4.0;
            for z in [-0.05, 0.05] {
                id += 1;
                text += &format!(
                    "  - {{id: {id}, patch: 2, position: [{}, {}, {z}], normal: [{}, {}, 0]}}\n",
                    0.04 * a.cos(),
                    0.04 * a.sin(),
                    a.cos(),
                    a.sin()
                );
            }
        }
        let l = layout(&text);
        let r = vec![CellReading::uniform(0.5, 0.5); l.num_cells()];
        let mut out = Vec::new();
        aggregate_patches(&l, &r, &fusion(0.5), &mut out).unwrap();
        assert_eq!(out.len(), 2);
        assert_relative_eq!(out[0].moment, Vector3::zeros(), epsilon = 1e-12);
        assert_relative_eq!(out[0].force, Vector3::new(0.0, 0.0, 25.0 * 0.5), epsilon = 1e-12);
        assert_eq!(out[0].active_cells, 25);
        assert_relative_eq!(out[1].moment, Vector3::zeros(), epsilon = 1e-12);
        assert_relative_eq!(out[1].force, Vector3::zeros(), epsilon = 1e-12);
        assert_eq!(out[1].active_cells, 16);
        // Reuse: no reallocation on the second call.
        let cap = out.capacity();
        let ptr = out.as_ptr();
        aggregate_patches(&l, &r, &fusion(0.5), &mut out).unwrap();
        assert_eq!((out.capacity(), out.as_ptr()), (cap, ptr));
    }

    #[test]
    fn live_cells_give_the_same_wrenches() {
        let mut text = String::from("patches:\n  - {id: 1, link: a}\n  - {id: 2, link: b}\ncells:\n");
        for id in 1..=12 {
            let (patch, x) = (1 + id / 7, 0.01 * id as f64);
            text += &format!("  - {{id: {id}, patch: {patch}, position: [{x}, 0, 0], normal: [0, {x}, 1]}}\n");
        }
        let l = layout(&text);
        let mut r = vec![CellReading::default(); l.num_cells()];
        r[1] = CellReading::uniform(0.4, 0.0);
        r[6].proximity = 0.7;
        r[7].force = [0.0, 0.9, f64::NAN];
        r[11] = CellReading::uniform(0.005, 0.0); // below the activity threshold
        let (mut all, mut live) = (Vec::new(), Vec::new());
        aggregate_patches(&l, &r, &fusion(0.5), &mut all).unwrap();
        let prox = crate::skin::characteristic::ProximityCharacteristic { range_m: 0.2, decay_m: 0.05 };
        aggregate_live_patches(&l, &LiveCells::from_readings(&r, &prox), &fusion(0.5), &mut live).unwrap();
        assert_eq!(all, live);
        assert_eq!(live.iter().map(|w| w.active_cells).collect::<Vec<_>>(), [1, 2]);
    }

    #[test]
    fn length_mismatch_is_an_error() {
        let l = layout(
            "patches:\n  - {id: 1, link: a}\ncells:\n  - {id: 1, patch: 1, position: [0, 0, 0], normal: [1, 0, 0]}\n",
        );
        let mut out = Vec::new();
        let e = aggregate_patches(&l, &[], &fusion(0.5), &mut out).unwrap_err();
        assert_eq!((e.expected, e.got), (1, 0));
    }
}
