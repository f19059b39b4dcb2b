//! The 6-byte record of a packed entry and the 32-bit "kind" it points to
//! (data type with its string length, access bits, persistence, unit): the
//! bit layout, shared by the builder and the decoder.
//!
//! A record is 48 bits, from bit 0: name offset in the string table (14),
//! name length (6), subindex (8), kind index (7), range index (5, all ones:
//! none), default index (8, all ones: none = 0). A kind is 32 bits: access
//! (10), persistent (1), unit index (5), type (4), string length (12).

use crate::{Access, DataType};

const OFF: (u32, u32) = (0, 14);
const LEN: (u32, u32) = (14, 6);
const SUB: (u32, u32) = (20, 8);
const KIND: (u32, u32) = (28, 7);
const RANGE: (u32, u32) = (35, 5);
const DEFAULT: (u32, u32) = (40, 8);

/// Largest value of a field.
const fn max(f: (u32, u32)) -> u64 {
    (1 << f.1) - 1
}

/// Most bytes of the string table a record can point into.
pub(super) const MAX_STRINGS: usize = max(OFF) as usize + 1;
/// Longest name.
pub(super) const MAX_NAME: usize = max(LEN) as usize;
/// Most distinct kinds in a table.
pub(super) const MAX_KINDS: usize = max(KIND) as usize + 1;
/// No range (range index).
pub(super) const NO_RANGE: u16 = max(RANGE) as u16;
/// No default: reads 0 (default index).
pub(super) const NO_DEFAULT: u16 = max(DEFAULT) as u16;

/// One entry in 6 bytes: name (offset and length in the string table),
/// subindex, and indices into the table's kinds, ranges and defaults.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PackedEntry([u16; 3]);

impl PackedEntry {
    /// A record of no table: subindex 0, no name, kind 0 (every table's
    /// kind 0 is UNSIGNED8, read-only, no unit, not persistent), no range, no
    /// default (placeholder in fixed-size tables).
    pub const UNUSED: Self = Self::new(0, 0, 0, 0, NO_RANGE, NO_DEFAULT);

    /// A record; each field must fit its width (checked by the builder).
    pub(super) const fn new(off: u16, len: u16, sub: u8, kind: u16, range: u16, default: u16) -> Self {
        let v = (off as u64) << OFF.0
            | (len as u64) << LEN.0
            | (sub as u64) << SUB.0
            | (kind as u64) << KIND.0
            | (range as u64) << RANGE.0
            | (default as u64) << DEFAULT.0;
        Self([v as u16, (v >> 16) as u16, (v >> 32) as u16])
    }

    const fn field(&self, f: (u32, u32)) -> u16 {
        let v = self.0[0] as u64 | (self.0[1] as u64) << 16 | (self.0[2] as u64) << 32;
        ((v >> f.0) & max(f)) as u16
    }

    /// Subindex.
    pub const fn sub(&self) -> u8 {
        self.field(SUB) as u8
    }

    /// Offset of the name in the string table.
    pub(super) const fn name_at(&self) -> usize {
        self.field(OFF) as usize
    }

    /// Length of the name.
    pub(super) const fn name_len(&self) -> usize {
        self.field(LEN) as usize
    }

    /// Index of the kind.
    pub(super) const fn kind(&self) -> usize {
        self.field(KIND) as usize
    }

    /// Index of the range ([`NO_RANGE`]: none).
    pub(super) const fn range(&self) -> usize {
        self.field(RANGE) as usize
    }

    /// Index of the default ([`NO_DEFAULT`]: none).
    pub(super) const fn default(&self) -> usize {
        self.field(DEFAULT) as usize
    }
}

const PERSISTENT: u32 = 1 << 10;
const UNIT_SHIFT: u32 = 11;
const TYPE_SHIFT: u32 = 16;
const LEN_SHIFT: u32 = 20;
/// Access bits of a kind.
pub(super) const ACCESS_MASK: u32 = (1 << 10) - 1;
/// Most units a kind can name.
pub(super) const MAX_UNITS: usize = 1 << (TYPE_SHIFT - UNIT_SHIFT);
/// Longest string type.
pub(super) const MAX_STRING: u16 = (1 << 12) - 1;

/// The kind of an entry: data type, access, persistence, unit index.
pub(super) const fn kind_of(t: DataType, access: Access, persistent: bool, unit: u32) -> u32 {
    let (k, n) = type_code(t);
    access.0 as u32 & ACCESS_MASK
        | if persistent { PERSISTENT } else { 0 }
        | unit << UNIT_SHIFT
        | (k as u32) << TYPE_SHIFT
        | (n as u32) << LEN_SHIFT
}

/// Kind 0 of every table (and of [`PackedEntry::UNUSED`]).
pub(super) const PLACEHOLDER_KIND: u32 = kind_of(DataType::U8, Access::RO, false, 0);

/// Access of a kind.
pub(super) const fn access_of(kind: u32) -> Access {
    Access((kind & ACCESS_MASK) as u16)
}

/// Persistent kind?
pub(super) const fn persistent_of(kind: u32) -> bool {
    kind & PERSISTENT != 0
}

/// Unit index of a kind.
pub(super) const fn unit_of(kind: u32) -> usize {
    ((kind >> UNIT_SHIFT) as usize) & (MAX_UNITS - 1)
}

/// Type code and string length of `t`.
pub(super) const fn type_code(t: DataType) -> (u16, u16) {
    match t {
        DataType::Bool => (0, 0),
        DataType::I8 => (1, 0),
        DataType::I16 => (2, 0),
        DataType::I32 => (3, 0),
        DataType::U8 => (4, 0),
        DataType::U16 => (5, 0),
        DataType::U32 => (6, 0),
        DataType::F32 => (7, 0),
        DataType::VisibleString(n) => (8, n),
        DataType::OctetString(n) => (9, n),
        DataType::I64 => (10, 0),
        DataType::U64 => (11, 0),
    }
}

/// Data type of a kind.
pub(super) const fn type_of(kind: u32) -> DataType {
    let n = (kind >> LEN_SHIFT) as u16 & MAX_STRING;
    match (kind >> TYPE_SHIFT) & 0xF {
        0 => DataType::Bool,
        1 => DataType::I8,
        2 => DataType::I16,
        3 => DataType::I32,
        4 => DataType::U8,
        5 => DataType::U16,
        6 => DataType::U32,
        7 => DataType::F32,
        8 => DataType::VisibleString(n),
        9 => DataType::OctetString(n),
        10 => DataType::I64,
        _ => DataType::U64,
    }
}
