//! The user status word A67 from the sources in A66 (C-143), the set-value monitor (C-148) and
//! the causes of Switch on disabled in E47/E49 (C-015).

use super::*;

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
