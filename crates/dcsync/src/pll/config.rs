//! What the PLL is built from and hands out: its configuration and tuning,
//! the A149 cycle sequence, the cycle command of each control cycle, the
//! frame timing it measures, its state and faults.

use super::*;

/// Cycle sequence A149 (spec §11.5, E-111).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CycleSequence {
    /// A149 = 0: RxPDO → application → TxPDO (default).
    #[default]
    RxAppTx,
    /// A149 = 1: RxPDO → TxPDO → application (recommended below 1 ms).
    RxTxApp,
}

impl CycleSequence {
    /// From the A149 value; `None` for values the spec does not define.
    pub const fn from_a149(value: u8) -> Option<Self> {
        match value {
            0 => Some(Self::RxAppTx),
            1 => Some(Self::RxTxApp),
            _ => None,
        }
    }

    /// The A149 value.
    pub const fn a149(self) -> u8 {
        match self {
            Self::RxAppTx => 0,
            Self::RxTxApp => 1,
        }
    }

    /// The three steps in execution order.
    pub const fn order(self) -> [Step; 3] {
        match self {
            Self::RxAppTx => [Step::ReadOutputs, Step::Application, Step::WriteInputs],
            Self::RxTxApp => [Step::ReadOutputs, Step::WriteInputs, Step::Application],
        }
    }
}

/// One step of a drive cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// Rx: read the master's outputs (RxPDO, SM2) from the ESC.
    ReadOutputs,
    /// The application (control, motion).
    Application,
    /// Tx: write the inputs (TxPDO, SM3) into the ESC.
    WriteInputs,
}

/// Loop parameters. Defaults: [`Tuning::DEFAULT`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Tuning {
    /// Proportional gain, Q16 (65536 = 1: a phase error of e ns corrects
    /// the next SYNC0 cycle by e ns).
    pub kp_q16: i32,
    /// Integral gain, Q16, per SYNC0 cycle.
    pub ki_q16: i32,
    /// Control range: the largest correction, ppm of the SYNC0 cycle
    /// (covers the local oscillator's drift; A298 bits 0–1 at 50 %, bit 3
    /// at 100 %).
    pub range_ppm: u32,
    /// SYNC0 intervals measured for frequency acquisition.
    pub freq_window: u16,
    /// |phase error| counted towards lock, ns.
    pub lock_threshold_ns: u32,
    /// Consecutive SYNC0 cycles within `lock_threshold_ns` for phase lock.
    pub lock_cycles: u16,
    /// |phase error| that loses the lock, ns.
    pub unlock_threshold_ns: u32,
    /// |phase error| beyond which the phase is re-aligned in one step
    /// instead of pulled in by the PI loop, ns.
    pub realign_threshold_ns: u32,
    /// Consecutive missing SYNC0 pulses that lose SYNC0 (and the lock).
    pub missing_limit: u16,
    /// Consecutive late frames that raise [`SyncFault::SyncIo`].
    pub late_frame_limit: u16,
    /// Also count a frame as late when it arrives more than A150/2 before
    /// SYNC0 (the spec's TwinCAT wording, E-118). For k = 1 this is the same
    /// as "after the previous SYNC0", so it only matters for k > 1.
    pub late_half_cycle_rule: bool,
}

impl Tuning {
    /// Kp 1/4, Ki 1/32, ±500 ppm, 16-interval acquisition, lock at ≤ 500 ns
    /// for 16 cycles, unlock above 5 µs, re-align above 50 µs, 3 missing
    /// SYNC0, 5 late frames, A150/2 rule on.
    pub const DEFAULT: Self = Self {
        kp_q16: 16384,
        ki_q16: 2048,
        range_ppm: 500,
        freq_window: 16,
        lock_threshold_ns: 500,
        lock_cycles: 16,
        unlock_threshold_ns: 5_000,
        realign_threshold_ns: 50_000,
        missing_limit: 3,
        late_frame_limit: 5,
        late_half_cycle_rule: true,
    };
}

