//! Skin cell messages into per-layout-cell readings, with bad input sanitized and counted.
//!
//! The ROS-free core of the `SkinCellArray` conversion (skin_control's `convert` adapts the
//! message to [`CellSample`]s). Rules:
//! - a message updates a [`CellReading`] buffer indexed like the layout's cells; cells absent
//!   from a message keep their last reading (the skin is event driven: a message may carry only
//!   the cells that changed); every cell reads zero until its first sample;
//! - bad input is sanitized, counted per [`IssueKind`] and reported, never propagated: unknown ids
//!   and repeated ids within one message are ignored (the first occurrence wins), NaN/Inf signals
//!   read as 0 (no signal), finite signals outside [0, 1] are clamped, a force array without
//!   exactly three values has its missing values read as 0 and its extra ones ignored.
//!
//! Every reading the buffer holds is therefore finite and in [0, 1].

use std::fmt;

use super::layout::ResolvedLayout;
use super::signals::CellReading;

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

/// One bad value found in a message.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Issue {
    /// Its category.
    pub kind: IssueKind,
    /// Index of the cell in the message's cells.
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
        write!(f, "cells[{}] (cell {}) {}", self.index, self.cell_id, self.field)?;
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

/// One cell of a message as it arrives, unchecked (a view: borrows the message's force array).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellSample<'a> {
    /// The cell id (a layout cell id, if the sender is right).
    pub cell_id: u32,
    /// The three normalized force signals (any length is accepted and reported).
    pub force: &'a [f32],
    /// The normalized proximity signal.
    pub proximity: f32,
}

const FORCE_FIELDS: [&str; 3] = ["force[0]", "force[1]", "force[2]"];

