//! Distributed clocks end to end: ethercrab (in-process) against simulated
//! drives whose oscillators drift differently. The master's DC start-up
//! (receive-time latch, offsets, delays, static drift compensation) must
//! synchronise the ESCs' system times through the ESCs' drift-control loops,
//! and the SYNC0 configuration it writes must make the cyclic units pulse at
//! the configured period (E-107 DC-Sync; E-113 frame jitter).

use ethercrab::subdevice_group::DcConfiguration;
use ethercrab::{MainDevice, SubDeviceGroup};
use hil_sim::master::{into_dc_sync0, run_in_process};
use hil_sim::sim::{SimDrive, Simulation};
use nanos::Nanos;
use std::cell::RefCell;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

/// Oscillator drift of drive 0 (the DC reference) and drive 1, ppm.
const DRIFTS: [f64; 2] = [50.0, -80.0];
/// Local time of each drive at simulation time 0, ns (unrelated phases).
const OFFSETS: [u64; 2] = [3_000_000_000, 987_654_321];
/// SYNC0 period, ns.
const SYNC0_NS: u64 = 1_000_000;

/// Two drifting drives.
fn line() -> RefCell<Simulation> {
    RefCell::new(Simulation::with_clocks(&DRIFTS, &OFFSETS))
}

async fn init<'a>(md: &'a MainDevice<'a>, clock: &'a AtomicU64) -> SubDeviceGroup<8, 512> {
    md.init_single_group::<8, 512>(|| clock.load(Ordering::Relaxed))
        .await
        .expect("ethercrab init")
}

/// Signed value of a system time difference register (sign bit 31, magnitude).
fn signed(v: u32) -> i64 {
    let mag = i64::from(v & 0x7FFF_FFFF);
    if v & 1 << 31 != 0 {
        -mag
    } else {
        mag
    }
}

/// System time of drive 0 minus drive 1, at the same instant.
fn skew(sim: &RefCell<Simulation>) -> i64 {
    let s = sim.borrow();
    let now = s.now();
    let [a, b] = [0, 1].map(|i| s.drives()[i].esc.system_time_ns(now));
    a.wrapping_sub(b) as i64
}

#[test]
fn e107_dc_start_up_synchronises_drifting_clocks() {
    let sim = line();
    let (diff, skew_after_init) = run_in_process(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 1).expect("second drive");
        let diff: u32 = sd
            .register_read(esc::regs::dc::SYSTEM_TIME_DIFFERENCE)
            .await
            .expect("read 0x092C");
        (signed(diff), skew(&sim))
    });
    let s = sim.borrow();
    let rate = [0, 1].map(|i| s.drives()[i].esc.clock_rate_ppb());
    println!(
        "after init ({} frames, {:.1} ms): 0x092C of drive 1 = {diff} ns, system time skew {skew_after_init} ns, \
         clock rates {rate:?} ppb",
        s.frames(),
        s.now().as_ns() as f64 / 1e6
    );
    assert!(diff.abs() <= 5, "system time difference {diff} ns");
    assert!(skew_after_init.abs() <= 5, "skew {skew_after_init} ns");
    assert_eq!(rate[0], 50_000, "the reference clock is not adjusted");
    assert!(
        (rate[1] - 50_000).abs() < 1_000,
        "drive 1 follows the reference: {} ppb",
        rate[1]
    );
}

/// Brings the line to OP with SYNC0 every [`SYNC0_NS`] and runs `cycles` DC
/// cycles (`tx_rx_dc`, the clock advanced to the next cycle as ethercrab
/// computes it); returns the worst |0x092C| of drive 1 and the worst system
/// time skew seen over the last half of the cycles.
fn run_sync0(sim: &RefCell<Simulation>, cycles: usize) -> (i64, i64) {
    run_in_process(sim, async |md, clock| {
        let dc = DcConfiguration {
            start_delay: Duration::from_millis(20),
            sync0_period: Duration::from_nanos(SYNC0_NS),
            // frames 250 µs before SYNC0: after it they would be late
            // (E-118) and the drive would refuse Op with 0033h
            sync0_shift: Duration::from_nanos(SYNC0_NS - SYNC0_NS / 4),
        };
        let group = into_dc_sync0(md, init(md, clock).await, dc, async |_| {})
            .await
            .expect("SYNC0, PRE-OP with PDI, DC configuration")
            .request_into_op(md)
            .await
            .expect("request OP");
        let (mut worst_diff, mut worst_skew) = (0i64, 0i64);
        let mut op = false;
        for i in 0..cycles {
            let r = group.tx_rx_dc(md).await.expect("DC cycle");
            op |= r.all_op();
            if i >= cycles / 2 {
                let sd = group.subdevice(md, 1).expect("second drive");
                let d: u32 = sd
                    .register_read(esc::regs::dc::SYSTEM_TIME_DIFFERENCE)
                    .await
                    .expect("read 0x092C");
                worst_diff = worst_diff.max(signed(d).abs());
                worst_skew = worst_skew.max(skew(sim).abs());
            }
            let wait = r.extra.next_cycle_wait.as_nanos() as u64;
            let mut s = sim.borrow_mut();
            let t = s.now() + Nanos::from_ns(wait);
            s.advance_to(t);
        }
        assert!(op, "the group reached OP");
        (worst_diff, worst_skew)
    })
}

