//! A `/skin/cells` message read from its serialized bytes (CDR, XCDR1 little endian: what
//! rmw_fastrtps puts on the wire), for `Node::subscribe_raw`: the cells go straight into a
//! reused buffer instead of a C message that is allocated, filled field by field by the type
//! support and freed for every message (700 cells on TOMM, 250 times a second: the graph's
//! largest input, on the path the latency benchmark times).
//!
//! Layout (`skin_msgs/SkinCellArray`), offsets relative to the payload after the 4-byte
//! encapsulation header, each primitive aligned to its size: `header.stamp` (int32 sec, uint32
//! nanosec), `header.frame_id` (uint32 length with the NUL, bytes), `cells` (uint32 count), then
//! per cell `cell_id` (uint32), `force` (float32[3]), `proximity` (float32), `acceleration`
//! (3 float64), `temperature` (float32).
use r2r::builtin_interfaces::msg::Time;

use super::{CellMessage, CellSample};

/// One cell as the rules read it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Cell {
    id: u32,
    force: [f32; 3],
    proximity: f32,
}

/// The last message parsed by [`CdrCells::parse`]; its buffer is kept for the next one.
#[derive(Debug, Clone, Default)]
pub struct CdrCells {
    stamp: Time,
    cells: Vec<Cell>,
}

/// A reader of the CDR payload: a position and the alignment rule.
struct Cursor<'a> {
    payload: &'a [u8],
    pos: usize,
}

impl Cursor<'_> {
    /// The next `N` bytes after aligning to `align`.
    fn take<const N: usize>(&mut self, align: usize, field: &str) -> Result<[u8; N], String> {
        let start = self.pos.next_multiple_of(align);
        let bytes = self.payload.get(start..start + N).ok_or_else(|| format!("ends inside {field} (offset {start})"))?;
        self.pos = start + N;
        Ok(bytes.try_into().expect("N bytes"))
    }

    fn u32(&mut self, field: &str) -> Result<u32, String> {
        self.take::<4>(4, field).map(u32::from_le_bytes)
    }

    fn f32(&mut self, field: &str) -> Result<f32, String> {
        self.take::<4>(4, field).map(f32::from_le_bytes)
    }

    fn skip(&mut self, n: usize, align: usize, field: &str) -> Result<(), String> {
        let start = self.pos.next_multiple_of(align);
        if start + n > self.payload.len() {
            return Err(format!("ends inside {field} (offset {start})"));
        }
        self.pos = start + n;
        Ok(())
    }
}

/// Fewest bytes one cell takes (the count is checked against the message's size before the
/// buffer grows).
const MIN_CELL_BYTES: usize = 4 + 12 + 4 + 24 + 4;

impl CdrCells {
    /// Reads `data` (a whole serialized message); on an error (the reason names the field) the
    /// previous contents are gone.
    pub fn parse(&mut self, data: &[u8]) -> Result<(), String> {
        self.cells.clear();
        let payload = match data.split_first_chunk::<4>() {
            Some(([0, 1, _, _], payload)) => payload,
            Some((header, _)) => return Err(format!("CDR encapsulation {header:02x?}: only little-endian CDR (00 01) is read")),
            None => return Err(format!("{} bytes: shorter than the CDR header", data.len())),
        };
        let mut c = Cursor { payload, pos: 0 };
        let sec = c.take::<4>(4, "header.stamp.sec").map(i32::from_le_bytes)?;
        let nanosec = c.u32("header.stamp.nanosec")?;
        self.stamp = Time { sec, nanosec };
        let frame_id = c.u32("header.frame_id")? as usize;
        c.skip(frame_id, 1, "header.frame_id")?;
        let n = c.u32("cells")? as usize;
        if n > payload.len() / MIN_CELL_BYTES {
            return Err(format!("cells: {n} announced, {} bytes hold fewer", payload.len()));
        }
        self.cells.reserve(n);
        for _ in 0..n {
            let id = c.u32("cells[].cell_id")?;
            let force = [c.f32("cells[].force")?, c.f32("cells[].force")?, c.f32("cells[].force")?];
            let proximity = c.f32("cells[].proximity")?;
            c.skip(24, 8, "cells[].acceleration")?;
            c.skip(4, 4, "cells[].temperature")?;
            self.cells.push(Cell { id, force, proximity });
        }
        Ok(())
    }
}

impl CellMessage for CdrCells {
    fn stamp(&self) -> Time {
        self.stamp.clone()
    }

    fn samples(&self) -> impl Iterator<Item = CellSample<'_>> {
        self.cells.iter().map(|c| CellSample { cell_id: c.id, force: &c.force, proximity: c.proximity })
    }
}

#[cfg(test)]
mod tests {
    use r2r::skin_msgs::msg::{SkinCell, SkinCellArray};
    use r2r::WrappedTypesupport;

    use super::*;

    fn message(n: u32, frame_id: &str) -> SkinCellArray {
        let mut m = SkinCellArray::default();
        m.header.stamp = Time { sec: -3, nanosec: 999_999_999 };
        m.header.frame_id = frame_id.into();
        m.cells = (0..n)
            .map(|i| SkinCell {
                cell_id: 1000 + i,
                force: vec![0.1 * i as f32, -0.0, f32::NAN],
                proximity: 1.0 / (i + 1) as f32,
                acceleration: r2r::geometry_msgs::msg::Vector3 { x: 1.0, y: 2.0, z: 3.0 },
                temperature: 36.6,
            })
            .collect();
        m
    }

    fn same(got: &CdrCells, want: &SkinCellArray) {
        assert_eq!(got.stamp(), want.header.stamp);
        let got: Vec<_> = got.samples().map(|s| (s.cell_id, s.force.iter().map(|f| f.to_bits()).collect::<Vec<_>>(), s.proximity.to_bits())).collect();
        let want: Vec<_> = want.samples().map(|s| (s.cell_id, s.force.iter().map(|f| f.to_bits()).collect::<Vec<_>>(), s.proximity.to_bits())).collect();
        assert_eq!(got, want);
    }

    #[test]
    fn the_bytes_of_the_type_support_read_as_the_message() {
        // every frame_id length mod 8 (the cells' float64 alignment shifts with it), no cell to many
        let mut cells = CdrCells::default();
        for (n, frame) in [(0, ""), (1, "a"), (3, "ab"), (718, "skin"), (5, "patch_07"), (2, "patch_007")] {
            let m = message(n, frame);
            cells.parse(&m.to_serialized_bytes().unwrap()).unwrap();
            same(&cells, &m);
        }
    }

    #[test]
    fn cut_or_foreign_bytes_are_refused_naming_the_field() {
        let bytes = message(3, "skin").to_serialized_bytes().unwrap();
        let mut cells = CdrCells::default();
        for cut in [2, 10, 20, bytes.len() - 30, bytes.len() - 1] {
            let e = cells.parse(&bytes[..cut]).unwrap_err();
            assert!(["shorter", "ends inside", "announced"].iter().any(|w| e.contains(w)), "{cut}: {e}");
        }
        let mut big_endian = bytes.clone();
        big_endian[1] = 0;
        assert!(cells.parse(&big_endian).unwrap_err().contains("little-endian"));
        // a count the bytes cannot hold is refused before anything is allocated for it
        let mut huge = message(0, "").to_serialized_bytes().unwrap();
        let at = huge.len() - 4;
        huge[at..].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(cells.parse(&huge).unwrap_err().contains("announced"));
    }
}
