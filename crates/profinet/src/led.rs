//! The SF and BF LEDs (spec §2.5, P-011, P-020…P-024) as a function of the
//! device's state and the time.
//!
//! | LED | pattern | when (first match wins) |
//! |---|---|---|
//! | SF | red flashing 1 Hz | a DCP Signal is active (3 s, three flashes) |
//! | SF | red steady | watchdog timeout, diagnosis present, or system error |
//! | SF | off | otherwise |
//! | BF | red steady | no link, or no AR ("no configuration") |
//! | BF | red flashing 2 Hz | an AR but no cyclic data exchanged recently |
//! | BF | off | otherwise |
//!
//! Flashing is in phase with the time: 1 Hz is lit for the first 500 ms of
//! the signal's every second (counted from its start), 2 Hz is lit while
//! `now mod 500 ms < 250 ms`.

use nanos::Nanos;

/// How long a DCP Signal flashes the SF LED.
pub const DCP_SIGNAL: Nanos = Nanos::from_secs(3);

/// An LED's pattern.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pattern {
    /// Dark.
    Off,
    /// Lit.
    On,
    /// Flashing: lit for half of each period of this many ms.
    Flash {
        /// The period in ms (1000 = 1 Hz, 500 = 2 Hz).
        period_ms: u32,
    },
}

/// The inputs of the LED logic; the caller sets them from the stack's state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LedInputs {
    /// The Ethernet link is up (on either port).
    pub link_up: bool,
    /// An AR is established.
    pub ar_established: bool,
    /// Cyclic data was exchanged recently (the consumer runs and its data
    /// hold timer has not expired: [`crate::rt::Consumer::exchanging`]).
    pub cyclic_exchange: bool,
    /// The consumer watchdog expired (kept until a new AR exchanges data).
    pub watchdog_expired: bool,
    /// Channel, general or extended diagnosis is present
    /// ([`crate::alarm::DiagList::any_present`]).
    pub diagnosis: bool,
    /// A system error (firmware, hardware).
    pub system_error: bool,
    /// A DCP Signal flashes until this time (`None`: no signal).
    pub dcp_signal_until: Option<Nanos>,
}

impl LedInputs {
    /// Starts a DCP Signal at `now` (3 s of 1 Hz flashing).
    pub fn dcp_signal(&mut self, now: Nanos) {
        self.dcp_signal_until = Some(now.saturating_add(DCP_SIGNAL));
    }

    /// The SF (system fault) pattern at `now`.
    pub fn sf(&self, now: Nanos) -> Pattern {
        if self.dcp_signal_until.is_some_and(|t| now < t) {
            Pattern::Flash { period_ms: 1000 }
        } else if self.watchdog_expired || self.diagnosis || self.system_error {
            Pattern::On
        } else {
            Pattern::Off
        }
    }

    /// The BF (bus fault) pattern.
    pub fn bf(&self) -> Pattern {
        if !self.link_up || !self.ar_established {
            Pattern::On
        } else if !self.cyclic_exchange {
            Pattern::Flash { period_ms: 500 }
        } else {
            Pattern::Off
        }
    }

    /// The SF LED is lit at `now`.
    pub fn sf_lit(&self, now: Nanos) -> bool {
        match (self.sf(now), self.dcp_signal_until) {
            (Pattern::Flash { period_ms }, Some(until)) => {
                // lit in the first half of each period since the signal began
                let since = now.saturating_sub(until.saturating_sub(DCP_SIGNAL));
                lit_in(since, period_ms)
            }
            (p, _) => lit(p, now),
        }
    }

    /// The BF LED is lit at `now`.
    pub fn bf_lit(&self, now: Nanos) -> bool {
        lit(self.bf(), now)
    }
}

/// A pattern is lit at `t` (flashing in phase with `t`).
pub fn lit(p: Pattern, t: Nanos) -> bool {
    match p {
        Pattern::Off => false,
        Pattern::On => true,
        Pattern::Flash { period_ms } => lit_in(t, period_ms),
    }
}

fn lit_in(t: Nanos, period_ms: u32) -> bool {
    let period = u64::from(period_ms.max(1)) * 1_000_000;
    t.as_ns() % period < period / 2
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(v: u64) -> Nanos {
        Nanos::from_ms(v)
    }

    fn running() -> LedInputs {
        LedInputs {
            link_up: true,
            ar_established: true,
            cyclic_exchange: true,
            ..LedInputs::default()
        }
    }

    #[test]
    fn p020_p022_both_off_in_data_exchange_without_errors() {
        let l = running();
        assert_eq!((l.sf(ms(0)), l.bf()), (Pattern::Off, Pattern::Off));
        assert!((0..2000)
            .step_by(50)
            .all(|t| !l.sf_lit(ms(t)) && !l.bf_lit(ms(t))));
    }

    #[test]
    fn p021_sf_steady_on_watchdog_diagnosis_or_system_error() {
        for set in [
            |l: &mut LedInputs| l.watchdog_expired = true,
            |l: &mut LedInputs| l.diagnosis = true,
            |l: &mut LedInputs| l.system_error = true,
        ] {
            let mut l = running();
            set(&mut l);
            assert_eq!(l.sf(ms(0)), Pattern::On);
            assert!((0..2000).step_by(50).all(|t| l.sf_lit(ms(t))));
        }
    }

    #[test]
    fn p023_bf_steady_without_link_or_configuration() {
        let mut l = running();
        l.link_up = false;
        assert_eq!(l.bf(), Pattern::On);
        let mut l = running();
        l.ar_established = false;
        l.cyclic_exchange = false;
        assert_eq!(l.bf(), Pattern::On);
        assert!((0..1000).step_by(50).all(|t| l.bf_lit(ms(t))));
    }

    #[test]
    fn p024_bf_flashes_2_hz_without_cyclic_data() {
        let mut l = running();
        l.cyclic_exchange = false;
        assert_eq!(l.bf(), Pattern::Flash { period_ms: 500 });
        let lit: std::vec::Vec<bool> = (0..8).map(|i| l.bf_lit(ms(i * 125))).collect();
        assert_eq!(lit, [true, true, false, false, true, true, false, false]);
        // 2 Hz: two rising edges per second
        let edges = (1..=1000)
            .filter(|t| l.bf_lit(ms(*t)) && !l.bf_lit(ms(t - 1)))
            .count();
        assert_eq!(edges, 2);
    }

    #[test]
    fn p011_dcp_signal_flashes_sf_1_hz_for_3_s_then_back() {
        let mut l = running();
        l.diagnosis = true;
        l.dcp_signal(ms(10_250));
        assert_eq!(l.sf(ms(10_250)), Pattern::Flash { period_ms: 1000 });
        let on: std::vec::Vec<bool> = (0..6).map(|i| l.sf_lit(ms(10_250 + i * 500))).collect();
        assert_eq!(on, [true, false, true, false, true, false]);
        assert!(l.sf_lit(ms(10_250 + 499)));
        assert!(!l.sf_lit(ms(10_250 + 500)));
        // after 3 s: steady again (diagnosis present)
        assert_eq!(l.sf(ms(13_250)), Pattern::On);
        assert!(l.sf_lit(ms(13_750)));
        l.diagnosis = false;
        assert!(!l.sf_lit(ms(13_750)));
    }
}
