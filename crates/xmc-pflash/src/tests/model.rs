//! A model of the XMC4800 PFLASH behind the [`Bus`]: 2 MiB of cells, the
//! logical/physical sector map, the command state machine, the page buffer, FSR.
//!
//! What it models (from the sources named in the crate docs):
//!
//! - erased cells read 00h; Write Page ORs the page buffer into the cells (bits go
//!   0 → 1), so a page programmed twice without an erase reads the OR of both (on
//!   the chip such a page is corrupt, with a double-bit ECC error on reading, as an
//!   Infineon forum thread on the XMC4500 reports; the driver refuses to do it);
//! - the command sequences of `crate::cmd`, exactly: Reset to Read (F0h) from any
//!   state (aborts a sequence, leaves page mode); Clear Status (F5h) and Enter Page
//!   Mode (50h) from an idle sequence; Load Page (55F0h then 55F4h, 32 pairs) only in
//!   page mode; Write Page (AAh, 55h, A0h, AAh to a page boundary) only in page mode
//!   with a full buffer, leaving page mode; Erase (AAh, 55h, 80h, AAh, 55h, then 30h to
//!   a logical or 40h to a physical sector start). Any other write — another value,
//!   address or order, a command while busy, a 33rd pair, a Write Page without a full
//!   buffer (the model's choice; the reference manual's exact rule was not at hand)
//!   — sets FSR.SQER, aborts the sequence and leaves page mode;
//! - a started program/erase sets PROG/ERASE and PBUSY, which stays set for
//!   [`Model::busy_polls`] FSR reads (or for ever with [`Model::stuck`]); the cells
//!   change when it ends; the PFLASH array reads garbage while busy (counted in
//!   [`Model::reads_while_busy`]);
//! - injectable: protected logical sectors (PROER, nothing started), an operation
//!   error (PFOPER, cells unchanged), a verify error (VER, cells changed), a bit that
//!   an erase leaves set.
extern crate std;
use std::vec;
use std::vec::Vec;

use crate::{cmd, fsr, logical_sector, physical_sector, Bus, FSR_ADDR, PAGE, SIZE, UNCACHED_BASE};

/// Garbage the array reads while busy.
pub const BUSY_GARBAGE: u32 = 0xDEAD_BEEF;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Seq {
    Idle,
    /// AAh at 5554h.
    U1,
    /// AAh, 55h.
    U2,
    /// Write Page: AAh, 55h, A0h.
    WriteA0,
    /// Erase: AAh, 55h, 80h.
    E80,
    /// AAh, 55h, 80h, AAh.
    E80U1,
    /// AAh, 55h, 80h, AAh, 55h.
    E80U2,
    /// A low word loaded, its high word next.
    LoadHigh(u32),
}

#[derive(Debug, Clone, Copy)]
enum Op {
    Program { off: u32 },
    Erase { off: u32, len: u32 },
}

/// The PFLASH model.
pub struct Model {
    pub mem: Vec<u8>,
    pub fsr: u32,
    seq: Seq,
    page_mode: bool,
    buf: [u8; PAGE],
    pairs: usize,
    busy: Option<(u32, Op)>,
    /// FSR reads that a started operation stays busy for.
    pub busy_polls: u32,
    /// The operation never ends.
    pub stuck: bool,
    /// Write-protected logical sectors (bit n: sector Sn).
    pub protected: u16,
    /// The next operation fails with PFOPER (cells unchanged).
    pub fail_next: bool,
    /// The next operation ends with VER (cells changed).
    pub verify_error_next: bool,
    /// The next erase leaves this PFLASH offset at 01h.
    pub erase_leaves: Option<u32>,
    /// Reads of the array while busy.
    pub reads_while_busy: u32,
    /// Every write: (address, value).
    pub writes: Vec<(u32, u32)>,
    /// Programs and erases started.
    pub started: u32,
}

impl Model {
    /// An erased chip, operations busy for 3 polls.
    pub fn new() -> Self {
        Self {
            mem: vec![0; SIZE as usize],
            fsr: 0,
            seq: Seq::Idle,
            page_mode: false,
            buf: [0; PAGE],
            pairs: 0,
            busy: None,
            busy_polls: 3,
            stuck: false,
            protected: 0,
            fail_next: false,
            verify_error_next: false,
            erase_leaves: None,
            reads_while_busy: 0,
            writes: Vec::new(),
            started: 0,
        }
    }

    /// The bytes at uncached address `addr`.
    pub fn at(&self, addr: u32, len: usize) -> &[u8] {
        let o = (addr - UNCACHED_BASE) as usize;
        &self.mem[o..o + len]
    }

    pub fn page_mode(&self) -> bool {
        self.page_mode
    }

    fn error(&mut self) {
        self.fsr |= fsr::SQER;
        self.seq = Seq::Idle;
        self.leave_page_mode();
    }

    fn leave_page_mode(&mut self) {
        self.page_mode = false;
        self.fsr &= !fsr::PFPAGE;
        self.pairs = 0;
    }

    fn sector_index(off: u32) -> Option<u32> {
        (0..16u32).find(|&i| {
            let start = match i {
                0..=7 => i * 16 * 1024,
                8 => 128 * 1024,
                _ => (i - 8) * 256 * 1024,
            };
            logical_sector(start).is_some_and(|(s, l)| off >= s && off < s + l)
        })
    }

    fn protected_range(&self, off: u32, len: u32) -> bool {
        (off..off + len)
            .step_by(16 * 1024)
            .any(|o| Self::sector_index(o).is_some_and(|i| self.protected & (1 << i) != 0))
    }

