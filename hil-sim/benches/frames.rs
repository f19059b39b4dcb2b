//! Simulated lines of 2, 16, 64 and 128 drives at a 1 kHz and a 4 kHz
//! cycle: frames per wall-clock second and the real-time factor (simulated
//! time / wall time).
//!
//! `cargo bench -p hil-sim --bench frames [-- --cycles N] [--drives N] [--hz F] [--pcap FILE]`
//!
//! Each case: ethercrab (in-process, its own time the simulated clock)
//! brings the line to Op with A150 = the cycle (1000 µs at 1 kHz, 250 µs at
//! 4 kHz, the drive's shortest), then runs `--cycles` process-data cycles
//! (default 500), each the group's LRW in as many frames as the process
//! image needs plus ethercrab's AL status checks; the clock runs on to the
//! next cycle between them (`Simulation::advance_to`: SYNC0, control cycles
//! and the firmware's polls in between). Two ways, printed as `sync`:
//!
//! - `DC`: SYNC0 at the cycle, `tx_rx_dc` (with the FRMW of the reference
//!   clock), the master cycle placed so that every drive's frame arrives a
//!   quarter cycle before SYNC0. Before Op the line waits in Safe-Op until
//!   every drive's PLL is locked.
//! - `free`: when the line cannot carry the cycle that way (the frames of
//!   one cycle spread over more than a quarter cycle, so some drive's data
//!   would arrive outside the half cycle before SYNC0 that E-118 allows, or
//!   they take longer than the cycle): no SYNC0, the drives' control cycle
//!   free-runs at A150, and the master's cycle (`cycle µs`) is the shortest
//!   multiple of A150 that carries the frames (ethercrab sends one frame at
//!   a time and waits for it; 100 Mbit/s and 0.5 µs per drive on the line).
//!
//! Columns: `frames` per cycle; `bus µs` simulated time from a cycle's
//! first frame out to its last back; `cycle µs` the master cycle run;
//! `frames/s` through the whole chain (master, link, ESCs, drive firmware)
//! per wall-clock second; `RTF` simulated time / wall time of the whole
//! chain (> 1: faster than real time); `RTF cpu` simulated time / the
//! CPU time the benchmark's thread used (on a shared machine the wall time
//! includes the time other processes had the CPU); `RTF sim` simulated
//! time / the wall time inside `Simulation::exchange` and `advance_to` (the
//! simulation alone: what `hil-sim serve` has to keep up with, where the
//! master is another machine); `wkc` the cycle's working counter (3 per drive, more
//! where a drive's data is split between two frames) and the cycles that
//! had it; `Op` drives in Op at the end; `setup s` wall time to Op.
//!
//! `--drives N` and `--hz F` run one case (e.g. under `perf record`);
//! `--pcap FILE` records its frames, setup included, at their simulated
//! times (the simulation is deterministic: an optimisation of the simulator
//! that changes no behaviour leaves the file as it was; the figures then
//! include writing it).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use ethercrab::subdevice_group::DcConfiguration;
use ethercrab::{DcSync, MainDevice, MainDeviceConfig, PduRx, PduTx, SubDeviceState};
use hil_sim::sim::Simulation;
use nanos::Nanos;
use std::cell::{Cell, RefCell};
use std::future::Future;
use std::pin::Pin;
use std::sync::atomic::{AtomicU64, Ordering};
use std::task::{Context, Poll};
use std::time::{Duration, Instant};

/// Most drives of a case (ethercrab's group capacity).
const MAX_DRIVES: usize = 128;
/// Process image capacity of the group, bytes.
const MAX_PDI: usize = 8192;
/// A150, the drive's application cycle time, µs.
const A150: u16 = 0x2096;
/// Slack between the last frame of a cycle and the next cycle.
const MARGIN: Nanos = Nanos::from_us(20);

/// [`hil_sim::master::InProcessLink`] that adds up the wall time spent in
/// the simulation and notes when each frame went out.
struct TimedLink<'a> {
    tx: PduTx<'a>,
    rx: PduRx<'a>,
    sim: &'a RefCell<Simulation>,
    clock: &'a AtomicU64,
    in_sim: &'a Cell<Duration>,
    /// Simulated time the frames of the current cycle went out.
    sent: &'a RefCell<Vec<Nanos>>,
}

