//! The one time type of the firmware: [`Nanos`], a count of nanoseconds in a `u64`.
//!
//! Every crate takes time as an argument (the drive core, the fieldbus stacks, the
//! simulator); this is the type of that argument. It is an instant (nanoseconds since an
//! epoch the caller chooses: boot, the DC system-time origin, the start of a simulation)
//! or a span (a cycle time, a timeout); a `u64` of nanoseconds lasts 584 years, so the
//! firmware never sees it wrap.
//!
//! Arithmetic is explicit about the edge: `+` and `-` saturate (a span computed from two
//! instants in the wrong order is zero, never a huge number and never a panic), and so
//! does `*` by a count (`3 * cycle`); the `wrapping_*` and `checked_*` forms are there
//! where a caller needs them. Conversions to and from µs/ms/s truncate toward zero and
//! saturate on overflow.
//!
//! `#![no_std]`, no dependencies, every operation `const` or `#[inline]` and panic-free;
//! the newtype is `repr(transparent)` and costs nothing over a bare `u64`.
#![no_std]
#![deny(missing_docs)]

use core::fmt;
use core::ops::{Add, AddAssign, Mul, Sub, SubAssign};

/// Nanoseconds: an instant since the caller's epoch, or a span.
#[derive(Clone, Copy, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(transparent)]
pub struct Nanos(u64);

impl Nanos {
    /// Zero: the epoch, or an empty span.
    pub const ZERO: Nanos = Nanos(0);
    /// The largest value (584 years); used as "never" for deadlines.
    pub const MAX: Nanos = Nanos(u64::MAX);

    /// `ns` nanoseconds.
    #[inline]
    pub const fn from_ns(ns: u64) -> Nanos {
        Nanos(ns)
    }

    /// `us` microseconds (saturating).
    #[inline]
    pub const fn from_us(us: u64) -> Nanos {
        Nanos(us.saturating_mul(1_000))
    }

    /// `ms` milliseconds (saturating).
    #[inline]
    pub const fn from_ms(ms: u64) -> Nanos {
        Nanos(ms.saturating_mul(1_000_000))
    }

    /// `s` seconds (saturating).
    #[inline]
    pub const fn from_secs(s: u64) -> Nanos {
        Nanos(s.saturating_mul(1_000_000_000))
    }

    /// The count of nanoseconds.
    #[inline]
    pub const fn as_ns(self) -> u64 {
        self.0
    }

    /// Whole microseconds (truncated).
    #[inline]
    pub const fn as_us(self) -> u64 {
        self.0 / 1_000
    }

    /// Whole milliseconds (truncated).
    #[inline]
    pub const fn as_ms(self) -> u64 {
        self.0 / 1_000_000
    }

    /// Whole seconds (truncated).
    #[inline]
    pub const fn as_secs(self) -> u64 {
        self.0 / 1_000_000_000
    }

    /// Seconds as `f32` (for a control cycle's `dt`).
    #[inline]
    pub fn as_secs_f32(self) -> f32 {
        self.0 as f32 * 1e-9
    }

    /// Seconds as `f64`.
    #[inline]
    pub fn as_secs_f64(self) -> f64 {
        self.0 as f64 * 1e-9
    }

    /// `true` for zero.
    #[inline]
    pub const fn is_zero(self) -> bool {
        self.0 == 0
    }

    /// `self + rhs`, saturating at [`Nanos::MAX`].
    #[inline]
    pub const fn saturating_add(self, rhs: Nanos) -> Nanos {
        Nanos(self.0.saturating_add(rhs.0))
    }

    /// `self - rhs`, zero if `rhs` is later.
    #[inline]
    pub const fn saturating_sub(self, rhs: Nanos) -> Nanos {
        Nanos(self.0.saturating_sub(rhs.0))
    }

    /// `self + rhs` modulo 2^64 (free-running hardware counters).
    #[inline]
    pub const fn wrapping_add(self, rhs: Nanos) -> Nanos {
        Nanos(self.0.wrapping_add(rhs.0))
    }

    /// `self - rhs` modulo 2^64 (free-running hardware counters).
    #[inline]
    pub const fn wrapping_sub(self, rhs: Nanos) -> Nanos {
        Nanos(self.0.wrapping_sub(rhs.0))
    }

    /// `self + rhs`, `None` on overflow.
    #[inline]
    pub const fn checked_add(self, rhs: Nanos) -> Option<Nanos> {
        match self.0.checked_add(rhs.0) {
            Some(v) => Some(Nanos(v)),
            None => None,
        }
    }

    /// `self - rhs`, `None` if `rhs` is later.
    #[inline]
    pub const fn checked_sub(self, rhs: Nanos) -> Option<Nanos> {
        match self.0.checked_sub(rhs.0) {
            Some(v) => Some(Nanos(v)),
            None => None,
        }
    }

    /// `self × n`, saturating.
    #[inline]
    pub const fn saturating_mul(self, n: u64) -> Nanos {
        Nanos(self.0.saturating_mul(n))
    }

    /// `self / n`, `None` for `n == 0`.
    #[inline]
    pub const fn checked_div(self, n: u64) -> Option<Nanos> {
        match self.0.checked_div(n) {
            Some(v) => Some(Nanos(v)),
            None => None,
        }
    }

    /// How many whole `span`s fit in `self`; `None` for an empty `span`.
    #[inline]
    pub const fn checked_div_span(self, span: Nanos) -> Option<u64> {
        self.0.checked_div(span.0)
    }

