//! The compile-time builder of a [`PackedTable`](super::PackedTable): the
//! string table, the shared range and default tables and the records, from a
//! `const` slice of [`EntryInfo`]; [`packed_table!`](crate::packed_table) calls
//! these in order. Each check is an `assert!` in compile-time evaluation: a
//! declaration that does not fit the packed form does not compile.

use super::record::{
    kind_of, type_code, ACCESS_MASK, MAX_DETAILS, MAX_KINDS, MAX_NAME, MAX_STRINGS, NO_DEFAULT,
    PLACEHOLDER_KIND,
};
use super::{narrow, PackedEntry, NO_RANGE, UNIT_NAMES as UNITS};
use crate::EntryInfo;

const fn str_eq(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        // i < a.len() = b.len() (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

const fn opt_eq(a: Option<i64>, b: Option<i64>) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => a == b,
        (None, None) => true,
        _ => false,
    }
}

/// The same entry (every field)? For de-duplicating lists at compile time.
pub const fn same_entry(a: &EntryInfo, b: &EntryInfo) -> bool {
    let (ka, kb) = (type_code(a.data_type), type_code(b.data_type));
    a.sub == b.sub
        && ka.0 == kb.0
        && ka.1 == kb.1
        && a.access.0 == b.access.0
        && opt_eq(a.min, b.min)
        && opt_eq(a.max, b.max)
        && a.default == b.default
        && a.persistent == b.persistent
        && str_eq(a.name, b.name)
        && str_eq(a.unit, b.unit)
}

/// The same entries, in the same order?
pub const fn same_entries(a: &[EntryInfo], b: &[EntryInfo]) -> bool {
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        // i < a.len() = b.len() (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if !same_entry(&a[i], &b[i]) {
            return false;
        }
        i += 1;
    }
    true
}

/// Position of the first entry before `i` with the name of entry `i`.
const fn first_name(es: &[EntryInfo], i: usize) -> usize {
    let mut j = 0;
    while j < i {
        // j < i < es.len() (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if str_eq(es[j].name, es[i].name) {
            return j;
        }
        j += 1;
    }
    i
}

/// Is `extra[k]` neither an entry name of `es` nor an earlier extra?
const fn extra_is_new(es: &[EntryInfo], extra: &[&str], k: usize) -> bool {
    let mut i = 0;
    while i < es.len() {
        // i < es.len() (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if str_eq(es[i].name, extra[k]) {
            return false;
        }
        i += 1;
    }
    let mut j = 0;
    while j < k {
        // j < k < extra.len() (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if str_eq(extra[j], extra[k]) {
            return false;
        }
        j += 1;
    }
    true
}

/// Is `needle` the part of `hay` from byte `at` on, up to its length?
const fn is_at(hay: &[u8], needle: &[u8], at: usize) -> bool {
    if at + needle.len() > hay.len() {
        return false;
    }
    let mut k = 0;
    while k < needle.len() {
        // at + k < hay.len(), k < needle.len() (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if hay[at + k] != needle[k] {
            return false;
        }
        k += 1;
    }
    true
}

/// Where `needle` is in `hay` when it is its beginning or its end.
const fn find_in(hay: &str, needle: &str) -> Option<usize> {
    let (h, n) = (hay.as_bytes(), needle.as_bytes());
    if n.len() > h.len() {
        None
    } else if is_at(h, n, 0) {
        Some(0)
    } else if is_at(h, n, h.len() - n.len()) {
        Some(h.len() - n.len())
    } else {
        None
    }
}

/// Where `needle` is in `hay`, anywhere.
const fn position_in(hay: &str, needle: &str) -> Option<usize> {
    let (h, n) = (hay.as_bytes(), needle.as_bytes());
    let mut at = 0;
    while at + n.len() <= h.len() {
        if is_at(h, n, at) {
            return Some(at);
        }
        at += 1;
    }
    None
}

/// Where the names of `es` are in the string table: a name that begins or
/// ends a longer name (e.g. "Application object 1" of "Application object
/// 10") points into it; the others ("stored") follow each other in entry order.
/// Computed once per table ([`packed_table!`](crate::packed_table)).
pub struct NameLayout<const N: usize> {
    /// Offset of each entry's name.
    offsets: [u16; N],
    /// Is entry `i` the one whose name is laid out?
    stored: [bool; N],
    /// Bytes of the stored names.
    bytes: usize,
}

