//! SPI ESCs over [`embedded_hal::spi::SpiDevice`].
//!
//! The `SpiDevice` owns chip select: one [`SpiDevice::transaction`] is one
//! chip-select-low frame, which is what both chips use to delimit a command.
//! See the crate documentation for the two protocols.
//!
//! [`SpiDevice`]: embedded_hal::spi::SpiDevice
//! [`SpiDevice::transaction`]: embedded_hal::spi::SpiDevice::transaction

mod et1100;
mod lan9252;

pub use et1100::Et1100;
pub use lan9252::{regs as lan9252_regs, Config, Lan9252, ReadCommand};

#[cfg(test)]
mod mock_et1100;
#[cfg(test)]
mod mock_lan9252;
#[cfg(test)]
mod tests;

/// Error of an SPI PDI driver.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Error<E> {
    /// The SPI bus (or chip select) failed.
    Spi(E),
    /// A busy bit did not clear (or data/space did not become available)
    /// within the configured number of polls of `register` (an address in the
    /// SPI chip's own register space, e.g. 0x0304 `ECAT_CSR_CMD`).
    Timeout {
        /// The register that was polled.
        register: u16,
    },
    /// The access does not fit in the 64 KiB ESC address space.
    OutOfRange {
        /// Start address.
        addr: u16,
        /// Length in bytes.
        len: usize,
    },
    /// The chip did not report ready (LAN9252: `BYTE_TEST` != 0x8765_4321 or
    /// `HW_CFG.READY` clear) within the configured number of polls.
    NotReady {
        /// The last `BYTE_TEST` value read.
        byte_test: u32,
    },
}
