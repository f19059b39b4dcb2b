//! The firmware's clock: a 32-bit hardware counter extended to 64-bit
//! nanoseconds.
//!
//! The reference board counts CPU cycles (DWT CYCCNT at 144 MHz, wrapping
//! every 29.8 s); every task reads the clock at least once per control cycle,
//! so two readings are never a whole wrap apart and the wraps can be counted.
//! Time is an argument to the core crates: only the RTIC shell reads this.

use drive_ecat::runtime::dcsync::{div_rem_u64, gcd};
use nanos::Nanos;

/// Extends a wrapping 32-bit tick counter of `hz` to monotonic ns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Clock {
    /// ns per tick as the reduced fraction `ns_num / tick_den` (144 MHz:
    /// 125/18), so a reading is a 64-bit product and a small division.
    ns_num: u64,
    tick_den: u64,
    last_raw: u32,
    ticks: u64,
}

impl Clock {
    /// A clock over a counter of `hz` ticks per second (0 is taken as 1).
    pub const fn new(hz: u32) -> Self {
        let hz = if hz == 0 { 1 } else { hz as u64 };
        let g = gcd(hz, NS_PER_S);
        Self {
            ns_num: NS_PER_S / g,
            tick_den: hz / g,
            last_raw: 0,
            ticks: 0,
        }
    }

    /// The time at counter value `raw`, since the counter's first reading of 0.
    /// Readings must come at least once per counter wrap.
    pub fn now(&mut self, raw: u32) -> Nanos {
        self.ticks = self
            .ticks
            .wrapping_add(u64::from(raw.wrapping_sub(self.last_raw)));
        self.last_raw = raw;
        // 144 MHz: 64 bits for 32 years of ticks, then 128 out of line
        Nanos::from_ns(mul_div(self.ticks, self.ns_num, self.tick_den).0)
    }
}

const NS_PER_S: u64 = 1_000_000_000;

/// `a · b / c` truncated and saturated, and whether it left a remainder
/// (`c` = 0 counts as 1): a 64-bit product and [`div_rem_u64`]'s division
/// by the small denominators of the reduced fractions, 128 bits out of line
/// only when the product overflows. The clock and the cycle timer's
/// tick ↔ ns conversions use it.
pub(crate) fn mul_div(a: u64, b: u64, c: u64) -> (u64, bool) {
    match a.checked_mul(b) {
        Some(x) => div_rem_u64(x, c.max(1)).map_or((u64::MAX, false), |(q, r)| (q, r != 0)),
        None => mul_div_wide(a, b, c),
    }
}

#[cold]
#[inline(never)]
fn mul_div_wide(a: u64, b: u64, c: u64) -> (u64, bool) {
    let x = u128::from(a) * u128::from(b);
    let c = u128::from(c.max(1));
    (u64::try_from(x / c).unwrap_or(u64::MAX), x % c != 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reduced-fraction reading equals the exact 128-bit one, for the
    /// board's clock and a clock whose ratio to 1 GHz does not reduce, up to
    /// and beyond the 64-bit product.
    #[test]
    fn e111_clock_reading_equals_the_128_bit_reference() {
        for hz in [144_000_000u32, 99_999_989, 1, 0] {
            let mut c = Clock::new(hz);
            let hz = u128::from(hz.max(1));
            for ticks in [
                0u64,
                1,
                17,
                144_000,
                1 << 32,
                123_456_789_012_345,
                1 << 60,
                u64::MAX / 3,
            ] {
                c.ticks = ticks;
                c.last_raw = 0;
                let got = c.now(0).as_ns();
                let want = u64::try_from(u128::from(ticks) * 1_000_000_000 / hz).unwrap_or(u64::MAX);
                assert_eq!(got, want, "{hz} Hz, {ticks} ticks");
            }
        }
    }
}
