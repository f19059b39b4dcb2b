//! The device state machine through CW1/ZSW1 (spec §7.3: each transition
//! from its source state), the mode PNU 1500 and the status PNUs 967/968,
//! through the drive's telegrams.

use super::{frame, pkw_request, positioning, speed, Bench};
use profidrive::telegram::FbTorque;

/// ZSW1's state bits.
const STATE: u16 = 0x0047;
const SOI: u16 = 0x0040;
const RTSO: u16 = 0x0001;
const SO: u16 = 0x0003;
const OP: u16 = 0x0007;

impl Bench {
    /// CW1 `cw1` in receive telegram 1 for `ms` ms; ZSW1's state.
    fn cw(&mut self, cw1: u16, ms: u64) -> u16 {
        self.run(&speed(cw1, 0, 10_000, [0; 8]), ms);
        self.zsw1() & STATE
    }

    /// From switching on inhibited to `state` with the enable sequence.
    fn reach(&mut self, state: u16) {
        assert_eq!(self.cw(0x0400, 20), SOI, "{:#06x}", self.zsw1());
        for (cw1, s) in [(0x0406, RTSO), (0x0407, SO), (0x040F, OP)] {
            assert_eq!(self.cw(cw1, 20), s, "CW1 {cw1:#06x}: ZSW1 {:#06x}", self.zsw1());
            if s == state {
                return;
            }
        }
    }

    /// A PKW read of `pnu`.`sub` answered (after the 0x00 toggle): the
    /// response's code and value.
    fn pkw_read(&mut self, pnu: u16, sub: u8, cw1: u16) -> (u8, i32) {
        self.run(&speed(cw1, 0, 10_000, [0; 8]), 5);
        self.run(&speed(cw1, 0, 10_000, pkw_request(0x41, pnu, sub, 0)), 10);
        (self.response[24], self.i32_at(28))
    }
}

/// T1 needs the hardware controller-enable input (A60 here): without it
/// OFF leaves the drive in switching on inhibited; with it ready; losing it
/// in operation takes the drive back to switching on inhibited.
#[test]
fn p112_the_controller_enable_input_gates_ready_for_switching_on() {
    let mut b = Bench::new();
    b.io[0].additional_enable = false;
    assert_eq!(b.cw(0x0400, 20), SOI);
    assert_eq!(b.cw(0x0406, 50), SOI, "no enable input: {:#06x}", b.zsw1());
    b.io[0].additional_enable = true;
    assert_eq!(b.cw(0x0406, 20), RTSO, "{:#06x}", b.zsw1());
    assert_eq!(b.cw(0x0407, 20), SO);
    assert_eq!(b.cw(0x040F, 20), OP);
    b.io[0].additional_enable = false;
    assert_eq!(
        b.cw(0x040F, 50),
        SOI,
        "input lost in operation: {:#06x}",
        b.zsw1()
    );
}

/// T4: disable operation (0111) in operation → switched on.
#[test]
fn p115_disable_operation_returns_to_switched_on() {
    let mut b = Bench::new();
    b.reach(OP);
    assert_eq!(b.cw(0x0407, 50), SO, "{:#06x}", b.zsw1());
    assert_eq!(b.cw(0x040F, 20), OP, "enable again from switched on");
}

/// T5: OFF (x110) in switched on → ready.
#[test]
fn p116_off_returns_switched_on_to_ready() {
    let mut b = Bench::new();
    b.reach(SO);
    assert_eq!(b.cw(0x0406, 20), RTSO, "{:#06x}", b.zsw1());
}

/// T6, T7, T8: coast stop (bit 1 = 0) from ready, operation and switched
/// on → switching on inhibited at once, ZSW1 bit 4 = 0 while commanded.
#[test]
fn p117_p118_p119_coast_stop_from_each_state() {
    stops_from_each_state([RTSO, OP, SO], (0x040D, 20), (0x0010, "coast stop"), 0x0020);
}

/// From each state of `states` CW1 `stop` (for its ms) gives switching on
/// inhibited with ZSW1's bit `active` 0 (the stop, named `what`, active)
/// and bit `other` 1 (the other stop not); OFF then leaves it for ready.
fn stops_from_each_state(states: [u16; 3], (stop, ms): (u16, u64), (active, what): (u16, &str), other: u16) {
    for from in states {
        let mut b = Bench::new();
        b.reach(from);
        assert_eq!(b.cw(stop, ms), SOI, "from {from:#06x}: {:#06x}", b.zsw1());
        assert_eq!(
            b.zsw1() & active,
            0,
            "bit {}: {what} active",
            active.trailing_zeros()
        );
        assert_ne!(
            b.zsw1() & other,
            0,
            "bit {}: only the {what}",
            other.trailing_zeros()
        );
        assert_eq!(b.cw(0x0406, 20), RTSO, "OFF leaves the {what}");
    }
}