impl Future for TimedLink<'_> {
    type Output = ();

    fn poll(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<()> {
        self.tx.replace_waker(cx.waker());
        while let Some(frame) = self.tx.next_sendable_frame() {
            let mut buf = [0u8; 1536];
            let mut len = 0;
            let sent = frame.send_blocking(|bytes| {
                len = bytes.len().min(buf.len());
                buf[..len].copy_from_slice(&bytes[..len]);
                Ok(len)
            });
            if sent.is_err() {
                continue;
            }
            let start = Instant::now();
            let now = {
                let mut sim = self.sim.borrow_mut();
                self.sent.borrow_mut().push(sim.now());
                sim.exchange(&mut buf[..len]);
                sim.now().as_ns()
            };
            self.in_sim.set(self.in_sim.get() + start.elapsed());
            self.clock.store(now, Ordering::Relaxed);
            let _ = self.rx.receive_frame(&buf[..len]);
        }
        Poll::Pending
    }
}

/// The CPU time this thread has used (on a shared machine the wall time
/// also holds the time other processes had the CPU).
fn thread_cpu() -> Duration {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid timespec for the call to fill.
    #[allow(unsafe_code)]
    unsafe {
        libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts);
    }
    Duration::new(ts.tv_sec as u64, ts.tv_nsec as u32)
}

/// What one master cycle gave: working counter, drives in Op, and (DC)
/// ethercrab's wait from the cycle's start to the next cycle.
type CycleResult = (u16, usize, Option<Duration>);

fn in_op<'a>(states: impl IntoIterator<Item = &'a SubDeviceState>) -> usize {
    states.into_iter().filter(|s| **s == SubDeviceState::Op).count()
}

/// One measured case.
struct Row {
    drives: usize,
    hz: u32,
    /// SYNC0 on, or free run (the line cannot carry the cycle with SYNC0).
    dc: bool,
    pdi_bytes: usize,
    setup: Duration,
    cycles: usize,
    frames: u64,
    /// Simulated time of the measured cycles.
    sim: Nanos,
    wall: Duration,
    /// CPU time of the measured cycles.
    cpu: Duration,
    /// Wall time inside the simulation.
    in_sim: Duration,
    bus_sum: Nanos,
    /// The working counter of the first cycle with every drive in Op.
    wkc: u16,
    /// Cycles with that working counter.
    wkc_ok: usize,
    op: usize,
}

/// The shared state of one case.
struct Rig<'a> {
    sim: &'a RefCell<Simulation>,
    in_sim: &'a Cell<Duration>,
    sent: &'a RefCell<Vec<Nanos>>,
    setup_start: Instant,
}

impl Rig<'_> {
    /// Runs `step` (one master cycle) until every drive is in Op (bounded),
    /// then `cycles` measured cycles, each `cycle` after the previous one's
    /// start (or when DC says).
    async fn measure(
        &self,
        cycles: usize,
        cycle: Nanos,
        mut step: impl AsyncFnMut() -> CycleResult,
    ) -> (Duration, u16, Measured) {
        let sim = self.sim;
        let drives = sim.borrow().drives().len();
        let mut next = sim.borrow().now();
        let mut wkc = 0;
        for _ in 0..5_000 {
            sim.borrow_mut().advance_to(next);
            let out = sim.borrow().now();
            let (w, op, wait) = step().await;
            next = out + wait.map_or(cycle, |w| Nanos::from_ns(w.as_nanos() as u64));
            if op == drives {
                wkc = w;
                break;
            }
        }
        let setup = self.setup_start.elapsed();
        self.in_sim.set(Duration::ZERO);
        let (f0, t0) = {
            let s = sim.borrow();
            (s.frames(), s.now())
        };
        let mut m = Measured::default();
        let cpu = thread_cpu();
        let start = Instant::now();
        for _ in 0..cycles {
            let a = Instant::now();
            sim.borrow_mut().advance_to(next);
            self.in_sim.set(self.in_sim.get() + a.elapsed());
            let out = sim.borrow().now();
            let (w, op, wait) = step().await;
            m.bus_sum += sim.borrow().now() - out;
            m.wkc_ok += usize::from(w == wkc);
            m.op = op;
            next = out + wait.map_or(cycle, |w| Nanos::from_ns(w.as_nanos() as u64));
        }
        m.wall = start.elapsed();
        m.cpu = thread_cpu() - cpu;
        let s = sim.borrow();
        m.frames = s.frames() - f0;
        m.sim = s.now() - t0;
        (setup, wkc, m)
    }
}

/// What the measured cycles gave.
#[derive(Default)]
struct Measured {
    frames: u64,
    sim: Nanos,
    wall: Duration,
    cpu: Duration,
    bus_sum: Nanos,
    wkc_ok: usize,
    op: usize,
}

