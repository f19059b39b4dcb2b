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
