//! CoE data types (ETG.1000.6 Table 63 / CiA 301) and their little-endian
//! encoding.

use crate::SdoAbort;

/// A CoE data type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DataType {
    /// BOOLEAN (0001h), 1 bit.
    Bool,
    /// INTEGER8 (0002h).
    I8,
    /// INTEGER16 (0003h).
    I16,
    /// INTEGER32 (0004h).
    I32,
    /// UNSIGNED8 (0005h).
    U8,
    /// UNSIGNED16 (0006h).
    U16,
    /// UNSIGNED32 (0007h).
    U32,
    /// REAL32 (0008h).
    F32,
    /// VISIBLE_STRING (0009h) of the given maximum length in bytes.
    VisibleString(u16),
    /// OCTET_STRING (000Ah) of the given length in bytes.
    OctetString(u16),
    /// INTEGER64 (0015h).
    I64,
    /// UNSIGNED64 (001Bh).
    U64,
}

impl DataType {
    /// The CoE data type index (also the SII/ESI data type code).
    pub const fn code(self) -> u16 {
        match self {
            DataType::Bool => 0x0001,
            DataType::I8 => 0x0002,
            DataType::I16 => 0x0003,
            DataType::I32 => 0x0004,
            DataType::U8 => 0x0005,
            DataType::U16 => 0x0006,
            DataType::U32 => 0x0007,
            DataType::F32 => 0x0008,
            DataType::VisibleString(_) => 0x0009,
            DataType::OctetString(_) => 0x000A,
            DataType::I64 => 0x0015,
            DataType::U64 => 0x001B,
        }
    }

    /// Size in bits.
    pub const fn bits(self) -> u16 {
        match self {
            DataType::Bool => 1,
            DataType::I8 | DataType::U8 => 8,
            DataType::I16 | DataType::U16 => 16,
            DataType::I32 | DataType::U32 | DataType::F32 => 32,
            DataType::I64 | DataType::U64 => 64,
            DataType::VisibleString(n) | DataType::OctetString(n) => n.saturating_mul(8),
        }
    }

    /// Size in bytes (a BOOLEAN takes one byte in SDO transfers).
    pub const fn bytes(self) -> usize {
        (self.bits() as usize).div_ceil(8)
    }

    /// Signed integer type?
    pub const fn signed(self) -> bool {
        matches!(self, DataType::I8 | DataType::I16 | DataType::I32 | DataType::I64)
    }

    /// Variable-length (string) type?
    pub const fn is_string(self) -> bool {
        matches!(self, DataType::VisibleString(_) | DataType::OctetString(_))
    }

    /// An integer type (BOOL, INTx, UINTx)? REAL32 and strings are not.
    pub const fn is_integer(self) -> bool {
        !matches!(
            self,
            DataType::F32 | DataType::VisibleString(_) | DataType::OctetString(_)
        )
    }

    /// Smallest value of an integer type (0 for the other types).
    pub const fn min_value(self) -> i64 {
        match self {
            DataType::I8 => i8::MIN as i64,
            DataType::I16 => i16::MIN as i64,
            DataType::I32 => i32::MIN as i64,
            DataType::I64 => i64::MIN,
            _ => 0,
        }
    }

    /// Largest value of an integer type (UNSIGNED64 saturates at `i64::MAX`;
    /// REAL32 reports `u32::MAX` for its raw bits; 0 for strings).
    pub const fn max_value(self) -> i64 {
        match self {
            DataType::Bool => 1,
            DataType::I8 => i8::MAX as i64,
            DataType::I16 => i16::MAX as i64,
            DataType::I32 => i32::MAX as i64,
            DataType::I64 | DataType::U64 => i64::MAX,
            DataType::U8 => u8::MAX as i64,
            DataType::U16 => u16::MAX as i64,
            DataType::U32 | DataType::F32 => u32::MAX as i64,
            DataType::VisibleString(_) | DataType::OctetString(_) => 0,
        }
    }

    /// Checks the length of a value written to an entry of this type:
    /// numbers need exactly [`bytes`](Self::bytes) bytes (0607 0012h too
    /// long, 0607 0013h too short), a VISIBLE_STRING at most its length, an
    /// OCTET_STRING exactly its length.
    pub const fn check_len(self, len: usize) -> Result<(), SdoAbort> {
        let n = self.bytes();
        let ok = match self {
            DataType::VisibleString(_) => len <= n,
            _ => len == n,
        };
        if ok {
            Ok(())
        } else if len > n {
            Err(SdoAbort::LENGTH_TOO_HIGH)
        } else {
            Err(SdoAbort::LENGTH_TOO_LOW)
        }
    }

