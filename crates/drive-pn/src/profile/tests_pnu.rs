//! The profile's parameter side through the drive: what PROFINET reaches
//! (PNUs and CANopen objects in one index space), in which units, and what
//! survives a restart.

use super::{frame, pkw_request, positioning, speed, Bench};
use crate::tests::TestFlash;
use crate::PnDrive;
use profidrive::telegram::FbTorque;

impl Bench {
    /// A PKW request in the receive telegram `t` after the 0x00 toggle: the
    /// response's code and value.
    fn pkw_in(&mut self, mut t: [u8; 36], code: u8, index: u16, sub: u8, value: u32) -> (u8, i32) {
        self.run(&t, 5);
        t[24..32].copy_from_slice(&pkw_request(code, index, sub, value));
        self.run(&t, 10);
        (self.response[24], self.i32_at(28))
    }

    /// A PKW request in receive telegram 0 after the 0x00 toggle.
    pub(super) fn pkw0(&mut self, code: u8, index: u16, sub: u8, value: u32) -> (u8, i32) {
        self.pkw_in(positioning(0x0400, 0, 100, 10_000), code, index, sub, value)
    }

    /// Writes each `(PNU, value)` (sub-index 0) by PKW in receive telegram
    /// 0, each acknowledged.
    fn pkw0_write_all(&mut self, settings: &[(u16, u32)]) {
        for &(pnu, value) in settings {
            assert_eq!(self.pkw0(0x42, pnu, 0, value).0, 0x42, "PNU {pnu} = {value}");
        }
    }

    /// Saves the parameters (PNU 971 = 1 by PKW) and gives back a new drive
    /// started over the same flash.
    fn saved_and_restarted(&mut self) -> PnDrive<TestFlash> {
        assert_eq!(self.pkw0(0x42, 971, 0, 1).0, 0x42, "saved");
        let flash = core::mem::replace(&mut self.d, crate::tests::commissioned()).into_flash();
        PnDrive::new(flash, crate::tests::hardware())
    }
}

/// `d`'s objects hold each `(index, value)` (sub-index 0).
fn holds(d: &PnDrive<TestFlash>, settings: &[(u16, u32)]) {
    for &(index, value) in settings {
        assert_eq!(d.objects().get(index, 0), Ok(i64::from(value)), "{index:04X}h");
    }
}

/// A manufacturer profile, not PROFIdrive's standard telegrams: standard
/// telegram 1 (STW1, NSOLL_A: no identifier byte) is not understood, the
/// drive neither moves nor answers it, and no telegram but E0…E3 exists.
#[test]
fn p044_standard_telegram_1_is_not_understood() {
    let mut b = Bench::new();
    // standard telegram 1: STW1 0x047F at bytes 0–1, NSOLL_A 0x4000 (100 %)
    let mut std1 = [0u8; 36];
    std1[0..2].copy_from_slice(&0x047Fu16.to_be_bytes());
    std1[2..4].copy_from_slice(&0x4000u16.to_be_bytes());
    b.run(&std1, 50);
    assert!(
        b.response.iter().all(|&x| x == 0),
        "no response telegram: {:02x?}",
        b.response
    );
    assert_eq!(b.d.objects().get(0x6040, 0), Ok(0), "controlword untouched");
    assert!(b.d.profile().warnings() > 0, "counted as unknown frames");
    let t = b.d.profile().telegrams().unwrap();
    for n in 4..8 {
        assert!(
            t.layout(profidrive::telegram::Dir::Receive, n).is_none(),
            "telegram {n}"
        );
    }
}

/// Any CANopen object is reachable from PROFINET in the one index space:
/// PKW reads the statusword 6041h and a manufacturer object (A150 at
/// 2096h), writes 6071h; the telegrams map CANopen objects (6071h in
/// telegram 2, 6077h in the responses).
#[test]
fn p045_canopen_objects_through_pkw_and_telegrams() {
    let mut b = Bench::new();
    let (code, sw) = b.pkw0(0x41, 0x6041, 0, 0);
    assert_eq!(code, 0x41);
    assert_eq!(i64::from(sw), b.d.objects().get(0x6041, 0).unwrap());
    let a150 = drive_core::params::A150;
    let (code, v) = b.pkw0(0x41, a150, 0, 0);
    assert_eq!((code, i64::from(v)), (0x41, b.d.objects().get(a150, 0).unwrap()));
    assert_eq!(b.pkw0(0x42, 0x6071, 0, 250).0, 0x42);
    assert_eq!(b.d.objects().get(0x6071, 0), Ok(250));
    // a missing object: error 0 (impermissible PNU), nothing written
    assert_eq!(b.pkw0(0x42, 0x6FFF, 0, 1), (0xC2, 0));
    let t = b.d.profile().telegrams().unwrap();
    let receive2 = t.layout(profidrive::telegram::Dir::Receive, 2).unwrap();
    assert!(receive2
        .slots()
        .iter()
        .any(|e| e.addr == profidrive::Addr::new(0x6071, 0)));
}

