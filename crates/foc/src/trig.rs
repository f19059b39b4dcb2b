//! sin/cos of the electrical angle: a 512-entry table over one turn with linear
//! interpolation.
//!
//! Why a table and not a crate: the angle arrives as an integer (encoder increments
//! times pole pairs, scaled to a `u32` turn), so the table index is the angle's top
//! 9 bits and the interpolation fraction its low 23 bits: no range reduction, no
//! division, no branch, one table for sin and cos (cos = sin a quarter turn on).
//! That is about 10 instructions per pair on the M4F against ~40 for `libm::sinf`
//! plus `cosf` each. The worst-case error of linear interpolation is
//! (2π/512)²/8 ≈ 1.9·10⁻⁵ (measured by `sin_cos_table_accuracy`), far below the
//! 12-bit ADC's 2.4·10⁻⁴ resolution. The table (rows of sin, cos and their
//! differences to the next row: 8 KiB of flash) is built at compile time by a Taylor
//! series in `const fn`.

use core::f64::consts::{PI, TAU};

/// Table entries per electrical turn (a power of two).
const N: usize = 512;
/// Bits of the angle that index the table.
const INDEX_BITS: u32 = 9;
/// Bits of the angle that interpolate.
const FRAC_BITS: u32 = 32 - INDEX_BITS;

/// sin(x) for x in [−π, π] by its Taylor series (compile time only).
const fn taylor_sin(x: f64) -> f64 {
    let mut term = x;
    let mut sum = x;
    let mut k = 1u32;
    while k < 30 {
        let n = (2 * k) as f64;
        term = -term * x * x / (n * (n + 1.0));
        sum += term;
        k += 1;
    }
    sum
}

/// One turn of sin, N + 1 entries (the last repeats the first, so entry i + 1
/// exists for every index i < N). Compile time only: [`SIN_COS`] is built from it.
#[allow(clippy::indexing_slicing)] // compile time: an index out of range fails the build
const SIN: [f32; N + 1] = {
    let mut t = [0.0f32; N + 1];
    let mut i = 0;
    while i <= N {
        let mut x = i as f64 / N as f64 * TAU;
        if x > PI {
            x -= TAU;
        }
        t[i] = taylor_sin(x) as f32;
        i += 1;
    }
    t
};

/// Per table step i: sin and cos at its start and their f32 differences to the
/// next step, `[sin, cos, Δsin, Δcos]` (cos = sin a quarter turn on). One row
/// holds all the interpolation needs: one index, four adjacent loads, two
/// multiply-adds per (sin, cos) pair, the differences not subtracted per step
/// (the same f32 subtraction, done at compile time: the same results). 8 KiB of
/// flash.
#[allow(clippy::indexing_slicing)] // compile time: an index out of range fails the build
static SIN_COS: [[f32; 4]; N] = {
    let mut t = [[0.0f32; 4]; N];
    let mut i = 0;
    while i < N {
        let ic = (i + N / 4) & (N - 1);
        t[i] = [SIN[i], SIN[ic], SIN[i + 1] - SIN[i], SIN[ic + 1] - SIN[ic]];
        i += 1;
    }
    t
};

/// An electrical angle as a fraction of a turn: 2³² = one electrical revolution.
/// Wraps by construction.
pub type Angle = u32;

/// Radians per [`Angle`] unit.
pub const RAD_PER_ANGLE: f32 = core::f32::consts::TAU / 4_294_967_296.0;
/// [`Angle`] units per radian.
pub const ANGLE_PER_RAD: f32 = 4_294_967_296.0 / core::f32::consts::TAU;

/// (sin, cos) of an electrical angle, interpolated from the table
/// (error ≤ 2·10⁻⁵).
#[inline]
pub fn sin_cos(angle: Angle) -> (f32, f32) {
    let i = (angle >> FRAC_BITS) as usize;
    let f = (angle & ((1 << FRAC_BITS) - 1)) as f32 * (1.0 / (1u32 << FRAC_BITS) as f32);
    // i < N by construction: the check folds away
    let [s, c, ds, dc] = SIN_COS.get(i).copied().unwrap_or([0.0; 4]);
    (s + ds * f, c + dc * f)
}

/// The angle of `rad` radians (any value; wraps).
#[inline]
pub fn angle_from_rad(rad: f32) -> Angle {
    // wraps through i64 so negative and multi-turn angles land on the same turn
    ((rad * ANGLE_PER_RAD) as i64) as u32
}
