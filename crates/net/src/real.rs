//! REAL32 as text for the UDP parameter service, without core's float
//! formatting and parsing (about 22 KB of tables and code on the board:
//! `dec2flt`'s 10 KB power-of-five table, Grisu/Dragon).
//!
//! - [`write_f32`] prints the shortest decimal (1 to 9 significant digits)
//!   that [`parse_f32`] reads back to the same bits, in the form core's
//!   `{}` uses: no exponent, `-` for negative values (also `-0`), `inf`,
//!   `-inf`, `NaN`.
//! - [`parse_f32`] reads `[+-]digits[.digits][(e|E)[+-]digits]`, `inf`,
//!   `infinity` and `nan` (any case), as `str::parse::<f32>` does. The
//!   value is the first 19 significant digits times a power of ten in
//!   `f64`, rounded to `f32`: exact for every text [`write_f32`] prints
//!   (at most 9 digits, powers of ten up to 10^22 are exact in `f64`);
//!   a longer text can round differently from core's correctly rounded
//!   parser in its last bit (the value still fits REAL32's precision).

use core::fmt::{self, Write};

/// Largest power of ten that is exact in `f64`.
const EXACT_POW10: i32 = 22;

/// 10^k in `f64` (exact for |k| ≤ 22).
fn pow10(k: i32) -> f64 {
    let mut p = 1.0f64;
    let mut n = k.unsigned_abs().min(400);
    let mut base = 10.0f64;
    while n > 0 {
        if n & 1 == 1 {
            p *= base;
        }
        base *= base;
        n >>= 1;
    }
    if k < 0 {
        1.0 / p
    } else {
        p
    }
}

/// `m` × 10^`e` rounded to `f32` (through `f64`).
fn scale(m: u64, e: i32) -> f32 {
    let m = m as f64;
    let v = if (-EXACT_POW10..0).contains(&e) {
        // one rounding: division by an exact power of ten
        m / pow10(-e)
    } else if e < 0 {
        // below 10^-22: two steps, the first exact
        m / pow10(EXACT_POW10) / pow10(-e - EXACT_POW10)
    } else {
        m * pow10(e)
    };
    v as f32
}

/// Parses a REAL32 value (see the module docs); `None` for anything else.
pub fn parse_f32(s: &str) -> Option<f32> {
    let (neg, body) = match s.as_bytes().first() {
        Some(b'-') => (true, s.get(1..)?),
        Some(b'+') => (false, s.get(1..)?),
        _ => (false, s),
    };
    let sign = |v: f32| if neg { -v } else { v };
    if body.eq_ignore_ascii_case("inf") || body.eq_ignore_ascii_case("infinity") {
        return Some(sign(f32::INFINITY));
    }
    if body.eq_ignore_ascii_case("nan") {
        return Some(sign(f32::NAN));
    }
    let b = body.as_bytes();
    let mut i = 0;
    let mut mantissa: u64 = 0;
    let mut digits = 0u32; // significant digits taken into the mantissa
    let mut exp: i32 = 0; // decimal exponent of the mantissa's last digit
    let mut any = false;
    fn take(d: u8, frac: bool, m: &mut u64, digits: &mut u32, exp: &mut i32) {
        if *m == 0 && d == 0 {
            // leading zeros: only the position counts
            if frac {
                *exp -= 1;
            }
        } else if *digits < 19 {
            *m = *m * 10 + u64::from(d);
            *digits += 1;
            if frac {
                *exp -= 1;
            }
        } else if !frac {
            // beyond 19 digits: dropped, the position kept
            *exp += 1;
        }
    }
    // the digits from `i` on, integer part or fraction (`frac`)
    let mut run = |i: &mut usize, frac: bool| {
        while let Some(&c) = b.get(*i) {
            if !c.is_ascii_digit() {
                break;
            }
            take(c - b'0', frac, &mut mantissa, &mut digits, &mut exp);
            any = true;
            *i += 1;
        }
    };
    run(&mut i, false);
    if b.get(i) == Some(&b'.') {
        i += 1;
        run(&mut i, true);
    }
    if !any {
        return None;
    }
    if matches!(b.get(i), Some(b'e' | b'E')) {
        i += 1;
        let eneg = match b.get(i) {
            Some(b'-') => {
                i += 1;
                true
            }
            Some(b'+') => {
                i += 1;
                false
            }
            _ => false,
        };
        let mut e: i32 = 0;
        let start = i;
        while let Some(&c) = b.get(i) {
            if !c.is_ascii_digit() {
                break;
            }
            e = e.saturating_mul(10).saturating_add(i32::from(c - b'0'));
            i += 1;
        }
        if i == start {
            return None;
        }
        exp = exp.saturating_add(if eneg { -e } else { e });
    }
    if i != b.len() {
        return None;
    }
    let v = if mantissa == 0 {
        0.0
    } else if exp > 60 {
        f32::INFINITY
    } else if exp < -80 {
        0.0
    } else {
        scale(mantissa, exp)
    };
    Some(sign(v))
}

/// The decimal exponent of `a` (> 0, finite): 10^e ≤ a < 10^(e+1).
fn exponent10(a: f64) -> i32 {
    // log10(2) ≈ 0.30103: a first guess from the binary exponent
    let e2 = ((a.to_bits() >> 52) & 0x7FF) as i32 - 1023;
    let mut e = (e2 * 30103).div_euclid(100_000);
    while e > -60 && pow10(e) > a {
        e -= 1;
    }
    while e < 60 && pow10(e + 1) <= a {
        e += 1;
    }
    e
}

