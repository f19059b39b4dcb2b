//! The compact form of entry metadata: 6-byte [`PackedEntry`] records
//! pointing into one string table (a name that begins or ends a longer one
//! points into it), a table of 16-bit kinds (type, access, persistence, unit)
//! with their 16-bit details (the distinct accesses and string lengths),
//! shared range (32-bit) and default (16-bit, 32-bit) tables and the unit table
//! [`UNITS`], built at compile time from a declaration of [`EntryInfo`] values
//! ([`packed_table!`](crate::packed_table)).
//!
//! [`Entries`] is the handle an [`ObjectInfo`](crate::ObjectInfo) holds: a run
//! of records in a [`PackedTable`] (optionally renumbered, see
//! [`PackedTable::renumbered`]), or a plain slice of [`EntryInfo`] (small
//! hand-made dictionaries, tests). Either way entries are read by value,
//! decoded; [`PackedRef`] reads single fields of a record without decoding.
//!
//! Constraints of the packed form (checked when the table is built, a violation
//! is a compile error): names at most 63 bytes and 16 KiB of names in all; a
//! unit from [`UNIT_NAMES`]; a range has both ends or none; ranges and defaults fit
//! 32 bits (signed types: `i32`, the others `u32`); strings have default 0;
//! per table at most 128 distinct kinds, 16 distinct accesses, 31 distinct
//! ranges and 255 distinct defaults.

use crate::{Access, DataType, EntryInfo};

mod build;
pub use build::*;

/// The units an entry of a packed table may have (index 0: none); in the
/// image as [`UNITS`].
pub const UNIT_NAMES: [&str; 30] = [
    "",
    "inc",
    "inc/s",
    "inc/s²",
    "inc/s³",
    "0.1 %",
    "0.1 %/s",
    "0.1 kW",
    "%",
    "‰",
    "rpm",
    "s",
    "ms",
    "µs",
    "ns",
    "mNm",
    "mV",
    "0.1 /s",
    "µNm·s/rad",
    "mA",
    "mNm/A",
    "µH",
    "mΩ",
    "Hz",
    "Ω",
    "V",
    "W",
    "g·cm²",
    "µNm",
    "nNm·s/rad",
];

/// Bytes of the unit names.
const UNIT_BYTES: usize = {
    let mut n = 0;
    let mut i = 0;
    while i < UNIT_NAMES.len() {
        // i < UNIT_NAMES.len() (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            n += UNIT_NAMES[i].len();
        }
        i += 1;
    }
    assert!(n <= u8::MAX as usize, "unit names in 255 bytes");
    n
};

/// [`UNIT_NAMES`] packed: the names one after the other and where each ends.
#[derive(Debug)]
pub struct Units {
    text: [u8; UNIT_BYTES],
    ends: [u8; UNIT_NAMES.len()],
}

impl Units {
    const fn new() -> Self {
        let mut out = Self {
            text: [0; UNIT_BYTES],
            ends: [0; UNIT_NAMES.len()],
        };
        let (mut at, mut i) = (0, 0);
        while i < UNIT_NAMES.len() {
            // i < UNIT_NAMES.len(), at + k < UNIT_BYTES (compile-time evaluation)
            #[allow(clippy::indexing_slicing)]
            let b = UNIT_NAMES[i].as_bytes();
            let mut k = 0;
            while k < b.len() {
                #[allow(clippy::indexing_slicing)]
                {
                    out.text[at + k] = b[k];
                }
                k += 1;
            }
            at += b.len();
            #[allow(clippy::indexing_slicing)]
            {
                out.ends[i] = at as u8;
            }
            i += 1;
        }
        out
    }

