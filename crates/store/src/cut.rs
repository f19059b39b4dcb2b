//! [`PowerCut`]: any [`Flash`] with a power-cut switch.

use crate::{Flash, FlashError};

/// A [`Flash`] whose erase and write operations fail once a budget is spent: the
/// flash stays as the last completed operation left it, as after a power cut.
///
/// Unlike [`RamFlash::cut_after`](crate::RamFlash::cut_after), which tears the cut
/// operation itself, the cut here falls between two operations, and reads keep
/// working (they show what the next boot would find). With no cut armed
/// ([`PowerCut::new`], [`PowerCut::power_on`]) every call goes straight through.
#[derive(Debug, Clone)]
pub struct PowerCut<F> {
    flash: F,
    left: Option<u32>,
}

impl<F> PowerCut<F> {
    /// `flash` with no cut armed.
    pub const fn new(flash: F) -> Self {
        Self { flash, left: None }
    }

    /// `flash` letting `n` erase/write operations complete and failing every later
    /// one with [`FlashError::Device`].
    pub const fn after(flash: F, n: u32) -> Self {
        Self { flash, left: Some(n) }
    }

    /// Lets `n` more erase/write operations complete, then fails every later one.
    pub fn cut_after(&mut self, n: u32) {
        self.left = Some(n);
    }

    /// Disarms the cut: every operation goes through again.
    pub fn power_on(&mut self) {
        self.left = None;
    }

    /// The wrapped flash.
    pub fn inner_mut(&mut self) -> &mut F {
        &mut self.flash
    }

    /// The wrapped flash, the switch dropped.
    pub fn into_inner(self) -> F {
        self.flash
    }

    /// Spends one operation of the budget; [`FlashError::Device`] once none is left.
    fn spend(&mut self) -> Result<(), FlashError> {
        match self.left {
            Some(n) => {
                self.left = Some(n.checked_sub(1).ok_or(FlashError::Device)?);
                Ok(())
            }
            None => Ok(()),
        }
    }
}

impl<F: Flash> Flash for PowerCut<F> {
    const SECTOR: usize = F::SECTOR;
    const SECTORS: usize = F::SECTORS;
    const WRITE: usize = F::WRITE;

    fn read(&mut self, addr: u32, buf: &mut [u8]) -> Result<(), FlashError> {
        self.flash.read(addr, buf)
    }

    fn erase(&mut self, sector: u32) -> Result<(), FlashError> {
        self.spend()?;
        self.flash.erase(sector)
    }

    fn write(&mut self, addr: u32, data: &[u8]) -> Result<(), FlashError> {
        self.spend()?;
        self.flash.write(addr, data)
    }
}
