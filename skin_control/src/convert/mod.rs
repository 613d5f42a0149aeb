//! The one conversion module between ROS messages and `skin_core` types.
//!
//! Conventions (see `docs/ros.md`):
//! - **Cells in**: a `SkinCellArray` updates a per-layout-cell [`CellReading`] buffer. Cells absent
//!   from a message keep their last reading (the skin is event driven: a message may carry only
//!   the cells that changed); every cell reads zero until its first sample. Bad input is
//!   sanitized, counted per [`IssueKind`] and reported, never propagated: unknown ids and
//!   repeated ids within one message are ignored (the first occurrence wins), NaN/Inf signals read
//!   as 0 (no signal), finite signals outside [0, 1] are clamped. Acceleration and temperature are
//!   not used by the aggregation and pass unchecked.
//! - **Patches out**: one `PatchWrench` per layout patch, in layout order. Wrench and centroid are
//!   in the patch frame {p_j} (as `PatchWrench.msg` specifies); `header.frame_id` names that frame
//!   [`patch_frame_id`] (`skin_patch_<id>`), fixed in `link` at the layout's pose. RViz cannot
//!   display this message type: `/skin/markers` draws the wrenches in the link frames.
use std::fmt::{self, Write as _};

pub mod cdr_cells;
pub mod control;
pub mod robot;

use nalgebra::Vector3;
use r2r::builtin_interfaces::msg::Time;
use r2r::geometry_msgs::msg::{Point, Vector3 as Vector3Msg};
use r2r::skin_msgs::msg::{PatchWrench as PatchWrenchMsg, PatchWrenchArray, SkinCellArray};
use skin_core::skin::aggregate::PatchWrench;
pub use skin_core::skin::cell_input::{CellBuffer, CellSample, Issue, IssueCounts, IssueKind};
use skin_core::skin::layout::ResolvedLayout;
use skin_core::skin::signals::CellReading;

/// A `/skin/cells` message as the cell rules read it: r2r's Rust message (tests, the in-process
/// simulation bridge) or [`cdr_cells::CdrCells`], read from the serialized bytes (the nodes).
pub trait CellMessage {
    /// `header.stamp`.
    fn stamp(&self) -> Time;
    /// The arrays: `cell_id`, `force`, `proximity`, and the lengths of `acceleration` and
    /// `temperature` (checked, not read).
    fn arrays(&self) -> CellArrays<'_>;
}

/// The signal arrays of a `SkinCellArray` (see the message's definition).
#[derive(Debug, Clone, Copy)]
pub struct CellArrays<'a> {
    /// `cell_id`: n entries.
    pub cell_id: &'a [u32],
    /// `force`: 3n entries.
    pub force: &'a [f32],
    /// `proximity`: n entries.
    pub proximity: &'a [f32],
    /// Length of `acceleration`: 3n or 0.
    pub acceleration_len: usize,
    /// Length of `temperature`: n or 0.
    pub temperature_len: usize,
}

impl<'a> CellArrays<'a> {
    /// The cells in message order; an array whose length disagrees with `cell_id` is named.
    pub fn samples(self) -> Result<impl Iterator<Item = CellSample<'a>>, String> {
        let n = self.cell_id.len();
        let check = |field: &str, len: usize, per_cell: usize, optional: bool| {
            if len == per_cell * n || (optional && len == 0) {
                Ok(())
            } else {
                let or_none = if optional { " or none" } else { "" };
                Err(format!("{field} has {len} values for {n} cells ({per_cell} per cell{or_none})"))
            }
        };
        check("force", self.force.len(), 3, false)?;
        check("proximity", self.proximity.len(), 1, false)?;
        check("acceleration", self.acceleration_len, 3, true)?;
        check("temperature", self.temperature_len, 1, true)?;
        let cells = self.cell_id.iter().zip(self.force.chunks_exact(3)).zip(self.proximity);
        Ok(cells.map(|((&cell_id, force), &proximity)| CellSample { cell_id, force, proximity }))
    }
}