    /// Unit `i` (`None` past the last).
    pub fn get(&'static self, i: usize) -> Option<&'static str> {
        let start = match i.checked_sub(1) {
            None => 0,
            Some(j) => usize::from(*self.ends.get(j)?),
        };
        let end = usize::from(*self.ends.get(i)?);
        core::str::from_utf8(self.text.get(start..end)?).ok()
    }

    /// Number of units.
    pub const fn len(&self) -> usize {
        self.ends.len()
    }

    /// No units?
    pub const fn is_empty(&self) -> bool {
        self.ends.is_empty()
    }
}

/// The units of packed entries (index 0: none), packed.
pub static UNITS: Units = Units::new();

mod record;
pub use record::PackedEntry;
use record::{type_of, NO_RANGE};

/// A table of packed entries with its string, kind, range and default tables.
#[derive(Debug)]
pub struct PackedTable {
    entries: &'static [PackedEntry],
    strings: &'static str,
    kinds: &'static [u16],
    details: &'static [u16],
    ranges: &'static [[u32; 2]],
    defaults: Defaults,
}

/// The defaults of a table: those that fit 16 bits, then the others (one
/// index space).
#[derive(Debug)]
struct Defaults {
    small: &'static [u16],
    wide: &'static [u32],
}

impl Defaults {
    /// Number of defaults.
    #[cfg(test)]
    const fn len(&self) -> usize {
        self.small.len() + self.wide.len()
    }

    /// The default at index `i`, as a 32-bit table value.
    fn get(&self, i: usize) -> Option<u32> {
        match i.checked_sub(self.small.len()) {
            None => self.small.get(i).map(|&v| u32::from(v)),
            Some(w) => self.wide.get(w).copied(),
        }
    }
}

/// A 32-bit table value as the entry's type reads it.
const fn widen(t: DataType, raw: u32) -> i64 {
    if t.signed() {
        raw as i32 as i64
    } else {
        raw as i64
    }
}

/// `v` as a 32-bit table value of type `t`; a compile error when it does not fit.
const fn narrow(t: DataType, v: i64) -> u32 {
    if t.signed() {
        assert!(
            v >= i32::MIN as i64 && v <= i32::MAX as i64,
            "a packed range/default must fit i32"
        );
        v as i32 as u32
    } else {
        assert!(
            v >= 0 && v <= u32::MAX as i64,
            "a packed range/default must fit u32"
        );
        v as u32
    }
}

impl PackedTable {
    /// A table (used by [`packed_table!`](crate::packed_table)).
    pub const fn new(
        entries: &'static [PackedEntry],
        strings: &'static str,
        kinds: &'static [u16],
        details: &'static [u16],
        ranges: &'static [[u32; 2]],
        small_defaults: &'static [u16],
        wide_defaults: &'static [u32],
    ) -> Self {
        Self {
            entries,
            strings,
            kinds,
            details,
            ranges,
            defaults: Defaults {
                small: small_defaults,
                wide: wide_defaults,
            },
        }
    }

    /// The `len` entries from position `start`.
    pub const fn list(&'static self, start: u16, len: u16) -> Entries {
        self.renumbered(start, len, 0)
    }

    /// The `len` entries from position `start`, each at its record's
    /// subindex minus `shift` (e.g. the "EtherCAT Rx" view of a manufacturer
    /// array: the SDO Info view's elements 1… at subindices 0…). Every record
    /// of the run must have a subindex of at least `shift` (the builder's
    /// check).
    pub const fn renumbered(&'static self, start: u16, len: u16, shift: u8) -> Entries {
        Entries(Repr::Packed {
            table: self,
            first: start,
            rest: start.wrapping_add(1),
            len,
            shift,
        })
    }

    /// `len` entries: the record at position `first`, then the `len - 1`
    /// records from position `rest` (lists that differ only in their first
    /// entry, e.g. sub 0, share the others).
    pub const fn joined(&'static self, first: u16, rest: u16, len: u16) -> Entries {
        Entries(Repr::Packed {
            table: self,
            first,
            rest,
            len,
            shift: 0,
        })
    }

    /// Number of entries.
    pub const fn len(&self) -> usize {
        self.entries.len()
    }

    /// No entries?
    pub const fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The string table (entry names, then further names, each once).
    pub const fn strings(&self) -> &'static str {
        self.strings
    }