/// No 0x4000 normalisation: values are physical (rpm, 1/1000 rev): 100 rpm
/// in PNU 1010 is 6042h = 100 rpm, not 100/16384 of a reference speed.
#[test]
fn p046_values_are_physical_not_normalised() {
    let mut b = Bench::new();
    b.run(&speed(0x0400, 100, 10_000, [0; 8]), 10);
    assert_eq!(b.d.objects().get(0x6042, 0), Ok(100));
    b.run(&speed(0x0400, 0x4000, 10_000, [0; 8]), 10);
    assert_eq!(b.d.objects().get(0x6042, 0), Ok(0x4000), "16384 rpm, not 100 %");
}

/// The speed set-point PNU 1010 (6042h) is never saved: after PNU 971
/// saves and the drive restarts, it is 0 (P-132).
#[test]
fn p132_the_speed_setpoint_is_zero_after_a_restart() {
    let mut b = Bench::new();
    b.run(&speed(0x0400, 250, 10_000, [0; 8]), 10);
    assert_eq!(b.d.objects().get(0x6042, 0), Ok(250));
    b.run(&positioning(0x0400, 0, 100, 10_000), 5);
    let again = b.saved_and_restarted();
    assert_eq!(again.objects().get(0x6042, 0), Ok(0));
}

/// PNU 1271 (I22) is the target window of ZSW1 bit 10: the encoder 2°
/// from the target is inside a 5° window and outside a 1° one (P-158); a
/// PKW write takes the PROFINET position unit (1/1000 rev).
#[test]
fn p158_target_window_drives_bit_10() {
    const BIT_10: u16 = 0x0400;
    let deg = |d: f64| (d / 360.0 * f64::from(1 << 20)) as i32;
    let mut b = Bench::new();
    // 5° window = 13.9/1000 rev: 14
    assert_eq!(b.pkw0(0x42, 1271, 0, 14), (0x42, 14));
    assert_eq!(
        b.d.objects().get(drive_core::params::I22, 0),
        Ok(i64::from(14 * (1 << 20) / 1000))
    );
    for cw1 in [0x0406, 0x0407, 0x040F] {
        b.run(&positioning(cw1, 0, 1000, 10_000), 20);
    }
    b.run(&positioning(0x0C3F, 0, 1000, 10_000), 50); // home (method 34)
    b.run(&positioning(0x043F, 0, 1000, 10_000), 20);
    b.run(&positioning(0x047F, 0, 1000, 10_000), 100); // a task to 0
    assert_ne!(b.zsw1() & BIT_10, 0, "on the target: {:#06x}", b.zsw1());
    b.io[0].position_inc = deg(2.0);
    b.run(&positioning(0x047F, 0, 1000, 10_000), 200);
    assert_ne!(b.zsw1() & BIT_10, 0, "inside 5°: {:#06x}", b.zsw1());
    // 1° = 2.8/1000 rev: 3
    let mut t = positioning(0x047F, 0, 1000, 10_000);
    t[24..32].copy_from_slice(&pkw_request(0x42, 1271, 0, 3));
    b.run(&t, 200);
    assert_eq!(b.response[24], 0x42);
    assert_eq!(b.zsw1() & BIT_10, 0, "outside 1°: {:#06x}", b.zsw1());
}

impl Bench {
    /// Enabled in positioning and homed at the encoder's position (method
    /// 34), standing.
    fn enabled_and_homed(&mut self) {
        for cw1 in [0x0406, 0x0407, 0x040F] {
            self.run(&positioning(cw1, 0, 1000, 10_000), 20);
        }
        self.run(&positioning(0x0C3F, 0, 1000, 10_000), 50);
        self.run(&positioning(0x043F, 0, 1000, 10_000), 20);
    }
}

