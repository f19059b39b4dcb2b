//! The EtherCAT indicators (spec §13.3, ETG.1300) as pure functions: which
//! pattern each LED shows follows from the ESM state and error indication
//! (RUN, ERR) or from the port's link and traffic (LA_EC IN/OUT); whether it
//! is lit at a given moment follows from the pattern and the time, which is
//! an argument (ns, any monotonic time base: the patterns repeat with their
//! period, so the phase is that of the time base).
//!
//! | LED | pattern | meaning |
//! |---|---|---|
//! | RUN (green) | off / blinking / single flash / on | Init / Pre-Op / Safe-Op / Op (Bootstrap: flickering) |
//! | ERR (red) | off | no error |
//! | | blinking | invalid configuration: a requested state change was refused |
//! | | single flash | unsolicited state change: the slave left a state on its own (sync fault, …) |
//! | | double flash | application watchdog timeout: PDO timeout / SM watchdog (AL 001Bh) |
//! | LA_EC IN/OUT (green) | off / flickering / on | no link / link with traffic / link without traffic |
//!
//! Timing (ETG.1300): blinking 200 ms on, 200 ms off; single flash 200 ms on,
//! 1000 ms off; double flash 200 on, 200 off, 200 on, 1000 off; flickering
//! 50 ms on, 50 ms off.

use esc::{AlState, AlStatusCode};
use nanos::Nanos;

/// One on or off phase of blinking and flashes.
pub const FLASH: Nanos = Nanos::from_ms(200);
/// The long off phase after a flash.
pub const FLASH_PAUSE: Nanos = Nanos::from_ms(1_000);
/// One on or off phase of flickering.
pub const FLICKER: Nanos = Nanos::from_ms(50);

/// An ETG.1300 indicator pattern.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Pattern {
    /// Always off.
    Off,
    /// Always on.
    On,
    /// 200 ms on, 200 ms off.
    Blinking,
    /// 200 ms on, 1000 ms off.
    SingleFlash,
    /// 200 ms on, 200 ms off, 200 ms on, 1000 ms off.
    DoubleFlash,
    /// 50 ms on, 50 ms off.
    Flickering,
}

impl Pattern {
    /// Length of one repetition (zero for the steady patterns).
    pub const fn period(self) -> Nanos {
        match self {
            Pattern::Off | Pattern::On => Nanos::ZERO,
            Pattern::Blinking => FLASH.saturating_mul(2),
            Pattern::SingleFlash => FLASH.saturating_add(FLASH_PAUSE),
            Pattern::DoubleFlash => FLASH.saturating_mul(3).saturating_add(FLASH_PAUSE),
            Pattern::Flickering => FLICKER.saturating_mul(2),
        }
    }

    /// Whether the LED is lit at `t`.
    pub const fn is_on(self, t: Nanos) -> bool {
        let phase = match t.checked_rem(self.period()) {
            Some(p) => p.as_ns(),
            None => 0,
        };
        let flash = FLASH.as_ns();
        match self {
            Pattern::Off => false,
            Pattern::On => true,
            Pattern::Blinking | Pattern::SingleFlash => phase < flash,
            Pattern::DoubleFlash => phase < flash || (phase >= 2 * flash && phase < 3 * flash),
            Pattern::Flickering => phase < FLICKER.as_ns(),
        }
    }
}

/// The green RUN LED for ESM state `state`.
pub const fn run(state: AlState) -> Pattern {
    match state {
        AlState::Init => Pattern::Off,
        AlState::PreOp => Pattern::Blinking,
        AlState::SafeOp => Pattern::SingleFlash,
        AlState::Op => Pattern::On,
        AlState::Bootstrap => Pattern::Flickering,
    }
}

/// The red ERR LED from the AL status: the error indication `error`, whether
/// the slave changed its state on its own (`unsolicited`, until the master's
/// next request) and the AL status `code`. An unsolicited change for the
/// SM watchdog / PDO timeout (001Bh) is the application watchdog (double
/// flash), any other one a local error (single flash); a refused request is
/// an invalid configuration (blinking).
pub fn err(error: bool, unsolicited: bool, code: AlStatusCode) -> Pattern {
    match (error, unsolicited) {
        (false, _) => Pattern::Off,
        (true, true) if code == AlStatusCode::SM_WATCHDOG => Pattern::DoubleFlash,
        (true, true) => Pattern::SingleFlash,
        (true, false) => Pattern::Blinking,
    }
}

