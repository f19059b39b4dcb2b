//! The firmware download over FoE (issue 8): file names, the handler that
//! writes the boot slots, the FoE error of each update error. Signed images
//! (issue 18): at the end of a download the image in flash is verified against
//! [`FIRMWARE_PUBLIC_KEY`]; a wrong load address or a security counter below
//! the running image's is refused at the header already.

use super::*;

/// The public key a downloaded image must be signed with, chosen at build
/// time: [`boot::FIRMWARE_PUBLIC_KEY`] (the 64 hex digits of the environment
/// variable `SC6_FIRMWARE_PUBLIC_KEY` when `crates/boot` is built, else the
/// **development** key `keys/dev-ed25519.pub`, which the simulator and the
/// QEMU images use): the key built into the boot loader too.
pub const FIRMWARE_PUBLIC_KEY: [u8; 32] = boot::FIRMWARE_PUBLIC_KEY;

/// Whether [`FIRMWARE_PUBLIC_KEY`] is the development key (never for a
/// production drive).
pub const FIRMWARE_KEY_IS_DEVELOPMENT: bool = boot::FIRMWARE_KEY_IS_DEVELOPMENT;

/// FoE file names (prefix) of the firmware image; other names: 8001h.
pub const FIRMWARE_FILE: &[u8] = b"firmware";

/// A download the drive verified and stored (issue 33): the slot it went
/// to (the next power-on starts it on trial) and the version its header
/// names. [`Drive::take_firmware_stored`] hands it to the firmware's log and
/// to `hil-sim serve`'s console.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FirmwareStored {
    /// The slot the image is stored in (the one the drive did not start from).
    pub slot: boot::Slot,
    /// The version field of the image's header (informational).
    pub version: u32,
}

/// The value of the firmware-update-slot object (E54, [`crate::params::E54`])
/// for `slot`: 1 = A, 2 = B; 0 = the drive has no firmware slots.
pub fn update_slot_value(slot: Option<boot::Slot>) -> i64 {
    slot.map_or(0, |s| s.index() as i64 + 1)
}

/// The FoE handler of the drive: firmware images into the boot slots.
pub struct FirmwareFoe<'a, B: Flash> {
    pub(super) slots: Option<&'a mut BootSlots<B>>,
    stored: Option<FirmwareStored>,
}

impl<'a, B: Flash> FirmwareFoe<'a, B> {
    /// The handler over `slots` (`None`: every write is refused with 8002h).
    pub fn new(slots: Option<&'a mut BootSlots<B>>) -> Self {
        Self { slots, stored: None }
    }

    /// The download this handler verified and stored, if one ended through it.
    pub fn stored(&self) -> Option<FirmwareStored> {
        self.stored
    }
}

/// The FoE error code of an update error (docs/conformance.md, decisions).
pub fn foe_error(e: UpdateError) -> FoeError {
    match e {
        UpdateError::NotStarted | UpdateError::BadHeader => FoeError::ILLEGAL,
        UpdateError::Unconfirmed => FoeError::ACCESS_DENIED,
        UpdateError::TooLarge => FoeError::DISK_FULL,
        UpdateError::Incomplete | UpdateError::Crc | UpdateError::Signature => FoeError::CHECKSUM,
        UpdateError::LoadAddress => FoeError::ILLEGAL,
        UpdateError::Downgrade => FoeError::NO_RIGHTS,
        UpdateError::Flash(_) => FoeError::PROGRAM_ERROR,
    }
}

impl<B: Flash> FoeHandler for FirmwareFoe<'_, B> {
    fn begin_write(&mut self, name: &[u8], _password: u32) -> Result<(), FoeError> {
        if !name.starts_with(FIRMWARE_FILE) {
            return Err(FoeError::NOT_FOUND);
        }
        let slots = self.slots.as_deref_mut().ok_or(FoeError::ACCESS_DENIED)?;
        slots.begin().map(|_| ()).map_err(foe_error)
    }

    fn write(&mut self, data: &[u8]) -> Result<Accept, FoeError> {
        let slots = self.slots.as_deref_mut().ok_or(FoeError::ILLEGAL)?;
        slots.write(data).map(|()| Accept::Done).map_err(foe_error)
    }

    fn end_write(&mut self) -> Result<(), FoeError> {
        let slots = self.slots.as_deref_mut().ok_or(FoeError::ILLEGAL)?;
        let slot = slots.finish_verified(&FIRMWARE_PUBLIC_KEY).map_err(foe_error)?;
        // the header was just verified in flash: a read failure now only
        // loses the version of the report, not the stored image
        let version = slots.header(slot).ok().flatten().map_or(0, |h| h.version);
        self.stored = Some(FirmwareStored { slot, version });
        Ok(())
    }

    fn abort(&mut self) {
        if let Some(slots) = self.slots.as_deref_mut() {
            slots.abort();
        }
    }
}