/// PNU 1270.2 (I23) is the position controller's dead band, in 1/1000 rev:
/// with the axis held 1000 increments off its set-point, no torque inside a
/// 2/1000 rev band (2097 increments), the correction without it (P-157).
/// PNU 1270 has no subindex 0 or 1.
#[test]
fn p157_inside_the_dead_band_the_position_controller_is_quiet() {
    let held_off = |band: Option<u32>| {
        let mut b = Bench::new();
        if let Some(band) = band {
            assert_eq!(b.pkw0(0x42, 1270, 2, band), (0x42, band as i32));
            assert_eq!(
                b.d.objects().get(drive_core::params::I23, 0),
                Ok(i64::from(band) * (1 << 20) / 1000)
            );
        }
        b.enabled_and_homed();
        assert_eq!(b.zsw1() & 0x0007, 0x0007, "enabled: {:#06x}", b.zsw1());
        // the jump's one-cycle velocity leaves the velocity controller's
        // integral part; after it only the position controller can act
        b.io[0].position_inc = 1000;
        b.run(&positioning(0x043F, 0, 1000, 10_000), 5);
        let early = b.commands[0].torque_nm;
        b.run(&positioning(0x043F, 0, 1000, 10_000), 100);
        (early, b.commands[0].torque_nm)
    };
    let (early, late) = held_off(Some(2));
    assert!(
        (late - early).abs() < 1e-3 && late.abs() < 0.01,
        "inside the band, nothing pulls: {early} → {late} N·m"
    );
    let (early, late) = held_off(None);
    assert!(
        late < -0.01 && late - early < -0.01,
        "without the band, pulled back: {early} → {late} N·m"
    );
    let mut b = Bench::new();
    assert_eq!(b.pkw0(0x41, 1270, 2, 0), (0x41, 0), "off by default");
    assert_eq!(b.pkw0(0x42, 1270, 0, 5), (0xC2, 3), "no subindex 0");
    assert_eq!(b.pkw0(0x41, 1270, 1, 0), (0xC1, 3), "no subindex 1");
    assert_eq!(b.d.objects().get(drive_core::params::I23, 0), Ok(0));
}

/// PNU 1273 (I21) is the position error limit, in 1/1000 rev: the encoder
/// pulled 2000 increments off the set-point passes a 1/1000 rev limit (1049
/// increments) and the drive faults at once with 54-2 (ZSW1 bit 3, PNU 1600
/// = 54 × 16 + 2); off by default, and the value a read of the default
/// returns writes the default back (P-160).
#[test]
fn p160_the_position_error_limit_faults_at_once() {
    let mut b = Bench::new();
    let i21 = drive_core::params::I21;
    let (code, off) = b.pkw0(0x41, 1273, 0, 0);
    assert_eq!((code, off), (0x41, 4_096_000), "u32::MAX increments");
    assert_eq!(b.pkw0(0x42, 1273, 0, 4_096_000).0, 0x42, "read value writes back");
    assert_eq!(b.d.objects().get(i21, 0), Ok(i64::from(u32::MAX)));
    assert_eq!(b.pkw0(0x42, 1273, 0, 4_096_001), (0xC2, 2), "beyond UINT32");
    assert_eq!(b.d.objects().get(i21, 0), Ok(i64::from(u32::MAX)), "unchanged");
    // off: far off the set-point, no fault
    b.enabled_and_homed();
    b.io[0].position_inc = 500_000;
    b.run(&positioning(0x043F, 0, 1000, 10_000), 3);
    assert_eq!(b.zsw1() & 0x0008, 0, "no limit: {:#06x}", b.zsw1());

    let mut b = Bench::new();
    assert_eq!(b.pkw0(0x42, 1273, 0, 1), (0x42, 1));
    assert_eq!(b.d.objects().get(i21, 0), Ok(1049));
    b.enabled_and_homed();
    b.io[0].position_inc = 1000;
    b.run(&positioning(0x043F, 0, 1000, 10_000), 3);
    assert_eq!(b.zsw1() & 0x0008, 0, "inside: {:#06x}", b.zsw1());
    b.io[0].position_inc = 2000;
    // the fault reaction (quick stop) runs first, then ZSW1 bit 3
    b.run(&positioning(0x043F, 0, 1000, 10_000), 50);
    assert_ne!(b.zsw1() & 0x0008, 0, "fault: {:#06x}", b.zsw1());
    b.run(&speed(0x0400, 0, 0, super::pkw_request(0x41, 1600, 0, 0)), 10);
    assert_eq!((b.response[24], b.i32_at(28)), (0x41, 54 * 16 + 2));
}

