//! The PLL's integer arithmetic: phase wrapping, 64-bit division by
//! 32-bit hardware divisions, the reduced tick fractions.

pub(super) const Q: u32 = 16;

pub(super) const NS_PER_S: i128 = 1_000_000_000;

/// `d` wrapped into [−p/2, p/2) (p ≥ 1). In 64 bits (a Cortex-M divides
/// them in a library call of ~100 instructions, 128 bits take several
/// hundred); 128 only where `d + p/2` would overflow.
pub(crate) fn wrap_signed(d: i64, p: i64) -> i64 {
    let p = p.max(1);
    if d >= -(p / 2) && d < p - p / 2 {
        return d; // already inside: no division (the usual phase error)
    }
    match d.checked_add(p / 2) {
        Some(x) => x.rem_euclid(p) - p / 2,
        None => {
            let p = i128::from(p);
            let w = (i128::from(d) + p / 2).rem_euclid(p) - p / 2;
            i64::try_from(w).unwrap_or(0)
        }
    }
}

/// `x / d` and `x % d` (`None` for `d = 0`). A divisor below 2^16 (the
/// reduced ns denominators, 125 for 144 MHz) takes four 32-bit hardware
/// divisions in base 2^16 instead of the ~100-instruction 64-bit library
/// call a Cortex-M needs; larger ones take that call.
#[inline]
pub fn div_rem_u64(x: u64, d: u64) -> Option<(u64, u64)> {
    let Ok(d16) = u16::try_from(d) else {
        return Some((x.checked_div(d)?, x.checked_rem(d)?));
    };
    let d = u32::from(d16);
    let hi = (x >> 32) as u32;
    let (q_hi, r) = (hi.checked_div(d)?, hi.checked_rem(d)?);
    // each step divides a value below d · 2^16 < 2^32
    let x1 = (r << 16) | (x as u32 >> 16);
    let (q1, r1) = (x1 / d, x1 % d);
    let x0 = (r1 << 16) | (x as u32 & 0xFFFF);
    let (q0, r0) = (x0 / d, x0 % d);
    Some((
        u64::from(q_hi) << 32 | u64::from(q1) << 16 | u64::from(q0),
        u64::from(r0),
    ))
}

/// Greatest common divisor (Euclid), `gcd(0, b) = b`: reduces timer ticks
/// per ns to a small fraction (here and in the firmware's cycle timer).
pub const fn gcd(mut a: u64, mut b: u64) -> u64 {
    while b != 0 {
        let r = a % b;
        a = b;
        b = r;
    }
    a
}

/// `a · b / c` truncated toward zero, in 64 bits when `a · b` fits, else
/// 128 (`c` ≠ 0; a quotient beyond 64 bits saturates).
pub(super) fn mul_div(a: i64, b: i64, c: i64) -> i64 {
    if a == 0 {
        return 0;
    }
    // a Cortex-M divides 32 bits in hardware, 64 in a library call
    if let (Ok(a), Ok(b), Ok(c)) = (u32::try_from(a), u32::try_from(b), u32::try_from(c)) {
        if let Some(x) = a.checked_mul(b) {
            return i64::from(x.checked_div(c).unwrap_or(0));
        }
    }
    match a.checked_mul(b) {
        Some(x) => x.checked_div(c).unwrap_or(0),
        None => {
            let q = (i128::from(a) * i128::from(b))
                .checked_div(i128::from(c))
                .unwrap_or(0);
            i64::try_from(q).unwrap_or(if q < 0 { i64::MIN } else { i64::MAX })
        }
    }
}
