//! The boot loader on QEMU's mps2-an386 (`scripts/cross boot-qemu`): the
//! logic of `crates/bootloader` over the flash file's slot region
//! (`semiflash`), logging as plain text over semihosting (the boot loader and
//! the image it starts write to the same console, so no defmt: one decoder
//! could not read both).
//!
//! Reads both slots, runs the boot decision (`bootloader::select`: writes the
//! TRIED mark of a pending image, rolls back an unconfirmed trial, checks the
//! chosen image), and starts the image in place: VTOR = its body, MSP = word 0,
//! jump to word 1. With nothing to start it reports and stops QEMU (exit
//! status 1): on the board, the safe loop.
#![no_std]
#![no_main]

use bootloader::{fault_name, mps2, select, slot_name, state_name, BootSlots, Entry, Outcome, Slot};
use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};

#[path = "../semiflash.rs"]
mod semiflash;

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    hprintln!("boot: panic");
    halt()
}

/// The safe stop: QEMU exits with a failure status.
fn halt() -> ! {
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}

#[entry]
fn main() -> ! {
    hprintln!(
        "boot: boot loader on mps2-an386, slot region at {:#010x}",
        mps2::SLOTS_BASE
    );
    let mut flash = semiflash::slot_flash();
    if !flash.mirror_mut().is_open() {
        hprintln!("boot: flash file not open: marks cannot be written");
    }
    let mut slots = BootSlots::new(flash);
    for slot in [Slot::A, Slot::B] {
        let version = slots.header(slot).ok().flatten().map(|h| h.version);
        match (slots.state(slot), version) {
            (Ok(s), Some(v)) => match s.seq() {
                Some(seq) => hprintln!(
                    "boot: slot {}: {} (version {}, seq {})",
                    slot_name(slot),
                    state_name(s),
                    v,
                    seq
                ),
                None => hprintln!(
                    "boot: slot {}: not bootable (header of version {}: no VALID mark or CRC-32 mismatch)",
                    slot_name(slot),
                    v
                ),
            },
            (Ok(s), None) => hprintln!("boot: slot {}: {}", slot_name(slot), state_name(s)),
            (Err(_), _) => hprintln!("boot: slot {}: flash read failed", slot_name(slot)),
        }
    }
    match select(&mut slots, &mps2::LAYOUT) {
        Outcome::Start(s) => {
            if let Some(r) = s.decision.rolled_back {
                hprintln!(
                    "boot: slot {} was on trial and never confirmed: rolled back",
                    slot_name(r)
                );
            }
            if let Some(f) = s.fallback {
                hprintln!(
                    "boot: slot {} not started: {}",
                    slot_name(s.decision.slot),
                    fault_name(f)
                );
            }
            if s.marks_failed.is_some() {
                hprintln!("boot: marks cannot be written: a pending image is not started");
            }
            let how = if s.decision.trial && s.slot == s.decision.slot {
                " on trial"
            } else {
                ""
            };
            hprintln!(
                "boot: starting slot {} (version {}){} at {:#010x}",
                slot_name(s.slot),
                s.version,
                how,
                s.entry.vtor
            );
            let mut flash = slots.into_inner();
            flash.mirror_mut().close();
            start(s.entry)
        }
        Outcome::Halt { error, fault } => {
            if error.is_some() {
                hprintln!("boot: flash read failed");
            }
            if let Some((slot, f)) = fault {
                hprintln!("boot: slot {} not started: {}", slot_name(slot), fault_name(f));
            }
            hprintln!("boot: no bootable image: halted");
            halt()
        }
    }
}

/// Starts the image at `e` in place (direct execute-in-place).
fn start(e: Entry) -> ! {
    // SAFETY: `check_image` found a vector table at `e.vtor` whose stack
    // pointer is in RAM and whose reset vector lies in the image; nothing of
    // this image is used after the jump. No interrupt was enabled here.
    #[allow(unsafe_code)]
    unsafe {
        (*cortex_m::peripheral::SCB::PTR).vtor.write(e.vtor);
        cortex_m::asm::dsb();
        cortex_m::asm::isb();
        cortex_m::asm::bootload(e.vtor as *const u32)
    }
}
