//! Firmware image slots A/B (issue 8, FoE firmware update).
//!
//! The flash region behind a [`store::Flash`] holds two firmware slots, A (first half of
//! the sectors) and B (second half). A new image is downloaded into the slot the running
//! firmware did **not** start from, checked against its CRC-32 at the end, and marked
//! *pending*; the next boot tries it (*trial*) and the image confirms itself once it runs
//! ([`BootSlots::confirm`]). A trial that was never confirmed is skipped at the next boot:
//! the previous, confirmed slot runs again (rollback).
//!
//! # The image file (what the master downloads, e.g. over FoE)
//!
//! ```text
//! offset 0   magic "SC6F" u32, body length u32, CRC-32/ISO-HDLC of the body u32,
//!            version u32 (all LE)                                  = IMAGE_HEADER_LEN bytes
//! offset 16  body (the firmware), `length` bytes
//! ```
//!
//! # A slot in flash
//!
//! ```text
//! 0          the image header, padded with FFh to a multiple of Flash::WRITE (H)
//! H          VALID unit:     "VAL1", sequence u32, 00h padding — written after the CRC check
//! H + W      TRIED unit:     "TRY1", 00h padding — written by the boot that first runs it
//! H + 2W     CONFIRMED unit: "CNF1", 00h padding — written by the running image
//! H + 3W     body
//! ```
//!
//! Every mark is one program unit written once after the slot's erase (NOR semantics,
//! see [`store::Flash`]), so the states only move forward:
//! erased/partial → pending (VALID) → trial (TRIED) → confirmed (CONFIRMED). A transfer
//! cut at any point leaves no VALID unit: the slot counts as empty and never boots.
//!
//! The boot decision is the pure function [`decide`] of the two [`SlotState`]s.
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

pub use store::{crc32, Crc32, Flash, FlashError, RamFlash, MAX_WRITE};

/// "SC6F": the image file's magic.
pub const IMAGE_MAGIC: u32 = 0x4636_4353;
/// Length of the image file's header.
pub const IMAGE_HEADER_LEN: usize = 16;

const VALID: [u8; 4] = *b"VAL1";
const TRIED: [u8; 4] = *b"TRY1";
const CONFIRMED: [u8; 4] = *b"CNF1";
/// Read chunk for the CRC check (stack).
const CHUNK: usize = 256;

/// One of the two slots.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Slot {
    /// First half of the region.
    A,
    /// Second half of the region.
    B,
}

impl Slot {
    /// 0 for A, 1 for B.
    pub const fn index(self) -> usize {
        match self {
            Slot::A => 0,
            Slot::B => 1,
        }
    }

    /// The other slot.
    pub const fn other(self) -> Slot {
        match self {
            Slot::A => Slot::B,
            Slot::B => Slot::A,
        }
    }
}

/// The image file's header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ImageHeader {
    /// Body length in bytes.
    pub length: u32,
    /// CRC-32/ISO-HDLC of the body.
    pub crc: u32,
    /// Version of the image (informational).
    pub version: u32,
}

impl ImageHeader {
    /// The header of `body` with `version`.
    pub fn for_body(body: &[u8], version: u32) -> Self {
        Self {
            length: u32::try_from(body.len()).unwrap_or(u32::MAX),
            crc: crc32(body),
            version,
        }
    }

    /// The header's bytes.
    pub fn to_bytes(&self) -> [u8; IMAGE_HEADER_LEN] {
        let mut b = [0u8; IMAGE_HEADER_LEN];
        for (dst, v) in b
            .chunks_exact_mut(4)
            .zip([IMAGE_MAGIC, self.length, self.crc, self.version])
        {
            dst.copy_from_slice(&v.to_le_bytes());
        }
        b
    }

    /// Parses a header; `None` when the magic is wrong or `b` is short.
    pub fn parse(b: &[u8]) -> Option<Self> {
        (le32(b, 0)? == IMAGE_MAGIC).then_some(Self {
            length: le32(b, 4)?,
            crc: le32(b, 8)?,
            version: le32(b, 12)?,
        })
    }
}

fn le32(b: &[u8], at: usize) -> Option<u32> {
    match b.get(at..at.checked_add(4)?)? {
        &[a, b, c, d] => Some(u32::from_le_bytes([a, b, c, d])),
        _ => None,
    }
}