    /// Bytes of the records, strings, kinds, ranges and defaults.
    pub const fn bytes(&self) -> usize {
        core::mem::size_of_val(self.entries)
            + self.strings.len()
            + core::mem::size_of_val(self.kinds)
            + core::mem::size_of_val(self.details)
            + core::mem::size_of_val(self.ranges)
            + core::mem::size_of_val(self.defaults.small)
            + core::mem::size_of_val(self.defaults.wide)
    }

    /// The entry at position `at`, decoded.
    pub fn get(&self, at: usize) -> Option<EntryInfo> {
        self.entries.get(at).map(|p| self.decode(p))
    }

    /// The kind of a record (kind 0 when the table has no such kind).
    fn kind(&self, p: &PackedEntry) -> u16 {
        self.kinds
            .get(p.kind())
            .copied()
            .unwrap_or(record::PLACEHOLDER_KIND)
    }

    /// The data type of a record of kind `kind`.
    fn type_of(&self, p: &PackedEntry, kind: u16) -> DataType {
        let n = match record::is_string(kind) {
            true => self.details.get(p.default()).copied().unwrap_or(0),
            false => 0,
        };
        type_of(kind, n)
    }

    /// The access of a kind (read-only when the table has none).
    fn access_of(&self, kind: u16) -> Access {
        Access(
            self.details
                .get(record::access_at(kind))
                .copied()
                .unwrap_or(Access::READ),
        )
    }

    /// Data type of a record of this table.
    pub fn data_type(&self, p: &PackedEntry) -> DataType {
        self.type_of(p, self.kind(p))
    }

    /// Access rights of a record of this table.
    pub fn access(&self, p: &PackedEntry) -> Access {
        self.access_of(self.kind(p))
    }

    /// Is a record of this table saved by "save values"?
    pub fn persistent(&self, p: &PackedEntry) -> bool {
        record::persistent_of(self.kind(p))
    }

    /// The declared default of a record of this table.
    pub fn default_of(&self, p: &PackedEntry) -> i64 {
        let kind = self.kind(p);
        if record::is_string(kind) {
            return 0;
        }
        self.defaults
            .get(p.default())
            .map_or(0, |d| widen(self.type_of(p, kind), d))
    }

    /// [`EntryInfo::check_range`] of a record of this table.
    pub fn check_range(&self, p: &PackedEntry, value: i64) -> Result<(), crate::SdoAbort> {
        let t = self.data_type(p);
        let (lo, hi) = match self.ranges.get(p.range()) {
            Some(&[lo, hi]) => (widen(t, lo), widen(t, hi)),
            None => (t.min_value(), t.max_value()),
        };
        if !t.is_integer() {
            Ok(())
        } else if value < lo {
            Err(crate::SdoAbort::VALUE_TOO_LOW)
        } else if value > hi {
            Err(crate::SdoAbort::VALUE_TOO_HIGH)
        } else {
            Ok(())
        }
    }

    /// Decodes a record of this table.
    pub fn decode(&self, p: &PackedEntry) -> EntryInfo {
        let kind = self.kind(p);
        let t = self.type_of(p, kind);
        let start = p.name_at();
        let name = self.strings.get(start..start + p.name_len()).unwrap_or("");
        let (min, max) = match self.ranges.get(p.range()) {
            Some(&[lo, hi]) => (Some(widen(t, lo)), Some(widen(t, hi))),
            None => (None, None),
        };
        EntryInfo {
            sub: p.sub(),
            name,
            data_type: t,
            access: self.access_of(kind),
            min,
            max,
            default: self.default_of(p),
            unit: UNITS.get(record::detail_of(kind)).unwrap_or(""),
            persistent: record::persistent_of(kind),
        }
    }
}

/// A record with its table: what the record says, read without decoding the
/// whole entry (8 bytes, `Copy`).
#[derive(Debug, Clone, Copy)]
pub struct PackedRef {
    table: &'static PackedTable,
    record: &'static PackedEntry,
}

const EMPTY: PackedTable = PackedTable::new(&[], "", &[], &[], &[], &[], &[]);

