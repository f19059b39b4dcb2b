//! Power-fail-safe parameter store (spec §2.5, items E-018/E-020).
//!
//! The flash region behind a [`Flash`] is split into two slots, A (first half of the
//! sectors) and B (second half). Every [`ParamStore::save`] goes into the slot that does
//! **not** hold the newest valid record, so the previous set stays untouched until the
//! new one is complete. A record is
//!
//! ```text
//! offset 0          header: magic u32, layout u32, sequence u32, length u32, CRC-32 u32 (LE),
//!                   padded with FFh to a multiple of Flash::WRITE
//! offset H          payload, last write unit padded with FFh
//! offset H+pad(len) commit unit: Flash::WRITE bytes of a fixed pattern without any FFh byte
//! ```
//!
//! The CRC-32/ISO-HDLC covers the first 16 header bytes and the payload. A save erases
//! the slot, writes header and payload, and writes the commit unit **last**: a save torn
//! at any point leaves either no commit unit (the record is ignored) or a complete record.
//! [`ParamStore::load`] takes the valid record with the highest sequence number (serial
//! number arithmetic, so the u32 may wrap) whose layout matches.
//!
//! [`RamFlash`] is a RAM model of NOR flash with a power-cut injector for tests and the
//! simulator; [`PowerCut`] puts a power-cut switch in front of any [`Flash`] (the boot
//! loader's tests and `tools/flash-compose` cut their downloads with it).
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

mod crc;
mod cut;
mod ram;

pub use crc::{crc32, Crc32};
pub use cut::PowerCut;
pub use ram::RamFlash;

/// Largest program unit ([`Flash::WRITE`]) the store supports.
pub const MAX_WRITE: usize = 256;

/// Errors of a [`Flash`] device.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FlashError {
    /// Address or sector outside the region.
    OutOfRange,
    /// A write not aligned to [`Flash::WRITE`] in address or length.
    Misaligned,
    /// The device failed (programming/erase error, timeout, power loss).
    Device,
}

/// The flash region given to the store, with NOR semantics: [`Flash::erase`] sets a
/// whole sector to FFh; [`Flash::write`] can only clear bits (the result is
/// `old & data`) and covers whole, aligned units of [`Flash::WRITE`] bytes, each
/// programmed at most once between erases (the store never programs a unit twice, so
/// flashes with ECC per unit work). Addresses are relative to the region start.
pub trait Flash {
    /// Bytes per erase sector.
    const SECTOR: usize;
    /// Sectors in the region (at least 2; one half per slot).
    const SECTORS: usize;
    /// Program unit in bytes: a power of two, at most [`MAX_WRITE`].
    const WRITE: usize;
    /// Reads `buf.len()` bytes at `addr`.
    fn read(&mut self, addr: u32, buf: &mut [u8]) -> Result<(), FlashError>;
    /// Erases sector `sector` (0-based) to FFh.
    fn erase(&mut self, sector: u32) -> Result<(), FlashError>;
    /// Programs `data` at `addr` (both aligned to [`Flash::WRITE`]).
    fn write(&mut self, addr: u32, data: &[u8]) -> Result<(), FlashError>;
}

/// Errors of the [`ParamStore`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StoreError {
    /// No valid record in either slot.
    NoData,
    /// Valid records exist, but none with the requested layout.
    LayoutMismatch,
    /// The payload does not fit a slot ([`ParamStore::capacity`]) or the output buffer.
    TooLarge,
    /// The flash failed.
    Flash(FlashError),
}

impl From<FlashError> for StoreError {
    fn from(e: FlashError) -> Self {
        StoreError::Flash(e)
    }
}

/// "PST1": marks a record header.
const MAGIC: u32 = 0x3154_5350;
/// magic, layout, sequence, length, CRC.
const HEADER_LEN: usize = 20;
/// The commit unit repeats these bytes (none is FFh, so a torn program is visible).
const COMMIT: [u8; 4] = [0xC0, 0x4D, 0x17, 0x5A];
/// Read chunk for CRC checks (stack).
const CHUNK: usize = 64;

/// A valid record found in a slot.
#[derive(Debug, Clone, Copy)]
struct Record {
    slot: usize,
    layout: u32,
    seq: u32,
    len: usize,
}

/// `a` is newer than `b` in serial number arithmetic.
fn newer(a: u32, b: u32) -> bool {
    (a.wrapping_sub(b) as i32) > 0
}

fn round_up(n: usize, unit: usize) -> usize {
    n.div_ceil(unit).saturating_mul(unit)
}

fn addr(n: usize) -> Result<u32, StoreError> {
    u32::try_from(n).map_err(|_| StoreError::Flash(FlashError::OutOfRange))
}

fn le32(b: &[u8], at: usize) -> u32 {
    match b.get(at..at + 4) {
        Some(&[a, b, c, d]) => u32::from_le_bytes([a, b, c, d]),
        _ => 0,
    }
}

/// The two-slot parameter store over a [`Flash`].
#[derive(Clone, Debug)]
pub struct ParamStore<F: Flash> {
    flash: F,
}

impl<F: Flash> ParamStore<F> {
    /// Sectors per slot.
    const SLOT_SECTORS: usize = F::SECTORS / 2;
    /// Bytes per slot.
    const SLOT_LEN: usize = Self::SLOT_SECTORS * F::SECTOR;
    /// Header size including padding to the program unit.
    const HEAD: usize = HEADER_LEN.div_ceil(F::WRITE) * F::WRITE;

    /// A store over `flash`. Does not touch the flash.
    pub fn new(flash: F) -> Self {
        const {
            assert!(F::WRITE.is_power_of_two() && F::WRITE <= MAX_WRITE);
        }
        Self { flash }
    }

