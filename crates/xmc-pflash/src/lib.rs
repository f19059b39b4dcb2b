//! Erase/program driver of the Infineon XMC4000 program flash (PFLASH), for the
//! XMC4800 of the reference board (docs/flashing.md, "Flash layout" and "The
//! PFLASH driver").
//!
//! The PFLASH is programmed and erased with *command sequences*: 32-bit writes of
//! fixed values to fixed addresses in the uncached flash alias 0x0C00_xxxx, the last
//! one to the page or sector concerned; the flash status register FSR
//! ([`FSR_ADDR`]) tells busy, page mode and errors. [`Pflash`] issues them through a
//! [`Bus`] (two methods: a 32-bit write and a 32-bit read), so the command logic runs
//! on the host against a model of the chip (the crate's tests); on the target the bus
//! is [`Volatile`].
//!
//! # Sources
//!
//! The addresses, values and FSR bit positions were checked against two public
//! sources (read, not copied): Infineon's XMCLib (`xmc4_flash.c` and `xmc4_flash.h`,
//! v2.1.14/v2.1.16: the command functions `XMC_FLASH_lEnterPageModeCommand`,
//! `..LoadPageCommand`, `..WritePageCommand`, `..EraseSectorCommand`,
//! `..ErasePhysicalSectorCommand`, `..ClearStatusCommand`, `XMC_FLASH_Reset`; the
//! sector and physical-sector addresses) and OpenOCD's `src/flash/nor/xmc4xxx.c`
//! (the same sequences, FSR at 0x5800_2010 with its bit positions, the 16-sector map
//! of the XMC4700/4800, and "erased value 0x00"). The XMC4800 reference manual itself
//! was not at hand; nothing here has run on silicon.
//!
//! # Erased flash reads 00h
//!
//! An erased XMC4000 PFLASH cell reads **0**, programming sets bits to 1 (OpenOCD
//! sets the bank's erased and padding value to 0x00 for this family). The
//! [`store::Flash`] trait documents NOR flash erased to FFh; the parameter store
//! (`crates/store`) and the firmware slots (`crates/boot`) never rely on that value
//! when they read (an erased header has no magic, an erased mark unit no tag, an
//! erased commit unit not the commit pattern), and program every unit once after an
//! erase, whole, so the FFh padding they write reads back as written (the driver
//! refuses to program a page that does not read erased: on the chip a second
//! program corrupts the page and its ECC). [`Region`] therefore passes the chip's
//! contents through unchanged (an image in a slot must be stored as it executes);
//! the crate's tests run both crates over it to show that.
//!
//! # Must run from RAM
//!
//! The XMC4800 has one PFLASH bank: while it erases or programs, it cannot be read,
//! instruction fetches from it stall until it is idle. The function that writes a
//! command's last cycle and polls FSR until the flash is idle again is placed in RAM
//! on the target (`#[link_section = ".data.ramfunc"]`, never inlined: cortex-m-rt
//! copies `.data.*` to RAM at reset); the rest of the driver runs from flash (before
//! a command starts or after it ended). With [`Volatile`] the caller must also keep
//! interrupts masked during an erase or a write (their handlers and vector table are
//! in flash) — see [`Volatile::new`].
#![no_std]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]
#![deny(missing_docs)]

use store::{Flash, FlashError};

/// Uncached alias of the PFLASH (commands and the reads that must see a change at
/// once go here; code runs from the cached alias 0x0800_0000, the same cells).
pub const UNCACHED_BASE: u32 = 0x0C00_0000;
/// Bytes of PFLASH on the XMC4800-F144x2048.
pub const SIZE: u32 = 2 * 1024 * 1024;
/// Program unit: one page.
pub const PAGE: usize = 256;
/// Flash status register FSR (FLASH0 module at 0x5800_1000, FSR at +0x1010).
pub const FSR_ADDR: u32 = 0x5800_2010;

