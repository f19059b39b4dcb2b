//! FMMU register block (0x0600 + 16·n, 16 bytes): logical → physical mapping.

use crate::{byte, le_u16, le_u32, Truncated};

/// The 16-byte FMMU register block.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Fmmu {
    /// Logical start address (u32).
    pub logical_start: u32,
    /// Length in bytes (u16).
    pub length: u16,
    /// Logical start bit (0..7).
    pub logical_start_bit: u8,
    /// Logical stop bit (0..7).
    pub logical_stop_bit: u8,
    /// Physical start address (u16).
    pub physical_start: u16,
    /// Physical start bit (0..7).
    pub physical_start_bit: u8,
    /// Type: bit 0 read (ECAT reads, i.e. inputs), bit 1 write (outputs).
    pub kind: u8,
    /// Activate: bit 0 enabled.
    pub activate: u8,
}

impl Fmmu {
    /// Register block length in bytes.
    pub const LEN: usize = 16;
    /// `kind` bit: mapping used for reads (LRD, LRW).
    pub const READ: u8 = 1;
    /// `kind` bit: mapping used for writes (LWR, LRW).
    pub const WRITE: u8 = 2;

    /// Parses the register block; errors when `b` is shorter than 16 bytes.
    pub fn parse(b: &[u8]) -> Result<Self, Truncated> {
        Ok(Self {
            logical_start: le_u32(b, 0)?,
            length: le_u16(b, 4)?,
            logical_start_bit: byte(b, 6)? & 7,
            logical_stop_bit: byte(b, 7)? & 7,
            physical_start: le_u16(b, 8)?,
            physical_start_bit: byte(b, 10)? & 7,
            kind: byte(b, 11)?,
            activate: byte(b, 12)?,
        })
    }

    /// The register block as bytes.
    pub fn to_bytes(&self) -> [u8; 16] {
        let l = self.logical_start.to_le_bytes();
        let n = self.length.to_le_bytes();
        let p = self.physical_start.to_le_bytes();
        [
            l[0],
            l[1],
            l[2],
            l[3],
            n[0],
            n[1],
            self.logical_start_bit,
            self.logical_stop_bit,
            p[0],
            p[1],
            self.physical_start_bit,
            self.kind,
            self.activate,
            0,
            0,
            0,
        ]
    }

    /// Enabled.
    pub const fn enabled(&self) -> bool {
        self.activate & 1 != 0
    }

    /// The physical address of logical address `logical`, when this FMMU maps it
    /// (byte-granular; bit-granular mappings are mapped by their whole bytes).
    pub fn map(&self, logical: u32) -> Option<u16> {
        let off = logical.checked_sub(self.logical_start)?;
        if off >= u32::from(self.length) {
            return None;
        }
        u16::try_from(off)
            .ok()
            .and_then(|o| self.physical_start.checked_add(o))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fmmu_round_trip_and_map() {
        let f = Fmmu {
            logical_start: 0x10000,
            length: 23,
            logical_start_bit: 0,
            logical_stop_bit: 7,
            physical_start: 0x1100,
            physical_start_bit: 0,
            kind: Fmmu::WRITE,
            activate: 1,
        };
        assert_eq!(Fmmu::parse(&f.to_bytes()), Ok(f));
        assert_eq!(Fmmu::parse(&[0; 12]), Err(Truncated));
        assert_eq!(f.map(0x10000), Some(0x1100));
        assert_eq!(f.map(0x10016), Some(0x1116));
        assert_eq!(f.map(0x10017), None);
        assert_eq!(f.map(0xFFFF), None);
    }
}