/// A port's green LA_EC LED: `link` (physical link) and `activity` (frames
/// seen recently).
pub const fn link(link: bool, activity: bool) -> Pattern {
    match (link, activity) {
        (false, _) => Pattern::Off,
        (true, true) => Pattern::Flickering,
        (true, false) => Pattern::On,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lit/unlit sequence of `p` sampled every `step` ns over `span`.
    fn trace(p: Pattern, step: u64, span: u64) -> std::vec::Vec<bool> {
        (0..span / step)
            .map(|k| p.is_on(Nanos::from_ns(k * step)))
            .collect()
    }

    extern crate std;

    #[test]
    fn e132_e133_etg1300_timing() {
        let ms = 1_000_000;
        // 100 ms samples over one repetition
        let t = |p| trace(p, 100 * ms, p.period().as_ns().max(100 * ms));
        assert_eq!(t(Pattern::Blinking), [true, true, false, false]);
        let mut single = std::vec![true, true];
        single.extend([false; 10]);
        assert_eq!(t(Pattern::SingleFlash), single);
        let mut double = std::vec![true, true, false, false, true, true];
        double.extend([false; 10]);
        assert_eq!(t(Pattern::DoubleFlash), double);
        assert_eq!(
            trace(Pattern::Flickering, 25 * ms, 100 * ms),
            [true, true, false, false]
        );
        assert!((0..50).all(|k| Pattern::On.is_on(Nanos::from_ns(k * 37 * ms))
            && !Pattern::Off.is_on(Nanos::from_ns(k * 37 * ms))));
        // repeats with its period, from any time base
        let p = Pattern::DoubleFlash;
        for k in 0..40u64 {
            let t0 = k * 50 * ms + 7;
            assert_eq!(
                p.is_on(Nanos::from_ns(t0)),
                p.is_on(Nanos::from_ns(t0 + 5 * p.period().as_ns())),
                "{t0}"
            );
        }
        // edges exactly at the ETG.1300 times
        assert!(
            Pattern::SingleFlash.is_on(Nanos::from_ns(200 * ms - 1))
                && !Pattern::SingleFlash.is_on(Nanos::from_ns(200 * ms))
        );
        assert!(
            !Pattern::SingleFlash.is_on(Nanos::from_ns(1200 * ms - 1))
                && Pattern::SingleFlash.is_on(Nanos::from_ns(1200 * ms))
        );
        assert!(
            !Pattern::DoubleFlash.is_on(Nanos::from_ns(400 * ms - 1))
                && Pattern::DoubleFlash.is_on(Nanos::from_ns(400 * ms))
        );
        assert!(!Pattern::DoubleFlash.is_on(Nanos::from_ns(600 * ms)));
    }

    #[test]
    fn e133_run_led_by_state() {
        assert_eq!(run(AlState::Init), Pattern::Off);
        assert_eq!(run(AlState::PreOp), Pattern::Blinking);
        assert_eq!(run(AlState::SafeOp), Pattern::SingleFlash);
        assert_eq!(run(AlState::Op), Pattern::On);
    }

    #[test]
    fn e132_err_led_by_indication() {
        let wd = AlStatusCode::SM_WATCHDOG;
        assert_eq!(err(false, false, AlStatusCode::NO_ERROR), Pattern::Off);
        assert_eq!(err(false, true, wd), Pattern::Off, "acknowledged");
        assert_eq!(
            err(true, false, AlStatusCode::INVALID_STATE_CHANGE),
            Pattern::Blinking
        );
        assert_eq!(err(true, false, wd), Pattern::Blinking, "S→O refused: a request");
        assert_eq!(err(true, true, AlStatusCode(0x0034)), Pattern::SingleFlash);
        assert_eq!(err(true, true, wd), Pattern::DoubleFlash);
    }

    #[test]
    fn e134_link_led() {
        assert_eq!(link(false, true), Pattern::Off);
        assert_eq!(link(true, false), Pattern::On);
        assert_eq!(link(true, true), Pattern::Flickering);
    }
}