/// The [`NameLayout`] of `es`. `N` = `es.len()`.
pub const fn name_layout<const N: usize>(es: &[EntryInfo]) -> NameLayout<N> {
    assert!(N == es.len(), "entry count");
    let mut first = [0usize; N];
    let mut i = 0;
    while i < N {
        // i < N = es.len() (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            first[i] = first_name(es, i);
        }
        i += 1;
    }
    // stored: the first entry of a name that no longer name contains
    let mut stored = [false; N];
    let mut i = 0;
    while i < N {
        // i, j < N = es.len() (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if first[i] == i {
            let mut inside = false;
            let mut j = 0;
            while j < N && !inside {
                let (a, b) = (es[i].name, es[j].name);
                inside = first[j] == j && b.len() > a.len() && find_in(b, a).is_some();
                j += 1;
            }
            stored[i] = !inside;
        }
        i += 1;
    }
    let mut offsets = [0u16; N];
    let mut at = 0usize;
    let mut i = 0;
    while i < N {
        // i < N (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if stored[i] {
            offsets[i] = at as u16;
            at += es[i].name.len();
        }
        i += 1;
    }
    // the other names: in a stored one (a chain of containing names ends
    // at a stored one), or the same as an earlier entry's
    let mut i = 0;
    while i < N {
        // i, j, first[i] < N (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if first[i] == i && !stored[i] {
            let mut found = false;
            let mut j = 0;
            while j < N && !found {
                if stored[j] {
                    if let Some(p) = position_in(es[j].name, es[i].name) {
                        offsets[i] = offsets[j] + p as u16;
                        found = true;
                    }
                }
                j += 1;
            }
            assert!(found, "a contained name is in a stored one");
        } else if first[i] != i {
            offsets[i] = offsets[first[i]];
        }
        i += 1;
    }
    NameLayout {
        offsets,
        stored,
        bytes: at,
    }
}

/// Bytes of the names of `es` (laid out by [`NameLayout`]) and the strings
/// `extra` (e.g. object names, each once). `N` = `es.len()`.
pub const fn string_bytes<const N: usize>(layout: &NameLayout<N>, es: &[EntryInfo], extra: &[&str]) -> usize {
    let mut n = layout.bytes;
    let mut k = 0;
    while k < extra.len() {
        if extra_is_new(es, extra, k) {
            // k < extra.len() (compile-time evaluation)
            #[allow(clippy::indexing_slicing)]
            {
                n += extra[k].len();
            }
        }
        k += 1;
    }
    assert!(n <= MAX_STRINGS, "packed names exceed 16 KiB");
    n
}

const fn put(out: &mut [u8], at: usize, s: &str) -> usize {
    let b = s.as_bytes();
    let mut k = 0;
    while k < b.len() {
        // at + k < out.len() by [`string_bytes`] (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            out[at + k] = b[k];
        }
        k += 1;
    }
    at + b.len()
}

/// The string table of `es` and `extra`: the entry names laid out by
/// [`NameLayout`], then each new extra string once. `N` = `es.len()`, `S` =
/// [`string_bytes`].
pub const fn strings<const N: usize, const S: usize>(
    layout: &NameLayout<N>,
    es: &[EntryInfo],
    extra: &[&str],
) -> [u8; S] {
    let mut out = [0u8; S];
    let mut at = 0usize;
    let mut i = 0;
    while i < N {
        // i < N = es.len() (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if layout.stored[i] {
            at = put(&mut out, at, es[i].name);
        }
        i += 1;
    }
    let mut k = 0;
    while k < extra.len() {
        if extra_is_new(es, extra, k) {
            // k < extra.len() (compile-time evaluation)
            #[allow(clippy::indexing_slicing)]
            {
                at = put(&mut out, at, extra[k]);
            }
        }
        k += 1;
    }
    assert!(at == S, "string table size");
    out
}