    fn start(&mut self, op: Op, flag: u32) {
        let (off, len) = match op {
            Op::Program { off } => (off, PAGE as u32),
            Op::Erase { off, len } => (off, len),
        };
        if self.protected_range(off, len) {
            self.fsr |= fsr::PROER;
            return;
        }
        self.started += 1;
        self.fsr |= flag | fsr::PBUSY;
        self.busy = Some((self.busy_polls, op));
        if self.busy_polls == 0 && !self.stuck {
            self.complete();
        }
    }

    fn complete(&mut self) {
        let Some((_, op)) = self.busy.take() else { return };
        self.fsr &= !fsr::PBUSY;
        if std::mem::take(&mut self.fail_next) {
            self.fsr |= fsr::PFOPER;
            return;
        }
        match op {
            Op::Program { off } => {
                let o = off as usize;
                for (c, b) in self.mem[o..o + PAGE].iter_mut().zip(self.buf) {
                    *c |= b;
                }
            }
            Op::Erase { off, len } => {
                self.mem[off as usize..(off + len) as usize].fill(0);
                if let Some(at) = self.erase_leaves.take() {
                    self.mem[at as usize] = 1;
                }
            }
        }
        if std::mem::take(&mut self.verify_error_next) {
            self.fsr |= fsr::VER;
        }
    }

    fn command(&mut self, addr: u32, value: u32) {
        if self.busy.is_some() {
            return self.error();
        }
        let off = addr.wrapping_sub(UNCACHED_BASE);
        if addr == cmd::A5554 && value == cmd::RESET_TO_READ {
            self.seq = Seq::Idle;
            return self.leave_page_mode();
        }
        self.seq = match (self.seq, addr, value) {
            (Seq::Idle, cmd::A5554, cmd::CLEAR_STATUS) => {
                self.fsr &= !(fsr::PROG | fsr::ERASE | fsr::PFOPER | fsr::SQER | fsr::PROER | fsr::VER);
                Seq::Idle
            }
            (Seq::Idle, cmd::A5554, cmd::ENTER_PAGE_MODE) if !self.page_mode => {
                self.page_mode = true;
                self.fsr |= fsr::PFPAGE;
                self.buf = [0; PAGE];
                self.pairs = 0;
                Seq::Idle
            }
            (Seq::Idle, cmd::LOAD_LOW, low) if self.page_mode && self.pairs < PAGE / 8 => Seq::LoadHigh(low),
            (Seq::LoadHigh(low), cmd::LOAD_HIGH, high) => {
                let at = self.pairs * 8;
                self.buf[at..at + 4].copy_from_slice(&low.to_le_bytes());
                self.buf[at + 4..at + 8].copy_from_slice(&high.to_le_bytes());
                self.pairs += 1;
                Seq::Idle
            }
            (Seq::Idle, cmd::A5554, cmd::UNLOCK1) => Seq::U1,
            (Seq::U1, cmd::AAAA8, cmd::UNLOCK2) => Seq::U2,
            (Seq::U2, cmd::A5554, cmd::WRITE_PAGE) if self.page_mode => Seq::WriteA0,
            (Seq::U2, cmd::A5554, cmd::ERASE) => Seq::E80,
            (Seq::E80, cmd::A5554, cmd::UNLOCK1) => Seq::E80U1,
            (Seq::E80U1, cmd::AAAA8, cmd::UNLOCK2) => Seq::E80U2,
            (Seq::WriteA0, _, cmd::WRITE_PAGE_GO)
                if off < SIZE && off as usize % PAGE == 0 && self.pairs == PAGE / 8 =>
            {
                self.leave_page_mode();
                self.start(Op::Program { off }, fsr::PROG);
                Seq::Idle
            }
            (Seq::E80U2, _, cmd::ERASE_SECTOR) if logical_sector(off).is_some() => {
                let (_, len) = logical_sector(off).unwrap();
                self.start(Op::Erase { off, len }, fsr::ERASE);
                Seq::Idle
            }
            (Seq::E80U2, _, cmd::ERASE_PHYSICAL_SECTOR)
                if physical_sector(off).is_some_and(|(s, _)| s == off) =>
            {
                let (_, len) = physical_sector(off).unwrap();
                self.start(Op::Erase { off, len }, fsr::ERASE);
                Seq::Idle
            }
            _ => return self.error(),
        };
    }
}

impl Bus for Model {
    fn write32(&mut self, addr: u32, value: u32) {
        self.writes.push((addr, value));
        self.command(addr, value);
    }

    fn read32(&mut self, addr: u32) -> u32 {
        if addr == FSR_ADDR {
            let s = self.fsr;
            if let Some((left, op)) = self.busy {
                if !self.stuck {
                    if left <= 1 {
                        self.complete();
                    } else {
                        self.busy = Some((left - 1, op));
                    }
                }
            }
            return s;
        }
        let off = addr.wrapping_sub(UNCACHED_BASE);
        if off >= SIZE || addr % 4 != 0 {
            panic!("model: read of {addr:#010x}");
        }
        if self.busy.is_some() {
            self.reads_while_busy += 1;
            return BUSY_GARBAGE;
        }
        let o = off as usize;
        u32::from_le_bytes(self.mem[o..o + 4].try_into().unwrap())
    }
}

/// A bus that changes the value of the `nth` write (0-based) on its way to the
/// model: a garbled command.
pub struct Garble<'a> {
    pub model: &'a mut Model,
    pub nth: usize,
    pub seen: usize,
}

impl Bus for Garble<'_> {
    fn write32(&mut self, addr: u32, value: u32) {
        let v = if self.seen == self.nth { value ^ 1 } else { value };
        self.seen += 1;
        self.model.write32(addr, v);
    }

    fn read32(&mut self, addr: u32) -> u32 {
        self.model.read32(addr)
    }
}
