//! CiA 402 items through a real master that the mode scenarios of
//! motion/*.rs / motion_more.rs do not name (features-cia402.md): mode 0,
//! replacing commands, the velocity override A340, the cyclic modes without
//! mode bits, the pp set-point handshake and absolute moves, switch sources
//! from I210, E80, reference retaining I46, the position encoder I02, the
//! user status word A66/A67 and the set-value monitor. Every check reads
//! what the master received (TxPDO or SDO) or the plant's encoder.

use drive_ecat::parameter_index;
use drive_tests::axis::*;
use drive_tests::{init, line, motor_rev_s, sw, with_cyclic, with_master, Cyclic};
use drive_tests::{REV, REV_F};

const A66: u16 = parameter_index(0, 66);
const A340: u16 = parameter_index(0, 340);
const E80: u16 = parameter_index(4, 80);
const I02: u16 = parameter_index(8, 2);
const I46: u16 = parameter_index(8, 46);
const I101: u16 = parameter_index(8, 101);
const I102: u16 = parameter_index(8, 102);
const I210: u16 = parameter_index(8, 210);

/// A bit-4 edge in pp with `bits`; returns whether bit 12 acknowledged it
/// within 5 cycles (bit 4 is taken back afterwards).
async fn pp_edge(m: &mut Cyclic<'_>, target: i32, bits: u16) -> bool {
    m.set_target_position(target);
    m.set_controlword(CW_ENABLED | bits);
    m.run(1).await;
    m.set_controlword(CW_ENABLED | bits | CW_BIT4);
    let ack = m.run_until(5, |t| t.bit(12)).await.is_some();
    m.set_controlword(CW_ENABLED | bits);
    m.run(2).await;
    ack
}

/// [`pp_edge`] that must be taken, the move [`settle`]d within `max`
/// cycles, then 20 cycles more.
async fn pp_move(m: &mut Cyclic<'_>, target: i32, bits: u16, max: usize) {
    assert!(pp_edge(m, target, bits).await, "taken");
    settle(m, max).await.expect("arrives");
    m.run(20).await;
}

/// Waits until bit 10 (target reached) and standstill.
async fn settle(m: &mut Cyclic<'_>, max: usize) -> Option<usize> {
    m.run_until(max, |t| t.bit(10) && t.velocity.abs() < REV / 200)
        .await
}

// ---------------------------------------------------------------------------
// C-028 mode 0, C-029 replacing commands
// ---------------------------------------------------------------------------

#[test]
fn c028_mode_0_generates_no_motion() {
    let sim = line(1);
    with_cyclic(&sim, async |m, _| {
        let tx = m.enable_in(0).await;
        assert_eq!(tx.mode_display, 0, "6061h shows mode 0");
        let p0 = motor_position(&sim, 0);
        // every set-point of every mode and all mode bits: nothing moves
        m.set_target_position(3 * REV);
        m.set_target_velocity(2 * REV);
        m.set_target_torque(300);
        m.set_controlword(CW_ENABLED | CW_BIT4 | CW_BIT5 | CW_BIT6);
        let tx = m.run(300).await;
        let moved = motor_position(&sim, 0) - p0;
        println!("mode 0: moved {moved} inc, 6077h {}", tx.torque);
        assert_eq!(tx.state(), sw::OE);
        assert!(moved.abs() < 50, "no motion in mode 0: {moved}");
        assert!(tx.velocity.abs() < REV / 1000, "606Ch {}", tx.velocity);
        // the same outputs in csv move the axis (the check above could fail)
        m.set_controlword(CW_ENABLED);
        m.set_mode(9);
        m.run(300).await;
        assert!(motor_position(&sim, 0) - p0 > i64::from(REV) / 4, "csv moves");
    });
}

