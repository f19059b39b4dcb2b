//! Interpolation error and compute time of the fine interpolator (and the
//! profile generator's step and planning time), printed as a table.
//!
//! `cargo run -p motion --release --example interp_bench`
//!
//! Error: each control-cycle output against the exact continuous trajectory
//! at the same instant (shifted by the interpolator's fixed delay of one
//! master cycle minus one control cycle), in increments: `max|e|` and `rms e`
//! against the continuous value, `max|e−round|` against the continuous value
//! rounded to whole increments (the best an integer set-point can do). The
//! master's set-points are the trajectory rounded to whole increments.
//! Times are host wall-clock figures, no assertions.

// A host benchmark program: a failed setup may stop it.
#![allow(clippy::expect_used)]

use std::f64::consts::PI;
use std::hint::black_box;
use std::time::Instant;

use motion::{
    CycleRatio, FeedforwardSource, FineInterpolator, InterpolationOrder, InterpolatorConfig, MasterSetpoint,
    PositionTarget, ProfileGenerator, ProfileLimits, SetMode,
};

const REV: f64 = 1_048_576.0; // increments per revolution

struct Trajectory {
    name: &'static str,
    x: fn(f64) -> f64, // increments at time t (s)
}

fn constant(t: f64) -> f64 {
    // 1 234 567 increments per 1 ms master cycle (≈ 70.6 rev/s), starting
    // just below i32::MAX so the run wraps around.
    2_147_000_000.0 + 1_234_567_000.0 * t
}

fn sine(t: f64) -> f64 {
    // 1 rev amplitude, 1 Hz.
    REV * (2.0 * PI * t).sin()
}

fn wrap(x: f64) -> i32 {
    (x.round() as i64) as i32
}

struct Stats {
    max: f64,
    rms: f64,
    max_rounded: f64,
}

/// An interpolator of `order` at `ratio`, internal feedforward at 100 %.
fn interpolator(order: InterpolationOrder, ratio: CycleRatio) -> FineInterpolator {
    let cfg = InterpolatorConfig {
        ratio,
        order,
        feedforward: FeedforwardSource::Internal,
        velocity_feedforward_percent: 100.0,
        max_extrapolation: nanos::Nanos::from_ms(10),
    };
    FineInterpolator::new(cfg).expect("config")
}

fn measure(order: InterpolationOrder, ratio: CycleRatio, traj: &Trajectory) -> Stats {
    let mut ip = interpolator(order, ratio);
    let n = ratio.n() as usize;
    let tm = f64::from(ratio.master_ns()) * 1e-9;
    let tc = f64::from(ratio.control_ns()) * 1e-9;
    ip.start(wrap((traj.x)(0.0)));
    let masters = 2000; // 2 s
    let (mut max, mut sum_sq, mut max_rounded, mut count) = (0.0f64, 0.0f64, 0.0f64, 0usize);
    for c in 0..masters * n {
        let sp = (c % n == 0).then(|| MasterSetpoint {
            position: wrap((traj.x)((c / n) as f64 * tm)),
            velocity_offset: 0.0,
        });
        let out = ip.cycle(sp).expect("no fault");
        if c < 4 * n {
            continue; // history still at standstill
        }
        let exact = (traj.x)((c as f64 + 1.0) * tc - tm);
        // Wrap-around: compare modulo 2^32.
        let e = f64::from(out.position.wrapping_sub(wrap(exact.floor()))) - (exact - exact.floor());
        let er = f64::from(out.position.wrapping_sub(wrap(exact)));
        max = max.max(e.abs());
        max_rounded = max_rounded.max(er.abs());
        sum_sq += e * e;
        count += 1;
    }
    Stats {
        max,
        rms: (sum_sq / count as f64).sqrt(),
        max_rounded,
    }
}

