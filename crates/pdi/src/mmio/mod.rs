//! The memory-mapped on-chip ESC.
//!
//! [`OnChip`] holds the `Pdi` logic (range checks, splitting into naturally
//! aligned 8/16/32-bit accesses, the 32-bit AL event read); a
//! [`RegisterWindow`] does the accesses. On the target the window is a
//! [`VolatileWindow`] over the ESC's bus address range; on the host the tests
//! use a RAM-backed window that records every access.

mod volatile;

pub use volatile::VolatileWindow;

/// Base address of the XMC4800's on-chip ESC (ECAT0) in the MCU's address map.
pub const XMC4800_ECAT0_BASE: usize = 0x5401_0000;
/// Bytes of ESC address space the XMC4800 maps: registers (0x0000..0x0FFF)
/// and 8 KiB process RAM (0x1000..0x2FFF).
pub const XMC4800_ECAT0_LEN: usize = 0x3000;

/// Width of one bus access.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Width {
    /// 8 bits.
    U8,
    /// 16 bits (offset 2-aligned).
    U16,
    /// 32 bits (offset 4-aligned).
    U32,
}

impl Width {
    /// Bytes per access.
    pub const fn bytes(self) -> usize {
        match self {
            Width::U8 => 1,
            Width::U16 => 2,
            Width::U32 => 4,
        }
    }
}

/// The window lacks the offset, or the offset is not aligned to the width.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BadAccess {
    /// Offset in the window.
    pub offset: usize,
    /// Requested width.
    pub width: Width,
}

/// Byte-addressed access to a window of the ESC's address space: offset 0 is
/// ESC address 0. Values are little-endian (the ESC's and Cortex-M's order).
/// An implementation refuses accesses outside the window or not aligned to
/// their width.
pub trait RegisterWindow {
    /// Window length in bytes.
    fn len(&self) -> usize;

    /// `true` if the window has no bytes.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Reads `width` bytes at `offset` (zero-extended).
    fn read(&mut self, offset: usize, width: Width) -> Result<u32, BadAccess>;

    /// Writes the low `width` bytes of `value` at `offset`.
    fn write(&mut self, offset: usize, width: Width, value: u32) -> Result<(), BadAccess>;
}

/// Error of [`OnChip`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Error {
    /// The access does not fit the window.
    OutOfRange {
        /// Start address.
        addr: u16,
        /// Length in bytes.
        len: usize,
    },
    /// The window refused an access (a window smaller than it claims).
    Window(BadAccess),
}

impl From<BadAccess> for Error {
    fn from(e: BadAccess) -> Self {
        Error::Window(e)
    }
}

/// The widest naturally aligned access at `offset` for `remaining` bytes.
fn access_width(offset: usize, remaining: usize) -> Width {
    if offset % 4 == 0 && remaining >= 4 {
        Width::U32
    } else if offset % 2 == 0 && remaining >= 2 {
        Width::U16
    } else {
        Width::U8
    }
}

/// A memory-mapped ESC as an [`esc::Pdi`].
///
/// Every access is split into naturally aligned accesses, widest first: a
/// 4-byte read at a 4-aligned address is one 32-bit bus read, so a 16- or
/// 32-bit register is never torn into bytes when it is read whole. The
/// ESC-side effects (SyncManager buffer handover on its first/last byte, AL
/// control acknowledge) happen as the bytes are accessed in ascending order.
#[derive(Debug)]
pub struct OnChip<W> {
    window: W,
}

impl<W: RegisterWindow> OnChip<W> {
    /// A PDI over `window`.
    pub fn new(window: W) -> Self {
        Self { window }
    }

    /// The window.
    pub fn window(&self) -> &W {
        &self.window
    }

    /// Gives the window back.
    pub fn release(self) -> W {
        self.window
    }

    fn check(&self, addr: u16, len: usize) -> Result<usize, Error> {
        let start = usize::from(addr);
        match start.checked_add(len) {
            Some(end) if end <= self.window.len() => Ok(start),
            _ => Err(Error::OutOfRange { addr, len }),
        }
    }
}

impl<W: RegisterWindow> esc::Pdi for OnChip<W> {
    type Error = Error;

    fn read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Error> {
        let mut offset = self.check(addr, buf.len())?;
        let mut rest = buf;
        while !rest.is_empty() {
            let width = access_width(offset, rest.len());
            let value = self.window.read(offset, width)?.to_le_bytes();
            let (chunk, tail) = rest.split_at_mut_checked(width.bytes()).unwrap_or_default();
            for (d, s) in chunk.iter_mut().zip(value) {
                *d = s;
            }
            rest = tail;
            offset += width.bytes();
        }
        Ok(())
    }

    fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), Error> {
        let mut offset = self.check(addr, data.len())?;
        let mut rest = data;
        while !rest.is_empty() {
            let width = access_width(offset, rest.len());
            let (chunk, tail) = rest.split_at_checked(width.bytes()).unwrap_or_default();
            let mut value = [0u8; 4];
            for (d, s) in value.iter_mut().zip(chunk) {
                *d = *s;
            }
            self.window.write(offset, width, u32::from_le_bytes(value))?;
            rest = tail;
            offset += width.bytes();
        }
        Ok(())
    }

    /// One 32-bit read of 0x0220.
    fn al_event(&mut self) -> Result<u32, Error> {
        let offset = self.check(esc::regs::AL_EVENT_REQUEST, 4)?;
        Ok(self.window.read(offset, Width::U32)?)
    }
}

#[cfg(test)]
mod tests;