    /// The flash (for tests and fault injection).
    pub fn flash(&self) -> &F {
        &self.flash
    }

    /// The flash, mutable (for tests and fault injection).
    pub fn flash_mut(&mut self) -> &mut F {
        &mut self.flash
    }

    /// Gives the flash back.
    pub fn into_inner(self) -> F {
        self.flash
    }

    /// Largest payload in bytes that [`ParamStore::save`] accepts.
    pub fn capacity(&self) -> usize {
        let room = Self::SLOT_LEN.saturating_sub(Self::HEAD + F::WRITE);
        room / F::WRITE * F::WRITE
    }

    /// Loads the newest valid record with layout `layout` into `out`, returns its length.
    pub fn load(&mut self, layout: u32, out: &mut [u8]) -> Result<usize, StoreError> {
        let recs = [self.scan(0)?, self.scan(1)?];
        let mut best: Option<Record> = None;
        for r in recs.iter().flatten().filter(|r| r.layout == layout) {
            if best.is_none_or(|b| newer(r.seq, b.seq)) {
                best = Some(*r);
            }
        }
        let Some(rec) = best else {
            return Err(if recs.iter().any(Option::is_some) {
                StoreError::LayoutMismatch
            } else {
                StoreError::NoData
            });
        };
        let dst = out.get_mut(..rec.len).ok_or(StoreError::TooLarge)?;
        let at = addr(rec.slot * Self::SLOT_LEN + Self::HEAD)?;
        self.flash.read(at, dst)?;
        Ok(rec.len)
    }

    /// Saves `payload` under `layout` as the newest record (sequence = newest + 1) in the
    /// slot that does not hold the newest valid record.
    pub fn save(&mut self, payload: &[u8], layout: u32) -> Result<(), StoreError> {
        let len = payload.len();
        if len > self.capacity() {
            return Err(StoreError::TooLarge);
        }
        let newest = match (self.scan(0)?, self.scan(1)?) {
            (Some(a), Some(b)) => Some(if newer(b.seq, a.seq) { b } else { a }),
            (a, b) => a.or(b),
        };
        let (slot, seq) = match newest {
            Some(r) => (1 - r.slot, r.seq.wrapping_add(1)),
            None => (0, 1),
        };
        let len32 = addr(len)?;
        let base = slot * Self::SLOT_LEN;

        for s in 0..Self::SLOT_SECTORS {
            self.flash.erase(addr(slot * Self::SLOT_SECTORS + s)?)?;
        }

        let mut head = [0u8; 16];
        for (dst, v) in head.chunks_exact_mut(4).zip([MAGIC, layout, seq, len32]) {
            dst.copy_from_slice(&v.to_le_bytes());
        }
        let mut crc = Crc32::new();
        crc.update(&head);
        crc.update(payload);

        let mut buf = [0xFFu8; MAX_WRITE];
        let unit = buf.get_mut(..Self::HEAD).ok_or(StoreError::TooLarge)?;
        for (dst, src) in unit
            .iter_mut()
            .zip(head.iter().chain(&crc.finish().to_le_bytes()))
        {
            *dst = *src;
        }
        self.flash.write(addr(base)?, unit)?;

        let full = len / F::WRITE * F::WRITE;
        let (body, tail) = payload.split_at_checked(full).ok_or(StoreError::TooLarge)?;
        if !body.is_empty() {
            self.flash.write(addr(base + Self::HEAD)?, body)?;
        }
        if !tail.is_empty() {
            let unit = buf.get_mut(..F::WRITE).ok_or(StoreError::TooLarge)?;
            unit.fill(0xFF);
            for (dst, src) in unit.iter_mut().zip(tail) {
                *dst = *src;
            }
            self.flash.write(addr(base + Self::HEAD + full)?, unit)?;
        }

        let unit = buf.get_mut(..F::WRITE).ok_or(StoreError::TooLarge)?;
        for (dst, src) in unit.iter_mut().zip(COMMIT.iter().cycle()) {
            *dst = *src;
        }
        self.flash.write(addr(base + Self::commit_offset(len))?, unit)?;
        Ok(())
    }

    fn commit_offset(len: usize) -> usize {
        Self::HEAD + round_up(len, F::WRITE)
    }

    /// The record in `slot` when it is complete and its CRC matches.
    fn scan(&mut self, slot: usize) -> Result<Option<Record>, StoreError> {
        if self.capacity() == 0 {
            return Ok(None);
        }
        let base = slot * Self::SLOT_LEN;
        let mut head = [0u8; HEADER_LEN];
        self.flash.read(addr(base)?, &mut head)?;
        let len = le32(&head, 12) as usize;
        if le32(&head, 0) != MAGIC || len > self.capacity() {
            return Ok(None);
        }

        let mut buf = [0u8; MAX_WRITE];
        let unit = buf.get_mut(..F::WRITE).ok_or(StoreError::TooLarge)?;
        self.flash.read(addr(base + Self::commit_offset(len))?, unit)?;
        if !unit.iter().zip(COMMIT.iter().cycle()).all(|(a, b)| a == b) {
            return Ok(None);
        }

        let mut crc = Crc32::new();
        crc.update(head.get(..16).unwrap_or_default());
        let mut done = 0;
        while done < len {
            let n = (len - done).min(CHUNK);
            let chunk = buf.get_mut(..n).ok_or(StoreError::TooLarge)?;
            self.flash.read(addr(base + Self::HEAD + done)?, chunk)?;
            crc.update(chunk);
            done += n;
        }
        if crc.finish() != le32(&head, 16) {
            return Ok(None);
        }
        Ok(Some(Record {
            slot,
            layout: le32(&head, 4),
            seq: le32(&head, 8),
            len,
        }))
    }
}

#[cfg(test)]
mod tests;