/// What a slot holds, as the boot decision sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlotState {
    /// Nothing bootable: erased, a partial or failed download, or a CRC mismatch.
    Empty,
    /// A complete, checked image never started ("switch on the next boot").
    Pending {
        /// Sequence number (newer images have higher numbers).
        seq: u32,
    },
    /// Started once and not (yet) confirmed: at the next boot it has failed.
    Trial {
        /// Sequence number.
        seq: u32,
    },
    /// Started and confirmed itself.
    Confirmed {
        /// Sequence number.
        seq: u32,
    },
}

impl SlotState {
    /// The sequence number, `None` for an empty slot.
    pub const fn seq(self) -> Option<u32> {
        match self {
            SlotState::Empty => None,
            SlotState::Pending { seq } | SlotState::Trial { seq } | SlotState::Confirmed { seq } => Some(seq),
        }
    }
}

/// What the boot runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Decision {
    /// The slot to start.
    pub slot: Slot,
    /// Start it on trial: its TRIED mark is written before it starts, and it must
    /// confirm itself before the next boot.
    pub trial: bool,
    /// A slot that was on trial and never confirmed, skipped in favour of `slot`.
    pub rolled_back: Option<Slot>,
}

/// `a` is newer than `b` in serial number arithmetic.
fn newer(a: u32, b: u32) -> bool {
    (a.wrapping_sub(b) as i32) > 0
}

/// The newest slot whose state passes `pick`.
fn newest(states: [SlotState; 2], pick: impl Fn(SlotState) -> bool) -> Option<Slot> {
    let [a, b] = states;
    match (pick(a), pick(b), a.seq(), b.seq()) {
        (true, true, Some(sa), Some(sb)) => Some(if newer(sb, sa) { Slot::B } else { Slot::A }),
        (true, _, _, _) => Some(Slot::A),
        (_, true, _, _) => Some(Slot::B),
        _ => None,
    }
}

fn state_of(states: [SlotState; 2], slot: Slot) -> SlotState {
    let [a, b] = states;
    match slot {
        Slot::A => a,
        Slot::B => b,
    }
}

/// The boot decision from the two slot states (`[A, B]`), a pure function:
///
/// 1. a pending image (the newest, if both are) starts on trial;
/// 2. otherwise the newest confirmed image starts; a slot still on trial
///    (it never confirmed itself) is skipped: rollback;
/// 3. otherwise an image on trial starts again when it is all there is
///    (nothing to roll back to; it stays on trial);
/// 4. otherwise nothing can start (`None`).
pub fn decide(states: [SlotState; 2]) -> Option<Decision> {
    if let Some(slot) = newest(states, |s| matches!(s, SlotState::Pending { .. })) {
        return Some(Decision {
            slot,
            trial: true,
            rolled_back: None,
        });
    }
    if let Some(slot) = newest(states, |s| matches!(s, SlotState::Confirmed { .. })) {
        let other = slot.other();
        let rolled_back = matches!(state_of(states, other), SlotState::Trial { .. }).then_some(other);
        return Some(Decision {
            slot,
            trial: false,
            rolled_back,
        });
    }
    newest(states, |s| matches!(s, SlotState::Trial { .. })).map(|slot| Decision {
        slot,
        trial: false,
        rolled_back: None,
    })
}

/// Why an update step failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UpdateError {
    /// No download in progress.
    NotStarted,
    /// The running image is on trial: its confirmed predecessor in the other slot
    /// is the rollback target and must not be overwritten (confirm first).
    Unconfirmed,
    /// The file does not start with a valid image header.
    BadHeader,
    /// The image does not fit a slot, or more bytes arrived than the header announced.
    TooLarge,
    /// The transfer ended before the announced length.
    Incomplete,
    /// The CRC-32 of the body in flash does not match the header.
    Crc,
    /// The flash failed.
    Flash(FlashError),
}

impl From<FlashError> for UpdateError {
    fn from(e: FlashError) -> Self {
        UpdateError::Flash(e)
    }
}

/// A download into the inactive slot.
#[derive(Debug, Clone, Copy)]
struct Download {
    slot: Slot,
    /// File bytes received (header included).
    received: u32,
    header: [u8; IMAGE_HEADER_LEN],
    /// Body length from the header (valid once the header is complete).
    length: u32,
    /// Body bytes waiting for a full program unit.
    unit: [u8; MAX_WRITE],
    fill: usize,
    /// Sectors of the slot erased so far (from its start).
    erased: u32,
}

/// The two firmware slots over a [`Flash`].
#[derive(Clone, Debug)]
pub struct BootSlots<F: Flash> {
    flash: F,
    /// The slot the running firmware started from.
    active: Option<Slot>,
    /// The running firmware is on trial (not yet confirmed).
    trial: bool,
    download: Option<Download>,
}