/// PNU 1051 (607Ch) is the home offset in 1/1000 rev: with method 34 the
/// present position becomes the offset (CiA 402's rule, which the core
/// follows: the zero point lies the offset below the reference point, so a
/// positive value shifts zero in the negative direction; docs/conformance.md,
/// P-162).
#[test]
fn p162_home_offset_in_position_units() {
    let mut b = Bench::new();
    assert_eq!(b.pkw0(0x42, 1051, 0, 500).0, 0x42);
    assert_eq!(
        b.d.objects().get(0x607C, 0),
        Ok(i64::from(1 << 19)),
        "half a revolution"
    );
    for cw1 in [0x0406, 0x0407, 0x040F] {
        b.run(&positioning(cw1, 0, 1000, 10_000), 20);
    }
    b.run(&positioning(0x0C3F, 0, 1000, 10_000), 50);
    b.run(&positioning(0x043F, 0, 1000, 10_000), 50);
    assert_ne!(b.zsw1() & 0x0800, 0, "homed");
    assert_eq!(b.i32_at(4), 500, "PNU 1100 at the reference point");
}

/// Methods −23/−27 (end of travel, then the last of several reference
/// switches on one input) are not built: PNU 1050 refuses them with error
/// 0x14 and keeps the method it had (P-169, P-172).
#[test]
fn p169_methods_minus_23_and_minus_27_are_refused() {
    // telegram 1: telegram 0 writes 1050.0 from its byte 1 every cycle
    let mut b = Bench::new();
    let write = |b: &mut Bench, m: i32| {
        b.run(&speed(0x0400, 0, 10_000, [0; 8]), 5);
        b.run(
            &speed(0x0400, 0, 10_000, pkw_request(0x42, 1050, 0, m as u32)),
            10,
        );
        (b.response[24], b.i32_at(28))
    };
    assert_eq!(write(&mut b, 33).0, 0x42);
    for m in [-23, -27] {
        assert_eq!(write(&mut b, m), (0xC2, 0x14), "method {m}");
    }
    assert_eq!(b.d.profile().own().homing_method, 33);
}

/// PNU 1110.0/.1: the position latched on the rising and the falling edge
/// of the sample input (touch probe 1, enabled for both edges in 60B8h),
/// in the PROFINET position unit (P-188).
#[test]
fn p188_pnu_1110_sampling_positions() {
    use drive_core::axis::ProbeEdge;
    let mut b = Bench::new();
    // probe 1 on, continuous, input 1, both edges
    b.d.objects_mut().set(0x60B8, 0, 0x0033).unwrap();
    b.run(&speed(0x0400, 0, 10_000, [0; 8]), 10);
    let edge = |rising: bool, at: i32, t: u64| ProbeEdge {
        input: 1,
        rising,
        time_ns: nanos::Nanos::from_ms(t),
        position_inc: Some(at),
    };
    let t = b.ms;
    b.io[0].probe_edges[0] = Some(edge(true, 1 << 20, t));
    b.run(&speed(0x0400, 0, 10_000, [0; 8]), 1);
    b.io[0].probe_edges[0] = Some(edge(false, 3 << 19, t + 1));
    b.run(&speed(0x0400, 0, 10_000, [0; 8]), 1);
    b.io[0].probe_edges[0] = None;
    assert_eq!(b.pkw0(0x41, 1110, 0, 0), (0x41, 1000), "rising: 1 rev");
    assert_eq!(b.pkw0(0x41, 1110, 1, 0), (0x41, 1500), "falling: 1.5 rev");
    // read-only
    b.run(&speed(0x0400, 0, 10_000, [0; 8]), 5);
    b.run(&speed(0x0400, 0, 10_000, pkw_request(0x42, 1110, 0, 1)), 10);
    assert_eq!((b.response[24], b.i32_at(28)), (0xC2, 0x01));
}

