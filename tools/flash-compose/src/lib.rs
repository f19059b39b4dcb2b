//! The flash file of the boot-loader scenarios (`scripts/cross boot-qemu`,
//! docs/flashing.md): QEMU's mps2-an386 starts with it at address 0
//! (`bootloader::mps2`: the boot loader at 0, the slot region at 0x8000).
//! With [`Target::Xmc4800`] the same for the board (`bootloader::xmc4800`: a
//! file to flash at 0x0C00_0000 with the boot loader and confirmed images, as
//! long as the board's boot loader cannot write marks itself).
//!
//! The boot loader's bytes come from its ELF (`foe_image::body_from_elf`, linked
//! at 0). The slot region is filled the way the drive fills it, by `crates/boot`
//! itself: a list of [`Step`]s — downloads of update files (`tools/foe-image`'s
//! output) into the inactive slot with `BootSlots::begin/write/finish`, power-ons
//! through the boot loader's own decision (`bootloader::select`, with the key
//! built into the boot loader, `bootloader::PUBLIC_KEY`), confirmations, and
//! two faults: a body byte flipped after the download, a power cut in the
//! middle of one.
//!
//! The scenarios' update files are signed (`foe-image make --key
//! keys/dev-ed25519.key`: the development key the QEMU boot loader is built
//! with). An install checks only what `BootSlots::finish` checks (header, load
//! address, length, CRC-32), not the signature, as a programmer writing the
//! flash would: so a wrongly signed image can reach a slot, and a scenario
//! shows that the boot loader never starts it (the drive's FoE path refuses
//! it already, `BootSlots::finish_verified`).
#![forbid(unsafe_code)]

use boot::{BootSlots, Flash, PowerCut, Slot};
use bootloader::{
    mps2, select, slot_name, state_name, xmc4800, Layout, MemFlash, NoMirror, Outcome, PUBLIC_KEY,
};

/// One step of a scenario's history.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Step {
    /// The running image downloads this update file into the inactive slot.
    Install(Vec<u8>),
    /// Power-on: the boot loader's decision (marks written as it writes them).
    Reset,
    /// The running image confirms itself.
    Confirm,
    /// Flips bit 4 of this body byte of the slot last installed (after the
    /// download: the header and the VALID mark are already written).
    Flip(usize),
    /// A download of this file during which the power fails at flash
    /// operation `n` (erase or program unit, from 0): it and all later ones do
    /// not happen; the flash stays as it was then.
    Cut(Vec<u8>, u32),
}

/// A flash file's target: where the boot loader is linked, where the slot
/// region starts in the file, its geometry and execution layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// QEMU's mps2-an386 (`bootloader::mps2`): the file is loaded at 0.
    Mps2,
    /// The XMC4800 board (`bootloader::xmc4800`): the file is flashed at
    /// 0x0C00_0000 and ends after slot B (the parameter sectors in it are FFh).
    Xmc4800,
}

impl Target {
    /// Address of the file's first byte (the boot loader's link address).
    pub fn base(self) -> u32 {
        match self {
            Target::Mps2 => 0,
            Target::Xmc4800 => 0x0C00_0000,
        }
    }

    /// Offset of the slot region in the file.
    pub fn slots_offset(self) -> usize {
        match self {
            Target::Mps2 => mps2::SLOTS_BASE as usize,
            Target::Xmc4800 => (xmc4800::SLOTS_UNCACHED - 0x0C00_0000) as usize,
        }
    }

    /// Largest boot loader (the room the layout gives it, not its budget).
    fn boot_room(self) -> usize {
        match self {
            Target::Mps2 => mps2::SLOTS_BASE as usize,
            // S0..S1: the rest of the first physical sector is not the boot loader's
            Target::Xmc4800 => 32 * 1024,
        }
    }
}

/// Downloads `file` in chunks of 256 bytes (an FoE packet's worth, roughly).
fn download<F: Flash>(s: &mut BootSlots<F>, file: &[u8]) -> Result<Slot, String> {
    download_counted(s, file).1
}

/// [`download`], and the file bytes taken before it ended.
fn download_counted<F: Flash>(s: &mut BootSlots<F>, file: &[u8]) -> (usize, Result<Slot, String>) {
    if let Err(e) = s.begin() {
        return (0, Err(format!("begin: {e:?}")));
    }
    let mut sent = 0;
    for chunk in file.chunks(256) {
        if let Err(e) = s.write(chunk) {
            return (sent, Err(format!("write: {e:?}")));
        }
        sent += chunk.len();
    }
    (sent, s.finish().map_err(|e| format!("finish: {e:?}")))
}

/// The boot loader's bytes from its ELF (linked at the target's base).
pub fn boot_bytes(boot_elf: &[u8], target: Target) -> Result<Vec<u8>, String> {
    let boot = foe_image::body_from_elf(boot_elf).map_err(|e| format!("boot loader: {e}"))?;
    if boot.address != target.base() {
        return Err(format!(
            "boot loader linked at {:#010x}, not {:#010x}",
            boot.address,
            target.base()
        ));
    }
    Ok(boot.bytes)
}

