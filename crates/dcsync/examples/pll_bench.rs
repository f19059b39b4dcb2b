//! Lock time and steady-state phase error of the DC-Sync PLL, printed as a
//! table.
//!
//! `cargo run -p dcsync --release --example pll_bench`
//!
//! Model ([`dcsync::sim`]): SYNC0 exact on the DC grid (hardware-generated);
//! local oscillator drifting by the row's ppm; cycle timer at 144 MHz
//! (6.94 ns ticks); SYNC0 interrupt latency 300 ns ± 100 ns (uniform; the
//! PLL compensates the 300 ns); master frames 4 µs before SYNC0 with the
//! row's frame jitter (±5 µs makes some of them late: they only count in
//! A261[2], SYNC0 does not move); A292 = −100 µs (start 100 µs after
//! SYNC0); default tuning; 3 s of DC time per row, seed 1.
//!
//! Lock time: first SYNC0 → phase-locked flag (A298 bit 10). Phase error:
//! true DC start time of every aligned cycle minus (SYNC0 − A292), from the
//! lock on: mean (signed), p99 and max of |error|, ns. Goal per row: lock
//! ≤ 100 ms and max |error| ≤ 1 µs.

use dcsync::sim::{Scenario, SimEvent, Simulator};
use dcsync::{Config, PllStatus};
use nanos::Nanos;

struct Row {
    sync0_ns: u32,
    a150_ns: u32,
    drift_ppm: i64,
    frame_jitter_ns: u32,
}

struct Result {
    lock_ms: Option<f64>,
    mean: f64,
    p99: i64,
    max: i64,
    unlocks: u32,
    late: u32,
    frames: u32,
}

const RUN: Nanos = Nanos::from_secs(3);

fn run(row: &Row) -> Result {
    let sc = Scenario {
        drift_ppb: row.drift_ppm * 1000,
        frame_lead_ns: 4_000,
        frame_jitter_ns: row.frame_jitter_ns,
        ..Scenario::default()
    };
    let mut cfg = Config::new(row.sync0_ns, row.a150_ns, 144_000_000);
    cfg.a292_ns = -100_000;
    let mut sim = match Simulator::new(sc, cfg) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("bad row: {e:?}");
            std::process::exit(1);
        }
    };
    let first = sim.sync0_dc(0);
    let mut lock_at = None;
    let mut errors = Vec::new();
    let mut was_locked = false;
    let mut unlocks = 0;
    let mut frames = 0;
    sim.run_until(RUN, |pll, ev| match ev {
        SimEvent::Cycle {
            dc,
            error_ns: Some(e),
            ..
        } => {
            let locked = pll.status().contains(PllStatus::PHASE_LOCKED);
            if locked && lock_at.is_none() {
                lock_at = Some(*dc);
            }
            if was_locked && !locked {
                unlocks += 1;
            }
            was_locked = locked;
            if lock_at.is_some() {
                errors.push(*e);
            }
        }
        SimEvent::Frame { .. } => frames += 1,
        _ => {}
    });
    let n = errors.len().max(1) as f64;
    let mean = errors.iter().sum::<i64>() as f64 / n;
    let mut abs: Vec<i64> = errors.iter().map(|e| e.abs()).collect();
    abs.sort_unstable();
    let p99 = abs
        .get((abs.len() * 99 / 100).min(abs.len().saturating_sub(1)))
        .copied()
        .unwrap_or(0);
    let max = abs.last().copied().unwrap_or(0);
    Result {
        lock_ms: lock_at.map(|t: Nanos| t.since(first).as_ns() as f64 / 1e6),
        mean,
        p99,
        max,
        unlocks,
        late: sim.pll().diagnostics().late_frames,
        frames,
    }
}

fn main() {
    let mut rows = Vec::new();
    for drift in [0, 50, -50, 100, -100] {
        for jitter in [0, 5_000] {
            rows.push(Row {
                sync0_ns: 1_000_000,
                a150_ns: 1_000_000,
                drift_ppm: drift,
                frame_jitter_ns: jitter,
            });
        }
    }
    for jitter in [0, 5_000] {
        rows.push(Row {
            sync0_ns: 2_000_000,
            a150_ns: 500_000,
            drift_ppm: 100,
            frame_jitter_ns: jitter,
        });
    }
    println!("DC-Sync PLL: 3 s per row, timer 144 MHz, SYNC0 latency 300 ns ± 100 ns, A292 = -100 us, frames 4 us before SYNC0");
    println!(
        "{:>9} {:>7} {:>7} {:>8} | {:>9} | {:>8} {:>6} {:>6} | {:>7} {:>10} | goal",
        "SYNC0", "A150", "drift", "frame", "lock", "mean", "p99", "max", "unlocks", "late/frames"
    );
    println!(
        "{:>9} {:>7} {:>7} {:>8} | {:>9} | {:>8} {:>6} {:>6} | {:>7} {:>10} |",
        "us", "us", "ppm", "jit us", "ms", "ns", "|ns|", "|ns|", "", ""
    );
    let mut all = true;
    for row in &rows {
        let r = run(row);
        let ok = r.lock_ms.is_some_and(|t| t <= 100.0) && r.max <= 1_000;
        all &= ok;
        println!(
            "{:>9} {:>7} {:>+7} {:>8} | {:>9} | {:>8.1} {:>6} {:>6} | {:>7} {:>5}/{:<5} | {}",
            row.sync0_ns / 1000,
            row.a150_ns / 1000,
            row.drift_ppm,
            if row.frame_jitter_ns == 0 {
                "0".to_string()
            } else {
                format!("±{}", row.frame_jitter_ns / 1000)
            },
            r.lock_ms.map_or("never".to_string(), |t| format!("{t:.1}")),
            r.mean,
            r.p99,
            r.max,
            r.unlocks,
            r.late,
            r.frames,
            if ok { "met" } else { "MISSED" }
        );
    }
    println!(
        "goal (lock <= 100 ms, |error| <= 1 us): {}",
        if all {
            "met on every row"
        } else {
            "missed on some row"
        }
    );
}
