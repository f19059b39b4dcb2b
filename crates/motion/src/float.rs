//! `f32` helpers for the control cycle's instruction count.
//!
//! 64-bit integers to `f32` without the library call where they fit in 32
//! bits: a Cortex-M4 converts 32-bit integers in one instruction, 64-bit ones
//! in a call of ~40 instructions. The result is the same value (one rounding
//! of the same integer).
//!
//! The wide conversion is a cold out-of-line function on purpose: written
//! inline, the compiler runs the library call on every path and selects the
//! result afterwards.

/// `x as f32`, through 32 bits when `x` fits.
#[inline]
pub fn from_i64(x: i64) -> f32 {
    match i32::try_from(x) {
        Ok(v) => v as f32,
        Err(_) => wide_i64(x),
    }
}

/// `x as f32`, through 32 bits when `x` fits.
#[inline]
pub fn from_u64(x: u64) -> f32 {
    match u32::try_from(x) {
        Ok(v) => v as f32,
        Err(_) => wide_u64(x),
    }
}

/// `x.max(lo).min(hi)` for `lo ≤ hi` (NaN gives `lo`, as there), in two
/// compares: a Cortex-M4 has no `f32` min/max instruction, `f32::min` and
/// `f32::max` are library calls.
#[inline]
pub fn clamp(x: f32, lo: f32, hi: f32) -> f32 {
    let y = if x >= lo { x } else { lo };
    if y <= hi {
        y
    } else {
        hi
    }
}

#[cold]
#[inline(never)]
fn wide_i64(x: i64) -> f32 {
    x as f32
}

#[cold]
#[inline(never)]
fn wide_u64(x: u64) -> f32 {
    x as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The compare clamp equals `max(lo).min(hi)`, NaN and infinities
    /// included (the cascade of C-035: its torque and velocity limits).
    #[test]
    fn c035_clamp_equals_max_min() {
        let xs = [
            0.0f32,
            -0.0,
            1.5,
            -1.5,
            3.0,
            -3.0,
            2.0,
            -2.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        for &(lo, hi) in &[
            (-2.0f32, 2.0f32),
            (0.0, 0.0),
            (-1e9, 5e-3),
            (f32::NEG_INFINITY, f32::INFINITY),
        ] {
            for &x in &xs {
                assert_eq!(
                    clamp(x, lo, hi).to_bits(),
                    x.max(lo).min(hi).to_bits(),
                    "{x} in {lo}..{hi}"
                );
            }
        }
    }

    /// The 32-bit path rounds like the direct 64-bit conversion, at and
    /// beyond the edges of the 32-bit types (the interpolator's |∇³| reaches
    /// 2³³; C-115).
    #[test]
    fn c115_conversion_rounds_like_the_direct_one() {
        let edges = [
            0i64,
            1,
            -1,
            16_777_217,
            -16_777_217,
            i64::from(i32::MAX),
            i64::from(i32::MIN),
        ];
        for &e in &edges {
            for x in [
                e,
                e + 1,
                e - 1,
                e * 2 + 1,
                -(e * 3) - 1,
                (1 << 33) - 1,
                -(1 << 33) + 3,
                i64::MAX,
                i64::MIN,
            ] {
                assert_eq!(from_i64(x).to_bits(), (x as f32).to_bits(), "{x}");
                let u = x.unsigned_abs();
                assert_eq!(from_u64(u).to_bits(), (u as f32).to_bits(), "{u}");
            }
        }
        let u = u64::from(u32::MAX);
        for x in [u, u + 1, u - 1, u64::MAX] {
            assert_eq!(from_u64(x).to_bits(), (x as f32).to_bits(), "{x}");
        }
    }
}