impl CellMessage for SkinCellArray {
    fn stamp(&self) -> Time {
        self.header.stamp.clone()
    }

    fn arrays(&self) -> CellArrays<'_> {
        CellArrays {
            cell_id: &self.cell_id,
            force: &self.force,
            proximity: &self.proximity,
            acceleration_len: self.acceleration.len(),
            temperature_len: self.temperature.len(),
        }
    }
}

/// Writes the cells of `msg` into `buf` (the rules of `skin_core::skin::cell_input`); `report`
/// is called for every issue. A message whose arrays disagree is refused whole: the reason names
/// the array, `buf` is unchanged. No allocation.
pub fn update_cells(
    buf: &mut CellBuffer,
    layout: &ResolvedLayout,
    msg: &impl CellMessage,
    report: impl FnMut(&Issue),
) -> Result<(), String> {
    buf.update(layout, msg.arrays().samples()?, report);
    Ok(())
}

/// Writes the readings of the layout cells `k` with `keep(k)` into `msg`, in layout order (the
/// simulation's skin driver; an event-driven skin keeps the cells that changed): ids from the
/// layout, signals as the message's float32, no acceleration or temperature. Reuses `msg`'s
/// arrays.
pub fn write_cell_array(
    layout: &ResolvedLayout,
    readings: &[CellReading],
    stamp: &Time,
    mut keep: impl FnMut(usize) -> bool,
    msg: &mut SkinCellArray,
) {
    msg.header.stamp = stamp.clone();
    for a in [&mut msg.force, &mut msg.proximity, &mut msg.acceleration, &mut msg.temperature] {
        a.clear();
    }
    msg.cell_id.clear();
    for (k, (cell, r)) in layout.cells().iter().zip(readings).enumerate() {
        if keep(k) {
            msg.cell_id.push(cell.id);
            msg.force.extend(r.force.iter().map(|&f| f as f32));
            msg.proximity.push(r.proximity as f32);
        }
    }
}

/// TF frame name of patch `patch_id`'s frame {p_j}: `skin_patch_<id>`.
pub fn patch_frame_id(patch_id: u32) -> String {
    let mut s = String::new();
    write_patch_frame_id(&mut s, patch_id);
    s
}

fn write_patch_frame_id(out: &mut String, patch_id: u32) {
    out.clear();
    // Writing into a String cannot fail.
    let _ = write!(out, "skin_patch_{patch_id}");
}

fn vector_msg(v: &Vector3<f64>) -> Vector3Msg {
    Vector3Msg { x: v.x, y: v.y, z: v.z }
}

/// Writes `wrenches` (indexed like `layout.patches()`) into `msg`, one entry per patch in layout
/// order, every entry stamped `stamp`. Reuses `msg`'s storage: after the first call it allocates
/// nothing.
pub fn write_patch_array(layout: &ResolvedLayout, wrenches: &[PatchWrench], stamp: &Time, msg: &mut PatchWrenchArray) {
    msg.header.stamp = stamp.clone();
    msg.header.frame_id.clear();
    msg.patches.resize_with(layout.patches().len(), PatchWrenchMsg::default);
    for ((out, patch), w) in msg.patches.iter_mut().zip(layout.patches()).zip(wrenches) {
        out.header.stamp = stamp.clone();
        write_patch_frame_id(&mut out.header.frame_id, patch.id);
        out.patch_id = patch.id;
        out.link.clear();
        out.link.push_str(&patch.link);
        out.wrench.force = vector_msg(&w.force);
        out.wrench.torque = vector_msg(&w.moment);
        out.centroid = Point { x: w.centroid.x, y: w.centroid.y, z: w.centroid.z };
        out.active_cells = u32::try_from(w.active_cells).unwrap_or(u32::MAX);
        out.max_force = w.max_force_signal as f32;
        out.max_proximity = w.max_proximity_signal as f32;
    }
}

