//! The flash file of the QEMU boot scenarios (`scripts/cross boot-qemu`):
//! QEMU's mps2-an386 has RAM at 0, filled from `flash.bin` at start
//! (`-device loader`); a [`FileMirror`] writes every change of the slot region
//! through semihosting file I/O back into that file, so the next QEMU run (a
//! reset) sees the marks the boot loader and the image wrote.

use bootloader::{mps2, FlashError, Mirror};

/// The flash file, relative to QEMU's working directory (NUL-terminated for
/// semihosting).
const FILE: &[u8] = b"flash.bin\0";

/// Semihosting `SYS_OPEN` mode "r+b": read and write, no truncation.
const OPEN_RW_BINARY: usize = 3;

/// Writes the slot region's changes to the flash file at their offset
/// (`mps2::SLOTS_BASE` + the address in the region).
pub struct FileMirror {
    fd: Option<usize>,
}

impl FileMirror {
    /// Opens the flash file; [`FileMirror::is_open`] says whether that worked
    /// (if not, changes stay in memory and [`Mirror::changed`] fails).
    pub fn open() -> Self {
        // SAFETY: OPEN takes a NUL-terminated name, its mode and the name's
        // length without the NUL; the name is a static.
        #[allow(unsafe_code)]
        let fd =
            unsafe { cortex_m_semihosting::syscall!(OPEN, FILE.as_ptr(), OPEN_RW_BINARY, FILE.len() - 1) }
                as isize;
        Self {
            fd: (fd >= 0).then_some(fd as usize),
        }
    }

    /// Whether the flash file is open.
    #[allow(dead_code)] // the test image does not ask
    pub fn is_open(&self) -> bool {
        self.fd.is_some()
    }

    /// Closes the file (before the boot loader jumps).
    pub fn close(&mut self) {
        if let Some(fd) = self.fd.take() {
            // SAFETY: CLOSE of a handle OPEN returned.
            #[allow(unsafe_code)]
            unsafe {
                cortex_m_semihosting::syscall!(CLOSE, fd);
            }
        }
    }
}

impl Mirror for FileMirror {
    fn changed(&mut self, addr: u32, bytes: &[u8]) -> Result<(), FlashError> {
        let fd = self.fd.ok_or(FlashError::Device)?;
        let at = mps2::SLOTS_BASE as usize + addr as usize;
        // SAFETY: SEEK and WRITE of an open handle; WRITE reads `bytes` only.
        #[allow(unsafe_code)]
        let (seek, left) = unsafe {
            (
                cortex_m_semihosting::syscall!(SEEK, fd, at),
                cortex_m_semihosting::syscall!(WRITE, fd, bytes.as_ptr(), bytes.len()),
            )
        };
        // SEEK returns 0, WRITE the number of bytes not written
        if seek == 0 && left == 0 {
            Ok(())
        } else {
            Err(FlashError::Device)
        }
    }
}

/// The slot region (RAM at `mps2::SLOTS_BASE` in QEMU) as flash, its changes
/// mirrored to the flash file.
pub fn slot_flash() -> mps2::SlotFlash<'static, FileMirror> {
    // SAFETY: QEMU's mps2-an386 has RAM at 0..4 MiB; the slot region is only
    // reached through this slice (the running code in it is never written:
    // BootSlots writes marks and, in a download, the other slot). Called once
    // per image.
    #[allow(unsafe_code)]
    let region =
        unsafe { core::slice::from_raw_parts_mut(mps2::SLOTS_BASE as usize as *mut u8, mps2::REGION_LEN) };
    mps2::SlotFlash::new(region, FileMirror::open())
}