/// The command sequences' addresses and values (XMCLib `xmc4_flash.c`).
pub mod cmd {
    /// First command address (`0x5554` in the uncached alias).
    pub const A5554: u32 = super::UNCACHED_BASE + 0x5554;
    /// Second command address (`0xAAA8`).
    pub const AAAA8: u32 = super::UNCACHED_BASE + 0xAAA8;
    /// Load Page: the low word of a 64-bit pair.
    pub const LOAD_LOW: u32 = super::UNCACHED_BASE + 0x55F0;
    /// Load Page: the high word of the pair (the pair goes into the page buffer).
    pub const LOAD_HIGH: u32 = super::UNCACHED_BASE + 0x55F4;
    /// Reset to Read, to [`A5554`]: aborts a sequence, leaves page mode.
    pub const RESET_TO_READ: u32 = 0xF0;
    /// Clear Status, to [`A5554`]: clears PROG, ERASE and the error flags.
    pub const CLEAR_STATUS: u32 = 0xF5;
    /// Enter Page Mode, to [`A5554`]: the page buffer is used.
    pub const ENTER_PAGE_MODE: u32 = 0x50;
    /// First unlock cycle, to [`A5554`].
    pub const UNLOCK1: u32 = 0xAA;
    /// Second unlock cycle, to [`AAAA8`].
    pub const UNLOCK2: u32 = 0x55;
    /// Write Page, third cycle to [`A5554`]; the fourth writes [`WRITE_PAGE_GO`] to
    /// the page's address.
    pub const WRITE_PAGE: u32 = 0xA0;
    /// Write Page, fourth cycle (to the page).
    pub const WRITE_PAGE_GO: u32 = 0xAA;
    /// Erase, third cycle to [`A5554`]; then [`UNLOCK1`], [`UNLOCK2`] and the sector
    /// command to the sector's address.
    pub const ERASE: u32 = 0x80;
    /// Erase Sector (a logical sector), last cycle.
    pub const ERASE_SECTOR: u32 = 0x30;
    /// Erase Physical Sector, last cycle.
    pub const ERASE_PHYSICAL_SECTOR: u32 = 0x40;
}

/// FSR bits (XMCLib `XMC_FLASH_STATUS_t`, OpenOCD `FSR_*`).
pub mod fsr {
    /// PBUSY: the PFLASH is busy (programming or erasing).
    pub const PBUSY: u32 = 1 << 0;
    /// PROG: a Write Page was started (until Clear Status).
    pub const PROG: u32 = 1 << 4;
    /// ERASE: an erase was started (until Clear Status).
    pub const ERASE: u32 = 1 << 5;
    /// PFPAGE: page mode (the page buffer is in use).
    pub const PFPAGE: u32 = 1 << 6;
    /// PFOPER: the operation failed (aborted).
    pub const PFOPER: u32 = 1 << 8;
    /// SQER: command sequence error (wrong address, value or state).
    pub const SQER: u32 = 1 << 10;
    /// PROER: the command addressed a protected sector.
    pub const PROER: u32 = 1 << 11;
    /// VER: the chip's own verification after programming or erasing failed.
    pub const VER: u32 = 1 << 31;
}

/// The logical sector (offset, size) that starts at `offset` (from the PFLASH
/// start): 8 × 16 KiB, 1 × 128 KiB, 7 × 256 KiB.
pub const fn logical_sector(offset: u32) -> Option<(u32, u32)> {
    const K: u32 = 1024;
    if offset < 128 * K && offset % (16 * K) == 0 {
        Some((offset, 16 * K))
    } else if offset == 128 * K {
        Some((offset, 128 * K))
    } else if offset >= 256 * K && offset < SIZE && offset % (256 * K) == 0 {
        Some((offset, 256 * K))
    } else {
        None
    }
}

/// The physical sector (offset, size) that contains `offset`: 64 KiB (S0..S3),
/// 64 KiB (S4..S7), 128 KiB (S8), then one per 256 KiB logical sector. Erasing a
/// logical sector disturbs the others of its physical sector (docs/flashing.md).
pub const fn physical_sector(offset: u32) -> Option<(u32, u32)> {
    const K: u32 = 1024;
    if offset >= SIZE {
        None
    } else if offset < 64 * K {
        Some((0, 64 * K))
    } else if offset < 128 * K {
        Some((64 * K, 64 * K))
    } else if offset < 256 * K {
        Some((128 * K, 128 * K))
    } else {
        Some((offset / (256 * K) * (256 * K), 256 * K))
    }
}

