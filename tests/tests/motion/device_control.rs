//! Device control through the PDO (C-002 … C-018): the enable sequence, and enabling
//! refused without A60, supply or STO.

use super::*;

#[test]
fn c002_c004_c005_c018_enable_sequence_through_pdo() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await.into_op(md).await.expect("OP");
        let mut m = Cyclic::new(md, &group, &sim, 0);
        m.set_mode(8);
        // controlword 0: Switch on disabled, nothing else
        let tx = m.run(5).await;
        assert_eq!(tx.state(), sw::SOD, "statusword {:#06x}", tx.statusword);
        assert_eq!(tx.mode_display, 8, "6061h shows csp");

        // each command gives exactly the next state, and the state holds
        for (cw, state) in [(0x0006, sw::RTSO), (0x0007, sw::SO), (0x000F, sw::OE)] {
            m.command(cw, state, 10).await;
            // and holds
            let tx = m.run(5).await;
            assert_eq!(
                tx.state(),
                state,
                "controlword {cw:#06x}: statusword {:#06x}",
                tx.statusword
            );
            // bit 9 remote (the master is in control), bit 4 voltage enabled from RTSO on
            assert!(tx.bit(9), "remote bit 9: {:#06x}", tx.statusword);
            assert!(tx.bit(4), "voltage enabled bit 4: {:#06x}", tx.statusword);
        }
        // E48 agrees (C-019)
        let sd = group.subdevice(md, 0).unwrap();
        let e48_index = drive_ecat::parameter_index(4, 48);
        let e48: u8 = sd.sdo_read(e48_index, 0).await.expect("E48");
        assert_eq!(e48, 4, "E48 = operation enabled");

        // Disable operation (7) → Switched on (T5), shutdown (6) → RTSO (T6),
        // disable voltage (0) → SOD (T7)
        for (cw, state) in [(0x0007, sw::SO), (0x0006, sw::RTSO), (0x0000, sw::SOD)] {
            let tx = m.command(cw, state, 50).await;
            assert_eq!(tx.state(), state);
        }
        // a skipped step: 15 straight from SOD does nothing (no T2 without 6)
        m.set_controlword(0x000F);
        let tx = m.run(10).await;
        assert_eq!(tx.state(), sw::SOD, "15 in SOD: {:#06x}", tx.statusword);
    });
}

#[test]
fn c003_c015_enable_refused_without_a60_supply_or_sto() {
    type Cut = fn(&mut AxisConditions);
    let cuts: [(&str, Cut); 3] = [
        ("A60 off", |c| c.additional_enable = false),
        ("no supply", |c| c.supply_ok = false),
        ("STO active", |c| c.sto_active = true),
    ];
    let sim = line(1);
    with_cyclic(&sim, async |m, _| {
        m.set_mode(8);
        m.run(3).await;
        for (what, cut) in cuts {
            with_drive(&sim, |d| cut(&mut d.conditions[0]));
            // T2, then T3/T4 as a master would try them: all refused
            for cw in [0x0006, 0x0007, 0x000F] {
                m.set_controlword(cw);
                let tx = m.run(10).await;
                assert_eq!(
                    tx.state(),
                    sw::SOD,
                    "{what}: controlword {cw:#06x} gives {:#06x}",
                    tx.statusword
                );
            }
            // restored: the same sequence enables
            with_drive(&sim, |d| d.conditions[0] = AxisConditions::READY);
            m.set_controlword(0);
            m.run(2).await;
            m.enable().await;
            // lost while enabled: forced out of Operation enabled (C-013/C-015);
            // the supply with the power stage on is event 46 (decisions)
            with_drive(&sim, |d| cut(&mut d.conditions[0]));
            let to = if what == "no supply" { sw::FAULT } else { sw::SOD };
            let left = m.run_until(50, |t| t.state() == to).await;
            assert!(left.is_some(), "{what} in OE: {:#06x}", m.tx.statusword);
            with_drive(&sim, |d| d.conditions[0] = AxisConditions::READY);
            m.set_controlword(0);
            m.run(2).await;
            m.set_controlword(0x0080);
            m.run(2).await;
            m.set_controlword(0);
            m.run(2).await;
        }
    });
}
