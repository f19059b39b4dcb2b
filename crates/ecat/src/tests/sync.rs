//! Synchronisation: sync mode and free-run checks, the watchdog and RxPDO monitor, unsolicited
//! state changes, and the DC sync state gating Op (E-029..E-031, E-038, E-046, E-127, E-131).

use super::*;

#[test]
fn e029_e030_sync_mode_and_free_run_check() {
    use crate::esm::{check_free_run, sync_mode, SyncMode};
    assert_eq!(sync_mode(0x03, Some(0)), Ok(SyncMode::DcSync0), "0x0981 wins");
    assert_eq!(
        sync_mode(0x01, Some(0)),
        Ok(SyncMode::FreeRun),
        "cyclic unit without SYNC0"
    );
    assert_eq!(sync_mode(0, Some(1)), Ok(SyncMode::SmSync));
    assert_eq!(sync_mode(0, Some(2)), Ok(SyncMode::DcSync0));
    assert_eq!(sync_mode(0, None), Ok(SyncMode::SmSync));
    assert_eq!(sync_mode(0, Some(3)), Err(AlStatusCode::INVALID_DC_SYNC_CONFIG));
    let sm = |control| esc::SyncManager {
        start: 0x1100,
        length: 3,
        control,
        status: 0,
        activate: activate::ENABLE,
        pdi_control: 0,
    };
    assert_eq!(
        check_free_run(SyncMode::FreeRun, &sm(0x66), 3),
        Err(AlStatusCode::FREERUN_NEEDS_3BUFFER)
    );
    assert_eq!(check_free_run(SyncMode::FreeRun, &sm(0x64), 3), Ok(()));
    assert_eq!(check_free_run(SyncMode::SmSync, &sm(0x66), 3), Ok(()));
    assert_eq!(
        check_free_run(SyncMode::FreeRun, &sm(0x66), 0),
        Ok(()),
        "no outputs"
    );
}

#[test]
fn e031_e127_watchdog_check_and_pdo_monitor() {
    use crate::esm::{check_watchdog, pdo_monitor, EscWatchdog, PdoMonitor};
    use crate::PdoTimeout::{EscWatchdog as Esc, LostFrames, Ms, Off};
    let wd = EscWatchdog {
        divider: 2498,
        pd_time: 1000,
        sm2_trigger: true,
    };
    let bad = Err(AlStatusCode::INVALID_WATCHDOG_CONFIG);
    assert_eq!(wd.time(), Some(Nanos::from_ms(100)));
    assert_eq!(check_watchdog(Off, &wd, 1_000_000, 23), Ok(()));
    assert_eq!(
        check_watchdog(Off, &EscWatchdog { divider: 0, ..wd }, 1_000_000, 23),
        bad
    );
    assert_eq!(
        check_watchdog(Off, &EscWatchdog { pd_time: 0, ..wd }, 1_000_000, 23),
        Ok(())
    );
    assert_eq!(
        check_watchdog(Esc, &EscWatchdog { pd_time: 0, ..wd }, 1_000_000, 23),
        bad
    );
    let no_trigger = EscWatchdog {
        sm2_trigger: false,
        ..wd
    };
    assert_eq!(check_watchdog(Esc, &no_trigger, 1_000_000, 23), bad);
    assert_eq!(
        check_watchdog(Esc, &EscWatchdog { pd_time: 5, ..wd }, 1_000_000, 23),
        bad
    );
    assert_eq!(check_watchdog(Esc, &wd, 1_000_000, 23), Ok(()));
    assert_eq!(
        check_watchdog(Esc, &EscWatchdog { pd_time: 0, ..wd }, 1_000_000, 0),
        Ok(())
    );

    assert_eq!(pdo_monitor(Off, 1_000_000, &wd), None);
    assert_eq!(pdo_monitor(Ms(0), 1_000_000, &wd), None);
    assert_eq!(
        pdo_monitor(Ms(1), 1_000_000, &wd),
        Some(PdoMonitor::Timeout(Nanos::from_ns(1_000_000)))
    );
    assert_eq!(
        pdo_monitor(Ms(65531), 1_000_000, &wd),
        Some(PdoMonitor::Timeout(Nanos::from_ns(65_531_000_000)))
    );
    assert_eq!(
        pdo_monitor(LostFrames(1), 1_000_000, &wd),
        Some(PdoMonitor::Timeout(Nanos::from_ns(2_500_000)))
    );
    assert_eq!(
        pdo_monitor(LostFrames(3), 1_000_000, &wd),
        Some(PdoMonitor::Timeout(Nanos::from_ns(4_500_000)))
    );
    assert_eq!(
        pdo_monitor(Esc, 1_000_000, &wd),
        Some(PdoMonitor::EscWatchdog(Nanos::from_ns(100_000_000)))
    );
    assert_eq!(
        pdo_monitor(Esc, 1_000_000, &EscWatchdog { pd_time: 0, ..wd }),
        None
    );
}

