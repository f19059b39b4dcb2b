//! The boot loader's logic (issue 18): which image to start, and where.
//!
//! The boot loader is a small image at the start of flash. At every reset it
//!
//! 1. reads both firmware slots and runs the A/B boot decision of `crates/boot`
//!    through [`BootSlots::boot`], which also writes the TRIED mark of a pending
//!    image (it starts on trial) and rolls back a trial that never confirmed itself;
//! 2. checks the chosen image ([`check_image`]: the one place where an image is
//!    judged before it runs), its Ed25519 signature included, against the public
//!    key built into the boot loader ([`PUBLIC_KEY`]);
//! 3. starts it in place (direct execute-in-place, as MCUboot's direct-XIP mode
//!    does): VTOR = the slot's body address, MSP = word 0 of the vector table found
//!    there, jump to word 1, the reset vector. Images are linked for their slot
//!    (`memory.x` per slot), so nothing is copied.
//!
//! [`select`] does 1 and 2 and returns an [`Outcome`]; the jump itself (a few
//! instructions of `cortex_m::asm::bootload`) and the logging are the binaries'
//! (`firmware/src/bin/boot_*.rs`). Nothing here touches hardware: a slot region is
//! any [`Flash`], so the host tests run the whole decision on RAM.
//!
//! The running image confirms itself through [`BootSlots::resume`] and
//! [`BootSlots::confirm`] once it reached its confirmation point.
//!
//! [`MemFlash`] is NOR flash over a byte slice with an optional [`Mirror`] of every
//! change (the QEMU images keep their flash file up to date with it; the host tool
//! `tools/flash-compose` lays out that file with it). [`mps2`] and [`xmc4800`] are
//! the two layouts.
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

pub use boot::{
    boot_api_code, boot_api_result, decide, ed25519_verify, ed25519_verify_builtin, verify_image, BootApi,
    BootSlots, Decision, Flash, FlashError, ImageHeader, Slot, SlotState, VerifyError, BOOT_API_MAGIC,
    BOOT_API_OFFSET, IMAGE_HEADER_LEN, KEY_LEN, SIGNATURE_LEN,
};

/// The public key images must be signed with, built into the boot loader:
/// [`boot::FIRMWARE_PUBLIC_KEY`] (the 64 hex digits of `SC6_FIRMWARE_PUBLIC_KEY`
/// when `crates/boot` is built, else the **development** key
/// `keys/dev-ed25519.pub`), the same key the application's FoE path checks.
pub const PUBLIC_KEY: [u8; KEY_LEN] = boot::FIRMWARE_PUBLIC_KEY;

mod mem;
pub use mem::{MemFlash, Mirror, NoMirror};

/// Where the slot region is mapped for execution and where a stack may point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    /// Address the CPU executes the slot region's byte 0 at (slot A's header).
    pub region_xip: u32,
    /// Lowest RAM address (an initial stack pointer must be above it).
    pub ram_start: u32,
    /// One past the highest RAM address (an initial stack pointer may equal it).
    pub ram_end: u32,
}

impl Layout {
    /// Execution address of `slot`'s body (its vector table) for flash `F`.
    pub fn body_address<F: Flash>(&self, slot: Slot) -> Option<u32> {
        let off = slot
            .index()
            .checked_mul(BootSlots::<F>::slot_len())?
            .checked_add(BootSlots::<F>::body_offset())?;
        self.region_xip.checked_add(u32::try_from(off).ok()?)
    }

    /// The slot whose body starts at `vtor` (what a running image finds in
    /// SCB.VTOR), `None` for any other address.
    pub fn slot_at<F: Flash>(&self, vtor: u32) -> Option<Slot> {
        [Slot::A, Slot::B]
            .into_iter()
            .find(|&s| self.body_address::<F>(s) == Some(vtor))
    }
}

/// Where and how to start an image: the values the jump needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Entry {
    /// The image's vector table (its body address): written to SCB.VTOR.
    pub vtor: u32,
    /// Word 0 of the vector table: the initial main stack pointer.
    pub msp: u32,
    /// Word 1: the reset handler (Thumb bit set).
    pub reset: u32,
}

