//! A skin layout resolved against a robot model ([`super::layout::SkinLayout::resolve`]):
//! link frame indices, cell poses precomputed in the patch and link frames, and compact
//! per-cell geometry for the per-cycle loops.

use std::ops::Range;

use nalgebra::{Isometry3, Vector3};

/// A patch resolved against a robot model.
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedPatch {
    /// Patch id from the layout.
    pub id: u32,
    /// Link name.
    pub link: String,
    /// Frame index of the link in the robot model.
    pub frame: usize,
    /// Pose of the patch frame {p_j} in the link frame.
    pub link_from_patch: Isometry3<f64>,
    /// Indices into [`ResolvedLayout::cells`] of this patch's cells.
    pub cells: Range<usize>,
}

/// A cell resolved against a robot model, with its pose precomputed in the patch and link frames.
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedCell {
    /// Cell id from the layout.
    pub id: u32,
    /// Index into [`ResolvedLayout::patches`].
    pub patch: usize,
    /// Frame index of the link carrying the cell.
    pub frame: usize,
    /// Cell position in the patch frame, `{p_j} t_{s_i}` \[m\].
    pub position_patch: Vector3<f64>,
    /// Unit outward normal in the patch frame (z axis of {s_i}).
    pub normal_patch: Vector3<f64>,
    /// Pose of the cell frame {s_i} in the patch frame.
    pub patch_from_cell: Isometry3<f64>,
    /// Cell position in the link frame \[m\].
    pub position_link: Vector3<f64>,
    /// Unit outward normal in the link frame.
    pub normal_link: Vector3<f64>,
    /// Pose of the cell frame {s_i} in the link frame.
    pub link_from_cell: Isometry3<f64>,
}

/// Compact per-cell geometry in the patch frame, for the aggregation hot loop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PatchCellGeometry {
    /// Unit outward normal `n_i` in the patch frame.
    pub(crate) normal: Vector3<f64>,
    /// Lever `t_i × n_i` (interactive-force-control paper eq. (8) per unit virtual force).
    pub(crate) lever: Vector3<f64>,
    /// Position `t_i` in the patch frame \[m\].
    pub(crate) position: Vector3<f64>,
}

/// Compact per-cell geometry in the link frame, for the cell force loops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LinkCellGeometry {
    /// Frame index of the link.
    pub(crate) frame: usize,
    /// Position in the link frame \[m\].
    pub(crate) position: Vector3<f64>,
    /// Unit outward normal in the link frame.
    pub(crate) normal: Vector3<f64>,
}

/// Cell id -> index into [`ResolvedLayout::cells`]. Every cell of every `/skin/cells` message is
/// looked up, so ids numbered densely (a skin's cells are 1..n) get a table indexed by id;
/// sparse ids (a table would be large) keep the sorted pairs and a binary search.
#[derive(Debug, Clone, PartialEq)]
enum IdIndex {
    /// `table[id]` is the index, `u32::MAX` where no cell has that id.
    Dense(Vec<u32>),
    /// `(id, index)` sorted by id.
    Sorted(Vec<(u32, usize)>),
}

impl IdIndex {
    /// Ids up to this many per cell (plus a margin) get a table.
    const DENSE_IDS_PER_CELL: usize = 8;

    fn new(cells: &[ResolvedCell]) -> Self {
        let max = cells.iter().map(|c| c.id as usize).max().unwrap_or(0);
        if max < Self::DENSE_IDS_PER_CELL * cells.len() + 1024 && cells.len() < u32::MAX as usize {
            let mut table = vec![u32::MAX; max + 1];
            for (i, c) in cells.iter().enumerate() {
                table[c.id as usize] = i as u32;
            }
            IdIndex::Dense(table)
        } else {
            let mut ids: Vec<(u32, usize)> = cells.iter().enumerate().map(|(i, c)| (c.id, i)).collect();
            ids.sort_unstable();
            IdIndex::Sorted(ids)
        }
    }

    fn get(&self, id: u32) -> Option<usize> {
        match self {
            IdIndex::Dense(table) => table.get(id as usize).filter(|&&i| i != u32::MAX).map(|&i| i as usize),
            IdIndex::Sorted(ids) => ids.binary_search_by_key(&id, |&(i, _)| i).ok().map(|k| ids[k].1),
        }
    }
}

/// A validated layout resolved against a robot model; cells are grouped by patch. Immutable:
/// read through the accessors.
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedLayout {
    source: String,
    patches: Vec<ResolvedPatch>,
    cells: Vec<ResolvedCell>,
    ids: IdIndex,
    pub(crate) patch_geometry: Vec<PatchCellGeometry>,
    pub(crate) link_geometry: Vec<LinkCellGeometry>,
}

impl ResolvedLayout {
    pub(crate) fn new(source: String, patches: Vec<ResolvedPatch>, cells: Vec<ResolvedCell>) -> Self {
        let ids = IdIndex::new(&cells);
        let patch_geometry = cells
            .iter()
            .map(|c| PatchCellGeometry {
                normal: c.normal_patch,
                lever: c.position_patch.cross(&c.normal_patch),
                position: c.position_patch,
            })
            .collect();
        let link_geometry = cells
            .iter()
            .map(|c| LinkCellGeometry { frame: c.frame, position: c.position_link, normal: c.normal_link })
            .collect();
        ResolvedLayout { source, patches, cells, ids, patch_geometry, link_geometry }
    }

    /// Source file of the layout.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Patches, in file order.
    pub fn patches(&self) -> &[ResolvedPatch] {
        &self.patches
    }

    /// Cells, grouped by patch (see [`ResolvedPatch::cells`]). Per-cell signal arrays are
    /// indexed like this slice.
    pub fn cells(&self) -> &[ResolvedCell] {
        &self.cells
    }

    /// Index into [`Self::cells`] of the cell with id `id`.
    pub fn cell_index(&self, id: u32) -> Option<usize> {
        self.ids.get(id)
    }

    /// Index into [`Self::patches`] of the patch with id `id`.
    pub fn patch_index(&self, id: u32) -> Option<usize> {
        self.patches.iter().position(|p| p.id == id)
    }

    /// Number of cells.
    pub fn num_cells(&self) -> usize {
        self.cells.len()
    }
}
