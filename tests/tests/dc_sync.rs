//! DC-Sync end to end: ethercrab (in-process) configures DC (static drift
//! compensation, SYNC0 period and start) on two drives whose oscillators drift
//! by +50 / −80 ppm and brings them to OP; each drive's PLL locks its
//! control-cycle timer to SYNC0 − A292 (E-107, E-109, E-113, E-114); loss of
//! SYNC0 is reported (A298, PLL fault); a late frame counts in A261[2]
//! (E-117, E-118); a SYNC0 cycle the PLL cannot run is refused (A261[0], E-116).

use drive_ecat::runtime::dcsync;
use drive_ecat::runtime::dcsync::{PllStatus, SyncFault};
use drive_tests::al::{OP, SAFEOP};
use drive_tests::init;
use ethercrab::subdevice_group::DcConfiguration;
use ethercrab::{MainDevice, SubDeviceGroup};
use hil_sim::master::{into_dc_sync0, run_in_process};
use hil_sim::sim::Simulation;
use std::cell::RefCell;
use std::sync::atomic::AtomicU64;
use std::time::Duration;

/// Oscillator drift of drive 0 (the DC reference) and drive 1, ppm.
const DRIFTS: [f64; 2] = [50.0, -80.0];
/// Local time of each drive at simulation time 0, ns.
const OFFSETS: [u64; 2] = [3_000_000_000, 987_654_321];
/// SYNC0 period = A150, ns.
const SYNC0_NS: u64 = 1_000_000;
/// A292 written by SDO: the drive's aligned cycle starts 100 µs after SYNC0.
const A292_US: i32 = -100;
/// Frames arrive 100 µs before SYNC0 (ethercrab sends at SYNC0 + shift).
const FRAME_LEAD_NS: u64 = 100_000;
const A261: u16 = drive_ecat::parameter_index(0, 261);

/// SYNC0 every `sync0_ns`, starting 20 ms out, frames arriving
/// [`FRAME_LEAD_NS`] before each SYNC0.
fn dc_config(sync0_ns: u64) -> DcConfiguration {
    DcConfiguration {
        start_delay: Duration::from_millis(20),
        sync0_period: Duration::from_nanos(sync0_ns),
        sync0_shift: Duration::from_nanos(sync0_ns - FRAME_LEAD_NS),
    }
}
const A292: u16 = drive_ecat::parameter_index(0, 292);
const A264: u16 = drive_ecat::parameter_index(0, 264);
const A296: u16 = drive_ecat::parameter_index(0, 296);
const A298: u16 = drive_ecat::parameter_index(0, 298);

fn line() -> RefCell<Simulation> {
    RefCell::new(Simulation::with_clocks(&DRIFTS, &OFFSETS))
}

/// The line in Op with DC.
type DcOpGroup = SubDeviceGroup<
    8,
    512,
    ethercrab::DefaultLock,
    ethercrab::subdevice_group::Op,
    ethercrab::subdevice_group::HasDc,
>;

/// What to do to the line during the DC cycles.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Inject {
    Nothing,
    /// Deactivate SYNC0 (0x0981 = 0) on both drives before this cycle.
    StopSync0(usize),
    /// Send this cycle's frame 200 µs late (100 µs after SYNC0).
    LateFrame(usize),
}

/// Per-drive snapshot taken through the bus (SDO) after the cycles.
#[derive(Debug, Clone, Copy)]
struct Seen {
    a298: u16,
    a261_late: u32,
    a296_us: u32,
    /// 1C32h:0B / 1C33h:0B SM-event missed counters, A264[7] (their mirror).
    sm_missed: [u16; 3],
    /// 1C32h:20 sync error, A264[9].
    sync_error: [u8; 2],
}

/// Configures A292 by SDO, DC with SYNC0 every [`SYNC0_NS`], requests OP and
/// runs `cycles` `tx_rx_dc` cycles; calls `probe` with the cycle number and
/// the simulation after each cycle; reads A298, A261[2], A296 by SDO at the end.
fn run(
    sim: &RefCell<Simulation>,
    cycles: usize,
    inject: Inject,
    mut probe: impl FnMut(usize, &Simulation),
) -> [Seen; 2] {
    run_in_process(sim, async |md, clock| {
        let group = dc_requested_op_after(md, clock, SYNC0_NS, async |sd| {
            sd.sdo_write(A292, 0, A292_US).await.expect("A292");
        })
        .await;
        let mut op = false;
        for i in 0..cycles {
            if inject == Inject::StopSync0(i) {
                for sd in group.iter(md) {
                    sd.register_write(esc::regs::dc::ACTIVATION, 0u8)
                        .await
                        .expect("0x0981");
                }
            }
            let r = group.tx_rx_dc(md).await.expect("DC cycle");
            op |= r.all_op();
            probe(i, &sim.borrow());
            let mut wait = r.extra.next_cycle_wait.as_nanos() as u64;
            if inject == Inject::LateFrame(i + 1) {
                wait += 2 * FRAME_LEAD_NS;
            }
            let mut s = sim.borrow_mut();
            let t = s.now().as_ns() + wait;
            s.advance_to(nanos::Nanos::from_ns(t));
        }
        assert!(op, "the group reached OP");
        let mut seen = [Seen {
            a298: 0,
            a261_late: 0,
            a296_us: 0,
            sm_missed: [0; 3],
            sync_error: [0; 2],
        }; 2];
        for (i, s) in seen.iter_mut().enumerate() {
            let sd = group.subdevice(md, i).expect("drive");
            s.a298 = sd.sdo_read(A298, 0).await.expect("A298");
            s.a261_late = sd.sdo_read(A261, 3).await.expect("A261[2]");
            s.a296_us = sd.sdo_read(A296, 0).await.expect("A296");
            s.sm_missed = [
                sd.sdo_read(0x1C32, 0x0B).await.expect("1C32h:0B"),
                sd.sdo_read(0x1C33, 0x0B).await.expect("1C33h:0B"),
                sd.sdo_read(A264, 8).await.expect("A264[7]"),
            ];
            s.sync_error = [
                sd.sdo_read(0x1C32, 0x20).await.expect("1C32h:20"),
                sd.sdo_read(A264, 10).await.expect("A264[9]"),
            ];
        }
        seen
    })
}