/// 32-bit register and memory access: all the driver does to the chip.
pub trait Bus {
    /// Writes `value` to `addr`.
    fn write32(&mut self, addr: u32, value: u32);
    /// Reads the word at `addr`.
    fn read32(&mut self, addr: u32) -> u32;
}

impl<B: Bus + ?Sized> Bus for &mut B {
    #[inline(always)]
    fn write32(&mut self, addr: u32, value: u32) {
        (**self).write32(addr, value);
    }

    #[inline(always)]
    fn read32(&mut self, addr: u32) -> u32 {
        (**self).read32(addr)
    }
}

/// The target's bus: volatile accesses, limited to the PFLASH's uncached alias and
/// FSR (any other address: writes are dropped, reads give 0).
#[derive(Debug)]
pub struct Volatile {
    _private: (),
}

impl Volatile {
    /// The bus of the running chip.
    ///
    /// # Safety
    ///
    /// Only on an XMC4000 with its PFLASH at 0x0C00_0000 and FLASH0 at 0x5800_1000;
    /// one `Volatile` at a time (nothing else issues PFLASH commands meanwhile), and
    /// while a [`Pflash`] erase or write runs on it, interrupts are masked and no
    /// other bus master reads the PFLASH (the flash cannot be read while busy; the
    /// driver's waiting part runs from RAM, the handlers would not).
    #[allow(unsafe_code)]
    pub const unsafe fn new() -> Self {
        Self { _private: () }
    }

    #[inline(always)]
    const fn allowed(addr: u32) -> bool {
        addr % 4 == 0 && (addr == FSR_ADDR || (addr >= UNCACHED_BASE && addr - UNCACHED_BASE < SIZE))
    }
}

impl Bus for Volatile {
    #[inline(always)]
    fn write32(&mut self, addr: u32, value: u32) {
        if Self::allowed(addr) {
            // SAFETY: an aligned word of the PFLASH command window or FSR
            // (`allowed`), on the chip `new`'s contract names.
            #[allow(unsafe_code)]
            unsafe {
                core::ptr::write_volatile(addr as usize as *mut u32, value);
            }
            // the command write before the next access (an FSR poll)
            core::sync::atomic::fence(core::sync::atomic::Ordering::SeqCst);
        }
    }

    #[inline(always)]
    fn read32(&mut self, addr: u32) -> u32 {
        if Self::allowed(addr) {
            // SAFETY: as in `write32`; PFLASH and FSR are always readable.
            #[allow(unsafe_code)]
            unsafe {
                core::ptr::read_volatile(addr as usize as *const u32)
            }
        } else {
            0
        }
    }
}

/// Bounds of the busy waits: FSR polls before an operation counts as timed out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Polls for one Write Page.
    pub page_polls: u32,
    /// Polls for one sector erase.
    pub erase_polls: u32,
}

impl Limits {
    /// Bounds for a CPU at `cpu_hz`: one poll takes at least one cycle, so
    /// `cpu_hz × t` polls last at least `t`. `t` is 50 ms per page and 20 s per
    /// erase: generous, **not checked against the XMC4800 datasheet's maxima** here.
    pub const fn at_cpu_hz(cpu_hz: u32) -> Self {
        Self {
            page_polls: if cpu_hz < 20 { 1 } else { cpu_hz / 20 },
            erase_polls: cpu_hz.saturating_mul(20),
        }
    }
}

/// What went wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Error {
    /// An address (or its range) outside the PFLASH or the region.
    OutOfRange,
    /// Not on a page boundary, or not whole pages (a write never crosses a page).
    Misaligned,
    /// An erase address that is no (logical or physical) sector start.
    NotSectorStart,
    /// FSR.SQER: the chip refused the command sequence.
    Sequence,
    /// FSR.PROER: the sector is write-protected.
    Protection,
    /// FSR.PFOPER: the chip aborted the operation.
    Operation,
    /// FSR.VER: the chip's own verification failed.
    Verify,
    /// Page mode not entered (FSR.PFPAGE stayed clear).
    PageMode,
    /// The command was taken but FSR shows no program or erase started.
    NotStarted,
    /// FSR.PBUSY still set after the poll bound ([`Limits`]).
    Timeout,
    /// After an erase, the sector does not read 00h everywhere.
    NotBlank,
    /// Before a write, the page does not read 00h everywhere: it was programmed
    /// since its erase (programming it again would corrupt it and its ECC).
    NotErased,
    /// After a write, the page does not read back as written.
    ReadBack,
}