#[test]
fn c029_running_move_is_replaced_but_not_during_a_stop() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        sd.sdo_write(0x6081, 0, (2 * REV) as u32).await.unwrap();
        // 605Ah = 6: quick stop ramp, then stay in Quick stop active
        sd.sdo_write(0x605A, 0, 6i16).await.unwrap();
        m.enable_in(1).await;
        // relative move +5 rev, replaced after 0.4 s by −1 rev (bit 5: at once)
        assert!(pp_edge(m, 5 * REV, CW_BIT6).await, "first move taken");
        m.run(400).await;
        let mid = m.tx.position;
        assert!(mid > REV / 4, "moving: {mid}");
        // 60F2h = 10b: relative to the actual position, −2 rev, at once (bit 5)
        sd.sdo_write(0x60F2, 0, 2u16).await.unwrap();
        assert!(
            pp_edge(m, -2 * REV, CW_BIT5 | CW_BIT6).await,
            "replacement acknowledged: {:#06x}",
            m.tx.statusword
        );
        settle(m, 5000).await.expect("replacement done");
        let end = m.tx.position;
        println!("C-029: replaced at {mid}, ends at {end} (first target 5 rev)");
        assert!(
            end < 0,
            "the new command replaced the running one: ended at {end}"
        );

        // during the stop (quick stop, 605Ah = 6) a new command is not taken
        assert!(pp_edge(m, 4 * REV, CW_BIT6).await, "move taken");
        m.run(300).await;
        m.set_controlword(0x000B); // quick stop
        let qs = m
            .run_until(2000, |t| t.state() == sw::QSA && t.velocity.abs() < REV / 200)
            .await;
        assert!(qs.is_some(), "quick stop active: {:#06x}", m.tx.statusword);
        m.run(30).await;
        assert_eq!(m.tx.state(), sw::QSA, "605Ah = 6 stays in Quick stop active");
        let at = motor_position(&sim, 0);
        m.set_target_position(3 * REV);
        m.set_controlword(0x000B | CW_BIT5 | CW_BIT6);
        m.run(2).await;
        m.set_controlword(0x000B | CW_BIT4 | CW_BIT5 | CW_BIT6);
        let tx = m.run(300).await;
        let moved = motor_position(&sim, 0) - at;
        assert!(
            !tx.bit(12),
            "no set-point acknowledge while stopped: {:#06x}",
            tx.statusword
        );
        assert!(moved.abs() < 200, "no motion while stopped: {moved}");
        assert_eq!(tx.state(), sw::QSA);
    });
}

// ---------------------------------------------------------------------------
// C-030 velocity override A340
// ---------------------------------------------------------------------------

#[test]
fn c030_velocity_override_a340_in_pv_pp_and_vl() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        let ovr: u16 = sd.sdo_read(A340, 0).await.unwrap();
        assert_eq!(ovr, 100, "A340 default 100 %");
        m.enable_in(3).await;

        // pv: 60FFh = 2 rev/s at 50 % → 1 rev/s, back to 100 % → 2 rev/s
        sd.sdo_write(A340, 0, 50u16).await.unwrap();
        m.set_target_velocity(2 * REV);
        m.run(600).await;
        let v50 = f64::from(m.tx.velocity) / REV_F;
        sd.sdo_write(A340, 0, 100u16).await.unwrap();
        m.run(600).await;
        let v100 = f64::from(m.tx.velocity) / REV_F;
        println!("pv: 50 % → {v50:.3} rev/s, 100 % → {v100:.3} rev/s");
        assert!((v50 - 1.0).abs() < 0.03, "pv at 50 %: {v50}");
        assert!((v100 - 2.0).abs() < 0.03, "pv at 100 %: {v100}");
        m.set_target_velocity(0);
        m.run_until(2000, |t| t.bit(12)).await.expect("zero speed");
        m.run(100).await;

        // pp: 6081h = 2 rev/s at 50 % peaks at 1 rev/s; 0 % pauses, 100 % resumes
        sd.sdo_write(0x6081, 0, (2 * REV) as u32).await.unwrap();
        sd.sdo_write(A340, 0, 50u16).await.unwrap();
        m.set_mode(1);
        m.run(20).await;
        assert_eq!(m.tx.mode_display, 1, "pp: {:#06x}", m.tx.statusword);
        let start = m.tx.position;
        assert!(pp_edge(m, 4 * REV, CW_BIT6).await, "move taken");
        // cruise speed from the travel over 0.2 s
        let p1 = m.run(300).await.position;
        let p2 = m.run(200).await.position;
        let peak50 = f64::from(p2 - p1) / REV_F / 0.2;
        sd.sdo_write(A340, 0, 0u16).await.unwrap();
        m.run(300).await;
        let paused_at = m.tx.position;
        let tx = m.run(100).await;
        println!(
            "pp: cruise at 50 % {peak50:.3} rev/s, paused at {:.3} rev",
            f64::from(paused_at - start) / REV_F
        );
        assert!((peak50 - 1.0).abs() < 0.02, "pp cruise at 50 %: {peak50}");
        // (the cascade settles with some stick-slip on the plant's friction)
        assert!(
            (tx.position - paused_at).abs() < REV / 100,
            "0 % pauses: {} → {} ({} inc/s)",
            paused_at,
            tx.position,
            tx.velocity
        );
        assert!(
            !tx.bit(10),
            "paused is not target reached: {:#06x}",
            tx.statusword
        );
        assert!(paused_at - start < 4 * REV - REV / 2, "paused before the target");
        sd.sdo_write(A340, 0, 100u16).await.unwrap();
        settle(m, 5000).await.expect("resumes and arrives");
        let end = m.tx.position - start;
        assert!((end - 4 * REV).abs() < REV / 300, "arrives at +4 rev: {end}");

        // vl: 6042h = 120 rpm at 50 % → 6043h 60 rpm
        sd.sdo_write(A340, 0, 50u16).await.unwrap();
        sd.sdo_write(0x6042, 0, 120i16).await.unwrap();
        m.set_mode(2);
        m.set_controlword(CW_ENABLED | CW_BIT4 | CW_BIT5 | CW_BIT6);
        m.run(2000).await;
        let demand: i16 = sd.sdo_read(0x6043, 0).await.unwrap();
        let actual = f64::from(m.tx.velocity) / REV_F * 60.0;
        println!("vl: 6043h {demand} rpm, actual {actual:.1} rpm");
        assert_eq!(m.tx.mode_display, 2);
        assert_eq!(demand, 60, "vl demand at 50 %");
        assert!((actual - 60.0).abs() < 2.0, "vl actual: {actual}");
    });
}

