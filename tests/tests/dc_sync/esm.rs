//! The state machine under DC: Safe-Op → Op waits for SYNC0 and the PLL lock, SYNC0 loss in Op,
//! a SYNC0 stop below Safe-Op, and the diagnosis time stamp (E-038, E-046, E-129, E-131, E-147).

use super::*;

const ERR_ACK: u16 = 0x10;

/// E-046, E-131, E-038 (spec §3.3 "S→O / in O: SYNC0 present, PLL locked",
/// §13.4): in DC mode Safe-Op → Op waits (no error) while the PLL has no
/// SYNC0 (002Dh) or is not locked (0032h) and is granted once it is locked;
/// SYNC0 switched off in Op (0x0981 = 0) drops to Safe-Op with the error
/// indication, AL 0034h (SYNC0 timeout), EMCY 7500h / 10h / event 52 cause
/// 7 and an unsolicited state change; acknowledge + SYNC0 back: Op again.
#[test]
fn e046_e131_e129_e038_dc_op_waits_for_pll_lock_and_sync0_loss_drops_to_safeop() {
    use drive_ecat::runtime::dcsync::al;
    use drive_tests::{al_status, request, CoeClient};
    use esc::AlStatusCode;
    let sim = line();
    let seen = run_in_process(&sim, async |md, clock| {
        let group = dc_requested_op(md, clock).await;

        // S→O waits for the lock: Safe-Op without error, 002Dh then 0032h
        let mut waiting = Vec::new();
        let mut first_op = None;
        dc_cycles(md, &group, &sim, 150, |i, all_op, s| {
            for d in s.drives() {
                let slave = d.drive.slave();
                if slave.state() == esc::AlState::SafeOp {
                    assert!(!slave.error(), "cycle {i}: no error while waiting");
                    assert!(slave.op_pending(), "cycle {i}: S→O pending");
                    let ready = d.drive.sync_state().ready;
                    if !waiting.contains(&ready) {
                        waiting.push(ready);
                    }
                }
            }
            if all_op && first_op.is_none() {
                first_op = Some(i);
                for d in s.drives() {
                    assert!(
                        d.drive.pll().is_some_and(|p| p.is_locked()),
                        "Op only once locked"
                    );
                }
            }
        })
        .await;
        println!("S→O waited {first_op:?} cycles: {waiting:?}");
        assert!(first_op.is_some(), "the group reached OP");
        assert!(
            waiting.contains(&Err(AlStatusCode(al::NO_SYNC))),
            "002Dh before SYNC0"
        );
        assert!(
            waiting.contains(&Err(AlStatusCode(al::PLL_ERROR))),
            "0032h before the lock"
        );

        // SYNC0 off in Op: Safe-Op + error, 0034h
        for sd in group.iter(md) {
            sd.register_write(esc::regs::dc::ACTIVATION, 0u8)
                .await
                .expect("0x0981");
        }
        dc_cycles(md, &group, &sim, 20, |_, _, _| {}).await;
        // the fault matrix's row: drive 0 as the master sees it
        let mut seen = Vec::new();
        for i in 0..2 {
            let sd = group.subdevice(md, i).expect("drive");
            let status = al_status(&sd).await;
            assert_eq!(
                status,
                (SAFEOP | 0x10, al::DC_SYNC_TIMEOUT),
                "drive {i}: SYNC0 timeout"
            );
            let mut c = CoeClient::new();
            c.upload(&sd, 0x1000, 0).await.expect("1000h");
            let emcy = c.emergencies.first().expect("EMCY");
            println!("drive {i}: EMCY {emcy:02x?}");
            assert_eq!(u16::from_le_bytes([emcy[0], emcy[1]]), 0x7500);
            assert_eq!(
                (emcy[2], emcy[3], emcy[4]),
                (0x10, 52, 7),
                "register 10h, event 52 cause 7"
            );
            // E-129/E-131: both axes react (Fault, 603Fh 7500h, E43 = 7)
            // with no second EMCY for the event
            c.upload(&sd, 0x1000, 0).await.expect("1000h");
            let n = c.emergencies.iter().filter(|e| e[0..2] == [0x00, 0x75]).count();
            assert_eq!(n, 1, "one EMCY 7500h: {:02x?}", c.emergencies);
            // E-038: A257[0] Er3 "unsolicited state change", ERR single flash
            let a257 = c
                .upload(&sd, drive_ecat::parameter_index(0, 257), 1)
                .await
                .expect("A257[0]");
            assert!(a257.starts_with(b"Er3 "), "A257[0] {a257:02x?}");
            let s = sim.borrow();
            assert_eq!(
                s.drives()[i].leds(nanos::Nanos::from_ns(s.now().as_ns())).err,
                ecat::led::Pattern::SingleFlash
            );
            let d = &s.drives()[i].drive;
            for axis in d.axes() {
                let state = d.objects().get(axis.cia402_index(0x6041), 0).unwrap() & 0x6F;
                assert!(
                    state == 0x08 || state == 0x0F,
                    "axis {}: {state:#x}",
                    axis.index()
                );
                assert_eq!(axis.error_code(), 0x7500);
            }
            assert_eq!(
                d.objects().get(drive_ecat::parameter_index(4, 43), 0),
                Ok(7),
                "E43"
            );
            let (_, last) = s.drives()[i].state_log.last().copied().expect("state change");
            println!("drive {i}: {last}");
            assert!(last.unsolicited, "E-038: {last}");
            assert_eq!((last.from, last.to), (esc::AlState::Op, esc::AlState::SafeOp));
            assert_eq!(last.code, AlStatusCode(al::DC_SYNC_TIMEOUT));
            assert!(s.drives()[i].drive.slave().sync_status().unsolicited);
            assert_eq!(
                s.drives()[i].drive.pll().and_then(|p| p.fault()),
                Some(SyncFault::Sync0Timeout)
            );
            if i == 0 {
                let axes: Vec<String> = d
                    .axes()
                    .iter()
                    .map(|a| {
                        let sw = d.objects().get(a.cia402_index(0x6041), 0).unwrap() as u16;
                        format!(
                            "{} {:04X}h",
                            drive_tests::matrix::cia402_state(sw),
                            a.error_code()
                        )
                    })
                    .collect();
                seen.push(format!(
                    "{}; {}; axes A, B: {}; A257[0] {}",
                    drive_tests::matrix::al(status),
                    drive_tests::matrix::emcys(&c.emergencies),
                    axes.join(", "),
                    String::from_utf8_lossy(&a257[..3])
                ));
            }
        }
        // without acknowledge a request is ignored
        let sd0 = group.subdevice(md, 0).expect("drive");
        request(&sd0, OP).await;
        assert_eq!(al_status(&sd0).await.0, SAFEOP | 0x10, "no acknowledge: ignored");

        // SYNC0 back (on the same grid: 0x0990 holds the next pulse) and
        // acknowledge + Op: the PLL fault is cleared, Op once locked again
        for sd in group.iter(md) {
            sd.register_write(esc::regs::dc::ACTIVATION, 0x03u8)
                .await
                .expect("0x0981");
            request(&sd, OP | ERR_ACK).await;
        }
        let mut back = None;
        dc_cycles(md, &group, &sim, 150, |i, all_op, _| {
            if all_op && back.is_none() {
                back = Some(i);
            }
        })
        .await;
        println!("Op again after {back:?} cycles");
        assert!(back.is_some(), "Op again after acknowledge");
        seen.push("after SYNC0 is back and an acknowledge: Op once the PLL locks".into());
        for i in 0..2 {
            let sd = group.subdevice(md, i).expect("drive");
            assert_eq!(al_status(&sd).await, (OP, 0), "drive {i}");
            let s = sim.borrow();
            let pll = s.drives()[i].drive.pll().expect("PLL");
            assert_eq!(pll.fault(), None, "acknowledge cleared the PLL fault");
            assert!(pll.is_locked());
        }
        seen.join("; ")
    });
    let row = drive_tests::matrix::Row {
        order: "11",
        case: "SYNC0 stops in Op (0x0981 = 0) on a line of two drives under DC",
        spec: "E-131, E-129, E-038",
        peer: "ethercrab",
        expected: "Safe-Op + ERR, AL 0034h; EMCY 7500h/10h event 52 cause 7; axes A, B: Fault 7500h, Fault \
                   7500h; A257[0] Er3; after SYNC0 is back and an acknowledge: Op once the PLL locks",
    };
    drive_tests::fault_row!(row, seen);
}