impl From<Error> for FlashError {
    fn from(e: Error) -> Self {
        match e {
            Error::OutOfRange | Error::NotSectorStart => FlashError::OutOfRange,
            Error::Misaligned => FlashError::Misaligned,
            _ => FlashError::Device,
        }
    }
}

/// Writes `seq` in order, then polls FSR until PBUSY is clear, at most `polls`
/// times: the FSR seen, or [`Error::Timeout`]. The last write of `seq` starts the
/// program or erase, so this function and all it runs are in RAM on the target:
/// nothing may be fetched from the PFLASH until it is idle.
// (`link_section` counts as unsafe code: the section must hold executable code
// that the runtime copies to RAM before use, which cortex-m-rt does for .data.*)
#[allow(unsafe_code)]
#[cfg_attr(all(target_arch = "arm", target_os = "none"), link_section = ".data.ramfunc")]
#[inline(never)]
fn issue_and_wait<B: Bus>(bus: &mut B, seq: &[(u32, u32)], polls: u32) -> Result<u32, Error> {
    for &(addr, value) in seq {
        bus.write32(addr, value);
    }
    let mut n = 0;
    while n < polls {
        let s = bus.read32(FSR_ADDR);
        if s & fsr::PBUSY == 0 {
            return Ok(s);
        }
        n += 1;
    }
    Err(Error::Timeout)
}

/// The PFLASH driver over a [`Bus`]. Addresses are absolute, in the uncached alias.
#[derive(Debug)]
pub struct Pflash<B> {
    bus: B,
    limits: Limits,
}

impl<B: Bus> Pflash<B> {
    /// The driver over `bus`, busy waits bounded by `limits`.
    pub const fn new(bus: B, limits: Limits) -> Self {
        Self { bus, limits }
    }

    /// The bus (tests: the model).
    pub fn bus_mut(&mut self) -> &mut B {
        &mut self.bus
    }

    /// The bus back.
    pub fn into_inner(self) -> B {
        self.bus
    }

    /// FSR as it is now.
    pub fn status(&mut self) -> u32 {
        self.bus.read32(FSR_ADDR)
    }

    /// Reads `buf.len()` bytes at `addr` (one word read per word touched).
    pub fn read(&mut self, addr: u32, buf: &mut [u8]) -> Result<(), Error> {
        offset_of(addr, buf.len())?;
        let mut word_at = None;
        let mut word = [0u8; 4];
        let mut a = addr;
        for b in buf.iter_mut() {
            let wa = a & !3;
            if word_at != Some(wa) {
                word = self.bus.read32(wa).to_le_bytes();
                word_at = Some(wa);
            }
            let [w0, w1, w2, w3] = word;
            *b = match a & 3 {
                0 => w0,
                1 => w1,
                2 => w2,
                _ => w3,
            };
            a = a.wrapping_add(1);
        }
        Ok(())
    }

    /// Erases the logical sector that starts at `addr`, then checks that it reads 00h.
    pub fn erase_sector(&mut self, addr: u32) -> Result<(), Error> {
        let off = offset_of(addr, 4)?;
        let (_, len) = logical_sector(off).ok_or(Error::NotSectorStart)?;
        self.erase(addr, len, cmd::ERASE_SECTOR)
    }

    /// Erases the physical sector that starts at `addr` (all its logical sectors),
    /// then checks that it reads 00h.
    pub fn erase_physical_sector(&mut self, addr: u32) -> Result<(), Error> {
        let off = offset_of(addr, 4)?;
        match physical_sector(off) {
            Some((at, len)) if at == off => self.erase(addr, len, cmd::ERASE_PHYSICAL_SECTOR),
            _ => Err(Error::NotSectorStart),
        }
    }