// ---------------------------------------------------------------------------
// C-040 cyclic modes without mode bits
// ---------------------------------------------------------------------------

#[test]
fn c040_csp_csv_cst_need_no_mode_specific_controlword_bits() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await.into_op(md).await.expect("OP");
        let mut m = Cyclic::new(md, &group, &sim, 0);
        m.enable_in(9).await;
        // csv: the same velocity with controlword 000Fh and with bits 4, 5, 6, 8, 9
        let mut speeds = Vec::new();
        for cw in [
            CW_ENABLED,
            CW_ENABLED | CW_BIT4 | CW_BIT5 | CW_BIT6 | CW_HALT | 1 << 9,
        ] {
            m.set_controlword(cw);
            m.set_target_velocity(REV);
            m.run(500).await;
            speeds.push(f64::from(m.tx.velocity) / REV_F);
            assert!(m.tx.bit(12), "csv follows (bit 12): {:#06x}", m.tx.statusword);
        }
        println!("csv at 1 rev/s: {speeds:?}");
        for v in &speeds {
            assert!((v - 1.0).abs() < 0.02, "csv velocity {v}");
        }
        m.set_target_velocity(0);
        m.set_controlword(CW_ENABLED);
        m.run(300).await;

        // csp: a ramp of 0.5 rev/s followed with both controlwords
        m.set_mode(8);
        let mut p = m.tx.position;
        m.set_target_position(p);
        m.run(20).await;
        for cw in [
            CW_ENABLED,
            CW_ENABLED | CW_BIT4 | CW_BIT5 | CW_BIT6 | CW_HALT | 1 << 9,
        ] {
            m.set_controlword(cw);
            let before = m.tx.position;
            for _ in 0..500 {
                p += REV / 2000;
                m.set_target_position(p);
                m.cycle().await;
            }
            let moved = m.tx.position - before;
            assert!(m.tx.bit(12), "csp follows (bit 12): {:#06x}", m.tx.statusword);
            assert!(
                (moved - REV / 4).abs() < REV / 100,
                "csp with {cw:#06x}: moved {moved}"
            );
        }
        m.set_controlword(CW_ENABLED);
        m.run(50).await;

        // cst: the torque acts with and without the bits (speed limits
        // G472/G475 lifted by SDO to 10 % of I10, 5 rev/s)
        let sd = group.subdevice(md, 0).unwrap();
        sd.sdo_write(drive_ecat::params::G472, 0, 100u16).await.unwrap();
        sd.sdo_write(drive_ecat::params::G475, 0, 100u16).await.unwrap();
        m.set_mode(10);
        m.run(20).await;
        for cw in [CW_ENABLED, CW_ENABLED | CW_BIT4 | CW_BIT5 | CW_BIT6 | CW_HALT] {
            m.set_controlword(cw);
            m.set_target_torque(50);
            let tx = m.run(20).await;
            assert!(tx.bit(12), "cst follows (bit 12): {:#06x}", tx.statusword);
            assert!(tx.torque > 0, "cst torque with {cw:#06x}: {}", tx.torque);
            m.set_target_torque(0);
            m.run(20).await;
        }
    });
}

// ---------------------------------------------------------------------------
// C-042, C-045, C-050 pp handshake and absolute moves
// ---------------------------------------------------------------------------

#[test]
fn c042_c050_setpoint_acknowledge_only_for_accepted_targets() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        sd.sdo_write(0x6081, 0, REV as u32).await.unwrap();
        m.enable_in(1).await;
        let p0 = motor_position(&sim, 0);
        // not referenced: an absolute target is refused, no acknowledge, no motion (C-050)
        assert!(
            !pp_edge(m, REV, 0).await,
            "absolute refused: {:#06x}",
            m.tx.statusword
        );
        m.run(300).await;
        assert!((motor_position(&sim, 0) - p0).abs() < 100, "no motion");
        // a relative one is accepted and acknowledged (C-042)
        assert!(pp_edge(m, REV, CW_BIT6).await, "relative taken");
        m.run(100).await;
        // while it runs, bit 5 = 0: a new target is not accepted, bit 12 stays 0 (C-043)
        assert!(
            !pp_edge(m, REV, CW_BIT6).await,
            "not accepted while moving: {:#06x}",
            m.tx.statusword
        );
        settle(m, 3000).await.expect("arrives");
        let end = motor_position(&sim, 0) - p0;
        assert!(
            (end - i64::from(REV)).abs() < i64::from(REV / 300),
            "one move only: {end}"
        );
        // referenced: the absolute target is now acknowledged and reached (C-050)
        home_here(m).await;
        m.set_mode(1);
        m.run(10).await;
        assert!(pp_edge(m, REV / 2, 0).await, "absolute taken once referenced");
        settle(m, 3000).await.expect("arrives");
        assert!(
            (m.tx.position - REV / 2).abs() < REV / 300,
            "at 0.5 rev: {}",
            m.tx.position
        );
    });
}