fn ns_per_cycle(order: InterpolationOrder, ratio: CycleRatio) -> f64 {
    let mut ip = interpolator(order, ratio);
    ip.start(0);
    let n = ratio.n() as usize;
    let calls = 5_000_000usize;
    let mut acc = 0i64;
    let t0 = Instant::now();
    for c in 0..calls {
        let sp = (c % n == 0).then(|| MasterSetpoint {
            position: black_box(sine(c as f64 * 1e-5) as i32),
            velocity_offset: 0.0,
        });
        let out = ip.cycle(black_box(sp)).expect("no fault");
        acc = acc.wrapping_add(i64::from(out.position));
    }
    let dt = t0.elapsed();
    black_box(acc);
    dt.as_nanos() as f64 / calls as f64
}

fn main() {
    let orders = [
        ("linear", InterpolationOrder::Linear),
        ("quadratic", InterpolationOrder::Quadratic),
        ("cubic", InterpolationOrder::Cubic),
    ];
    let trajectories = [
        Trajectory {
            name: "const 1234567 inc/ms",
            x: constant,
        },
        Trajectory {
            name: "sine 1 rev, 1 Hz",
            x: sine,
        },
    ];
    for (master_ns, control_ns) in [(1_000_000, 125_000), (1_000_000, 250_000), (4_000_000, 250_000)] {
        let ratio = CycleRatio::new(master_ns, control_ns).expect("ratio");
        println!(
            "\nFine interpolator: master {} µs, control {} µs (N = {}), delay {} µs, 2 s per run",
            master_ns / 1000,
            control_ns / 1000,
            ratio.n(),
            (master_ns - control_ns) / 1000
        );
        println!(
            "| {:<22} | {:<9} | {:>12} | {:>12} | {:>17} | {:>10} |",
            "trajectory", "order", "max|e| inc", "rms e inc", "max|e-round| inc", "ns/cycle"
        );
        println!(
            "|{:-<24}|{:-<11}|{:->14}|{:->14}|{:->19}|{:->12}|",
            "", "", "", "", "", ""
        );
        for traj in &trajectories {
            for (name, order) in orders {
                let s = measure(order, ratio, traj);
                let ns = ns_per_cycle(order, ratio);
                println!(
                    "| {:<22} | {:<9} | {:>12.4} | {:>12.4} | {:>17.0} | {:>10.1} |",
                    traj.name, name, s.max, s.rms, s.max_rounded, ns
                );
            }
        }
    }

    // Profile generator: step time and planning time.
    let limits = ProfileLimits {
        velocity: 52_428_800.0,
        acceleration: 1.0e9,
        deceleration: 5.0e8,
        jerk: 1.0e11,
    };
    let mut g = ProfileGenerator::new(0);
    let plans = 200_000u32;
    let t0 = Instant::now();
    for i in 0..plans {
        let target = black_box((i as i32).wrapping_mul(7919) << 8);
        g.move_to(PositionTarget::Absolute(target), limits, SetMode::Immediate)
            .expect("limits");
        g.step(250_000);
    }
    let plan_ns = t0.elapsed().as_nanos() as f64 / f64::from(plans);
    g.reset(0);
    g.move_to(PositionTarget::Absolute(1 << 30), limits, SetMode::Immediate)
        .expect("limits");
    let steps = 80_000u32;
    let t0 = Instant::now();
    let mut acc = 0i64;
    for _ in 0..steps {
        acc = acc.wrapping_add(i64::from(g.step(black_box(250_000)).position));
    }
    black_box(acc);
    let step_ns = t0.elapsed().as_nanos() as f64 / f64::from(steps);
    println!("\nProfile generator (pp, 250 µs steps)");
    println!("| {:<30} | {:>10} |", "operation", "ns/call");
    println!("|{:-<32}|{:->12}|", "", "");
    println!("| {:<30} | {:>10.1} |", "step (evaluate set-point)", step_ns);
    println!("| {:<30} | {:>10.1} |", "move_to (plan) + one step", plan_ns);
}