/// Why a slot's image is not started although the boot decision chose it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFault {
    /// The slot holds no image that passes `crates/boot`'s checks (header, VALID
    /// mark, length, CRC-32 of the body).
    NotBootable,
    /// The Ed25519 signature does not verify with the boot loader's key (signed
    /// with another key, changed after signing, or unsigned).
    Signature,
    /// The header's load address is not the body address of the slot the image
    /// is in.
    LoadAddress,
    /// The body address is not a valid VTOR value (bits 6..0 must be zero).
    Misaligned(u32),
    /// Word 0 is not a stack pointer into RAM.
    BadStack(u32),
    /// Word 1 is not a Thumb address inside the image's body: the image was linked
    /// for another slot (or is not a Cortex-M image).
    BadReset(u32),
    /// The flash failed while the image was read.
    Flash(FlashError),
}

impl From<FlashError> for ImageFault {
    fn from(e: FlashError) -> Self {
        ImageFault::Flash(e)
    }
}

/// What the boot loader does after [`select`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Start an image.
    Start(Start),
    /// Nothing can start: stay in the safe loop.
    Halt {
        /// The flash failed while the slots were read (else: no slot holds a
        /// bootable image).
        error: Option<FlashError>,
        /// The chosen slot's fault, when the decision found one but it failed
        /// [`check_image`] and the other slot has no image that ran before and
        /// passes it.
        fault: Option<(Slot, ImageFault)>,
    },
}

/// An image to start, and how it was chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Start {
    /// Its slot.
    pub slot: Slot,
    /// Where to jump.
    pub entry: Entry,
    /// The header's version.
    pub version: u32,
    /// The boot decision (its `slot` differs from [`Start::slot`] after a fallback).
    pub decision: Decision,
    /// The marks could not be written ([`BootSlots::boot`] failed with this error):
    /// a pending image is not started (it could not be marked TRIED, so a failing
    /// one would be retried forever); the decision is then made without it.
    pub marks_failed: Option<FlashError>,
    /// The decision's slot failed [`check_image`] with this fault; the other slot
    /// (confirmed or on trial: an image that ran before) starts instead.
    pub fallback: Option<ImageFault>,
}

/// The image check before a start: **the one place where the boot loader judges
/// an image.**
///
/// The slot must be bootable as `crates/boot` sees it ([`BootSlots::state`]:
/// image header, VALID mark, length within the slot, CRC-32 of the body; the
/// [`BootSlots::boot`] before this already ran the same check); its image must
/// verify with `public_key` ([`BootSlots::verify`]: the Ed25519 signature over
/// SHA-256 of the header and the body as they are in flash, and the header's
/// load address against the slot's; `slots` must be made with
/// [`BootSlots::with_base`]`(flash, layout.region_xip)`); then the body address
/// must be a valid VTOR value, word 0 of its vector table a stack pointer into
/// RAM and word 1 a Thumb address inside the body (an image linked for the
/// other slot fails here).
pub fn check_image<F: Flash>(
    slots: &mut BootSlots<F>,
    slot: Slot,
    layout: &Layout,
    public_key: &[u8; KEY_LEN],
) -> Result<Entry, ImageFault> {
    if slots.state(slot)? == SlotState::Empty {
        return Err(ImageFault::NotBootable);
    }
    let header = slots.verify(slot, public_key).map_err(|e| match e {
        VerifyError::Signature | VerifyError::Key => ImageFault::Signature,
        VerifyError::LoadAddress => ImageFault::LoadAddress,
        VerifyError::Header | VerifyError::Crc => ImageFault::NotBootable,
        VerifyError::Flash(e) => ImageFault::Flash(e),
    })?;
    let vtor = layout
        .body_address::<F>(slot)
        .ok_or(ImageFault::Misaligned(u32::MAX))?;
    if vtor & 0x7F != 0 {
        return Err(ImageFault::Misaligned(vtor));
    }
    let at = slot
        .index()
        .checked_mul(BootSlots::<F>::slot_len())
        .and_then(|o| o.checked_add(BootSlots::<F>::body_offset()))
        .and_then(|o| u32::try_from(o).ok())
        .ok_or(FlashError::OutOfRange)?;
    let mut words = [0u8; 8];
    slots.flash_mut().read(at, &mut words)?;
    let [m0, m1, m2, m3, r0, r1, r2, r3] = words;
    let msp = u32::from_le_bytes([m0, m1, m2, m3]);
    let reset = u32::from_le_bytes([r0, r1, r2, r3]);
    if msp <= layout.ram_start || msp > layout.ram_end || msp % 4 != 0 {
        return Err(ImageFault::BadStack(msp));
    }
    let target = reset & !1;
    let body_end = vtor.saturating_add(header.length);
    if reset & 1 == 0 || target < vtor.saturating_add(8) || target >= body_end {
        return Err(ImageFault::BadReset(reset));
    }
    Ok(Entry { vtor, msp, reset })
}