/// CANopen objects keep the CANopen factor group, PNUs the PROFINET
/// units: with a feed of 60 user units per revolution (6092h), 6064h reads
/// in 1/60 rev while PNU 1100 still reads 1/1000 rev (P-214).
#[test]
fn p214_canopen_objects_use_their_factor_group_pnus_the_profinet_units() {
    let mut b = Bench::new();
    b.d.objects_mut().set(0x6092, 1, 60).unwrap();
    b.d.objects_mut().set(0x6092, 2, 1).unwrap();
    b.io[0].position_inc = 2 << 20;
    b.run(&speed(0x0400, 0, 10_000, [0; 8]), 50);
    assert_eq!(
        b.pkw0(0x41, 0x6064, 0, 0),
        (0x41, 120),
        "6064h: 2 rev in 1/60 rev"
    );
    assert_eq!(
        b.pkw0(0x41, 1100, 0, 0),
        (0x41, 2000),
        "PNU 1100: 2 rev in 1/1000 rev"
    );
    assert_eq!(b.i32_at(4), 2000, "the response telegram's 1100.0");
}

/// A PKW request in receive telegram 2, which maps no jog entry (telegrams
/// 0 and 1 write 1040.0 every cycle).
pub(super) fn pkw2(b: &mut Bench, code: u8, index: u16, sub: u8, value: u32) -> (u8, i32) {
    let t = frame(|f| {
        FbTorque {
            cw1: 0x0400,
            ..FbTorque::default()
        }
        .write(f)
    });
    b.pkw_in(t, code, index, sub, value)
}

/// PNU 1041 (TIPP0, record 259) and 1042 (TIPP1, record 260): .0 the
/// velocity, .1 the acceleration, .2 the deceleration, .3 writes both
/// and reads .1; each direction's record only (P-174, P-175).
#[test]
fn p174_p175_jog_records_per_direction() {
    use drive_core::objects::records::{JOG_NEGATIVE, JOG_POSITIVE};
    let inc = |rpm: f64| (rpm * f64::from(1 << 20) / 60.0).round() as u32;
    let mut b = Bench::new();
    for (pnu, mine, other) in [
        (1041, JOG_POSITIVE, JOG_NEGATIVE),
        (1042, JOG_NEGATIVE, JOG_POSITIVE),
    ] {
        let before = b.d.objects().record(0, other).unwrap();
        assert_eq!(pkw2(&mut b, 0x42, pnu, 0, 250).0, 0x42);
        assert_eq!(pkw2(&mut b, 0x42, pnu, 1, 2000).0, 0x42);
        assert_eq!(pkw2(&mut b, 0x42, pnu, 2, 3000).0, 0x42);
        let r = b.d.objects().record(0, mine).unwrap();
        assert_eq!(
            (r.profile_velocity, r.acceleration, r.deceleration),
            (inc(250.0), inc(2000.0), inc(3000.0))
        );
        assert_eq!(pkw2(&mut b, 0x41, pnu, 0, 0), (0x41, 250));
        assert_eq!(pkw2(&mut b, 0x42, pnu, 3, 1500).0, 0x42);
        let r = b.d.objects().record(0, mine).unwrap();
        assert_eq!(
            (r.acceleration, r.deceleration),
            (inc(1500.0), inc(1500.0)),
            "sub 3 writes both"
        );
        assert_eq!(pkw2(&mut b, 0x41, pnu, 3, 0), (0x41, 1500), "sub 3 reads sub 1");
        assert_eq!(
            b.d.objects().record(0, other).unwrap(),
            before,
            "record {other} untouched"
        );
    }
}

/// A279 chooses the PROFINET units: the position in 1/10 degree reads one
/// revolution as 3600 in PNU 1100 (P-208); gear and feed take positive
/// values only (P-213: 0 is out of range).
#[test]
fn p208_p213_a279_chooses_the_units() {
    let a279 = drive_core::params::A279;
    let mut b = Bench::new();
    b.io[0].position_inc = 1 << 20;
    assert_eq!(pkw2(&mut b, 0x42, a279, 1, 0x0101).0, 0x42, "1/10 degree");
    b.run(&speed(0x0400, 0, 10_000, [0; 8]), 20);
    assert_eq!(b.i32_at(4), 3600, "PNU 1100 in 1/10 degree");
    assert_eq!(
        pkw2(&mut b, 0x42, a279, 4, 0),
        (0xC2, 0x02),
        "gear 0: limit exceeded"
    );
    assert_eq!(b.d.objects().get(a279, 4), Ok(1));
}

