use crate::fake::Fake;
use crate::telegram::*;
use crate::Addr;

fn a(index: u16, sub: u8) -> Addr {
    Addr::new(index, sub)
}

fn defaults(f: &Fake) -> Telegrams {
    Telegrams::with_defaults(f).expect("the FB defaults configure")
}

fn offsets(t: &Telegrams, dir: Dir, n: u8) -> std::vec::Vec<(Addr, u8, u8)> {
    let l = t.layout(dir, n).expect("layout");
    l.slots().iter().map(|s| (s.addr, s.offset, s.size)).collect()
}

/// Fig. 20 / Fig. 22 of the manual (spec §4.4).
fn manual_example() -> TelegramSet {
    let mut set = FB_DEFAULTS;
    set.receive[0] = TelegramSet::pad(&[PAD8, CW1, a(1001, 0), a(1001, 1), a(1001, 5)]).expect("5 entries");
    set.receive[0][7] = UNUSED;
    set.response[0] = TelegramSet::pad(&[a(1500, 0), ZSW1, a(1100, 0), a(1101, 0), a(1102, 0), a(1141, 0)])
        .expect("6 entries");
    // PKW in neither telegram 0 now
    set
}

#[test]
fn p057_p071_p072_p073_p074_the_fb_defaults_lay_out_36_bytes_each() {
    let f = Fake::drive();
    let t = defaults(&f);
    assert_eq!(
        offsets(&t, Dir::Receive, 0),
        [
            (a(1050, 0), 1, 1),
            (CW1, 2, 2),
            (a(1001, 0), 4, 4),
            (a(1001, 1), 8, 4),
            (a(1001, 2), 12, 4),
            (a(1001, 5), 16, 4),
            (a(1040, 0), 20, 4),
            (PKW, 24, 8),
            (a(0x2415, 2), 32, 4),
        ]
    );
    let rx1: std::vec::Vec<u8> = offsets(&t, Dir::Receive, 1).iter().map(|s| s.1).collect();
    assert_eq!(rx1, [1, 2, 4, 8, 12, 16, 20, 24, 32]);
    let rx2 = offsets(&t, Dir::Receive, 2);
    assert_eq!(rx2[2], (a(0x6071, 0), 4, 2));
    assert_eq!(rx2[3], (PAD16, 6, 2));
    assert_eq!(rx2[9], (a(0x2416, 2), 32, 4));
    for n in 0..3 {
        let tx = offsets(&t, Dir::Response, n);
        assert_eq!(tx[4], (a(0x6077, 0), 12, 2));
        assert_eq!(tx[5], (a(1141, 0), 14, 4));
        assert_eq!(tx[8], (PKW, 24, 8));
        for dir in [Dir::Receive, Dir::Response] {
            assert_eq!(t.layout(dir, n).map(|l| l.len()), Some(36), "{dir:?} {n}");
        }
    }
    assert_eq!(t.layout(Dir::Receive, 3).map(|l| l.len()), Some(1));
}

#[test]
fn p049_p051_p052_p053_the_identifier_selects_the_telegram_and_binds_the_mode() {
    let mut f = Fake::drive();
    let mut t = defaults(&f);
    let mut frame = [0u8; 36];
    for (id, n, mode) in [
        (0xE0, 0, ModeBinding::Positioning),
        (0xE1, 1, ModeBinding::Speed),
        (0xE2, 2, ModeBinding::None),
        (0xE2, 2, ModeBinding::None),
        (0xE0, 0, ModeBinding::Positioning),
    ] {
        frame[0] = id;
        let prev = t.active_receive();
        let r = t.apply_receive(&frame, &mut f);
        assert_eq!((r.telegram, r.mode, r.response), (Some(n), mode, Some(n)));
        assert_eq!(r.changed, prev != Some(n));
        assert!(r.warnings.is_empty());
    }
}

#[test]
fn p050_p062_the_response_starts_with_f0_plus_n_and_zsw1_at_offset_2() {
    let mut f = Fake::drive();
    let mut t = defaults(&f);
    f.set(ZSW1, 0x2B70);
    f.set(a(1500, 0), 0x10);
    let mut buf = [0xAAu8; 36];
    for n in 0..3 {
        let r = t.build_response(n, &mut f, [0; 8], &mut buf).expect("configured");
        assert_eq!((r.len, r.warnings), (36, Warnings::default()));
        assert_eq!(buf[..4], [0xF0 + n, 0x10, 0x2B, 0x70]);
    }
    assert!(t.build_response(4, &mut f, [0; 8], &mut buf).is_none());
}

