//! The control-cycle timer.
//!
//! Without SYNC0 the control cycle runs free at A150
//! ([`Drive::free_run_period`](drive_ecat::runtime::Drive::free_run_period);
//! the first cycle at [`CYCLE`]). Once
//! the drive's DC-Sync PLL exists, each cycle's [`CycleCommand`](drive_ecat::runtime::dcsync::CycleCommand) gives the
//! length of the next one in timer ticks ([`TIMER_HZ`]): the board programs
//! its compare register from [`CycleTimer::next_at`] (the QEMU world pends
//! the control interrupt at that time).

use drive_ecat::axis::{AxisCommand, AxisIo};
use drive_ecat::runtime::TIMER_HZ;

use nanos::Nanos;

use crate::clock::mul_div;
use crate::Drive;

/// The first free-running control cycle starts at this local time (A150's
/// default); the next ones follow A150.
pub const CYCLE: Nanos = Nanos::from_us(drive_ecat::params::A150_FALLBACK_US as u64);

const NS_PER_S: u64 = 1_000_000_000;

/// Timer ticks per ns as a reduced fraction (144 MHz: 18/125), so the
/// conversions stay in 64 bits for centuries of uptime.
const G: u64 = drive_ecat::runtime::dcsync::gcd(TIMER_HZ as u64, NS_PER_S);
const TICK_NUM: u64 = TIMER_HZ as u64 / G;
const NS_DEN: u64 = NS_PER_S / G;

/// `a · b / c` rounded up, saturated ([`crate::clock::mul_div`]).
fn mul_div_ceil(a: u64, b: u64, c: u64) -> u64 {
    let (q, remainder) = mul_div(a, b, c);
    q.saturating_add(u64::from(remainder))
}

/// Local time of timer tick `tick` (rounded up to the ns: the tick is reached then).
fn tick_time(tick: u64) -> Nanos {
    Nanos::from_ns(mul_div_ceil(tick, NS_DEN, TICK_NUM))
}

/// The tick at or after local time `t`.
fn tick_at(t: Nanos) -> u64 {
    mul_div_ceil(t.as_ns(), TICK_NUM, NS_DEN)
}

/// A cycle start in timer ticks with its local time kept as
/// `tick · NS_DEN = q · TICK_NUM + r`, so that advancing it by a cycle's
/// ticks takes a 32-bit division instead of [`tick_time`]'s 64-bit product
/// and division (issue 36); equal to [`tick_time`] at every tick
/// (`e111_advanced_tick_times_equal_the_conversion`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct TickTime {
    tick: u64,
    q: u64,
    /// The remainder, below `TICK_NUM`; `u64::MAX` where `tick · NS_DEN`
    /// overflows 64 bits (centuries of uptime): the time is then converted.
    r: u64,
}

impl TickTime {
    /// Tick `tick`, its time split exactly.
    fn at(tick: u64) -> Self {
        match tick.checked_mul(NS_DEN) {
            Some(x) => Self {
                tick,
                q: x / TICK_NUM,
                r: x % TICK_NUM,
            },
            None => Self {
                tick,
                q: 0,
                r: u64::MAX,
            },
        }
    }

    /// Local time of the tick (rounded up to the ns, as [`tick_time`]).
    fn time(self) -> Nanos {
        match self.r {
            0 => Nanos::from_ns(self.q),
            u64::MAX => tick_time(self.tick),
            _ => Nanos::from_ns(self.q.saturating_add(1)),
        }
    }

    /// `ticks` later.
    fn advance(self, ticks: u32) -> Self {
        let tick = self.tick.saturating_add(u64::from(ticks));
        // ticks · NS_DEN + r stays below 2^32 for any cycle this timer runs
        // (ticks < 2^32 / NS_DEN: 238 ms at 144 MHz): one 32-bit division
        let x = u64::from(ticks)
            .checked_mul(NS_DEN)
            .and_then(|x| x.checked_add(self.r))
            .and_then(|x| u32::try_from(x).ok());
        match (x, u32::try_from(TICK_NUM)) {
            (Some(x), Ok(den)) if self.r != u64::MAX && den > 0 => Self {
                tick,
                q: self.q.saturating_add(u64::from(x / den)),
                r: u64::from(x % den),
            },
            _ => Self::at(tick),
        }
    }
}