/// T9, T10, T12: quick stop (bit 2 = 0, bit 1 = 1) from operation,
/// switched on and ready → switching on inhibited; bit 5 = 0 meanwhile.
#[test]
fn p120_p121_p123_quick_stop_from_each_state() {
    stops_from_each_state([OP, SO, RTSO], (0x040B, 50), (0x0020, "quick stop"), 0x0010);
}

/// T11: OFF (x110) in operation → ready.
#[test]
fn p122_off_in_operation_returns_to_ready() {
    let mut b = Bench::new();
    b.reach(OP);
    assert_eq!(b.cw(0x0406, 50), RTSO, "{:#06x}", b.zsw1());
}

/// F: an error in any state ends in switching on inhibited with bit 3,
/// after the error reaction; the acknowledge needs the full sequence again.
#[test]
fn p124_an_error_in_any_state_ends_in_soi_with_bit_3() {
    for from in [SOI, RTSO, SO, OP] {
        let mut b = Bench::new();
        b.reach(from);
        let cw1 = [(SOI, 0x0400), (RTSO, 0x0406), (SO, 0x0407), (OP, 0x040F)]
            .iter()
            .find(|(s, _)| *s == from)
            .map(|(_, c)| *c)
            .unwrap();
        b.d.axes_mut()[0].raise_event(motion::Event { number: 44, cause: 1 });
        b.cw(cw1, 50);
        assert_ne!(b.zsw1() & 0x0008, 0, "from {from:#06x}: fault {:#06x}", b.zsw1());
        assert_eq!(b.zsw1() & 0x0007, 0, "disabled");
        // enable commands do nothing while the fault is present
        assert_eq!(b.cw(0x040F, 20) & 0x0007, 0);
        b.cw(0x0480 | cw1, 20);
        assert_eq!(b.zsw1() & 0x0008, 0, "acknowledged");
        assert_eq!(b.zsw1() & STATE, SOI);
        b.reach(OP);
    }
}

/// PNU 1500 reads 0x10 in positioning, 0x08 in speed control and 0x04 in
/// torque control; a write of 0x04 with telegram 2 (no bound mode)
/// switches to torque control; a value outside the three is refused.
#[test]
fn p127_p128_p055_pnu_1500_reports_and_switches_the_mode() {
    let mut b = Bench::new();
    b.run(&positioning(0x0400, 0, 100, 10_000), 10);
    assert_eq!(b.pkw0(0x41, 1500, 0, 0), (0x41, 0x10));
    assert_eq!(b.pkw_read(1500, 0, 0x0400), (0x41, 0x08));
    // telegram 2 keeps the mode; PKW writes 0x04
    let mut t = frame(|f| {
        FbTorque {
            cw1: 0x0400,
            ..FbTorque::default()
        }
        .write(f)
    });
    b.run(&t, 10);
    assert_eq!(b.response[0], 0xF2);
    assert_eq!(b.response[1], 0x08, "telegram 2 has no bound mode");
    t[24..32].copy_from_slice(&pkw_request(0x42, 1500, 0, 0x04));
    b.run(&t, 10);
    assert_eq!(b.response[24], 0x42, "written");
    assert_eq!(b.d.objects().get(0x6060, 0), Ok(4));
    assert_eq!(b.response[1], 0x04, "torque control in byte 1");
    t[24..32].copy_from_slice(&[0; 8]);
    b.run(&t, 5);
    t[24..32].copy_from_slice(&pkw_request(0x42, 1500, 0, 0x20));
    b.run(&t, 10);
    assert_eq!((b.response[24], b.i32_at(28)), (0xC2, 0x14), "0x20 is no mode");
    assert_eq!(b.d.objects().get(0x6060, 0), Ok(4), "unchanged");
}