#[test]
fn p061_p063_cw1_off_offset_2_or_a_wide_byte_1_is_refused_and_nothing_changes() {
    let f = Fake::drive();
    let mut t = defaults(&f);
    let cases = [
        (std::vec![a(1001, 0), CW1], Some(0), Reason::Byte1NotOneByte),
        (
            std::vec![a(1050, 0), a(1001, 0), CW1],
            Some(1),
            Reason::ControlWordNotAtOffset2,
        ),
        (
            std::vec![a(1050, 0), a(0x6071, 0)],
            Some(1),
            Reason::ControlWordNotAtOffset2,
        ),
        (std::vec![a(1050, 0)], None, Reason::ControlWordNotAtOffset2),
        (std::vec![a(1050, 0), CW1, CW1], Some(2), Reason::ControlWordTwice),
        (std::vec![a(0x6071, 0), CW1], Some(0), Reason::Byte1NotOneByte),
    ];
    for (entries, entry, reason) in cases {
        let e = TelegramSet::pad(&entries).expect("≤ 10");
        let err = t.set_telegram(Dir::Receive, 0, &e, &f).expect_err("refused");
        assert_eq!(
            (err.dir, err.telegram, err.entry, err.reason),
            (Dir::Receive, 0, entry, reason)
        );
        assert_eq!(*t.set(), FB_DEFAULTS, "nothing changed");
        assert_eq!(t.layout(Dir::Receive, 0).map(|l| l.len()), Some(36));
    }
    // byte 1 takes any 1-byte entry
    let mut ok = FB_DEFAULTS.receive[0];
    ok[0] = a(1500, 0);
    t.set_telegram(Dir::Receive, 0, &ok, &f).expect("a U8 at byte 1");
    assert_eq!(offsets(&t, Dir::Receive, 0)[0], (a(1500, 0), 1, 1));
}

#[test]
fn p062_zsw1_must_sit_at_offset_2_of_responses_0_to_2_and_never_in_receive() {
    let f = Fake::drive();
    let mut t = defaults(&f);
    let mut bad = FB_DEFAULTS.response[1];
    bad.swap(1, 2);
    let err = t.set_telegram(Dir::Response, 1, &bad, &f).expect_err("refused");
    assert_eq!((err.telegram, err.reason), (1, Reason::ControlWordNotAtOffset2));
    let mut rx = FB_DEFAULTS.receive[2];
    rx[3] = ZSW1;
    let err = t.set_telegram(Dir::Receive, 2, &rx, &f).expect_err("refused");
    assert_eq!((err.entry, err.reason), (Some(3), Reason::StatusWordInReceive));
    assert_eq!(*t.set(), FB_DEFAULTS);
}

#[test]
fn p058_p059_p060_entries_are_checked_against_the_drive() {
    let f = Fake::drive();
    let mut t = defaults(&f);
    let with = |i: usize, e: Addr, base: Entries| {
        let mut x = base;
        x[i] = e;
        x
    };
    let rx = FB_DEFAULTS.receive[0];
    let tx = FB_DEFAULTS.response[0];
    let cases = [
        (
            Dir::Receive,
            with(2, a(0x5555, 0), rx),
            Reason::NoObject(crate::PdError::IMPERMISSIBLE_PNU),
        ),
        (
            Dir::Receive,
            with(2, a(1001, 9), rx),
            Reason::NoObject(crate::PdError::FAULTY_SUBINDEX),
        ),
        (Dir::Receive, with(2, a(1100, 0), rx), Reason::ReadOnlyInReceive),
        (
            Dir::Response,
            with(2, a(0x6040, 0), tx),
            Reason::WriteOnlyInResponse,
        ),
        (Dir::Response, with(2, a(0x1008, 0), tx), Reason::UnsupportedType),
    ];
    for (dir, entries, reason) in cases {
        let err = t.set_telegram(dir, 0, &entries, &f).expect_err("refused");
        assert_eq!((err.entry, err.reason), (Some(2), reason));
        assert_eq!(*t.set(), FB_DEFAULTS);
    }
    // a writable object in a response is fine (it is readable)
    t.set_telegram(Dir::Response, 0, &with(2, a(1001, 0), tx), &f)
        .expect("rw in a response");
}

