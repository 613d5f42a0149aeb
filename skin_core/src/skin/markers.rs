//! What the skin feels, as display markers: the content of `/skin/markers` (RViz's
//! `visualization_msgs/MarkerArray`) without ROS, so that the aggregator node, the simulator's
//! recordings and its rendered frames draw the same thing.
//!
//! Per layout patch, two markers with stable ids (the patch index) in their own namespaces, both
//! in the patch's LINK frame (which the robot's TF tree resolves):
//! - [`CELLS_NS`]: a sphere list of the patch's active cells (fused signal above the activity
//!   threshold, the same rule as the aggregation), each coloured by [`cell_color`] (force signal
//!   red, proximity signal cyan);
//! - [`WRENCH_NS`]: an arrow from the centroid of the active cells along the patch force
//!   (interactive-force-control paper eq. 7: outward), [`ARROW_M_PER_UNIT`] metres per unit of
//!   fused signal.
//!
//! A patch that has become inactive gets a delete of both markers; an inactive patch that was
//! already deleted gets nothing; the first update after start begins with a delete-all (clears
//! what an earlier run left in RViz). Updating in place keeps RViz from accumulating markers and
//! avoids re-creating every marker each cycle; a viewer applies the updates in order.

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use super::aggregate::{cell_virtual_force, FusionParams, PatchWrench};
use super::layout::{ResolvedLayout, ResolvedPatch};
use super::signals::CellReading;

/// Namespace of the active-cell sphere lists.
pub const CELLS_NS: &str = "skin_cells";
/// Namespace of the patch wrench arrows.
pub const WRENCH_NS: &str = "skin_patch_wrench";
/// Sphere diameter of an active cell \[m\].
pub const CELL_DIAMETER_M: f64 = 0.02;
/// Arrow length per unit of patch force (fused, normalized signal) \[m\].
pub const ARROW_M_PER_UNIT: f64 = 0.05;
/// Colour of the patch wrench arrows.
pub const ARROW_COLOR: Rgba = [1.0, 0.85, 0.0, 1.0];
/// Arrow shaft diameter, head diameter, head length \[m\] (RViz's ARROW with two points).
pub const ARROW_SCALE: [f64; 3] = [0.01, 0.02, 0.02];

/// A colour: red, green, blue, alpha in \[0, 1\].
pub type Rgba = [f32; 4];

/// Colour of an active cell from its force and proximity signals in \[0, 1\]: `r = f`,
/// `g = b = p`, opaque (white: touched and close, black: neither).
pub fn cell_color(force_signal: f64, proximity_signal: f64) -> Rgba {
    let (f, p) = (force_signal as f32, proximity_signal as f32);
    [f, p, p, 1.0]
}

/// What a marker update does (`visualization_msgs/Marker` actions).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MarkerAction {
    /// Add or replace the marker `(ns, id)`.
    Add,
    /// Remove the marker `(ns, id)`.
    Delete,
    /// Remove every marker.
    DeleteAll,
}

/// The marker shapes the skin uses (`visualization_msgs/Marker` types).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MarkerShape {
    /// Spheres of diameter `scale` at `points`, coloured per point by `colors`.
    SphereList,
    /// An arrow from `points[0]` to `points[1]`; `scale`: shaft diameter, head diameter, head
    /// length.
    Arrow,
}

/// One marker update, the fields of `visualization_msgs/Marker` the skin sets (pose identity,
/// no lifetime).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SkinMarker {
    /// Namespace ([`CELLS_NS`] or [`WRENCH_NS`]; empty for a delete-all).
    pub ns: &'static str,
    /// Id within the namespace: the patch index.
    pub id: i32,
    /// Add, delete or delete all.
    pub action: MarkerAction,
    /// The shape (meaningful for adds).
    pub shape: MarkerShape,
    /// The link frame `points` are in (empty for deletes).
    pub frame: String,
    /// Sphere diameter (all three) or the arrow's dimensions \[m\].
    pub scale: [f64; 3],
    /// Colour of the whole marker.
    pub color: Rgba,
    /// Sphere centres or arrow start and end, in `frame` \[m\].
    pub points: Vec<[f64; 3]>,
    /// Per-point colours (sphere lists).
    pub colors: Vec<Rgba>,
}

impl SkinMarker {
    fn new(ns: &'static str, id: i32, action: MarkerAction, shape: MarkerShape) -> Self {
        SkinMarker {
            ns,
            id,
            action,
            shape,
            frame: String::new(),
            scale: [0.0; 3],
            color: [1.0; 4],
            points: Vec::new(),
            colors: Vec::new(),
        }
    }

    /// A delete-all: clears every marker of the display.
    pub fn delete_all() -> Self {
        Self::new("", 0, MarkerAction::DeleteAll, MarkerShape::SphereList)
    }
}

/// Builds the marker updates from the aggregation results, remembering what a viewer shows.
#[derive(Debug, Clone)]
pub struct SkinMarkers {
    /// Per patch: its markers are shown (added and not deleted since).
    shown: Vec<bool>,
    cleared: bool,
}

impl SkinMarkers {
    /// Nothing shown yet, for `layout`'s patches.
    pub fn new(layout: &ResolvedLayout) -> Self {
        SkinMarkers { shown: vec![false; layout.patches().len()], cleared: false }
    }

