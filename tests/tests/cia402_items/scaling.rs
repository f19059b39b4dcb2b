//! The gear ratio and feed constant end to end (C-109) and the endless axis wrapping at 607Bh
//! (C-111).

use super::*;

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
