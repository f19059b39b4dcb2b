//! Synchronisation and RxPDO monitoring through a real master (spec §3.3,
//! §11, §13.1–13.4): the P→S checks of the sync mode (DC SYNC0 cycle vs
//! A150, free run needs a 3-buffer SM2, SM watchdog settings), the S→O wait
//! for stable RxPDO and the PDO timeout in Op.

use drive_tests::al::{ACK, ERR, OP, PREOP, SAFEOP};
use drive_tests::step::{advance, cycles, op_via_safe_op, set};
use drive_tests::{
    al_status, expect_al, init, line, request_gives, with_master, with_sdo_set_up, write_sm, CoeClient,
    OpGroup,
};
use esc::regs::{self, dc};
use esc::AlStatusCode;
use ethercrab::{MainDevice, SubDeviceRef};
use hil_sim::sim::Simulation;
use std::cell::RefCell;
use std::sync::atomic::AtomicU64;

/// A258 PDO timeout (ms), parameter 2000h + 258.
const A258: u16 = 0x2102;
/// Safe-Op + ERR with 001Bh: the RxPDO not steady, or gone in Op (the SM
/// watchdog or the PDO timeout).
const SAFEOP_001B: (u16, u16) = (SAFEOP | ERR, AlStatusCode::SM_WATCHDOG.0);
/// Safe-Op + ERR with 002Bh: no RxPDO at all.
const SAFEOP_002B: (u16, u16) = (SAFEOP | ERR, AlStatusCode::NO_VALID_IO.0);

/// SM2 as the drive's SII describes it.
const SM2_START: u16 = 0x1200;
const SM2_LEN: u16 = 23;
const SM2_CONTROL: u8 = 0x64;

/// A258 = `a258`, then Safe-Op, five cycles of process data and Op
/// (process data just ran: ethercrab's `into_op` gets Op at once).
async fn op_with_a258<'a>(
    md: &'a MainDevice<'a>,
    clock: &'a AtomicU64,
    sim: &RefCell<Simulation>,
    a258: i64,
) -> OpGroup {
    set(sim, A258, 0, a258);
    op_via_safe_op(md, init(md, clock).await, sim).await
}

/// SYNC0 configured with plain register writes, as a master's DC set-up does.
async fn start_sync0<S>(sd: &ethercrab::SubDeviceRef<'_, S>, cycle_ns: u32) {
    let now: u64 = sd.register_read(dc::SYSTEM_TIME).await.unwrap();
    sd.register_write(dc::SYNC0_CYCLE, cycle_ns).await.unwrap();
    sd.register_write(dc::START_TIME, now + 1_000_000).await.unwrap();
    sd.register_write(dc::ACTIVATION, 0x03u8).await.unwrap();
}

async fn stop_sync0<S>(sd: &ethercrab::SubDeviceRef<'_, S>) {
    sd.register_write(dc::ACTIVATION, 0x00u8).await.unwrap();
}

/// `ns` of simulated time without process data; then the AL status and
/// code must be `expected` (`what`: the case).
async fn quiet_for<S>(
    sim: &RefCell<Simulation>,
    sd: &SubDeviceRef<'_, S>,
    ns: u64,
    expected: (u16, u16),
    what: &str,
) {
    advance(sim, ns);
    expect_al(sd, expected, what).await;
}

fn u32_of(d: &[u8]) -> u32 {
    let mut b = [0u8; 4];
    b[..d.len()].copy_from_slice(d);
    u32::from_le_bytes(b)
}

#[test]
fn e029_sync0_cycle_not_a_multiple_of_a150_or_above_8ms_refused() {
    let sim = line(1);
    with_sdo_set_up(&sim, async |sd, c| {
        // the master's SM set-up, then back to Pre-Op for the DC configuration

        // 1C32h:01 = 2 (DC SYNC0) without SYNC0 active: 0030h
        c.download(sd, 0x1C32, 1, &2u16.to_le_bytes()).await.unwrap();
        request_gives(
            sd,
            SAFEOP,
            (PREOP | ERR, AlStatusCode::INVALID_DC_SYNC_CONFIG.0),
            "DC selected, SYNC0 inactive",
        )
        .await;
        c.download(sd, 0x1C32, 1, &0u16.to_le_bytes()).await.unwrap();

        // A150 = 1 ms (default): 1.5 ms is not a multiple, 10 ms is above 8 ms
        for bad in [1_500_000u32, 10_000_000] {
            start_sync0(sd, bad).await;
            request_gives(
                sd,
                SAFEOP | ACK,
                (PREOP | ERR, 0x0036),
                &format!("SYNC0 {bad} ns: DC SYNC0 cycle time"),
            )
            .await;
            stop_sync0(sd).await;
        }
        // 2 ms = 2 × A150: accepted; 1C32h/1C33h show DC SYNC0 and the cycle
        start_sync0(sd, 2_000_000).await;
        request_gives(sd, SAFEOP | ACK, (SAFEOP, 0), "SYNC0 2 ms").await;
        for index in [0x1C32, 0x1C33] {
            let st = c.upload(sd, index, 1).await.unwrap();
            assert_eq!(u32_of(&st), 2, "{index:04X}h:01 sync type DC SYNC0");
            let cy = c.upload(sd, index, 2).await.unwrap();
            assert_eq!(u32_of(&cy), 2_000_000, "{index:04X}h:02 cycle time");
        }
        let supported = c.upload(sd, 0x1C32, 4).await.unwrap();
        assert_eq!(u32_of(&supported), 0x0007, "free run, SM2, DC SYNC0");
        let min = c.upload(sd, 0x1C32, 5).await.unwrap();
        assert_eq!(u32_of(&min), 250_000, "minimum cycle 250 µs");
    });
}