    /// Writes into `out` the updates that bring a viewer up to date with `readings` (indexed like
    /// `layout.cells()`) and `wrenches` (indexed like `layout.patches()`). `out` is empty when
    /// nothing changed in what is shown.
    pub fn update(
        &mut self,
        layout: &ResolvedLayout,
        readings: &[CellReading],
        fusion: &FusionParams,
        wrenches: &[PatchWrench],
        out: &mut Vec<SkinMarker>,
    ) {
        out.clear();
        if !self.cleared {
            out.push(SkinMarker::delete_all());
            self.cleared = true;
        }
        for (k, (patch, w)) in layout.patches().iter().zip(wrenches).enumerate() {
            let id = k as i32;
            if w.active_cells > 0 {
                out.push(cells_marker(layout, patch, readings, fusion, id));
                out.push(arrow_marker(patch, w, id));
                self.shown[k] = true;
            } else if self.shown[k] {
                out.push(SkinMarker::new(CELLS_NS, id, MarkerAction::Delete, MarkerShape::SphereList));
                out.push(SkinMarker::new(WRENCH_NS, id, MarkerAction::Delete, MarkerShape::Arrow));
                self.shown[k] = false;
            }
        }
    }
}

fn cells_marker(
    layout: &ResolvedLayout,
    patch: &ResolvedPatch,
    readings: &[CellReading],
    fusion: &FusionParams,
    id: i32,
) -> SkinMarker {
    let mut m = SkinMarker::new(CELLS_NS, id, MarkerAction::Add, MarkerShape::SphereList);
    m.frame.clone_from(&patch.link);
    m.scale = [CELL_DIAMETER_M; 3];
    let cells = &layout.cells()[patch.cells.clone()];
    for (cell, r) in cells.iter().zip(&readings[patch.cells.clone()]) {
        if cell_virtual_force(r, fusion) > fusion.activity_threshold {
            m.points.push(cell.position_link.into());
            m.colors.push(cell_color(r.force_signal(fusion.force_reduction), r.proximity_signal()));
        }
    }
    m
}

fn arrow_marker(patch: &ResolvedPatch, w: &PatchWrench, id: i32) -> SkinMarker {
    let mut m = SkinMarker::new(WRENCH_NS, id, MarkerAction::Add, MarkerShape::Arrow);
    m.frame.clone_from(&patch.link);
    m.scale = ARROW_SCALE;
    m.color = ARROW_COLOR;
    let start = patch.link_from_patch * Point3::from(w.centroid);
    let along: Vector3<f64> = patch.link_from_patch.rotation * w.force * ARROW_M_PER_UNIT;
    m.points = vec![start.coords.into(), (start + along).coords.into()];
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skin::aggregate::aggregate_patches;
    use crate::skin::layout::SkinLayout;
    use crate::skin::signals::ForceReduction;

    const FUSION: FusionParams =
        FusionParams { weight_force: 0.5, activity_threshold: 0.02, force_reduction: ForceReduction::Mean };

    fn layout() -> ResolvedLayout {
        let text = "patches:\n  - {id: 7, link: a, xyz: [0, 0, 1], rpy: [0, 0, 1.5707963267948966]}\n  \
                    - {id: 3, link: b}\ncells:\n  \
                    - {id: 10, patch: 7, position: [0.1, 0, 0], normal: [1, 0, 0]}\n  \
                    - {id: 11, patch: 7, position: [0, 0.1, 0], normal: [0, 1, 0]}\n  \
                    - {id: 20, patch: 3, position: [0, 0, 0.1], normal: [0, 0, 1]}\n";
        SkinLayout::from_yaml_str(text, "t.yaml").unwrap().resolve_with(|_| Some(1)).unwrap()
    }

    fn run(m: &mut SkinMarkers, l: &ResolvedLayout, r: &[CellReading]) -> Vec<SkinMarker> {
        let mut w = Vec::new();
        aggregate_patches(l, r, &FUSION, &mut w).unwrap();
        let mut out = Vec::new();
        m.update(l, r, &FUSION, &w, &mut out);
        out
    }

    #[test]
    fn active_cells_and_arrows_in_link_frames_then_deleted_once() {
        let l = layout();
        let mut m = SkinMarkers::new(&l);
        let mut r = vec![CellReading::default(); 3];
        r[l.cell_index(10).unwrap()] = CellReading::uniform(0.8, 0.4);
        let out = run(&mut m, &l, &r);
        let actions: Vec<MarkerAction> = out.iter().map(|m| m.action).collect();
        assert_eq!(actions, [MarkerAction::DeleteAll, MarkerAction::Add, MarkerAction::Add]);
        let (cells, arrow) = (&out[1], &out[2]);
        assert_eq!(
            (cells.ns, cells.id, cells.frame.as_str(), cells.shape),
            (CELLS_NS, 0, "a", MarkerShape::SphereList)
        );
        assert_eq!(cells.points.len(), 1);
        // Cell 10 at (0.1, 0, 0) in the patch frame, turned 90 degrees about z, 1 m up.
        let p = cells.points[0];
        assert!(p[0].abs() < 1e-9 && (p[1] - 0.1).abs() < 1e-9 && (p[2] - 1.0).abs() < 1e-9);
        assert_eq!(cells.colors[0], cell_color(0.8, 0.4));
        assert_eq!((arrow.ns, arrow.shape, arrow.frame.as_str()), (WRENCH_NS, MarkerShape::Arrow, "a"));
        // Force (0.6, 0, 0) in the patch frame is (0, 0.6, 0) in the link frame.
        let (a, b) = (arrow.points[0], arrow.points[1]);
        assert!((b[1] - a[1] - 0.6 * ARROW_M_PER_UNIT).abs() < 1e-9 && (b[0] - a[0]).abs() < 1e-9);

        let out = run(&mut m, &l, &[CellReading::default(); 3]);
        let deleted: Vec<(&str, i32, MarkerAction)> = out.iter().map(|m| (m.ns, m.id, m.action)).collect();
        assert_eq!(deleted, [(CELLS_NS, 0, MarkerAction::Delete), (WRENCH_NS, 0, MarkerAction::Delete)]);
        assert!(run(&mut m, &l, &[CellReading::default(); 3]).is_empty());
    }
}