#[test]
fn c045_bit_6_clear_moves_to_the_absolute_position() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        sd.sdo_write(0x6081, 0, (2 * REV) as u32).await.unwrap();
        m.enable_in(6).await;
        home_here(m).await;
        m.set_mode(1);
        m.run(10).await;
        // 607Ah = 1.5 rev absolute, twice: the second move goes nowhere
        for k in 0..2 {
            pp_move(m, 3 * REV / 2, 0, 3000).await;
            let p = m.tx.position;
            println!("absolute move {k}: 6064h {p}");
            assert!((p - 3 * REV / 2).abs() < REV / 300, "at 1.5 rev: {p}");
        }
        // the same value relative (bit 6) would move on: contrast
        pp_move(m, 3 * REV / 2, CW_BIT6, 3000).await;
        assert!(
            (m.tx.position - 3 * REV).abs() < REV / 300,
            "relative: {}",
            m.tx.position
        );
        // and back to an absolute −0.5 rev
        pp_move(m, -REV / 2, 0, 5000).await;
        assert!(
            (m.tx.position + REV / 2).abs() < REV / 300,
            "at −0.5 rev: {}",
            m.tx.position
        );
    });
}

// ---------------------------------------------------------------------------
// C-104 switch signals from I210, C-107 E80
// ---------------------------------------------------------------------------

#[test]
fn c104_c107_limit_switches_from_i210_and_e80() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        sd.sdo_write(I101, 0, 2u8).await.unwrap();
        sd.sdo_write(I102, 0, 2u8).await.unwrap();
        m.csv_at(REV, 200).await;
        assert_eq!(m.tx.state(), sw::OE);
        let e80: u8 = sd.sdo_read(E80, 0).await.unwrap();
        assert_eq!(e80, 0, "E80 without limitation");
        // the fieldbus sets +LS (I210 bit 0): limit-switch fault at once
        sd.sdo_write(I210, 0, 1u16).await.unwrap();
        let hit = m.run_until(100, |t| t.state() == sw::FAULT).await;
        assert!(hit.is_some(), "fault from I210: {:#06x}", m.tx.statusword);
        assert!(m.tx.digital_inputs & 0b10 != 0, "60FDh bit 1 shows +LS");
        let code: u16 = sd.sdo_read(0x603F, 0).await.unwrap();
        assert_eq!(
            Some(code),
            drive_ecat::faults::fault_code_for_event(53).map(|(c, _)| c),
            "event 53"
        );
        m.set_target_velocity(0);
        m.reset_and_enable().await;
        // still on the switch: positive locked, E80 = 20 (C-107)
        m.set_target_velocity(REV);
        m.run(200).await;
        let e80: u8 = sd.sdo_read(E80, 0).await.unwrap();
        let at = m.tx.position;
        m.run(100).await;
        println!("on +LS from I210: E80 {e80}, statusword {:#06x}", m.tx.statusword);
        assert_eq!(e80, 20, "E80 = 20 limit switch");
        assert!(m.tx.bit(11), "internal limit: {:#06x}", m.tx.statusword);
        assert!((m.tx.position - at).abs() < REV / 200, "positive refused");
        // the hardware input is not the source: the plant has no switch, I210 alone decides
        sd.sdo_write(I210, 0, 0u16).await.unwrap();
        m.set_target_velocity(-REV);
        m.run(300).await;
        m.set_target_velocity(REV / 2);
        m.run(300).await;
        assert_eq!(m.tx.state(), sw::OE, "I210 cleared: moving again");
        assert!(m.tx.velocity > REV / 4, "positive free: {}", m.tx.velocity);
        let e80: u8 = sd.sdo_read(E80, 0).await.unwrap();
        assert_eq!(e80, 0, "E80 cleared");
    });
}

