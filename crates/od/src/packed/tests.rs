//! The packed tables against the entries they pack.

use super::*;
use crate::DataType::{OctetString, I16, U32, U8};

const ES: &[EntryInfo] = &[
    EntryInfo::new(0, "Highest subindex supported", U8, Access::RO).default_value(2),
    EntryInfo::new(1, "Speed", I16, Access::RW)
        .range(-100, 100)
        .default_value(-5)
        .unit("rpm")
        .saved(),
    EntryInfo::new(2, "Limit", U32, Access::RW.with(Access::RXPDO))
        .range(1, u32::MAX as i64)
        .default_value(0xFFFF_FFFF),
    EntryInfo::new(0, "Highest subindex supported", U8, Access::RO).default_value(2),
    EntryInfo::new(1, "Blob", OctetString(16), Access::RO).unit("µs"),
];
packed_table!(static TABLE = ES;);

#[test]
fn packs_and_decodes_every_field() {
    assert_eq!(core::mem::size_of::<PackedEntry>(), 6);
    assert_eq!(TABLE.len(), ES.len());
    for (i, e) in ES.iter().enumerate() {
        assert_eq!(TABLE.get(i), Some(*e), "entry {i}");
    }
    // one copy of the repeated name, one of the shared default
    assert_eq!(
        TABLE.strings.len(),
        "Highest subindex supportedSpeedLimitBlob".len()
    );
    assert_eq!(TABLE.defaults.len(), 4);
    assert_eq!(TABLE.ranges.len(), 2);
}

const NUMBERED: &[EntryInfo] = &[
    EntryInfo::new(0, "Source bit 1", U8, Access::RO),
    EntryInfo::new(1, "Source bit 10", U8, Access::RO),
    EntryInfo::new(2, "bit 10", U8, Access::RO),
    EntryInfo::new(3, "Source", U8, Access::RO),
];
packed_table!(static SHARED = NUMBERED;);

#[test]
fn names_that_begin_or_end_another_share_its_bytes() {
    assert_eq!(SHARED.strings(), "Source bit 10");
    for (i, e) in NUMBERED.iter().enumerate() {
        assert_eq!(SHARED.get(i), Some(*e), "entry {i}");
    }
}

#[test]
fn runs_read_like_slices() {
    let run = TABLE.list(0, 3);
    let slice = Entries::slice(&ES[..3]);
    assert_eq!(run, slice);
    assert_eq!(run.find(2), ES.get(2).copied());
    assert_eq!(run.find(3), None);
    assert_eq!(run.get(3), None);
    assert_eq!(run.max_sub(), 2);
    assert_eq!(run.iter().next_back(), ES.get(2).copied());
    assert_eq!(TABLE.list(3, 2).iter().count(), 2);
    // sub 0 of the second list, then the first list's elements
    let joined = TABLE.joined(3, 1, 3);
    assert_eq!(joined.get(0), ES.get(3).copied());
    assert_eq!(joined.find(2), ES.get(2).copied());
    assert_eq!(joined.position(1), Some(1));
    assert_eq!(joined.max_sub(), 2);
    assert_eq!(joined.get(3), None);
}
