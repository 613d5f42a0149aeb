//! Skin cell messages into the TOMM layout: arbitrary bytes decode into fusion parameters and a
//! sequence of messages (any ids, force arrays of any length, NaN/Inf/huge values) that go through
//! [`CellBuffer::update`], then patch aggregation and cell forces. Checked: no panic, every
//! reading finite and in [0, 1] and equal to an independent model of the rules, issue counts
//! consistent with the reports, every wrench and cell force finite and bounded.

use std::collections::HashSet;

use skin_core::skin::aggregate::{aggregate_patches, FusionParams, PatchWrench};
use skin_core::skin::cell_forces::{cell_contact_forces, cell_repulsion_forces, PointForce};
use skin_core::skin::cell_input::{CellBuffer, CellSample, Issue, IssueKind};
use skin_core::skin::layout::ResolvedLayout;
use skin_core::skin::signals::{CellReading, ForceReduction};

use crate::fixtures::tomm;

/// Values a sender gets wrong, picked by the decoder besides raw bit patterns.
const SPECIAL: [f32; 16] = [
    f32::NAN,
    -f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::MAX,
    f32::MIN,
    f32::MIN_POSITIVE,
    -f32::MIN_POSITIVE,
    1.0e-45,
    -0.0,
    0.0,
    1.0,
    1.000_000_1,
    -1.0,
    2.0,
    0.5,
];

/// Reads the fuzz input front to back; every read past the end yields `None`.
struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn u8(&mut self) -> Option<u8> {
        let (&b, rest) = self.0.split_first()?;
        self.0 = rest;
        Some(b)
    }

    fn array<const N: usize>(&mut self) -> Option<[u8; N]> {
        let (head, rest) = self.0.split_first_chunk::<N>()?;
        self.0 = rest;
        Some(*head)
    }

    /// A signal value: raw bits, a [`SPECIAL`] value or a byte scaled into [0, 1].
    fn signal(&mut self) -> Option<f32> {
        let tag = self.u8()?;
        Some(match tag % 4 {
            0 => f32::from_le_bytes(self.array()?),
            1 => SPECIAL[usize::from(tag >> 2) % SPECIAL.len()],
            _ => f32::from(self.u8()?) / 255.0,
        })
    }

    /// A cell id: mostly one of the layout's (so that updates land), else any `u32`.
    fn cell_id(&mut self, layout: &ResolvedLayout, tag: u8) -> Option<u32> {
        Some(if tag.is_multiple_of(4) {
            u32::from_le_bytes(self.array()?)
        } else {
            let k = usize::from(u16::from_le_bytes(self.array()?));
            layout.cells()[k % layout.num_cells()].id
        })
    }
}

/// One cell as a message owns it.
struct Cell {
    id: u32,
    force: Vec<f32>,
    proximity: f32,
}

/// Decodes one message (up to 16 cells, force arrays of 0 to 5 values); `None` at the end of the
/// input (a message cut short is dropped).
fn message(bytes: &mut Bytes<'_>, layout: &ResolvedLayout) -> Option<Vec<Cell>> {
    let n = bytes.u8()? % 17;
    (0..n)
        .map(|_| {
            let tag = bytes.u8()?;
            let id = bytes.cell_id(layout, tag)?;
            let force = (0..(tag >> 2) % 6).map(|_| bytes.signal()).collect::<Option<_>>()?;
            Some(Cell { id, force, proximity: bytes.signal()? })
        })
        .collect()
}

/// The rules of `skin_core::skin::cell_input`, written independently: the expected reading of a
/// sample and the issues it raises (in report order).
fn expected(cell: &Cell) -> (CellReading, Vec<IssueKind>) {
    let mut kinds = Vec::new();
    if cell.force.len() != 3 {
        kinds.push(IssueKind::Malformed);
    }
    let mut sane = |raw: f32| {
        if raw.is_nan() || raw.is_infinite() {
            kinds.push(IssueKind::NonFinite);
            0.0
        } else if raw < 0.0 {
            kinds.push(IssueKind::OutOfRange);
            0.0
        } else if raw > 1.0 {
            kinds.push(IssueKind::OutOfRange);
            1.0
        } else {
            f64::from(raw)
        }
    };
    let force = [0, 1, 2].map(|j| sane(cell.force.get(j).copied().unwrap_or(0.0)));
    let proximity = sane(cell.proximity);
    (CellReading { force, proximity }, kinds)
}

fn in_unit_range(v: f64) -> bool {
    v.is_finite() && (0.0..=1.0).contains(&v)
}

