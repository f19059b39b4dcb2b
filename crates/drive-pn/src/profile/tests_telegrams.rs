//! The telegram configuration over the bus (PNU 2020…2022) and in the
//! parameter set (A280, P-069): edited, checked entry by entry and as a
//! whole, refused with its error and nothing changed, saved and loaded.

use super::pnu::pkw2;
use super::Bench;
use crate::PnDrive;

/// CANopen-style entry: index << 16 | sub << 8.
fn entry(index: u16, sub: u8) -> u32 {
    u32::from(index) << 16 | u32::from(sub) << 8
}

/// Receive telegram 3 (free format): CW1, the target velocity.
fn telegram3(cw1: u16, rpm: i32) -> [u8; 36] {
    let mut t = [0u8; 36];
    t[0] = 0xE3;
    t[1..3].copy_from_slice(&cw1.to_be_bytes());
    t[3..7].copy_from_slice(&rpm.to_be_bytes());
    t
}

/// Receive telegram 3 configured over PKW (selector 3, entries 967.0 and
/// 1010.0, apply) and response telegram 3 (ZSW1, 1101.0): frames with
/// identifier 0xE3 then work, answered with 0xF3; PNU 971 saves the
/// configuration in A280 and a restarted drive has it (P-069, P-055).
#[test]
fn p069_a_telegram_configured_over_pkw_is_used_saved_and_loaded() {
    let mut b = Bench::new();
    assert_eq!(
        pkw2(&mut b, 0x42, 2020, 0, 7).0,
        0x42,
        "select response telegram 3"
    );
    assert_eq!(pkw2(&mut b, 0x42, 2021, 0, entry(968, 0)).0, 0x42);
    assert_eq!(pkw2(&mut b, 0x42, 2021, 1, entry(1101, 0)).0, 0x42);
    assert_eq!(pkw2(&mut b, 0x42, 2022, 0, 1).0, 0x42, "applied");
    assert_eq!(
        pkw2(&mut b, 0x42, 2020, 0, 3).0,
        0x42,
        "select receive telegram 3"
    );
    assert_eq!(
        pkw2(&mut b, 0x41, 2021, 0, 0),
        (0x41, 0x07DB_0000),
        "2011.0: unused"
    );
    assert_eq!(pkw2(&mut b, 0x42, 2021, 0, entry(967, 0)).0, 0x42);
    assert_eq!(pkw2(&mut b, 0x42, 2021, 1, entry(1010, 0)).0, 0x42);
    assert_eq!(
        pkw2(&mut b, 0x41, 2021, 1, 0),
        (0x41, 0x03F2_0020),
        "1010.0, 32 bits"
    );
    assert_eq!(
        pkw2(&mut b, 0x41, 2021, 10, 0),
        (0x41, 3),
        "answered by response 3"
    );
    assert_eq!(pkw2(&mut b, 0x42, 2022, 0, 1).0, 0x42, "applied");
    assert_eq!(pkw2(&mut b, 0x41, 2022, 0, 0), (0x41, 0), "no refusal");
    b.run(&telegram3(0x0400, 123), 10);
    assert_eq!(b.response[0], 0xF3, "response telegram 3");
    assert_eq!(b.d.objects().get(0x6042, 0), Ok(123), "1010.0 from telegram 3");
    // saved with the parameters, loaded at start
    assert_eq!(pkw2(&mut b, 0x42, 971, 0, 1).0, 0x42);
    let flash = core::mem::replace(&mut b.d, crate::tests::commissioned()).into_flash();
    b.d = crate::tests::connected(PnDrive::new(flash, crate::tests::hardware()));
    b.run(&telegram3(0x0400, 77), 10);
    assert_eq!(b.response[0], 0xF3);
    assert_eq!(
        b.d.objects().get(0x6042, 0),
        Ok(77),
        "telegram 3 after the restart"
    );
}