/// Phase error of each aligned, locked cycle start in DC system time against
/// SYNC0 − A292 (SYNC0 on the system-time grid of [`SYNC0_NS`]), ns.
fn phase_errors(sim: &Simulation, drive: usize) -> Vec<i64> {
    let target = -i64::from(A292_US) * 1000;
    let p = SYNC0_NS as i64;
    sim.drives()[drive]
        .cycle_log
        .iter()
        .filter(|c| c.index == 0 && c.locked)
        .map(|c| {
            let e = (c.system_ns as i64 - target).rem_euclid(p);
            if e >= p / 2 {
                e - p
            } else {
                e
            }
        })
        .collect()
}

#[test]
fn e107_e109_e114_pll_locks_control_cycle_to_sync0_minus_a292_on_drifting_drives() {
    let sim = line();
    // simulation time of the first SYNC0 and of the first cycle with both drives locked
    let (mut first_sync0, mut all_locked) = (None, None);
    let seen = run(&sim, 400, Inject::Nothing, |_, s| {
        let d = &s.drives()[0];
        if first_sync0.is_none() {
            first_sync0 = d.sync0_log.front().map(|p| p.now.as_ns());
        }
        let locked = s
            .drives()
            .iter()
            .all(|d| d.drive.pll().is_some_and(|p| p.is_locked()));
        if all_locked.is_none() && locked {
            all_locked = Some(s.now().as_ns());
        }
    });
    let lock_ms = all_locked.zip(first_sync0).map(|(l, f)| (l - f) as f64 / 1e6);
    println!("both drives phase locked {lock_ms:?} ms after the first SYNC0");
    assert!(lock_ms.is_some_and(|t| t <= 100.0), "lock within 100 ms");
    let s = sim.borrow();
    for (i, seen) in seen.iter().enumerate() {
        let d = &s.drives()[i];
        let pll = d.drive.pll().expect("PLL running");
        let errors = phase_errors(&s, i);
        let worst = errors.iter().map(|e| e.abs()).max().unwrap_or(i64::MAX);
        let mean = errors.iter().sum::<i64>() as f64 / errors.len().max(1) as f64;
        let first_lock = d.cycle_log.iter().find(|c| c.locked).map(|c| c.now.as_ns());
        println!(
            "drive {i} ({:+} ppm): A298 {:#06x} (SDO), A296 {} µs, A261 {:?}, PLL phase error {:?} ns, \
             {} locked aligned cycles in the log: mean {mean:.1} ns, worst |error| {worst} ns; first locked \
             cycle in the log at {:?} ns; late frames {}",
            DRIFTS[i],
            seen.a298,
            seen.a296_us,
            pll.diagnostics().elements(),
            pll.phase_error_ns(),
            errors.len(),
            first_lock,
            seen.a261_late,
        );
        assert!(pll.is_locked(), "drive {i} locked");
        let st = PllStatus(seen.a298);
        assert!(
            st.contains(PllStatus::PHASE_LOCKED | PllStatus::FREQUENCY_LOCKED | PllStatus::SYNC0_PRESENT),
            "drive {i}: A298 {:#06x}",
            seen.a298
        );
        assert_eq!(seen.a298 & PllStatus::DEACTIVATED, 0);
        assert_eq!(
            pll.phase_offset_ns(),
            i64::from(A292_US) * 1000,
            "A292 from the SDO"
        );
        assert!(
            errors.len() >= 100,
            "drive {i}: {} locked aligned cycles",
            errors.len()
        );
        assert!(
            worst <= 1_000,
            "drive {i}: cycle start within ±1 µs of SYNC0 − A292: {worst} ns"
        );
        assert_eq!(seen.a296_us, 1000, "A296: the measured SYNC0 cycle, µs");
        // frames 100 µs before SYNC0: A261[1] ≈ +100 µs (data before SYNC0)
        let data_us = pll.diagnostics().data_to_sync0_us;
        assert!((80..=100).contains(&data_us), "drive {i}: A261[1] = {data_us} µs");
    }
    // every cycle (k = 1) is an aligned one, 1 ms apart in system time
    for d in s.drives() {
        for w in d.cycle_log.iter().collect::<Vec<_>>().windows(2) {
            let dt = w[1].system_ns - w[0].system_ns;
            assert!(dt.abs_diff(SYNC0_NS) <= 1_000, "cycle length {dt} ns");
        }
    }
}

