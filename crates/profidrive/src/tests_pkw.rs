use crate::fake::Fake;
use crate::pkw::*;
use crate::telegram::Telegrams;
use crate::Addr;

fn req(code: u8, index: u16, sub: u8, data: u32) -> [u8; 8] {
    let [i0, i1] = index.to_be_bytes();
    let [d0, d1, d2, d3] = data.to_be_bytes();
    [code, i0, i1, sub, d0, d1, d2, d3]
}

#[test]
fn p191_a_read_mirrors_0x41_with_the_value_in_bytes_4_to_7() {
    let mut f = Fake::drive();
    f.set(Addr::new(1100, 0), -5);
    let mut p = Pkw::new();
    assert_eq!(
        p.step(req(READ, 1100, 0, 0), &mut f),
        req(READ, 1100, 0, 0xFFFF_FFFB)
    );
    assert!(f.writes.is_empty());
}

#[test]
fn p192_a_write_mirrors_0x42_and_is_not_cyclic() {
    let mut f = Fake::drive();
    let mut p = Pkw::new();
    let r = req(WRITE, 1001, 0, 1234);
    assert_eq!(p.step(r, &mut f), r);
    assert_eq!(f.writes, [(Addr::new(1001, 0), 1234, false)]);
}

#[test]
fn p193_a_second_access_of_the_same_type_needs_0x00_in_between() {
    let mut f = Fake::drive();
    f.set(Addr::new(1100, 0), 1);
    f.set(Addr::new(1101, 0), 2);
    let mut p = Pkw::new();
    let first = p.step(req(READ, 1100, 0, 0), &mut f);
    assert_eq!(first, req(READ, 1100, 0, 1));
    // same code, other index: not a new access
    assert_eq!(p.step(req(READ, 1101, 0, 0), &mut f), first);
    assert_eq!(p.step(req(NONE, 1101, 0, 0), &mut f)[0], NONE, "0x00 is mirrored");
    assert_eq!(p.step(req(READ, 1101, 0, 0), &mut f), req(READ, 1101, 0, 2));
    // writes: a held request is written once
    let w = req(WRITE, 1001, 1, 7);
    p.step(w, &mut f);
    p.step(w, &mut f);
    p.step(w, &mut f);
    assert_eq!(f.writes.len(), 1);
    // a read right after a write is a code change: executed
    assert_eq!(p.step(req(READ, 1001, 1, 0), &mut f), req(READ, 1001, 1, 7));
}

#[test]
fn p194_the_pkw_addresses_canopen_objects_too() {
    let mut f = Fake::drive();
    f.set(Addr::new(0x6077, 0), -14);
    let mut p = Pkw::new();
    assert_eq!(
        p.step(req(READ, 0x6077, 0, 0), &mut f),
        req(READ, 0x6077, 0, 0xFFFF_FFF2)
    );
    p.step(req(NONE, 0, 0, 0), &mut f);
    let w = req(WRITE, 0x2415, 2, 5000);
    assert_eq!(p.step(w, &mut f), w);
    assert_eq!(f.value(Addr::new(0x2415, 2)), 5000);
}

#[test]
fn p195_reserved_codes_start_nothing() {
    let mut f = Fake::drive();
    let mut p = Pkw::new();
    let before = p.step(req(READ, 1100, 0, 0), &mut f);
    for code in [0x43u8, 0x01, 0xC1, 0xFF] {
        assert_eq!(p.step(req(code, 1001, 0, 99), &mut f), before);
    }
    assert_eq!(p.reserved_requests(), 4);
    assert!(f.writes.is_empty());
    // after a reserved code a read is a code change again
    assert_eq!(p.step(req(READ, 1100, 0, 0), &mut f)[0], READ);
}

