//! The signed boot decision and the check of a slot's image (issue 18).

use crate::{addr, BootSlots, Decision, Flash, FlashError, ImageHeader, Slot, SlotState, VerifyError};
use crate::{verify_image, IMAGE_HEADER_LEN, KEY_LEN};

impl<F: Flash> BootSlots<F> {
    /// Verifies the image in `slot` as it is in flash: header format, body
    /// length, CRC-32, the Ed25519 signature with `public_key` (the body is
    /// streamed from flash in 256-byte chunks: no heap, a small stack) and the
    /// load address against the slot's ([`BootSlots::load_address`]). Marks
    /// and security counter are not looked at. Returns the header.
    pub fn verify(&mut self, slot: Slot, public_key: &[u8; KEY_LEN]) -> Result<ImageHeader, VerifyError> {
        let start = slot.index() * Self::SLOT_LEN;
        let mut head = [0u8; IMAGE_HEADER_LEN];
        self.flash.read(addr(start)?, &mut head)?;
        let header = ImageHeader::parse(&head).ok_or(VerifyError::Header)?;
        if header.length as usize > self.capacity() {
            return Err(VerifyError::Header);
        }
        let body = start + Self::BODY;
        let flash = &mut self.flash;
        let checked = verify_image(&head, |at, buf| flash.read(addr(body + at)?, buf), public_key)?;
        if checked.load_address != self.load_address(slot) {
            return Err(VerifyError::LoadAddress);
        }
        Ok(checked)
    }

    /// Both slots' states (`[A, B]`) with signatures checked and the
    /// security counters (0 for an empty slot): a slot whose image fails
    /// [`BootSlots::verify`] is [`SlotState::Empty`].
    pub fn verified_states(
        &mut self,
        public_key: &[u8; KEY_LEN],
    ) -> Result<[(SlotState, u32); 2], FlashError> {
        Ok([
            self.verified_state(Slot::A, public_key)?,
            self.verified_state(Slot::B, public_key)?,
        ])
    }

    fn verified_state(
        &mut self,
        slot: Slot,
        public_key: &[u8; KEY_LEN],
    ) -> Result<(SlotState, u32), FlashError> {
        let Some((_, state)) = self.marks(slot)? else {
            return Ok((SlotState::Empty, 0));
        };
        match self.verify(slot, public_key) {
            Ok(h) => Ok((state, h.security_counter)),
            Err(VerifyError::Flash(e)) => Err(e),
            Err(_) => Ok((SlotState::Empty, 0)),
        }
    }

    /// Power-on of a boot loader that takes signed images only: as
    /// [`BootSlots::boot`], but the decision never picks a slot whose image
    /// fails [`BootSlots::verify`] with `public_key`, nor one whose security
    /// counter is below the floor.
    ///
    /// Downgrade protection: the floor is the highest security counter of a
    /// **confirmed** image that verifies (kept in the signed headers of the
    /// slots themselves, so it needs no storage of its own), or
    /// `min_security_counter` if that is higher: the board's own record (e.g.
    /// an OTP word a boot loader raises after a confirm; 0 without one). A
    /// trial image that never confirmed does not raise it, so the rollback to
    /// the confirmed image stays possible. After the boot,
    /// [`security_floor`](Self::security_floor) is the floor or the running
    /// image's counter if higher: what a download must reach.
    pub fn boot_verified(
        &mut self,
        public_key: &[u8; KEY_LEN],
        min_security_counter: u32,
    ) -> Result<Option<Decision>, FlashError> {
        let (states, floor) = floored(self.verified_states(public_key)?, min_security_counter);
        self.start(states, floor)
    }
}

/// The states with every slot below the floor emptied, and the floor: the
/// highest counter of a confirmed image, at least `min`.
fn floored(checked: [(SlotState, u32); 2], min: u32) -> ([SlotState; 2], u32) {
    let floor = checked
        .iter()
        .filter(|(s, _)| matches!(s, SlotState::Confirmed { .. }))
        .map(|&(_, c)| c)
        .fold(min, u32::max);
    (
        checked.map(|(s, c)| if c < floor { SlotState::Empty } else { s }),
        floor,
    )
}
