//! `/skin/markers`: what the skin feels, for RViz.
//!
//! Per layout patch, two markers with stable ids (the patch index) in their own namespaces, both
//! in the patch's LINK frame (which the robot's TF tree resolves):
//! - [`CELLS_NS`]: a `SPHERE_LIST` of the patch's active cells (fused signal above the activity
//!   threshold, the same rule as the aggregation), each coloured `r = f`, `g = b = p` (force
//!   signal red, proximity signal cyan), alpha 1;
//! - [`WRENCH_NS`]: an `ARROW` from the centroid of the active cells along the patch force
//!   (paper 003 eq. 7: outward), [`ARROW_M_PER_UNIT`] metres per unit of fused signal.
//!
//! A patch that has become inactive gets a `DELETE` of both markers (stamped too); an inactive patch that was
//! already deleted gets nothing; the first array after start begins with a `DELETEALL` (clears
//! what an earlier run left in RViz). Updating in place keeps RViz from accumulating markers and
//! avoids re-creating every marker each cycle.
use nalgebra::{Point3, Vector3};
use r2r::builtin_interfaces::msg::Time;
use r2r::geometry_msgs::msg::Point;
use r2r::std_msgs::msg::ColorRGBA;
use r2r::visualization_msgs::msg::{Marker, MarkerArray};
use skin_core::skin::aggregate::{cell_virtual_force, FusionParams, PatchWrench};
use skin_core::skin::layout::{ResolvedLayout, ResolvedPatch};
use skin_core::skin::signals::CellReading;

/// Namespace of the active-cell sphere lists.
pub const CELLS_NS: &str = "skin_cells";
/// Namespace of the patch wrench arrows.
pub const WRENCH_NS: &str = "skin_patch_wrench";
/// Sphere diameter of an active cell [m].
pub const CELL_DIAMETER_M: f64 = 0.02;
/// Arrow length per unit of patch force (fused, normalized signal) [m].
pub const ARROW_M_PER_UNIT: f64 = 0.05;

const ARROW_COLOR: ColorRGBA = ColorRGBA {
    r: 1.0,
    g: 0.85,
    b: 0.0,
    a: 1.0,
};

/// Colour of an active cell from its force and proximity signals in [0, 1].
pub fn cell_color(force_signal: f64, proximity_signal: f64) -> ColorRGBA {
    let (f, p) = (force_signal as f32, proximity_signal as f32);
    ColorRGBA {
        r: f,
        g: p,
        b: p,
        a: 1.0,
    }
}

/// Builds the marker arrays from the aggregation results, remembering what RViz shows.
#[derive(Debug, Clone)]
pub struct SkinMarkers {
    /// Per patch: its markers are shown (added and not deleted since).
    shown: Vec<bool>,
    cleared: bool,
}

impl SkinMarkers {
    /// Nothing shown yet, for `layout`'s patches.
    pub fn new(layout: &ResolvedLayout) -> Self {
        SkinMarkers {
            shown: vec![false; layout.patches().len()],
            cleared: false,
        }
    }

    /// Writes into `out` the markers that bring RViz up to date with `readings` (indexed like
    /// `layout.cells()`) and `wrenches` (indexed like `layout.patches()`), stamped `stamp`.
    /// `out` is empty when nothing changed in what is shown.
    pub fn update(
        &mut self,
        layout: &ResolvedLayout,
        readings: &[CellReading],
        fusion: &FusionParams,
        wrenches: &[PatchWrench],
        stamp: &Time,
        out: &mut MarkerArray,
    ) {
        out.markers.clear();
        if !self.cleared {
            out.markers.push(delete_all());
            self.cleared = true;
        }
        for (k, (patch, w)) in layout.patches().iter().zip(wrenches).enumerate() {
            let id = k as i32;
            if w.active_cells > 0 {
                out.markers
                    .push(cells_marker(layout, patch, readings, fusion, stamp, id));
                out.markers.push(arrow_marker(patch, w, stamp, id));
                self.shown[k] = true;
            } else if self.shown[k] {
                out.markers.push(delete(CELLS_NS, id, stamp));
                out.markers.push(delete(WRENCH_NS, id, stamp));
                self.shown[k] = false;
            }
        }
    }
}

/// A `DELETEALL` marker: clears every marker of the display.
pub fn delete_all() -> Marker {
    Marker {
        action: Marker::DELETEALL as i32,
        ..Default::default()
    }
}

fn delete(ns: &str, id: i32, stamp: &Time) -> Marker {
    let mut m = Marker {
        ns: ns.to_string(),
        id,
        action: Marker::DELETE as i32,
        ..Default::default()
    };
    m.header.stamp = stamp.clone();
    m
}

fn added(ns: &str, id: i32, kind: i32, frame: &str, stamp: &Time) -> Marker {
    let mut m = Marker {
        ns: ns.to_string(),
        id,
        type_: kind,
        action: Marker::ADD as i32,
        ..Default::default()
    };
    m.header.frame_id = frame.to_string();
    m.header.stamp = stamp.clone();
    m.pose.orientation.w = 1.0;
    m
}

