//! DC-Sync for the drive: a PLL that locks the local control-cycle timer to
//! the ESC's SYNC0, the checks that decide whether a DC configuration can be
//! run, the sync diagnostics and the DC-Sync optimisation measurement
//! (spec `ethercat.md` §11, §12, §13.4).
//!
//! - [`validate()`]: the stability conditions of §11.4 / §12 the slave stack
//!   checks at Pre-Op → Safe-Op (SYNC0 cycle = k × A150, ≤ 8 ms, cycles
//!   ≥ 250 µs on a 250 µs grid, SM2 = SM3 cycle) with the AL status code and
//!   the `A261[0]` code of each failure ([`SyncError`]).
//! - [`pll`]: [`Pll`], the phase-locked loop (A290 enable, A291 set cycle,
//!   A292 phase offset, A296 measured cycle, A298 status, A149 cycle
//!   sequence) with frequency acquisition, coarse phase alignment, a PI loop
//!   with anti-windup, lock detection and loss of lock; the late-frame
//!   statistics of A261.
//! - [`status`]: [`PllStatus`] (A298 bits) and [`SyncDiagnostics`] (A261).
//! - [`optimize`]: [`Optimizer`], the A287 DC-Sync optimisation measurement
//!   (progress, result code, suggested A292 range).
//! - [`sim`]: a deterministic host model (DC time, drifting local
//!   oscillator, interrupt-latency and frame jitter from a seeded xorshift)
//!   that drives a [`Pll`] for the tests and the benchmark
//!   (`cargo run -p dcsync --release --example pll_bench`).
//!
//! # Time and units
//!
//! Every time is an integer number of nanoseconds and an argument: nothing
//! here reads a clock. Two time bases appear and the names say which:
//!
//! - *local* ns (`*_local_ns`): the firmware's free-running counter converted
//!   to ns at its nominal frequency. The local oscillator drifts against the
//!   DC clock by some ppm, so a local ns is not exactly a DC ns.
//! - *DC* ns: the ESC's distributed-clock time. Configuration values (A150,
//!   SYNC0 cycle, A292) are DC durations.
//!
//! Timestamps are `u64` (wrapping differences are taken, so a counter that
//! wraps is fine); signed durations are `i64`.
//!
//! # Sign of A292
//!
//! The spec (§11.3) says a *negative* A292 moves the start of processing to
//! after the SYNC0 edge, so the drive's aligned cycle starts at
//! `SYNC0 − A292`: positive A292 = start before SYNC0, negative = after. A292
//! is limited to one drive cycle: `|A292| < A150` (clamped).
#![no_std]
#![deny(missing_docs)]

pub mod optimize;
pub mod pll;
pub mod sim;
pub mod status;
pub mod validate;

pub use optimize::{FrameSample, OptimizeOutcome, OptimizeRequest, OptimizeResult, Optimizer};
pub use pll::{
    div_rem_u64, gcd, Config, CycleCommand, CycleSequence, FrameTiming, Pll, PllState, Step, SyncFault,
    Tuning,
};
pub use status::{DiagCode, PllStatus, SyncDiagnostics};
pub use validate::{recommended_sequence, validate, SyncError};

/// AL status codes this crate hands to the slave stack (the values of
/// `esc::AlStatusCode`; kept as `u16` so the crate has no dependencies).
pub mod al {
    /// 001Ah Synchronization error.
    pub const SYNC_ERROR: u16 = 0x001A;
    /// 002Dh No sync error (SYNC0 not received).
    pub const NO_SYNC: u16 = 0x002D;
    /// 0030h Invalid DC SYNC configuration.
    pub const INVALID_DC_SYNC_CONFIG: u16 = 0x0030;
    /// 0032h PLL error.
    pub const PLL_ERROR: u16 = 0x0032;
    /// 0033h DC sync IO error.
    pub const DC_SYNC_IO_ERROR: u16 = 0x0033;
    /// 0034h DC sync timeout error.
    pub const DC_SYNC_TIMEOUT: u16 = 0x0034;
    /// 0035h DC invalid sync cycle time.
    pub const DC_INVALID_CYCLE_TIME: u16 = 0x0035;
    /// 0036h DC SYNC0 cycle time.
    pub const DC_SYNC0_CYCLE_TIME: u16 = 0x0036;
}

/// Event 52 "Communication" cause for synchronisation errors (spec §13.4,
/// E-131; the table cell is merged with connection errors, uncertain).
pub const EVENT52_CAUSE_SYNC: u8 = 7;