/// Why a `PatchWrenchArray` does not fit a layout.
#[derive(Debug, Clone, PartialEq)]
pub enum PatchArrayError {
    /// `patches[index].patch_id` is not in the layout.
    UnknownPatch {
        /// Index in `patches`.
        index: usize,
        /// The id.
        patch_id: u32,
    },
    /// `patches[index].patch_id` appears twice.
    DuplicatePatch {
        /// Index of the repetition in `patches`.
        index: usize,
        /// The id.
        patch_id: u32,
    },
    /// `patches[index].link` differs from the layout's link of that patch.
    LinkMismatch {
        /// Index in `patches`.
        index: usize,
        /// The patch id.
        patch_id: u32,
        /// Link in the message.
        got: String,
        /// Link in the layout.
        expected: String,
    },
    /// A wrench or centroid component that is NaN or infinite.
    NonFinite {
        /// Index in `patches`.
        index: usize,
        /// The field, e.g. `wrench.force`.
        field: &'static str,
    },
    /// A layout patch that the message does not carry.
    MissingPatch {
        /// The patch id.
        patch_id: u32,
    },
}

impl fmt::Display for PatchArrayError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PatchArrayError::UnknownPatch { index, patch_id } => {
                write!(f, "patches[{index}].patch_id: patch {patch_id} is not in the layout")
            }
            PatchArrayError::DuplicatePatch { index, patch_id } => {
                write!(f, "patches[{index}].patch_id: patch {patch_id} appears twice")
            }
            PatchArrayError::LinkMismatch { index, patch_id, got, expected } => {
                write!(f, "patches[{index}].link: `{got}`, but patch {patch_id} is on `{expected}` in the layout")
            }
            PatchArrayError::NonFinite { index, field } => {
                write!(f, "patches[{index}].{field}: not finite")
            }
            PatchArrayError::MissingPatch { patch_id } => {
                write!(f, "patches: patch {patch_id} of the layout is missing")
            }
        }
    }
}

impl std::error::Error for PatchArrayError {}

fn vector(v: &Vector3Msg) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

