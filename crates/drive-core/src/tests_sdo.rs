//! SDO access to the dictionary in Pre-Op as the tests of the dictionary
//! make it (`tests_od.rs`, `tests_variant.rs`).

use crate::DriveObjects;
use od::{CommState, Dictionary as _, SdoAbort};
use std::vec::Vec;

/// Pre-Op: where a master reads and writes the dictionary by SDO.
pub const PREOP: CommState = CommState::PreOp;

/// Reads `index:sub` in Pre-Op; its bytes.
pub fn rd(d: &mut DriveObjects, index: u16, sub: u8) -> Result<Vec<u8>, SdoAbort> {
    let mut buf = [0u8; 64];
    let n = d.read(index, sub, &mut buf, PREOP)?;
    Ok(buf[..n].to_vec())
}

/// Reads `index:sub` in Pre-Op as an unsigned little-endian number.
pub fn rd_u(d: &mut DriveObjects, index: u16, sub: u8) -> u64 {
    let v = rd(d, index, sub).unwrap();
    let mut b = [0u8; 8];
    b[..v.len()].copy_from_slice(&v);
    u64::from_le_bytes(b)
}
