//! Option codes 605Ah..605Eh (spec §5.5) and how hard a stop decelerates.
//!
//! Every option code converts from its object's INT16 value with `TryFrom<i16>`; a value
//! the spec does not list is an [`OptionCodeError`] (the OD layer answers it with SDO abort
//! 0609 0030h "value range exceeded"). `code()` gives the object value back.

/// How the motion core brings the axis to standstill. "Coast" (disable the drive function
/// at once) is not a deceleration: it shows as the power stage going off.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Decel {
    /// The slow-down ramp: the mode's profile deceleration (e.g. 6084h; vl: 6049h).
    SlowDown,
    /// The quick-stop ramp: 6085h (A578); vl: 604Ah (A525).
    QuickStop,
    /// Brake at the current limit.
    CurrentLimit,
    /// Brake at the voltage limit.
    VoltageLimit,
}

/// A value the option-code object does not accept.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct OptionCodeError(pub i16);

/// 605Ah quick stop option code (A536), `[std]` values 0..8.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum QuickStopOption {
    /// 0: disable the drive function (coast), then Switch on disabled.
    Coast,
    /// 1..4: stop with the deceleration, then Switch on disabled (transition 12).
    ThenDisable(Decel),
    /// 5..8: stop with the deceleration and stay in Quick stop active (holding) until
    /// Disable voltage, a switch-on-disabled cause or a loss of A60; never back to
    /// Operation enabled (no transition 16).
    ThenHold(Decel),
}

const fn decel_from(n: i16) -> Option<Decel> {
    match n {
        1 => Some(Decel::SlowDown),
        2 => Some(Decel::QuickStop),
        3 => Some(Decel::CurrentLimit),
        4 => Some(Decel::VoltageLimit),
        _ => None,
    }
}

const fn decel_code(d: Decel) -> i16 {
    match d {
        Decel::SlowDown => 1,
        Decel::QuickStop => 2,
        Decel::CurrentLimit => 3,
        Decel::VoltageLimit => 4,
    }
}

impl QuickStopOption {
    /// The `[std]` default: 2, quick-stop ramp then Switch on disabled.
    pub const DEFAULT: Self = QuickStopOption::ThenDisable(Decel::QuickStop);

    /// The object value.
    pub const fn code(self) -> i16 {
        match self {
            QuickStopOption::Coast => 0,
            QuickStopOption::ThenDisable(d) => decel_code(d),
            QuickStopOption::ThenHold(d) => decel_code(d) + 4,
        }
    }
}

impl TryFrom<i16> for QuickStopOption {
    type Error = OptionCodeError;
    fn try_from(v: i16) -> Result<Self, OptionCodeError> {
        if v == 0 {
            return Ok(QuickStopOption::Coast);
        }
        if let Some(d) = decel_from(v) {
            return Ok(QuickStopOption::ThenDisable(d));
        }
        match decel_from(v.wrapping_sub(4)) {
            Some(d) if v > 4 => Ok(QuickStopOption::ThenHold(d)),
            _ => Err(OptionCodeError(v)),
        }
    }
}

/// 605Bh shutdown option code and 605Ch disable operation option code, `[std]` values 0, 1.
/// The SC6 manual does not support either object; the default is 0, i.e. the drive
/// function goes off at once, which is what the manual describes for T5 and T8.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum DisableOption {
    /// 0: disable the drive function at once (coast).
    #[default]
    Coast,
    /// 1: slow-down ramp to standstill, then disable the drive function.
    SlowDown,
}

impl DisableOption {
    /// The object value.
    pub const fn code(self) -> i16 {
        match self {
            DisableOption::Coast => 0,
            DisableOption::SlowDown => 1,
        }
    }
}

impl TryFrom<i16> for DisableOption {
    type Error = OptionCodeError;
    fn try_from(v: i16) -> Result<Self, OptionCodeError> {
        match v {
            0 => Ok(DisableOption::Coast),
            1 => Ok(DisableOption::SlowDown),
            _ => Err(OptionCodeError(v)),
        }
    }
}

/// 605Dh halt option code, `[std]` values 1..4 (not supported by the SC6 manual).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct HaltOption(pub Decel);

impl HaltOption {
    /// The `[std]` default: 1, slow-down ramp.
    pub const DEFAULT: Self = HaltOption(Decel::SlowDown);

    /// The object value.
    pub const fn code(self) -> i16 {
        decel_code(self.0)
    }
}

impl TryFrom<i16> for HaltOption {
    type Error = OptionCodeError;
    fn try_from(v: i16) -> Result<Self, OptionCodeError> {
        decel_from(v).map(HaltOption).ok_or(OptionCodeError(v))
    }
}

/// 605Eh fault reaction option code (A540), `[std]` values 0..4; also the reaction a
/// single fault event may demand (spec: "depends on the individual fault event").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FaultReaction {
    /// 0: disable the drive function at once (coast), brake engages.
    Coast,
    /// 1..4: stop with the deceleration, then disable.
    Stop(Decel),
}

impl FaultReaction {
    /// The `[std]` default: 2, quick-stop ramp.
    pub const DEFAULT: Self = FaultReaction::Stop(Decel::QuickStop);

    /// The object value.
    pub const fn code(self) -> i16 {
        match self {
            FaultReaction::Coast => 0,
            FaultReaction::Stop(d) => decel_code(d),
        }
    }
}

impl TryFrom<i16> for FaultReaction {
    type Error = OptionCodeError;
    fn try_from(v: i16) -> Result<Self, OptionCodeError> {
        if v == 0 {
            return Ok(FaultReaction::Coast);
        }
        decel_from(v).map(FaultReaction::Stop).ok_or(OptionCodeError(v))
    }
}
