//! The declaration packed: every distinct entry list of [`super::TABLE`]
//! once, one after the other, in [`ENTRY_TABLE`] (6-byte records, one string
//! table, shared kind, range and default tables, `od::packed`), and the
//! objects pointing into it. Axis-B copies and repeated lists (e.g. the PDO
//! mapping objects) share the records of their first occurrence. The
//! "EtherCAT Rx" view of a manufacturer array ([`RxView::Elements`]) shares
//! its SDO Info view's records (elements 1…, renumbered from 0); a mirror's
//! view ([`RxView::ElementsNoDefaults`]) is a list of its own.

use super::{declared, rx_entry, Object, RxView, COUNT, TABLE};
use od::packed::{same_entries, same_entry};
use od::{Access, DataType, EntryInfo, ObjectInfo, PackedEntry, PackedRef, PackedTable, SdoAbort};

/// The SDO Info entries of object `i`.
const fn info(objs: &[Object], i: usize) -> &'static [EntryInfo] {
    // i < objs.len() (compile-time evaluation)
    #[allow(clippy::indexing_slicing)]
    let o = &objs[i];
    declared(o.info.entries)
}

/// The "EtherCAT Rx" view of object `i` when it is a list of its own.
const fn own_rx(objs: &[Object], i: usize) -> Option<(&'static [EntryInfo], RxView)> {
    // i < objs.len() (compile-time evaluation)
    #[allow(clippy::indexing_slicing)]
    match objs[i].rx {
        RxView::ElementsNoDefaults => Some((info(objs, i), RxView::ElementsNoDefaults)),
        _ => None,
    }
}

/// The same own "EtherCAT Rx" views?
const fn same_rx(a: (&[EntryInfo], RxView), b: (&[EntryInfo], RxView)) -> bool {
    if a.0.len() != b.0.len() || a.0.is_empty() {
        return false;
    }
    let mut k = 0;
    while k + 1 < a.0.len() {
        if !same_entry(&rx_entry(a.0, a.1, k), &rx_entry(b.0, b.1, k)) {
            return false;
        }
        k += 1;
    }
    true
}

/// Where object `i`'s SDO Info list (`rx` false) or own Rx view (`rx` true)
/// starts among the lists laid out before it, if it is there.
const fn earlier(objs: &[Object], starts: &[Starts; COUNT], i: usize, rx: bool) -> Option<Starts> {
    let mut j = 0;
    while j < i {
        // j < i < COUNT (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        let s = starts[j];
        if !rx && same_entries(info(objs, j), info(objs, i)) {
            return Some(s);
        }
        if rx {
            if let (Some(a), Some(b)) = (own_rx(objs, j), own_rx(objs, i)) {
                if same_rx(a, b) {
                    return Some(s);
                }
            }
        }
        j += 1;
    }
    None
}

/// Where the entries after the first of object `i`'s SDO Info list are
/// among the lists laid out before it, if they are there (lists that differ
/// in sub 0 only, e.g. the RxPDO and TxPDO mapping objects).
const fn earlier_rest(objs: &[Object], starts: &[Starts; COUNT], i: usize) -> Option<u16> {
    let mine = info(objs, i);
    let Some((_, rest)) = mine.split_first() else {
        return None;
    };
    if rest.is_empty() {
        return None;
    }
    let mut j = 0;
    while j < i {
        if let Some((_, theirs)) = info(objs, j).split_first() {
            // j < i < COUNT (compile-time evaluation)
            #[allow(clippy::indexing_slicing)]
            if same_entries(theirs, rest) {
                return Some(starts[j].info[1]);
            }
        }
        j += 1;
    }
    None
}

/// Where an object's lists are in the packed table: its SDO Info list (the
/// record of position 0, the records from position 1 on, see
/// `PackedTable::joined`) and its own Rx view (a plain run).
#[derive(Clone, Copy)]
struct Starts {
    info: [u16; 2],
    rx: u16,
}

/// Where each object's lists are in the packed table, and its length.
const fn layout(objs: &[Object]) -> ([Starts; COUNT], usize) {
    let mut starts = [Starts { info: [0, 1], rx: 0 }; COUNT];
    let mut total = 0usize;
    let mut i = 0;
    while i < COUNT {
        let n = info(objs, i).len();
        let info_at = match earlier(objs, &starts, i, false) {
            Some(s) => s.info,
            None => match earlier_rest(objs, &starts, i) {
                // a record of its own for position 0
                Some(rest) => {
                    total += 1;
                    [(total - 1) as u16, rest]
                }
                None => {
                    total += n;
                    [(total - n) as u16, (total - n + 1) as u16]
                }
            },
        };
        // i < COUNT (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            starts[i].info = info_at;
        }
        if own_rx(objs, i).is_some() {
            assert!(n > 0, "an array has sub 0");
            let sb = match earlier(objs, &starts, i, true) {
                Some(s) => s.rx,
                None => {
                    total += n - 1;
                    (total - (n - 1)) as u16
                }
            };
            #[allow(clippy::indexing_slicing)]
            {
                starts[i].rx = sb;
            }
        }
        i += 1;
    }
    assert!(total < u16::MAX as usize, "packed entry positions are u16");
    (starts, total)
}

const LAYOUT: ([Starts; COUNT], usize) = layout(&TABLE);
/// Entries in the packed table.
const ENTRY_COUNT: usize = LAYOUT.1;