/// PNU 967 reads the CW1 the telegram carries (default 0 before any);
/// PNU 968 reads ZSW1 and refuses a write.
#[test]
fn p076_p095_cw1_and_zsw1_as_pnus() {
    let mut b = Bench::new();
    assert_eq!(b.d.profile().own().cw1, 0, "default 0");
    assert_eq!(b.pkw_read(967, 0, 0x0406), (0x41, 0x0406));
    let (code, zsw1) = b.pkw_read(968, 0, 0x0406);
    assert_eq!(code, 0x41);
    assert_eq!(zsw1 as u16, b.zsw1(), "the ZSW1 of the response");
    assert_eq!(zsw1 as u16 & STATE, RTSO);
    b.run(&speed(0x0406, 0, 10_000, [0; 8]), 5);
    b.run(&speed(0x0406, 0, 10_000, pkw_request(0x42, 968, 0, 0)), 10);
    assert_eq!((b.response[24], b.i32_at(28)), (0xC2, 0x01), "cannot be changed");
}

/// PNU 1011.0 / .1 write the vl ramp of both directions (6048h / 6049h:
/// rpm per second); reading returns it (telegram 0 here: telegram 1 maps
/// 1011.2 and writes both ramps every cycle).
#[test]
fn p179_p180_pnu_1011_ramps() {
    let mut b = Bench::new();
    // the one declaration's default (6048h/6049h: 3 000 rpm per 1 s), not
    // the Metronix drive's 14 100 rpm/s (docs/conformance.md, P-182)
    assert_eq!(b.pkw0(0x41, 1011, 0, 0), (0x41, 3_000), "default acceleration");
    assert_eq!(b.pkw0(0x41, 1011, 1, 0), (0x41, 3_000), "default deceleration");
    assert_eq!(b.pkw0(0x42, 1011, 0, 2_000).0, 0x42);
    assert_eq!(b.d.objects().get(0x6048, 1), Ok(2_000));
    assert_eq!(b.d.objects().get(0x6048, 2), Ok(1), "per 1 s");
    assert_eq!(b.d.objects().get(0x6049, 1), Ok(3_000), "deceleration kept");
    assert_eq!(b.pkw0(0x41, 1011, 0, 0), (0x41, 2_000));
    assert_eq!(b.pkw0(0x42, 1011, 1, 3_000).0, 0x42);
    assert_eq!(b.d.objects().get(0x6049, 1), Ok(3_000));
    assert_eq!(b.d.objects().get(0x6048, 1), Ok(2_000), "acceleration kept");
    assert_eq!(b.pkw0(0x41, 1011, 1, 0), (0x41, 3_000));
}

/// PNU 1101 is the actual velocity in the velocity unit (rpm): the encoder
/// turning at 300 rpm reads 300; PNU 1100 the position in 1/1000 rev.
#[test]
fn p184_p185_actual_position_and_velocity_in_profinet_units() {
    let mut b = Bench::new();
    // 300 rpm = 5 rev/s = 5 · 2^20 increments per second
    b.advance = 5 * (1 << 20) / 1000;
    b.run(&speed(0x0400, 0, 10_000, [0; 8]), 200);
    let rpm = b.i32_at(8);
    assert!((rpm - 300).abs() <= 1, "PNU 1101 in the response: {rpm}");
    // standing still: the position, exactly
    b.advance = 0;
    b.run(&speed(0x0400, 0, 10_000, [0; 8]), 100);
    let at = b.io[0].position_inc;
    let expect = (f64::from(at) * 1000.0 / f64::from(1 << 20)).round() as i32;
    assert_eq!(b.i32_at(4), expect, "PNU 1100, encoder at {at} increments");
    assert_eq!(b.i32_at(8), 0, "standing");
}

/// Speed control: ZSW1 bit 8 = the actual speed inside the window (C40,
/// 0.1 rev/s) around the set-point, bit 10 = the set-point reached or
/// exceeded (signed); the encoder turns at the speeds given.
#[test]
fn p102_p106_speed_mode_window_and_reached_bits() {
    const BIT_8: u16 = 0x0100;
    const BIT_10: u16 = 0x0400;
    // increments per 1 ms cycle at `rpm`
    let per_ms = |rpm: i32| rpm * (1 << 20) / 60 / 1000;
    for (target, actual, within, reached) in [
        (300, 300, true, true),
        (300, 0, false, false),
        (300, 400, false, true),
        (300, 280, false, false),
        (-300, -300, true, true),
        (-300, 0, false, true),
        (0, 0, true, true),
    ] {
        let mut b = Bench::new();
        b.advance = per_ms(actual);
        // CW1 bits 4, 5, 6: the set-point enabled (the drive stays disabled:
        // the encoder, not the drive, turns the axis here)
        b.run(&speed(0x0470, target, 10_000, [0; 8]), 300);
        let z = b.zsw1();
        assert_eq!(
            (z & BIT_8 != 0, z & BIT_10 != 0),
            (within, reached),
            "target {target} rpm, actual {actual} rpm: ZSW1 {z:#06x}"
        );
    }
    // bit 6 = 0: the set-point is 0, so a turning axis is outside it
    let mut b = Bench::new();
    b.advance = per_ms(300);
    b.run(&speed(0x0430, 300, 10_000, [0; 8]), 300);
    assert_eq!(b.zsw1() & BIT_8, 0, "{:#06x}", b.zsw1());
}

