//! The one place with `unsafe` code: volatile accesses to a bus address range.
#![allow(unsafe_code)]

use super::{BadAccess, RegisterWindow, Width};

/// A [`RegisterWindow`] over `len` bytes of memory-mapped ESC at `base`,
/// accessed with volatile 8/16/32-bit loads and stores. Every access is
/// checked against the window and for natural alignment (an unaligned access
/// to device memory faults on Cortex-M).
#[derive(Debug)]
pub struct VolatileWindow {
    base: usize,
    len: usize,
}

impl VolatileWindow {
    /// A window over `[base, base + len)`.
    ///
    /// # Safety
    ///
    /// For the lifetime of the window, `[base, base + len)` must be a mapped,
    /// readable and writable device region (for the XMC4800:
    /// [`XMC4800_ECAT0_BASE`](super::XMC4800_ECAT0_BASE),
    /// [`XMC4800_ECAT0_LEN`](super::XMC4800_ECAT0_LEN), with the ECAT0 clock
    /// enabled and its reset released), `base` must be 4-aligned, and nothing
    /// else may treat that range as Rust memory (no references into it). Two
    /// windows over the same ESC are allowed only if their users coordinate
    /// (e.g. an RTIC resource), because ESC accesses have side effects.
    pub const unsafe fn new(base: usize, len: usize) -> Self {
        Self { base, len }
    }

    /// The XMC4800's ECAT0 (0x5401_0000, 12 KiB).
    ///
    /// # Safety
    ///
    /// As for [`VolatileWindow::new`]: only on an XMC4800 with ECAT0 clocked
    /// and out of reset, and only one user at a time.
    pub const unsafe fn xmc4800_ecat0() -> Self {
        Self {
            base: super::XMC4800_ECAT0_BASE,
            len: super::XMC4800_ECAT0_LEN,
        }
    }

    /// Base address.
    pub const fn base(&self) -> usize {
        self.base
    }

    /// The bus address of `offset` if `width` bytes fit there and are aligned.
    fn address(&self, offset: usize, width: Width) -> Result<usize, BadAccess> {
        let n = width.bytes();
        let fits = offset.checked_add(n).is_some_and(|end| end <= self.len);
        let address = self.base.checked_add(offset).filter(|a| fits && a % n == 0);
        address.ok_or(BadAccess { offset, width })
    }
}

impl RegisterWindow for VolatileWindow {
    fn len(&self) -> usize {
        self.len
    }

    fn read(&mut self, offset: usize, width: Width) -> Result<u32, BadAccess> {
        let a = self.address(offset, width)?;
        // SAFETY: `address` checked that the access lies inside the window and
        // is naturally aligned; `new`'s contract makes the window a mapped
        // device region that no Rust reference aliases.
        let v = unsafe {
            match width {
                Width::U8 => u32::from(core::ptr::read_volatile(a as *const u8)),
                Width::U16 => u32::from(core::ptr::read_volatile(a as *const u16)),
                Width::U32 => core::ptr::read_volatile(a as *const u32),
            }
        };
        Ok(v)
    }

    fn write(&mut self, offset: usize, width: Width, value: u32) -> Result<(), BadAccess> {
        let a = self.address(offset, width)?;
        // SAFETY: as in `read`: in bounds, aligned, a device region owned by
        // this window. The truncating casts keep the low `width` bytes.
        unsafe {
            match width {
                Width::U8 => core::ptr::write_volatile(a as *mut u8, value as u8),
                Width::U16 => core::ptr::write_volatile(a as *mut u16, value as u16),
                Width::U32 => core::ptr::write_volatile(a as *mut u32, value),
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn volatile_window_reads_writes_le_and_refuses_bad_offsets() {
        let mut mem = [0u32; 4];
        let base = mem.as_mut_ptr() as usize;
        // SAFETY: `mem` outlives the window, is 4-aligned and is only touched
        // through the window while it is in use.
        let mut w = unsafe { VolatileWindow::new(base, 16) };
        w.write(0, Width::U32, 0x4433_2211).unwrap();
        w.write(6, Width::U16, 0xBBAA).unwrap();
        w.write(9, Width::U8, 0xCC).unwrap();
        assert_eq!(w.read(0, Width::U8).unwrap(), 0x11);
        assert_eq!(w.read(2, Width::U16).unwrap(), 0x4433);
        assert_eq!(w.read(4, Width::U32).unwrap(), 0xBBAA_0000);
        assert_eq!(w.read(8, Width::U32).unwrap(), 0x0000_CC00);
        // Misaligned and out-of-window accesses are refused, not performed.
        assert_eq!(
            w.read(1, Width::U16),
            Err(BadAccess {
                offset: 1,
                width: Width::U16
            })
        );
        assert_eq!(
            w.read(2, Width::U32),
            Err(BadAccess {
                offset: 2,
                width: Width::U32
            })
        );
        assert_eq!(
            w.read(16, Width::U8),
            Err(BadAccess {
                offset: 16,
                width: Width::U8
            })
        );
        assert_eq!(
            w.write(14, Width::U32, 0),
            Err(BadAccess {
                offset: 14,
                width: Width::U32
            })
        );
        assert_eq!(
            w.read(usize::MAX, Width::U8),
            Err(BadAccess {
                offset: usize::MAX,
                width: Width::U8
            })
        );
        let _ = w;
        assert_eq!(mem, [0x4433_2211, 0xBBAA_0000, 0x0000_CC00, 0]);
    }
}