/// A unit setting whose conversion does not fit 32-bit fractions raises the
/// error 22-4 (event 70 cause 4: ZSW1 bit 3, PNU 1600 = 70 × 16 + 4) and the
/// previous units stay; after Save & Reset the drive raises it again at
/// start (the setting is really invalid) and runs on the default units
/// (P-211, P-212).
#[test]
fn p211_p212_an_overflowing_unit_setting_raises_22_4_and_keeps_the_units() {
    let a279 = drive_core::params::A279;
    let mut b = Bench::new();
    b.io[0].position_inc = 1 << 20;
    b.run(&speed(0x0400, 0, 10_000, [0; 8]), 20);
    assert_eq!(b.i32_at(4), 1000);
    let before = *b.d.profile().units();
    // two large primes as gear: the fraction needs more than 32 bits
    assert_eq!(pkw2(&mut b, 0x42, a279, 4, 4_294_967_291).0, 0x42);
    assert_eq!(pkw2(&mut b, 0x42, a279, 5, 4_294_967_279).0, 0x42);
    b.run(&speed(0x0400, 0, 10_000, [0; 8]), 20);
    assert_ne!(b.zsw1() & 0x0008, 0, "22-4 is a fault: {:#06x}", b.zsw1());
    assert_eq!(pkw2(&mut b, 0x41, 1600, 0, 0), (0x41, 70 * 16 + 4));
    assert_eq!(*b.d.profile().units(), before, "the units stay");
    assert_eq!(b.i32_at(4), 1000, "PNU 1100 still in 1/1000 rev");
    // saved and started again: raised at start, default units
    assert_eq!(pkw2(&mut b, 0x42, 971, 0, 1).0, 0x42);
    let flash = core::mem::replace(&mut b.d, crate::tests::commissioned()).into_flash();
    b.d = crate::tests::connected(PnDrive::new(flash, crate::tests::hardware()));
    b.run(&speed(0x0400, 0, 10_000, [0; 8]), 20);
    assert_ne!(
        b.zsw1() & 0x0008,
        0,
        "raised again after the restart: {:#06x}",
        b.zsw1()
    );
    assert_eq!(
        *b.d.profile().units(),
        motion::units::UnitProfile::default_profile()
    );
}

/// PNU 1003, the position profile type: 0 (jerk filter 0, what record
/// tasks do) reads and writes; 1 (the automatic jerk filter) is refused
/// with 0x14, anything else with 0x02 (P-147, P-148).
#[test]
fn p147_p148_pnu_1003_profile_type() {
    let mut b = Bench::new();
    assert_eq!(pkw2(&mut b, 0x41, 1003, 0, 0), (0x41, 0));
    assert_eq!(pkw2(&mut b, 0x42, 1003, 0, 0).0, 0x42);
    assert_eq!(
        pkw2(&mut b, 0x42, 1003, 0, 1),
        (0xC2, 0x14),
        "automatic jerk: not built"
    );
    assert_eq!(pkw2(&mut b, 0x42, 1003, 0, 2), (0xC2, 0x02));
    assert_eq!(pkw2(&mut b, 0x41, 1003, 0, 0), (0x41, 0));
}

/// The axis settings of the one declaration through PKW in the
/// manufacturer range (PNU = index, issue 40): G472 (2DD8h) and the
/// velocity controller's C31 (241Fh) written and read back; a value beyond
/// G472's range gets PKW error 2 (limit exceeded) and changes nothing;
/// PNU 971 saves them and a new drive over the same flash starts with them.
#[test]
fn p045_issue40_g472_and_c31_through_pkw_saved_and_read_after_a_restart() {
    use drive_core::params::{C31, G472};
    let mut b = Bench::new();
    assert_eq!(b.pkw0(0x41, G472, 0, 0), (0x41, 0), "0 % by default");
    assert_eq!(
        b.pkw0(0x42, G472, 0, 1001),
        (0xC2, 2),
        "beyond 100 %: limit exceeded"
    );
    assert_eq!(b.d.objects().get(G472, 0), Ok(0), "unchanged");
    let settings = [(G472, 300), (C31, 45_000)];
    b.pkw0_write_all(&settings);
    assert_eq!(b.pkw0(0x41, G472, 0, 0), (0x41, 300));
    assert_eq!(b.pkw0(0x41, C31, 0, 0), (0x41, 45_000));
    holds(&b.saved_and_restarted(), &settings);
}

