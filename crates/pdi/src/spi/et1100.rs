//! ET1100-class SPI ESC: direct ESC addressing, AL event in every header.

use embedded_hal::spi::{Operation, SpiDevice};

use super::Error;

/// Command: no operation (used to fetch the AL event request alone).
pub(crate) const CMD_NOP: u8 = 0b000;
/// Command: read (data follows the address phase without a wait state).
#[cfg(test)]
pub(crate) const CMD_READ: u8 = 0b010;
/// Command: read with one wait state byte after the address phase.
pub(crate) const CMD_READ_WAIT_STATE: u8 = 0b011;
/// Command: write.
pub(crate) const CMD_WRITE: u8 = 0b100;
/// Command in byte 1: a third address/command byte follows.
pub(crate) const CMD_ADDRESS_EXTENSION: u8 = 0b110;
/// Wait state byte the master sends after the address phase of a read.
pub(crate) const WAIT_STATE: u8 = 0xFF;
/// The master sends this on MOSI during the last byte of a read.
pub(crate) const READ_TERMINATION: u8 = 0xFF;

/// The 3-byte address/command phase for `addr` and `cmd`.
pub(crate) fn header(addr: u16, cmd: u8) -> [u8; 3] {
    let [hi, lo] = addr.to_be_bytes();
    [
        // A[12:5]
        (hi << 3) | (lo >> 5),
        // A[4:0], address extension
        ((lo & 0x1F) << 3) | CMD_ADDRESS_EXTENSION,
        // A[15:13], command, two reserved zero bits
        ((hi >> 5) << 5) | ((cmd & 0b111) << 2),
    ]
}

/// An ET1100-class SPI ESC (see the crate documentation for the protocol).
///
/// The SPI mode is the ESC's configuration (PDI control / SPI configuration
/// in the SII EEPROM, 0x0140/0x0150); the driver does not depend on it.
#[derive(Debug)]
pub struct Et1100<D> {
    spi: D,
    last_al_event: u32,
}

impl<D: SpiDevice> Et1100<D> {
    /// A driver over `spi` (the device handles chip select).
    pub fn new(spi: D) -> Self {
        Self {
            spi,
            last_al_event: 0,
        }
    }

    /// The SPI device (tests inspect and steer the chip model).
    #[cfg(test)]
    pub(crate) fn spi_mut(&mut self) -> &mut D {
        &mut self.spi
    }

    /// Gives the SPI device back.
    pub fn release(self) -> D {
        self.spi
    }

    /// The AL event request (0x0220..0x0222) the ESC returned in the header
    /// of the most recent access, without a bus transfer; 0 before the first.
    pub fn last_al_event(&self) -> u32 {
        self.last_al_event
    }

    fn record_header(&mut self, rx: [u8; 3]) {
        let [a, b, c] = rx;
        self.last_al_event = u32::from_le_bytes([a, b, c, 0]);
    }
}

impl<D: SpiDevice> esc::Pdi for Et1100<D> {
    type Error = Error<D::Error>;

    fn read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Self::Error> {
        super::check_range(addr, buf.len())?;
        if buf.is_empty() {
            return Ok(());
        }
        // MOSI during the data phase: 0x00, and 0xFF on the last byte.
        buf.fill(0x00);
        if let Some(last) = buf.last_mut() {
            *last = READ_TERMINATION;
        }
        let tx = header(addr, CMD_READ_WAIT_STATE);
        let mut rx = [0u8; 3];
        self.spi
            .transaction(&mut [
                Operation::Transfer(&mut rx, &tx),
                Operation::Write(&[WAIT_STATE]),
                Operation::TransferInPlace(buf),
            ])
            .map_err(Error::Spi)?;
        self.record_header(rx);
        Ok(())
    }

    fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), Self::Error> {
        super::check_range(addr, data.len())?;
        if data.is_empty() {
            return Ok(());
        }
        let tx = header(addr, CMD_WRITE);
        let mut rx = [0u8; 3];
        self.spi
            .transaction(&mut [Operation::Transfer(&mut rx, &tx), Operation::Write(data)])
            .map_err(Error::Spi)?;
        self.record_header(rx);
        Ok(())
    }

    /// One 3-byte NOP: the ESC returns 0x0220..0x0222 during the header.
    fn al_event(&mut self) -> Result<u32, Self::Error> {
        let tx = header(0, CMD_NOP);
        let mut rx = [0u8; 3];
        self.spi
            .transaction(&mut [Operation::Transfer(&mut rx, &tx)])
            .map_err(Error::Spi)?;
        self.record_header(rx);
        Ok(self.last_al_event)
    }
}