/// Bad entries are refused as they are written, with their error, and the
/// edit copy keeps what it had: a read-only object in a receive telegram
/// (0x14, P-059), a missing object (0x00), a missing subindex (0x03), a
/// string (0x05); a write-only object is fine in a receive telegram but
/// a read-only one is what a response needs (P-060).
#[test]
fn p058_p059_p060_entries_are_checked_as_they_are_entered() {
    let mut b = Bench::new();
    assert_eq!(pkw2(&mut b, 0x42, 2020, 0, 3).0, 0x42);
    for (value, error) in [
        (entry(1100, 0), 0x14),
        (entry(0x6FFF, 0), 0x00),
        (entry(1001, 9), 0x03),
        (entry(drive_core::params::A271, 0), 0x05),
    ] {
        assert_eq!(pkw2(&mut b, 0x42, 2021, 2, value), (0xC2, error), "{value:#010x}");
        assert_eq!(pkw2(&mut b, 0x41, 2021, 2, 0), (0x41, 0x07DB_0000), "unchanged");
    }
    assert_eq!(pkw2(&mut b, 0x42, 2020, 0, 4).0, 0x42, "response telegram 0");
    assert_eq!(
        pkw2(&mut b, 0x42, 2021, 3, entry(1100, 0)).0,
        0x42,
        "read-only in a response"
    );
    assert_eq!(
        pkw2(&mut b, 0x42, 2021, 10, 1),
        (0xC2, 0x14),
        "responses have no association"
    );
    assert_eq!(pkw2(&mut b, 0x42, 2020, 0, 8), (0xC2, 0x02), "no telegram 8");
}

/// A280's bytes as they stand.
fn a280(b: &mut Bench) -> std::vec::Vec<u8> {
    let mut buf = [0u8; 255];
    let n = od::Dictionary::read(
        b.d.objects_mut(),
        drive_core::params::A280,
        0,
        &mut buf,
        od::CommState::Op,
    )
    .unwrap();
    buf[..n].to_vec()
}

/// A telegram set that does not check as a whole is refused at apply with
/// 0x18 and its reason in PNU 2022, and nothing changes: receive telegram 0
/// with CW1 moved off offset 2 (P-061) keeps working as it was, A280 keeps
/// its value.
#[test]
fn p061_p069_a_malformed_telegram_is_refused_at_apply_and_changes_nothing() {
    let mut b = Bench::new();
    let a280_before = a280(&mut b);
    assert_eq!(pkw2(&mut b, 0x42, 2020, 0, 0).0, 0x42, "receive telegram 0");
    // byte 1 the homing method, then the target position before CW1
    assert_eq!(pkw2(&mut b, 0x42, 2021, 1, entry(1001, 0)).0, 0x42);
    assert_eq!(pkw2(&mut b, 0x42, 2021, 2, entry(967, 0)).0, 0x42);
    let (code, _) = pkw2(&mut b, 0x42, 2022, 0, 1);
    assert_eq!((code, b.i32_at(28)), (0xC2, 0x18), "values inconsistent");
    let (code, why) = pkw2(&mut b, 0x41, 2022, 0, 0);
    assert_eq!(code, 0x41);
    assert_eq!(why & 0x00FF, 6, "CW1 not at offset 2: {why:#06x}");
    assert_eq!(why & 0x7000, 0, "receive telegram 0");
    let a280_after = a280(&mut b);
    assert_eq!(a280_after, a280_before, "A280 unchanged");
    // telegram 0 as before: CW1 at offset 2
    b.run(&super::positioning(0x0406, 0, 100, 10_000), 20);
    assert_eq!(b.response[0], 0xF0);
    assert_eq!(b.zsw1() & 0x47, 0x01, "CW1 still taken from offset 2");
}

/// A280 is as long as the longest stored telegram set (P-069).
#[test]
fn p069_a280_holds_the_longest_stored_form() {
    assert_eq!(
        usize::from(drive_core::objects::manufacturer::PN_TELEGRAMS_LEN),
        profidrive::telegram::MAX_SERIAL_BYTES
    );
}
