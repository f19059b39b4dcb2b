//! The DCP Signal indication (P-011): the SF LED flashes red at 1 Hz for 3 s.
//!
//! [`Signal`] only remembers when the flashing started; the LED logic asks
//! [`Signal::is_lit`] at its own times. Each second of the 3 s starts with the
//! LED on for 500 ms, then off for 500 ms (three flashes). A Signal that arrives
//! while the LED flashes does not restart it, so the rhythm stays even.

use nanos::Nanos;

/// How long the LED flashes.
pub const DURATION: Nanos = Nanos::from_secs(3);
/// One on/off period (1 Hz).
pub const PERIOD: Nanos = Nanos::from_secs(1);
/// The lit part of each period.
pub const ON_TIME: Nanos = Nanos::from_ms(500);

/// State of the identification flash.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Signal {
    start: Option<Nanos>,
}

impl Signal {
    /// Starts flashing at `now` unless it is already flashing; returns the time
    /// the flashing ends.
    pub fn trigger(&mut self, now: Nanos) -> Nanos {
        match self.start {
            Some(s) if self.is_active(now) => s + DURATION,
            _ => {
                self.start = Some(now);
                now + DURATION
            }
        }
    }

    /// `true` during the 3 s after a trigger.
    pub fn is_active(&self, t: Nanos) -> bool {
        match self.start {
            Some(s) => t >= s && t.since(s) < DURATION,
            None => false,
        }
    }

    /// `true` if the SF LED is lit (red) by the identification flash at `t`.
    pub fn is_lit(&self, t: Nanos) -> bool {
        match self.start {
            Some(s) if self.is_active(t) => t
                .since(s)
                .checked_rem(PERIOD)
                .is_some_and(|phase| phase < ON_TIME),
            _ => false,
        }
    }

    /// When the current flashing ends, if it is flashing at `now`.
    pub fn until(&self, now: Nanos) -> Option<Nanos> {
        self.start.filter(|_| self.is_active(now)).map(|s| s + DURATION)
    }
}