/// PNU 1060, the set-up speed, defaults to 3276 rpm and writes J404.
#[test]
fn p183_pnu_1060_set_up_speed_default_3276_rpm() {
    let mut b = Bench::new();
    assert_eq!(b.pkw_read(1060, 0, 0x0400), (0x41, 3276));
    b.run(&speed(0x0400, 0, 10_000, [0; 8]), 5);
    b.run(&speed(0x0400, 0, 10_000, pkw_request(0x42, 1060, 0, 600)), 10);
    assert_eq!(b.response[24], 0x42);
    assert_eq!(b.pkw_read(1060, 0, 0x0400), (0x41, 600));
}

/// PNU 964.1…4: this drive's device ID, the version 0xMMSS of its
/// software revision, the creation year and day/month (DDMMh in BCD,
///
#[test]
fn p203_p204_p205_pnu_964_identification() {
    let mut b = Bench::new();
    let (_, major, minor, _) = profinet::model::SOFTWARE_REVISION;
    assert_eq!(
        b.pkw_read(964, 1, 0x0400),
        (0x41, i32::from(profinet::model::DEVICE_ID))
    );
    assert_eq!(
        b.pkw_read(964, 2, 0x0400),
        (0x41, i32::from(major) << 8 | i32::from(minor))
    );
    let (code, year) = b.pkw_read(964, 3, 0x0400);
    assert_eq!(code, 0x41);
    assert!((2026..2100).contains(&year), "{year}");
    let (code, ddmm) = b.pkw_read(964, 4, 0x0400);
    assert_eq!(code, 0x41);
    // the digits of day and month read in hex (BCD): 0x0112 is 1 Dec
    let bcd = |v: i32| (v >> 4) * 10 + (v & 0xF);
    assert!(
        ddmm >> 4 & 0xF <= 9 && ddmm >> 12 <= 3 && ddmm & 0xF <= 9,
        "BCD digits: {ddmm:#06x}"
    );
    let (day, month) = (bcd(ddmm >> 8), bcd(ddmm & 0xFF));
    assert!(
        (1..=31).contains(&day) && (1..=12).contains(&month),
        "{ddmm:#06x}"
    );
    // read-only
    b.run(&speed(0x0400, 0, 10_000, [0; 8]), 5);
    b.run(&speed(0x0400, 0, 10_000, pkw_request(0x42, 964, 1, 1)), 10);
    assert_eq!((b.response[24], b.i32_at(28)), (0xC2, 0x01));
}

/// PNU 1141: the limit switches are bits 7 (negative, DIN6) and 8
/// (positive, DIN7) of the manual's bit map; response bytes 14…17.
#[test]
fn p189_pnu_1141_limit_switch_bits() {
    let mut b = Bench::new();
    let inputs = |b: &Bench| u32::from_be_bytes(b.response[14..18].try_into().unwrap());
    b.run(&speed(0x0400, 0, 10_000, [0; 8]), 20);
    assert_eq!(inputs(&b), 0);
    b.io[0].limit_negative = true;
    b.run(&speed(0x0400, 0, 10_000, [0; 8]), 20);
    assert_eq!(inputs(&b), 1 << 7);
    b.io[0].limit_negative = false;
    b.io[0].limit_positive = true;
    b.run(&speed(0x0400, 0, 10_000, [0; 8]), 20);
    assert_eq!(inputs(&b), 1 << 8);
    assert_eq!(b.pkw_read(1141, 0, 0x0400), (0x41, 1 << 8));
}

