//! The 6-byte record of a packed entry and the 32-bit "kind" it points to
//! (data type with its string length, access bits, persistence, unit): the
//! bit layout, shared by the builder and the decoder.
//!
//! A record is 48 bits, from bit 0: name offset in the string table (14),
//! name length (6), subindex (8), kind index (7), range index (5, all ones:
//! none), default index (8, all ones: none = 0; strings, whose default is 0:
//! the position of the length in the details). A kind is 16 bits: position of
//! the access in the table's "details" (4), persistent (1), type (4), unit
//! index (5); the details are 16-bit values, the distinct accesses, then the
//! distinct string lengths.

use crate::DataType;

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

const ACCESS_BITS: u32 = 4;
const PERSISTENT: u16 = 1 << ACCESS_BITS;
const TYPE_SHIFT: u32 = ACCESS_BITS + 1;
const DETAIL_SHIFT: u32 = TYPE_SHIFT + 4;
const DETAIL_BITS: u32 = 5;
/// Most accesses a table can have (kind field).
pub(super) const MAX_ACCESSES: usize = 1 << ACCESS_BITS;
/// Most units (kind field).
pub(super) const MAX_DETAILS: usize = 1 << DETAIL_BITS;
/// Access bits.
pub(super) const ACCESS_MASK: u16 = (1 << 10) - 1;

/// The kind of an entry: the position of its access in the table's
/// "details", persistence, type code and unit index.
pub(super) const fn kind_of(access_at: usize, persistent: bool, t: DataType, detail: usize) -> u16 {
    assert!(access_at < MAX_ACCESSES, "at most 16 distinct accesses");
    assert!(detail < MAX_DETAILS, "at most 32 units");
    access_at as u16
        | if persistent { PERSISTENT } else { 0 }
        | type_code(t).0 << TYPE_SHIFT
        | (detail as u16) << DETAIL_SHIFT
}

/// Kind 0 of every table (and of [`PackedEntry::UNUSED`]): the table's
/// first access (read-only, [`super::build`] puts it there), UNSIGNED8, no
/// unit.
pub(super) const PLACEHOLDER_KIND: u16 = kind_of(0, false, DataType::U8, 0);

/// Position of the access of a kind in the details.
pub(super) const fn access_at(kind: u16) -> usize {
    (kind & (PERSISTENT - 1)) as usize
}

/// Persistent kind?
pub(super) const fn persistent_of(kind: u16) -> bool {
    kind & PERSISTENT != 0
}

/// The unit index of a kind.
pub(super) const fn detail_of(kind: u16) -> usize {
    ((kind >> DETAIL_SHIFT) as usize) & (MAX_DETAILS - 1)
}

/// Is the kind a string type's (the record's default index is then the
/// position of the length in the details)?
pub(super) const fn is_string(kind: u16) -> bool {
    matches!((kind >> TYPE_SHIFT) & 0xF, 8 | 9)
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

/// Data type of a kind with the string length `n` (strings).
pub(super) const fn type_of(kind: u16, n: u16) -> DataType {
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
