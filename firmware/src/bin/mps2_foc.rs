//! Instructions per current-loop step on a Cortex-M4F: `foc::FocAxis::step` for
//! two axes, as the fast task will run them, on QEMU's mps2-an386 under
//! `-icount shift=0` (one instruction per virtual ns; SysTick calibrated against
//! a loop of known length, as `boot-mps2` does). `scripts/cross foc` builds and
//! runs it. The samples are a precomputed rotating current set (64 of them, a
//! turning encoder at 3750 rpm), the current the reference asks for (iq = 1.5 A,
//! a positive-sequence set), so the step takes its ordinary path: no trip, the
//! voltage circle not reached. A second run asks for iq = 6 A of the same samples:
//! the integrators wind up to the circle and the step takes its voltage-limited
//! path (the square root and the anti-windup's cases), printed on its own line.
//! The reference goes through `black_box` (the firmware's comes from the control
//! cycle, no constant to fold). The loop's own overhead (sample fetch, black-boxed
//! output) is measured with an empty step and subtracted. Prints the figures and
//! exits.
#![no_std]
#![no_main]

use core::hint::black_box;
use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use firmware::semihost::exit as stop;
use firmware::systick::{start, ticks};
use foc::{Dq, FocAxis, LoopParams, MotorData, Protection, PwmOut, Sample, Scaling};

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    hprintln!("foc: panic");
    stop(false)
}

/// Steps per measurement (each: both axes).
const STEPS: u32 = 4096;

/// A rotating current of iq = 1.5 A (id = 0) at the encoder's angle, sampled as
/// the default board would: phase a = −iq·sin θ, b = −iq·sin(θ − 120°),
/// c = −a − b.
fn samples() -> [Sample; 64] {
    let sc = Scaling::default_board();
    core::array::from_fn(|k| {
        // 1/64 of an electrical turn per step; 4 pole pairs: 2^20/(4·64) increments
        let pos = (k as u32) * 4096;
        let th = k as f32 * (core::f32::consts::TAU / 64.0);
        let (s, c) = foc::trig::sin_cos(foc::trig::angle_from_rad(th));
        let ia = -1.5 * s;
        let ib = -1.5 * (-0.5 * s - 0.866_025_4 * c);
        let cnt = |i: f32| (2048.0 + i / sc.amps_per_count) as u16;
        Sample {
            phase_counts: [cnt(ia), cnt(ib), cnt(-ia - ib)],
            dc_link_count: 2260,
            position_inc: pos,
            encoder_ok: true,
        }
    })
}

#[entry]
fn main() -> ! {
    let Some(cp) = cortex_m::Peripherals::take() else {
        stop(false)
    };
    let mut syst = cp.SYST;
    let per_1000 = start(&mut syst);

    let mk = || {
        FocAxis::new(
            MotorData::default_servo(),
            LoopParams::default_16k(),
            Scaling::default_board(),
            Protection::default_stage(),
        )
        .ok()
    };
    let (Some(mut a), Some(mut b)) = (mk(), mk()) else {
        hprintln!("foc: parameters refused");
        stop(false)
    };
    a.enable(true);
    b.enable(true);
    let s = samples();
    let empty = empty_loop(&s);
    // the ordinary path: the measured current is the reference
    let (ordinary, ok) = run(&mut a, &mut b, &s, Dq { d: 0.0, q: 1.5 }, empty, per_1000);
    let ok = ok && !a.measured().voltage_limited && a.measured().current.q.abs() > 1.0;
    hprintln!(
        "foc: figure: current-loop step, two axes: {} instructions ({} per axis; goal 350 per axis) over {} steps{}",
        ordinary,
        ordinary / 2,
        STEPS,
        if ok { "" } else { " (FAILED: tripped, wrong current or voltage-limited)" }
    );
    // the voltage-limited path: 6 A asked, 1.5 A measured
    let (limited, ok2) = run(&mut a, &mut b, &s, Dq { d: 0.0, q: 6.0 }, empty, per_1000);
    let ok2 = ok2 && a.measured().voltage_limited;
    hprintln!(
        "foc: figure: current-loop step on the voltage circle, two axes: {} instructions ({} per axis) over {} steps{}",
        limited,
        limited / 2,
        STEPS,
        if ok2 { "" } else { " (FAILED: tripped or not voltage-limited)" }
    );
    stop(ok && ok2)
}

/// SysTick ticks of the loop without the step: fetch, black box.
fn empty_loop(s: &[Sample; 64]) -> u32 {
    let t0 = cortex_m::peripheral::SYST::get_current();
    for k in 0..STEPS {
        let x = black_box(&s[(k & 63) as usize]);
        let r = black_box(Dq { d: 0.0, q: 1.5 });
        black_box(PwmOut {
            compare: [x.phase_counts[0]; 3],
            gate_enable: r.q > 0.0,
        });
        black_box(PwmOut {
            compare: [x.phase_counts[1]; 3],
            gate_enable: true,
        });
    }
    ticks(t0, cortex_m::peripheral::SYST::get_current())
}

/// Instructions per step of both axes with this reference (the empty loop
/// subtracted), and whether neither axis tripped.
fn run(
    a: &mut FocAxis,
    b: &mut FocAxis,
    s: &[Sample; 64],
    reference: Dq,
    empty: u32,
    per_1000: u32,
) -> (u64, bool) {
    let t0 = cortex_m::peripheral::SYST::get_current();
    for k in 0..STEPS {
        let x = black_box(&s[(k & 63) as usize]);
        let r = black_box(reference);
        black_box(a.step(x, r));
        black_box(b.step(x, r));
    }
    let full = ticks(t0, cortex_m::peripheral::SYST::get_current());
    let per_step = u64::from(full.saturating_sub(empty)) * u64::from(per_1000) / 1000 / u64::from(STEPS);
    (per_step, a.trip().is_none() && b.trip().is_none())
}