#[test]
fn p198_pkw_at_most_once_and_in_both_a_receive_telegram_and_its_response() {
    let f = Fake::drive();
    let mut t = defaults(&f);
    let mut twice = FB_DEFAULTS.receive[2];
    twice[4] = PKW;
    let err = t.set_telegram(Dir::Receive, 2, &twice, &f).expect_err("twice");
    assert_eq!((err.entry, err.reason), (Some(8), Reason::PkwTwice));
    let mut no_pkw = FB_DEFAULTS.receive[1];
    no_pkw[7] = PAD32;
    no_pkw[8] = PAD32;
    no_pkw[9] = a(0x2415, 2);
    let err = t
        .set_telegram(Dir::Receive, 1, &no_pkw, &f)
        .expect_err("response has PKW");
    assert_eq!((err.telegram, err.reason), (1, Reason::PkwNotInBoth));
    // receive 0 (PKW) answered by the empty response 3 (no PKW)
    let err = t.set_associated(0, 3, &f).expect_err("response 3 has no PKW");
    assert_eq!(err.reason, Reason::PkwNotInBoth);
    let err = t.set_associated(0, 4, &f).expect_err("no response 4");
    assert_eq!(err.reason, Reason::BadAssociation);
    assert_eq!(*t.set(), FB_DEFAULTS);
}

#[test]
fn p055_the_associated_response_telegram_answers() {
    let mut f = Fake::drive();
    let mut t = defaults(&f);
    t.set_associated(1, 0, &f).expect("response 0 has PKW too");
    let mut frame = [0u8; 36];
    frame[0] = 0xE1;
    let r = t.apply_receive(&frame, &mut f);
    assert_eq!((r.telegram, r.response), (Some(1), Some(0)));
    assert_eq!(t.associated(1), Some(0));
    let mut buf = [0u8; 36];
    t.build_response(0, &mut f, [0; 8], &mut buf).expect("built");
    assert_eq!(buf[0], 0xF0);
}

#[test]
fn p066_p067_entries_are_written_every_cycle_ram_only_and_cw1_is_returned_not_written() {
    let mut f = Fake::drive();
    let mut t = defaults(&f);
    let mut frame = [0u8; 36];
    frame[0] = 0xE0;
    frame[1] = 0xFD; // homing method -3
    frame[2..4].copy_from_slice(&0x047Fu16.to_be_bytes());
    frame[4..8].copy_from_slice(&5000i32.to_be_bytes());
    frame[24..32].copy_from_slice(&[0x41, 0x04, 0x4C, 0, 0, 0, 0, 0]);
    for cycle in 1..=2 {
        let r = t.apply_receive(&frame, &mut f);
        assert_eq!(r.cw1, Some(0x047F));
        assert_eq!(r.pkw, Some([0x41, 0x04, 0x4C, 0, 0, 0, 0, 0]));
        assert_eq!(
            f.writes.len(),
            7 * cycle,
            "every entry but CW1, PKW and placeholders"
        );
    }
    assert!(f.writes.iter().all(|w| w.2), "cyclic = RAM only");
    assert!(f.writes.iter().all(|w| w.0 != CW1 && w.0 != PKW));
    assert_eq!(f.value(a(1050, 0)), -3);
    assert_eq!(f.value(a(1001, 0)), 5000);
    assert_eq!(f.value(CW1), 0, "CW1 is the caller's, applied last");
}

#[test]
fn p068_the_manuals_dump_decodes_big_endian() {
    let mut f = Fake::drive();
    let mut t = Telegrams::new();
    t.configure(&manual_example(), &f).expect("Fig. 20/22");
    let rx = [
        0xE0, 0x00, 0x04, 0x30, 0x00, 0x00, 0x13, 0x88, 0x00, 0x00, 0x00, 0xC8, 0x00, 0x01, 0x86, 0xA0,
    ];
    let r = t.apply_receive(&rx, &mut f);
    assert_eq!(r.cw1, Some(0x0430));
    assert!(r.warnings.is_empty());
    assert_eq!(
        (f.value(a(1001, 0)), f.value(a(1001, 1)), f.value(a(1001, 5))),
        (5000, 200, 100_000)
    );
    for (addr, v) in [
        (a(1500, 0), 0x10),
        (ZSW1, 0x2B70),
        (a(1100, 0), 213),
        (a(1101, 0), 111),
        (a(1102, 0), -14),
    ] {
        f.set(addr, v);
    }
    let mut buf = [0u8; 20];
    t.build_response(0, &mut f, [0; 8], &mut buf).expect("built");
    assert_eq!(
        buf,
        [
            0xF0, 0x10, 0x2B, 0x70, 0x00, 0x00, 0x00, 0xD5, 0x00, 0x00, 0x00, 0x6F, 0xFF, 0xFF, 0xFF, 0xF2,
            0, 0, 0, 0
        ]
    );
}