#[test]
fn e113_pll_stays_locked_with_5us_frame_jitter() {
    let sim = line();
    sim.borrow_mut()
        .set_frame_jitter(nanos::Nanos::from_ns(5_000), 0xE113);
    run(&sim, 400, Inject::Nothing, |_, _| {});
    let s = sim.borrow();
    for i in 0..2 {
        let worst = phase_errors(&s, i)
            .iter()
            .map(|e| e.abs())
            .max()
            .unwrap_or(i64::MAX);
        println!("drive {i} with ±5 µs frame jitter: worst |phase error| {worst} ns");
        assert!(s.drives()[i].drive.pll().is_some_and(|p| p.is_locked()));
        assert!(worst <= 1_000, "drive {i}: {worst} ns");
    }
}

#[test]
fn e114_e119_loss_of_sync0_loses_the_lock_and_reports_a_pll_fault() {
    let sim = line();
    let mut locked_before = [false; 2];
    let seen = run(&sim, 330, Inject::StopSync0(300), |i, s| {
        if i != 299 {
            return;
        }
        for (i, d) in s.drives().iter().enumerate() {
            locked_before[i] = d.drive.pll().is_some_and(|p| p.is_locked());
        }
    });
    let s = sim.borrow();
    for (i, seen) in seen.iter().enumerate() {
        let d = &s.drives()[i];
        let pll = d.drive.pll().expect("PLL kept (hold-over)");
        println!(
            "drive {i}: locked before {}, after: A298 {:#06x}, fault {:?} (AL {:#06x})",
            locked_before[i],
            seen.a298,
            pll.fault(),
            pll.fault().map_or(0, |f| f.al_status_code())
        );
        assert!(locked_before[i], "drive {i} locked before SYNC0 stopped");
        assert!(!pll.is_locked());
        assert_eq!(pll.fault(), Some(SyncFault::Sync0Timeout));
        assert_eq!(seen.sync_error, [1, 1], "E-119: 1C32h:20 and A264[9]");
        let st = PllStatus(seen.a298);
        assert!(
            st.contains(PllStatus::ERROR),
            "A298 error bit: {:#06x}",
            seen.a298
        );
        assert_eq!(
            seen.a298 & (PllStatus::PHASE_LOCKED | PllStatus::SYNC0_PRESENT),
            0
        );
        // the control cycle keeps running at the last frequency
        let last: Vec<_> = d.cycle_log.iter().rev().take(20).collect();
        for w in last.windows(2) {
            let dt = w[0].system_ns - w[1].system_ns;
            assert!(dt.abs_diff(SYNC0_NS) <= 1_000, "hold-over cycle {dt} ns");
        }
    }
}

#[test]
fn e117_e118_e119_a_late_frame_counts_in_a261_and_1c32h() {
    let sim = line();
    let mut before = [(0u32, None); 2];
    let seen = run(&sim, 330, Inject::LateFrame(300), |i, s| {
        if i != 299 {
            return;
        }
        for (i, d) in s.drives().iter().enumerate() {
            let pll = d.drive.pll().expect("PLL");
            before[i] = (pll.diagnostics().late_frames, pll.fault());
        }
    });
    let s = sim.borrow();
    for (i, seen) in seen.iter().enumerate() {
        let pll = s.drives()[i].drive.pll().expect("PLL");
        println!(
            "drive {i}: A261[2] {} before, {} after one late frame (SDO); fault {:?}",
            before[i].0,
            seen.a261_late,
            pll.fault()
        );
        assert_eq!(seen.a261_late, before[i].0 + 1, "drive {i}: one late frame");
        // E-119: 1C32h/1C33h:0B count it too, A264[7] mirrors 1C32h:0B
        let late = seen.a261_late as u16;
        assert_eq!(seen.sm_missed, [late; 3], "drive {i}: SM-event missed");
        assert_eq!(seen.sync_error, [0, 0], "drive {i}: no sync error");
        assert!(pll.is_locked(), "SYNC0 is not moved by a frame");
        assert_eq!(pll.fault(), before[i].1, "one late frame is no sync I/O fault");
    }
}

