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

/// When the next control cycle starts and how it runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CycleTimer {
    /// The next start in timer ticks while the PLL runs.
    next_tick: Option<u64>,
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
            Some(tick) => tick_time(tick),
            None => self.next,
        }
    }

    /// Switches to the PLL's periods when it appeared (continuing from the
    /// free-running phase) and back when it went. Call after the SYNC0 task
    /// and the ESC task.
    pub fn follow_pll(&mut self, drive: &Drive) {
        match (drive.pll().is_some(), self.next_tick) {
            (true, None) => self.next_tick = Some(tick_at(self.next)),
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
        if let Some(tick) = self.next_tick {
            if let Some(cmd) = drive.cycle_start(tick_time(tick)) {
                self.next_tick = Some(tick.saturating_add(u64::from(cmd.period_ticks.max(1))));
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
