//! The single-axis device (SI6A061, [`crate::Variant::Single`]): the
//! objects it declares differently from the double-axis device. Everything
//! else is the double-axis declaration without axis B's objects
//! ([`crate::variant::is_axis_b`]); each object here is the double-axis one
//! with its packed entries (those of [`super::OBJECTS`]) and only what differs changed,
//! so the entries' subindices, names, types, access and ranges stay those
//! of the one declaration (a test checks it):
//!
//! - 1008h (E50): the device name `SI6`;
//! - 1018h: product code [`crate::PRODUCT_CODE_SINGLE`] (E-005);
//! - 1601h/1A01h and their mirrors A226/A234: channel 2 belongs to axis B
//!   on the double-axis device (E-051); here it is a free channel like
//!   channel 3, empty by default (the entries of 1602h/1A02h, A227/A235);
//! - F050h: no module on axis B, sub 2 = 0 (E-148).

use super::pack::{packed_object, ENTRY_TABLE};
use super::{count_entry, declared, Object, Value};
use od::{Entries, EntryInfo, PackedTable};

const _: () = assert!(
    crate::DEVICE_NAME_SINGLE.len() == crate::DEVICE_NAME.len(),
    "1008h and E50 keep their declared string length"
);

/// The double-axis entries `from` with the default of subindex `sub` set
/// to `value`. `N` = `from.len()`.
const fn with_default<const N: usize>(from: &[EntryInfo], sub: u8, value: i64) -> [EntryInfo; N] {
    let mut out = [count_entry(0); N];
    let mut i = 0;
    while i < N {
        // i < N = from.len() (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            out[i] = from[i];
            if from[i].sub == sub {
                out[i] = out[i].default_value(value);
            }
        }
        i += 1;
    }
    out
}

/// The declared (unpacked) entries of the double-axis object at `index`.
const fn double(index: u16) -> &'static [EntryInfo] {
    let mut rest: &[Object] = &super::TABLE;
    while let [o, tail @ ..] = rest {
        if o.info.index == index {
            return declared(o.info.entries);
        }
        rest = tail;
    }
    &[]
}

const IDENTITY: [EntryInfo; 5] = with_default(double(0x1018), 2, crate::PRODUCT_CODE_SINGLE as i64);
const MODULES: [EntryInfo; 3] = with_default(double(0xF050), 2, 0);
const _: () = assert!(
    double(0x1018).len() == IDENTITY.len() && double(0xF050).len() == MODULES.len(),
    "the single-axis identity and module list have the double-axis entries"
);

/// `o` with `entries`.
const fn entries(mut o: Object, entries: Entries) -> Object {
    o.info.entries = entries;
    o
}

/// `o` with the value `value`.
const fn value(mut o: Object, value: Value) -> Object {
    o.value = value;
    o
}

/// The objects the single-axis device declares differently, sorted by index.
pub static OBJECTS: [Object; 7] = {
    let t: &'static PackedTable = &ENTRY_TABLE;
    [
        value(packed_object(t, 0x1008), Value::Text(&crate::DEVICE_NAME_SINGLE))
            .note("E50; the single-axis device"),
        entries(packed_object(t, 0x1018), Entries::slice(&IDENTITY))
            .note("E-005; :02 = the single-axis device's product code"),
        entries(packed_object(t, 0x1601), packed_object(t, 0x1602).info.entries)
            .note("channel 2, free (no axis B); A226"),
        entries(packed_object(t, 0x1A01), packed_object(t, 0x1A02).info.entries)
            .note("channel 2, free (no axis B); A234"),
        entries(packed_object(t, 0x20E2), packed_object(t, 0x20E3).info.entries).note("A226 = 1601h"),
        entries(packed_object(t, 0x20EA), packed_object(t, 0x20EB).info.entries).note("A234 = 1A01h"),
        entries(packed_object(t, 0xF050), Entries::slice(&MODULES)).note("E-148; :02 = 0, no axis B"),
    ]
};