fn addr(n: usize) -> Result<u32, FlashError> {
    u32::try_from(n).map_err(|_| FlashError::OutOfRange)
}

impl<F: Flash> BootSlots<F> {
    /// Sectors per slot.
    const SLOT_SECTORS: usize = F::SECTORS / 2;
    /// Bytes per slot.
    const SLOT_LEN: usize = Self::SLOT_SECTORS * F::SECTOR;
    /// Header size including padding to the program unit.
    const HEAD: usize = IMAGE_HEADER_LEN.div_ceil(F::WRITE) * F::WRITE;
    /// Offset of the body in a slot.
    const BODY: usize = Self::HEAD + 3 * F::WRITE;

    /// The slots over `flash`; nothing runs yet (see [`BootSlots::boot`]). Does not
    /// touch the flash.
    pub fn new(flash: F) -> Self {
        const {
            assert!(F::WRITE.is_power_of_two() && F::WRITE >= 8 && F::WRITE <= MAX_WRITE);
        }
        Self {
            flash,
            active: None,
            trial: false,
            download: None,
        }
    }

    /// The slots as a separate boot loader left them (it ran
    /// [`boot`](Self::boot) and started `slot`): the running image's view,
    /// on trial unless its slot carries the CONFIRMED mark. Reads (and
    /// CRC-checks) `slot` only; writes nothing.
    pub fn resume(flash: F, slot: Slot) -> Result<Self, FlashError> {
        let mut s = Self::new(flash);
        let state = s.state(slot)?;
        s.active = Some(slot);
        s.trial = matches!(state, SlotState::Trial { .. });
        Ok(s)
    }

    /// Offset of the image body (the firmware's first byte) in a slot:
    /// the header and the three mark units before it.
    pub const fn body_offset() -> usize {
        Self::BODY
    }

    /// Bytes per slot (slot A at 0, slot B at this offset of the region).
    pub const fn slot_len() -> usize {
        Self::SLOT_LEN
    }

    /// The flash (for tests and fault injection).
    pub fn flash_mut(&mut self) -> &mut F {
        &mut self.flash
    }

    /// Powers off: gives the flash back (a download in progress is lost).
    pub fn into_inner(self) -> F {
        self.flash
    }

    /// Largest image body a slot takes, bytes.
    pub fn capacity(&self) -> usize {
        Self::SLOT_LEN.saturating_sub(Self::BODY)
    }

    /// The slot the running firmware started from ([`BootSlots::boot`]).
    pub fn active(&self) -> Option<Slot> {
        self.active
    }

    /// Whether the running firmware is on trial (must [`confirm`](Self::confirm)).
    pub fn on_trial(&self) -> bool {
        self.trial
    }

    /// The slot a download goes to: the one the firmware did not start from (A
    /// when nothing started).
    pub fn inactive(&self) -> Slot {
        self.active.map_or(Slot::A, Slot::other)
    }

    /// Power-on: reads both slots (CRC-checked), [`decide`]s, writes the TRIED
    /// mark of a pending image and records the slot as the running one.
    pub fn boot(&mut self) -> Result<Option<Decision>, FlashError> {
        let states = self.states()?;
        let decision = decide(states);
        self.download = None;
        self.active = decision.map(|d| d.slot);
        self.trial = false;
        if let Some(d) = decision {
            if d.trial {
                self.mark(d.slot, 1, TRIED)?;
            }
            self.trial = d.trial || matches!(state_of(states, d.slot), SlotState::Trial { .. });
        }
        Ok(decision)
    }

    /// The running image confirms itself (call it after a successful start): its
    /// slot is kept from now on. Nothing to do when it is not on trial.
    pub fn confirm(&mut self) -> Result<(), FlashError> {
        match self.active {
            Some(slot) if self.trial => {
                self.mark(slot, 2, CONFIRMED)?;
                self.trial = false;
                Ok(())
            }
            _ => Ok(()),
        }
    }

    /// Both slots' states (`[A, B]`), CRC-checked.
    pub fn states(&mut self) -> Result<[SlotState; 2], FlashError> {
        Ok([self.state(Slot::A)?, self.state(Slot::B)?])
    }