/// The distinct lists, one after the other.
#[allow(clippy::large_const_arrays)]
const FLAT: [EntryInfo; ENTRY_COUNT] = {
    let (starts, _) = LAYOUT;
    let mut out = [super::count_entry(0); ENTRY_COUNT];
    let mut i = 0;
    while i < COUNT {
        let list = info(&TABLE, i);
        // i < COUNT; the positions < ENTRY_COUNT by the layout (compile-time
        // evaluation; shared records are written again with the same entry)
        #[allow(clippy::indexing_slicing)]
        let [first, rest] = starts[i].info;
        let mut k = 0;
        while k < list.len() {
            let at = if k == 0 {
                first as usize
            } else {
                rest as usize + k - 1
            };
            #[allow(clippy::indexing_slicing)]
            {
                out[at] = list[k];
            }
            k += 1;
        }
        if let Some((list, rx)) = own_rx(&TABLE, i) {
            #[allow(clippy::indexing_slicing)]
            let at = starts[i].rx as usize;
            let mut k = 0;
            while k + 1 < list.len() {
                #[allow(clippy::indexing_slicing)]
                {
                    out[at + k] = rx_entry(list, rx, k);
                }
                k += 1;
            }
        }
        i += 1;
    }
    out
};

od::packed_table!(
    /// The entries of every object of the drive (both templates), packed.
    pub static ENTRY_TABLE = &FLAT;
);

/// A record of [`ENTRY_TABLE`] in 4 bytes (the table is implied): what the
/// declaration says of one entry, read without decoding it (the process
/// images keep one per mapped entry).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EntryRecord(&'static PackedEntry);

impl EntryRecord {
    /// No entry: subindex 0, UNSIGNED8, read-only, default 0 (placeholder in
    /// fixed-size tables).
    pub const UNUSED: Self = Self(&PackedEntry::UNUSED);

    /// The record of `r`, a record of [`ENTRY_TABLE`] (the objects' entries
    /// are).
    pub const fn of(r: PackedRef) -> Self {
        Self(r.entry())
    }

    /// Subindex.
    pub const fn sub(&self) -> u8 {
        self.0.sub()
    }

    /// Data type.
    pub fn data_type(&self) -> DataType {
        ENTRY_TABLE.data_type(self.0)
    }

    /// Access rights.
    pub fn access(&self) -> Access {
        ENTRY_TABLE.access(self.0)
    }

    /// Saved by "save values"?
    pub fn persistent(&self) -> bool {
        ENTRY_TABLE.persistent(self.0)
    }

    /// The declared default.
    pub fn default_value(&self) -> i64 {
        ENTRY_TABLE.default_of(self.0)
    }

    /// [`EntryInfo::check_range`] of the entry.
    pub fn check_range(&self, value: i64) -> Result<(), SdoAbort> {
        ENTRY_TABLE.check_range(self.0, value)
    }
}

/// Number of objects with an "EtherCAT Rx" view of their own.
const RX_COUNT: usize = {
    let mut n = 0;
    let mut i = 0;
    while i < COUNT {
        // i < COUNT (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if TABLE[i].has_rx_view() {
            n += 1;
        }
        i += 1;
    }
    n
};

/// The "EtherCAT Rx" views, in object order (sorted by index).
static RX_VIEWS: [ObjectInfo; RX_COUNT] = {
    let (starts, _) = LAYOUT;
    let table: &'static PackedTable = &ENTRY_TABLE;
    let mut out = [TABLE[0].info; RX_COUNT];
    let (mut i, mut k) = (0, 0);
    while i < COUNT {
        let n = info(&TABLE, i).len() as u16;
        // i < COUNT, k < RX_COUNT (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        let entries = match TABLE[i].rx {
            RxView::Same => None,
            // elements 1… of the SDO Info list at subindex - 1
            RxView::Elements => Some(table.renumbered(starts[i].info[1], n - 1, 1)),
            RxView::ElementsNoDefaults => Some(table.list(starts[i].rx, n - 1)),
        };
        if let Some(entries) = entries {
            #[allow(clippy::indexing_slicing)]
            {
                out[k] = ObjectInfo {
                    entries,
                    ..TABLE[i].info
                };
            }
            k += 1;
        }
        i += 1;
    }
    out
};

/// The "EtherCAT Rx" view of the object at `index`, if it has one.
pub(super) fn rx_view(index: u16) -> Option<&'static ObjectInfo> {
    let i = RX_VIEWS.binary_search_by_key(&index, |v| v.index).ok()?;
    RX_VIEWS.get(i)
}

/// The objects of `objs` with their entries in `table` (laid out by
/// [`layout`]).
pub(super) const fn objects(objs: &[Object; COUNT], table: &'static PackedTable) -> [Object; COUNT] {
    let (starts, _) = LAYOUT;
    let mut out = *objs;
    let mut i = 0;
    while i < COUNT {
        let n = info(objs, i).len() as u16;
        // i < COUNT (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            out[i].info.entries = table.joined(starts[i].info[0], starts[i].info[1], n);
        }
        i += 1;
    }
    out
}

/// The object at `index` as [`super::OBJECTS`] holds it (its entries in
/// `table`, [`ENTRY_TABLE`]): for declarations built from the double-axis
/// one (the single-axis device's objects, `super::single`), which then
/// share its packed records. Compile-time evaluation; `index` must be
/// declared.
pub(super) const fn packed_object(table: &'static PackedTable, index: u16) -> Object {
    let (starts, _) = LAYOUT;
    let mut i = 0;
    // i < COUNT (compile-time evaluation)
    #[allow(clippy::indexing_slicing)]
    while i < COUNT && TABLE[i].info.index != index {
        i += 1;
    }
    assert!(i < COUNT, "packed_object: no such object");
    let n = info(&TABLE, i).len() as u16;
    // i < COUNT (compile-time evaluation)
    #[allow(clippy::indexing_slicing)]
    let mut o = TABLE[i];
    #[allow(clippy::indexing_slicing)]
    {
        o.info.entries = table.joined(starts[i].info[0], starts[i].info[1], n);
    }
    o
}