/// E-147: with DC-Sync running and the PLL locked, a diagnosis message (a
/// refused AL state change in Op) carries the DC system time (0x0910).
#[test]
fn e147_message_time_stamp_is_the_dc_system_time_when_synchronised() {
    let sim = line();
    let (stamp, system_time) = dc_op(
        &sim,
        SYNC0_NS,
        async |_: &Sd<'_>| {},
        150,
        async |md, group| {
            let sd = group.subdevice(md, 0).expect("drive");
            assert!(sim.borrow().drives()[0]
                .drive
                .pll()
                .is_some_and(|p| p.is_locked()));
            // Op → Bootstrap is not a valid transition (0011h): a message
            sd.register_write(esc::regs::AL_CONTROL, 3u16)
                .await
                .expect("AL control");
            dc_cycles(md, group, &sim, 3, |_, _, _| {}).await;
            let system_time: u64 = sd
                .register_read(esc::regs::dc::SYSTEM_TIME)
                .await
                .expect("0x0910");
            let s = sim.borrow();
            let d = &s.drives()[0].drive;
            let stamp = d
                .diag()
                .message(d.diag().newest_subindex())
                .map(|(_, t)| t.as_ns());
            (stamp, system_time)
        },
    );
    let stamp = stamp.expect("a message");
    // written within the three cycles before the read
    assert!(
        stamp <= system_time && system_time - stamp < 4 * SYNC0_NS,
        "{stamp} vs {system_time}"
    );
}