#[test]
fn c107_e80_shows_illegal_direction_on_an_endless_axis() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        // I00 = 1 "endless" by SDO in Pre-Op, I04 = 1 positive only (issue 40)
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        sd.sdo_write(drive_ecat::params::I00, 0, 1u8).await.unwrap();
        sd.sdo_write(drive_ecat::params::I04, 0, 1u8).await.unwrap();
        assert!(
            sd.sdo_write(drive_ecat::params::I04, 0, 3u8).await.is_err(),
            "I04 = 3 is out of range"
        );
        let group = group.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).unwrap();
        let mut m = Cyclic::new(md, &group, &sim, 0);
        m.csv_at(REV / 2, 300).await;
        let e80: u8 = sd.sdo_read(E80, 0).await.unwrap();
        assert_eq!(e80, 15, "E80 = 15 illegal direction (negative locked)");
        assert!(m.tx.velocity > REV / 4, "the permitted direction moves");
        let at = m.tx.position;
        m.set_target_velocity(-REV / 2);
        m.run(300).await;
        println!(
            "I04 positive only: E80 {e80}, −0.5 rev/s from {at} → {} ({} inc/s)",
            m.tx.position, m.tx.velocity
        );
        assert!(m.tx.position >= at, "negative refused: {} vs {at}", m.tx.position);
        assert!(m.tx.velocity.abs() < REV / 100, "stopped: {}", m.tx.velocity);
        assert!(m.tx.bit(11), "internal limit: {:#06x}", m.tx.statusword);
    });
}

// ---------------------------------------------------------------------------
// C-112 reference retaining I46 = 5, C-113 position encoder I02
// ---------------------------------------------------------------------------

#[test]
fn c112_direct_absolute_encoder_position_without_homing() {
    let sim = line(1);
    let start = 3 * i64::from(REV) + 123_457;
    with_drive(&sim, |d| d.motors[0].set_position_inc(start));
    with_cyclic(&sim, async |m, sd| {
        m.set_mode(1);
        let tx = m.run(3).await;
        println!("power-up: 6064h {} (encoder {start})", tx.position);
        assert_eq!(
            i64::from(tx.position),
            start,
            "the absolute encoder position in 6064h"
        );
        m.enable().await;
        // I46 = 0: not referenced, absolute pp refused
        assert!(!pp_edge(m, 2 * REV, 0).await, "absolute refused with I46 = 0");
        // I46 = 5 (direct absolute, I02 = 0): referenced as it is
        sd.sdo_write(I46, 0, 5u8).await.unwrap();
        m.run(2).await;
        assert!(pp_edge(m, 2 * REV, 0).await, "absolute taken with I46 = 5");
        settle(m, 5000).await.expect("arrives");
        m.run(20).await;
        assert!(
            (m.tx.position - 2 * REV).abs() < REV / 300,
            "at 2 rev: {}",
            m.tx.position
        );
        assert!((motor_position(&sim, 0) - 2 * i64::from(REV)).abs() < i64::from(REV / 300));
    });
}

#[test]
fn c113_the_motor_encoder_closes_the_position_loop() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        let i02: u8 = sd.sdo_read(I02, 0).await.unwrap();
        assert_eq!(i02, 0, "I02 = 0: motor encoder");
        assert!(
            sd.sdo_write(I02, 0, 1u8).await.is_err(),
            "no position encoder on this hardware: I02 = 1 refused"
        );
        m.enable_in(8).await;
        let mut p = m.tx.position;
        for _ in 0..1000 {
            p += REV / 1000;
            m.set_target_position(p);
            m.cycle().await;
        }
        m.run(200).await;
        let enc = motor_position(&sim, 0);
        println!(
            "csp +1 rev: 6064h {}, motor encoder {enc}, set {p}, 60F4h {}",
            m.tx.position, m.tx.following_error
        );
        // the TxPDO is sampled one cycle before the plant is read here
        assert!(
            (i64::from(m.tx.position) - enc).abs() <= 10,
            "6064h is the motor encoder"
        );
        assert!(
            (enc - i64::from(p)).abs() < i64::from(REV / 1000),
            "the loop closed on it: {enc} vs {p}"
        );
    });
}

// ---------------------------------------------------------------------------
// C-143 user status word, C-148 set-value monitoring
// ---------------------------------------------------------------------------