#[test]
fn e116_a_sync0_cycle_the_pll_cannot_run_is_refused() {
    // the PLL's configuration check (the P→S check is the slave stack's)
    let bad = dcsync::Config::new(1_100_000, 1_000_000, drive_ecat::runtime::TIMER_HZ);
    assert!(dcsync::Pll::new(bad).is_err());
    let sim = line();
    let a261_0: u8 = run_in_process(&sim, async |md, clock| {
        let dc = DcConfiguration {
            start_delay: Duration::from_millis(5),
            sync0_period: Duration::from_nanos(1_100_000),
            sync0_shift: Duration::ZERO,
        };
        let group = into_dc_sync0(md, init(md, clock).await, dc, async |_| {})
            .await
            .expect("SYNC0, PRE-OP with PDI, DC configuration");
        {
            let mut s = sim.borrow_mut();
            let t = s.now().as_ns() + 20_000_000;
            s.advance_to(nanos::Nanos::from_ns(t));
        }
        let sd = group.subdevice(md, 0).expect("drive");
        let a298: u16 = sd.sdo_read(A298, 0).await.expect("A298");
        assert_ne!(a298 & PllStatus::ERROR, 0, "A298 {a298:#06x}");
        sd.sdo_read(A261, 1).await.expect("A261[0]")
    });
    let s = sim.borrow();
    let d = &s.drives()[0];
    assert!(d.sync0_log.len() > 5, "SYNC0 runs");
    assert!(d.drive.pll().is_none(), "no PLL for a 1.1 ms SYNC0 cycle");
    println!("1.1 ms SYNC0: {:?}, A261[0] = {a261_0}", d.drive.sync_error());
    assert_eq!(
        d.drive.sync_error().map(|e| e.diag_code()),
        Some(dcsync::DiagCode::CycleNotOnGrid)
    );
    assert_eq!(a261_0, 3, "A261[0] = 3: not a multiple of 250 µs");
    assert!(d.cycle_log.is_empty(), "the control cycle stays free-running");
}

const ERR_ACK: u16 = 0x10;

/// The line with DC SYNC0 at [`SYNC0_NS`] on every drive and Op requested
/// (ethercrab's init, Pre-Op with PDI, the DC configuration).
async fn dc_requested_op<'a>(md: &'a MainDevice<'a>, clock: &'a AtomicU64) -> DcOpGroup {
    dc_requested_op_after(md, clock, SYNC0_NS, async |_| {}).await
}

/// [`dc_requested_op`] with SYNC0 every `sync0_ns`, `pre_op` run on every
/// drive in Pre-Op.
async fn dc_requested_op_after<'a>(
    md: &'a MainDevice<'a>,
    clock: &'a AtomicU64,
    sync0_ns: u64,
    pre_op: impl for<'b> AsyncFn(&'b Sd<'b>),
) -> DcOpGroup {
    into_dc_sync0(md, init(md, clock).await, dc_config(sync0_ns), pre_op)
        .await
        .expect("SYNC0, PRE-OP with PDI, DC configuration")
        .request_into_op(md)
        .await
        .expect("request OP")
}

/// Runs `n` `tx_rx_dc` cycles, the clock advanced as ethercrab computes it;
/// calls `probe` after each with the cycle number, whether the group is in
/// OP, and the simulation.
async fn dc_cycles<'a>(
    md: &'a MainDevice<'a>,
    group: &DcOpGroup,
    sim: &RefCell<Simulation>,
    n: usize,
    mut probe: impl FnMut(usize, bool, &Simulation),
) {
    for i in 0..n {
        let r = group.tx_rx_dc(md).await.expect("DC cycle");
        probe(i, r.all_op(), &sim.borrow());
        let wait = r.extra.next_cycle_wait.as_nanos() as u64;
        let mut s = sim.borrow_mut();
        let t = s.now().as_ns() + wait;
        s.advance_to(nanos::Nanos::from_ns(t));
    }
}

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

const A149: u16 = drive_ecat::parameter_index(0, 149);
const A150: u16 = drive_ecat::parameter_index(0, 150);
const A287: u16 = drive_ecat::parameter_index(0, 287);

/// Brings the line to OP with DC (SYNC0 every `sync0_ns`, frames
/// [`FRAME_LEAD_NS`] before SYNC0, A292 = [`A292_US`]) after `pre_op` ran in
/// Pre-Op, runs `n` cycles (see [`dc_cycles`]), then `body`.
fn dc_op<T>(
    sim: &RefCell<Simulation>,
    sync0_ns: u64,
    pre_op: impl for<'a> AsyncFn(&'a Sd<'a>),
    n: usize,
    body: impl for<'a> AsyncFnOnce(&'a MainDevice<'a>, &'a DcOpGroup) -> T,
) -> T {
    run_in_process(sim, async |md, clock| {
        let group = dc_requested_op_after(md, clock, sync0_ns, async |sd| {
            sd.sdo_write(A292, 0, A292_US).await.expect("A292");
            pre_op(sd).await;
        })
        .await;
        let mut op = None;
        dc_cycles(md, &group, sim, n, |i, all_op, _| {
            if all_op && op.is_none() {
                op = Some(i);
            }
        })
        .await;
        assert!(op.is_some(), "the group reached OP");
        body(md, &group).await
    })
}