/// E-046 (spec §3.3: S→O needs SYNC0 and the PLL locked, nothing older): a
/// master that leaves the line in Init with SYNC0 running (the PLL is
/// built anew and locks there) and then switches SYNC0 off (a new master's
/// start-up does) leaves a SYNC0 timeout latched below Safe-Op, where the
/// drive shows no error to acknowledge; the next master's Safe-Op → Op must
/// not be refused for it (it was with 0034h until P→S cleared it; SOEM's
/// stop and restart found it, `faults.py --case stop-restart`).
#[test]
fn e046_a_sync0_stop_below_safe_op_does_not_refuse_the_next_op() {
    use drive_tests::{al_status, request};
    let sim = line();
    let first_op = run_in_process(&sim, async |md, clock| {
        let group = dc_requested_op(md, clock).await;
        let mut op = false;
        dc_cycles(md, &group, &sim, 300, |_, all_op, _| op |= all_op).await;
        // the master stops as SOEM's samples do: Init, SYNC0 left running
        for sd in group.iter(md) {
            request(&sd, drive_tests::al::INIT).await;
        }
        let t = sim.borrow().now().as_ns();
        sim.borrow_mut()
            .advance_to(nanos::Nanos::from_ns(t + 100_000_000));
        // the PLL was built again in Init and locked
        assert!(sim.borrow().drives()[0]
            .drive
            .pll()
            .is_some_and(|p| p.is_locked()));
        // then SYNC0 goes off (the next master's start-up): a timeout latches
        for sd in group.iter(md) {
            sd.register_write(esc::regs::dc::ACTIVATION, 0u8)
                .await
                .expect("0x0981");
        }
        let t = sim.borrow().now().as_ns();
        sim.borrow_mut().advance_to(nanos::Nanos::from_ns(t + 50_000_000));
        for sd in group.iter(md) {
            assert_eq!(
                al_status(&sd).await,
                (drive_tests::al::INIT, 0),
                "no error shown in Init"
            );
        }
        op
    });
    assert!(first_op, "the first master reached Op");
    // a new master: its start-up, DC, Op
    let (op, status) = run_in_process(&sim, async |md, clock| {
        let group = dc_requested_op(md, clock).await;
        let mut op = false;
        dc_cycles(md, &group, &sim, 300, |_, all_op, _| op |= all_op).await;
        let sd = group.subdevice(md, 0).expect("drive");
        (op, al_status(&sd).await)
    });
    assert!(op, "the new master's Op: {status:04x?}");
    assert_eq!(status, (OP, 0));
}