    /// One slot's state; a slot whose body fails its CRC is [`SlotState::Empty`].
    pub fn state(&mut self, slot: Slot) -> Result<SlotState, FlashError> {
        let base = slot.index() * Self::SLOT_LEN;
        let mut head = [0u8; IMAGE_HEADER_LEN];
        self.flash.read(addr(base)?, &mut head)?;
        let Some(header) = ImageHeader::parse(&head) else {
            return Ok(SlotState::Empty);
        };
        let mut marks = [[0u8; 8]; 3];
        for (i, m) in marks.iter_mut().enumerate() {
            self.flash.read(addr(base + Self::HEAD + i * F::WRITE)?, m)?;
        }
        let [valid, tried, confirmed] = marks;
        if valid.get(..4) != Some(&VALID[..]) || header.length as usize > self.capacity() {
            return Ok(SlotState::Empty);
        }
        if self.body_crc(slot, header.length)? != header.crc {
            return Ok(SlotState::Empty);
        }
        let seq = le32(&valid, 4).unwrap_or(0);
        Ok(if confirmed.get(..4) == Some(&CONFIRMED[..]) {
            SlotState::Confirmed { seq }
        } else if tried.get(..4) == Some(&TRIED[..]) {
            SlotState::Trial { seq }
        } else {
            SlotState::Pending { seq }
        })
    }

    /// The header of the image in `slot` (whatever its state).
    pub fn header(&mut self, slot: Slot) -> Result<Option<ImageHeader>, FlashError> {
        let mut head = [0u8; IMAGE_HEADER_LEN];
        self.flash.read(addr(slot.index() * Self::SLOT_LEN)?, &mut head)?;
        Ok(ImageHeader::parse(&head))
    }

    fn body_crc(&mut self, slot: Slot, length: u32) -> Result<u32, FlashError> {
        let base = slot.index() * Self::SLOT_LEN + Self::BODY;
        let len = length as usize;
        let mut crc = Crc32::new();
        let mut buf = [0u8; CHUNK];
        let mut done = 0;
        while done < len {
            let n = (len - done).min(CHUNK);
            let chunk = buf.get_mut(..n).ok_or(FlashError::OutOfRange)?;
            self.flash.read(addr(base + done)?, chunk)?;
            crc.update(chunk);
            done += n;
        }
        Ok(crc.finish())
    }

    /// Writes mark `n` (0 VALID, 1 TRIED, 2 CONFIRMED) of `slot`: `tag`, then
    /// `extra` (LE), 00h padding.
    fn mark_with(&mut self, slot: Slot, n: usize, tag: [u8; 4], extra: u32) -> Result<(), FlashError> {
        let mut unit = [0u8; MAX_WRITE];
        let u = unit.get_mut(..F::WRITE).ok_or(FlashError::OutOfRange)?;
        for (dst, src) in u.iter_mut().zip(tag.iter().chain(&extra.to_le_bytes())) {
            *dst = *src;
        }
        let at = slot.index() * Self::SLOT_LEN + Self::HEAD + n * F::WRITE;
        self.flash.write(addr(at)?, u)
    }

    fn mark(&mut self, slot: Slot, n: usize, tag: [u8; 4]) -> Result<(), FlashError> {
        self.mark_with(slot, n, tag, 0)
    }

    /// Whether a download is in progress.
    pub fn downloading(&self) -> bool {
        self.download.is_some()
    }

    /// File bytes received by the download in progress.
    pub fn received(&self) -> u32 {
        self.download.map_or(0, |d| d.received)
    }

    /// Starts a download into the inactive slot: erases its first sector (the old
    /// content of that slot is gone from here on). Replaces a download in progress.
    pub fn begin(&mut self) -> Result<Slot, UpdateError> {
        self.download = None;
        if self.trial {
            return Err(UpdateError::Unconfirmed);
        }
        if self.capacity() == 0 {
            return Err(UpdateError::TooLarge);
        }
        let slot = self.inactive();
        self.flash.erase(addr(slot.index() * Self::SLOT_SECTORS)?)?;
        self.download = Some(Download {
            slot,
            received: 0,
            header: [0xFF; IMAGE_HEADER_LEN],
            length: 0,
            unit: [0xFF; MAX_WRITE],
            fill: 0,
            erased: 1,
        });
        Ok(slot)
    }

    /// The next bytes of the image file. An error ends the download (the slot stays
    /// without VALID mark: empty).
    pub fn write(&mut self, data: &[u8]) -> Result<(), UpdateError> {
        let mut d = self.download.take().ok_or(UpdateError::NotStarted)?;
        let r = self.feed(&mut d, data);
        if r.is_ok() {
            self.download = Some(d);
        }
        r
    }

