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

pub mod control;
pub mod robot;

use nalgebra::Vector3;
use r2r::builtin_interfaces::msg::Time;
use r2r::geometry_msgs::msg::{Point, Vector3 as Vector3Msg};
use r2r::skin_msgs::msg::{PatchWrench as PatchWrenchMsg, PatchWrenchArray, SkinCell, SkinCellArray};
use skin_core::skin::aggregate::PatchWrench;
use skin_core::skin::layout::ResolvedLayout;
use skin_core::skin::signals::CellReading;

/// A category of bad cell input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IssueKind {
    /// A cell id that is not in the layout (the cell is ignored).
    UnknownId,
    /// A cell id repeated within one message (the repetition is ignored).
    DuplicateId,
    /// A NaN or infinite signal (read as 0: no signal).
    NonFinite,
    /// A finite signal outside [0, 1] (clamped).
    OutOfRange,
    /// A `force` array without exactly three values (missing values read as 0, extra ignored).
    Malformed,
}

impl IssueKind {
    /// Every kind, in the order of [`IssueCounts`].
    pub const ALL: [IssueKind; 5] = [
        IssueKind::UnknownId,
        IssueKind::DuplicateId,
        IssueKind::NonFinite,
        IssueKind::OutOfRange,
        IssueKind::Malformed,
    ];

    /// Short name, as used in logs and counters.
    pub fn name(self) -> &'static str {
        match self {
            IssueKind::UnknownId => "unknown cell id",
            IssueKind::DuplicateId => "duplicate cell id",
            IssueKind::NonFinite => "non-finite signal",
            IssueKind::OutOfRange => "signal outside [0, 1]",
            IssueKind::Malformed => "malformed force array",
        }
    }

    /// What the conversion did about it.
    pub fn action(self) -> &'static str {
        match self {
            IssueKind::UnknownId => "cell ignored",
            IssueKind::DuplicateId => "repetition ignored, first occurrence used",
            IssueKind::NonFinite => "read as 0",
            IssueKind::OutOfRange => "clamped to [0, 1]",
            IssueKind::Malformed => "missing values read as 0, extra ones ignored",
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// One bad value found in a `SkinCellArray`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Issue {
    /// Its category.
    pub kind: IssueKind,
    /// Index of the cell in the message's `cells`.
    pub index: usize,
    /// The cell id.
    pub cell_id: u32,
    /// The field, e.g. `force[1]`, `proximity`, `cell_id`.
    pub field: &'static str,
    /// The offending value, for signal issues.
    pub value: Option<f32>,
}

impl fmt::Display for Issue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "cells[{}] (cell {}) {}",
            self.index, self.cell_id, self.field
        )?;
        if let Some(v) = self.value {
            write!(f, " = {v}")?;
        }
        write!(f, ": {} ({})", self.kind.name(), self.kind.action())
    }
}

/// Number of issues per [`IssueKind`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct IssueCounts([u64; IssueKind::ALL.len()]);

impl IssueCounts {
    /// Count of `kind`.
    pub fn get(&self, kind: IssueKind) -> u64 {
        self.0[kind.index()]
    }

    /// Sum over all kinds.
    pub fn total(&self) -> u64 {
        self.0.iter().sum()
    }

    fn add(&mut self, kind: IssueKind) {
        self.0[kind.index()] += 1;
    }
}

impl fmt::Display for IssueCounts {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (k, kind) in IssueKind::ALL.iter().enumerate() {
            let sep = if k == 0 { "" } else { ", " };
            write!(f, "{sep}{}: {}", kind.name(), self.get(*kind))?;
        }
        Ok(())
    }
}

const FORCE_FIELDS: [&str; 3] = ["force[0]", "force[1]", "force[2]"];

/// The latest reading of every layout cell, updated from `SkinCellArray` messages.
#[derive(Debug, Clone)]
pub struct CellBuffer {
    readings: Vec<CellReading>,
    /// Number of the message that last wrote each cell: finds repeated ids without clearing a
    /// per-message set.
    written_by: Vec<u64>,
    messages: u64,
    issues: IssueCounts,
}

impl CellBuffer {
    /// A buffer for every cell of `layout`, all readings zero.
    pub fn new(layout: &ResolvedLayout) -> Self {
        CellBuffer {
            readings: vec![CellReading::default(); layout.num_cells()],
            written_by: vec![0; layout.num_cells()],
            messages: 0,
            issues: IssueCounts::default(),
        }
    }

    /// Readings indexed like `layout.cells()`, as `skin_core::skin::aggregate` takes them.
    pub fn readings(&self) -> &[CellReading] {
        &self.readings
    }

    /// Issues counted since the buffer was created.
    pub fn issues(&self) -> &IssueCounts {
        &self.issues
    }