fn point(p: &Point3<f64>) -> Point {
    Point {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

fn cells_marker(
    layout: &ResolvedLayout,
    patch: &ResolvedPatch,
    readings: &[CellReading],
    fusion: &FusionParams,
    stamp: &Time,
    id: i32,
) -> Marker {
    let mut m = added(CELLS_NS, id, Marker::SPHERE_LIST as i32, &patch.link, stamp);
    m.scale.x = CELL_DIAMETER_M;
    m.scale.y = CELL_DIAMETER_M;
    m.scale.z = CELL_DIAMETER_M;
    m.color = ColorRGBA {
        r: 1.0,
        g: 1.0,
        b: 1.0,
        a: 1.0,
    };
    let cells = &layout.cells()[patch.cells.clone()];
    for (cell, r) in cells.iter().zip(&readings[patch.cells.clone()]) {
        if cell_virtual_force(r, fusion) > fusion.activity_threshold {
            m.points.push(point(&Point3::from(cell.position_link)));
            m.colors.push(cell_color(
                r.force_signal(fusion.force_reduction),
                r.proximity_signal(),
            ));
        }
    }
    m
}

fn arrow_marker(patch: &ResolvedPatch, w: &PatchWrench, stamp: &Time, id: i32) -> Marker {
    let mut m = added(WRENCH_NS, id, Marker::ARROW as i32, &patch.link, stamp);
    // ARROW with two points: scale.x shaft diameter, scale.y head diameter, scale.z head length.
    m.scale.x = 0.01;
    m.scale.y = 0.02;
    m.scale.z = 0.02;
    m.color = ARROW_COLOR;
    let start = patch.link_from_patch * Point3::from(w.centroid);
    let along: Vector3<f64> = patch.link_from_patch.rotation * w.force * ARROW_M_PER_UNIT;
    m.points = vec![point(&start), point(&(start + along))];
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use skin_core::skin::aggregate::aggregate_patches;
    use skin_core::skin::layout::SkinLayout;
    use skin_core::skin::signals::ForceReduction;

    const FUSION: FusionParams = FusionParams {
        weight_force: 0.5,
        activity_threshold: 0.02,
        force_reduction: ForceReduction::Mean,
    };

    fn layout() -> ResolvedLayout {
        let text =
            "patches:\n  - {id: 7, link: a, xyz: [0, 0, 1], rpy: [0, 0, 1.5707963267948966]}\n  \
                    - {id: 3, link: b}\ncells:\n  \
                    - {id: 10, patch: 7, position: [0.1, 0, 0], normal: [1, 0, 0]}\n  \
                    - {id: 11, patch: 7, position: [0, 0.1, 0], normal: [0, 1, 0]}\n  \
                    - {id: 20, patch: 3, position: [0, 0, 0.1], normal: [0, 0, 1]}\n";
        SkinLayout::from_yaml_str(text, "t.yaml")
            .unwrap()
            .resolve_with(|_| Some(1))
            .unwrap()
    }

    fn run(m: &mut SkinMarkers, l: &ResolvedLayout, r: &[CellReading]) -> MarkerArray {
        let mut w = Vec::new();
        aggregate_patches(l, r, &FUSION, &mut w).unwrap();
        let mut out = MarkerArray::default();
        m.update(l, r, &FUSION, &w, &Time::default(), &mut out);
        out
    }

    #[test]
    fn active_cells_and_arrows_in_link_frames_then_deleted_once() {
        let l = layout();
        let mut m = SkinMarkers::new(&l);
        let mut r = vec![CellReading::default(); 3];
        r[l.cell_index(10).unwrap()] = CellReading::uniform(0.8, 0.4);
        let out = run(&mut m, &l, &r);
        let actions: Vec<i32> = out.markers.iter().map(|m| m.action).collect();
        assert_eq!(
            actions,
            [
                Marker::DELETEALL as i32,
                Marker::ADD as i32,
                Marker::ADD as i32
            ]
        );
        let (cells, arrow) = (&out.markers[1], &out.markers[2]);
        assert_eq!(
            (cells.ns.as_str(), cells.id, cells.header.frame_id.as_str()),
            (CELLS_NS, 0, "a")
        );
        assert_eq!(cells.type_, Marker::SPHERE_LIST as i32);
        assert_eq!(cells.points.len(), 1);
        // Cell 10 at (0.1, 0, 0) in the patch frame, turned 90 degrees about z, 1 m up.
        let p = &cells.points[0];
        assert!((p.x).abs() < 1e-9 && (p.y - 0.1).abs() < 1e-9 && (p.z - 1.0).abs() < 1e-9);
        assert_eq!(cells.colors[0], cell_color(0.8, 0.4));
        assert_eq!(
            (arrow.ns.as_str(), arrow.type_),
            (WRENCH_NS, Marker::ARROW as i32)
        );
        // Force (0.6, 0, 0) in the patch frame is (0, 0.6, 0) in the link frame.
        let (a, b) = (&arrow.points[0], &arrow.points[1]);
        assert!((b.y - a.y - 0.6 * ARROW_M_PER_UNIT).abs() < 1e-9 && (b.x - a.x).abs() < 1e-9);

        let out = run(&mut m, &l, &[CellReading::default(); 3]);
        let deleted: Vec<(&str, i32, i32)> = out
            .markers
            .iter()
            .map(|m| (m.ns.as_str(), m.id, m.action))
            .collect();
        let del = Marker::DELETE as i32;
        assert_eq!(deleted, [(CELLS_NS, 0, del), (WRENCH_NS, 0, del)]);
        assert!(run(&mut m, &l, &[CellReading::default(); 3])
            .markers
            .is_empty());
    }
}