/// Power-on: the boot decision ([`BootSlots::boot`]) and the check of the chosen
/// image ([`check_image`] with `public_key`); when that fails, the other slot if
/// it holds an image that passes. See [`Outcome`].
pub fn select<F: Flash>(slots: &mut BootSlots<F>, layout: &Layout, public_key: &[u8; KEY_LEN]) -> Outcome {
    let (decision, marks_failed) = match slots.boot() {
        Ok(d) => (d, None),
        Err(e) => match slots.states() {
            // no marks can be written: never start a pending image (it would
            // stay pending and be tried at every reset); the rest as decided
            Ok(states) => (decide(states.map(without_pending)), Some(e)),
            Err(e) => {
                return Outcome::Halt {
                    error: Some(e),
                    fault: None,
                }
            }
        },
    };
    let Some(decision) = decision else {
        return Outcome::Halt {
            error: None,
            fault: None,
        };
    };
    let start = |slot, entry, fallback, slots: &mut BootSlots<F>| {
        let version = slots.header(slot).ok().flatten().map_or(0, |h| h.version);
        Outcome::Start(Start {
            slot,
            entry,
            version,
            decision,
            marks_failed,
            fallback,
        })
    };
    match check_image(slots, decision.slot, layout, public_key) {
        Ok(entry) => start(decision.slot, entry, None, slots),
        Err(fault) => {
            // the other slot, if it holds an image that ran before (a pending
            // one is started only on trial, through the decision)
            let other = decision.slot.other();
            let ran = matches!(
                slots.state(other),
                Ok(SlotState::Confirmed { .. } | SlotState::Trial { .. })
            );
            match check_image(slots, other, layout, public_key) {
                Ok(entry) if ran => start(other, entry, Some(fault), slots),
                _ => Outcome::Halt {
                    error: None,
                    fault: Some((decision.slot, fault)),
                },
            }
        }
    }
}

fn without_pending(s: SlotState) -> SlotState {
    match s {
        SlotState::Pending { .. } => SlotState::Empty,
        other => other,
    }
}

/// One slot's state as a short word for the boot log.
pub fn state_name(s: SlotState) -> &'static str {
    match s {
        SlotState::Empty => "empty",
        SlotState::Pending { .. } => "pending",
        SlotState::Trial { .. } => "on trial",
        SlotState::Confirmed { .. } => "confirmed",
    }
}

/// A slot's letter for the boot log.
pub fn slot_name(s: Slot) -> &'static str {
    match s {
        Slot::A => "A",
        Slot::B => "B",
    }
}