#[test]
fn p064_p065_placeholders_carry_zero_and_unused_entries_take_no_bytes() {
    let mut f = Fake::drive();
    let mut t = defaults(&f);
    let mut tx = FB_DEFAULTS.response[0];
    tx[2] = UNUSED; // in the middle: no bytes either
    t.set_telegram(Dir::Response, 0, &tx, &f).expect("ok");
    assert_eq!(t.layout(Dir::Response, 0).map(|l| l.len()), Some(32));
    f.set(a(1101, 0), -1);
    let mut buf = [0x55u8; 32];
    t.build_response(0, &mut f, [9; 8], &mut buf).expect("built");
    assert_eq!(buf[4..8], [0xFF; 4], "1101.0 moved up to offset 4");
    assert_eq!(buf[14..20], [0; 6], "2010.1 + 2010.2 carry 0");
    assert_eq!(buf[20..28], [9; 8], "PKW");
    assert_eq!(buf[28..32], [0; 4]);
    // receive placeholders are not written anywhere
    let mut frame = [0xFFu8; 36];
    frame[0] = 0xE1;
    t.apply_receive(&frame, &mut f);
    assert!(f.writes.iter().all(|w| w.0.index != 2010));
    assert_eq!(TelegramSet::pad(&[PAD8; 11]), None, "at most 10 entries (P-056)");
}

#[test]
fn p075_an_unknown_identifier_is_ignored_with_a_warning() {
    let mut f = Fake::drive();
    let mut t = defaults(&f);
    let mut frame = [0x11u8; 36];
    frame[0] = 0xE0;
    t.apply_receive(&frame, &mut f);
    let before = f.writes.len();
    for id in [0xE4u8, 0xF0, 0x00] {
        frame[0] = id;
        let r = t.apply_receive(&frame, &mut f);
        assert_eq!((r.telegram, r.cw1, r.pkw), (None, None, None));
        assert!(r.warnings.has(Warnings::UNKNOWN_IDENTIFIER));
        assert_eq!(r.response, None, "nothing sent yet");
    }
    assert!(t
        .apply_receive(&[], &mut f)
        .warnings
        .has(Warnings::UNKNOWN_IDENTIFIER));
    assert_eq!(f.writes.len(), before, "payload ignored");
    assert_eq!(t.unknown_frames(), 4);
    assert_eq!(t.active_receive(), Some(0));
    // unconfigured: every identifier is unknown
    let mut fresh = Telegrams::new();
    frame[0] = 0xE0;
    assert!(fresh
        .apply_receive(&frame, &mut f)
        .warnings
        .has(Warnings::UNKNOWN_IDENTIFIER));
}

#[test]
fn p029_a_short_frame_writes_only_whole_entries_and_a_long_one_is_cut() {
    let mut f = Fake::drive();
    let mut t = defaults(&f);
    let mut frame = [0u8; 38];
    frame[0] = 0xE0;
    frame[2..4].copy_from_slice(&0x0406u16.to_be_bytes());
    frame[4..8].copy_from_slice(&7i32.to_be_bytes());
    frame[8..12].copy_from_slice(&8i32.to_be_bytes());
    let r = t.apply_receive(&frame[..10], &mut f);
    assert!(r.warnings.has(Warnings::LENGTH_MISMATCH));
    assert_eq!(r.cw1, Some(0x0406));
    assert_eq!(
        (f.value(a(1001, 0)), f.value(a(1001, 1))),
        (7, 0),
        "1001.1 only half inside"
    );
    assert_eq!(f.writes.len(), 2);
    let r = t.apply_receive(&frame[..3], &mut f);
    assert_eq!(r.cw1, None, "CW1 not wholly inside");
    let r = t.apply_receive(&frame, &mut f);
    assert!(r.warnings.has(Warnings::LENGTH_MISMATCH));
    assert_eq!(f.value(a(1001, 1)), 8);
    // the response: cut or zero-padded to the module
    f.set(a(0x6077, 0), -2);
    let mut short = [0u8; 14];
    let r = t.build_response(0, &mut f, [1; 8], &mut short).expect("built");
    assert_eq!((r.len, r.warnings.has(Warnings::LENGTH_MISMATCH)), (14, true));
    assert_eq!(short[12..14], [0xFF, 0xFE]);
    let mut long = [0xEEu8; 38];
    t.build_response(0, &mut f, [1; 8], &mut long).expect("built");
    assert_eq!(long[36..], [0, 0]);
}

