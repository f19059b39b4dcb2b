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
//! The slot region is erased and programmed with the PFLASH driver
//! `xmc-pflash` ([`XmcFlash`]; its command-issuing part runs from RAM,
//! interrupts masked), so the TRIED mark of a pending image is written and
//! updates are taken. The driver is host-tested against a model of the chip
//! only: it has not run on silicon (docs/flashing.md, "The PFLASH driver").
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

/// The slot region of program flash (S9..S12) through the PFLASH driver, read
/// through the uncached alias. Each erase and write runs with interrupts masked
/// (the boot loader enables none; a handler in flash must not run while the
/// single PFLASH bank is busy).
struct XmcFlash(xmc_pflash::SlotRegion<xmc_pflash::Volatile>);

// the driver's slot region is the one `bootloader::xmc4800` lays out
const _: () = {
    type R = xmc_pflash::SlotRegion<xmc_pflash::Volatile>;
    assert!(R::BASE == xmc4800::SLOTS_UNCACHED);
    assert!(<R as Flash>::SECTOR == xmc4800::SECTOR && <R as Flash>::SECTORS == xmc4800::SECTORS);
    assert!(<R as Flash>::WRITE == xmc4800::WRITE);
};

/// CPU clock bound for the busy waits: the boot loader runs at the reset clock
/// (below 144 MHz); assuming the maximum makes the bounds only longer.
const CPU_HZ_MAX: u32 = 144_000_000;

impl XmcFlash {
    fn new() -> Self {
        // SAFETY: the XMC4800's PFLASH and FLASH0; the boot loader is the only
        // user of the flash commands, runs single-threaded and masks interrupts
        // around every erase and write (below).
        #[allow(unsafe_code)]
        let bus = unsafe { xmc_pflash::Volatile::new() };
        let limits = xmc_pflash::Limits::at_cpu_hz(CPU_HZ_MAX);
        Self(xmc_pflash::Region::new(xmc_pflash::Pflash::new(bus, limits)))
    }
}

impl Flash for XmcFlash {
    const SECTOR: usize = xmc4800::SECTOR;
    const SECTORS: usize = xmc4800::SECTORS;
    const WRITE: usize = xmc4800::WRITE;

    fn read(&mut self, addr: u32, buf: &mut [u8]) -> Result<(), FlashError> {
        self.0.read(addr, buf)
    }

    fn erase(&mut self, sector: u32) -> Result<(), FlashError> {
        cortex_m::interrupt::free(|_| self.0.erase(sector))
    }

    fn write(&mut self, addr: u32, data: &[u8]) -> Result<(), FlashError> {
        cortex_m::interrupt::free(|_| self.0.write(addr, data))
    }
}

#[entry]
fn main() -> ! {
    defmt::info!(
        "boot: boot loader (XMC4800), slots at {=u32:#010x}",
        xmc4800::SLOTS_UNCACHED
    );
    let mut slots = BootSlots::with_base(XmcFlash::new(), xmc4800::LAYOUT.region_xip);
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
                defmt::warn!("boot: marks cannot be written (flash error): no pending image started");
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
        firmware::start_image(e.vtor)
    }
}