/// Reads a `PatchWrenchArray` back into `out`, indexed like `layout.patches()` (the inverse of
/// [`write_patch_array`]); every layout patch must appear exactly once, on its layout link, with
/// finite values. `out` is resized (allocates only on the first call).
pub fn read_patch_array(
    layout: &ResolvedLayout,
    msg: &PatchWrenchArray,
    out: &mut Vec<PatchWrench>,
) -> Result<(), PatchArrayError> {
    out.resize(layout.patches().len(), PatchWrench::default());
    for (index, p) in msg.patches.iter().enumerate() {
        let patch_id = p.patch_id;
        let k = layout.patch_index(patch_id).ok_or(PatchArrayError::UnknownPatch { index, patch_id })?;
        // A handful of patches per robot: a scan is cheaper than a set.
        if msg.patches[..index].iter().any(|q| q.patch_id == patch_id) {
            return Err(PatchArrayError::DuplicatePatch { index, patch_id });
        }
        let expected = &layout.patches()[k].link;
        if &p.link != expected {
            return Err(PatchArrayError::LinkMismatch {
                index,
                patch_id,
                got: p.link.clone(),
                expected: expected.clone(),
            });
        }
        let w = PatchWrench {
            force: vector(&p.wrench.force),
            moment: vector(&p.wrench.torque),
            centroid: Vector3::new(p.centroid.x, p.centroid.y, p.centroid.z),
            active_cells: p.active_cells as usize,
            max_force_signal: f64::from(p.max_force),
            max_proximity_signal: f64::from(p.max_proximity),
            proximity_moment: Vector3::zeros(), // not in the message; the controller aggregates its own
        };
        let finite = |v: &Vector3<f64>| v.iter().all(|c| c.is_finite());
        let checks = [
            ("wrench.force", finite(&w.force)),
            ("wrench.torque", finite(&w.moment)),
            ("centroid", finite(&w.centroid)),
            ("max_force", w.max_force_signal.is_finite()),
            ("max_proximity", w.max_proximity_signal.is_finite()),
        ];
        if let Some((field, _)) = checks.iter().find(|(_, ok)| !ok) {
            return Err(PatchArrayError::NonFinite { index, field });
        }
        out[k] = w;
    }
    match layout.patches().iter().find(|lp| !msg.patches.iter().any(|p| p.patch_id == lp.id)) {
        Some(lp) => Err(PatchArrayError::MissingPatch { patch_id: lp.id }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use skin_core::skin::aggregate::{aggregate_patches, FusionParams};
    use skin_core::skin::layout::SkinLayout;
    use skin_core::skin::signals::ForceReduction;

    /// Two patches on links `a` and `b`, cells 10, 11 (patch 7) and 20 (patch 3).
    fn layout() -> ResolvedLayout {
        SkinLayout::from_yaml_str(
            include_str!("../../../skin_core/src/skin/testdata/two_patches.yaml"),
            "two_patches.yaml",
        )
        .unwrap()
        .resolve_with(|l| Some(if l == "a" { 1 } else { 2 }))
        .unwrap()
    }

    /// A message of `(id, force, proximity)` cells.
    fn cells(cells: &[(u32, [f32; 3], f32)]) -> SkinCellArray {
        SkinCellArray {
            cell_id: cells.iter().map(|c| c.0).collect(),
            force: cells.iter().flat_map(|c| c.1).collect(),
            proximity: cells.iter().map(|c| c.2).collect(),
            ..Default::default()
        }
    }

    fn update(buf: &mut CellBuffer, l: &ResolvedLayout, msg: &SkinCellArray) -> Vec<Issue> {
        let mut issues = Vec::new();
        update_cells(buf, l, msg, |i| issues.push(*i)).unwrap();
        issues
    }

    /// Cell k reads `cell_id[k]`, `force[3k..3k + 3]`, `proximity[k]`, with the sanitize rules.
    #[test]
    fn cells_read_from_the_arrays_by_index() {
        let l = layout();
        let mut buf = CellBuffer::new(&l);
        let msg = cells(&[
            (11, [0.5, f32::NAN, 2.0], -0.5),
            (99, [0.1; 3], 0.1),
            (10, [0.25, 0.5, 0.75], 0.125),
            (11, [0.9; 3], 0.9),
        ]);
        let issues = update(&mut buf, &l, &msg);
        let kinds: Vec<_> = issues.iter().map(|i| (i.cell_id, i.kind)).collect();
        use IssueKind::*;
        assert_eq!(kinds, [(11, NonFinite), (11, OutOfRange), (11, OutOfRange), (99, UnknownId), (11, DuplicateId)]);
        let at = |id| buf.readings()[l.cell_index(id).unwrap()];
        assert_eq!(at(10), CellReading { force: [0.25, 0.5, 0.75], proximity: 0.125 });
        assert_eq!(at(11), CellReading { force: [0.5, 0.0, 1.0], proximity: 0.0 });
    }

    /// A force or proximity array that does not match `cell_id` (or an acceleration or
    /// temperature array that is neither empty nor matching) refuses the message, naming the
    /// array; the buffer keeps its readings.
    #[test]
    fn arrays_that_disagree_refuse_the_message() {
        let l = layout();
        let mut buf = CellBuffer::new(&l);
        update(&mut buf, &l, &cells(&[(10, [0.5; 3], 0.5)]));
        let before = buf.readings().to_vec();
        let good = cells(&[(10, [0.1; 3], 0.1), (20, [0.2; 3], 0.2)]);
        let mut bad = Vec::new();
        let mut m = good.clone();
        m.force.pop();
        bad.push((m, "force has 5 values for 2 cells (3 per cell)"));
        let mut m = good.clone();
        m.proximity.push(0.0);
        bad.push((m, "proximity has 3 values for 2 cells (1 per cell)"));
        let mut m = good.clone();
        m.acceleration = vec![0.0; 3];
        bad.push((m, "acceleration has 3 values for 2 cells (3 per cell or none)"));
        let mut m = good.clone();
        m.temperature = vec![20.0];
        bad.push((m, "temperature has 1 values for 2 cells (1 per cell or none)"));
        for (m, want) in bad {
            let e = update_cells(&mut buf, &l, &m, |_| panic!("no cell is read")).unwrap_err();
            assert!(e.starts_with(want), "{e}");
            assert_eq!(buf.readings(), &before[..]);
        }
        let mut m = good.clone();
        (m.acceleration, m.temperature) = (vec![0.0; 6], vec![20.0; 2]);
        assert!(update(&mut buf, &l, &m).is_empty());
        assert_eq!(buf.readings()[l.cell_index(20).unwrap()].proximity, 0.2f32 as f64);
    }

    #[test]
    fn patch_array_round_trip() {
        let l = layout();
        let mut buf = CellBuffer::new(&l);
        update(&mut buf, &l, &cells(&[(10, [0.5; 3], 0.2), (20, [0.0; 3], 0.8)]));
        let fusion =
            FusionParams { weight_force: 0.5, activity_threshold: 0.02, force_reduction: ForceReduction::Mean };
        let mut wrenches = Vec::new();
        aggregate_patches(&l, buf.readings(), &fusion, &mut wrenches).unwrap();
        let stamp = Time { sec: 12, nanosec: 34 };
        let mut msg = PatchWrenchArray::default();
        write_patch_array(&l, &wrenches, &stamp, &mut msg);
        assert_eq!(msg.patches.len(), 2);
        let p = &msg.patches[1];
        assert_eq!((p.patch_id, p.link.as_str(), p.header.frame_id.as_str()), (3, "b", "skin_patch_3"));
        assert_eq!(p.header.frame_id, patch_frame_id(3));
        assert_eq!(p.header.stamp, stamp);
        assert_eq!(p.active_cells, 1);
        assert!((p.wrench.force.z - 0.4).abs() < 1e-7, "0.8 travels as float32");
        let mut back = Vec::new();
        read_patch_array(&l, &msg, &mut back).unwrap();
        for (a, b) in back.iter().zip(&wrenches) {
            assert_eq!(
                (a.force, a.moment, a.centroid, a.active_cells),
                (b.force, b.moment, b.centroid, b.active_cells)
            );
            // max signals travel as float32.
            assert!((a.max_force_signal - b.max_force_signal).abs() < 1e-7);
        }
    }

    #[test]
    fn patch_array_errors_name_the_field() {
        let l = layout();
        let mut msg = PatchWrenchArray::default();
        write_patch_array(&l, &[PatchWrench::default(); 2], &Time::default(), &mut msg);
        let mut out = Vec::new();
        let mut bad = msg.clone();
        bad.patches[1].link = "c".into();
        let e = read_patch_array(&l, &bad, &mut out).unwrap_err().to_string();
        assert_eq!(e, "patches[1].link: `c`, but patch 3 is on `b` in the layout");
        let mut bad = msg.clone();
        bad.patches.pop();
        let e = read_patch_array(&l, &bad, &mut out).unwrap_err();
        assert_eq!(e, PatchArrayError::MissingPatch { patch_id: 3 });
        let mut bad = msg.clone();
        bad.patches[1] = bad.patches[0].clone();
        let e = read_patch_array(&l, &bad, &mut out).unwrap_err();
        assert_eq!(e, PatchArrayError::DuplicatePatch { index: 1, patch_id: 7 });
        let mut bad = msg.clone();
        bad.patches[0].wrench.torque.y = f64::NAN;
        let e = read_patch_array(&l, &bad, &mut out).unwrap_err().to_string();
        assert_eq!(e, "patches[0].wrench.torque: not finite");
        let mut bad = msg;
        bad.patches[0].patch_id = 8;
        let e = read_patch_array(&l, &bad, &mut out).unwrap_err();
        assert_eq!(e, PatchArrayError::UnknownPatch { index: 0, patch_id: 8 });
    }
}