#[test]
fn p070_the_live_view_shows_the_last_frames_entry_by_entry() {
    let mut f = Fake::drive();
    let mut t = defaults(&f);
    let mut frame = [0u8; 36];
    frame[0] = 0xE1;
    frame[4..8].copy_from_slice(&(-300i32).to_be_bytes());
    t.apply_receive(&frame, &mut f);
    f.set(a(1100, 0), 42);
    let mut buf = [0u8; 36];
    t.build_response(1, &mut f, [0; 8], &mut buf).expect("built");
    assert_eq!(t.live_receive(), &frame[..]);
    assert_eq!(t.live_response(), &buf[..]);
    let mut rx = std::vec::Vec::new();
    t.for_each_live(Dir::Receive, |addr, off, size, v| rx.push((addr, off, size, v)));
    assert_eq!(rx.len(), 9);
    assert_eq!(rx[2], (a(1010, 0), 4, 4, -300));
    let mut tx = std::vec::Vec::new();
    t.for_each_live(Dir::Response, |addr, _, _, v| tx.push((addr, v)));
    assert_eq!(tx[2], (a(1100, 0), 42));
}

#[test]
fn p047_p048_telegram_3_is_free_format_with_cw1_wherever_mapped() {
    let mut f = Fake::drive();
    let mut t = defaults(&f);
    let rx3 = TelegramSet::pad(&[a(1010, 0), CW1]).expect("2");
    t.set_telegram(Dir::Receive, 3, &rx3, &f).expect("free format");
    let tx3 = TelegramSet::pad(&[a(1100, 0)]).expect("1");
    t.set_telegram(Dir::Response, 3, &tx3, &f).expect("free format");
    let frame = [0xE3, 0, 0, 0, 9, 0x04, 0x0F];
    let r = t.apply_receive(&frame, &mut f);
    assert_eq!(
        (r.telegram, r.mode, r.cw1),
        (Some(3), ModeBinding::None, Some(0x040F))
    );
    assert_eq!(f.value(a(1010, 0)), 9);
    let mut buf = [0u8; 5];
    f.set(a(1100, 0), 0x0102_0304);
    t.build_response(3, &mut f, [0; 8], &mut buf).expect("built");
    assert_eq!(buf, [0xF3, 1, 2, 3, 4]);
}

#[test]
fn p067_a_refused_cyclic_write_skips_that_entry_only_with_a_warning() {
    let mut f = Fake::drive();
    let mut t = defaults(&f);
    let mut tx = FB_DEFAULTS.receive[1];
    tx[3] = a(1004, 0); // override, at most 2000
    tx[4] = PAD16;
    t.set_telegram(Dir::Receive, 1, &tx, &f).expect("ok");
    let mut frame = [0u8; 36];
    frame[0] = 0xE1;
    frame[4..8].copy_from_slice(&55i32.to_be_bytes());
    frame[8..10].copy_from_slice(&3000u16.to_be_bytes());
    let r = t.apply_receive(&frame, &mut f);
    assert!(r.warnings.has(Warnings::ACCESS_REFUSED));
    assert_eq!((f.value(a(1010, 0)), f.value(a(1004, 0))), (55, 0));
}

