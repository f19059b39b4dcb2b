//! The EtherCAT slave controller (ESC) as the slave firmware sees it.
//!
//! - [`regs`]: the register map (ET1100 / LAN9252 / XMC4800 ECAT0 share it), one
//!   constant per register, addresses as in the ETG.1000.4 / ESC datasheets.
//! - [`al`], [`sm`], [`fmmu`], [`sii`]: typed views of the register groups.
//!   Each view parses from a byte slice of the register's length with
//!   `parse`/`from_bytes` (checked: a short slice is an error, never a panic)
//!   and writes back with `emit`/`to_bytes`.
//! - [`Pdi`]: the process data interface, the only way slave code reaches the
//!   ESC: SPI ESC, memory-mapped on-chip ESC or `hil-sim`'s simulated ESC.
#![no_std]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]
#![deny(missing_docs)]

pub mod al;
pub mod fmmu;
pub mod pdi;
pub mod regs;
pub mod sii;
pub mod sm;

pub use al::{AlControl, AlState, AlStatus, AlStatusCode};
pub use fmmu::Fmmu;
pub use pdi::{Pdi, PdiExt};
pub use sm::{SmControl, SmDirection, SmMode, SyncManager};

/// A byte slice was shorter than the register block it should hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Truncated;

/// Reads a little-endian `u16` at `off`, or `Truncated`.
pub(crate) fn le_u16(b: &[u8], off: usize) -> Result<u16, Truncated> {
    match b.get(off..off + 2) {
        Some(&[lo, hi]) => Ok(u16::from_le_bytes([lo, hi])),
        _ => Err(Truncated),
    }
}

/// Reads a little-endian `u32` at `off`, or `Truncated`.
pub(crate) fn le_u32(b: &[u8], off: usize) -> Result<u32, Truncated> {
    match b.get(off..off + 4) {
        Some(&[a, b1, c, d]) => Ok(u32::from_le_bytes([a, b1, c, d])),
        _ => Err(Truncated),
    }
}

/// Reads the byte at `off`, or `Truncated`.
pub(crate) fn byte(b: &[u8], off: usize) -> Result<u8, Truncated> {
    b.get(off).copied().ok_or(Truncated)
}