    /// Decodes a little-endian number of exactly [`bytes`](Self::bytes)
    /// bytes: integers sign- or zero-extended, REAL32 as its raw bits (zero
    /// extended). Strings: 0607 0010h.
    pub fn decode(self, data: &[u8]) -> Result<i64, SdoAbort> {
        if self.is_string() {
            return Err(SdoAbort::TYPE_MISMATCH);
        }
        self.check_len(data.len())?;
        let mut raw = [0u8; 8];
        for (d, s) in raw.iter_mut().zip(data) {
            *d = *s;
        }
        let v = u64::from_le_bytes(raw);
        let bits = u32::from(self.bits().max(8));
        Ok(if self.signed() && bits < 64 {
            let shift = 64 - bits;
            ((v << shift) as i64) >> shift
        } else {
            v as i64
        })
    }

    /// Encodes `value` little-endian into the first [`bytes`](Self::bytes)
    /// bytes of `out` (truncating to the type's width), returning the byte
    /// count. Strings: 0607 0010h; `out` too short: 0504 0005h.
    pub fn encode(self, value: i64, out: &mut [u8]) -> Result<usize, SdoAbort> {
        if self.is_string() {
            return Err(SdoAbort::TYPE_MISMATCH);
        }
        let n = self.bytes();
        let bytes = value.to_le_bytes();
        out.get_mut(..n)
            .zip(bytes.get(..n))
            .map(|(o, b)| o.copy_from_slice(b))
            .ok_or(SdoAbort::OUT_OF_MEMORY)?;
        Ok(n)
    }

    /// ETG name, as used in ESI files ("UINT", "DINT", ...).
    pub const fn esi_name(self) -> &'static str {
        match self {
            DataType::Bool => "BOOL",
            DataType::I8 => "SINT",
            DataType::I16 => "INT",
            DataType::I32 => "DINT",
            DataType::U8 => "USINT",
            DataType::U16 => "UINT",
            DataType::U32 => "UDINT",
            DataType::F32 => "REAL",
            DataType::VisibleString(_) => "STRING",
            DataType::OctetString(_) => "OCTET_STRING",
            DataType::I64 => "LINT",
            DataType::U64 => "ULINT",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_and_sizes() {
        assert_eq!((DataType::U16.code(), DataType::U16.bits()), (6, 16));
        assert_eq!((DataType::I64.code(), DataType::I64.bytes()), (0x15, 8));
        assert_eq!(DataType::VisibleString(16).bits(), 128);
        assert_eq!(DataType::Bool.bytes(), 1);
        assert!(DataType::I8.signed() && !DataType::U8.signed());
    }

    #[test]
    fn decode_encode_round_trip() {
        assert_eq!(DataType::I8.decode(&[0xFF]), Ok(-1));
        assert_eq!(DataType::U8.decode(&[0xFF]), Ok(255));
        assert_eq!(DataType::I16.decode(&[0x00, 0x80]), Ok(-32768));
        assert_eq!(DataType::U32.decode(&[0xFF; 4]), Ok(0xFFFF_FFFF));
        assert_eq!(DataType::I32.decode(&[0xFF; 4]), Ok(-1));
        assert_eq!(DataType::U16.decode(&[1]), Err(SdoAbort::LENGTH_TOO_LOW));
        assert_eq!(DataType::U16.decode(&[1, 2, 3]), Err(SdoAbort::LENGTH_TOO_HIGH));
        assert_eq!(DataType::VisibleString(4).check_len(2), Ok(()));
        assert_eq!(
            DataType::OctetString(4).check_len(2),
            Err(SdoAbort::LENGTH_TOO_LOW)
        );
        let mut b = [0u8; 4];
        assert_eq!(DataType::I16.encode(-2, &mut b), Ok(2));
        assert_eq!(b, [0xFE, 0xFF, 0, 0]);
        assert_eq!(DataType::U32.encode(1, &mut b[..2]), Err(SdoAbort::OUT_OF_MEMORY));
    }
}