/// The homing, interpolation and speed settings of issue 40 through PKW
/// (PNU = index): I28, I53, I425, I10 written and read back; I28 beyond
/// 300 % and I425 = 2 get PKW error 2 and change nothing; PNU 971 saves
/// them and a new drive over the same flash starts with them.
#[test]
fn p045_issue40_homing_and_speed_settings_through_pkw_saved_and_read_after_a_restart() {
    use drive_core::params::{I10, I28, I425, I53};
    let mut b = Bench::new();
    assert_eq!(b.pkw0(0x41, I28, 0, 0), (0x41, 1000), "100 % by default");
    assert_eq!(b.pkw0(0x42, I28, 0, 3001), (0xC2, 2), "beyond 300 %");
    assert_eq!(b.pkw0(0x42, I425, 0, 2).0, 0xC2, "I425 = 2 refused");
    assert_eq!(b.d.objects().get(I28, 0), Ok(1000), "unchanged");
    assert_eq!(b.d.objects().get(I425, 0), Ok(0), "unchanged");
    let settings = [(I28, 400), (I425, 4), (I53, 4096), (I10, 20 << 20)];
    b.pkw0_write_all(&settings);
    assert_eq!(b.pkw0(0x41, I28, 0, 0), (0x41, 400));
    holds(&b.saved_and_restarted(), &settings);
}

/// The motor data of issue 34 through PKW (PNU = index): B10 pole pairs,
/// B73 thermal time constant, U11 i²t warning time and 6075h rated current
/// written and read back; B10 = 0 and 6075h = 0 get PKW error 2 (limit
/// exceeded: below the range) and change nothing; PNU 971 saves them and a
/// new drive over the same flash starts with them (P-133's mA limit refers
/// to the rated current read from there).
#[test]
fn p045_issue34_motor_data_through_pkw_saved_and_read_after_a_restart() {
    use drive_core::params::{B10, B73, U11};
    let mut b = Bench::new();
    assert_eq!(b.pkw0(0x41, B10, 0, 0), (0x41, 4), "4 pole pairs by default");
    assert_eq!(b.pkw0(0x42, B10, 0, 0), (0xC2, 2), "0 pole pairs refused");
    assert_eq!(b.pkw0(0x42, 0x6075, 0, 0), (0xC2, 2), "0 mA refused");
    assert_eq!(b.d.objects().get(B10, 0), Ok(4), "unchanged");
    assert_eq!(b.d.objects().get(0x6075, 0), Ok(2000), "unchanged");
    let settings = [(B10, 5), (B73, 900_000), (U11, 2_000), (0x6075, 2_500)];
    b.pkw0_write_all(&settings);
    assert_eq!(b.pkw0(0x41, B10, 0, 0), (0x41, 5));
    holds(&b.saved_and_restarted(), &settings);
}

/// The power stage's data and the DC-link window of issue 34 through PKW
/// (PNU = index): A38 (chopper threshold) at or above the over-voltage trip
/// A40 and A35 (low voltage limit) at or above A38 − 20 V get PKW error 2
/// (limit exceeded) and change nothing; A40 (the stage's hardware) is read
/// only (error 1); a consistent A38 is taken.
#[test]
fn p045_issue34_dc_link_window_through_pkw_refused_where_written() {
    use drive_core::params::{A35, A38, A40};
    let mut b = Bench::new();
    assert_eq!(b.pkw0(0x41, A40, 0, 0), (0x41, 800), "800 V over-voltage trip");
    assert_eq!(b.pkw0(0x42, A38, 0, 800), (0xC2, 2), "threshold at the trip");
    assert_eq!(
        b.pkw0(0x42, A35, 0, 745),
        (0xC2, 2),
        "limit above threshold − hysteresis"
    );
    assert_eq!(b.pkw0(0x42, A40, 0, 900), (0xC2, 1), "read only");
    assert_eq!(b.d.objects().get(A38, 0), Ok(760), "unchanged");
    assert_eq!(b.d.objects().get(A35, 0), Ok(400), "unchanged");
    assert_eq!(b.pkw0(0x42, A38, 0, 700).0, 0x42);
    assert_eq!(b.d.objects().get(A38, 0), Ok(700));
}
