//! Board-independent parts of the RTIC application.
//!
//! The RTIC apps (`src/main.rs` for the reference board, `src/bin/qemu.rs` for
//! QEMU) only wire interrupts and priorities; what the tasks do lives here so
//! that both images run the same code.
#![no_std]
#![deny(unsafe_code)]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]

/// Number of SYNC0 cycles the boot self-test pends before it reports success.
pub const SELF_TEST_CYCLES: u32 = 3;

/// State shared between the SYNC0 task (highest priority) and the mailbox task
/// (lowest priority) through an RTIC resource lock.
#[derive(Debug, Default)]
pub struct SyncState {
    /// SYNC0 events handled since boot (wraps at 2^32).
    cycles: u32,
}

impl SyncState {
    /// A state with no SYNC0 event seen.
    pub const fn new() -> Self {
        Self { cycles: 0 }
    }

    /// Called by the SYNC0 task once per event; returns the new cycle count.
    pub fn on_sync0(&mut self) -> u32 {
        self.cycles = self.cycles.wrapping_add(1);
        self.cycles
    }

    /// Cycles handled so far, read by lower-priority tasks under the lock.
    pub fn cycles(&self) -> u32 {
        self.cycles
    }
}
