//! `foe-image`: writes the update file the drive takes over FoE, and checks one.
//!
//! ```text
//! foe-image make --version N [--out FILE] INPUT   # INPUT: the firmware ELF or a flat binary
//! foe-image check FILE
//! ```
//!
//! The drive takes a download whose FoE file name starts with `firmware`
//! (docs/flashing.md), so the default output is `firmware.sc6f` beside the input.
#![forbid(unsafe_code)]

use clap::{Parser, Subcommand};
use foe_image::{body_from_elf, check, is_elf, update_file, FILE_PREFIX};
use std::path::PathBuf;
use std::process::ExitCode;

/// Firmware update files for the drive's FoE download (docs/flashing.md).
#[derive(Parser)]
#[command(name = "foe-image", version)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Write INPUT (the firmware ELF, or a flat binary) as an update file.
    Make {
        /// Version written into the header (a number, e.g. the build number).
        #[arg(long)]
        version: u32,
        /// Output file; its name must start with "firmware" for the drive to take it.
        #[arg(long, short)]
        out: Option<PathBuf>,
        /// The firmware ELF (its loadable segments) or a flat binary.
        input: PathBuf,
    },
    /// Check an update file as the drive does (header, length, CRC-32).
    Check {
        /// The update file.
        file: PathBuf,
    },
}

fn run(cli: Cli) -> Result<(), String> {
    match cli.command {
        Command::Make { version, out, input } => {
            let data = std::fs::read(&input).map_err(|e| format!("{}: {e}", input.display()))?;
            let (body, from) = if is_elf(&data) {
                let b = body_from_elf(&data).map_err(|e| format!("{}: {e}", input.display()))?;
                (b.bytes, format!("ELF, loaded at {:#010x}", b.address))
            } else {
                (data, "flat binary".to_string())
            };
            let file = update_file(&body, version).map_err(|e| format!("{}: {e}", input.display()))?;
            let out = out.unwrap_or_else(|| input.with_file_name(format!("{FILE_PREFIX}.sc6f")));
            let named_ok = out
                .file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with(FILE_PREFIX));
            std::fs::write(&out, &file).map_err(|e| format!("{}: {e}", out.display()))?;
            let h = check(&file).map_err(|e| e.to_string())?;
            println!(
                "{}: {} bytes ({from}), body {} bytes, CRC-32 {:#010x}, version {}",
                out.display(),
                file.len(),
                h.length,
                h.crc,
                h.version
            );
            if !named_ok {
                eprintln!(
                    "foe-image: note: the drive takes only FoE file names starting with \"{FILE_PREFIX}\"; \
                     give the master such a name"
                );
            }
            Ok(())
        }
        Command::Check { file } => {
            let data = std::fs::read(&file).map_err(|e| format!("{}: {e}", file.display()))?;
            let h = check(&data).map_err(|e| format!("{}: {e}", file.display()))?;
            println!(
                "{}: update file, body {} bytes, CRC-32 {:#010x}, version {}",
                file.display(),
                h.length,
                h.crc,
                h.version
            );
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("foe-image: {e}");
            ExitCode::FAILURE
        }
    }
}
