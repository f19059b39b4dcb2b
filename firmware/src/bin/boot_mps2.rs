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
//! status 1): on the board, the safe loop. The image check verifies the
//! Ed25519 signature with the key built in (`bootloader::PUBLIC_KEY`: the
//! development key unless `SC6_FIRMWARE_PUBLIC_KEY` was set for the build).
//!
//! The verification figure: when QEMU loaded an update file at [`BENCH_AT`]
//! (`scripts/cross boot-qemu` puts a signed 256 KiB one there and runs this
//! image under `-icount shift=0`), the boot loader verifies it as it verifies a
//! slot (SHA-256 over header and body in 256-byte reads, then Ed25519), prints
//! the instructions that took (SysTick, calibrated against a loop of known
//! length, as the `firmware-qemu` figures) and stops QEMU. The scenarios'
//! flash files end far below that address, which QEMU leaves zero.
#![no_std]
#![no_main]

use bootloader::{
    fault_name, mps2, select, slot_name, state_name, verify_image, BootSlots, Entry, FlashError, ImageHeader,
    Outcome, Slot, IMAGE_HEADER_LEN, PUBLIC_KEY,
};
use cortex_m_rt::entry;
// SysTick ticks and their calibration, as `firmware-qemu` measures (one wrap
// at most: 2^24 ticks are about 670 million instructions on this machine)
use cortex_m_semihosting::{debug, hprintln};
use firmware::systick::{now, ticks};

#[path = "../semiflash.rs"]
mod semiflash;

/// The service table for the running image (`boot::BootApi`).
#[path = "../bootapi.rs"]
mod bootapi;

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    hprintln!("boot: panic");
    halt()
}

/// The safe stop: QEMU exits with a failure status.
fn halt() -> ! {
    firmware::semihost::exit(false)
}

#[entry]
fn main() -> ! {
    hprintln!(
        "boot: boot loader on mps2-an386, slot region at {:#010x}",
        mps2::SLOTS_BASE
    );
    bench();
    let mut flash = semiflash::slot_flash();
    if !flash.mirror_mut().is_open() {
        hprintln!("boot: flash file not open: marks cannot be written");
    }
    let mut slots = BootSlots::with_base(flash, mps2::LAYOUT.region_xip);
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
    match select(&mut slots, &mps2::LAYOUT, &PUBLIC_KEY) {
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
    // pointer is in RAM and whose reset vector lies in the image; nothing
    // of the boot loader is used after the jump. No interrupt was enabled.
    #[allow(unsafe_code)]
    unsafe {
        firmware::start_image(e.vtor)
    }
}

/// Where `scripts/cross boot-qemu` loads the update file of the verification
/// figure (1 MiB: in the machine's 4 MiB at 0, above the flash file).
pub const BENCH_AT: usize = 0x0010_0000;
/// Largest body the figure takes (the rest of the 4 MiB).
const BENCH_MAX: usize = 0x0030_0000 - IMAGE_HEADER_LEN;

/// The verification figure, when an update file is at [`BENCH_AT`] (see the
/// crate docs): prints it and stops QEMU; else returns at once.
fn bench() {
    // SAFETY: the machine's 4 MiB at 0 are RAM, always readable; QEMU zeroes
    // what no loader filled, so without a bench file the magic does not match.
    #[allow(unsafe_code)]
    let head = unsafe { core::slice::from_raw_parts(BENCH_AT as *const u8, IMAGE_HEADER_LEN) };
    let Some(header) = ImageHeader::parse(head) else {
        return;
    };
    let len = (header.length as usize).min(BENCH_MAX);
    // SAFETY: as above; `len` keeps the body inside the 4 MiB.
    #[allow(unsafe_code)]
    let body = unsafe { core::slice::from_raw_parts((BENCH_AT + IMAGE_HEADER_LEN) as *const u8, len) };
    let Some(cp) = cortex_m::Peripherals::take() else {
        return;
    };
    let mut syst = cp.SYST;
    let per_1000 = firmware::systick::start(&mut syst);
    let t0 = now();
    let r = verify_image(
        head,
        |at, buf| {
            let src = at
                .checked_add(buf.len())
                .and_then(|end| body.get(at..end))
                .ok_or(FlashError::OutOfRange)?;
            buf.copy_from_slice(src);
            Ok(())
        },
        &PUBLIC_KEY,
    );
    let t = ticks(t0, now());
    let instructions = u64::from(t) * u64::from(per_1000) / 1000;
    hprintln!(
        "boot: figure: verification of a {} KiB image (CRC-32, SHA-256 of header and body in 256-byte reads, Ed25519): {} instructions ({})",
        len / 1024,
        instructions,
        if r.is_ok() { "verified" } else { "FAILED" }
    );
    debug::exit(if r.is_ok() {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
}