/// E-120, E-121, E-123, E-124 (spec §11.8): A287[0] = 1 (sub 1) in Pre-Op
/// fails at once with 2 ("not executable"); in Op with DC SYNC0 it runs over
/// ≥ 1000 × A150, A287[1] (progress) rises by SDO, then A287[2] is 7 or 8
/// with a proposed A292 range min ≤ max (A287[3], [4]) around the A292 in
/// force, and A287[0] is back to 0.
#[test]
fn e120_e123_e124_a287_optimisation_through_the_master() {
    let sim = line();
    let pre_op = async |sd: &Sd<'_>| {
        sd.sdo_write(A287, 1, 1u8).await.expect("A287[0] in Pre-Op");
        let mut result = 0u8;
        for _ in 0..10 {
            result = sd.sdo_read(A287, 3).await.expect("A287[2]");
            if result != 0 {
                break;
            }
        }
        let start: u8 = sd.sdo_read(A287, 1).await.expect("A287[0]");
        println!("A287 in Pre-Op: result {result}, start {start}");
        assert_eq!(result, 2, "E-121: not executable in Pre-Op");
        assert_eq!(start, 0, "A287[0] back to 0");
    };
    let (progress, seen) = dc_op(&sim, SYNC0_NS, pre_op, 150, async |md, group| {
        for sd in group.iter(md) {
            sd.sdo_write(A287, 1, 1u8).await.expect("A287[0] = 1");
        }
        let mut progress: Vec<u8> = Vec::new();
        let mut done = false;
        for _ in 0..30 {
            dc_cycles(md, group, &sim, 50, |_, _, _| {}).await;
            let sd = group.subdevice(md, 0).expect("drive");
            let p: u8 = sd.sdo_read(A287, 2).await.expect("A287[1]");
            progress.push(p);
            let r: u8 = sd.sdo_read(A287, 3).await.expect("A287[2]");
            if r >= 2 {
                done = true;
                break;
            }
        }
        assert!(done, "finished: progress {progress:?}");
        let mut seen = Vec::new();
        for i in 0..2 {
            let sd = group.subdevice(md, i).expect("drive");
            let mut v = [0i64; 8];
            for (k, slot) in v.iter_mut().enumerate() {
                *slot = match k {
                    0..=2 => i64::from(sd.sdo_read::<u8>(A287, k as u8 + 1).await.expect("A287")),
                    _ => i64::from(sd.sdo_read::<i32>(A287, k as u8 + 1).await.expect("A287")),
                };
            }
            seen.push(v);
        }
        (progress, seen)
    });
    println!("A287[1] progress of drive 0 by SDO: {progress:?}");
    assert!(
        progress.iter().any(|&p| p > 0 && p < 100),
        "E-124: progress during the measurement"
    );
    assert!(progress.windows(2).all(|w| w[0] <= w[1]), "progress never falls");
    let s = sim.borrow();
    for (i, v) in seen.iter().enumerate() {
        println!(
            "drive {i}: A287 = {v:?} ([0] start, [1] %, [2] result, [3]/[4] A292 min/max µs, [5] EoF→SYNC0, \
             [6] frame, [7] SYNC0→Rx)"
        );
        assert_eq!(v[0], 0, "drive {i}: A287[0] back to 0");
        assert_eq!(v[1], 100, "drive {i}: progress 100 %");
        assert!(matches!(v[2], 7 | 8), "E-123: drive {i}: result {}", v[2]);
        assert!(v[3] <= v[4], "drive {i}: min ≤ max");
        if v[2] == 7 {
            assert!(
                (v[3]..=v[4]).contains(&i64::from(A292_US)),
                "drive {i}: 7 = A292 in range"
            );
        }
        assert!((-1000..1000).contains(&v[3]) && (-1000..1000).contains(&v[4]));
        let out = s.drives()[i].drive.optimizer().outcome().expect("outcome");
        assert!(out.result.is_success());
        // frames ≈ 100 µs before SYNC0; the SDO reads in between delay some
        assert!((-500..=110).contains(&v[5]), "drive {i}: EoF → SYNC0 {} µs", v[5]);
        assert!((0..500).contains(&v[6]), "drive {i}: frame window {} µs", v[6]);
    }
}

/// Position actual value 6064h of axis A: the drive's object and its bytes in
/// the TxPDO image the drive's Tx step wrote (what the next frame carries).
fn actual_and_txpdo(d: &mut hil_sim::sim::SimDrive) -> (i64, i64) {
    let obj = d.drive.objects().get(0x6064, 0).expect("6064h");
    let at = txpdo_6064_at(d);
    let img = d.drive.slave_mut().inputs_mut();
    let tx = i32::from_le_bytes(img[at..at + 4].try_into().unwrap());
    (obj, i64::from(tx))
}

/// The byte offset of 6064h (axis A) in the drive's TxPDO image.
fn txpdo_6064_at(d: &hil_sim::sim::SimDrive) -> usize {
    let e = d
        .drive
        .pdo_image()
        .tx()
        .entries()
        .iter()
        .find(|e| e.index == 0x6064)
        .expect("6064h mapped");
    usize::from(e.bit_offset / 8)
}