/// Homing runs inside positioning: PNU 1500 reads 0x10 while the homing
/// run goes and after it (6060h back to 1), and ZSW1 bit 11 is 0 during
/// the run (method 1: the negative limit switch, never reached here).
#[test]
fn p139_p107_homing_runs_inside_positioning() {
    let mut b = Bench::new();
    for cw1 in [0x0406, 0x0407, 0x040F] {
        b.run(&positioning(cw1, 0, 1000, 10_000), 20);
    }
    let mut t = positioning(0x043F | 0x0800, 0, 1000, 10_000);
    t[1] = 1;
    b.run(&t, 50);
    assert_eq!(b.d.objects().get(0x6061, 0), Ok(6), "the core's homing mode runs");
    assert_eq!(b.response[1], 0x10, "PNU 1500 stays positioning");
    assert_eq!(b.zsw1() & 0x0800, 0, "not homed during the run");
    // the falling edge of bit 11 cancels: back to positioning, no error
    t[2..4].copy_from_slice(&0x043Fu16.to_be_bytes());
    b.run(&t, 50);
    assert_eq!(b.d.objects().get(0x6061, 0), Ok(1));
    assert_eq!(b.response[1], 0x10);
    assert_eq!(b.zsw1() & 0x0008, 0, "no fault: {:#06x}", b.zsw1());
}

/// A fault whose cause is still there is not acknowledged: both limit
/// switches evaluated (I101, I102 = 1: input) and hit (event 53 cause 7);
/// CW1 bit 7 does nothing until one is released, then its next rising edge
/// acknowledges (C-017 through CW1).
#[test]
fn p218_c017_acknowledge_fails_while_the_cause_persists() {
    let mut b = Bench::new();
    for index in [drive_core::params::I101, drive_core::params::I101 + 1] {
        b.d.objects_mut().set(index, 0, 1).unwrap();
    }
    b.reach(OP);
    b.io[0].limit_positive = true;
    b.io[0].limit_negative = true;
    b.cw(0x040F, 50);
    assert_ne!(b.zsw1() & 0x0008, 0, "fault: {:#06x}", b.zsw1());
    b.run(&speed(0x0480, 0, 10_000, [0; 8]), 20);
    assert_ne!(b.zsw1() & 0x0008, 0, "the cause persists: {:#06x}", b.zsw1());
    b.cw(0x0400, 20);
    b.io[0].limit_negative = false;
    b.cw(0x0400, 20);
    assert_ne!(b.zsw1() & 0x0008, 0, "no edge yet");
    b.run(&speed(0x0480, 0, 10_000, [0; 8]), 20);
    assert_eq!(b.zsw1() & 0x0008, 0, "acknowledged: {:#06x}", b.zsw1());
}

/// Receive telegram 2 (torque): CW1, target torque 6071h (‰), PKW, the
/// speed limit 2416h.02 (the PROFINET velocity unit: rpm).
fn torque(cw1: u16, per_mille: i16, limit: i32, pkw: [u8; 8]) -> [u8; 36] {
    let t = FbTorque {
        cw1,
        torque: per_mille,
        pkw,
        speed_limit: limit,
    };
    frame(|f| t.write(f))
}

impl Bench {
    /// Torque control through telegram 2 and PNU 1500 = 0x04, enabled.
    fn torque_mode(&mut self, limit: i32) {
        self.run(&torque(0x0400, 0, limit, pkw_request(0x42, 1500, 0, 0x04)), 10);
        assert_eq!(self.response[24], 0x42);
        for cw1 in [0x0406, 0x0407, 0x040F] {
            self.run(&torque(cw1, 0, limit, [0; 8]), 20);
        }
        assert_eq!(self.zsw1() & STATE, OP, "{:#06x}", self.zsw1());
        assert_eq!(self.response[1], 0x04);
    }

    /// 6077h, ‰ of the rated torque (response bytes 12…13).
    fn torque_actual(&self) -> i16 {
        i16::from_be_bytes([self.response[12], self.response[13]])
    }
}

/// Torque control: 6071h from telegram 2 through the torque ramp 6087h
/// (‰ per second): 500 ‰ at 1000 ‰/s takes half a second.
#[test]
fn p129_p187_torque_setpoint_through_the_ramp() {
    let mut b = Bench::new();
    b.d.objects_mut().set(0x6087, 0, 1000).unwrap();
    let limit = 1200; // rpm (20 rev/s): the speed limiter leaves 500 ‰ alone
    b.torque_mode(limit);
    b.run(&torque(0x040F, 500, limit, [0; 8]), 100);
    assert_eq!(b.d.objects().get(0x6071, 0), Ok(500), "6071h from the telegram");
    let t = b.torque_actual();
    assert!((60..=140).contains(&t), "ramping: {t} ‰ after 100 ms");
    b.run(&torque(0x040F, 500, limit, [0; 8]), 600);
    assert_eq!(b.torque_actual(), 500, "the set-point after the ramp");
}

