//! `/skin/markers`: what the skin feels, for RViz. The markers are built by
//! [`skin_core::skin::markers`] (shared with the simulator's recordings and pictures); this module
//! turns them into `visualization_msgs/MarkerArray` messages, stamped like the cells.
use r2r::builtin_interfaces::msg::Time;
use r2r::geometry_msgs::msg::Point;
use r2r::std_msgs::msg::ColorRGBA;
use r2r::visualization_msgs::msg::{Marker, MarkerArray};
use skin_core::skin::aggregate::{FusionParams, PatchWrench};
use skin_core::skin::layout::ResolvedLayout;
use skin_core::skin::markers::{self as core_markers, MarkerAction, MarkerShape, Rgba, SkinMarker};
use skin_core::skin::signals::CellReading;

pub use skin_core::skin::markers::{ARROW_M_PER_UNIT, CELLS_NS, CELL_DIAMETER_M, WRENCH_NS};

/// Builds the marker arrays from the aggregation results, remembering what RViz shows.
#[derive(Debug, Clone)]
pub struct SkinMarkers {
    inner: core_markers::SkinMarkers,
    updates: Vec<SkinMarker>,
}

impl SkinMarkers {
    /// Nothing shown yet, for `layout`'s patches.
    pub fn new(layout: &ResolvedLayout) -> Self {
        SkinMarkers { inner: core_markers::SkinMarkers::new(layout), updates: Vec::new() }
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
        self.inner.update(layout, readings, fusion, wrenches, &mut self.updates);
        out.markers.clear();
        out.markers.extend(self.updates.iter().map(|m| marker(m, stamp)));
    }
}

/// A `DELETEALL` marker: clears every marker of the display.
pub fn delete_all() -> Marker {
    marker(&SkinMarker::delete_all(), &Time::default())
}

fn color([r, g, b, a]: Rgba) -> ColorRGBA {
    ColorRGBA { r, g, b, a }
}

/// The message of one marker update, stamped `stamp` (a delete-all is not stamped).
fn marker(m: &SkinMarker, stamp: &Time) -> Marker {
    let mut out = Marker { ns: m.ns.to_string(), id: m.id, ..Default::default() };
    out.action = match m.action {
        MarkerAction::DeleteAll => return Marker { action: Marker::DELETEALL as i32, ..Default::default() },
        MarkerAction::Delete => Marker::DELETE as i32,
        MarkerAction::Add => Marker::ADD as i32,
    };
    out.header.stamp = stamp.clone();
    if m.action == MarkerAction::Add {
        out.type_ = match m.shape {
            MarkerShape::SphereList => Marker::SPHERE_LIST as i32,
            MarkerShape::Arrow => Marker::ARROW as i32,
        };
        out.header.frame_id.clone_from(&m.frame);
        out.pose.orientation.w = 1.0;
        [out.scale.x, out.scale.y, out.scale.z] = m.scale;
        out.color = color(m.color);
        out.points = m.points.iter().map(|&[x, y, z]| Point { x, y, z }).collect();
        out.colors = m.colors.iter().map(|&c| color(c)).collect();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use skin_core::skin::aggregate::aggregate_patches;
    use skin_core::skin::layout::SkinLayout;
    use skin_core::skin::markers::cell_color;
    use skin_core::skin::signals::ForceReduction;

    const FUSION: FusionParams =
        FusionParams { weight_force: 0.5, activity_threshold: 0.02, force_reduction: ForceReduction::Mean };

    fn layout() -> ResolvedLayout {
        let text = "patches:\n  - {id: 7, link: a, xyz: [0, 0, 1]}\ncells:\n  \
                    - {id: 10, patch: 7, position: [0.1, 0, 0], normal: [1, 0, 0]}\n";
        SkinLayout::from_yaml_str(text, "t.yaml").unwrap().resolve_with(|_| Some(1)).unwrap()
    }

    fn run(m: &mut SkinMarkers, l: &ResolvedLayout, r: &[CellReading], stamp: &Time) -> MarkerArray {
        let mut w = Vec::new();
        aggregate_patches(l, r, &FUSION, &mut w).unwrap();
        let mut out = MarkerArray::default();
        m.update(l, r, &FUSION, &w, stamp, &mut out);
        out
    }

    #[test]
    fn updates_become_stamped_messages_in_link_frames() {
        let l = layout();
        let mut m = SkinMarkers::new(&l);
        let stamp = Time { sec: 3, nanosec: 5 };
        let out = run(&mut m, &l, &[CellReading::uniform(0.8, 0.4)], &stamp);
        let actions: Vec<i32> = out.markers.iter().map(|m| m.action).collect();
        assert_eq!(actions, [Marker::DELETEALL as i32, Marker::ADD as i32, Marker::ADD as i32]);
        let (cells, arrow) = (&out.markers[1], &out.markers[2]);
        assert_eq!(
            (cells.ns.as_str(), cells.type_, cells.header.frame_id.as_str()),
            (CELLS_NS, Marker::SPHERE_LIST as i32, "a")
        );
        assert_eq!(cells.header.stamp, stamp);
        assert_eq!((cells.points[0].x, cells.points[0].z), (0.1, 1.0));
        assert_eq!(cells.colors[0], color(cell_color(0.8, 0.4)));
        assert_eq!(cells.scale.x, CELL_DIAMETER_M);
        assert_eq!((arrow.ns.as_str(), arrow.type_, arrow.points.len()), (WRENCH_NS, Marker::ARROW as i32, 2));
        assert_eq!(arrow.pose.orientation.w, 1.0);

        let out = run(&mut m, &l, &[CellReading::default()], &stamp);
        let deleted: Vec<(&str, i32)> = out.markers.iter().map(|m| (m.ns.as_str(), m.action)).collect();
        assert_eq!(deleted, [(CELLS_NS, Marker::DELETE as i32), (WRENCH_NS, Marker::DELETE as i32)]);
        assert_eq!(out.markers[0].header.stamp, stamp);
    }
}