/// Offsets in the string table of `es` and `extra` ([`strings`]) of the
/// strings `extra`. `N` = `es.len()`, `K` = `extra.len()`.
pub const fn extra_offsets<const N: usize, const K: usize>(es: &[EntryInfo], extra: &[&str]) -> [u16; K] {
    let layout = name_layout::<N>(es);
    let names = layout.offsets;
    let mut at = layout.bytes;
    let mut out = [0u16; K];
    let mut k = 0;
    while k < K {
        // k < K = extra.len(), i < N, j < k (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        let s = extra[k];
        let mut found = false;
        let mut i = 0;
        while i < N && !found {
            #[allow(clippy::indexing_slicing)]
            if str_eq(es[i].name, s) {
                out[k] = names[i];
                found = true;
            }
            i += 1;
        }
        let mut j = 0;
        while j < k && !found {
            #[allow(clippy::indexing_slicing)]
            if str_eq(extra[j], s) {
                out[k] = out[j];
                found = true;
            }
            j += 1;
        }
        if !found {
            #[allow(clippy::indexing_slicing)]
            {
                out[k] = at as u16;
            }
            at += s.len();
        }
        k += 1;
    }
    out
}

/// The `len` bytes at `at` of the string table `table` (compile-time
/// evaluation; "" when that is not a string).
pub const fn str_at(table: &'static str, at: u16, len: usize) -> &'static str {
    let t = table.as_bytes();
    if at as usize + len > t.len() {
        return "";
    }
    let (_, rest) = t.split_at(at as usize);
    let (s, _) = rest.split_at(len);
    match core::str::from_utf8(s) {
        Ok(s) => s,
        Err(_) => "",
    }
}

const fn range_of(e: &EntryInfo) -> Option<[u32; 2]> {
    assert!(
        e.min.is_some() == e.max.is_some(),
        "a packed entry has both range ends or none"
    );
    match (e.min, e.max) {
        (Some(lo), Some(hi)) => Some([narrow(e.data_type, lo), narrow(e.data_type, hi)]),
        _ => None,
    }
}

const fn position_range(table: &[[u32; 2]], n: usize, r: [u32; 2]) -> usize {
    let mut j = 0;
    while j < n {
        // j < n <= table.len() (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if table[j][0] == r[0] && table[j][1] == r[1] {
            return j;
        }
        j += 1;
    }
    n
}

const fn position_value(table: &[u32], n: usize, v: u32) -> usize {
    let mut j = 0;
    while j < n {
        // j < n <= table.len() (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if table[j] == v {
            return j;
        }
        j += 1;
    }
    n
}

/// Distinct ranges of `es` (at most `MAX`), and how many.
const fn collect_ranges<const MAX: usize>(es: &[EntryInfo]) -> ([[u32; 2]; MAX], usize) {
    let mut out = [[0u32; 2]; MAX];
    let mut n = 0;
    let mut i = 0;
    while i < es.len() {
        // i < es.len(), n < MAX (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if let Some(r) = range_of(&es[i]) {
            if position_range(&out, n, r) == n {
                out[n] = r;
                n += 1;
            }
        }
        i += 1;
    }
    (out, n)
}

/// Does a 32-bit table value go into the 16-bit defaults?
const fn small(v: u32) -> bool {
    v <= u16::MAX as u32
}

/// Distinct defaults of `es` (at most `MAX`) that are `wide` (else those that
/// fit 16 bits), and how many.
const fn collect_defaults<const MAX: usize>(es: &[EntryInfo], wide: bool) -> ([u32; MAX], usize) {
    let mut out = [0u32; MAX];
    let mut n = 0;
    let mut i = 0;
    while i < es.len() {
        // i < es.len(), n < MAX (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        let v = narrow(es[i].data_type, es[i].default);
        if small(v) != wide && position_value(&out, n, v) == n {
            #[allow(clippy::indexing_slicing)]
            {
                out[n] = v;
            }
            n += 1;
        }
        i += 1;
    }
    (out, n)
}

/// Number of distinct ranges of `es` (`MAX`: an upper bound, e.g. `es.len()`).
pub const fn range_count<const MAX: usize>(es: &[EntryInfo]) -> usize {
    collect_ranges::<MAX>(es).1
}

/// The distinct ranges of `es`. `R` = [`range_count`].
pub const fn ranges<const MAX: usize, const R: usize>(es: &[EntryInfo]) -> [[u32; 2]; R] {
    let (all, n) = collect_ranges::<MAX>(es);
    assert!(n == R && R < NO_RANGE as usize, "range count");
    first(&all, [0u32; 2])
}

/// Number of distinct defaults of `es` that are `wide` (32 bits), else of
/// those that fit 16 bits (`MAX`: an upper bound).
pub const fn default_count<const MAX: usize>(es: &[EntryInfo], wide: bool) -> usize {
    collect_defaults::<MAX>(es, wide).1
}

