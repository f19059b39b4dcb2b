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
//! offset 0   magic "SC6F", body length, CRC-32/ISO-HDLC of the body, version,
//!            format (2), load address, security counter, reserved (0): u32 LE each
//! offset 32  Ed25519 signature (64 bytes) of SHA-256(bytes 0..32 ‖ body)
//! offset 96  body (the firmware), `length` bytes      (IMAGE_HEADER_LEN = 96)
//! ```
//!
//! The load address is where the body is linked to run: the CPU address of the
//! body in the slot it executes in place from ([`BootSlots::load_address`]), so
//! an image is built for slot A or for slot B. The security counter is the
//! downgrade protection: see [`BootSlots::boot_verified`]. Signing and
//! verification: module `sign` ([`verify_image`], [`BootSlots::verify`]).
//!
//! # A slot in flash
//!
//! ```text
//! 0          the image header, padded with FFh to a multiple of Flash::WRITE (H)
//! H          VALID unit:     "VAL1", sequence u32, 00h padding — written after the checks
//! H + W      TRIED unit:     "TRY1", 00h padding — written by the boot that first runs it
//! H + 2W     CONFIRMED unit: "CNF1", 00h padding — written by the running image
//! B          body, B = H + 3W rounded up to BODY_ALIGN (1024): a vector table can sit
//!            at the body's start ([`BootSlots::body_offset`])
//! ```
//!
//! Every mark is one program unit written once after the slot's erase (NOR semantics,
//! see [`store::Flash`]), so the states only move forward:
//! erased/partial → pending (VALID) → trial (TRIED) → confirmed (CONFIRMED). A transfer
//! cut at any point leaves no VALID unit: the slot counts as empty and never boots; a
//! VALID unit cut after its tag (its sequence number still reads FFFFFFFFh) does not
//! count either.
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

pub use store::{crc32, Crc32, Flash, FlashError, PowerCut, RamFlash, MAX_WRITE};

mod sign;
mod verified;
#[cfg(feature = "sign")]
pub use sign::public_key;
use sign::CHUNK;
pub use sign::{
    boot_api_code, boot_api_result, ed25519_verify, ed25519_verify_builtin, parse_key_hex, verify_digest,
    verify_file, verify_image, BootApi, ImageHasher, ImageHeader, VerifyError, BOOT_API_MAGIC,
    BOOT_API_OFFSET, DEV_PUBLIC_KEY, FIRMWARE_KEY_IS_DEVELOPMENT, FIRMWARE_PUBLIC_KEY, IMAGE_FORMAT,
    IMAGE_HEADER_LEN, IMAGE_MAGIC, KEY_LEN, SIGNATURE_LEN, SIGNED_HEADER_LEN,
};

/// Alignment of the body in a slot (its offset from the slot's start): enough
/// for a Cortex-M vector table of up to 256 entries at the body's start.
pub const BODY_ALIGN: usize = 1024;

const VALID: [u8; 4] = *b"VAL1";
/// A VALID unit's sequence number as erased flash reads it: the unit was
/// cut after its tag, so it does not count (no sequence number is ever
/// this value).
const ERASED_SEQ: u32 = u32::MAX;
const TRIED: [u8; 4] = *b"TRY1";
const CONFIRMED: [u8; 4] = *b"CNF1";

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
    /// The signature does not verify with the drive's public key
    /// ([`BootSlots::finish_verified`]).
    Signature,
    /// The image is linked for another address than the body of the slot it
    /// goes to ([`BootSlots::load_address`]).
    LoadAddress,
    /// The image's security counter is below the running image's
    /// ([`BootSlots::security_floor`]): a downgrade.
    Downgrade,
    /// The flash failed.
    Flash(FlashError),
}

impl From<FlashError> for UpdateError {
    fn from(e: FlashError) -> Self {
        UpdateError::Flash(e)
    }
}