/// The latest reading of every layout cell, updated from messages of [`CellSample`]s.
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

    /// Readings indexed like `layout.cells()`, as [`super::aggregate`] takes them.
    pub fn readings(&self) -> &[CellReading] {
        &self.readings
    }

    /// Issues counted since the buffer was created.
    pub fn issues(&self) -> &IssueCounts {
        &self.issues
    }

    /// Writes the `cells` of one message (see the module doc for the rules); `report` is called
    /// for every issue, in message order. `layout` must be the one the buffer was made for.
    /// No allocation.
    pub fn update<'a>(
        &mut self,
        layout: &ResolvedLayout,
        cells: impl IntoIterator<Item = CellSample<'a>>,
        mut report: impl FnMut(&Issue),
    ) {
        self.messages += 1;
        let mut note = |issues: &mut IssueCounts, issue: Issue| {
            issues.add(issue.kind);
            report(&issue);
        };
        for (index, cell) in cells.into_iter().enumerate() {
            let id_issue = |kind| Issue { kind, index, cell_id: cell.cell_id, field: "cell_id", value: None };
            let Some(k) = layout.cell_index(cell.cell_id) else {
                note(&mut self.issues, id_issue(IssueKind::UnknownId));
                continue;
            };
            if self.written_by[k] == self.messages {
                note(&mut self.issues, id_issue(IssueKind::DuplicateId));
                continue;
            }
            self.written_by[k] = self.messages;
            // the common case first: three forces and a proximity, all in [0, 1] (NaN is not)
            if let &[f0, f1, f2] = cell.force {
                if [f0, f1, f2, cell.proximity].iter().all(|v| (0.0..=1.0).contains(v)) {
                    let force = [f0, f1, f2].map(f64::from);
                    self.readings[k] = CellReading { force, proximity: f64::from(cell.proximity) };
                    continue;
                }
            }
            if cell.force.len() != 3 {
                note(&mut self.issues, Issue { field: "force", ..id_issue(IssueKind::Malformed) });
            }
            let mut signal = |field: &'static str, raw: Option<&f32>| {
                let raw = raw.copied().unwrap_or(0.0);
                let (value, kind) = sanitize(raw);
                if let Some(kind) = kind {
                    note(&mut self.issues, Issue { field, value: Some(raw), ..id_issue(kind) });
                }
                value
            };
            let force = [0, 1, 2].map(|j| signal(FORCE_FIELDS[j], cell.force.get(j)));
            let proximity = signal("proximity", Some(&cell.proximity));
            self.readings[k] = CellReading { force, proximity };
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skin::layout::SkinLayout;

    /// Two patches on links `a` and `b`, cells 10, 11 (patch 7) and 20 (patch 3).
    fn layout() -> ResolvedLayout {
        SkinLayout::from_yaml_str(include_str!("testdata/two_patches.yaml"), "two_patches.yaml")
            .unwrap()
            .resolve_with(|l| Some(if l == "a" { 1 } else { 2 }))
            .unwrap()
    }

    /// An owned cell, as a message holds it.
    struct Cell(u32, Vec<f32>, f32);

    fn cell(id: u32, force: [f32; 3], proximity: f32) -> Cell {
        Cell(id, force.to_vec(), proximity)
    }

    fn update(buf: &mut CellBuffer, l: &ResolvedLayout, msg: &[Cell]) -> Vec<Issue> {
        let mut issues = Vec::new();
        let cells = msg.iter().map(|c| CellSample { cell_id: c.0, force: &c.1, proximity: c.2 });
        buf.update(l, cells, |i| issues.push(*i));
        issues
    }

    #[test]
    fn cells_map_through_the_layout_and_absent_cells_keep_their_reading() {
        let l = layout();
        let mut buf = CellBuffer::new(&l);
        assert!(update(&mut buf, &l, &[cell(20, [0.5, 0.25, 1.0], 0.75)]).is_empty());
        let k20 = l.cell_index(20).unwrap();
        assert_eq!(buf.readings()[k20], CellReading { force: [0.5, 0.25, 1.0], proximity: 0.75 });
        assert!(update(&mut buf, &l, &[cell(10, [0.0; 3], 0.5)]).is_empty());
        assert_eq!(buf.readings()[k20].proximity, 0.75, "absent cell keeps its last reading");
        assert_eq!(buf.readings()[l.cell_index(11).unwrap()], CellReading::default());
        assert_eq!(buf.issues().total(), 0);
    }

    #[test]
    fn bad_input_is_sanitized_counted_and_reported() {
        let l = layout();
        let mut buf = CellBuffer::new(&l);
        let msg = [
            cell(10, [f32::NAN, 0.5, f32::INFINITY], 1.5),
            cell(99, [0.5; 3], 0.5),
            cell(10, [0.9; 3], 0.9),
            Cell(11, vec![0.3], -0.1),
        ];
        let issues = update(&mut buf, &l, &msg);
        let r10 = buf.readings()[l.cell_index(10).unwrap()];
        assert_eq!(r10, CellReading { force: [0.0, 0.5, 0.0], proximity: 1.0 }, "first wins");
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
        assert!(update(&mut buf, &l, &[cell(10, [0.1; 3], 0.1)]).is_empty());
    }

    #[test]
    fn empty_and_long_force_arrays_are_malformed_but_read() {
        let l = layout();
        let mut buf = CellBuffer::new(&l);
        let issues = update(&mut buf, &l, &[Cell(10, vec![], 0.5), Cell(11, vec![0.1, 0.2, 0.3, f32::NAN], 0.5)]);
        let kinds: Vec<_> = issues.iter().map(|i| (i.cell_id, i.kind, i.field)).collect();
        assert_eq!(kinds, [(10, IssueKind::Malformed, "force"), (11, IssueKind::Malformed, "force")]);
        assert_eq!(buf.readings()[l.cell_index(10).unwrap()], CellReading::uniform(0.0, 0.5));
        let r11 = buf.readings()[l.cell_index(11).unwrap()];
        assert_eq!(r11.force, [0.1f32, 0.2, 0.3].map(f64::from), "the extra NaN is ignored");
        assert_eq!(
            buf.issues().to_string(),
            "unknown cell id: 0, duplicate cell id: 0, non-finite signal: 0, signal outside [0, 1]: 0, \
             malformed force array: 2"
        );
    }

    #[test]
    fn huge_and_tiny_values_stay_in_unit_range() {
        let l = layout();
        let mut buf = CellBuffer::new(&l);
        let msg = [cell(10, [f32::MAX, f32::MIN, -0.0], f32::MIN_POSITIVE), cell(u32::MAX, [0.0; 3], 0.0)];
        let issues = update(&mut buf, &l, &msg);
        assert_eq!(issues.len(), 3, "{issues:?}");
        let r = buf.readings()[l.cell_index(10).unwrap()];
        assert_eq!(r.force, [1.0, 0.0, 0.0]);
        assert!(r.force[2].is_sign_negative(), "-0.0 is in range and kept as is");
        assert_eq!(r.proximity, f64::from(f32::MIN_POSITIVE));
    }
}