/// Checks the SYNC0 pulses both drives logged: exact period in system time,
/// none missed, both drives' edges at the same instant; returns the SYNC0
/// period in simulation time (ns) and the worst edge skew between the drives.
fn check_sync0_logs(sim: &RefCell<Simulation>) -> (f64, u64) {
    let s = sim.borrow();
    let logs: Vec<Vec<_>> = s
        .drives()
        .iter()
        .map(|d: &SimDrive| d.sync0_log.iter().copied().collect())
        .collect();
    for (i, log) in logs.iter().enumerate() {
        assert_eq!(log.len(), hil_sim::sim::SYNC0_LOG_LEN, "drive {i}: log full");
        assert!(
            log.iter().all(|p| p.system_ns % SYNC0_NS == 0),
            "on the cycle grid"
        );
        for w in log.windows(2) {
            assert_eq!(w[1].system_ns - w[0].system_ns, SYNC0_NS, "drive {i}: period");
            assert_eq!(w[1].pulses, 1, "drive {i}: no pulse missed");
        }
    }
    let mut worst = 0;
    for p in &logs[0] {
        if let Some(q) = logs[1].iter().find(|q| q.system_ns == p.system_ns) {
            worst = worst.max(p.now.as_ns().abs_diff(q.now.as_ns()));
        }
    }
    let l = &logs[0];
    let period = (l[l.len() - 1].now - l[0].now).as_ns() as f64 / (l.len() - 1) as f64;
    (period, worst)
}

#[test]
fn e107_sync0_pulses_at_the_configured_period_on_drifting_drives() {
    let sim = line();
    let (diff, skew) = run_sync0(&sim, 300);
    let (period, edge_skew) = check_sync0_logs(&sim);
    println!(
        "SYNC0: period {period:.1} ns of simulation time, edge skew between drives {edge_skew} ns, \
         worst 0x092C {diff} ns, worst system time skew {skew} ns"
    );
    // the system time runs with the reference's oscillator (+50 ppm)
    assert!((period - 1e6 / (1.0 + 50e-6)).abs() < 2.0, "period {period}");
    assert!(
        edge_skew <= 10,
        "SYNC0 of both drives at the same instant: {edge_skew} ns"
    );
    assert!(diff <= 5 && skew <= 5, "stays synchronised: {diff} / {skew} ns");
    // the SYNC0 lock as `serve` reports it, followed at every control
    // cycle: gained once, never lost
    for (i, d) in sim.borrow().drives().iter().enumerate() {
        let l = d.pll_lock;
        assert!(l.locked && l.gained == 1 && l.lost == 0, "drive {i}: {l:?}");
    }
}

#[test]
fn e113_frame_jitter_of_5us_does_not_disturb_sync0() {
    let sim = line();
    sim.borrow_mut().set_frame_jitter(Nanos::from_us(5), 0xE113);
    let (diff, skew) = run_sync0(&sim, 300);
    let (period, edge_skew) = check_sync0_logs(&sim);
    println!(
        "SYNC0 with ±5 µs frame jitter: period {period:.1} ns, edge skew {edge_skew} ns, \
         worst 0x092C {diff} ns, worst skew {skew} ns"
    );
    assert!((period - 1e6 / (1.0 + 50e-6)).abs() < 2.0, "period {period}");
    assert!(edge_skew <= 10, "{edge_skew} ns");
    assert!(diff <= 5 && skew <= 5, "{diff} / {skew} ns");
}