impl PackedRef {
    /// A reference of no table: [`PackedEntry::UNUSED`] (subindex 0,
    /// UNSIGNED8, read-only, default 0; placeholder in fixed-size tables).
    pub const UNUSED: Self = Self {
        table: &EMPTY,
        record: &PackedEntry::UNUSED,
    };

    /// Subindex.
    pub const fn sub(&self) -> u8 {
        self.record.sub()
    }

    /// The record (its table's).
    pub const fn entry(&self) -> &'static PackedEntry {
        self.record
    }

    /// Data type.
    pub fn data_type(&self) -> DataType {
        self.table.data_type(self.record)
    }

    /// Access rights.
    pub fn access(&self) -> Access {
        self.table.access(self.record)
    }

    /// Saved by "save values"?
    pub fn persistent(&self) -> bool {
        self.table.persistent(self.record)
    }

    /// The declared default.
    pub fn default_value(&self) -> i64 {
        self.table.default_of(self.record)
    }

    /// [`EntryInfo::check_range`] of the entry.
    pub fn check_range(&self, value: i64) -> Result<(), crate::SdoAbort> {
        self.table.check_range(self.record, value)
    }

    /// The entry, decoded.
    pub fn decode(&self) -> EntryInfo {
        self.table.decode(self.record)
    }
}

/// Equal records (as `PackedEntry` values; the table is not compared).
impl PartialEq for PackedRef {
    fn eq(&self, other: &Self) -> bool {
        self.record == other.record
    }
}

impl Eq for PackedRef {}

/// The entries of an object: a run of a [`PackedTable`] or a slice.
#[derive(Clone, Copy)]
pub struct Entries(Repr);

#[derive(Clone, Copy)]
enum Repr {
    Slice(&'static [EntryInfo]),
    Packed {
        table: &'static PackedTable,
        /// the record of position 0
        first: u16,
        /// the record of position 1; position p > 0 is at `rest + p - 1`
        rest: u16,
        len: u16,
        /// subindex = record subindex - shift
        shift: u8,
    },
}

impl Entries {
    /// Entries given as a slice (hand-made dictionaries).
    pub const fn slice(entries: &'static [EntryInfo]) -> Self {
        Self(Repr::Slice(entries))
    }

    /// The slice, for entries given as one (compile-time evaluation).
    pub const fn as_slice(&self) -> Option<&'static [EntryInfo]> {
        match self.0 {
            Repr::Slice(s) => Some(s),
            Repr::Packed { .. } => None,
        }
    }

    /// Number of entries.
    pub const fn len(&self) -> usize {
        match self.0 {
            Repr::Slice(s) => s.len(),
            Repr::Packed { len, .. } => len as usize,
        }
    }

    /// No entries?
    pub const fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The record at position `pos`, its table and the subindex shift
    /// (packed entries).
    fn at(&self, pos: usize) -> Option<(&'static PackedTable, &'static PackedEntry, u8)> {
        match self.0 {
            Repr::Slice(_) => None,
            Repr::Packed {
                table,
                first,
                rest,
                len,
                shift,
            } if pos < usize::from(len) => {
                let at = match pos {
                    0 => usize::from(first),
                    p => usize::from(rest) + p - 1,
                };
                table.entries.get(at).map(|p| (table, p, shift))
            }
            Repr::Packed { .. } => None,
        }
    }

    /// The entry at position `pos` (not subindex), decoded.
    pub fn get(&self, pos: usize) -> Option<EntryInfo> {
        match self.0 {
            Repr::Slice(s) => s.get(pos).copied(),
            Repr::Packed { .. } => {
                let (table, p, shift) = self.at(pos)?;
                let mut e = table.decode(p);
                e.sub = e.sub.wrapping_sub(shift);
                Some(e)
            }
        }
    }

    /// The first entry (sub 0 when there is one).
    pub fn first(&self) -> Option<EntryInfo> {
        self.get(0)
    }

    /// Subindex of the entry at position `pos` (packed entries).
    fn sub_at(&self, pos: usize) -> Option<u8> {
        self.at(pos).map(|(_, p, shift)| p.sub().wrapping_sub(shift))
    }