    fn feed(&mut self, d: &mut Download, mut data: &[u8]) -> Result<(), UpdateError> {
        let have = d.received as usize;
        if have < IMAGE_HEADER_LEN {
            let n = (IMAGE_HEADER_LEN - have).min(data.len());
            let (head, rest) = data.split_at_checked(n).ok_or(UpdateError::BadHeader)?;
            let dst = d.header.get_mut(have..have + n).ok_or(UpdateError::BadHeader)?;
            dst.copy_from_slice(head);
            d.received += n as u32;
            data = rest;
            if d.received as usize == IMAGE_HEADER_LEN {
                let h = ImageHeader::parse(&d.header).ok_or(UpdateError::BadHeader)?;
                if h.length as usize > self.capacity() {
                    return Err(UpdateError::TooLarge);
                }
                d.length = h.length;
                let mut unit = [0xFFu8; MAX_WRITE];
                let u = unit.get_mut(..Self::HEAD).ok_or(UpdateError::TooLarge)?;
                for (dst, src) in u.iter_mut().zip(d.header) {
                    *dst = src;
                }
                self.flash.write(addr(d.slot.index() * Self::SLOT_LEN)?, u)?;
            }
        }
        let body_done = (d.received as usize).saturating_sub(IMAGE_HEADER_LEN);
        if body_done + data.len() > d.length as usize {
            return Err(UpdateError::TooLarge);
        }
        for &b in data {
            let slot_unit = d.unit.get_mut(d.fill).ok_or(UpdateError::TooLarge)?;
            *slot_unit = b;
            d.fill += 1;
            d.received += 1;
            if d.fill == F::WRITE {
                self.flush(d)?;
            }
        }
        Ok(())
    }

    /// Programs the buffered unit (padded with FFh), erasing the sectors it reaches.
    fn flush(&mut self, d: &mut Download) -> Result<(), UpdateError> {
        if d.fill == 0 {
            return Ok(());
        }
        let body_end = (d.received as usize).saturating_sub(IMAGE_HEADER_LEN);
        let at = Self::BODY + (body_end - d.fill) / F::WRITE * F::WRITE;
        let end_sector = (at + F::WRITE).div_ceil(F::SECTOR);
        while (d.erased as usize) < end_sector {
            self.flash
                .erase(addr(d.slot.index() * Self::SLOT_SECTORS + d.erased as usize)?)?;
            d.erased += 1;
        }
        let unit = d.unit.get_mut(..F::WRITE).ok_or(UpdateError::TooLarge)?;
        if let Some(pad) = unit.get_mut(d.fill..) {
            pad.fill(0xFF);
        }
        self.flash
            .write(addr(d.slot.index() * Self::SLOT_LEN + at)?, unit)?;
        d.fill = 0;
        Ok(())
    }

    /// Ends the download: checks the length and the CRC-32 of the body as it is in
    /// flash, then marks the slot pending (VALID with the next sequence number) so
    /// the next [`boot`](Self::boot) tries it. On an error the slot stays empty.
    pub fn finish(&mut self) -> Result<Slot, UpdateError> {
        let mut d = self.download.take().ok_or(UpdateError::NotStarted)?;
        if (d.received as usize) < IMAGE_HEADER_LEN
            || d.received as usize - IMAGE_HEADER_LEN != d.length as usize
        {
            return Err(UpdateError::Incomplete);
        }
        self.flush(&mut d)?;
        let header = ImageHeader::parse(&d.header).ok_or(UpdateError::BadHeader)?;
        if self.body_crc(d.slot, header.length)? != header.crc {
            return Err(UpdateError::Crc);
        }
        let seq = match self.state(d.slot.other())?.seq() {
            Some(s) => s.wrapping_add(1),
            None => 1,
        };
        self.mark_with(d.slot, 0, VALID, seq)?;
        Ok(d.slot)
    }

    /// Drops a download in progress (the slot stays without VALID mark: empty).
    pub fn abort(&mut self) {
        self.download = None;
    }
}

/// A flash of nothing: every access fails. The `B` of a drive without firmware
/// slots.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoFlash;

impl Flash for NoFlash {
    const SECTOR: usize = 8;
    const SECTORS: usize = 2;
    const WRITE: usize = 8;
    fn read(&mut self, _addr: u32, _buf: &mut [u8]) -> Result<(), FlashError> {
        Err(FlashError::Device)
    }
    fn erase(&mut self, _sector: u32) -> Result<(), FlashError> {
        Err(FlashError::Device)
    }
    fn write(&mut self, _addr: u32, _data: &[u8]) -> Result<(), FlashError> {
        Err(FlashError::Device)
    }
}

#[cfg(test)]
mod tests;
