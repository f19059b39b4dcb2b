//! The test image of the boot scenarios (`scripts/cross boot-qemu`) on QEMU's
//! mps2-an386: linked for slot A or B (`FIRMWARE_SLOT=a|b`, build.rs), made an
//! update file by `tools/foe-image`, placed in its slot by
//! `tools/flash-compose`, started by the boot loader (`boot_mps2.rs`).
//!
//! It prints which slot it runs from (found from SCB.VTOR, where the boot
//! loader put its vector table) and its slot's state, runs its "cycles", and
//! after the first successful one — its confirmation point, as the drive's
//! first control cycle would be — confirms itself (`BootSlots::resume` +
//! `confirm`, the CONFIRMED mark written to memory and the flash file). Built
//! with the feature `mps2-slot-noconfirm` it never confirms (the rollback
//! scenario). Then it stops QEMU (exit status 0).
#![no_std]
#![no_main]

use bootloader::{mps2, slot_name, state_name, BootSlots, SlotState, PUBLIC_KEY};
use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;

#[path = "../semiflash.rs"]
mod semiflash;

/// Ed25519 through the boot loader's table (`boot::BootApi`).
#[path = "../bootapi.rs"]
mod bootapi;

/// Whether this image confirms itself.
const CONFIRMS: bool = !cfg!(feature = "mps2-slot-noconfirm");

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    hprintln!("app: panic");
    stop(false)
}

use firmware::semihost::exit as stop;

#[entry]
fn main() -> ! {
    // SAFETY: a read of SCB.VTOR.
    #[allow(unsafe_code)]
    let vtor = unsafe { (*cortex_m::peripheral::SCB::PTR).vtor.read() };
    let Some(slot) = mps2::LAYOUT.slot_at::<mps2::SlotFlash<'static, semiflash::FileMirror>>(vtor) else {
        hprintln!("app: vector table at {:#010x}: not started from a slot", vtor);
        stop(false)
    };
    let Ok(mut slots) = BootSlots::resume_with_base(semiflash::slot_flash(), mps2::LAYOUT.region_xip, slot)
    else {
        hprintln!("app: slot {}: flash read failed", slot_name(slot));
        stop(false)
    };
    let version = slots.header(slot).ok().flatten().map_or(0, |h| h.version);
    let state = slots.state(slot).unwrap_or(SlotState::Empty);
    hprintln!(
        "app: running from slot {} (version {}, {}) at {:#010x}",
        slot_name(slot),
        version,
        state_name(state),
        vtor
    );
    // the download check of the drive's FoE path, on this image's own slot:
    // Ed25519 by the boot loader's code, through its table
    match slots.verify(slot, &PUBLIC_KEY) {
        Ok(_) => hprintln!(
            "app: slot {} verified with the boot loader's Ed25519 (table at {:#010x})",
            slot_name(slot),
            bootapi::BOOT_API_AT
        ),
        Err(e) => hprintln!("app: slot {} does not verify: {:?}", slot_name(slot), e),
    }
    for cycle in 1..=3u32 {
        hprintln!("app: cycle {} ok", cycle);
        if cycle == 1 && slots.on_trial() {
            if !CONFIRMS {
                hprintln!("app: on trial, not confirming (test image)");
            } else if slots.confirm().is_ok() {
                hprintln!("app: confirmed slot {}", slot_name(slot));
            } else {
                hprintln!("app: confirming slot {} failed", slot_name(slot));
            }
        }
    }
    slots.into_inner().mirror_mut().close();
    stop(true)
}