impl From<VerifyError> for UpdateError {
    fn from(e: VerifyError) -> Self {
        match e {
            VerifyError::Header => UpdateError::BadHeader,
            VerifyError::Crc => UpdateError::Crc,
            VerifyError::Signature | VerifyError::Key => UpdateError::Signature,
            VerifyError::LoadAddress => UpdateError::LoadAddress,
            VerifyError::Flash(e) => UpdateError::Flash(e),
        }
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
    /// CPU address of flash offset 0 (the load addresses of the slots).
    base: u32,
    /// Lowest security counter a download may have (see [`BootSlots::security_floor`]).
    floor: u32,
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
    const BODY: usize = (Self::HEAD + 3 * F::WRITE).div_ceil(BODY_ALIGN) * BODY_ALIGN;

    /// The slots over `flash` mapped at CPU address 0; nothing runs yet (see
    /// [`BootSlots::boot`]). Does not touch the flash.
    pub fn new(flash: F) -> Self {
        Self::with_base(flash, 0)
    }

    /// The slots over `flash` whose offset 0 the CPU reads at `base` (the
    /// load addresses of the slots, [`BootSlots::load_address`]).
    pub fn with_base(flash: F, base: u32) -> Self {
        const {
            assert!(F::WRITE.is_power_of_two() && F::WRITE >= 8 && F::WRITE <= MAX_WRITE);
        }
        Self {
            flash,
            active: None,
            trial: false,
            download: None,
            base,
            floor: 0,
        }
    }

    /// The slots as a separate boot loader left them (it ran
    /// [`boot`](Self::boot) and started `slot`): the running image's view,
    /// on trial unless its slot carries the CONFIRMED mark, the flash mapped
    /// at CPU address 0 (see [`resume_with_base`](Self::resume_with_base)).
    /// Reads (and CRC-checks) `slot` only; writes nothing.
    pub fn resume(flash: F, slot: Slot) -> Result<Self, FlashError> {
        Self::resume_with_base(flash, 0, slot)
    }

    /// [`resume`](Self::resume) with the flash's offset 0 at CPU address
    /// `base` ([`with_base`](Self::with_base)); the security floor for
    /// downloads is the running image's security counter.
    pub fn resume_with_base(flash: F, base: u32, slot: Slot) -> Result<Self, FlashError> {
        let mut s = Self::with_base(flash, base);
        let state = s.state(slot)?;
        s.active = Some(slot);
        s.trial = matches!(state, SlotState::Trial { .. });
        s.floor = s.header(slot)?.map_or(0, |h| h.security_counter);
        Ok(s)
    }

    /// Where the body starts in a slot (bytes from the slot's start): after the
    /// header and the marks, a multiple of [`BODY_ALIGN`].
    pub const fn body_offset() -> usize {
        Self::BODY
    }

    /// Bytes per slot (slot A at 0, slot B at this offset of the region).
    pub const fn slot_len() -> usize {
        Self::SLOT_LEN
    }

    /// The load address an image for `slot` must have: the CPU address of the
    /// body in that slot.
    pub fn load_address(&self, slot: Slot) -> u32 {
        let off = slot.index() * Self::SLOT_LEN + Self::BODY;
        self.base.wrapping_add(u32::try_from(off).unwrap_or(u32::MAX))
    }

    /// The lowest security counter a download may have: the running image's,
    /// or the higher floor [`BootSlots::boot_verified`] found.
    pub fn security_floor(&self) -> u32 {
        self.floor
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
        self.start(states, 0)
    }

    /// Runs the decision over `states`; `floor` is the lowest security counter
    /// for downloads (raised to the running image's).
    fn start(&mut self, states: [SlotState; 2], floor: u32) -> Result<Option<Decision>, FlashError> {
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
        let running = match decision {
            Some(d) => self.header(d.slot)?.map_or(0, |h| h.security_counter),
            None => 0,
        };
        self.floor = floor.max(running);
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
        let Some((header, state)) = self.marks(slot)? else {
            return Ok(SlotState::Empty);
        };
        if self.body_crc(slot, header.length)? != header.crc {
            return Ok(SlotState::Empty);
        }
        Ok(state)
    }

    /// The header and the state of `slot` by its marks, the body unchecked
    /// (`None`: no header, no VALID mark, or a body larger than a slot).
    fn marks(&mut self, slot: Slot) -> Result<Option<(ImageHeader, SlotState)>, FlashError> {
        let base = slot.index() * Self::SLOT_LEN;
        let Some(header) = self.header(slot)? else {
            return Ok(None);
        };
        let mut marks = [[0u8; 8]; 3];
        for (i, m) in marks.iter_mut().enumerate() {
            self.flash.read(addr(base + Self::HEAD + i * F::WRITE)?, m)?;
        }
        let [valid, tried, confirmed] = marks;
        if valid.get(..4) != Some(&VALID[..]) || header.length as usize > self.capacity() {
            return Ok(None);
        }
        let seq = le32(&valid, 4).unwrap_or(ERASED_SEQ);
        if seq == ERASED_SEQ {
            // the VALID unit was cut after its tag: not committed
            return Ok(None);
        }
        Ok(Some((
            header,
            if confirmed.get(..4) == Some(&CONFIRMED[..]) {
                SlotState::Confirmed { seq }
            } else if tried.get(..4) == Some(&TRIED[..]) {
                SlotState::Trial { seq }
            } else {
                SlotState::Pending { seq }
            },
        )))
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
                if h.load_address != self.load_address(d.slot) {
                    return Err(UpdateError::LoadAddress);
                }
                if h.security_counter < self.floor {
                    return Err(UpdateError::Downgrade);
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
    /// flash (not the signature: see [`finish_verified`](Self::finish_verified)),
    /// then marks the slot pending (VALID with the next sequence number) so the
    /// next [`boot`](Self::boot) tries it. On an error the slot stays empty.
    pub fn finish(&mut self) -> Result<Slot, UpdateError> {
        self.finish_with(None)
    }

    /// [`finish`](Self::finish) that also verifies the image in flash against
    /// `public_key` ([`BootSlots::verify`]: CRC-32, signature, load address)
    /// and its security counter against [`security_floor`](Self::security_floor).
    /// A refused image gets no VALID mark: the slot stays empty.
    pub fn finish_verified(&mut self, public_key: &[u8; KEY_LEN]) -> Result<Slot, UpdateError> {
        self.finish_with(Some(public_key))
    }

    fn finish_with(&mut self, public_key: Option<&[u8; KEY_LEN]>) -> Result<Slot, UpdateError> {
        let mut d = self.download.take().ok_or(UpdateError::NotStarted)?;
        if (d.received as usize) < IMAGE_HEADER_LEN
            || d.received as usize - IMAGE_HEADER_LEN != d.length as usize
        {
            return Err(UpdateError::Incomplete);
        }
        self.flush(&mut d)?;
        let header = ImageHeader::parse(&d.header).ok_or(UpdateError::BadHeader)?;
        match public_key {
            Some(key) => {
                let h = self.verify(d.slot, key)?;
                if h != header {
                    return Err(UpdateError::BadHeader);
                }
            }
            None => {
                if self.body_crc(d.slot, header.length)? != header.crc {
                    return Err(UpdateError::Crc);
                }
            }
        }
        if header.security_counter < self.floor {
            return Err(UpdateError::Downgrade);
        }
        let seq = match self.state(d.slot.other())?.seq() {
            // never the erased pattern (a cut VALID unit reads so)
            Some(s) if s.wrapping_add(1) == ERASED_SEQ => 0,
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
#[cfg(test)]
mod tests_sign;