#[test]
fn e030_free_run_without_3_buffer_sm2_refused_with_0029() {
    let sim = line(1);
    with_sdo_set_up(&sim, async |sd, c| {
        let one_buffer = (SM2_CONTROL & !0x03) | 0x02;

        // 1C32h:01 = 0 (free run, the default) with SM2 in 1-buffer mode
        write_sm(sd, 2, SM2_START, SM2_LEN, one_buffer).await;
        request_gives(
            sd,
            SAFEOP,
            (PREOP | ERR, AlStatusCode::FREERUN_NEEDS_3BUFFER.0),
            "free run, 1-buffer SM2",
        )
        .await;
        // SM-synchronous: the device still needs its 3-buffer SM2 (001Dh)
        c.download(sd, 0x1C32, 1, &1u16.to_le_bytes()).await.unwrap();
        request_gives(
            sd,
            SAFEOP | ACK,
            (PREOP | ERR, AlStatusCode::INVALID_OUTPUT_CONFIG.0),
            "SM-synchronous, 1-buffer SM2",
        )
        .await;
        // free run with 3 buffers: fine
        c.download(sd, 0x1C32, 1, &0u16.to_le_bytes()).await.unwrap();
        write_sm(sd, 2, SM2_START, SM2_LEN, SM2_CONTROL).await;
        request_gives(sd, SAFEOP | ACK, (SAFEOP, 0), "free run, 3 buffers").await;
    });
}

#[test]
fn e031_invalid_sm_watchdog_settings_refused_with_001f() {
    let sim = line(1);
    with_sdo_set_up(&sim, async |sd, _| {
        let code = AlStatusCode::INVALID_WATCHDOG_CONFIG.0;

        // divider 0 with the watchdog running
        let divider: u16 = sd.register_read(regs::WATCHDOG_DIVIDER).await.unwrap();
        sd.register_write(regs::WATCHDOG_DIVIDER, 0u16).await.unwrap();
        request_gives(sd, SAFEOP, (PREOP | ERR, code), "divider 0").await;
        sd.register_write(regs::WATCHDOG_DIVIDER, divider).await.unwrap();

        // A258 = 65534 relies on the master's SM watchdog
        set(&sim, A258, 0, 65534);
        sd.register_write(regs::WATCHDOG_TIME_PD, 0u16).await.unwrap();
        request_gives(sd, SAFEOP | ACK, (PREOP | ERR, code), "SM watchdog off").await;
        // 5 × 100 µs is shorter than the 1 ms cycle
        sd.register_write(regs::WATCHDOG_TIME_PD, 5u16).await.unwrap();
        request_gives(sd, SAFEOP | ACK, (PREOP | ERR, code), "shorter than a cycle").await;
        // 100 ms: valid
        sd.register_write(regs::WATCHDOG_TIME_PD, 1000u16).await.unwrap();
        request_gives(sd, SAFEOP | ACK, (SAFEOP, 0), "100 ms").await;
    });
}

/// E-033; E-047: refused with 002Bh "no valid inputs and outputs" when no
/// RxPDO came at all, with 001Bh when it came but not regularly.
#[test]
fn e033_e047_safeop_to_op_waits_for_steady_rxpdo_and_refuses_after_200ms() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        set(&sim, A258, 0, 50);
        let group = init(md, clock).await;
        let group = group.into_safe_op(md).await.expect("SAFE-OP");
        let sd = group.subdevice(md, 0).unwrap();

        // no process data: the request waits (Safe-Op, no error)…
        request_gives(&sd, OP, (SAFEOP, 0), "pending").await;
        quiet_for(&sim, &sd, 100_000_000, (SAFEOP, 0), "still pending at 100 ms").await;
        // …and is refused after 200 ms
        quiet_for(&sim, &sd, 150_000_000, SAFEOP_002B, "no RxPDO within 200 ms").await;

        // one frame, then none: RxPDO, but not steady: 001Bh
        request_gives(&sd, OP | ACK, (SAFEOP, 0), "pending").await;
        cycles(md, &group, &sim, 1).await;
        quiet_for(
            &sim,
            &sd,
            250_000_000,
            SAFEOP_001B,
            "RxPDO not steady within 200 ms",
        )
        .await;

        // a waiting request is granted once the RxPDO runs
        request_gives(&sd, OP | ACK, (SAFEOP, 0), "pending again").await;
        cycles(md, &group, &sim, 5).await;
        assert_eq!(al_status(&sd).await, (OP, 0), "steady RxPDO: Op");
    });
}