fn run_case(drives: usize, hz: u32, cycles: usize, pcap: Option<&std::path::Path>) -> Row {
    let setup_start = Instant::now();
    let period = Nanos::from_ns(1_000_000_000 / u64::from(hz));
    let quarter = Nanos::from_ns(period.as_ns() / 4);
    let a150_us = u16::try_from(period.as_us()).expect("A150 in µs");
    let sim = RefCell::new(Simulation::new(drives));
    if let Some(p) = pcap {
        sim.borrow_mut().record_pcap(p).expect("the pcap file");
    }
    let storage =
        ethercrab::PduStorage::<{ hil_sim::master::MAX_FRAMES }, { hil_sim::master::MAX_PDU_DATA }>::new();
    let (tx, rx, pdu_loop) = storage.try_split().expect("split once");
    let clock = AtomicU64::new(0);
    let in_sim = Cell::new(Duration::ZERO);
    let sent = RefCell::new(Vec::new());
    let config = MainDeviceConfig {
        dc_static_sync_iterations: 100,
        ..Default::default()
    };
    let md = MainDevice::new(pdu_loop, hil_sim::master::in_process_timeouts(), config);
    let link = TimedLink {
        tx,
        rx,
        sim: &sim,
        clock: &clock,
        in_sim: &in_sim,
        sent: &sent,
    };
    let rig = Rig {
        sim: &sim,
        in_sim: &in_sim,
        sent: &sent,
        setup_start,
    };
    let body = async {
        let md = &md;
        let mut group = md
            .init_single_group::<MAX_DRIVES, MAX_PDI>(|| clock.load(Ordering::Relaxed))
            .await
            .expect("init");
        assert_eq!(group.len(), drives, "every drive found");
        for mut sd in group.iter_mut(md) {
            sd.set_dc_sync(DcSync::Sync0);
        }
        for sd in group.iter(md) {
            sd.sdo_write(A150, 0, a150_us).await.expect("A150 in Pre-Op");
        }
        let group = group.into_pre_op_pdi(md).await.expect("Pre-Op with PDI");
        let pdi_bytes: usize = group
            .iter(md)
            .map(|s| s.io_raw().inputs().len() + s.io_raw().outputs().len())
            .sum();
        // the cycle's frames: how long they take on the line, how far apart
        rig.sent.borrow_mut().clear();
        let out = sim.borrow().now();
        group.tx_rx(md).await.expect("Pre-Op cycle");
        let bus = sim.borrow().now() - out;
        let spread = {
            let s = rig.sent.borrow();
            *s.last().expect("a frame") - s[0]
        };
        let dc = spread + quarter + MARGIN <= quarter * 2 && bus + MARGIN <= period;
        let (setup, wkc, m) = if dc {
            let group = group
                .configure_dc_sync(
                    md,
                    DcConfiguration {
                        start_delay: Duration::from_millis(10),
                        sync0_period: Duration::from_nanos(period.as_ns()),
                        // the last frame a quarter cycle before SYNC0 (E-118)
                        sync0_shift: Duration::from_nanos((period - quarter - spread).as_ns()),
                    },
                )
                .await
                .expect("DC configuration")
                .into_safe_op(md)
                .await
                .expect("Safe-Op");
            // Safe-Op until every drive's PLL has locked to SYNC0 (bounded)
            let mut locked = 0;
            for _ in 0..20_000 {
                let out = sim.borrow().now();
                let r = group.tx_rx_dc(md).await.expect("DC cycle");
                let mut s = sim.borrow_mut();
                s.advance_to(out + Nanos::from_ns(r.extra.next_cycle_wait.as_nanos() as u64));
                if s.drives()
                    .iter()
                    .all(|d| d.drive.pll().is_some_and(|p| p.is_locked()))
                {
                    locked += 1;
                    if locked == 10 {
                        break;
                    }
                }
            }
            let group = group.request_into_op(md).await.expect("request Op");
            // A drive that counted frames late while its PLL pulled in
            // (A261[2]: the PLL's cycle estimate still moving) latched the
            // fault and refuses Op with 0033h after waiting 200 ms for the
            // lock: acknowledge and ask again (bounded: one simulated second)
            let second = Nanos::from_secs(1).checked_div_span(period).unwrap_or(1);
            for i in 0..second {
                let out = sim.borrow().now();
                let r = group.tx_rx_dc(md).await.expect("DC cycle");
                sim.borrow_mut()
                    .advance_to(out + Nanos::from_ns(r.extra.next_cycle_wait.as_nanos() as u64));
                if in_op(r.subdevice_states.iter()) == drives {
                    break;
                }
                if i % 20 != 19 {
                    continue;
                }
                for sd in group.iter(md) {
                    let status: u16 = sd.register_read(esc::regs::AL_STATUS).await.expect("AL status");
                    if status & 0x10 != 0 {
                        sd.register_write(esc::regs::AL_CONTROL, 0x14u16)
                            .await
                            .expect("acknowledge");
                        sd.register_write(esc::regs::AL_CONTROL, 0x08u16)
                            .await
                            .expect("Op");
                    }
                }
            }
            let group = &group;
            rig.measure(cycles, period, async || {
                let r = group.tx_rx_dc(md).await.expect("DC cycle");
                (
                    r.working_counter,
                    in_op(r.subdevice_states.iter()),
                    Some(r.extra.next_cycle_wait),
                )
            })
            .await
        } else {
            let group = group.request_into_op(md).await.expect("request Op");
            let group = &group;
            let k = (bus + MARGIN).as_ns().div_ceil(period.as_ns());
            rig.measure(cycles, period * k, async || {
                let r = group.tx_rx(md).await.expect("cycle");
                (r.working_counter, in_op(r.subdevice_states.iter()), None)
            })
            .await
        };
        Row {
            drives,
            hz,
            dc,
            pdi_bytes,
            setup,
            cycles,
            frames: m.frames,
            sim: m.sim,
            wall: m.wall,
            cpu: m.cpu,
            in_sim: in_sim.get(),
            bus_sum: m.bus_sum,
            wkc,
            wkc_ok: m.wkc_ok,
            op: m.op,
        }
    };
    let row = futures_lite::future::block_on(futures_lite::future::or(
        async {
            link.await;
            unreachable!("the link never completes")
        },
        body,
    ));
    sim.borrow_mut().flush().expect("the pcap file");
    row
}

