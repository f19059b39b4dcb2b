//! The process data interface: how slave code reaches the ESC.

use crate::regs;

/// Byte access to the ESC's address space from the application processor.
///
/// Implementations: an SPI ESC (LAN9252/ET1100 over `embedded_hal::spi::SpiDevice`),
/// the memory-mapped on-chip ESC of the reference MCU, and `hil-sim`'s simulated
/// ESC. Side effects are the ESC's: reading the last byte of a SyncManager
/// buffer releases it, writing the last byte of a mailbox hands it to ECAT,
/// reading AL control clears its event bit. Slave code therefore accesses
/// buffers whole and in one call.
pub trait Pdi {
    /// Transport error (SPI bus error, ...). The simulated ESC never fails.
    type Error: core::fmt::Debug;

    /// Reads `buf.len()` bytes starting at `addr`.
    fn read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Self::Error>;

    /// Writes `data` starting at `addr`.
    fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), Self::Error>;

    /// The AL event request register (0x0220). SPI ESCs return it with every
    /// command header; the default reads the register.
    fn al_event(&mut self) -> Result<u32, Self::Error> {
        let mut b = [0u8; 4];
        self.read(regs::AL_EVENT_REQUEST, &mut b)?;
        Ok(u32::from_le_bytes(b))
    }
}

/// Typed helpers over any [`Pdi`].
pub trait PdiExt: Pdi {
    /// Reads a byte.
    fn read_u8(&mut self, addr: u16) -> Result<u8, Self::Error> {
        let mut b = [0u8; 1];
        self.read(addr, &mut b)?;
        Ok(b[0])
    }

    /// Reads a little-endian `u16`.
    fn read_u16(&mut self, addr: u16) -> Result<u16, Self::Error> {
        let mut b = [0u8; 2];
        self.read(addr, &mut b)?;
        Ok(u16::from_le_bytes(b))
    }

    /// Reads a little-endian `u32`.
    fn read_u32(&mut self, addr: u16) -> Result<u32, Self::Error> {
        let mut b = [0u8; 4];
        self.read(addr, &mut b)?;
        Ok(u32::from_le_bytes(b))
    }

    /// Writes a byte.
    fn write_u8(&mut self, addr: u16, v: u8) -> Result<(), Self::Error> {
        self.write(addr, &[v])
    }

    /// Writes a little-endian `u16`.
    fn write_u16(&mut self, addr: u16, v: u16) -> Result<(), Self::Error> {
        self.write(addr, &v.to_le_bytes())
    }

    /// Writes a little-endian `u32`.
    fn write_u32(&mut self, addr: u16, v: u32) -> Result<(), Self::Error> {
        self.write(addr, &v.to_le_bytes())
    }

    /// Reads SyncManager `n`'s register block.
    fn read_sm(&mut self, n: u8) -> Result<crate::SyncManager, Self::Error> {
        let mut b = [0u8; 8];
        self.read(regs::sm(n), &mut b)?;
        // An 8-byte buffer always parses.
        Ok(crate::SyncManager::parse(&b).unwrap_or_default())
    }
}

impl<P: Pdi + ?Sized> PdiExt for P {}

impl<P: Pdi + ?Sized> Pdi for &mut P {
    type Error = P::Error;
    fn read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Self::Error> {
        (**self).read(addr, buf)
    }
    fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), Self::Error> {
        (**self).write(addr, data)
    }
    fn al_event(&mut self) -> Result<u32, Self::Error> {
        (**self).al_event()
    }
}
