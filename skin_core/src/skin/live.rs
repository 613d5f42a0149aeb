//! The cells of one cycle's readings that report anything, collected once per cycle.

use std::ops::Range;

use super::signals::CellReading;

/// The non-silent cells of one cycle's readings ([`CellReading::is_silent`]) with their
/// readings, in cell order. A silent cell adds nothing to a patch wrench (paper 003 eq. 6-8), an
/// avoidance row (paper 000 eq. 3) or a contact row (eq. 6), and most cells of a skin are
/// silent: collected once per cycle, the aggregation and the skin tasks visit only these cells
/// instead of scanning the whole skin each. Storage is allocated once
/// ([`LiveCells::with_capacity`]).
#[derive(Debug, Clone, Default)]
pub struct LiveCells {
    /// Number of readings collected from (one per layout cell).
    cells: usize,
    live: Vec<(usize, CellReading)>,
}

impl LiveCells {
    /// Room for the readings of `cells` cells: [`LiveCells::collect`] on at most that many
    /// readings does not allocate.
    pub fn with_capacity(cells: usize) -> Self {
        Self { cells: 0, live: Vec::with_capacity(cells) }
    }

    /// The non-silent cells of `readings` (indexed like the layout's cells), in new storage.
    pub fn from_readings(readings: &[CellReading]) -> Self {
        let mut live = Self::with_capacity(readings.len());
        live.collect(readings);
        live
    }

    /// Replaces the content by the non-silent cells of `readings` (indexed like the layout's
    /// cells).
    pub fn collect(&mut self, readings: &[CellReading]) {
        self.cells = readings.len();
        self.live.clear();
        self.live.extend(readings.iter().enumerate().filter(|(_, r)| !r.is_silent()).map(|(i, r)| (i, *r)));
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
        let live = LiveCells::from_readings(&readings);
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