#[test]
fn p196_a_refused_access_answers_0xc1_0xc2_with_the_error_number_and_changes_nothing() {
    let mut f = Fake::drive();
    let mut p = Pkw::new();
    let cases = [
        (req(WRITE, 0x5555, 0, 1), req(WRITE_ERROR, 0x5555, 0, 0x00)),
        (req(READ, 0x5555, 0, 0), req(READ_ERROR, 0x5555, 0, 0x00)),
        (req(WRITE, 1100, 0, 1), req(WRITE_ERROR, 1100, 0, 0x01)),
        (req(READ, 1001, 9, 0), req(READ_ERROR, 1001, 9, 0x03)),
        (req(WRITE, 1004, 0, 2001), req(WRITE_ERROR, 1004, 0, 0x02)),
        (req(WRITE, 0x2000, 0, 1), req(WRITE_ERROR, 0x2000, 0, 0x05)),
        (req(READ, 0x1008, 0, 0), req(READ_ERROR, 0x1008, 0, 0x05)),
        (req(READ, 0x6040, 0, 0), req(READ_ERROR, 0x6040, 0, 0x00)),
    ];
    for (r, want) in cases {
        p.step(req(NONE, 0, 0, 0), &mut f);
        assert_eq!(p.step(r, &mut f), want, "{r:02x?}");
    }
    assert!(f.writes.is_empty());
    assert_eq!(f.value(Addr::new(1004, 0)), 0);
    f.state_lock = true;
    p.step(req(NONE, 0, 0, 0), &mut f);
    assert_eq!(
        p.step(req(WRITE, 1001, 0, 3), &mut f),
        req(WRITE_ERROR, 1001, 0, 0x11)
    );
    assert_eq!(f.value(Addr::new(1001, 0)), 0);
}

#[test]
fn p197_small_values_are_right_aligned_and_sign_extended() {
    let mut f = Fake::drive();
    f.set(Addr::new(1050, 0), -3);
    f.set(Addr::new(1500, 0), 0x10);
    let mut p = Pkw::new();
    assert_eq!(
        p.step(req(READ, 1050, 0, 0), &mut f),
        req(READ, 1050, 0, 0xFFFF_FFFD)
    );
    p.step(req(NONE, 0, 0, 0), &mut f);
    assert_eq!(p.step(req(READ, 1500, 0, 0), &mut f), req(READ, 1500, 0, 0x10));
    p.step(req(NONE, 0, 0, 0), &mut f);
    p.step(req(WRITE, 0x6071, 0, 0xFFFF_FF9C), &mut f);
    assert_eq!(f.value(Addr::new(0x6071, 0)), -100);
    // a value that does not fit the object's type
    for (index, data) in [(0x6071u16, 0x0000_FFFFu32), (1500, 0x100), (1050, 0x80)] {
        p.step(req(NONE, 0, 0, 0), &mut f);
        assert_eq!(p.step(req(WRITE, index, 0, data), &mut f)[4..], [0, 0, 0, 2]);
    }
    assert_eq!(f.writes.len(), 1);
}

#[test]
fn p192_a_write_that_takes_cycles_keeps_the_previous_response_until_done() {
    let mut f = Fake::drive();
    f.save_cycles = 3;
    let mut p = Pkw::new();
    let before = p.step(req(READ, 1100, 0, 0), &mut f);
    let save = req(WRITE, 971, 0, 1);
    assert_eq!(p.step(save, &mut f), before);
    assert!(p.busy());
    assert_eq!(
        p.step(req(NONE, 0, 0, 0), &mut f),
        before,
        "the request is not looked at"
    );
    assert_eq!(p.step(save, &mut f), before);
    assert_eq!(p.step(save, &mut f), save, "done: mirrored");
    assert!(!p.busy());
    assert_eq!(f.writes.len(), 1);
}

#[test]
fn p191_the_pkw_slot_of_the_fb_telegram_works_end_to_end() {
    let mut f = Fake::drive();
    f.set(Addr::new(1101, 0), 300);
    let mut t = Telegrams::with_defaults(&f).expect("defaults");
    let mut p = Pkw::new();
    let mut frame = [0u8; 36];
    frame[0] = 0xE0;
    frame[2..4].copy_from_slice(&0x0406u16.to_be_bytes());
    frame[24..32].copy_from_slice(&req(READ, 1101, 0, 0));
    let rx = t.apply_receive(&frame, &mut f);
    let resp = p.step(rx.pkw.expect("mapped"), &mut f);
    let mut buf = [0u8; 36];
    t.build_response(rx.response.expect("associated"), &mut f, resp, &mut buf)
        .expect("built");
    assert_eq!(buf[24..32], req(READ, 1101, 0, 300));
}
