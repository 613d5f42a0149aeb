//! A `/skin/cells` message read from its serialized bytes (CDR, XCDR1 little endian: what
//! rmw_fastrtps puts on the wire), for `Node::subscribe_raw`: the arrays go straight into reused
//! buffers instead of a C message that is allocated and filled by the type support for every
//! message (700 cells on TOMM, 250 times a second: the graph's largest input, on the path the
//! latency benchmark times).
//!
//! Layout (`skin_msgs/SkinCellArray`), offsets relative to the payload after the 4-byte
//! encapsulation header, each primitive aligned to its size: `header.stamp` (int32 sec, uint32
//! nanosec), `header.frame_id` (uint32 length with the NUL, bytes), then the arrays `cell_id`
//! (uint32), `force`, `proximity`, `acceleration`, `temperature` (float32), each a uint32 count
//! and its values.
use r2r::builtin_interfaces::msg::Time;

use super::{CellArrays, CellMessage};

/// The last message parsed by [`CdrCells::parse`]; its buffers are kept for the next one.
#[derive(Debug, Clone, Default)]
pub struct CdrCells {
    stamp: Time,
    cell_id: Vec<u32>,
    force: Vec<f32>,
    proximity: Vec<f32>,
    acceleration_len: usize,
    temperature_len: usize,
}

/// A reader of the CDR payload: a position and the alignment rule.
struct Cursor<'a> {
    payload: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    /// The next `n` bytes after aligning to `align`.
    fn bytes(&mut self, n: usize, align: usize, field: &str) -> Result<&'a [u8], String> {
        let start = self.pos.next_multiple_of(align);
        let bytes = self
            .payload
            .get(start..start.saturating_add(n))
            .ok_or_else(|| format!("ends inside {field} (offset {start})"))?;
        self.pos = start + n;
        Ok(bytes)
    }

    fn u32(&mut self, field: &str) -> Result<u32, String> {
        let b = self.bytes(4, 4, field)?;
        Ok(u32::from_le_bytes(b.try_into().expect("4 bytes")))
    }

    /// A sequence of 4-byte values (count, then the values): the values' bytes and their count.
    fn words(&mut self, field: &str) -> Result<(&'a [u8], usize), String> {
        let n = self.u32(field)? as usize;
        Ok((self.bytes(n.saturating_mul(4), 4, field)?, n))
    }
}

/// Appends the little-endian 4-byte values in `bytes` to `out`.
fn read_words<T>(bytes: &[u8], out: &mut Vec<T>, from: impl Fn([u8; 4]) -> T) {
    out.extend(bytes.chunks_exact(4).map(|w| from(w.try_into().expect("4 bytes"))));
}

impl CdrCells {
    /// Reads `data` (a whole serialized message); on an error (the reason names the field) the
    /// previous contents are gone. Array lengths are checked against each other when the cells
    /// are read ([`CellArrays::samples`]).
    pub fn parse(&mut self, data: &[u8]) -> Result<(), String> {
        self.cell_id.clear();
        self.force.clear();
        self.proximity.clear();
        (self.acceleration_len, self.temperature_len) = (0, 0);
        let payload = match data.split_first_chunk::<4>() {
            Some(([0, 1, _, _], payload)) => payload,
            Some((header, _)) => {
                return Err(format!("CDR encapsulation {header:02x?}: only little-endian CDR (00 01) is read"))
            }
            None => return Err(format!("{} bytes: shorter than the CDR header", data.len())),
        };
        let mut c = Cursor { payload, pos: 0 };
        let sec = c.u32("header.stamp.sec")? as i32;
        let nanosec = c.u32("header.stamp.nanosec")?;
        let frame_id = c.u32("header.frame_id")? as usize;
        c.bytes(frame_id, 1, "header.frame_id")?;
        let (ids, _) = c.words("cell_id")?;
        let (force, _) = c.words("force")?;
        let (proximity, _) = c.words("proximity")?;
        let (_, acceleration_len) = c.words("acceleration")?;
        let (_, temperature_len) = c.words("temperature")?;
        // the type support pads a message to a multiple of 4 bytes at most: more is another type
        if payload.len() - c.pos >= 4 {
            return Err(format!(
                "{} bytes after temperature: not a skin_msgs/SkinCellArray of this definition",
                payload.len() - c.pos
            ));
        }
        read_words(ids, &mut self.cell_id, u32::from_le_bytes);
        read_words(force, &mut self.force, f32::from_le_bytes);
        read_words(proximity, &mut self.proximity, f32::from_le_bytes);
        (self.acceleration_len, self.temperature_len) = (acceleration_len, temperature_len);
        self.stamp = Time { sec, nanosec };
        Ok(())
    }
}

impl CellMessage for CdrCells {
    fn stamp(&self) -> Time {
        self.stamp.clone()
    }

    fn arrays(&self) -> CellArrays<'_> {
        CellArrays {
            cell_id: &self.cell_id,
            force: &self.force,
            proximity: &self.proximity,
            acceleration_len: self.acceleration_len,
            temperature_len: self.temperature_len,
        }
    }
}

#[cfg(test)]
mod tests {
    use r2r::skin_msgs::msg::SkinCellArray;
    use r2r::WrappedTypesupport;

    use super::*;

    fn message(n: u32, frame_id: &str) -> SkinCellArray {
        let mut m = SkinCellArray::default();
        m.header.stamp = Time { sec: -3, nanosec: 999_999_999 };
        m.header.frame_id = frame_id.into();
        m.cell_id = (0..n).map(|i| 1000 + i).collect();
        m.force = (0..n).flat_map(|i| [0.1 * i as f32, -0.0, f32::NAN]).collect();
        m.proximity = (0..n).map(|i| 1.0 / (i + 1) as f32).collect();
        if n % 2 == 1 {
            m.acceleration = (0..3 * n).map(|i| i as f32 - 9.81).collect();
            m.temperature = vec![36.6; n as usize];
        }
        m
    }

    fn same(got: &CdrCells, want: &SkinCellArray) {
        assert_eq!(got.stamp(), want.header.stamp);
        let bits = |a: CellArrays| {
            let f = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            (a.cell_id.to_vec(), f(a.force), f(a.proximity), a.acceleration_len, a.temperature_len)
        };
        assert_eq!(bits(got.arrays()), bits(want.arrays()));
    }

    #[test]
    fn the_bytes_of_the_type_support_read_as_the_message() {
        // frame_id lengths for every alignment of the arrays after it, no cell to many, with and
        // without acceleration and temperature
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
            assert!(["shorter", "ends inside"].iter().any(|w| e.contains(w)), "{cut}: {e}");
        }
        let mut longer = bytes.clone();
        longer.extend([0; 4]);
        assert!(cells.parse(&longer).unwrap_err().contains("4 bytes after temperature"));
        let mut big_endian = bytes.clone();
        big_endian[1] = 0;
        assert!(cells.parse(&big_endian).unwrap_err().contains("little-endian"));
        // a count the bytes cannot hold is refused before anything is allocated for it
        let mut huge = message(0, "").to_serialized_bytes().unwrap();
        let at = huge.len() - 4;
        huge[at..].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(cells.parse(&huge).unwrap_err().contains("ends inside temperature"));
    }
}
