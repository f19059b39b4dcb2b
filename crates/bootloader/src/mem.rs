//! [`MemFlash`]: NOR flash over a byte slice, every change mirrored.

use boot::{Flash, FlashError};

/// Told about every change of a [`MemFlash`]: `bytes` are the region's new
/// contents at `addr` (after an erase: the sector's FFh; after a write: the
/// programmed unit as it now reads). The QEMU images write them to their flash
/// file, so the next run (a reset) sees them.
pub trait Mirror {
    /// The region changed at `addr`.
    fn changed(&mut self, addr: u32, bytes: &[u8]) -> Result<(), FlashError>;
}

/// No mirror.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoMirror;

impl Mirror for NoMirror {
    fn changed(&mut self, _addr: u32, _bytes: &[u8]) -> Result<(), FlashError> {
        Ok(())
    }
}

/// NOR flash of `SECTORS` sectors of `SECTOR` bytes, program unit `WRITE`, over
/// `mem` (which must hold `SECTOR * SECTORS` bytes; the rest is out of range): an
/// erase sets a sector to FFh, a write clears bits (`old & data`). Each change
/// goes to the [`Mirror`] after it was made in `mem`; a mirror error is the
/// operation's error ([`FlashError::Device`] typically).
#[derive(Debug)]
pub struct MemFlash<'a, M, const SECTOR: usize, const SECTORS: usize, const WRITE: usize> {
    mem: &'a mut [u8],
    mirror: M,
}

impl<'a, M: Mirror, const SECTOR: usize, const SECTORS: usize, const WRITE: usize>
    MemFlash<'a, M, SECTOR, SECTORS, WRITE>
{
    /// The flash over `mem`, changes told to `mirror`.
    pub fn new(mem: &'a mut [u8], mirror: M) -> Self {
        Self { mem, mirror }
    }

    /// The contents (for tests and the flash-file tool).
    pub fn bytes(&self) -> &[u8] {
        self.mem.get(..SECTOR * SECTORS).unwrap_or(&[])
    }

    /// The contents, mutable (fault injection: no NOR rules, no mirror).
    pub fn bytes_mut(&mut self) -> &mut [u8] {
        let n = self.mem.len().min(SECTOR * SECTORS);
        self.mem.get_mut(..n).unwrap_or(&mut [])
    }

    /// The mirror.
    pub fn mirror_mut(&mut self) -> &mut M {
        &mut self.mirror
    }

    fn range(&self, addr: u32, len: usize) -> Result<core::ops::Range<usize>, FlashError> {
        let a = addr as usize;
        match a.checked_add(len) {
            Some(end) if end <= SECTOR * SECTORS && end <= self.mem.len() => Ok(a..end),
            _ => Err(FlashError::OutOfRange),
        }
    }
}

impl<M: Mirror, const SECTOR: usize, const SECTORS: usize, const WRITE: usize> Flash
    for MemFlash<'_, M, SECTOR, SECTORS, WRITE>
{
    const SECTOR: usize = SECTOR;
    const SECTORS: usize = SECTORS;
    const WRITE: usize = WRITE;

    fn read(&mut self, addr: u32, buf: &mut [u8]) -> Result<(), FlashError> {
        let r = self.range(addr, buf.len())?;
        buf.copy_from_slice(self.mem.get(r).ok_or(FlashError::OutOfRange)?);
        Ok(())
    }

    fn erase(&mut self, sector: u32) -> Result<(), FlashError> {
        let start = (sector as usize)
            .checked_mul(SECTOR)
            .ok_or(FlashError::OutOfRange)?;
        let addr = u32::try_from(start).map_err(|_| FlashError::OutOfRange)?;
        let r = self.range(addr, SECTOR)?;
        let s = self.mem.get_mut(r).ok_or(FlashError::OutOfRange)?;
        s.fill(0xFF);
        self.mirror.changed(addr, s)
    }

    fn write(&mut self, addr: u32, data: &[u8]) -> Result<(), FlashError> {
        if addr as usize % WRITE != 0 || data.len() % WRITE != 0 {
            return Err(FlashError::Misaligned);
        }
        let r = self.range(addr, data.len())?;
        let s = self.mem.get_mut(r).ok_or(FlashError::OutOfRange)?;
        for (b, d) in s.iter_mut().zip(data) {
            *b &= *d;
        }
        self.mirror.changed(addr, s)
    }
}
