//! The DC configuration checks of spec §11.3, §11.4, §11.7 and §12, run by
//! the slave stack at Pre-Op → Safe-Op (spec §3.3).

use crate::al;
use crate::pll::CycleSequence;
use crate::status::DiagCode;

/// Shortest cycle (A150, SYNC0): 250 µs, in ns (§11.7 code 2, §12).
pub const MIN_CYCLE_NS: u32 = 250_000;
/// Grid every cycle must sit on: 250 µs, in ns (§11.7 code 3).
pub const CYCLE_GRID_NS: u32 = 250_000;
/// Longest SYNC0 (sync-unit) cycle: 8 ms, in ns (§11.3).
pub const MAX_SYNC0_CYCLE_NS: u32 = 8_000_000;
/// The drive cycle times A150 allows, in ns (§12, E-125).
pub const A150_VALUES_NS: [u32; 6] = [250_000, 500_000, 1_000_000, 2_000_000, 4_000_000, 8_000_000];

/// Why a DC configuration cannot run. Each maps onto an AL status code
/// ([`SyncError::al_status_code`]) and an `A261[0]` code
/// ([`SyncError::diag_code`]).
///
/// AL code choice (spec §3.3 leaves 0030h/0035h/0036h open, §22 item 2):
/// - 0030h *invalid DC SYNC configuration*: SYNC0 not active, SM2/SM3
///   cycle times differ, A150 not one of the allowed values (the
///   configuration as a whole does not fit);
/// - 0035h *DC invalid sync cycle time*: a cycle below 250 µs or off the
///   250 µs grid (the cycle time itself is invalid);
/// - 0036h *DC SYNC0 cycle time*: SYNC0 cycle not an integer multiple of
///   A150 or above 8 ms ("SYNC0 cycle time does not fit the application
///   requirements", the spec's own wording for that code).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SyncError {
    /// SYNC0 cycle 0: SYNC0 not active although DC-Sync is selected.
    Sync0Inactive,
    /// 1C32h:02 and 1C33h:02 differ (both non-zero), ns.
    SmCycleMismatch {
        /// SM2 (outputs) cycle, ns.
        sm2_ns: u32,
        /// SM3 (inputs) cycle, ns.
        sm3_ns: u32,
    },
    /// A cycle (A150, SYNC0 or SM2) below 250 µs, ns.
    CycleTooShort {
        /// The offending cycle, ns.
        cycle_ns: u32,
    },
    /// A cycle not an integer multiple of 250 µs, ns.
    CycleNotOnGrid {
        /// The offending cycle, ns.
        cycle_ns: u32,
    },
    /// A150 is on the grid but not one of [`A150_VALUES_NS`].
    UnsupportedDriveCycle {
        /// A150, ns.
        a150_ns: u32,
    },
    /// SYNC0 cycle not an integer multiple of A150.
    Sync0NotMultipleOfA150 {
        /// SYNC0 cycle, ns.
        sync0_ns: u32,
        /// A150, ns.
        a150_ns: u32,
    },
    /// SYNC0 cycle above 8 ms.
    Sync0CycleTooLong {
        /// SYNC0 cycle, ns.
        sync0_ns: u32,
    },
}

impl SyncError {
    /// AL status code (0x0134) to refuse Pre-Op → Safe-Op with.
    pub const fn al_status_code(&self) -> u16 {
        match self {
            Self::Sync0Inactive | Self::SmCycleMismatch { .. } | Self::UnsupportedDriveCycle { .. } => {
                al::INVALID_DC_SYNC_CONFIG
            }
            Self::CycleTooShort { .. } | Self::CycleNotOnGrid { .. } => al::DC_INVALID_CYCLE_TIME,
            Self::Sync0NotMultipleOfA150 { .. } | Self::Sync0CycleTooLong { .. } => al::DC_SYNC0_CYCLE_TIME,
        }
    }