/// The distinct defaults of `es` that fit 16 bits. `D` = [`default_count`].
pub const fn small_defaults<const MAX: usize, const D: usize>(es: &[EntryInfo]) -> [u16; D] {
    let (all, n) = collect_defaults::<MAX>(es, false);
    assert!(n == D, "default count");
    let mut out = [0u16; D];
    let mut i = 0;
    while i < D {
        // i < D <= MAX (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            out[i] = all[i] as u16;
        }
        i += 1;
    }
    out
}

/// The first `N` of `all` (`N ≤ MAX`; evaluated at compile time, where an
/// index past `MAX` stops the build).
const fn first<T: Copy, const MAX: usize, const N: usize>(all: &[T; MAX], zero: T) -> [T; N] {
    let mut out = [zero; N];
    let mut i = 0;
    while i < N {
        // i < N <= MAX (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            out[i] = all[i];
        }
        i += 1;
    }
    out
}

/// The distinct defaults of `es` that need 32 bits. `D` = [`default_count`].
pub const fn wide_defaults<const MAX: usize, const D: usize>(es: &[EntryInfo]) -> [u32; D] {
    let (all, n) = collect_defaults::<MAX>(es, true);
    assert!(n == D, "default count");
    first(&all, 0u32)
}

const fn unit_index(unit: &str) -> u32 {
    let mut i = 0;
    // i < UNITS.len() (compile-time evaluation)
    #[allow(clippy::indexing_slicing)]
    while i < UNITS.len() && !str_eq(UNITS[i], unit) {
        i += 1;
    }
    assert!(
        i < UNITS.len(),
        "a packed entry's unit must be in od::packed::UNIT_NAMES"
    );
    i as u32
}

/// Position of `v` in `table[from..n]` (`n` when it is not there).
const fn position_u16(table: &[u16], from: usize, n: usize, v: u16) -> usize {
    let mut j = from;
    while j < n {
        // j < n <= table.len() (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if table[j] == v {
            return j;
        }
        j += 1;
    }
    n
}

/// The details of `es` (at most `MAX`): read-only first, the other distinct
/// accesses, then the distinct string lengths; how many, and how many
/// accesses.
const fn collect_details<const MAX: usize>(es: &[EntryInfo]) -> ([u16; MAX], usize, usize) {
    let mut out = [0u16; MAX];
    out[0] = crate::Access::READ;
    let mut n = 1;
    let mut i = 0;
    while i < es.len() {
        // i < es.len(), n < MAX (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        let a = es[i].access.0;
        assert!(a & !ACCESS_MASK == 0, "access bits 0..9");
        if position_u16(&out, 0, n, a) == n {
            assert!(n < MAX, "detail table size");
            #[allow(clippy::indexing_slicing)]
            {
                out[n] = a;
            }
            n += 1;
        }
        i += 1;
    }
    let accesses = n;
    let mut i = 0;
    while i < es.len() {
        // i < es.len(), n < MAX (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        let t = es[i].data_type;
        if t.is_string() {
            let len = type_code(t).1;
            if position_u16(&out, accesses, n, len) == n {
                assert!(n < MAX, "detail table size");
                #[allow(clippy::indexing_slicing)]
                {
                    out[n] = len;
                }
                n += 1;
            }
        }
        i += 1;
    }
    assert!(
        n < NO_DEFAULT as usize,
        "at most 254 distinct accesses and string lengths"
    );
    (out, n, accesses)
}

/// Number of details of `es` (`MAX`: an upper bound, e.g. `2 * es.len() + 1`).
pub const fn detail_count<const MAX: usize>(es: &[EntryInfo]) -> usize {
    collect_details::<MAX>(es).1
}

/// Number of accesses among the details of `es` (`MAX` as for
/// [`detail_count`]).
pub const fn access_count<const MAX: usize>(es: &[EntryInfo]) -> usize {
    collect_details::<MAX>(es).2
}

/// The details of `es`. `X` = [`detail_count`].
pub const fn details<const MAX: usize, const X: usize>(es: &[EntryInfo]) -> [u16; X] {
    let (all, n, _) = collect_details::<MAX>(es);
    assert!(n == X, "detail count");
    first(&all, 0u16)
}