#[test]
fn p069_the_stored_form_round_trips_and_is_checked() {
    let f = Fake::drive();
    let mut buf = [0u8; MAX_SERIAL_BYTES];
    let n = FB_DEFAULTS.to_bytes(&mut buf).expect("fits");
    assert!(n < MAX_SERIAL_BYTES);
    let back = TelegramSet::from_bytes(&buf[..n]).expect("valid");
    assert_eq!(back, FB_DEFAULTS);
    let mut t = Telegrams::new();
    t.configure(&back, &f).expect("configures");
    let mut flipped = buf;
    flipped[7] ^= 1;
    assert_eq!(TelegramSet::from_bytes(&flipped[..n]), Err(FormatError::Checksum));
    assert_eq!(
        TelegramSet::from_bytes(&buf[..n - 1]),
        Err(FormatError::Truncated)
    );
    assert_eq!(
        TelegramSet::from_bytes(&buf[..n + 1]),
        Err(FormatError::TrailingBytes)
    );
    assert_eq!(TelegramSet::from_bytes(&[]), Err(FormatError::Truncated));
    let mut v = buf;
    v[0] = 9;
    assert_eq!(TelegramSet::from_bytes(&v[..n]), Err(FormatError::Version));
    let mut many = buf;
    many[5] = 11;
    assert_eq!(
        TelegramSet::from_bytes(&many[..n]),
        Err(FormatError::TooManyEntries)
    );
    assert_eq!(
        FB_DEFAULTS.to_bytes(&mut [0u8; 10]),
        Err(FormatError::BufferTooSmall)
    );
    let mut empty = [0u8; MAX_SERIAL_BYTES];
    let m = TelegramSet::EMPTY.to_bytes(&mut empty).expect("fits");
    assert_eq!(m, 1 + 4 + 8 + 2);
}

#[test]
fn p056_a_telegram_longer_than_the_longest_module_is_refused() {
    let f = Fake::drive();
    let mut t = defaults(&f);
    let mut long = FB_DEFAULTS.receive[0];
    long[9] = a(1001, 3);
    let err = t.set_telegram(Dir::Receive, 0, &long, &f).expect_err("40 bytes");
    assert_eq!((err.entry, err.reason), (Some(9), Reason::TooLong));
    assert_eq!(*t.set(), FB_DEFAULTS);
}

/// `"e0220406 …"` as bytes.
fn unhex(s: &str) -> std::vec::Vec<u8> {
    let s: std::string::String = s.split_whitespace().collect();
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).expect("hex"))
        .collect()
}

#[test]
fn p071_p072_p073_the_fb_receive_builders_fill_the_default_layouts_entry_by_entry() {
    let mut f = Fake::drive();
    let mut t = defaults(&f);
    let mut frame = [0xAAu8; 40];
    let pkw = [0x41, 0x04, 0x4C, 0, 0, 0, 0, 0];
    let n = FbPositioning {
        homing_method: -3,
        cw1: 0x047F,
        target: -5000,
        profile_velocity: 1200,
        end_velocity: 30,
        accelerations: 40_000,
        jog_velocity: -600,
        pkw,
        current_limit: 1500,
    }
    .write(&mut frame);
    assert_eq!(n, Some(FB_RECEIVE_BYTES));
    assert_eq!(frame[36..], [0xAA; 4], "nothing written past the telegram");
    let r = t.apply_receive(&frame[..36], &mut f);
    assert_eq!((r.telegram, r.cw1, r.pkw), (Some(0), Some(0x047F), Some(pkw)));
    for (addr, v) in [
        (a(1050, 0), -3),
        (a(1001, 0), -5000),
        (a(1001, 1), 1200),
        (a(1001, 2), 30),
        (a(1001, 5), 40_000),
        (a(1040, 0), -600),
        (a(0x2415, 2), 1500),
    ] {
        assert_eq!(f.value(addr), v, "{addr:?}");
    }
    let speed = FbSpeed {
        cw1: 0x040F,
        velocity: -250,
        accelerations: 7000,
        jog_velocity: 90,
        pkw,
        current_limit: 800,
    };
    assert_eq!(speed.write(&mut frame), Some(FB_RECEIVE_BYTES));
    let r = t.apply_receive(&frame[..36], &mut f);
    assert_eq!((r.telegram, r.cw1, r.pkw), (Some(1), Some(0x040F), Some(pkw)));
    for (addr, v) in [
        (a(1010, 0), -250),
        (a(1011, 2), 7000),
        (a(1040, 0), 90),
        (a(0x2415, 2), 800),
    ] {
        assert_eq!(f.value(addr), v, "{addr:?}");
    }
    let torque = FbTorque {
        cw1: 0x0407,
        torque: -120,
        pkw,
        speed_limit: 2500,
    };
    assert_eq!(torque.write(&mut frame), Some(FB_RECEIVE_BYTES));
    let r = t.apply_receive(&frame[..36], &mut f);
    assert_eq!((r.telegram, r.cw1, r.pkw), (Some(2), Some(0x0407), Some(pkw)));
    assert_eq!((f.value(a(0x6071, 0)), f.value(a(0x2416, 2))), (-120, 2500));
    assert!(r.warnings.is_empty());
    // placeholders carry 0 (P-064) whatever the buffer held
    let mut frame = [0xAAu8; 36];
    assert_eq!(speed.write(&mut frame), Some(FB_RECEIVE_BYTES));
    assert_eq!((frame[1], &frame[8..16]), (0, &[0u8; 8][..]));
    assert_eq!(torque.write(&mut frame), Some(FB_RECEIVE_BYTES));
    assert_eq!((frame[1], &frame[6..24]), (0, &[0u8; 18][..]));
    // a short buffer is refused and left as it was
    let mut short = [0xAAu8; 35];
    assert_eq!(FbPositioning::default().write(&mut short), None);
    assert_eq!(speed.write(&mut short), None);
    assert_eq!(torque.write(&mut short), None);
    assert_eq!(short, [0xAA; 35]);
}

