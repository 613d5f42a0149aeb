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
use r2r::skin_msgs::msg::{PatchWrench as PatchWrenchMsg, PatchWrenchArray, SkinCell, SkinCellArray};
use r2r::NativeMsg;
use skin_core::skin::aggregate::PatchWrench;
pub use skin_core::skin::cell_input::{CellBuffer, CellSample, Issue, IssueCounts, IssueKind};
use skin_core::skin::layout::ResolvedLayout;
use skin_core::skin::signals::CellReading;

/// A `/skin/cells` message as the cell rules read it: r2r's Rust message, or the C message that a
/// native subscription (`Node::subscribe_native`) takes it into. The nodes read the C message:
/// r2r's Rust message costs an allocation per cell (its `force` is a `Vec`), and the cells are
/// most of the graph's traffic (700 on TOMM).
pub trait CellMessage {
    /// `header.stamp`.
    fn stamp(&self) -> Time;
    /// The cells, in message order.
    fn samples(&self) -> impl Iterator<Item = CellSample<'_>>;
}

impl CellMessage for SkinCellArray {
    fn stamp(&self) -> Time {
        self.header.stamp.clone()
    }

    fn samples(&self) -> impl Iterator<Item = CellSample<'_>> {
        self.cells.iter().map(|c| CellSample { cell_id: c.cell_id, force: &c.force, proximity: c.proximity })
    }
}

impl CellMessage for NativeMsg<SkinCellArray> {
    fn stamp(&self) -> Time {
        Time { sec: self.header.stamp.sec, nanosec: self.header.stamp.nanosec }
    }

    fn samples(&self) -> impl Iterator<Item = CellSample<'_>> {
        let seq = &self.cells;
        let cells = if seq.data.is_null() {
            &[][..]
        } else {
            // SAFETY: a rosidl sequence: `data` points at `size` initialized cells, owned by the
            // message, which the returned samples borrow.
            unsafe { std::slice::from_raw_parts(seq.data, seq.size) }
        };
        cells.iter().map(|c| CellSample { cell_id: c.cell_id, force: &c.force, proximity: c.proximity })
    }
}

/// Writes the cells of `msg` into `buf` (the rules of `skin_core::skin::cell_input`); `report`
/// is called for every issue. No allocation.
pub fn update_cells(buf: &mut CellBuffer, layout: &ResolvedLayout, msg: &impl CellMessage, report: impl FnMut(&Issue)) {
    buf.update(layout, msg.samples(), report);
}

/// Writes the readings of the layout cells `k` with `keep(k)` into `msg`, in layout order (the
/// simulation's skin driver; an event-driven skin keeps the cells that changed): ids from the
/// layout, signals as the message's float32, acceleration and temperature zero. Reuses `msg`'s
/// cells; a new one is built in Rust (r2r's `SkinCell::default` allocates a C message).
pub fn write_cell_array(
    layout: &ResolvedLayout,
    readings: &[CellReading],
    stamp: &Time,
    mut keep: impl FnMut(usize) -> bool,
    msg: &mut SkinCellArray,
) {
    msg.header.stamp = stamp.clone();
    let mut n = 0;
    for (k, (cell, r)) in layout.cells().iter().zip(readings).enumerate() {
        if !keep(k) {
            continue;
        }
        if n == msg.cells.len() {
            let zero = Vector3Msg { x: 0.0, y: 0.0, z: 0.0 };
            msg.cells.push(SkinCell { cell_id: 0, force: Vec::with_capacity(3), proximity: 0.0, acceleration: zero, temperature: 0.0 });
        }
        let out = &mut msg.cells[n];
        out.cell_id = cell.id;
        out.force.clear();
        out.force.extend(r.force.iter().map(|&f| f as f32));
        out.proximity = r.proximity as f32;
        n += 1;
    }
    msg.cells.truncate(n);
}

/// A normalized signal into [0, 1], with the issue it had, if any.
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
    Vector3Msg {
        x: v.x,
        y: v.y,
        z: v.z,
    }
}