/// E-111 (spec §11.5): the motor of axis A moves by a new position every
/// cycle. With A149 = 0 (Rx → app → Tx) the TxPDO written by a cycle carries
/// the actual position the application computed in that same cycle; with
/// A149 = 1 (Rx → Tx → app) it carries the previous cycle's.
#[test]
fn e111_a149_orders_rx_app_tx() {
    for a149 in [0u8, 1] {
        let sim = line();
        let pre_op = async |sd: &Sd<'_>| {
            sd.sdo_write(A149, 0, a149).await.expect("A149");
        };
        let (same, differ, master_lag) = dc_op(&sim, SYNC0_NS, pre_op, 150, async |md, group| {
            let (mut same, mut differ) = (0, 0);
            let mut images = Vec::new();
            let mut master = Vec::new();
            for i in 0..40i64 {
                sim.borrow_mut().drives_mut()[0].motors[0].set_position_inc(100_000 * (i + 1));
                dc_cycles(md, group, &sim, 1, |_, _, _| {}).await;
                let (obj, tx) = actual_and_txpdo(&mut sim.borrow_mut().drives_mut()[0]);
                if i >= 5 {
                    if obj == tx {
                        same += 1;
                    } else {
                        differ += 1;
                    }
                }
                images.push(tx);
                let sd = group.subdevice(md, 0).expect("drive");
                let inputs = sd.inputs_raw();
                let at = txpdo_6064_at(&sim.borrow().drives()[0]);
                master.push(i64::from(i32::from_le_bytes(
                    inputs[at..at + 4].try_into().unwrap(),
                )));
            }
            // the frame after a probe carries the image seen at the probe
            let lag = (0..3usize).find(|&l| (10..39).all(|i| master[i + l] == images[i]));
            (same, differ, lag)
        });
        println!(
            "A149 = {a149}: TxPDO = this cycle's 6064h in {same} cycles, another in {differ}; \
             master sees the image {master_lag:?} frame(s) later"
        );
        if a149 == 0 {
            assert_eq!(differ, 0, "A149 = 0: Tx after the application");
        } else {
            assert_eq!(same, 0, "A149 = 1: Tx before the application");
        }
        assert!(master_lag.is_some(), "the image written by Tx goes on the bus");
    }
}

/// E-112 (spec §11.3, §11.4): SYNC0 = 2 ms with A150 = 1 ms (k = 2): P→S
/// accepted, the PLL locks, two control cycles per SYNC0 of which only one
/// (index 0, at SYNC0 − A292) is aligned and runs Rx/Tx.
#[test]
fn e112_sync0_twice_a150() {
    const SYNC0_2MS: u64 = 2_000_000;
    let sim = line();
    let pre_op = async |sd: &Sd<'_>| {
        sd.sdo_write(A150, 0, 1000u16).await.expect("A150");
    };
    let a296 = dc_op(&sim, SYNC0_2MS, pre_op, 200, async |md, group| {
        let sd = group.subdevice(md, 0).expect("drive");
        let v: u32 = sd.sdo_read(A296, 0).await.expect("A296");
        v
    });
    assert_eq!(a296, 2000, "A296: the 2 ms SYNC0 cycle");
    let s = sim.borrow();
    for (i, d) in s.drives().iter().enumerate() {
        let pll = d.drive.pll().expect("PLL");
        assert_eq!(pll.k(), 2, "drive {i}: k = 2");
        assert!(pll.is_locked(), "drive {i} locked");
        assert_eq!(d.drive.slave().state(), esc::AlState::Op);
        let log: Vec<_> = d.cycle_log.iter().filter(|c| c.locked).collect();
        assert!(log.len() >= 100, "drive {i}: {} locked cycles", log.len());
        for w in log.windows(2) {
            let dt = w[1].system_ns - w[0].system_ns;
            assert!(dt.abs_diff(1_000_000) <= 1_000, "drive {i}: cycle {dt} ns");
            assert_ne!(w[0].index, w[1].index, "indices alternate");
        }
        for c in &log {
            assert_eq!((c.rx, c.tx), (c.index == 0, c.index == 0), "Rx/Tx only aligned");
            if c.index == 0 {
                let target = -i64::from(A292_US) * 1000;
                let p = SYNC0_2MS as i64;
                let e = (c.system_ns as i64 - target).rem_euclid(p);
                let e = if e >= p / 2 { e - p } else { e };
                assert!(e.abs() <= 1_000, "drive {i}: aligned at SYNC0 − A292: {e} ns");
            }
        }
        let aligned = log.iter().filter(|c| c.index == 0).count();
        println!(
            "drive {i}: k = 2, {} locked cycles in the log, {aligned} aligned",
            log.len()
        );
    }
}

/// A drive in the Pre-Op group as the master holds it.
type Sd<'a> = hil_sim::master::PdiSubDevice<'a, 512>;