impl Default for Tuning {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// PLL configuration: the A29x parameters plus the timer seam.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Config {
    /// Set SYNC0 cycle (A291, 1C32h:02 in DC mode), DC ns.
    pub sync0_cycle_ns: u32,
    /// Drive cycle A150, DC ns.
    pub a150_ns: u32,
    /// Phase offset A292, DC ns: the aligned cycle starts at SYNC0 − A292
    /// (negative = after SYNC0). Clamped to |A292| < A150.
    pub a292_ns: i32,
    /// Cycle sequence A149.
    pub sequence: CycleSequence,
    /// A290 = 1 (Active). When false the timer runs at the nominal A150 and
    /// A298 bit 5 is set.
    pub enabled: bool,
    /// Tick frequency of the local cycle timer, Hz (≥ 1).
    pub timer_hz: u32,
    /// Constant latency between the SYNC0 edge and the timestamp passed to
    /// [`Pll::on_sync0`], local ns (subtracted; 0 for a hardware capture).
    pub sync0_latency_ns: u32,
    /// Loop parameters.
    pub tuning: Tuning,
}

impl Config {
    /// Enabled PLL, A292 = 0, A149 = 0, no latency, default tuning.
    pub const fn new(sync0_cycle_ns: u32, a150_ns: u32, timer_hz: u32) -> Self {
        Self {
            sync0_cycle_ns,
            a150_ns,
            a292_ns: 0,
            sequence: CycleSequence::RxAppTx,
            enabled: true,
            timer_hz,
            sync0_latency_ns: 0,
            tuning: Tuning::DEFAULT,
        }
    }
}

/// Where the PLL is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PllState {
    /// A290 ≠ 1: nominal period, no control.
    Disabled,
    /// Measuring the SYNC0 cycle (waiting for SYNC0 if none arrives).
    Acquiring,
    /// Frequency known; the next aligned cycle removes the phase error.
    Aligning,
    /// PI loop running (phase locked or pulling in).
    Tracking,
}

/// A synchronisation fault for the slave stack (AL status code) and the
/// drive (event 52 cause 7).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SyncFault {
    /// No SYNC0 received (AL 002Dh).
    NoSync0,
    /// SYNC0 received but the PLL is not locked / lost the lock (AL 0032h).
    PllError,
    /// Too many SYNC0 pulses missing (AL 0034h).
    Sync0Timeout,
    /// Repeated late frames: process data not synchronous (AL 0033h).
    SyncIo,
}

impl SyncFault {
    /// AL status code (0x0134).
    pub const fn al_status_code(self) -> u16 {
        match self {
            Self::NoSync0 => al::NO_SYNC,
            Self::PllError => al::PLL_ERROR,
            Self::Sync0Timeout => al::DC_SYNC_TIMEOUT,
            Self::SyncIo => al::DC_SYNC_IO_ERROR,
        }
    }

    /// Event 52 cause (7, spec §13.4).
    pub const fn event52_cause(self) -> u8 {
        crate::EVENT52_CAUSE_SYNC
    }
}

/// What [`Pll::on_cycle_start`] tells the firmware about the cycle that has
/// just started.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CycleCommand {
    /// Length of this cycle in timer ticks: the next cycle starts at
    /// `start + period_ticks`.
    pub period_ticks: u32,
    /// The same length in local ns (rounded down).
    pub period_local_ns: u32,
    /// Position in the SYNC0 cycle, 0..k; 0 = the aligned cycle.
    pub index: u32,
    /// Read the outputs (RxPDO) in this cycle (the aligned cycle).
    pub rx: bool,
    /// Write the inputs (TxPDO) in this cycle (the aligned cycle).
    pub tx: bool,
    /// The A149 order of the steps.
    pub sequence: CycleSequence,
}

impl CycleCommand {
    /// This cycle's steps in order (Rx/Tx only in the aligned cycle).
    pub fn steps(&self) -> [Option<Step>; 3] {
        self.sequence.order().map(|s| match s {
            Step::ReadOutputs if !self.rx => None,
            Step::WriteInputs if !self.tx => None,
            s => Some(s),
        })
    }
}

/// Timing of one frame against SYNC0 ([`Pll::on_frame`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameTiming {
    /// Arrival relative to the nearest SYNC0 edge, local ns: negative =
    /// before SYNC0.
    pub rel_sync0_ns: i64,
    /// Counted as late (`A261[2]`).
    pub late: bool,
}