/// Writes `wrenches` (indexed like `layout.patches()`) into `msg`, one entry per patch in layout
/// order, every entry stamped `stamp`. Reuses `msg`'s storage: after the first call it allocates
/// nothing.
pub fn write_patch_array(
    layout: &ResolvedLayout,
    wrenches: &[PatchWrench],
    stamp: &Time,
    msg: &mut PatchWrenchArray,
) {
    msg.header.stamp = stamp.clone();
    msg.header.frame_id.clear();
    msg.patches
        .resize_with(layout.patches().len(), PatchWrenchMsg::default);
    for ((out, patch), w) in msg.patches.iter_mut().zip(layout.patches()).zip(wrenches) {
        out.header.stamp = stamp.clone();
        write_patch_frame_id(&mut out.header.frame_id, patch.id);
        out.patch_id = patch.id;
        out.link.clear();
        out.link.push_str(&patch.link);
        out.wrench.force = vector_msg(&w.force);
        out.wrench.torque = vector_msg(&w.moment);
        out.centroid = Point {
            x: w.centroid.x,
            y: w.centroid.y,
            z: w.centroid.z,
        };
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
            PatchArrayError::LinkMismatch { index, patch_id, got, expected } => write!(
                f,
                "patches[{index}].link: `{got}`, but patch {patch_id} is on `{expected}` in the layout"
            ),
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
        let k = layout
            .patch_index(patch_id)
            .ok_or(PatchArrayError::UnknownPatch { index, patch_id })?;
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
    match layout
        .patches()
        .iter()
        .find(|lp| !msg.patches.iter().any(|p| p.patch_id == lp.id))
    {
        Some(lp) => Err(PatchArrayError::MissingPatch { patch_id: lp.id }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use r2r::skin_msgs::msg::SkinCell;
    use skin_core::skin::aggregate::{aggregate_patches, FusionParams};
    use skin_core::skin::layout::SkinLayout;
    use skin_core::skin::signals::ForceReduction;

    /// Two patches on links `a` and `b`, cells 10, 11 (patch 7) and 20 (patch 3).
    fn layout() -> ResolvedLayout {
        SkinLayout::from_yaml_str(include_str!("../../../skin_core/src/skin/testdata/two_patches.yaml"), "two_patches.yaml")
            .unwrap()
            .resolve_with(|l| Some(if l == "a" { 1 } else { 2 }))
            .unwrap()
    }

    fn cell(id: u32, force: [f32; 3], proximity: f32) -> SkinCell {
        SkinCell {
            cell_id: id,
            force: force.to_vec(),
            proximity,
            ..Default::default()
        }
    }

    fn cells(cells: Vec<SkinCell>) -> SkinCellArray {
        SkinCellArray {
            cells,
            ..Default::default()
        }
    }

    fn update(buf: &mut CellBuffer, l: &ResolvedLayout, msg: &SkinCellArray) -> Vec<Issue> {
        let mut issues = Vec::new();
        update_cells(buf, l, msg, |i| issues.push(*i));
        issues
    }

    /// The C message of a native subscription reads exactly as r2r's Rust message: readings,
    /// issues, stamp (every sanitize rule a C message can carry: its force has three values).
    #[test]
    fn native_cells_read_as_rust_cells() {
        let l = layout();
        let mut msg = cells(vec![
            cell(11, [0.5, f32::NAN, 2.0], -0.5),
            cell(99, [0.1; 3], 0.1),
            cell(10, [0.25; 3], f32::INFINITY),
            cell(11, [0.9; 3], 0.9),
        ]);
        msg.header.stamp = Time { sec: 3, nanosec: 7 };
        let native = NativeMsg::from(&msg);
        assert_eq!(native.stamp(), msg.stamp());
        let (mut a, mut b) = (CellBuffer::new(&l), CellBuffer::new(&l));
        let issues = update(&mut a, &l, &msg);
        let mut native_issues = Vec::new();
        update_cells(&mut b, &l, &native, |i| native_issues.push(*i));
        assert_eq!(issues.len(), 6);
        // (the NaN value of an issue is not equal to itself)
        assert_eq!(format!("{native_issues:?}"), format!("{issues:?}"));
        assert_eq!(a.readings(), b.readings());
        assert_eq!(NativeMsg::from(&cells(Vec::new())).samples().count(), 0);
    }

    #[test]
    fn patch_array_round_trip() {
        let l = layout();
        let mut buf = CellBuffer::new(&l);
        update(
            &mut buf,
            &l,
            &cells(vec![cell(10, [0.5; 3], 0.2), cell(20, [0.0; 3], 0.8)]),
        );
        let fusion = FusionParams {
            weight_force: 0.5,
            activity_threshold: 0.02,
            force_reduction: ForceReduction::Mean,
        };
        let mut wrenches = Vec::new();
        aggregate_patches(&l, buf.readings(), &fusion, &mut wrenches).unwrap();
        let stamp = Time {
            sec: 12,
            nanosec: 34,
        };
        let mut msg = PatchWrenchArray::default();
        write_patch_array(&l, &wrenches, &stamp, &mut msg);
        assert_eq!(msg.patches.len(), 2);
        let p = &msg.patches[1];
        assert_eq!(
            (p.patch_id, p.link.as_str(), p.header.frame_id.as_str()),
            (3, "b", "skin_patch_3")
        );
        assert_eq!(p.header.frame_id, patch_frame_id(3));
        assert_eq!(p.header.stamp, stamp);
        assert_eq!(p.active_cells, 1);
        assert!(
            (p.wrench.force.z - 0.4).abs() < 1e-7,
            "0.8 travels as float32"
        );
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
        let e = read_patch_array(&l, &bad, &mut out)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "patches[1].link: `c`, but patch 3 is on `b` in the layout"
        );
        let mut bad = msg.clone();
        bad.patches.pop();
        let e = read_patch_array(&l, &bad, &mut out).unwrap_err();
        assert_eq!(e, PatchArrayError::MissingPatch { patch_id: 3 });
        let mut bad = msg.clone();
        bad.patches[1] = bad.patches[0].clone();
        let e = read_patch_array(&l, &bad, &mut out).unwrap_err();
        assert_eq!(
            e,
            PatchArrayError::DuplicatePatch {
                index: 1,
                patch_id: 7
            }
        );
        let mut bad = msg.clone();
        bad.patches[0].wrench.torque.y = f64::NAN;
        let e = read_patch_array(&l, &bad, &mut out)
            .unwrap_err()
            .to_string();
        assert_eq!(e, "patches[0].wrench.torque: not finite");
        let mut bad = msg;
        bad.patches[0].patch_id = 8;
        let e = read_patch_array(&l, &bad, &mut out).unwrap_err();
        assert_eq!(
            e,
            PatchArrayError::UnknownPatch {
                index: 0,
                patch_id: 8
            }
        );
    }
}