/// Torque control: 2416h.02 limits the speed: below the limit the torque
/// set-point goes through, above it the speed limiter takes the torque
/// back (below zero here: the encoder turns at twice the limit).
#[test]
fn p130_the_speed_limit_of_telegram_2_limits_torque_mode() {
    let limit = 600; // rpm = 10 rev/s
    let per_ms = |rev_per_s: f64| (rev_per_s * f64::from(1 << 20) / 1000.0) as i32;
    let mut b = Bench::new();
    b.torque_mode(limit);
    // the limiter is a P band around the limit: well below it, the set-point
    b.advance = per_ms(2.0);
    b.run(&torque(0x040F, 300, limit, [0; 8]), 100);
    assert_eq!(b.torque_actual(), 300, "below the limit");
    b.advance = per_ms(20.0);
    b.run(&torque(0x040F, 300, limit, [0; 8]), 100);
    assert!(b.torque_actual() < 0, "above the limit: {} ‰", b.torque_actual());
    // a limit of 0 keeps the axis still (as G472 = 0 % does)
    b.advance = per_ms(0.5);
    b.run(&torque(0x040F, 300, 0, [0; 8]), 100);
    assert!(b.torque_actual() < 0, "limit 0: {} ‰", b.torque_actual());
}

/// Speed control: 2415h.02 (mA, offset 32 of telegram 1) limits the torque
/// through the motor's rated current (2 A here): 100 mA = 50 ‰; the axis
/// held still against a 300 rpm set-point saturates at the limit; 0 sets
/// no limit (P-133).
#[test]
fn p133_the_current_limit_limits_the_torque_in_speed_control() {
    let telegram = |cw1: u16, ma: i32| {
        let mut t = speed(cw1, 300, 100_000, [0; 8]);
        t[32..36].copy_from_slice(&ma.to_be_bytes());
        t
    };
    for (ma, most) in [(100, Some(50)), (0, None)] {
        let mut b = Bench::new();
        for cw1 in [0x0406, 0x0407, 0x040F] {
            b.run(&telegram(cw1, ma), 20);
        }
        assert_eq!(b.zsw1() & STATE, OP);
        // the encoder stands still: the speed controller asks for all it may
        b.run(&telegram(0x047F, ma), 200);
        let t = b.torque_actual();
        match most {
            Some(m) => assert_eq!(t, m, "{ma} mA: {t} per mille"),
            None => assert!(t > 500, "no current limit: {t} per mille"),
        }
    }
}

/// A warning leaves the drive enabled and clears by itself: after the
/// positive limit switch's fault is acknowledged with the switch still hit,
/// the set-point lock (the direction is locked) shows in ZSW1 bit 7 while
/// the drive runs; off the switch and back behind it, bit 7 clears
/// (P-216, P-100).
#[test]
fn p216_p100_the_limit_switch_lock_is_a_warning_that_clears_itself() {
    const WARNING: u16 = 0x0080;
    let mut b = Bench::new();
    b.d.objects_mut().set(drive_core::params::I101, 0, 1).unwrap();
    b.io[0].position_inc = 1000;
    b.reach(OP);
    b.io[0].limit_positive = true;
    b.cw(0x040F, 50);
    assert_ne!(b.zsw1() & 0x0008, 0, "limit switch fault: {:#06x}", b.zsw1());
    b.run(&speed(0x0480, 0, 10_000, [0; 8]), 20);
    assert_eq!(b.zsw1() & 0x0008, 0, "acknowledged: {:#06x}", b.zsw1());
    b.reach(OP);
    b.cw(0x040F, 50);
    assert_eq!(b.zsw1() & STATE, OP, "enabled with the lock");
    assert_ne!(b.zsw1() & WARNING, 0, "the lock is a warning: {:#06x}", b.zsw1());
    b.io[0].limit_positive = false;
    b.io[0].position_inc = 0;
    b.cw(0x040F, 50);
    assert_eq!(b.zsw1() & WARNING, 0, "gone by itself: {:#06x}", b.zsw1());
    assert_eq!(b.zsw1() & STATE, OP);
}