    /// Position of the entry with subindex `sub` (without decoding).
    pub fn position(&self, sub: u8) -> Option<usize> {
        match self.0 {
            Repr::Slice(s) => s.iter().position(|e| e.sub == sub),
            Repr::Packed { len, .. } => (0..usize::from(len)).find(|&pos| self.sub_at(pos) == Some(sub)),
        }
    }

    /// Data type of the entry at position `pos` (without decoding).
    pub fn data_type(&self, pos: usize) -> Option<DataType> {
        match self.0 {
            Repr::Slice(s) => s.get(pos).map(|e| e.data_type),
            Repr::Packed { .. } => self.at(pos).map(|(table, p, _)| table.data_type(p)),
        }
    }

    /// Access rights of the entry at position `pos` (without decoding).
    pub fn access(&self, pos: usize) -> Option<Access> {
        match self.0 {
            Repr::Slice(s) => s.get(pos).map(|e| e.access),
            Repr::Packed { .. } => self.at(pos).map(|(table, p, _)| table.access(p)),
        }
    }

    /// The packed record at position `pos` with its table (`None` for slices
    /// and for runs that renumber their records, see
    /// [`PackedTable::renumbered`]: a record's subindex is its table's).
    pub fn record(&self, pos: usize) -> Option<PackedRef> {
        match self.at(pos)? {
            (table, record, 0) => Some(PackedRef { table, record }),
            _ => None,
        }
    }

    /// The entry with subindex `sub`.
    pub fn find(&self, sub: u8) -> Option<EntryInfo> {
        match self.0 {
            Repr::Slice(s) => s.iter().find(|e| e.sub == sub).copied(),
            Repr::Packed { .. } => self.get(self.position(sub)?),
        }
    }

    /// Highest subindex (0 without entries).
    pub fn max_sub(&self) -> u8 {
        match self.0 {
            Repr::Slice(s) => s.iter().map(|e| e.sub).max().unwrap_or(0),
            Repr::Packed { len, .. } => (0..usize::from(len))
                .filter_map(|pos| self.sub_at(pos))
                .max()
                .unwrap_or(0),
        }
    }

    /// The entries in order, decoded.
    pub fn iter(&self) -> Iter {
        Iter {
            entries: *self,
            front: 0,
            back: self.len(),
        }
    }
}

impl PartialEq for Entries {
    fn eq(&self, other: &Self) -> bool {
        self.len() == other.len() && self.iter().eq(other.iter())
    }
}

