//! Cycle times and their ratio (spec §10.1, §12; C-114, C-115, C-144).
//!
//! The master (bus/PLC) cycle A291 comes from 60C2h (value × 10^index s); it
//! must equal the application (control) cycle A150 or be an integer multiple
//! of it. The ratio N is the number of single interpolation steps per master
//! set-point.

/// The application cycle times A150 accepts, in ns (spec §12, C-144).
pub const APPLICATION_CYCLES_NS: [u32; 6] = [250_000, 500_000, 1_000_000, 2_000_000, 4_000_000, 8_000_000];

/// Largest ratio N = master cycle / control cycle the interpolator takes.
///
/// Bounds the interpolator's integer arithmetic so that it fits in `i64`
/// (e.g. a 128 ms master cycle over a 250 µs control cycle is N = 512).
pub const MAX_RATIO: u32 = 512;

/// Why a cycle time or a ratio is refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CycleError {
    /// A cycle time of 0 ns.
    Zero,
    /// The master cycle is not an integer multiple of the control cycle (C-114).
    NotIntegerMultiple,
    /// N = master / control is above [`MAX_RATIO`].
    RatioTooLarge,
    /// Not one of [`APPLICATION_CYCLES_NS`] (A150, C-144).
    NotAnApplicationCycle,
    /// 60C2h value × 10^index s is not a whole number of ns or does not fit
    /// in `u32` ns.
    PeriodOutOfRange,
}

/// Checks an application cycle time A150 (ns) against the allowed values
/// (C-144) and returns it.
pub fn application_cycle_ns(a150_ns: u32) -> Result<u32, CycleError> {
    if APPLICATION_CYCLES_NS.contains(&a150_ns) {
        Ok(a150_ns)
    } else {
        Err(CycleError::NotAnApplicationCycle)
    }
}

/// The interpolation period of 60C2h (`A602[0]` value, `A602[1]` index) in ns:
/// value × 10^index s (`[std]`), which the drive copies into A291 (C-114).
///
/// Refused when the period is 0, not a whole number of ns (index < −9 with a
/// value that is not a multiple of the missing power of ten) or above
/// `u32::MAX` ns (≈ 4.29 s).
pub fn interpolation_period_ns(value: u8, index: i8) -> Result<u32, CycleError> {
    if value == 0 {
        return Err(CycleError::Zero);
    }
    // Period in ns = value × 10^(index + 9).
    let exp = i32::from(index) + 9;
    let mut ns = u64::from(value);
    if exp >= 0 {
        for _ in 0..exp {
            ns = ns.checked_mul(10).ok_or(CycleError::PeriodOutOfRange)?;
            if ns > u64::from(u32::MAX) {
                return Err(CycleError::PeriodOutOfRange);
            }
        }
    } else {
        for _ in 0..(-exp) {
            if ns % 10 != 0 {
                return Err(CycleError::PeriodOutOfRange);
            }
            ns /= 10;
        }
    }
    u32::try_from(ns).map_err(|_| CycleError::PeriodOutOfRange)
}

/// A validated pair of master cycle (A291) and control cycle (A150) with
/// their integer ratio N (C-114, C-115).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CycleRatio {
    master_ns: u32,
    control_ns: u32,
    n: u32,
}

impl CycleRatio {
    /// Validates master cycle `master_ns` (A291, ns) against control cycle
    /// `control_ns` (A150 or the interpolation routine's cycle, ns): both
    /// non-zero, master an integer multiple of control, N ≤ [`MAX_RATIO`].
    pub fn new(master_ns: u32, control_ns: u32) -> Result<Self, CycleError> {
        if master_ns == 0 || control_ns == 0 {
            return Err(CycleError::Zero);
        }
        if master_ns % control_ns != 0 {
            return Err(CycleError::NotIntegerMultiple);
        }
        let n = master_ns / control_ns;
        if n > MAX_RATIO {
            return Err(CycleError::RatioTooLarge);
        }
        Ok(Self {
            master_ns,
            control_ns,
            n,
        })
    }

    /// Master cycle A291 in ns.
    pub const fn master_ns(&self) -> u32 {
        self.master_ns
    }

    /// Control (interpolation) cycle in ns.
    pub const fn control_ns(&self) -> u32 {
        self.control_ns
    }

    /// N: control cycles per master cycle (≥ 1).
    pub const fn n(&self) -> u32 {
        self.n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn c114_cycle_ratio_must_be_integer() {
        assert_eq!(CycleRatio::new(1_000_000, 250_000).map(|r| r.n()), Ok(4));
        assert_eq!(CycleRatio::new(250_000, 250_000).map(|r| r.n()), Ok(1));
        assert_eq!(
            CycleRatio::new(1_000_000, 300_000),
            Err(CycleError::NotIntegerMultiple)
        );
        // Master faster than the control cycle is not a multiple either.
        assert_eq!(
            CycleRatio::new(125_000, 250_000),
            Err(CycleError::NotIntegerMultiple)
        );
        assert_eq!(CycleRatio::new(0, 250_000), Err(CycleError::Zero));
        assert_eq!(CycleRatio::new(1_000_000, 0), Err(CycleError::Zero));
        assert_eq!(
            CycleRatio::new(1_000_000_000, 1_000),
            Err(CycleError::RatioTooLarge)
        );
    }

    #[test]
    fn c114_interpolation_period_from_60c2() {
        assert_eq!(interpolation_period_ns(1, -3), Ok(1_000_000));
        assert_eq!(interpolation_period_ns(250, -6), Ok(250_000));
        assert_eq!(interpolation_period_ns(125, -6), Ok(125_000));
        assert_eq!(interpolation_period_ns(4, 0), Ok(4_000_000_000));
        assert_eq!(interpolation_period_ns(5, 0), Err(CycleError::PeriodOutOfRange));
        assert_eq!(interpolation_period_ns(200, -11), Ok(2));
        assert_eq!(interpolation_period_ns(1, -10), Err(CycleError::PeriodOutOfRange));
        assert_eq!(interpolation_period_ns(0, -3), Err(CycleError::Zero));
        assert_eq!(interpolation_period_ns(1, 127), Err(CycleError::PeriodOutOfRange));
        assert_eq!(
            interpolation_period_ns(1, -128),
            Err(CycleError::PeriodOutOfRange)
        );
    }

    #[test]
    fn c144_application_cycle_values() {
        for ns in APPLICATION_CYCLES_NS {
            assert_eq!(application_cycle_ns(ns), Ok(ns));
        }
        assert_eq!(
            application_cycle_ns(125_000),
            Err(CycleError::NotAnApplicationCycle)
        );
        assert_eq!(
            application_cycle_ns(3_000_000),
            Err(CycleError::NotAnApplicationCycle)
        );
    }
}
