//! `flash-compose`: the flash file of the boot-loader scenarios on QEMU's
//! mps2-an386 (docs/flashing.md, "Boot scenarios in QEMU").
//!
//! ```text
//! flash-compose [--board] BOOT.elf OUT.bin STEP...
//!   --board        the XMC4800 layout: a file to flash at 0x0C00_0000 (default: QEMU's mps2-an386, at 0)
//!   install FILE   the running image downloads update file FILE into the inactive slot
//!   reset          power-on: the boot loader's decision (TRIED mark, rollback)
//!   confirm        the running image confirms itself
//!   flip N         flip a bit of body byte N of the slot last installed
//!   cut FILE N     download FILE, the power failing at flash operation N
//! ```
#![forbid(unsafe_code)]

use flash_compose::{boot_bytes, compose_for, parse_steps, Target};
use std::process::ExitCode;

fn run(args: &[String]) -> Result<(), String> {
    let (target, args) = match args {
        [flag, rest @ ..] if flag == "--board" => (Target::Xmc4800, rest),
        _ => (Target::Mps2, args),
    };
    let [boot, out, steps @ ..] = args else {
        return Err(
            "usage: flash-compose [--board] BOOT.elf OUT.bin [install FILE|reset|confirm|flip N|cut FILE N]...".into(),
        );
    };
    let read = |p: &str| std::fs::read(p).map_err(|e| format!("{p}: {e}"));
    let steps = parse_steps(steps, &read)?;
    let image = compose_for(target, &boot_bytes(&read(boot)?, target)?, &steps, &mut |line| {
        println!("flash-compose: {line}")
    })?;
    std::fs::write(out, &image).map_err(|e| format!("{out}: {e}"))?;
    println!("flash-compose: {out}: {} bytes", image.len());
    Ok(())
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("flash-compose: {e}");
            ExitCode::FAILURE
        }
    }
}