/// When the next control cycle starts and how it runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CycleTimer {
    /// The next start in timer ticks while the PLL runs.
    next_tick: Option<TickTime>,
    /// The next start in local time while free-running.
    next: Nanos,
}

impl Default for CycleTimer {
    fn default() -> Self {
        Self::new()
    }
}

impl CycleTimer {
    /// Free-running, first cycle at [`CYCLE`].
    pub const fn new() -> Self {
        Self {
            next_tick: None,
            next: CYCLE,
        }
    }

    /// Local time of the next cycle start.
    pub fn next_at(&self) -> Nanos {
        match self.next_tick {
            Some(t) => t.time(),
            None => self.next,
        }
    }

    /// Switches to the PLL's periods when it appeared (continuing from the
    /// free-running phase) and back when it went. Call after the SYNC0 task
    /// and the ESC task.
    pub fn follow_pll(&mut self, drive: &Drive) {
        match (drive.pll().is_some(), self.next_tick) {
            (true, None) => self.next_tick = Some(TickTime::at(tick_at(self.next))),
            (false, Some(_)) => {
                self.next = self.next_at();
                self.next_tick = None;
            }
            _ => {}
        }
    }

    /// Runs the control cycle due at local time `now` (the timer's
    /// compare time): under the PLL its cycle command
    /// (steps in the A149 order, Rx/Tx in the aligned cycle), else a
    /// free-running cycle; programs the next start. Returns the power-stage
    /// commands.
    pub fn run(&mut self, drive: &mut Drive, now: Nanos, io: &[AxisIo; 2]) -> [AxisCommand; 2] {
        if let Some(t) = self.next_tick {
            if let Some(cmd) = drive.cycle_start(t.time()) {
                self.next_tick = Some(t.advance(cmd.period_ticks.max(1)));
                return drive.sync_cycle(&cmd, now, io);
            }
            self.next_tick = None;
        }
        self.next = now.saturating_add(drive.free_run_period());
        drive.control_cycle(now, io)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// E-111 (issue 36): a cycle start advanced period by period has the
    /// local time [`tick_time`] gives its tick, from 0, from odd ticks, with
    /// periods of one tick to 8 ms and beyond the 32-bit step, and at the
    /// edge where `tick · NS_DEN` overflows 64 bits.
    #[test]
    fn e111_advanced_tick_times_equal_the_conversion() {
        let limit = u64::MAX / NS_DEN;
        for start in [0u64, 1, 17, 143_999, 1 << 40, limit - 3_000_000, limit + 5] {
            let mut t = TickTime::at(start);
            assert_eq!(t.time(), tick_time(start), "start {start}");
            for (k, period) in [1u32, 36_000, 143_999, 1_152_000, 7, 40_000_000, u32::MAX, 35_999]
                .into_iter()
                .cycle()
                .take(64)
                .enumerate()
            {
                t = t.advance(period);
                assert_eq!(t.time(), tick_time(t.tick), "start {start}, step {k}");
            }
        }
    }

    /// E-111: the 64-bit tick conversions equal the exact 128-bit ones,
    /// from 0 to centuries of uptime and at the overflow edge.
    #[test]
    fn e111_tick_conversions_match_128_bit_reference() {
        let hz = u128::from(TIMER_HZ);
        let ns = u128::from(NS_PER_S);
        for &v in &[
            0u64,
            1,
            7,
            143_999,
            1_000_000,
            123_456_789_012,
            1 << 40,
            1 << 60,
            u64::MAX / 200,
        ] {
            let t = u64::try_from((u128::from(v) * ns).div_ceil(hz)).unwrap_or(u64::MAX);
            assert_eq!(tick_time(v), Nanos::from_ns(t), "tick {v}");
            let n = u64::try_from((u128::from(v) * hz).div_ceil(ns)).unwrap_or(u64::MAX);
            assert_eq!(tick_at(Nanos::from_ns(v)), n, "ns {v}");
        }
    }
}