    /// `A261[0]` sync-diagnostics code (§11.7). Failures the spec gives no
    /// code for (SYNC0 inactive, not a multiple of A150, too long, A150 not
    /// allowed) report 4 "PLL could not be started": that is what follows.
    pub const fn diag_code(&self) -> DiagCode {
        match self {
            Self::SmCycleMismatch { .. } => DiagCode::SmCycleMismatch,
            Self::CycleTooShort { .. } => DiagCode::CycleTooShort,
            Self::CycleNotOnGrid { .. } => DiagCode::CycleNotOnGrid,
            Self::Sync0Inactive
            | Self::UnsupportedDriveCycle { .. }
            | Self::Sync0NotMultipleOfA150 { .. }
            | Self::Sync0CycleTooLong { .. } => DiagCode::PllStartFailed,
        }
    }
}

fn check_cycle(cycle_ns: u32) -> Result<(), SyncError> {
    if cycle_ns < MIN_CYCLE_NS {
        Err(SyncError::CycleTooShort { cycle_ns })
    } else if cycle_ns % CYCLE_GRID_NS != 0 {
        Err(SyncError::CycleNotOnGrid { cycle_ns })
    } else {
        Ok(())
    }
}

/// Checks a DC-Sync configuration (spec §11.3, §11.4, §11.7, §12) and
/// returns k = SYNC0 cycle / A150, the number of drive cycles per SYNC0
/// cycle (E-112).
///
/// - `sync0_cycle_ns`: SYNC0 cycle the master programmed (ESC 0x09A0), DC ns;
/// - `a150_ns`: drive cycle A150, ns;
/// - `sm2_cycle_ns`, `sm3_cycle_ns`: 1C32h:02 / 1C33h:02, ns; 0 = not
///   written by the master (then not checked).
///
/// Order of the checks: SYNC0 active, SM2 = SM3, each cycle ≥ 250 µs and on
/// the 250 µs grid (A150, SYNC0, SM2), A150 an allowed value, SYNC0 = k ×
/// A150, SYNC0 ≤ 8 ms.
pub fn validate(
    sync0_cycle_ns: u32,
    a150_ns: u32,
    sm2_cycle_ns: u32,
    sm3_cycle_ns: u32,
) -> Result<u32, SyncError> {
    if sync0_cycle_ns == 0 {
        return Err(SyncError::Sync0Inactive);
    }
    if sm2_cycle_ns != 0 && sm3_cycle_ns != 0 && sm2_cycle_ns != sm3_cycle_ns {
        return Err(SyncError::SmCycleMismatch {
            sm2_ns: sm2_cycle_ns,
            sm3_ns: sm3_cycle_ns,
        });
    }
    check_cycle(a150_ns)?;
    check_cycle(sync0_cycle_ns)?;
    if sm2_cycle_ns != 0 {
        check_cycle(sm2_cycle_ns)?;
    }
    if !A150_VALUES_NS.contains(&a150_ns) {
        return Err(SyncError::UnsupportedDriveCycle { a150_ns });
    }
    // a150_ns ≥ 250 µs here, so the division is defined.
    if sync0_cycle_ns % a150_ns != 0 {
        return Err(SyncError::Sync0NotMultipleOfA150 {
            sync0_ns: sync0_cycle_ns,
            a150_ns,
        });
    }
    if sync0_cycle_ns > MAX_SYNC0_CYCLE_NS {
        return Err(SyncError::Sync0CycleTooLong {
            sync0_ns: sync0_cycle_ns,
        });
    }
    Ok(sync0_cycle_ns / a150_ns)
}

/// The cycle sequence A149 the spec recommends for a drive cycle (§11.5,
/// §12): Rx → Tx → application below 1 ms, Rx → application → Tx otherwise.
pub const fn recommended_sequence(a150_ns: u32) -> CycleSequence {
    if a150_ns < 1_000_000 {
        CycleSequence::RxTxApp
    } else {
        CycleSequence::RxAppTx
    }
}