#[test]
fn c143_a67_is_assembled_from_the_sources_in_a66() {
    let sim = line(1);
    with_drive(&sim, |d| {
        d.motors[0].switches_mut().reference = hil_sim::motor::PositionInput::above(i64::from(REV) / 2);
    });
    with_cyclic(&sim, async |m, sd| {
        let src = |index: u32, sub: u32, bit: u32| index << 16 | sub << 8 | bit;
        // bit 0 = 6041h bit 2 (operation enabled), bit 5 = 60FDh bit 2 (reference switch),
        // bit 15 = 6041h bit 12 (csv follows)
        sd.sdo_write(A66, 1, src(0x6041, 0, 2)).await.unwrap();
        sd.sdo_write(A66, 6, src(0x60FD, 0, 2)).await.unwrap();
        sd.sdo_write(A66, 16, src(0x6041, 0, 12)).await.unwrap();
        m.set_mode(9);
        let tx = m.run(3).await;
        assert_eq!(tx.a67, 0, "not enabled, off the switch: {:#06x}", tx.a67);
        let tx = m.enable().await;
        let tx = if tx.a67 == 0 { m.run(2).await } else { tx };
        assert_eq!(tx.a67, 0x8001, "enabled and following: {:#06x}", tx.a67);
        m.set_target_velocity(REV);
        m.run_until(2000, |t| t.position > REV * 6 / 10)
            .await
            .expect("on the switch");
        let tx = m.run(2).await;
        assert_eq!(tx.a67, 0x8021, "reference switch in bit 5: {:#06x}", tx.a67);
        let a67: u16 = sd.sdo_read(parameter_index(0, 67), 0).await.unwrap();
        assert_eq!(a67 & 0x0021, 0x0021, "A67 by SDO");
    });
}

#[test]
fn c148_set_value_jump_trips_the_monitor() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        // 607Fh = 10 rev/s: 2 × 10 rev/s × 1 ms = 0.02 rev per cycle is feasible
        sd.sdo_write(0x607F, 0, (10 * REV) as u32).await.unwrap();
        m.enable_in(8).await;
        // steps of 0.015 rev per cycle (9 rev/s) are followed
        let mut p = m.tx.position;
        for _ in 0..100 {
            p += REV * 15 / 1000;
            m.set_target_position(p);
            m.cycle().await;
        }
        assert_eq!(m.tx.state(), sw::OE, "a feasible ramp: {:#06x}", m.tx.statusword);
        for _ in 0..100 {
            m.set_target_position(p);
            m.cycle().await;
        }
        // one step of 0.1 rev: excessive set value jump
        m.set_target_position(p + REV / 10);
        let hit = m
            .run_until(20, |t| t.state() == sw::FRA || t.state() == sw::FAULT)
            .await;
        assert!(hit.is_some(), "set-value jump fault: {:#06x}", m.tx.statusword);
        m.run_until(500, |t| t.state() == sw::FAULT).await.expect("fault");
        let code: u16 = sd.sdo_read(0x603F, 0).await.unwrap();
        println!("C-148: 603Fh {code:#06x}");
        assert_eq!(code, 0x8612, "603Fh of event 78");
        // the axis did not jump: it never reached the new set-point
        assert!(
            (motor_position(&sim, 0) - i64::from(p)).abs() < i64::from(REV / 20),
            "stayed near {p}: {}",
            motor_position(&sim, 0)
        );
        // monitoring off (I471 = 0 by SDO): the same jump is followed
        sd.sdo_write(parameter_index(8, 471), 0, 0u8).await.unwrap();
        m.set_controlword(CW_FAULT_RESET);
        m.run_until(20, |t| t.state() == sw::SOD).await.expect("reset");
        m.set_controlword(0);
        m.run(2).await;
        let here = m.tx.position;
        m.set_target_position(here);
        m.enable().await;
        m.set_target_position(here + REV / 10);
        let tx = m.run(200).await;
        assert_eq!(tx.state(), sw::OE, "no monitor: {:#06x}", tx.statusword);
        assert!(
            (tx.position - here - REV / 10).abs() < REV / 200,
            "followed the jump"
        );
    });
}

// ---------------------------------------------------------------------------
// C-015 causes of Switch on disabled in E47/E49
// ---------------------------------------------------------------------------

