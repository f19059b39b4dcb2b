//! The firmware's clock: a 32-bit hardware counter extended to 64-bit
//! nanoseconds.
//!
//! The reference board counts CPU cycles (DWT CYCCNT at 144 MHz, wrapping
//! every 29.8 s); every task reads the clock at least once per control cycle,
//! so two readings are never a whole wrap apart and the wraps can be counted.
//! Time is an argument to the core crates: only the RTIC shell reads this.

/// Extends a wrapping 32-bit tick counter of `hz` to monotonic ns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Clock {
    hz: u32,
    last_raw: u32,
    ticks: u64,
}

impl Clock {
    /// A clock over a counter of `hz` ticks per second (0 is taken as 1).
    pub const fn new(hz: u32) -> Self {
        Self {
            hz: if hz == 0 { 1 } else { hz },
            last_raw: 0,
            ticks: 0,
        }
    }

    /// The time at counter value `raw`, ns since the counter's first reading
    /// of 0. Readings must come at least once per counter wrap.
    pub fn now_ns(&mut self, raw: u32) -> u64 {
        self.ticks = self
            .ticks
            .wrapping_add(u64::from(raw.wrapping_sub(self.last_raw)));
        self.last_raw = raw;
        let ns = u128::from(self.ticks) * 1_000_000_000 / u128::from(self.hz);
        u64::try_from(ns).unwrap_or(u64::MAX)
    }
}