fn arg<T: std::str::FromStr>(args: &[String], name: &str) -> Option<T> {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let cycles: usize = arg(&args, "--cycles").unwrap_or(500);
    let drives: Vec<usize> = arg(&args, "--drives").map_or(vec![2, 16, 64, 128], |n| vec![n]);
    let rates: Vec<u32> = arg(&args, "--hz").map_or(vec![1000, 4000], |f| vec![f]);
    let pcap: Option<std::path::PathBuf> = arg(&args, "--pcap");
    assert!(
        pcap.is_none() || drives.len() * rates.len() == 1,
        "--pcap records one case: give --drives and --hz"
    );
    println!(
        "{cycles} process-data cycles per case through ethercrab in-process (RTF: simulated / wall time); \
         load average {}",
        std::fs::read_to_string("/proc/loadavg")
            .map(|l| l.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
            .unwrap_or_else(|_| "unknown".into())
    );
    println!(
        "{:>6} {:>5} {:>5} {:>5} {:>6} {:>7} {:>8} {:>9} {:>6} {:>7} {:>7} {:>14} {:>7} {:>7}",
        "drives",
        "Hz",
        "sync",
        "PDI B",
        "frames",
        "bus µs",
        "cycle µs",
        "frames/s",
        "RTF",
        "RTF cpu",
        "RTF sim",
        "wkc",
        "Op",
        "setup s"
    );
    for &n in &drives {
        for &hz in &rates {
            let r = run_case(n, hz, cycles, pcap.as_deref());
            let wall = r.wall.as_secs_f64();
            let sim_s = r.sim.as_ns() as f64 / 1e9;
            println!(
                "{:>6} {:>5} {:>5} {:>5} {:>6.1} {:>7.1} {:>8.1} {:>9.0} {:>6.2} {:>7.2} {:>7.2} {:>14} {:>7} {:>7.1}",
                r.drives,
                r.hz,
                if r.dc { "DC" } else { "free" },
                r.pdi_bytes,
                r.frames as f64 / r.cycles as f64,
                r.bus_sum.as_ns() as f64 / r.cycles as f64 / 1e3,
                r.sim.as_ns() as f64 / r.cycles as f64 / 1e3,
                r.frames as f64 / wall,
                sim_s / wall,
                sim_s / r.cpu.as_secs_f64(),
                sim_s / r.in_sim.as_secs_f64(),
                format!("{} {}/{}", r.wkc, r.wkc_ok, r.cycles),
                format!("{}/{}", r.op, r.drives),
                r.setup.as_secs_f64(),
            );
        }
    }
}
