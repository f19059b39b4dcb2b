//! Switch signals from I210 and E80 (C-104, C-107), reference retaining with I46 = 5 (C-112) and
//! the position encoder I02 (C-113).

use super::*;

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
