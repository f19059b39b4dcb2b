//! The cyclic modes without mode-specific controlword bits (C-040), and pp's set-point
//! handshake and absolute moves (C-042, C-045, C-050).

use super::*;

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