    /// Writes the cells of `msg` (see the module doc for the rules); `report` is called for every
    /// issue. `layout` must be the one the buffer was made for. No allocation.
    pub fn update(
        &mut self,
        layout: &ResolvedLayout,
        msg: &SkinCellArray,
        mut report: impl FnMut(&Issue),
    ) {
        self.messages += 1;
        let mut note = |issues: &mut IssueCounts, issue: Issue| {
            issues.add(issue.kind);
            report(&issue);
        };
        for (index, cell) in msg.cells.iter().enumerate() {
            let id_issue = |kind| Issue {
                kind,
                index,
                cell_id: cell.cell_id,
                field: "cell_id",
                value: None,
            };
            let Some(k) = layout.cell_index(cell.cell_id) else {
                note(&mut self.issues, id_issue(IssueKind::UnknownId));
                continue;
            };
            if self.written_by[k] == self.messages {
                note(&mut self.issues, id_issue(IssueKind::DuplicateId));
                continue;
            }
            self.written_by[k] = self.messages;
            if cell.force.len() != 3 {
                note(
                    &mut self.issues,
                    Issue {
                        field: "force",
                        ..id_issue(IssueKind::Malformed)
                    },
                );
            }
            let mut signal = |field: &'static str, raw: Option<&f32>| {
                let raw = raw.copied().unwrap_or(0.0);
                let (value, kind) = sanitize(raw);
                if let Some(kind) = kind {
                    let issue = Issue {
                        field,
                        value: Some(raw),
                        ..id_issue(kind)
                    };
                    note(&mut self.issues, issue);
                }
                value
            };
            let force = [0, 1, 2].map(|j| signal(FORCE_FIELDS[j], cell.force.get(j)));
            let proximity = signal("proximity", Some(&cell.proximity));
            self.readings[k] = CellReading { force, proximity };
        }
    }
}

/// Writes every layout cell's reading into `msg` (the simulation's skin driver): ids from the
/// layout, signals as the message's float32, acceleration and temperature zero. Reuses `msg`'s
/// storage.
pub fn write_cell_array(layout: &ResolvedLayout, readings: &[CellReading], stamp: &Time, msg: &mut SkinCellArray) {
    msg.header.stamp = stamp.clone();
    msg.cells.resize_with(readings.len(), SkinCell::default);
    for ((out, cell), r) in msg.cells.iter_mut().zip(layout.cells()).zip(readings) {
        out.cell_id = cell.id;
        out.force.clear();
        out.force.extend(r.force.iter().map(|&f| f as f32));
        out.proximity = r.proximity as f32;
    }
}

/// A normalized signal into [0, 1], with the issue it had, if any.
fn sanitize(raw: f32) -> (f64, Option<IssueKind>) {
    if !raw.is_finite() {
        (0.0, Some(IssueKind::NonFinite))
    } else if !(0.0..=1.0).contains(&raw) {
        (f64::from(raw.clamp(0.0, 1.0)), Some(IssueKind::OutOfRange))
    } else {
        (f64::from(raw), None)
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

    fn layout() -> ResolvedLayout {
        let text =
            "patches:\n  - {id: 7, link: a}\n  - {id: 3, link: b, xyz: [0, 0, 1]}\ncells:\n  \
                    - {id: 10, patch: 7, position: [0.1, 0, 0], normal: [1, 0, 0]}\n  \
                    - {id: 11, patch: 7, position: [0, 0.1, 0], normal: [0, 1, 0]}\n  \
                    - {id: 20, patch: 3, position: [0, 0, 0.1], normal: [0, 0, 1]}\n";
        SkinLayout::from_yaml_str(text, "t.yaml")
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
        buf.update(l, msg, |i| issues.push(*i));
        issues
    }

    #[test]
    fn cells_map_through_the_layout_and_absent_cells_keep_their_reading() {
        let l = layout();
        let mut buf = CellBuffer::new(&l);
        assert!(update(&mut buf, &l, &cells(vec![cell(20, [0.5, 0.25, 1.0], 0.75)])).is_empty());
        let k20 = l.cell_index(20).unwrap();
        assert_eq!(
            buf.readings()[k20],
            CellReading {
                force: [0.5, 0.25, 1.0],
                proximity: 0.75
            }
        );
        assert!(update(&mut buf, &l, &cells(vec![cell(10, [0.0; 3], 0.5)])).is_empty());
        assert_eq!(
            buf.readings()[k20].proximity,
            0.75,
            "absent cell keeps its last reading"
        );
        assert_eq!(
            buf.readings()[l.cell_index(11).unwrap()],
            CellReading::default()
        );
        assert_eq!(buf.issues().total(), 0);
    }

    #[test]
    fn bad_input_is_sanitized_counted_and_reported() {
        let l = layout();
        let mut buf = CellBuffer::new(&l);
        let msg = cells(vec![
            cell(10, [f32::NAN, 0.5, f32::INFINITY], 1.5),
            cell(99, [0.5; 3], 0.5),
            cell(10, [0.9; 3], 0.9),
            SkinCell {
                cell_id: 11,
                force: vec![0.3],
                proximity: -0.1,
                ..Default::default()
            },
        ]);
        let issues = update(&mut buf, &l, &msg);
        let r10 = buf.readings()[l.cell_index(10).unwrap()];
        assert_eq!(
            r10,
            CellReading {
                force: [0.0, 0.5, 0.0],
                proximity: 1.0
            },
            "first wins"
        );
        let r11 = buf.readings()[l.cell_index(11).unwrap()];
        assert_eq!(r11.force[1], 0.0);
        assert_eq!(r11.proximity, 0.0);
        let c = buf.issues();
        assert_eq!(c.get(IssueKind::NonFinite), 2);
        // proximity 1.5 of cell 10 and -0.1 of cell 11.
        assert_eq!(c.get(IssueKind::OutOfRange), 2);
        assert_eq!(c.get(IssueKind::UnknownId), 1);
        assert_eq!(c.get(IssueKind::DuplicateId), 1);
        assert_eq!(c.get(IssueKind::Malformed), 1);
        assert_eq!(issues.len() as u64, c.total());
        let text = issues[0].to_string();
        assert!(text.contains("cells[0] (cell 10) force[0] = NaN"), "{text}");
        // The same id in the next message is not a duplicate.
        assert!(update(&mut buf, &l, &cells(vec![cell(10, [0.1; 3], 0.1)])).is_empty());
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