    fn erase(&mut self, addr: u32, len: u32, last: u32) -> Result<(), Error> {
        self.prepare();
        let seq = [
            (cmd::A5554, cmd::UNLOCK1),
            (cmd::AAAA8, cmd::UNLOCK2),
            (cmd::A5554, cmd::ERASE),
            (cmd::A5554, cmd::UNLOCK1),
            (cmd::AAAA8, cmd::UNLOCK2),
            (addr, last),
        ];
        let r =
            issue_and_wait(&mut self.bus, &seq, self.limits.erase_polls).and_then(|s| outcome(s, fsr::ERASE));
        self.finish();
        r?;
        let mut at = 0;
        while at < len {
            if self.bus.read32(addr.wrapping_add(at)) != 0 {
                return Err(Error::NotBlank);
            }
            at += 4;
        }
        Ok(())
    }

    /// Programs one page at `addr` (a page boundary) that reads erased (00h), then
    /// checks its read-back.
    pub fn write_page(&mut self, addr: u32, page: &[u8; PAGE]) -> Result<(), Error> {
        offset_of(addr, PAGE)?;
        if addr as usize % PAGE != 0 {
            return Err(Error::Misaligned);
        }
        let mut at = 0;
        while at < PAGE as u32 {
            if self.bus.read32(addr.wrapping_add(at)) != 0 {
                return Err(Error::NotErased);
            }
            at += 4;
        }
        self.prepare();
        let r = self.load_and_write(addr, page);
        self.finish();
        r?;
        for (i, w) in page.chunks_exact(4).enumerate() {
            let want = match w {
                &[a, b, c, d] => u32::from_le_bytes([a, b, c, d]),
                _ => 0,
            };
            if self.bus.read32(addr.wrapping_add(4 * i as u32)) != want {
                return Err(Error::ReadBack);
            }
        }
        Ok(())
    }

    fn load_and_write(&mut self, addr: u32, page: &[u8; PAGE]) -> Result<(), Error> {
        self.bus.write32(cmd::A5554, cmd::ENTER_PAGE_MODE);
        let s = self.status();
        if s & fsr::SQER != 0 {
            return Err(Error::Sequence);
        }
        if s & fsr::PFPAGE == 0 {
            return Err(Error::PageMode);
        }
        for pair in page.chunks_exact(8) {
            if let &[a, b, c, d, e, f, g, h] = pair {
                self.bus.write32(cmd::LOAD_LOW, u32::from_le_bytes([a, b, c, d]));
                self.bus.write32(cmd::LOAD_HIGH, u32::from_le_bytes([e, f, g, h]));
            }
        }
        if self.status() & fsr::SQER != 0 {
            return Err(Error::Sequence);
        }
        let seq = [
            (cmd::A5554, cmd::UNLOCK1),
            (cmd::AAAA8, cmd::UNLOCK2),
            (cmd::A5554, cmd::WRITE_PAGE),
            (addr, cmd::WRITE_PAGE_GO),
        ];
        let s = issue_and_wait(&mut self.bus, &seq, self.limits.page_polls)?;
        outcome(s, fsr::PROG)
    }

    /// Programs `data` (whole pages) from `addr` (a page boundary), page by page.
    pub fn program(&mut self, addr: u32, data: &[u8]) -> Result<(), Error> {
        offset_of(addr, data.len())?;
        if addr as usize % PAGE != 0 || data.len() % PAGE != 0 {
            return Err(Error::Misaligned);
        }
        let mut at = addr;
        for chunk in data.chunks_exact(PAGE) {
            let page: &[u8; PAGE] = chunk.try_into().map_err(|_| Error::Misaligned)?;
            self.write_page(at, page)?;
            at = at.wrapping_add(PAGE as u32);
        }
        Ok(())
    }

    /// Before a command: out of any sequence or page mode, flags cleared.
    fn prepare(&mut self) {
        self.bus.write32(cmd::A5554, cmd::RESET_TO_READ);
        self.bus.write32(cmd::A5554, cmd::CLEAR_STATUS);
    }

    /// After a command (also a failed one): read mode, flags cleared.
    fn finish(&mut self) {
        if self.status() & fsr::PBUSY == 0 {
            self.prepare();
        }
    }
}

