//! The boot loader of the reference board (Infineon XMC4800), at the start of
//! program flash (0x0C00_0000, logical sectors S0..S1, budget 24 KiB; layout in
//! docs/flashing.md and `bootloader::xmc4800`). The chip's boot ROM starts it
//! like any image; it reads both firmware slots through the uncached flash
//! alias, runs the boot decision and the image check (`bootloader::select`)
//! and starts the chosen image in place from the cached alias: VTOR = the
//! slot's body, MSP = word 0, jump to word 1. With nothing to start it stays in
//! a safe loop (interrupts masked, WFI). Log: defmt over RTT. The image check
//! verifies the Ed25519 signature of the image with the key built in
//! (`bootloader::PUBLIC_KEY`: set `SC6_FIRMWARE_PUBLIC_KEY` for a production
//! build, else it is the development key).
//!
//! **The program-flash driver is a stub**: [`XmcFlash`] reads the memory-mapped
//! flash, but its erase and write return `FlashError::Device` (the XMC4800's
//! PFLASH command sequences are not written yet, docs/flashing.md). So the
//! TRIED mark cannot be written: `select` then never starts a pending image
//! (it would be retried at every reset) and starts a confirmed one, or a trial
//! image when it is all there is. Updates are taken once the driver exists.
#![no_std]
#![no_main]

use bootloader::{
    fault_name, select, slot_name, xmc4800, BootSlots, Entry, Flash, FlashError, Outcome, PUBLIC_KEY,
};
use cortex_m_rt::entry;
use defmt_rtt as _;

/// The service table for the running image (`boot::BootApi`).
#[path = "../bootapi.rs"]
mod bootapi;

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    defmt::error!("boot: panic");
    safe_loop()
}

/// Nothing to start: interrupts masked, sleep forever.
fn safe_loop() -> ! {
    cortex_m::interrupt::disable();
    loop {
        cortex_m::asm::wfi();
    }
}

/// The slot region of program flash (S9..S12), read through the uncached
/// alias. Erase and write: stub (see the crate docs).
struct XmcFlash;

const REGION_LEN: usize = xmc4800::SECTOR * xmc4800::SECTORS;

impl Flash for XmcFlash {
    const SECTOR: usize = xmc4800::SECTOR;
    const SECTORS: usize = xmc4800::SECTORS;
    const WRITE: usize = xmc4800::WRITE;

    fn read(&mut self, addr: u32, buf: &mut [u8]) -> Result<(), FlashError> {
        let a = addr as usize;
        match a.checked_add(buf.len()) {
            Some(end) if end <= REGION_LEN => {}
            _ => return Err(FlashError::OutOfRange),
        }
        let base = (xmc4800::SLOTS_UNCACHED as usize + a) as *const u8;
        for (i, b) in buf.iter_mut().enumerate() {
            // SAFETY: inside the slot region of the 2 MiB program flash,
            // memory-mapped and always readable.
            #[allow(unsafe_code)]
            {
                *b = unsafe { core::ptr::read_volatile(base.add(i)) };
            }
        }
        Ok(())
    }

    fn erase(&mut self, _sector: u32) -> Result<(), FlashError> {
        Err(FlashError::Device)
    }

    fn write(&mut self, _addr: u32, _data: &[u8]) -> Result<(), FlashError> {
        Err(FlashError::Device)
    }
}

#[entry]
fn main() -> ! {
    defmt::info!(
        "boot: boot loader (XMC4800), slots at {=u32:#010x}",
        xmc4800::SLOTS_UNCACHED
    );
    let mut slots = BootSlots::with_base(XmcFlash, xmc4800::LAYOUT.region_xip);
    match select(&mut slots, &xmc4800::LAYOUT, &PUBLIC_KEY) {
        Outcome::Start(s) => {
            if let Some(r) = s.decision.rolled_back {
                defmt::warn!("boot: slot {=str} never confirmed: rolled back", slot_name(r));
            }
            if let Some(f) = s.fallback {
                defmt::warn!(
                    "boot: slot {=str} not started: {=str}",
                    slot_name(s.decision.slot),
                    fault_name(f)
                );
            }
            if s.marks_failed.is_some() {
                defmt::warn!("boot: marks cannot be written (flash driver stub): no pending image started");
            }
            defmt::info!(
                "boot: starting slot {=str} (version {=u32}) at {=u32:#010x}",
                slot_name(s.slot),
                s.version,
                s.entry.vtor
            );
            start(s.entry)
        }
        Outcome::Halt { .. } => {
            defmt::error!("boot: no bootable image: safe loop");
            safe_loop()
        }
    }
}

/// Starts the image at `e` in place (direct execute-in-place).
fn start(e: Entry) -> ! {
    // SAFETY: `check_image` found a vector table at `e.vtor` whose stack
    // pointer is in DSRAM1 and whose reset vector lies in the image; nothing
    // of the boot loader is used after the jump. No interrupt was enabled.
    #[allow(unsafe_code)]
    unsafe {
        (*cortex_m::peripheral::SCB::PTR).vtor.write(e.vtor);
        cortex_m::asm::dsb();
        cortex_m::asm::isb();
        cortex_m::asm::bootload(e.vtor as *const u32)
    }
}