fn check_wrenches(layout: &ResolvedLayout, wrenches: &[PatchWrench]) {
    assert_eq!(wrenches.len(), layout.patches().len());
    for (w, patch) in wrenches.iter().zip(layout.patches()) {
        let finite = w.force.iter().chain(&w.moment).chain(&w.centroid).all(|v| v.is_finite());
        assert!(finite, "patch {}: non-finite wrench {w:?}", patch.id);
        assert!(w.active_cells <= patch.cells.len(), "patch {}: {w:?}", patch.id);
        // Each active cell adds at most a unit normal times a signal <= 1.
        assert!(w.force.norm() <= w.active_cells as f64 + 1e-9, "patch {}: {w:?}", patch.id);
        assert!(in_unit_range(w.max_force_signal) && in_unit_range(w.max_proximity_signal), "{w:?}");
    }
}

fn check_point_forces(forces: &[PointForce], bound_n: f64) {
    for f in forces {
        assert!(f.point.iter().chain(&f.force).all(|v| v.is_finite()), "non-finite cell force {f:?}");
        assert!(f.force.norm() <= bound_n * (1.0 + 1e-9), "cell force above {bound_n} N: {f:?}");
    }
}

/// The property check of the `cell_input` target.
pub fn check(data: &[u8]) {
    let t = tomm();
    let layout = &t.config.layout;
    let skin = &t.config.skin;
    let mut bytes = Bytes(data);
    let (Some(w), Some(threshold), Some(flags)) = (bytes.u8(), bytes.u8(), bytes.u8()) else {
        return;
    };
    let fusion = FusionParams {
        weight_force: f64::from(w) / 255.0,
        activity_threshold: f64::from(threshold) / 256.0,
        force_reduction: if flags & 1 == 0 { ForceReduction::Mean } else { ForceReduction::Max },
    };
    fusion.validate("fusion.").expect("decoded fusion parameters are valid");

    let mut buf = CellBuffer::new(layout);
    let mut model = vec![CellReading::default(); layout.num_cells()];
    let (mut wrenches, mut forces) = (Vec::new(), Vec::new());
    while let Some(msg) = message(&mut bytes, layout) {
        let before = *buf.issues();
        let mut reported: Vec<Issue> = Vec::new();
        let samples = msg.iter().map(|c| CellSample { cell_id: c.id, force: &c.force, proximity: c.proximity });
        buf.update(layout, samples, |i| reported.push(*i));

        let mut want: Vec<(usize, IssueKind)> = Vec::new();
        let mut seen = HashSet::new();
        for (index, cell) in msg.iter().enumerate() {
            let Some(k) = layout.cell_index(cell.id) else {
                want.push((index, IssueKind::UnknownId));
                continue;
            };
            if !seen.insert(k) {
                want.push((index, IssueKind::DuplicateId));
                continue;
            }
            let (reading, kinds) = expected(cell);
            model[k] = reading;
            want.extend(kinds.into_iter().map(|kind| (index, kind)));
        }
        let got: Vec<(usize, IssueKind)> = reported.iter().map(|i| (i.index, i.kind)).collect();
        assert_eq!(got, want, "reported issues");
        for i in &reported {
            assert_eq!(i.cell_id, msg[i.index].id, "{i}");
            let signal_issue = matches!(i.kind, IssueKind::NonFinite | IssueKind::OutOfRange);
            assert_eq!(i.value.is_some(), signal_issue, "{i}");
        }
        let counts = buf.issues();
        assert_eq!(counts.total(), before.total() + reported.len() as u64, "{counts}");
        for kind in IssueKind::ALL {
            let n = reported.iter().filter(|i| i.kind == kind).count() as u64;
            assert_eq!(counts.get(kind), before.get(kind) + n, "{}: {counts}", kind.name());
        }
        for (k, r) in buf.readings().iter().enumerate() {
            assert!(r.force.iter().all(|&v| in_unit_range(v)) && in_unit_range(r.proximity), "cell {k}: {r:?}");
        }
        assert_eq!(buf.readings(), &model[..], "readings differ from the rules");

        aggregate_patches(layout, buf.readings(), &fusion, &mut wrenches).expect("one reading per cell");
        check_wrenches(layout, &wrenches);
        let pose = |f: usize| &t.frame_poses[f];
        cell_repulsion_forces(layout, buf.readings(), &skin.proximity, &skin.repulsion, pose, &mut forces)
            .expect("one reading per cell");
        check_point_forces(&forces, skin.repulsion.gain_n_per_m * skin.repulsion.range_m);
        cell_contact_forces(layout, buf.readings(), &skin.force, &fusion, pose, &mut forces)
            .expect("one reading per cell");
        check_point_forces(&forces, skin.force.max_n);
    }
}