impl core::fmt::Debug for Entries {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

impl IntoIterator for Entries {
    type Item = EntryInfo;
    type IntoIter = Iter;
    fn into_iter(self) -> Iter {
        self.iter()
    }
}

impl IntoIterator for &Entries {
    type Item = EntryInfo;
    type IntoIter = Iter;
    fn into_iter(self) -> Iter {
        self.iter()
    }
}

/// Iterator over [`Entries`], yielding decoded entries.
#[derive(Clone)]
pub struct Iter {
    entries: Entries,
    front: usize,
    back: usize,
}

impl Iterator for Iter {
    type Item = EntryInfo;
    fn next(&mut self) -> Option<EntryInfo> {
        if self.front >= self.back {
            return None;
        }
        self.front += 1;
        self.entries.get(self.front - 1)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.back.saturating_sub(self.front);
        (n, Some(n))
    }
}

impl DoubleEndedIterator for Iter {
    fn next_back(&mut self) -> Option<EntryInfo> {
        if self.front >= self.back {
            return None;
        }
        self.back -= 1;
        self.entries.get(self.back)
    }
}

impl ExactSizeIterator for Iter {}

/// A `static` [`PackedTable`] of the entries `$entries` (a `const` slice of
/// [`EntryInfo`]): positions in the table are positions in the slice. An
/// optional `names = <const slice of &str>;` adds further strings to the
/// string table (after the entry names, each once; [`extra_offsets`] says
/// where).
///
/// The records, names, ranges and defaults become statics of their own
/// (`<NAME>_ENTRIES`, ... are not nameable; they appear in the image as
/// `…::<NAME>::ENTRIES` and so on).
#[macro_export]
macro_rules! packed_table {
    ($(#[$m:meta])* $vis:vis static $name:ident = $entries:expr;) => {
        $crate::packed_table!($(#[$m])* $vis static $name = $entries; names = &[];);
    };
    ($(#[$m:meta])* $vis:vis static $name:ident = $entries:expr; names = $names:expr;) => {
        $(#[$m])*
        #[allow(long_running_const_eval)]
        $vis static $name: $crate::PackedTable = {
            const PACKED_INPUT: &[$crate::EntryInfo] = $entries;
            #[allow(long_running_const_eval)]
            const N: usize = PACKED_INPUT.len();
            #[allow(long_running_const_eval)]
            const EXTRA: &[&str] = $names;
            #[allow(long_running_const_eval)]
            const NAME_LAYOUT: $crate::packed::NameLayout<N> = $crate::packed::name_layout::<N>(PACKED_INPUT);
            #[allow(long_running_const_eval)]
            const S: usize = $crate::packed::string_bytes::<N>(&NAME_LAYOUT, PACKED_INPUT, EXTRA);
            #[allow(long_running_const_eval)]
            const R: usize = $crate::packed::range_count::<N>(PACKED_INPUT);
            #[allow(long_running_const_eval)]
            const D16: usize = $crate::packed::default_count::<N>(PACKED_INPUT, false);
            #[allow(long_running_const_eval)]
            const D32: usize = $crate::packed::default_count::<N>(PACKED_INPUT, true);
            #[allow(long_running_const_eval)]
            const X: usize = $crate::packed::detail_count::<{ 2 * N + 1 }>(PACKED_INPUT);
            #[allow(long_running_const_eval)]
            static DETAILS: [u16; X] = $crate::packed::details::<{ 2 * N + 1 }, X>(PACKED_INPUT);
            #[allow(long_running_const_eval)]
            const A: usize = $crate::packed::access_count::<{ 2 * N + 1 }>(PACKED_INPUT);
            #[allow(long_running_const_eval)]
            const K: usize = $crate::packed::kind_count::<{ N + 1 }>(PACKED_INPUT, &DETAILS, A);
            #[allow(long_running_const_eval)]
            static ENTRIES: [$crate::PackedEntry; N] =
                $crate::packed::entries::<N>(&NAME_LAYOUT, PACKED_INPUT, &KINDS, (&DETAILS, A), &RANGES, (&SMALL_DEFAULTS, &WIDE_DEFAULTS));
            #[allow(long_running_const_eval)]
            static KINDS: [u16; K] = $crate::packed::kinds::<{ N + 1 }, K>(PACKED_INPUT, &DETAILS, A);
            #[allow(long_running_const_eval)]
            static RANGES: [[u32; 2]; R] = $crate::packed::ranges::<N, R>(PACKED_INPUT);
            #[allow(long_running_const_eval)]
            static SMALL_DEFAULTS: [u16; D16] = $crate::packed::small_defaults::<N, D16>(PACKED_INPUT);
            #[allow(long_running_const_eval)]
            static WIDE_DEFAULTS: [u32; D32] = $crate::packed::wide_defaults::<N, D32>(PACKED_INPUT);
            #[allow(long_running_const_eval)]
            static STRINGS: [u8; S] = $crate::packed::strings::<N, S>(&NAME_LAYOUT, PACKED_INPUT, EXTRA);
            #[allow(long_running_const_eval)]
            const _: () = assert!(::core::str::from_utf8(&STRINGS).is_ok(), "names are UTF-8");
            #[allow(long_running_const_eval)]
            const NAMES: &str = match ::core::str::from_utf8(&STRINGS) {
                Ok(s) => s,
                Err(_) => "",
            };
            $crate::PackedTable::new(&ENTRIES, NAMES, &KINDS, &DETAILS, &RANGES, &SMALL_DEFAULTS, &WIDE_DEFAULTS)
        };
    };
}

#[cfg(test)]
mod tests;