/// The result an idle FSR `s` says for an operation that sets `started`.
fn outcome(s: u32, started: u32) -> Result<(), Error> {
    if s & fsr::SQER != 0 {
        Err(Error::Sequence)
    } else if s & fsr::PROER != 0 {
        Err(Error::Protection)
    } else if s & fsr::PFOPER != 0 {
        Err(Error::Operation)
    } else if s & fsr::VER != 0 {
        Err(Error::Verify)
    } else if s & started == 0 {
        Err(Error::NotStarted)
    } else {
        Ok(())
    }
}

/// The PFLASH offset of the `len` bytes at `addr`, if they lie in the PFLASH.
fn offset_of(addr: u32, len: usize) -> Result<u32, Error> {
    let off = addr.checked_sub(UNCACHED_BASE).ok_or(Error::OutOfRange)?;
    let len = u32::try_from(len).map_err(|_| Error::OutOfRange)?;
    match off.checked_add(len) {
        Some(end) if end <= SIZE => Ok(off),
        _ => Err(Error::OutOfRange),
    }
}

/// A region of `SECTORS` logical sectors of `SECTOR` bytes from `BASE` (uncached
/// address) as a [`store::Flash`] (the parameter store's and, through `crates/boot`,
/// the boot loader's): program unit one page, erase one logical sector, contents as
/// the chip has them (erased reads 00h: see the crate docs).
#[derive(Debug)]
pub struct Region<B, const BASE: u32, const SECTOR: usize, const SECTORS: usize> {
    flash: Pflash<B>,
}

impl<B: Bus, const BASE: u32, const SECTOR: usize, const SECTORS: usize> Region<B, BASE, SECTOR, SECTORS> {
    /// Uncached address of the region's byte 0.
    pub const BASE: u32 = BASE;

    /// The region on `flash`. Compile-time check: each of its sectors is one logical
    /// sector of the PFLASH.
    pub fn new(flash: Pflash<B>) -> Self {
        const {
            let mut i = 0;
            while i < SECTORS {
                let off = BASE - UNCACHED_BASE + (i * SECTOR) as u32;
                assert!(matches!(logical_sector(off), Some((_, len)) if len as usize == SECTOR));
                i += 1;
            }
        }
        Self { flash }
    }

    /// The driver (tests and fault injection).
    pub fn pflash_mut(&mut self) -> &mut Pflash<B> {
        &mut self.flash
    }

    /// The driver back.
    pub fn into_inner(self) -> Pflash<B> {
        self.flash
    }

    fn at(addr: u32, len: usize) -> Result<u32, FlashError> {
        match (addr as usize).checked_add(len) {
            Some(end) if end <= SECTOR * SECTORS => Ok(BASE.wrapping_add(addr)),
            _ => Err(FlashError::OutOfRange),
        }
    }
}

impl<B: Bus, const BASE: u32, const SECTOR: usize, const SECTORS: usize> Flash
    for Region<B, BASE, SECTOR, SECTORS>
{
    const SECTOR: usize = SECTOR;
    const SECTORS: usize = SECTORS;
    const WRITE: usize = PAGE;

    fn read(&mut self, addr: u32, buf: &mut [u8]) -> Result<(), FlashError> {
        let a = Self::at(addr, buf.len())?;
        Ok(self.flash.read(a, buf)?)
    }

    fn erase(&mut self, sector: u32) -> Result<(), FlashError> {
        let off = (sector as usize)
            .checked_mul(SECTOR)
            .and_then(|o| u32::try_from(o).ok())
            .ok_or(FlashError::OutOfRange)?;
        let a = Self::at(off, SECTOR)?;
        Ok(self.flash.erase_sector(a)?)
    }

    fn write(&mut self, addr: u32, data: &[u8]) -> Result<(), FlashError> {
        let a = Self::at(addr, data.len())?;
        Ok(self.flash.program(a, data)?)
    }
}

/// The firmware slots (S9..S12, 4 × 256 KiB from 0x0C04_0000; `bootloader::xmc4800`).
pub type SlotRegion<B> = Region<B, 0x0C04_0000, { 256 * 1024 }, 4>;
/// The parameter store (S4..S7, 4 × 16 KiB from 0x0C01_0000, one physical sector).
pub type ParamRegion<B> = Region<B, 0x0C01_0000, { 16 * 1024 }, 4>;

#[cfg(test)]
mod tests;
