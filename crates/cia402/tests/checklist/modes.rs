//! Operating modes, general: mode values, the default mode, switching only at standstill (C-025..C-027).

use super::*;

// ---------------------------------------------------------------- modes

#[test]
fn c025_mode_values_and_display() {
    for v in [-1i8, 0, 1, 2, 3, 4, 6, 7, 8, 9, 10] {
        let mut r = Rig::new();
        r.inp.mode_request = v;
        let out = r.step();
        assert_eq!(out.mode_display, v);
        assert_eq!(out.mode_error, None);
        assert_eq!(Mode::from_i8(v).map(Mode::code), Some(v));
    }
    // Invalid values: old mode kept, error reported every cycle.
    for v in [5i8, 11, -2, 127, -128] {
        let mut r = Rig::new();
        r.inp.mode_request = 3;
        r.step();
        r.inp.mode_request = v;
        for _ in 0..2 {
            let out = r.step();
            assert_eq!(out.mode_display, 3);
            assert_eq!(out.mode_error, Some(ModeError::Unsupported(v)));
        }
        assert_eq!(
            Mode::check(v, SUPPORTED_DRIVE_MODES),
            Err(ModeError::Unsupported(v))
        );
    }
    // 6502h gates the request.
    let mut r = Rig::with(Options {
        supported_modes: SUPPORTED_DRIVE_MODES & !Mode::ProfilePosition.supported_bit(),
        ..Options::default()
    });
    r.inp.mode_request = 1;
    let out = r.step();
    assert_eq!(out.mode_display, 8);
    assert_eq!(out.mode_error, Some(ModeError::Unsupported(1)));
    // 6502h bits: pp, vl, pv, pt, hm, ip, csp, csv, cst, jog (bit 16).
    assert_eq!(SUPPORTED_DRIVE_MODES, 0x0001_03EF);
    for m in Mode::ALL {
        if m != Mode::NoMode {
            assert_ne!(m.supported_bit() & SUPPORTED_DRIVE_MODES, 0, "{m:?}");
        }
    }
}

#[test]
fn c026_default_mode_is_csp() {
    assert_eq!(Mode::DEFAULT.code(), 8);
    assert_eq!(Inputs::default().mode_request, 8);
    let mut dc = DeviceControl::new(Options::default());
    assert_eq!(dc.mode(), Mode::CyclicPosition);
    assert_eq!(dc.step(&Inputs::default(), Nanos::ZERO).mode_display, 8);
}

#[test]
fn c027_mode_switch_only_at_standstill() {
    let pairs = [
        (8i8, 1i8),
        (7, 3),
        (10, 4),
        (9, 2),
        (1, 8),
        (2, 7),
        (4, 10),
        (3, 9),
    ];
    for (from, to) in pairs {
        let mut r = Rig::new();
        r.inp.mode_request = from;
        r.goto(State::OperationEnabled);
        assert_eq!(r.step().mode_display, from);
        r.inp.standstill = false;
        r.inp.mode_request = to;
        for _ in 0..3 {
            let out = r.step();
            assert_eq!(out.mode_display, from, "{from}->{to}");
            assert!(out.mode_pending);
            assert_eq!(out.mode_error, None);
        }
        r.inp.standstill = true;
        let out = r.step();
        assert_eq!(out.mode_display, to, "{from}->{to}");
        assert!(!out.mode_pending);
    }
    // Within one class, and into/out of homing, jog and no mode: at once (spec §6.2 does
    // not restrict them).
    let free = [
        (8i8, 9i8),
        (7, 10),
        (1, 3),
        (2, 4),
        (8, 6),
        (6, 1),
        (9, -1),
        (-1, 3),
        (8, 0),
    ];
    for (from, to) in free {
        let mut r = Rig::new();
        r.inp.mode_request = from;
        r.goto(State::OperationEnabled);
        r.inp.standstill = false;
        r.inp.mode_request = to;
        let out = r.step();
        assert_eq!(out.mode_display, to, "{from}->{to}");
        assert!(!out.mode_pending);
    }
    // A pending change withdrawn: nothing changes.
    let mut r = Rig::new();
    r.inp.standstill = false;
    r.inp.mode_request = 1;
    assert!(r.step().mode_pending);
    r.inp.mode_request = 8;
    let out = r.step();
    assert!(!out.mode_pending);
    assert_eq!(out.mode_display, 8);
}