#[test]
fn e044_e126_e128_op_without_rxpdo_longer_than_a258_falls_to_safeop() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = op_with_a258(md, clock, &sim, 50).await;
        let sd = group.subdevice(md, 0).unwrap();
        cycles(md, &group, &sim, 20).await;
        assert_eq!(al_status(&sd).await, (OP, 0), "RxPDO every 1 ms");

        // 40 ms without RxPDO: still within A258
        quiet_for(&sim, &sd, 40_000_000, (OP, 0), "40 ms: within A258").await;
        cycles(md, &group, &sim, 1).await;
        // 60 ms without: PDO timeout
        quiet_for(&sim, &sd, 60_000_000, SAFEOP_001B, "PDO timeout").await;
        // EMCY 7500h, error register 10h, event 52 cause 6
        let mut c = CoeClient::new();
        c.upload(&sd, 0x1000, 0).await.unwrap();
        let emcy = c.emergencies.first().expect("EMCY");
        assert_eq!(u16::from_le_bytes([emcy[0], emcy[1]]), 0x7500);
        assert_eq!((emcy[2], emcy[3], emcy[4]), (0x10, 52, 6));
        // an unsolicited state change (E-038)
        let log = sim.borrow().drives()[0].state_log.clone();
        let (_, last) = log.last().unwrap();
        assert!(last.unsolicited, "{last}");
        assert_eq!((last.from, last.to), (esc::AlState::Op, esc::AlState::SafeOp));
        let status = *sim.borrow().drives()[0].drive.slave().sync_status();
        assert!(status.triggered && status.trigger_count == 1 && status.unsolicited);
    });
}

#[test]
fn e128_master_leaving_op_does_not_trigger_the_pdo_timeout() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = op_with_a258(md, clock, &sim, 50).await;
        cycles(md, &group, &sim, 5).await;
        let group = group.into_safe_op(md).await.expect("back to SAFE-OP");
        let sd = group.subdevice(md, 0).unwrap();
        quiet_for(&sim, &sd, 200_000_000, (SAFEOP, 0), "no timeout outside Op").await;
    });
}

#[test]
fn e127_sm_watchdog_mode_uses_the_escs_watchdog() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = op_with_a258(md, clock, &sim, 65534).await;
        let sd = group.subdevice(md, 0).unwrap();
        cycles(md, &group, &sim, 5).await;
        // the ESC's default SM watchdog: 1000 × 100 µs
        quiet_for(&sim, &sd, 90_000_000, (OP, 0), "90 ms: within the SM watchdog").await;
        quiet_for(&sim, &sd, 20_000_000, SAFEOP_001B, "SM watchdog expired").await;
    });
}

/// E-110 (spec §9.5.1, §11.2): in SM-Sync (`1C32h:01` = 1) the PLL locks
/// the control cycle to the SM2 event; A292 = −200 µs starts the drive's
/// cycle 200 µs after the process data arrived.
#[test]
fn e110_a292_applies_to_the_sm2_event_in_sm_sync() {
    let sim = line(1);
    let sends = with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        sd.sdo_write(0x1C32, 1, 1u16).await.unwrap();
        sd.sdo_write(drive_ecat::parameter_index(0, 292), 0, -200i32)
            .await
            .unwrap();
        let group = group.into_safe_op(md).await.expect("SAFE-OP");
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(
            sim.borrow().drives()[0].drive.slave().sync_status().mode,
            ecat::esm::SyncMode::SmSync
        );
        let mut sends = Vec::new();
        // a master cycle of exactly 1 ms (the PLL's range is ±500 ppm)
        let t0 = sim.borrow().now().as_ns();
        for k in 1..=300u64 {
            sim.borrow_mut()
                .advance_to(nanos::Nanos::from_ns(t0 + k * 1_000_000));
            sends.push(sim.borrow().now().as_ns());
            group.tx_rx(md).await.expect("process data cycle");
        }
        assert_eq!(al_status(&sd).await, (SAFEOP, 0));
        sends
    });
    let s = sim.borrow();
    let d = &s.drives()[0];
    let pll = d.drive.pll().expect("the PLL follows the SM2 event");
    assert!(pll.is_locked(), "locked to the SM2 event");
    assert_eq!(pll.phase_offset_ns(), -200_000);
    let locked: Vec<_> = d.cycle_log.iter().filter(|c| c.locked).collect();
    assert!(locked.len() >= 100, "{} locked cycles", locked.len());
    let mut worst = 0;
    for c in &locked {
        // the frame this cycle follows: the last one sent before it
        let sent = sends.iter().rev().find(|&&t| t <= c.now.as_ns()).unwrap();
        let after = c.now.as_ns() as i64 - *sent as i64;
        worst = worst.max((after - 200_000).abs());
    }
    println!("SM-Sync, A292 = −200 µs: cycle start − SM2 event within ±{worst} ns");
    assert!(worst <= 1_000, "{worst} ns");
}