/// The frames the builders replaced, as their users wrote them byte by byte
/// (`crates/drive-pn/examples/profile_bench.rs`, `firmware/src/bin/qemu_pn.rs`,
/// the drive-pn profile tests' `speed` and `positioning`): the same bytes.
#[test]
fn p071_p072_p073_the_fb_receive_builders_give_the_frames_their_users_wrote_by_hand() {
    let frame = |w: &dyn Fn(&mut [u8]) -> Option<usize>| {
        let mut t = [0xAAu8; 36];
        assert_eq!(w(&mut t), Some(36));
        t.to_vec()
    };
    let (mut p, mut s, mut q) = (FbPositioning::default(), FbSpeed::default(), FbTorque::default());
    // profile_bench's telegram0, telegram1, telegram2
    (p.homing_method, p.cw1, p.target, p.profile_velocity) = (34, 0x0406, 10_000, 5_000);
    (p.accelerations, p.jog_velocity, p.current_limit) = (10_000, 1_000, 2_000);
    (s.cw1, s.velocity, s.accelerations) = (0x0406, 100, 10_000);
    (q.cw1, q.torque, q.speed_limit) = (0x0406, 100, 3_000);
    let bench = [
        frame(&|t| p.write(t)),
        frame(&|t| s.write(t)),
        frame(&|t| q.write(t)),
    ];
    assert_eq!(
        bench,
        [
            unhex("e0220406 00002710 00001388 00000000 00002710 000003e8 00000000 00000000 000007d0"),
            unhex("e1000406 00000064 00000000 00000000 00002710 00000000 00000000 00000000 00000000"),
            unhex("e2000406 00640000 00000000 00000000 00000000 00000000 00000000 00000000 00000bb8"),
        ]
    );
    // qemu_pn's t0_pos and t2_torque (its t1_speed is the bench's telegram1)
    (p.target, p.profile_velocity, p.jog_velocity, p.current_limit) = (5000, 1000, 0, 0);
    (q.torque, q.speed_limit) = (0, 0);
    let qemu = unhex("e0220406 00001388 000003e8 00000000 00002710 00000000 00000000 00000000 00000000");
    assert_eq!(frame(&|t| p.write(t)), qemu);
    let qemu = unhex("e2000406 00000000 00000000 00000000 00000000 00000000 00000000 00000000 00000000");
    assert_eq!(frame(&|t| q.write(t)), qemu);
    // the profile tests' speed(0x047F, -1500, 20000, pkw) and
    // positioning(0x043F, -7, 3000, 250)
    (s.cw1, s.velocity, s.accelerations, s.pkw) = (0x047F, -1500, 20_000, [1, 2, 3, 4, 5, 6, 7, 8]);
    (p.cw1, p.target, p.profile_velocity, p.accelerations) = (0x043F, -7, 3000, 250);
    let tests = unhex("e100047f fffffa24 00000000 00000000 00004e20 00000000 01020304 05060708 00000000");
    assert_eq!(frame(&|t| s.write(t)), tests);
    let tests = unhex("e022043f fffffff9 00000bb8 00000000 000000fa 00000000 00000000 00000000 00000000");
    assert_eq!(frame(&|t| p.write(t)), tests);
}
