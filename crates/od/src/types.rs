//! CoE data types (ETG.1000.6 Table 63 / CiA 301).

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
}
