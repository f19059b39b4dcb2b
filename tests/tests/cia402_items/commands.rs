//! Mode 0 (C-028), replacing commands but not during a stop (C-029) and the velocity override
//! A340 in pv, pp and vl (C-030).

use super::*;

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
