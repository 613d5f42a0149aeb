//! CDR (XCDR1, little endian) as ROS 2 puts it on the wire and rosbag2 stores it: the 4-byte
//! encapsulation header `00 01 00 00`, then the payload, aligned relative to the payload start.

use byteorder::LittleEndian;
use serde::de::DeserializeOwned;
use serde::Serialize;

/// Encapsulation header: representation CDR_LE, options 0.
const CDR_LE: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// A message as stored in a bag.
pub fn encode<M: Serialize>(msg: &M) -> Result<Vec<u8>, String> {
    let payload = cdr_encoding::to_vec::<M, LittleEndian>(msg).map_err(|e| e.to_string())?;
    Ok([&CDR_LE[..], &payload].concat())
}

/// A message from its bag bytes (little-endian CDR only, the encoding every ROS 2 x86/ARM host
/// writes).
pub fn decode<M: DeserializeOwned>(data: &[u8]) -> Result<M, String> {
    match data.split_first_chunk::<4>() {
        Some((header, payload)) if header[..2] == CDR_LE[..2] => {
            cdr_encoding::from_bytes::<M, LittleEndian>(payload).map(|(msg, _)| msg).map_err(|e| e.to_string())
        }
        Some((header, _)) => Err(format!("unsupported CDR encapsulation {header:02x?}")),
        None => Err(format!("{} bytes: shorter than the CDR header", data.len())),
    }
}