    /// `self mod span`; `None` for an empty `span`.
    #[inline]
    pub const fn checked_rem(self, span: Nanos) -> Option<Nanos> {
        match self.0.checked_rem(span.0) {
            Some(v) => Some(Nanos(v)),
            None => None,
        }
    }

    /// Time from `earlier` to `self` (zero if `earlier` is later): `now.since(start)`.
    #[inline]
    pub const fn since(self, earlier: Nanos) -> Nanos {
        self.saturating_sub(earlier)
    }

    /// The smaller of two.
    #[inline]
    pub const fn min(self, other: Nanos) -> Nanos {
        if self.0 <= other.0 {
            self
        } else {
            other
        }
    }

    /// The larger of two.
    #[inline]
    pub const fn max(self, other: Nanos) -> Nanos {
        if self.0 >= other.0 {
            self
        } else {
            other
        }
    }
}

impl Add for Nanos {
    type Output = Nanos;
    /// Saturating.
    #[inline]
    fn add(self, rhs: Nanos) -> Nanos {
        self.saturating_add(rhs)
    }
}

impl Sub for Nanos {
    type Output = Nanos;
    /// Saturating: zero if `rhs` is later.
    #[inline]
    fn sub(self, rhs: Nanos) -> Nanos {
        self.saturating_sub(rhs)
    }
}

/// `span × n`, saturating (as [`Nanos::saturating_mul`]).
impl Mul<u64> for Nanos {
    type Output = Nanos;
    #[inline]
    fn mul(self, n: u64) -> Nanos {
        self.saturating_mul(n)
    }
}

/// `n × span`, saturating (as [`Nanos::saturating_mul`]): `200 * MS`.
impl Mul<Nanos> for u64 {
    type Output = Nanos;
    #[inline]
    fn mul(self, span: Nanos) -> Nanos {
        span.saturating_mul(self)
    }
}

impl AddAssign for Nanos {
    #[inline]
    fn add_assign(&mut self, rhs: Nanos) {
        *self = self.saturating_add(rhs);
    }
}

impl SubAssign for Nanos {
    #[inline]
    fn sub_assign(&mut self, rhs: Nanos) {
        *self = self.saturating_sub(rhs);
    }
}

impl fmt::Debug for Nanos {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}ns", self.0)
    }
}

/// `1.250000 ms`-style: seconds, milliseconds or microseconds with the fraction kept.
impl fmt::Display for Nanos {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let ns = self.0;
        if ns >= 1_000_000_000 {
            write!(f, "{}.{:09} s", ns / 1_000_000_000, ns % 1_000_000_000)
        } else if ns >= 1_000_000 {
            write!(f, "{}.{:06} ms", ns / 1_000_000, ns % 1_000_000)
        } else if ns >= 1_000 {
            write!(f, "{}.{:03} µs", ns / 1_000, ns % 1_000)
        } else {
            write!(f, "{ns} ns")
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::Nanos;
    use std::format;

    #[test]
    fn units_convert_both_ways_and_truncate() {
        assert_eq!(Nanos::from_us(250).as_ns(), 250_000);
        assert_eq!(Nanos::from_ms(4).as_us(), 4_000);
        assert_eq!(Nanos::from_secs(2).as_ms(), 2_000);
        assert_eq!(Nanos::from_ns(1_999).as_us(), 1);
        assert_eq!(Nanos::from_us(u64::MAX), Nanos::MAX);
        assert!((Nanos::from_us(250).as_secs_f32() - 250e-6).abs() < 1e-9);
    }

    #[test]
    fn operators_saturate_and_named_forms_do_what_they_say() {
        let a = Nanos::from_ns(5);
        let b = Nanos::from_ns(7);
        assert_eq!(a - b, Nanos::ZERO);
        assert_eq!(b - a, Nanos::from_ns(2));
        assert_eq!(Nanos::MAX + a, Nanos::MAX);
        assert_eq!(a.checked_sub(b), None);
        assert_eq!(a.wrapping_sub(b), Nanos::from_ns(u64::MAX - 1));
        assert_eq!(b.since(a), Nanos::from_ns(2));
        assert_eq!(Nanos::from_ms(1).checked_div_span(Nanos::from_us(250)), Some(4));
        assert_eq!(a.checked_div_span(Nanos::ZERO), None);
        assert_eq!(
            Nanos::from_ns(1_100).checked_rem(Nanos::from_ns(250)),
            Some(Nanos::from_ns(100))
        );
        let mut c = a;
        c += b;
        c -= Nanos::from_ns(20);
        assert_eq!(c, Nanos::ZERO);
        let ms = Nanos::from_ms(1);
        assert_eq!(3 * ms, Nanos::from_ms(3));
        assert_eq!(ms * 3, Nanos::from_ms(3));
        assert_eq!(u64::MAX * ms, Nanos::MAX);
    }

    #[test]
    fn display_keeps_the_fraction() {
        assert_eq!(format!("{}", Nanos::from_us(1_250)), "1.250000 ms");
        assert_eq!(format!("{}", Nanos::from_ns(999)), "999 ns");
        assert_eq!(format!("{}", Nanos::from_ns(62_500)), "62.500 µs");
        assert_eq!(format!("{}", Nanos::from_secs(3)), "3.000000000 s");
    }
}