#[test]
fn e038_unsolicited_change_displays() {
    let c = StateChange {
        from: AlState::Op,
        to: AlState::SafeOp,
        requested: 8,
        code: AlStatusCode::SM_WATCHDOG,
        unsolicited: true,
    };
    assert_eq!(
        std::format!("{c}"),
        "Op -> SafeOp (unsolicited, AL status code 0x001b)"
    );
}

#[test]
fn e046_e131_e038_dc_sync_state_gates_op_and_faults_in_op() {
    use crate::esm::{SyncMode, SyncState};
    let waiting = |code: u16| SyncState {
        required: true,
        ready: Err(AlStatusCode(code)),
        fault: None,
    };
    let locked = SyncState {
        required: true,
        ready: Ok(()),
        fault: None,
    };

    // SM-Sync: the sync state is not consulted
    let mut r = Rig::new();
    r.slave.set_sync_state(waiting(0x002D));
    r.goto(AlState::Op);

    // DC SYNC0 (0x0981 = 3, 1 ms = A150)
    let mut r = Rig::new();
    r.esc.mem[regs::dc::ACTIVATION as usize] = 0x03;
    let c0 = regs::dc::SYNC0_CYCLE as usize;
    r.esc.mem[c0..c0 + 4].copy_from_slice(&1_000_000u32.to_le_bytes());
    r.goto(AlState::SafeOp);
    assert_eq!(r.slave.sync_status().mode, SyncMode::DcSync0);
    // S→O waits (no error) while there is no SYNC0 / no lock …
    r.slave.set_sync_state(waiting(0x002D));
    assert_eq!(r.req(8), (4, 0));
    assert!(r.slave.op_pending());
    r.slave.set_sync_state(waiting(0x0032));
    r.poll();
    assert_eq!((r.esc.status(), r.esc.code()), (4, 0));
    // … and is granted once locked
    r.slave.set_sync_state(locked);
    let c = r.poll().expect("granted");
    assert_eq!((c.to, c.unsolicited), (AlState::Op, false));
    assert_eq!(r.esc.status(), 8);

    // a sync fault in Op: Safe-Op + error + its code, EMCY 7500h cause 7, unsolicited
    r.slave.set_sync_state(SyncState {
        required: true,
        ready: Err(AlStatusCode(0x0034)),
        fault: Some(AlStatusCode(0x0034)),
    });
    assert_eq!(r.slave.run_led(), crate::led::Pattern::On);
    assert_eq!(r.slave.err_led(), crate::led::Pattern::Off);
    assert_eq!(r.slave.take_op_loss(), None, "nothing raised in Op yet");
    let c = r.poll().expect("dropped");
    assert!(c.unsolicited);
    assert_eq!(
        (c.from, c.to, c.code),
        (AlState::Op, AlState::SafeOp, AlStatusCode(0x0034))
    );
    // the application learns the cause once (its event, EMCY and fault reaction, E-129)
    assert_eq!(r.slave.take_op_loss(), Some(crate::esm::OpLoss::Sync));
    assert_eq!(r.slave.take_op_loss(), None);
    assert_eq!(r.slave.run_led(), crate::led::Pattern::SingleFlash);
    assert_eq!(r.slave.err_led(), crate::led::Pattern::SingleFlash, "unsolicited");
    assert_eq!((r.esc.status(), r.esc.code()), (0x14, 0x0034));
    assert!(r.slave.sync_status().unsolicited);
    assert!(!r.slave.sync_status().triggered, "not a PDO timeout (A259)");
    // the event and its EMCY are the application's: the slave sends none
    r.poll();
    assert_eq!(r.esc.mbx_read(), None, "no EMCY from the slave itself");
    // no second drop while in Safe-Op; a request without acknowledge is ignored
    assert_eq!(r.poll(), None);
    assert_eq!(r.req(8), (0x14, 0x0034));
    assert!(!r.slave.take_error_ack());
    // acknowledge + Op: waits for the application to clear the fault and relock
    assert_eq!(r.req(0x18), (4, 0));
    assert!(r.slave.take_error_ack());
    assert!(!r.slave.take_error_ack(), "reported once");
    assert!(r.slave.op_pending());
    r.slave.set_sync_state(locked);
    r.poll();
    assert_eq!(r.esc.status(), 8);

    // no lock within 200 ms: refused with the sync code
    assert_eq!(r.req(4), (4, 0));
    r.slave.set_sync_state(waiting(0x0032));
    assert_eq!(r.req(8), (4, 0));
    for _ in 0..200 {
        r.poll();
    }
    assert_eq!((r.esc.status(), r.esc.code()), (4, 0), "still waiting at 200 ms");
    r.poll();
    assert_eq!(
        (r.esc.status(), r.esc.code()),
        (0x14, 0x0032),
        "refused after 200 ms"
    );
}