/// An [`ImageFault`] as a short phrase for the boot log.
pub fn fault_name(f: ImageFault) -> &'static str {
    match f {
        ImageFault::NotBootable => "no bootable image",
        ImageFault::Signature => "signature does not verify with the boot loader's key",
        ImageFault::LoadAddress => "header's load address is not this slot's",
        ImageFault::Misaligned(_) => "body address is no VTOR value",
        ImageFault::BadStack(_) => "initial stack pointer outside RAM",
        ImageFault::BadReset(_) => "reset vector outside the image (linked for another slot?)",
        ImageFault::Flash(_) => "flash read failed",
    }
}

/// QEMU's `mps2-an386` (the boot-loader scenarios of `scripts/cross boot-qemu`):
/// its 4 MiB at 0 are RAM, standing in for flash, filled from a flash file.
///
/// ```text
/// 0x0000_0000  boot loader            32 KiB (budget 24 KiB)
/// 0x0000_8000  slot A  64 KiB: header, marks, body at 0x0000_8400
/// 0x0001_8000  slot B  64 KiB: body at 0x0001_8400
/// 0x0002_8000  end of the flash file
/// ```
///
/// The sectors (4 KiB) and program unit (256 bytes, as the XMC4800's page) are
/// this model's choice.
pub mod mps2 {
    use super::{Layout, MemFlash};

    /// Address (and flash-file offset) of the slot region.
    pub const SLOTS_BASE: u32 = 0x0000_8000;
    /// Erase sector.
    pub const SECTOR: usize = 4096;
    /// Sectors of the slot region (half per slot).
    pub const SECTORS: usize = 32;
    /// Program unit.
    pub const WRITE: usize = 256;
    /// Bytes of the slot region.
    pub const REGION_LEN: usize = SECTOR * SECTORS;
    /// Bytes of the whole flash file (boot loader and both slots).
    pub const FILE_LEN: usize = SLOTS_BASE as usize + REGION_LEN;
    /// The slot region as flash.
    pub type SlotFlash<'a, M> = MemFlash<'a, M, SECTOR, SECTORS, WRITE>;
    /// Execution addresses: the region runs where it is (RAM at 0), RAM for
    /// data at 0x2000_0000 (128 KiB used, as the images' memory.x say).
    pub const LAYOUT: Layout = Layout {
        region_xip: SLOTS_BASE,
        ram_start: 0x2000_0000,
        ram_end: 0x2002_0000,
    };
}

/// The reference board, Infineon XMC4800 (2 MiB program flash; docs/flashing.md,
/// "Flash layout"). The slot region is the logical sectors S9..S12 (4 × 256 KiB),
/// 512 KiB per slot; it is read through the uncached alias 0x0C00_0000 (a mark just
/// programmed is seen at once) and executed through the cached one, 0x0800_0000.
///
/// ```text
/// 0x0C00_0000  S0..S1   boot loader (32 KiB, budget 24 KiB); S2..S3 unused
///                       (same physical sector: never erased in the field)
/// 0x0C01_0000  S4..S7   parameter store (its own 64 KiB physical sector)
/// 0x0C02_0000  S8       reserved (128 KiB)
/// 0x0C04_0000  S9..S10  slot A, body at 0x0804_0400
/// 0x0C0C_0000  S11..S12 slot B, body at 0x080C_0400
/// 0x0C14_0000  S13..S15 free (768 KiB)
/// ```
pub mod xmc4800 {
    use super::Layout;

    /// Uncached address of the slot region (where the boot loader reads it).
    pub const SLOTS_UNCACHED: u32 = 0x0C04_0000;
    /// Cached address of the slot region (where images run).
    pub const SLOTS_CACHED: u32 = 0x0804_0000;
    /// Erase sector (logical sectors S9..S15).
    pub const SECTOR: usize = 256 * 1024;
    /// Sectors of the slot region.
    pub const SECTORS: usize = 4;
    /// Program unit: one page.
    pub const WRITE: usize = 256;
    /// Execution addresses: DSRAM1 for the stack.
    pub const LAYOUT: Layout = Layout {
        region_xip: SLOTS_CACHED,
        ram_start: 0x2000_0000,
        ram_end: 0x2002_0000,
    };
}

#[cfg(test)]
mod tests;