/// E-109 (spec §11.3): A292 = −1500 µs written by the master with A150 =
/// 1 ms is limited to one drive cycle: the aligned cycle starts just under
/// one A150 after SYNC0 and the PLL locks there.
#[test]
fn e109_a292_beyond_one_a150_is_limited_to_one_cycle_through_the_master() {
    let sim = line();
    let pre_op = async |sd: &Sd<'_>| {
        sd.sdo_write(A292, 0, -1500i32).await.expect("A292");
    };
    dc_op(&sim, SYNC0_NS, pre_op, 400, async |_, _| {});
    let s = sim.borrow();
    for (i, d) in s.drives().iter().enumerate() {
        let pll = d.drive.pll().expect("PLL");
        assert_eq!(
            d.drive.objects().get(A292, 0),
            Ok(-1500),
            "the object keeps the value"
        );
        assert_eq!(pll.phase_offset_ns(), -999_999, "drive {i}: limited to one A150");
        assert!(pll.is_locked(), "drive {i} locked");
        let target = 999_999i64;
        let p = SYNC0_NS as i64;
        let errors: Vec<i64> = d
            .cycle_log
            .iter()
            .filter(|c| c.locked)
            .map(|c| {
                let e = (c.system_ns as i64 - target).rem_euclid(p);
                if e >= p / 2 {
                    e - p
                } else {
                    e
                }
            })
            .collect();
        let worst = errors.iter().map(|e| e.abs()).max().unwrap_or(i64::MAX);
        println!(
            "drive {i}: A292 −1500 µs → {} ns, worst {worst} ns",
            pll.phase_offset_ns()
        );
        assert!(errors.len() >= 100 && worst <= 1_000, "drive {i}: {worst} ns");
    }
}

/// E-115 (spec §11.6) through the master: bits 0/1 when the PLL uses at
/// least half of its ±500 ppm range (drive 0 is the DC reference at 0 ppm;
/// drive 1 at +300 ppm lengthens its cycle, drive 2 at −300 ppm shortens
/// it), bit 2 while it stretches cycles to align, bit 4 when A296 > A291
/// (60C2h = 500 µs is copied into A291), bit 5 when A290 ≠ 1.
#[test]
fn e115_a298_bits_through_the_master() {
    let mut line3 = Simulation::new(3);
    for (d, drift) in line3.drives_mut().iter_mut().zip([0.0, 300.0, -300.0]) {
        d.set_clock(drift, 1_234_567);
    }
    let sim = RefCell::new(line3);
    let mut ever = [0u16; 3];
    run(&sim, 600, Inject::Nothing, |_, s| {
        for (i, d) in s.drives().iter().enumerate() {
            ever[i] |= d.drive.objects().get(A298, 0).unwrap() as u16;
        }
    });
    let s = sim.borrow();
    let a298: Vec<u16> = s
        .drives()
        .iter()
        .map(|d| d.drive.objects().get(A298, 0).unwrap() as u16)
        .collect();
    println!("A298 at 0 / +300 / −300 ppm: {a298:04x?}, seen {ever:04x?}");
    let locked = PllStatus::PHASE_LOCKED | PllStatus::SYNC0_PRESENT;
    let engaged = PllStatus::ENGAGED_SLOWER | PllStatus::ENGAGED_FASTER;
    assert!(PllStatus(a298[0]).contains(locked));
    assert_eq!(a298[0] & engaged, 0, "the reference sees no drift");
    assert!(PllStatus(a298[1]).contains(locked | PllStatus::ENGAGED_SLOWER));
    assert!(PllStatus(a298[2]).contains(locked | PllStatus::ENGAGED_FASTER));
    for (i, a) in a298.iter().enumerate() {
        let not = PllStatus::MAX_RANGE | PllStatus::SYNC_CYCLE_TOO_LONG | PllStatus::DEACTIVATED;
        assert_eq!(a & not, 0, "drive {i}: {a:#06x}");
        assert_ne!(
            ever[i] & PllStatus::CYCLE_EXTENDED,
            0,
            "drive {i}: stretched while aligning"
        );
    }
    drop(s);

    // 60C2h = 5 × 10⁻⁴ s: A291 = 500 µs < A296 = 1000 µs; then A290 = 0
    let sim = line();
    let pre_op = async |sd: &Sd<'_>| {
        sd.sdo_write(0x60C2, 1, 5u8).await.expect("60C2h:01");
        sd.sdo_write(0x60C2, 2, -4i8).await.expect("60C2h:02");
    };
    let (bit4, bit5): (u16, u16) = dc_op(&sim, SYNC0_NS, pre_op, 200, async |md, group| {
        let sd = group.subdevice(md, 0).expect("drive");
        let a291: u32 = sd
            .sdo_read(drive_ecat::parameter_index(0, 291), 0)
            .await
            .expect("A291");
        assert_eq!(a291, 500, "60C2h copied into A291");
        let bit4 = sd.sdo_read(A298, 0).await.expect("A298");
        sd.sdo_write(drive_ecat::parameter_index(0, 290), 0, 0u8)
            .await
            .expect("A290");
        dc_cycles(md, group, &sim, 5, |_, _, _| {}).await;
        (bit4, sd.sdo_read(A298, 0).await.expect("A298"))
    });
    println!("A298 with A291 = 500 µs: {bit4:#06x}; then A290 = 0: {bit5:#06x}");
    assert!(PllStatus(bit4).contains(PllStatus::SYNC_CYCLE_TOO_LONG | PllStatus::PHASE_LOCKED));
    assert_eq!(bit4 & PllStatus::DEACTIVATED, 0);
    assert!(PllStatus(bit5).contains(PllStatus::DEACTIVATED));
}