/// The flash file of `target`: `boot` (the boot loader's bytes, [`boot_bytes`])
/// at its start, FFh up to the slot region, the slot region after `steps` (from
/// erased flash). `log` gets one line per step.
pub fn compose_for(
    target: Target,
    boot: &[u8],
    steps: &[Step],
    log: &mut dyn FnMut(String),
) -> Result<Vec<u8>, String> {
    if boot.len() > target.boot_room() {
        return Err(format!(
            "boot loader ({} bytes) is larger than its {} bytes",
            boot.len(),
            target.boot_room()
        ));
    }
    let region = match target {
        Target::Mps2 => {
            let mut region = vec![0xFF; mps2::REGION_LEN];
            run_steps(
                mps2::SlotFlash::new(&mut region, NoMirror),
                &mps2::LAYOUT,
                steps,
                log,
            )?;
            region
        }
        Target::Xmc4800 => {
            let mut region = vec![0xFF; xmc4800::SECTOR * xmc4800::SECTORS];
            type Board<'a> =
                MemFlash<'a, NoMirror, { xmc4800::SECTOR }, { xmc4800::SECTORS }, { xmc4800::WRITE }>;
            run_steps(Board::new(&mut region, NoMirror), &xmc4800::LAYOUT, steps, log)?;
            region
        }
    };
    let mut out = boot.to_vec();
    out.resize(target.slots_offset(), 0xFF);
    out.extend_from_slice(&region);
    Ok(out)
}

/// [`compose_for`] QEMU's mps2-an386.
pub fn compose(boot: &[u8], steps: &[Step], log: &mut dyn FnMut(String)) -> Result<Vec<u8>, String> {
    compose_for(Target::Mps2, boot, steps, log)
}

/// Byte access for fault injection.
trait Bytes {
    fn bytes_mut(&mut self) -> &mut [u8];
}

impl<const S: usize, const N: usize, const W: usize> Bytes for MemFlash<'_, NoMirror, S, N, W> {
    fn bytes_mut(&mut self) -> &mut [u8] {
        MemFlash::bytes_mut(self)
    }
}

/// Runs `steps` on the slot region `flash`.
fn run_steps<F: Flash + Bytes>(
    flash: F,
    layout: &Layout,
    steps: &[Step],
    log: &mut dyn FnMut(String),
) -> Result<(), String> {
    let mut slots = BootSlots::with_base(PowerCut::new(flash), layout.region_xip);
    let mut last = None;
    for step in steps {
        match step {
            Step::Install(file) => {
                let slot = download(&mut slots, file)?;
                last = Some(slot);
                log(format!(
                    "install: slot {} pending ({} bytes)",
                    slot_name(slot),
                    file.len()
                ));
            }
            Step::Reset => {
                let mut s = BootSlots::with_base(slots.into_inner(), layout.region_xip);
                s.flash_mut().power_on();
                match select(&mut s, layout, &PUBLIC_KEY) {
                    Outcome::Start(st) => {
                        log(format!("reset: slot {} starts", slot_name(st.slot)));
                        // the running image's view
                        let flash = s.into_inner();
                        slots = BootSlots::resume_with_base(flash, layout.region_xip, st.slot)
                            .map_err(|e| format!("resume: {e:?}"))?;
                    }
                    Outcome::Halt { .. } => {
                        log("reset: nothing to start".into());
                        slots = s;
                    }
                }
            }
            Step::Confirm => {
                slots.confirm().map_err(|e| format!("confirm: {e:?}"))?;
                log("confirm".into());
            }
            Step::Flip(at) => {
                let slot = last.ok_or("flip: no slot installed yet")?;
                let i = slot.index() * BootSlots::<F>::slot_len() + BootSlots::<F>::body_offset() + at;
                let b = slots
                    .flash_mut()
                    .inner_mut()
                    .bytes_mut()
                    .get_mut(i)
                    .ok_or("flip: offset outside the slot")?;
                *b ^= 0x10;
                log(format!("flip: slot {} body byte {at}", slot_name(slot)));
            }
            Step::Cut(file, n) => {
                slots.flash_mut().cut_after(*n);
                let slot = slots.inactive();
                let (sent, r) = download_counted(&mut slots, file);
                match r {
                    Ok(_) => return Err(format!("cut: the download needs fewer than {n} flash operations")),
                    Err(e) => log(format!(
                        "cut: power lost at flash operation {n} of the download into slot {}: {sent} of {} bytes taken ({e})",
                        slot_name(slot),
                        file.len()
                    )),
                }
                slots.abort();
            }
        }
    }
    let [a, b] = slots.states().map_err(|e| format!("states: {e:?}"))?;
    log(format!(
        "flash: slot A {}, slot B {}",
        state_name(a),
        state_name(b)
    ));
    Ok(())
}

/// Parses the steps of the command line (see `main.rs`); `read` loads a file.
pub fn parse_steps(
    args: &[String],
    read: &dyn Fn(&str) -> Result<Vec<u8>, String>,
) -> Result<Vec<Step>, String> {
    let mut steps = Vec::new();
    let mut it = args.iter();
    let num = |s: Option<&String>, what: &str| -> Result<u64, String> {
        let s = s.ok_or(format!("{what}: a number is missing"))?;
        s.parse().map_err(|_| format!("{what}: {s} is not a number"))
    };
    while let Some(a) = it.next() {
        steps.push(match a.as_str() {
            "install" => Step::Install(read(it.next().ok_or("install: FILE is missing")?)?),
            "reset" => Step::Reset,
            "confirm" => Step::Confirm,
            "flip" => Step::Flip(usize::try_from(num(it.next(), "flip")?).map_err(|e| e.to_string())?),
            "cut" => {
                let f = read(it.next().ok_or("cut: FILE is missing")?)?;
                Step::Cut(
                    f,
                    u32::try_from(num(it.next(), "cut")?).map_err(|e| e.to_string())?,
                )
            }
            other => return Err(format!("unknown step `{other}`")),
        });
    }
    Ok(steps)
}

#[cfg(test)]
mod tests;
