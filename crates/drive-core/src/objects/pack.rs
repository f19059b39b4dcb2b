//! The declaration packed: every distinct entry list of [`super::TABLE`] (both
//! templates) once, one after the other, in [`ENTRY_TABLE`] (12-byte records,
//! one string table, shared range and default tables, `od::packed`), and the
//! objects pointing into it. Axis-B copies and repeated lists (e.g. the PDO
//! mapping objects) share the records of their first occurrence.

use super::{declared, Object, COUNT, TABLE};
use od::packed::same_entries;
use od::{EntryInfo, ObjectInfo, PackedTable};

/// The entry lists of object `i`: (SDO Info template, "EtherCAT Rx" template).
const fn lists(objs: &[Object], i: usize) -> (&'static [EntryInfo], &'static [EntryInfo]) {
    // i < objs.len() (compile-time evaluation)
    #[allow(clippy::indexing_slicing)]
    let o = &objs[i];
    let rx = match o.rx {
        Some(rx) => declared(rx.entries),
        None => &[],
    };
    (declared(o.info.entries), rx)
}

/// Where `list` starts among the lists before object `i` (and object `i`'s
/// first list when `rx`), if it is there.
const fn earlier(
    objs: &[Object],
    starts: &[[u16; 2]; COUNT],
    i: usize,
    rx: bool,
    list: &[EntryInfo],
) -> Option<u16> {
    let mut j = 0;
    while j <= i {
        let (a, b) = lists(objs, j);
        // j <= i < COUNT (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        let s = starts[j];
        if (j < i || rx) && same_entries(a, list) {
            return Some(s[0]);
        }
        if j < i && !b.is_empty() && same_entries(b, list) {
            return Some(s[1]);
        }
        j += 1;
    }
    None
}

/// Start of each object's two lists in the packed table, and its length.
const fn layout(objs: &[Object]) -> ([[u16; 2]; COUNT], usize) {
    let mut starts = [[0u16; 2]; COUNT];
    let mut total = 0usize;
    let mut i = 0;
    while i < COUNT {
        let (a, b) = lists(objs, i);
        let sa = match earlier(objs, &starts, i, false, a) {
            Some(s) => s,
            None => {
                total += a.len();
                (total - a.len()) as u16
            }
        };
        // i < COUNT (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            starts[i][0] = sa;
        }
        if !b.is_empty() {
            let sb = match earlier(objs, &starts, i, true, b) {
                Some(s) => s,
                None => {
                    total += b.len();
                    (total - b.len()) as u16
                }
            };
            #[allow(clippy::indexing_slicing)]
            {
                starts[i][1] = sb;
            }
        }
        i += 1;
    }
    assert!(total <= u16::MAX as usize, "packed entry positions are u16");
    (starts, total)
}

const LAYOUT: ([[u16; 2]; COUNT], usize) = layout(&TABLE);
/// Entries in the packed table.
const ENTRY_COUNT: usize = LAYOUT.1;

/// The distinct lists, one after the other.
#[allow(clippy::large_const_arrays)]
const FLAT: [EntryInfo; ENTRY_COUNT] = {
    let (starts, _) = LAYOUT;
    let mut out = [super::count_entry(0); ENTRY_COUNT];
    let mut i = 0;
    while i < COUNT {
        let (a, b) = lists(&TABLE, i);
        let mut v = 0;
        while v < 2 {
            let list = if v == 0 { a } else { b };
            // i < COUNT, v < 2; start + k < ENTRY_COUNT by the layout (compile-time evaluation)
            #[allow(clippy::indexing_slicing)]
            let at = starts[i][v] as usize;
            let mut k = 0;
            while k < list.len() {
                #[allow(clippy::indexing_slicing)]
                {
                    out[at + k] = list[k];
                }
                k += 1;
            }
            v += 1;
        }
        i += 1;
    }
    out
};

od::packed_table!(
    /// The entries of every object of the drive (both templates), packed.
    pub static ENTRY_TABLE = &FLAT;
);

/// Number of objects with an "EtherCAT Rx" view.
const RX_COUNT: usize = {
    let mut n = 0;
    let mut i = 0;
    while i < COUNT {
        // i < COUNT (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if TABLE[i].rx.is_some() {
            n += 1;
        }
        i += 1;
    }
    n
};

/// The "EtherCAT Rx" views, in object order, their entries in [`ENTRY_TABLE`].
pub(super) static RX_VIEWS: [ObjectInfo; RX_COUNT] = {
    let (starts, _) = LAYOUT;
    let table: &'static PackedTable = &ENTRY_TABLE;
    let mut out = [TABLE[0].info; RX_COUNT];
    let (mut i, mut k) = (0, 0);
    while i < COUNT {
        let (_, b) = lists(&TABLE, i);
        // i < COUNT, k < RX_COUNT (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if let Some(rx) = TABLE[i].rx {
            out[k] = ObjectInfo {
                index: TABLE[i].info.index,
                entries: table.list(starts[i][1], b.len() as u16),
                ..*rx
            };
            k += 1;
        }
        i += 1;
    }
    out
};

/// The objects of `objs` with their entries in `table` and their "EtherCAT
/// Rx" views in `views` (laid out by [`layout`]).
pub(super) const fn objects(
    objs: &[Object; COUNT],
    table: &'static PackedTable,
    views: &'static [ObjectInfo; RX_COUNT],
) -> [Object; COUNT] {
    let (starts, _) = LAYOUT;
    let mut out = *objs;
    let (mut i, mut k) = (0, 0);
    while i < COUNT {
        let (a, _) = lists(objs, i);
        // i < COUNT, k < RX_COUNT (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            out[i].info.entries = table.list(starts[i][0], a.len() as u16);
            if out[i].rx.is_some() {
                out[i].rx = Some(&views[k]);
                k += 1;
            }
        }
        i += 1;
    }
    out
}
