//! A298 PLL status word and A261 sync diagnostics (spec §11.6, §11.7).

/// A298 PLL status word.
///
/// Bits 0–5 are the spec's (§11.6, E-115). The spec does not say which of
/// bits 0–1 is which; here bit 0 = the PLL lengthens the local cycle (local
/// oscillator fast against DC time, or SYNC0 slower than set) and bit 1 =
/// it shortens it.
///
/// Bits 8–11 are this implementation's additions (the spec leaves them
/// unused): SYNC0 present, frequency locked, phase locked, error. A tool
/// that only knows bits 0–5 ignores them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PllStatus(pub u16);

impl PllStatus {
    /// Bit 0: the correction lengthens the cycle by ≥ 50 % of the control range.
    pub const ENGAGED_SLOWER: u16 = 1 << 0;
    /// Bit 1: the correction shortens the cycle by ≥ 50 % of the control range.
    pub const ENGAGED_FASTER: u16 = 1 << 1;
    /// Bit 2: a cycle of the task system is being stretched (coarse phase
    /// alignment after frequency lock or after a large phase jump).
    pub const CYCLE_EXTENDED: u16 = 1 << 2;
    /// Bit 3: maximum control range reached (correction saturated).
    pub const MAX_RANGE: u16 = 1 << 3;
    /// Bit 4: measured SYNC0 cycle (A296) larger than the set cycle (A291).
    pub const SYNC_CYCLE_TOO_LONG: u16 = 1 << 4;
    /// Bit 5: control/synchronisation deactivated (A290 ≠ 1).
    pub const DEACTIVATED: u16 = 1 << 5;
    /// Bit 8 (addition): SYNC0 pulses arrive (none missing beyond the limit).
    pub const SYNC0_PRESENT: u16 = 1 << 8;
    /// Bit 9 (addition): frequency acquired (local cycle period measured).
    pub const FREQUENCY_LOCKED: u16 = 1 << 9;
    /// Bit 10 (addition): phase locked (|phase error| below the lock
    /// threshold for the configured number of SYNC0 cycles).
    pub const PHASE_LOCKED: u16 = 1 << 10;
    /// Bit 11 (addition): a latched [`crate::SyncFault`] or an `A261[0]` code ≠ 0.
    pub const ERROR: u16 = 1 << 11;

    /// Whether all of `bits` are set.
    pub const fn contains(self, bits: u16) -> bool {
        self.0 & bits == bits
    }
}

/// `A261[0]` sync-diagnostics error code (§11.7, E-116).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[repr(u16)]
pub enum DiagCode {
    /// 0: no error.
    #[default]
    None = 0,
    /// 1: SM2 and SM3 cycle times differ.
    SmCycleMismatch = 1,
    /// 2: cycle time < 250 µs.
    CycleTooShort = 2,
    /// 3: cycle time not an integer multiple of 250 µs.
    CycleNotOnGrid = 3,
    /// 4: the PLL could not be started (SYNC0 period not measurable or
    /// outside the control range, or a configuration [`crate::validate()`]
    /// refuses without a code of its own).
    PllStartFailed = 4,
    /// 6: drive interrupt not initialised (firmware error; the firmware
    /// reports it with [`crate::Pll::report_interrupt_not_initialised`]).
    InterruptNotInitialised = 6,
}

/// A261 sync diagnostics (§11.7, E-116..E-118).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SyncDiagnostics {
    /// `[0]` error code.
    pub code: DiagCode,
    /// `[1]` time between data provision (the master's process data reported
    /// with [`crate::Pll::on_frame`]) and SYNC0, µs, rounded towards zero:
    /// positive = data before SYNC0, negative = after. 0 before any frame.
    pub data_to_sync0_us: i32,
    /// `[2]` late-frame counter: frames after SYNC0 or more than A150/2
    /// before it (saturating).
    pub late_frames: u32,
    /// `[3]` (the spec names it but does not describe it; this
    /// implementation's choice) the last measured phase error, ns,
    /// saturated to `i32`: positive = local cycle late.
    pub phase_error_ns: i32,
}

impl SyncDiagnostics {
    /// The four elements as the object shows them (`A261[0..3]`).
    pub fn elements(&self) -> [i32; 4] {
        [
            self.code as u16 as i32,
            self.data_to_sync0_us,
            i32::try_from(self.late_frames).unwrap_or(i32::MAX),
            self.phase_error_ns,
        ]
    }
}