/// Writes `v` as the shortest decimal that [`parse_f32`] reads back to it.
pub fn write_f32(o: &mut impl Write, v: f32) -> fmt::Result {
    if v.is_nan() {
        return o.write_str("NaN");
    }
    if v.is_sign_negative() {
        o.write_char('-')?;
    }
    let a = v.abs();
    if a.is_infinite() {
        return o.write_str("inf");
    }
    if a == 0.0 {
        return o.write_char('0');
    }
    let af = f64::from(a);
    let e10 = exponent10(af);
    // the shortest p of 1..=9 significant digits that reads back (9 always does)
    let mut best = (0u64, 0i32);
    for p in 1..=9 {
        let x = e10 - p + 1;
        let scaled = if x < 0 { af * pow10(-x) } else { af / pow10(x) };
        let d = (scaled + 0.5) as u64;
        best = (d, x);
        if scale(d, x) == a {
            break;
        }
    }
    write_digits(o, best.0, best.1)
}

/// Writes `d` × 10^`x` without an exponent.
fn write_digits(o: &mut impl Write, mut d: u64, mut x: i32) -> fmt::Result {
    while d != 0 && d % 10 == 0 {
        d /= 10;
        x += 1;
    }
    let mut buf = [0u8; 20];
    let mut n = 0;
    let mut t = d;
    loop {
        if let Some(slot) = buf.get_mut(n) {
            *slot = b'0' + (t % 10) as u8;
        }
        n += 1;
        t /= 10;
        if t == 0 || n == buf.len() {
            break;
        }
    }
    let digits = buf.get(..n).unwrap_or_default();
    // digits are least significant first
    let len = n as i32;
    let point = len + x; // digits before the decimal point
    let mut put = |c: u8| o.write_char(char::from(c));
    if x >= 0 {
        for &c in digits.iter().rev() {
            put(c)?;
        }
        for _ in 0..x {
            put(b'0')?;
        }
    } else if point > 0 {
        for (k, &c) in digits.iter().rev().enumerate() {
            if k as i32 == point {
                put(b'.')?;
            }
            put(c)?;
        }
    } else {
        put(b'0')?;
        put(b'.')?;
        for _ in 0..-point {
            put(b'0')?;
        }
        for &c in digits.iter().rev() {
            put(c)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::string::String;

    fn text(v: f32) -> String {
        let mut s = String::new();
        write_f32(&mut s, v).unwrap();
        s
    }

    /// A fixed pseudo-random sequence of f32 bit patterns (xorshift).
    fn patterns(n: usize) -> impl Iterator<Item = f32> {
        let mut x: u32 = 0x9E37_79B9;
        (0..n).map(move |_| {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            f32::from_bits(x)
        })
    }

    /// E-101 (UDP parameter service, REAL32 values): the text the service
    /// prints reads back to the same value through core's parser, an
    /// independent one, and through ours, for normal, subnormal and
    /// extreme values.
    #[test]
    fn e101_real32_text_round_trips_through_core_and_ours() {
        let special = [
            0.1f32,
            1.5,
            100.0,
            1e-7,
            3.4028235e38,
            1.1754944e-38,
            1e-45,
            -2.5,
            16_777_216.0,
            0.3,
        ];
        for v in special.into_iter().chain(patterns(200_000)) {
            if !v.is_finite() {
                continue;
            }
            let s = text(v);
            let core: f32 = s.parse().unwrap();
            assert_eq!(core.to_bits(), v.to_bits(), "{v:e} printed {s}");
            assert_eq!(parse_f32(&s).map(f32::to_bits), Some(v.to_bits()), "{s}");
        }
    }

    /// The printed text is core's `{}` text (shortest digits, no exponent)
    /// for the values a commissioning engineer types and most others.
    #[test]
    fn e101_real32_text_is_cores_display() {
        for v in [0.1f32, 1.5, 100.0, 1e-7, -2.5, 0.3, 1e10, 123.456, -0.0, 7.0e-3] {
            assert_eq!(text(v), std::format!("{v}"));
        }
        let same = patterns(50_000)
            .filter(|v| v.is_finite())
            .filter(|&v| text(v) == std::format!("{v}"))
            .count();
        let finite = patterns(50_000).filter(|v| v.is_finite()).count();
        assert_eq!(same, finite, "texts differing from core's");
        assert_eq!(text(f32::INFINITY), "inf");
        assert_eq!(text(f32::NEG_INFINITY), "-inf");
        assert_eq!(text(f32::NAN), "NaN");
    }

    /// Parsing agrees with core's on the accepted forms and refuses what
    /// core refuses.
    #[test]
    fn e101_real32_parse_matches_core() {
        for s in [
            "0",
            "-0",
            "+1",
            "1.",
            ".5",
            "1e3",
            "1E-3",
            "2.5e+2",
            "0.000001",
            "123456789012345678901234",
            "1e39",
            "1e-50",
            "inf",
            "-Infinity",
            "3.4028235e38",
            "1.17549435e-38",
            "00012.5000",
        ] {
            let ours = parse_f32(s).map(f32::to_bits);
            let core = s.parse::<f32>().ok().map(f32::to_bits);
            assert_eq!(ours, core, "{s}");
        }
        assert!(parse_f32("nan").unwrap().is_nan());
        for s in [
            "", "-", ".", "e5", "1e", "1e+", "1.2.3", "0x10", "1 ", " 1", "--1", "1f",
        ] {
            assert_eq!(parse_f32(s), None, "{s:?}");
            assert!(s.parse::<f32>().is_err(), "core accepts {s:?}");
        }
    }
}
