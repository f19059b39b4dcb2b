//! Quick stop, fault and reset (C-010, C-011, C-016, C-017): quick stop through the PDO, and
//! the following-error fault with its EMCY and reset (E-007, E-087, E-088).

use super::*;

#[test]
fn c010_c011_quick_stop_through_pdo() {
    let sim = line(1);
    with_cyclic(&sim, async |m, sd| {
        // 6085h = 100 rev/s²: 5 rev/s stop in 50 ms over 0.125 rev
        sd.sdo_write(0x6085, 0, 100 * REV as u32).await.unwrap();
        let qs_option: i16 = sd.sdo_read(0x605A, 0).await.unwrap();
        assert_eq!(qs_option, 2, "605Ah default: quick stop ramp, then SOD");
        m.csv_reach(5 * REV).await;

        // quick stop: bit 2 = 0 with bits 0, 1, 3 kept (0x000B)
        let t0 = m.now().as_ns();
        let p0 = m.tx.position;
        m.set_controlword(0x000B);
        let qsa = m.run_until(5, |t| t.state() == sw::QSA).await;
        assert!(
            qsa.is_some(),
            "Quick stop active 0x0007: {:#06x}",
            m.tx.statusword
        );
        let mut stopped_at = None;
        let mut left_at = None;
        let mut states = vec![m.tx.state()];
        for _ in 0..300 {
            let tx = m.cycle().await;
            // standstill as the drive sees it: |606Ch| < C40 (0.1 rev/s)
            if stopped_at.is_none() && tx.velocity.abs() < REV / 10 {
                stopped_at = Some((m.now().as_ns() - t0) / 1_000_000);
            }
            if *states.last().unwrap() != tx.state() {
                states.push(tx.state());
            }
            if tx.state() == sw::SOD {
                left_at = Some((m.now().as_ns() - t0) / 1_000_000);
                break;
            }
            // the set velocity of csv is ignored meanwhile (C-024)
            assert!(
                tx.velocity < 5 * REV + REV / 10,
                "no acceleration during the stop"
            );
        }
        let stopped_at = stopped_at.expect("standstill");
        let left_at = left_at.expect("Switch on disabled after the stop (T12)");
        let distance = f64::from(m.tx.position - p0) / REV_F;
        println!(
            "quick stop from 5 rev/s at 6085h = 100 rev/s²: standstill after {stopped_at} ms over {distance:.3} rev, \
             Switch on disabled after {left_at} ms; states {states:04x?}"
        );
        assert_eq!(
            states,
            vec![sw::QSA, sw::SOD],
            "QSA, then SOD: no return to OE (no T16)"
        );
        assert!((45..90).contains(&stopped_at), "ramp of 6085h: {stopped_at} ms");
        assert!(
            (0.11..0.2).contains(&distance),
            "stopping distance {distance} rev"
        );
        assert!(left_at >= stopped_at, "SOD only after standstill");
        // the master still sends 0x000B and then 0x000F: both keep SOD
        for cw in [0x000B, 0x000F] {
            m.set_controlword(cw);
            let tx = m.run(20).await;
            assert_eq!(tx.state(), sw::SOD, "{cw:#06x} in SOD: {:#06x}", tx.statusword);
        }
        assert!(motor_rev_s(&sim, 0).abs() < 0.01, "the motor stands");
    });
}

/// Reads one EMCY (CoE service 1) from SM1: (603Fh-style code, error register).
async fn receive_emcy<S>(mbx: &mut RawMailbox, sd: &ethercrab::SubDeviceRef<'_, S>) -> (u16, u8, Vec<u8>) {
    let (kind, data) = mbx.receive(sd).await.expect("a mailbox message");
    assert_eq!(kind, 3, "CoE");
    assert_eq!(
        u16::from_le_bytes([data[0], data[1]]) >> 12,
        1,
        "CoE service 1 = EMCY"
    );
    (
        u16::from_le_bytes([data[2], data[3]]),
        data[4],
        data[2..].to_vec(),
    )
}