/// Runs one A287 measurement on both drives of `group`,
/// calling `each` with the cycle number and the simulation after every
/// cycle; returns drive 0's A287[2], [3], [4] (result, A292 min/max µs) as
/// the dictionary holds them.
async fn a287_measurement<'a>(
    md: &'a MainDevice<'a>,
    group: &DcOpGroup,
    sim: &RefCell<Simulation>,
    mut each: impl FnMut(usize, &mut Simulation),
) -> (i64, i64, i64) {
    // started in the dictionary, not by SDO: mailbox traffic would delay the
    // next frames and look like master jitter (the SDO start is tested above)
    for d in sim.borrow_mut().drives_mut() {
        d.drive.objects_mut().set(A287, 1, 1).expect("A287[0] = 1");
    }
    for k in 0..1500 {
        dc_cycles(md, group, sim, 1, |_, _, _| {}).await;
        let mut s = sim.borrow_mut();
        each(k, &mut s);
        if s.drives()[0].drive.objects().get(A287, 3).unwrap() >= 2 {
            break;
        }
    }
    let s = sim.borrow();
    let get = |sub| s.drives()[0].drive.objects().get(A287, sub).unwrap();
    (get(3), get(4), get(5))
}

/// E-121, E-122, E-123 (spec §11.8) through the master, with the drive's
/// measured Rx/Tx offsets ([`drive_ecat::runtime::Drive::set_step_offsets`]) and
/// the frame jitter injected: Rx…Tx over 995 µs of the 1 ms cycle leaves no
/// room for the frame (5: application runtime); Rx/Tx moving by 30 µs from
/// cycle to cycle (4: drive jitter); ±20 µs frame jitter (3: master jitter);
/// each failure proposes min = max = the A292 in force. A291 ≠ the master
/// cycle (60C2h = 2 ms) and SM-Sync (no DC) give 2 at once.
#[test]
fn e121_e122_e123_a287_failures_through_the_master() {
    let sim = line();
    let results = dc_op(
        &sim,
        SYNC0_NS,
        async |_| {},
        150,
        async |md, group| {
            let offsets = |s: &mut Simulation, rx: u32, tx: u32| {
                for d in s.drives_mut() {
                    d.drive.set_step_offsets(rx, tx);
                }
            };
            let runtime = a287_measurement(md, group, &sim, |_, s| offsets(s, 0, 995_000)).await;
            let jitter = a287_measurement(md, group, &sim, |k, s| {
                let j = if k % 2 == 0 { 0 } else { 30_000 };
                offsets(s, j, 960_000 + j);
            })
            .await;
            let master = a287_measurement(md, group, &sim, |k, s| {
                if k == 0 {
                    s.set_frame_jitter(nanos::Nanos::from_ns(20_000), 0xE122);
                }
                offsets(s, 0, 985_000);
            })
            .await;
            sim.borrow_mut().set_frame_jitter(nanos::Nanos::from_ns(0), 0);
            // A291 ≠ the master cycle: 60C2h = 2 ms is copied into A291
            let sd = group.subdevice(md, 0).expect("drive");
            sd.sdo_write(0x60C2, 1, 2u8).await.expect("60C2h:01");
            sd.sdo_write(0x60C2, 2, -3i8).await.expect("60C2h:02");
            dc_cycles(md, group, &sim, 3, |_, _, _| {}).await;
            let a291 = a287_measurement(md, group, &sim, |_, _| {}).await;
            [runtime, jitter, master, a291]
        },
    );
    println!(
        "A287 (result, min, max): runtime {:?}, drive jitter {:?}, frame jitter {:?}, A291 {:?}",
        results[0], results[1], results[2], results[3]
    );
    let a292 = i64::from(A292_US);
    for (r, want) in results.iter().zip([5, 4, 3, 2]) {
        assert_eq!(*r, (want, a292, a292), "result {want}: min = max = A292");
    }

    // SM-Sync (no DC): not executable
    let sim = RefCell::new(Simulation::new(1));
    let result: u8 = run_in_process(&sim, async |md, clock| {
        let group = init(md, clock).await.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).expect("drive");
        sd.sdo_write(A287, 1, 1u8).await.expect("A287[0]");
        sd.sdo_read(A287, 3).await.expect("A287[2]")
    });
    assert_eq!(result, 2, "E-121: DC not used");
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