#[test]
fn c015_switch_on_disabled_causes_in_e47_and_e49() {
    use hil_sim::sim::AxisConditions;
    let e47 = parameter_index(4, 47);
    let e49 = parameter_index(4, 49);
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        m.set_mode(8);
        let causes = async |m: &mut Cyclic<'_>| {
            m.run(3).await;
            let first: u8 = sd.sdo_read(e47, 0).await.unwrap();
            let all: u8 = sd.sdo_read(e49, 0).await.unwrap();
            (first, all)
        };
        // controlword 0: only the missing Shutdown command
        assert_eq!(causes(m).await, (4, 0b1000), "controlword");
        // Shutdown with STO and no supply: both block T2, STO is named first
        m.set_controlword(0x0006);
        with_drive(&sim, |d| {
            d.conditions[0].sto_active = true;
            d.conditions[0].supply_ok = false;
        });
        assert_eq!(causes(m).await, (1, 0b0011), "STO + supply");
        assert_eq!(m.tx.state(), sw::SOD, "T2 blocked");
        with_drive(&sim, |d| d.conditions[0].sto_active = false);
        assert_eq!(causes(m).await, (2, 0b0010), "supply");
        assert_eq!(m.tx.state(), sw::SOD);
        with_drive(&sim, |d| {
            d.conditions[0] = AxisConditions::READY;
            d.conditions[0].additional_enable = false;
        });
        assert_eq!(causes(m).await, (3, 0b0100), "A60");
        assert_eq!(m.tx.state(), sw::SOD);
        // all present: Ready to switch on, no cause
        with_drive(&sim, |d| d.conditions[0] = AxisConditions::READY);
        m.run_until(10, |t| t.state() == sw::RTSO).await.expect("T2");
        assert_eq!(causes(m).await, (0, 0), "not in Switch on disabled");
        // enabled, then the supply drops: event 46 "Low voltage" (the power
        // stage was on, decisions), and the fault reset, with the supply
        // still missing, leads to SOD with the supply as cause
        m.enable().await;
        with_drive(&sim, |d| d.conditions[0].supply_ok = false);
        m.run_until(50, |t| t.state() == sw::FAULT)
            .await
            .expect("event 46");
        assert_eq!(
            sd.sdo_read::<u16>(0x603F, 0).await.unwrap(),
            0x3120,
            "low voltage"
        );
        m.set_controlword(0x0080);
        m.run_until(50, |t| t.state() == sw::SOD)
            .await
            .expect("forced to SOD");
        let (first, all) = causes(m).await;
        println!("supply lost in OE: E47 {first}, E49 {all:#06b}");
        assert_eq!(first, 2, "E47 names the supply");
        assert_ne!(all & 0b0010, 0, "E49 bit 1");
    });
}

// ---------------------------------------------------------------------------
// C-109 gear ratio and feed constant end to end
// ---------------------------------------------------------------------------

#[test]
fn c109_gear_and_feed_scale_positions_and_velocities_through_the_master() {
    let sim = line(1);
    let start = i64::from(REV) / 8; // the motor at 45°
    with_drive(&sim, |d| d.motors[0].set_position_inc(start));
    with_cyclic(&sim, async |m, sd| {
        // user unit 0.001° of the output shaft: feed 360 000 per shaft revolution, gear 2 : 1
        sd.sdo_write(0x6092, 1, 360_000u32).await.unwrap();
        sd.sdo_write(0x6091, 1, 2u32).await.unwrap();
        sd.sdo_write(0x6091, 2, 1u32).await.unwrap();
        // 0.5 shaft rev/s, 10 shaft rev/s²
        set_profile(sd, Some(180_000u32), 3_600_000u32).await;
        sd.sdo_write(0x607F, 0, 18_000_000u32).await.unwrap(); // 50 shaft rev/s
        m.set_mode(9);
        let tx = m.run(3).await;
        // 45° of the motor = 22.5° of the shaft
        assert!(
            (tx.position - 22_500).abs() <= 1,
            "6064h in 0.001°: {}",
            tx.position
        );
        // csv: 60FFh = 36 000 = 0.1 shaft rev/s = 0.2 motor rev/s
        m.enable().await;
        m.set_target_velocity(36_000);
        m.run(500).await;
        let motor = motor_rev_s(&sim, 0);
        println!(
            "csv 36 000 units/s: 606Ch {}, motor {motor:.4} rev/s",
            m.tx.velocity
        );
        assert!((motor - 0.2).abs() < 0.005, "motor at 0.2 rev/s: {motor}");
        assert!(
            (m.tx.velocity - 36_000).abs() < 500,
            "606Ch in units/s: {}",
            m.tx.velocity
        );
        m.set_target_velocity(0);
        m.run(300).await;
        // pp absolute: referenced here (607Ch = 0), then to 90° of the shaft = 0.5 motor rev
        home_here(m).await;
        let p0 = motor_position(&sim, 0);
        m.set_mode(1);
        m.run(5).await;
        assert!(pp_edge(m, 90_000, 0).await, "taken");
        settle(m, 5000).await.expect("arrives");
        m.run(50).await;
        let moved = motor_position(&sim, 0) - p0;
        println!("pp to 90 000: 6064h {}, motor moved {moved} inc", m.tx.position);
        assert!((m.tx.position - 90_000).abs() <= 100, "6064h {}", m.tx.position);
        assert!(
            (moved - i64::from(REV) / 2).abs() < i64::from(REV / 300),
            "half a motor revolution: {moved}"
        );
    });
}

// ---------------------------------------------------------------------------
// C-111 endless axis
// ---------------------------------------------------------------------------