#[test]
fn c016_c017_e007_e087_e088_following_error_fault_emcy_and_reset() {
    let sim = line(1);
    // a rigid end stop at +0.5 rev blocks the motor
    with_drive(&sim, |d| {
        d.motors[0].params_mut().end_stops_inc = Some((-10 * i64::from(REV), i64::from(REV / 2)));
    });
    with_cyclic(&sim, async |m, sd| {
        // I470 = 1: the following error reaction is a fault (event 54)
        sd.sdo_write(drive_ecat::parameter_index(8, 470), 0, 1u8)
            .await
            .unwrap();
        // following error window 0.05 rev, 10 ms (6065h, 6066h)
        sd.sdo_write(0x6065, 0, (REV / 20) as u32).await.unwrap();
        sd.sdo_write(0x6066, 0, 10u16).await.unwrap();
        m.set_mode(8);
        m.run(3).await;
        m.set_target_position(m.tx.position);
        m.enable().await;

        // csp towards 2 rev at 2 rev/s: blocked at 0.5 rev
        let mut fault_at = None;
        let mut states = vec![m.tx.state()];
        for k in 1..1500 {
            let target = (2 * k as i64 * i64::from(REV) / 1000).min(2 * i64::from(REV)) as i32;
            m.set_target_position(target);
            let tx = m.cycle().await;
            if *states.last().unwrap() != tx.state() {
                states.push(tx.state());
            }
            if tx.state() == sw::FAULT {
                fault_at = Some(k);
                break;
            }
        }
        let fault_at = fault_at.expect("a following-error fault");
        let tx = m.tx;
        println!(
            "blocked at {} inc: Fault after {fault_at} ms, states {states:04x?}, statusword {:#06x}",
            tx.position, tx.statusword
        );
        assert!(
            states.contains(&sw::FRA) || states.contains(&sw::FAULT),
            "{states:04x?}"
        );
        assert_eq!(*states.last().unwrap(), sw::FAULT);
        assert!(tx.position <= REV / 2 + 10, "at the end stop: {}", tx.position);

        // the EMCY is in the mailbox, 603Fh and 1001h show the fault
        let mut mbx = RawMailbox::new();
        let (code, register, raw) = receive_emcy(&mut mbx, sd).await;
        println!("EMCY {raw:02x?}");
        assert_eq!(code, 0x8611, "following error (event 54)");
        assert_ne!(register, 0, "error register in the EMCY");
        let mut coe = CoeClient::new();
        let reg = coe.upload(sd, 0x1001, 0).await.unwrap();
        assert_ne!(reg[0], 0, "1001h error register");
        let e603f = coe.upload(sd, 0x603F, 0).await.unwrap();
        assert_eq!(u16::from_le_bytes([e603f[0], e603f[1]]), 0x8611, "603Fh");

        // bit 7 = 0 keeps the fault; its rising edge resets (T15)
        m.set_target_position(m.tx.position);
        m.set_controlword(0x0000);
        let tx = m.run(10).await;
        assert_eq!(
            tx.state(),
            sw::FAULT,
            "no reset without bit 7: {:#06x}",
            tx.statusword
        );
        m.set_controlword(0x0080);
        let reset = m.run_until(3, |t| t.state() == sw::SOD).await;
        assert!(
            reset.is_some(),
            "the rising edge of bit 7 resets: {:#06x}",
            m.tx.statusword
        );
        let tx = m.run(10).await;
        assert_eq!(
            tx.state(),
            sw::SOD,
            "stays SOD with bit 7 steady: {:#06x}",
            tx.statusword
        );
        let (code, register, raw) = receive_emcy(&mut mbx, sd).await;
        println!("EMCY {raw:02x?}");
        assert_eq!((code, register), (0, 0), "fault cleared");
        let reg = coe.upload(sd, 0x1001, 0).await.unwrap();
        assert_eq!(reg[0], 0, "1001h cleared");
        // and the axis can be enabled again (away from the stop)
        m.set_controlword(0);
        m.run(2).await;
        m.enable().await;
        assert!(
            coe.emergencies.is_empty(),
            "no further EMCY: {:02x?}",
            coe.emergencies
        );
    });
}
