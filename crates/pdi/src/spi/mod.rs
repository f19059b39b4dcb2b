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

/// [`Error::OutOfRange`] unless `len` bytes from `addr` stay inside the ESC
/// address space.
fn check_range<E>(addr: u16, len: usize) -> Result<(), Error<E>> {
    if crate::in_esc_space(addr, len) {
        Ok(())
    } else {
        Err(Error::OutOfRange { addr, len })
    }
}

/// Clocks the bytes of a mock's SPI `operations` through `exchange` (MOSI
/// in, MISO out; 0x00 sent while reading, missing bytes as 0x00).
#[cfg(test)]
fn clock_operations<P>(
    operations: &mut [embedded_hal::spi::Operation<'_, u8>],
    phase: &mut P,
    mut exchange: impl FnMut(&mut P, u8) -> u8,
) {
    use embedded_hal::spi::Operation;
    for op in operations.iter_mut() {
        match op {
            Operation::Read(buf) => {
                for b in buf.iter_mut() {
                    *b = exchange(phase, 0x00);
                }
            }
            Operation::Write(data) => {
                for b in data.iter() {
                    exchange(phase, *b);
                }
            }
            Operation::Transfer(rx, tx) => {
                for i in 0..rx.len().max(tx.len()) {
                    let miso = exchange(phase, tx.get(i).copied().unwrap_or(0));
                    if let Some(r) = rx.get_mut(i) {
                        *r = miso;
                    }
                }
            }
            Operation::TransferInPlace(buf) => {
                for b in buf.iter_mut() {
                    *b = exchange(phase, *b);
                }
            }
            Operation::DelayNs(_) => {}
        }
    }
}