/// The kind of `e` against the details `details` of which the first
/// `accesses` are accesses.
const fn entry_kind(e: &EntryInfo, details: &[u16], accesses: usize) -> u16 {
    let access_at = position_u16(details, 0, accesses, e.access.0);
    assert!(access_at < accesses, "access in the details");
    kind_of(access_at, e.persistent, e.data_type, unit_index(e.unit) as usize)
}

/// Position of the string length of `e` (a string) in the details.
const fn length_at(e: &EntryInfo, details: &[u16], accesses: usize) -> usize {
    let (_, len) = type_code(e.data_type);
    let at = position_u16(details, accesses, details.len(), len);
    assert!(at < details.len(), "string length in the details");
    at
}

/// Distinct kinds of `es`, [`PLACEHOLDER_KIND`] first (at most `MAX`), and how many.
const fn collect_kinds<const MAX: usize>(
    es: &[EntryInfo],
    details: &[u16],
    accesses: usize,
) -> ([u16; MAX], usize) {
    let mut out = [0u16; MAX];
    out[0] = PLACEHOLDER_KIND;
    let mut n = 1;
    let mut i = 0;
    while i < es.len() {
        // i < es.len(), n < MAX (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        let k = entry_kind(&es[i], details, accesses);
        if position_u16(&out, 0, n, k) == n {
            assert!(n < MAX, "kind table size");
            #[allow(clippy::indexing_slicing)]
            {
                out[n] = k;
            }
            n += 1;
        }
        i += 1;
    }
    (out, n)
}

/// Number of distinct kinds of `es` with the placeholder kind (`MAX`: an
/// upper bound, e.g. `es.len() + 1`).
pub const fn kind_count<const MAX: usize>(es: &[EntryInfo], details: &[u16], accesses: usize) -> usize {
    collect_kinds::<MAX>(es, details, accesses).1
}

/// The distinct kinds of `es`, `PLACEHOLDER_KIND` first. `K` = [`kind_count`].
pub const fn kinds<const MAX: usize, const K: usize>(
    es: &[EntryInfo],
    details: &[u16],
    accesses: usize,
) -> [u16; K] {
    let (all, n) = collect_kinds::<MAX>(es, details, accesses);
    assert!(n == K && K <= MAX_KINDS, "at most 128 distinct kinds");
    first(&all, 0u16)
}

/// The records of `es` against the tables built from the same `es`.
pub const fn entries<const N: usize>(
    layout: &NameLayout<N>,
    es: &[EntryInfo],
    kinds: &[u16],
    details: (&[u16], usize),
    ranges: &[[u32; 2]],
    defaults: (&[u16], &[u32]),
) -> [PackedEntry; N] {
    assert!(N == es.len(), "entry count");
    assert!(UNITS.len() <= MAX_DETAILS, "5-bit unit index");
    assert!(ranges.len() < NO_RANGE as usize, "at most 31 distinct ranges");
    assert!(
        defaults.0.len() + defaults.1.len() < NO_DEFAULT as usize,
        "at most 255 distinct defaults"
    );
    let names = layout.offsets;
    let mut out = [PackedEntry::UNUSED; N];
    let mut i = 0;
    while i < N {
        // i < N = es.len() (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        let e = &es[i];
        assert!(e.name.len() <= MAX_NAME, "a packed name has at most 63 bytes");
        let kind = position_u16(kinds, 0, kinds.len(), entry_kind(e, details.0, details.1));
        assert!(kind < kinds.len(), "kind in the table");
        let range = match range_of(e) {
            Some(r) => position_range(ranges, ranges.len(), r) as u16,
            None => NO_RANGE,
        };
        // strings: the default index is the position of the length
        let default = if e.data_type.is_string() {
            assert!(e.default == 0, "a packed string's default is 0");
            length_at(e, details.0, details.1)
        } else {
            let v = narrow(e.data_type, e.default);
            let (s16, s32) = defaults;
            if small(v) {
                position_u16(s16, 0, s16.len(), v as u16)
            } else {
                let at = position_value(s32, s32.len(), v);
                if at < s32.len() {
                    s16.len() + at
                } else {
                    usize::MAX
                }
            }
        };
        assert!(
            e.data_type.is_string() || default < defaults.0.len() + defaults.1.len(),
            "default in the table"
        );
        #[allow(clippy::indexing_slicing)]
        {
            out[i] = PackedEntry::new(
                names[i],
                e.name.len() as u16,
                e.sub,
                kind as u16,
                range,
                default as u16,
            );
        }
        i += 1;
    }
    out
}
