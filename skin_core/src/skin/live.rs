//! The cells of one cycle's readings that report anything, collected once per cycle.

use std::ops::Range;

use super::characteristic::{PreparedProximity, ProximityCharacteristic};
use super::signals::CellReading;

/// The non-silent cells of one cycle's readings ([`CellReading::is_silent`]) with their
/// readings, in cell order. A silent cell adds nothing to a patch wrench (interactive-force-control paper eq. 6-8), an
/// avoidance row (intentional-contact paper eq. 3) or a contact row (eq. 6), and most cells of a skin are
/// silent: collected once per cycle, the aggregation and the skin tasks visit only these cells
/// instead of scanning the whole skin each. With each cell its distance through the inverse
/// proximity characteristic, computed once per cycle for the supervisor's summary and the
/// avoidance task (intentional-contact paper eq. 3). Storage is allocated once ([`LiveCells::with_capacity`]).
#[derive(Debug, Clone)]
pub struct LiveCells {
    /// Number of readings collected from (one per layout cell).
    cells: usize,
    live: Vec<(usize, CellReading)>,
    /// `d_i` of each live cell (`range_m` without a proximity signal).
    distances: Vec<f64>,
    proximity: PreparedProximity,
}

impl LiveCells {
    /// Room for the readings of `cells` cells: [`LiveCells::collect`] on at most that many
    /// readings does not allocate. `proximity` turns the proximity signals into distances.
    pub fn with_capacity(cells: usize, proximity: &ProximityCharacteristic) -> Self {
        Self {
            cells: 0,
            live: Vec::with_capacity(cells),
            distances: Vec::with_capacity(cells),
            proximity: proximity.prepared(),
        }
    }

    /// The non-silent cells of `readings` (indexed like the layout's cells), in new storage.
    pub fn from_readings(readings: &[CellReading], proximity: &ProximityCharacteristic) -> Self {
        let mut live = Self::with_capacity(readings.len(), proximity);
        live.collect(readings);
        live
    }

    /// Replaces the content by the non-silent cells of `readings` (indexed like the layout's
    /// cells) and their distances.
    pub fn collect(&mut self, readings: &[CellReading]) {
        self.cells = readings.len();
        self.live.clear();
        collect_live(readings, &mut self.live);
        let prox = &self.proximity;
        self.distances.clear();
        self.distances.extend(self.live.iter().map(|(_, r)| prox.distance_m(r.proximity_signal())));
    }

    /// Distance \[m\] of each cell of [`LiveCells::cells`] (inverse proximity characteristic,
    /// in `[0, range_m]`).
    pub fn distances(&self) -> &[f64] {
        &self.distances
    }

    /// The sensing range \[m\] of the proximity characteristic the distances come from.
    pub fn proximity_range_m(&self) -> f64 {
        self.proximity.range_m()
    }

    /// Number of readings the cells were collected from.
    pub fn num_cells(&self) -> usize {
        self.cells
    }

    /// `(cell index, reading)` of every non-silent cell, ascending by index.
    pub fn cells(&self) -> &[(usize, CellReading)] {
        &self.live
    }

    /// The non-silent cells with an index in `range` (e.g. one patch's cells).
    pub fn in_range(&self, range: Range<usize>) -> &[(usize, CellReading)] {
        let start = self.live.partition_point(|&(i, _)| i < range.start);
        let end = start + self.live[start..].partition_point(|&(i, _)| i < range.end);
        &self.live[start..end]
    }
}

avx2_dispatch! {
    /// Appends `(index, reading)` of the non-silent `readings` to `live`: the scan of the whole
    /// skin every cycle, a cell's four values tested in one AVX2 comparison when the CPU has it.
    collect_live => collect_live_kernel(readings: &[CellReading], live: &mut Vec<(usize, CellReading)>)
}

#[inline(always)]
fn collect_live_kernel(readings: &[CellReading], live: &mut Vec<(usize, CellReading)>) {
    let blocks = readings.chunks_exact(SCAN_BLOCK);
    let tail = blocks.remainder();
    for (b, block) in blocks.enumerate() {
        // `|` without an exit per cell: a block of silent cells (most of a skin) is one branch
        if block.iter().fold(false, |any, r| any | !r.is_silent()) {
            push_live(block, b * SCAN_BLOCK, live);
        }
    }
    push_live(tail, readings.len() - tail.len(), live);
}

/// Cells per block of [`collect_live`]'s scan.
const SCAN_BLOCK: usize = 4;

/// Appends the non-silent `cells` to `live`, `first` being the index of `cells[0]`.
#[inline(always)]
fn push_live(cells: &[CellReading], first: usize, live: &mut Vec<(usize, CellReading)>) {
    live.extend(cells.iter().enumerate().filter(|(_, r)| !r.is_silent()).map(|(k, r)| (first + k, *r)));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_cells_with_any_value_above_zero() {
        let mut readings = vec![CellReading::default(); 10];
        readings[2].force[1] = 0.1;
        readings[5].proximity = 0.3;
        readings[7] = CellReading::uniform(f64::NAN, -1.0); // sanitized to 0: silent
        readings[9].proximity = 1.0;
        let prox = ProximityCharacteristic { range_m: 0.2, decay_m: 0.05 };
        let live = LiveCells::from_readings(&readings, &prox);
        assert_eq!(live.num_cells(), 10);
        let idx: Vec<usize> = live.cells().iter().map(|&(i, _)| i).collect();
        assert_eq!(idx, [2, 5, 9]);
        assert_eq!(live.cells()[1].1, readings[5]);
        let idx: Vec<usize> = live.in_range(3..9).iter().map(|&(i, _)| i).collect();
        assert_eq!(idx, [5]);
        assert!(live.in_range(6..9).is_empty());
        // reuse: no reallocation
        let (cap, ptr) = (live.live.capacity(), live.live.as_ptr());
        let mut live = live;
        live.collect(&readings[..4]);
        assert_eq!((live.num_cells(), live.cells().len()), (4, 1));
        assert_eq!((live.live.capacity(), live.live.as_ptr()), (cap, ptr));
    }
}