#[test]
fn c111_endless_axis_wraps_at_607b_through_the_master() {
    let sim = line(1);
    const L: i32 = 360_000; // 0.001° per motor revolution
    with_master(&sim, async |md, clock| {
        // I00 = 1 "endless" by SDO, in Pre-Op (issue 40)
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        sd.sdo_write(drive_ecat::params::I00, 0, 1u8).await.unwrap();
        let group = group.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).unwrap();
        // not in Op: 0800 0022h, unchanged
        let refused = sd.sdo_write(drive_ecat::params::I00, 0, 0u8).await;
        assert!(
            matches!(
                refused,
                Err(ethercrab::error::Error::Mailbox(
                    ethercrab::error::MailboxError::Aborted {
                        code: ethercrab::error::CoeAbortCode::InvalidState,
                        ..
                    }
                ))
            ),
            "I00 in Op: {refused:?}"
        );
        assert_eq!(sd.sdo_read::<u8>(drive_ecat::params::I00, 0).await.unwrap(), 1);
        sd.sdo_write(0x6092, 1, L as u32).await.unwrap();
        sd.sdo_write(0x607B, 2, L).await.unwrap();
        sd.sdo_write(0x607B, 1, -5i32).await.unwrap(); // no function
        let mut m = Cyclic::new(md, &group, &sim, 0);
        m.enable_in(9).await;
        // csv 1 rev/s for 1.6 s: 6064h stays in 0 … L − 1 and wraps once
        m.set_target_velocity(L);
        let p0 = motor_position(&sim, 0);
        let (mut lo, mut hi, mut wraps, mut last) = (i32::MAX, i32::MIN, 0, m.tx.position);
        for _ in 0..1600 {
            let t = m.cycle().await;
            lo = lo.min(t.position);
            hi = hi.max(t.position);
            if t.position < last - L / 2 {
                wraps += 1;
            }
            last = t.position;
        }
        m.set_target_velocity(0);
        m.run(300).await;
        let turned = motor_position(&sim, 0) - p0;
        println!("endless csv: 6064h {lo} … {hi}, {wraps} wrap(s), motor turned {turned} inc");
        assert!(
            lo >= 0 && hi < L,
            "6064h within the revolution length: {lo} … {hi}"
        );
        assert!(turned > i64::from(REV), "more than a revolution: {turned}");
        assert_eq!(wraps, 1, "wrapped once");
        let expected = (turned % i64::from(REV)) * i64::from(L) / i64::from(REV);
        let shown = i64::from(m.tx.position);
        assert!((shown - expected).abs() < 100 || (shown - expected).abs() > i64::from(L) - 100);

        // pp absolute: referenced here (607Ch = 0); 270° the shorter way is −90°
        home_here(&mut m).await;
        m.set_mode(1);
        m.run(5).await;
        let p1 = motor_position(&sim, 0);
        assert!(pp_edge(&mut m, 270_000, 0).await, "taken");
        settle(&mut m, 5000).await.expect("arrives");
        m.run(30).await;
        let d1 = motor_position(&sim, 0) - p1;
        println!("pp 270 000 shortest: moved {d1} inc, 6064h {}", m.tx.position);
        assert!(
            (d1 + i64::from(REV) / 4).abs() < i64::from(REV / 300),
            "−90°: {d1}"
        );
        assert!((m.tx.position - 270_000).abs() < 500, "6064h {}", m.tx.position);
        // 60F2h bits 7..6 = 10: positive only, 90° is +180° from 270°
        sd.sdo_write(0x60F2, 0, 0x0080u16).await.unwrap();
        let p2 = motor_position(&sim, 0);
        assert!(pp_edge(&mut m, 90_000, 0).await, "taken");
        settle(&mut m, 5000).await.expect("arrives");
        m.run(30).await;
        let d2 = motor_position(&sim, 0) - p2;
        assert!(
            (d2 - i64::from(REV) / 2).abs() < i64::from(REV / 300),
            "+180°: {d2}"
        );
        // outside the revolution length: refused
        assert!(!pp_edge(&mut m, L + 10, 0).await, "beyond 607Bh:02 refused");

        // to 330° (positive), then csp across the wrap: 330° → 70° in steps of 0.5°
        assert!(pp_edge(&mut m, 330_000, 0).await, "taken");
        settle(&mut m, 5000).await.expect("arrives");
        m.run(30).await;
        sd.sdo_write(0x60F2, 0, 0u16).await.unwrap();
        m.set_mode(8);
        let mut sp = m.tx.position;
        m.set_target_position(sp);
        m.run(20).await;
        let p3 = motor_position(&sim, 0);
        let target_total = 100_000; // +100°
        for _ in 0..(target_total / 500) {
            sp = (sp + 500) % L;
            m.set_target_position(sp);
            m.cycle().await;
        }
        m.run(100).await;
        let d3 = motor_position(&sim, 0) - p3;
        println!("csp across the wrap: moved {d3} inc, 6064h {}", m.tx.position);
        assert!(m.tx.position < L / 4, "wrapped past 0: {}", m.tx.position);
        assert_eq!(
            m.tx.state(),
            sw::OE,
            "no set-value jump: {:#06x}",
            m.tx.statusword
        );
        assert!(
            (d3 - i64::from(REV) * 100 / 360).abs() < i64::from(REV / 300),
            "+100° continuous: {d3}"
        );
    });
}
