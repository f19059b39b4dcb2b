//! [`RamFlash`]: NOR flash in RAM with a power-cut injector.

use crate::{Flash, FlashError};

/// NOR flash of `SECTORS` sectors of `SECTOR` bytes in RAM, program unit 8 bytes.
///
/// Power-cut injector: after [`RamFlash::cut_after`]`(n)` the next `n` erase/write
/// operations complete; the one after that does half its job (a write programs only
/// the first half of its bytes, an erase sets only the first half of the sector to
/// FFh) and fails, and every later operation (reads too) fails with
/// [`FlashError::Device`] until [`RamFlash::power_on`]. The content stays as it was
/// at the cut.
#[derive(Debug, Clone)]
pub struct RamFlash<const SECTOR: usize, const SECTORS: usize> {
    mem: [[u8; SECTOR]; SECTORS],
    ops: u32,
    cut_at: Option<u32>,
    powered: bool,
}

impl<const SECTOR: usize, const SECTORS: usize> Default for RamFlash<SECTOR, SECTORS> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const SECTOR: usize, const SECTORS: usize> RamFlash<SECTOR, SECTORS> {
    /// An erased flash.
    pub const fn new() -> Self {
        Self {
            mem: [[0xFF; SECTOR]; SECTORS],
            ops: 0,
            cut_at: None,
            powered: true,
        }
    }

    /// Erase and write operations attempted so far.
    pub fn ops(&self) -> u32 {
        self.ops
    }

    /// Lets `n` more erase/write operations complete, tears the next one and then
    /// fails everything (see the type's documentation).
    pub fn cut_after(&mut self, n: u32) {
        self.cut_at = Some(self.ops.saturating_add(n));
    }

    /// Restores power (and disarms the injector); the content is kept.
    pub fn power_on(&mut self) {
        self.powered = true;
        self.cut_at = None;
    }

    /// The whole content (for tests and fault injection).
    pub fn bytes_mut(&mut self) -> impl Iterator<Item = &mut u8> {
        self.mem.iter_mut().flatten()
    }

    /// [`Flash::read`] through a shared reference (a read changes nothing).
    pub fn read_shared(&self, addr: u32, buf: &mut [u8]) -> Result<(), FlashError> {
        let a = self.check(addr, buf.len())?;
        for (i, b) in buf.iter_mut().enumerate() {
            let at = a.saturating_add(i);
            let v = at
                .checked_div(SECTOR)
                .and_then(|s| self.mem.get(s))
                .and_then(|sec| sec.get(at % SECTOR.max(1)));
            *b = v.map_or(0xFF, |v| *v);
        }
        Ok(())
    }

    fn byte(&mut self, addr: usize) -> Option<&mut u8> {
        let s = addr.checked_div(SECTOR)?;
        let o = addr.checked_rem(SECTOR)?;
        self.mem.get_mut(s)?.get_mut(o)
    }

    fn check(&self, addr: u32, len: usize) -> Result<usize, FlashError> {
        if !self.powered {
            return Err(FlashError::Device);
        }
        let a = addr as usize;
        match a.checked_add(len) {
            Some(end) if end <= SECTOR * SECTORS => Ok(a),
            _ => Err(FlashError::OutOfRange),
        }
    }

    /// Counts an erase/write; `true` when this one is torn (power goes away).
    fn op(&mut self) -> bool {
        let torn = self.cut_at == Some(self.ops);
        self.ops = self.ops.saturating_add(1);
        if torn {
            self.powered = false;
        }
        torn
    }
}

impl<const SECTOR: usize, const SECTORS: usize> Flash for RamFlash<SECTOR, SECTORS> {
    const SECTOR: usize = SECTOR;
    const SECTORS: usize = SECTORS;
    const WRITE: usize = 8;

    fn read(&mut self, addr: u32, buf: &mut [u8]) -> Result<(), FlashError> {
        self.read_shared(addr, buf)
    }

    fn erase(&mut self, sector: u32) -> Result<(), FlashError> {
        let a = (sector as usize).saturating_mul(SECTOR);
        self.check(addr_of(a)?, SECTOR)?;
        let n = if self.op() { SECTOR / 2 } else { SECTOR };
        for i in 0..n {
            if let Some(b) = self.byte(a + i) {
                *b = 0xFF;
            }
        }
        if self.powered {
            Ok(())
        } else {
            Err(FlashError::Device)
        }
    }

    fn write(&mut self, addr: u32, data: &[u8]) -> Result<(), FlashError> {
        let a = self.check(addr, data.len())?;
        if a % Self::WRITE != 0 || data.len() % Self::WRITE != 0 {
            return Err(FlashError::Misaligned);
        }
        let n = if self.op() { data.len() / 2 } else { data.len() };
        for (i, d) in data.iter().take(n).enumerate() {
            if let Some(b) = self.byte(a + i) {
                *b &= *d;
            }
        }
        if self.powered {
            Ok(())
        } else {
            Err(FlashError::Device)
        }
    }
}

fn addr_of(a: usize) -> Result<u32, FlashError> {
    u32::try_from(a).map_err(|_| FlashError::OutOfRange)
}
