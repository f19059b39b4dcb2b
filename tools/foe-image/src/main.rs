//! `foe-image`: writes the signed update file the drive takes over FoE, checks
//! one, and makes signing key pairs.
//!
//! ```text
//! foe-image make --version N --key SEED_FILE [--security-counter N] [--load-addr ADDR] [--out FILE] INPUT
//! foe-image check [--pub PUBLIC_KEY_FILE] FILE
//! foe-image keygen --out FILE          # FILE: the secret seed; FILE.pub (or NAME.pub for NAME.key)
//! ```
//!
//! INPUT is the firmware ELF or a flat binary. An image runs from the slot it
//! is linked for, and the drive takes only the file for the slot it did not
//! start from (the other one: FoE 8004h), so the default output is named
//! for the slot of its load address, `firmware-slot-a.sc6f` or
//! `firmware-slot-b.sc6f` beside the input (`firmware.sc6f` for an image
//! linked for no known slot, with a warning); the drive takes FoE file names
//! starting with `firmware` (docs/flashing.md). `keys/dev-ed25519.key` is
//! the development key (never for a production drive).
#![forbid(unsafe_code)]

use clap::{Parser, Subcommand};
use foe_image::{
    body_from_elf, check, default_file_name, generate_seed, is_elf, key_hex, pub_path, public_key, read_key,
    slot_of, update_file, ImageInfo, FILE_PREFIX,
};
use std::path::PathBuf;
use std::process::ExitCode;

/// Firmware update files for the drive's FoE download (docs/flashing.md).
///
/// A drive has two firmware slots (A, B) and runs its image in place, so an
/// image is linked for one slot, and a download goes to the slot the drive
/// did not start from: the file for the other slot is refused (FoE 8004h).
/// Build the image once per slot (`scripts/cross foe-image` does: both files,
/// firmware-slot-a.sc6f and firmware-slot-b.sc6f) and send the file for the
/// drive's update slot, object E54 (2836h: 1 = A, 2 = B).
#[derive(Parser)]
#[command(name = "foe-image", version)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// A number in decimal or with 0x (hex).
fn number(s: &str) -> Result<u32, String> {
    let s = s.replace('_', "");
    match s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")) {
        Some(hex) => u32::from_str_radix(hex, 16),
        None => s.parse(),
    }
    .map_err(|e| format!("{s}: {e}"))
}

#[derive(Subcommand)]
enum Command {
    /// Write INPUT (the firmware ELF, or a flat binary) as a signed update file.
    Make {
        /// Version written into the header (a number, e.g. the build number).
        #[arg(long)]
        version: u32,
        /// The secret key (seed) file to sign with, 64 hex digits (e.g. keys/dev-ed25519.key).
        #[arg(long)]
        key: PathBuf,
        /// Security counter: the drive refuses an image below its running image's.
        #[arg(long, default_value = "0", value_parser = number)]
        security_counter: u32,
        /// The address the body is linked to run from (the body of the target slot);
        /// default: the lowest load address of the ELF; required for a flat binary.
        #[arg(long, value_parser = number)]
        load_addr: Option<u32>,
        /// Output file; its name must start with "firmware" for the drive to take it.
        /// Default: named for the slot of the load address, firmware-slot-a.sc6f or
        /// firmware-slot-b.sc6f beside INPUT (firmware.sc6f for an image linked for no slot).
        #[arg(long, short)]
        out: Option<PathBuf>,
        /// The firmware ELF (its loadable segments) or a flat binary.
        input: PathBuf,
    },
    /// Check an update file as the drive does (header, length, CRC-32, signature).
    Check {
        /// The public key file to verify the signature with (without it the
        /// signature is not checked).
        #[arg(long = "pub")]
        public: Option<PathBuf>,
        /// The update file.
        file: PathBuf,
    },
    /// Write a new key pair: the secret seed to FILE, the public key beside it.
    Keygen {
        /// The secret key file (NAME.key gets NAME.pub beside it, other names FILE.pub).
        #[arg(long, short)]
        out: PathBuf,
    },
}

fn make(
    version: u32,
    key: PathBuf,
    security_counter: u32,
    load_addr: Option<u32>,
    out: Option<PathBuf>,
    input: PathBuf,
) -> Result<(), String> {
    let seed = read_key(&key)?;
    let data = std::fs::read(&input).map_err(|e| format!("{}: {e}", input.display()))?;
    let (body, from, address) = if is_elf(&data) {
        let b = body_from_elf(&data).map_err(|e| format!("{}: {e}", input.display()))?;
        let from = format!("ELF, loaded at {:#010x}", b.address);
        (b.bytes, from, Some(b.address))
    } else {
        (data, "flat binary".to_string(), None)
    };
    let load_address = load_addr.or(address).ok_or_else(|| {
        format!(
            "{}: a flat binary needs --load-addr (the body's address in its slot)",
            input.display()
        )
    })?;
    let info = ImageInfo {
        version,
        load_address,
        security_counter,
    };
    let file = update_file(&body, info, &seed).map_err(|e| format!("{}: {e}", input.display()))?;
    let out = out.unwrap_or_else(|| input.with_file_name(default_file_name(load_address)));
    let named_ok = out
        .file_name()
        .and_then(|n| n.to_str())
        .is_some_and(|n| n.starts_with(FILE_PREFIX));
    let h = check(&file, Some(&public_key(&seed))).map_err(|e| e.to_string())?;
    std::fs::write(&out, &file).map_err(|e| format!("{}: {e}", out.display()))?;
    println!(
        "{}: {} bytes ({from}), body {} bytes, CRC-32 {:#010x}, version {}, load address {:#010x}, \
         security counter {}, signed with {}",
        out.display(),
        file.len(),
        h.length,
        h.crc,
        h.version,
        h.load_address,
        h.security_counter,
        key.display()
    );
    match slot_of(load_address) {
        Some((layout, slot)) => println!(
            "{}: linked for slot {} ({layout}): the drive takes it when its update slot E54 is {}",
            out.display(),
            if slot == 0 { 'A' } else { 'B' },
            slot + 1
        ),
        None => eprintln!(
            "foe-image: warning: load address {load_address:#010x} is in no firmware slot the tool knows: \
             a drive refuses it (FoE 8004h); link the image for a slot (FIRMWARE_SLOT=a|b)"
        ),
    }
    if seed_is_dev(&seed) {
        eprintln!("foe-image: note: signed with the DEVELOPMENT key: never for a production drive");
    }
    if !named_ok {
        eprintln!(
            "foe-image: note: the drive takes only FoE file names starting with \"{FILE_PREFIX}\"; \
             give the master such a name"
        );
    }
    Ok(())
}

fn seed_is_dev(seed: &[u8; 32]) -> bool {
    public_key(seed) == boot::DEV_PUBLIC_KEY
}

fn run(cli: Cli) -> Result<(), String> {
    match cli.command {
        Command::Make {
            version,
            key,
            security_counter,
            load_addr,
            out,
            input,
        } => make(version, key, security_counter, load_addr, out, input),
        Command::Check { public, file } => {
            let key = public.as_deref().map(read_key).transpose()?;
            let data = std::fs::read(&file).map_err(|e| format!("{}: {e}", file.display()))?;
            let h = check(&data, key.as_ref()).map_err(|e| format!("{}: {e}", file.display()))?;
            let signature = match &public {
                Some(p) => format!("signature verified with {}", p.display()),
                None => "signature not checked (no --pub)".to_string(),
            };
            println!(
                "{}: update file, body {} bytes, CRC-32 {:#010x}, version {}, load address {:#010x}, \
                 security counter {}, {signature}",
                file.display(),
                h.length,
                h.crc,
                h.version,
                h.load_address,
                h.security_counter
            );
            Ok(())
        }
        Command::Keygen { out } => {
            let public = pub_path(&out);
            for p in [&out, &public] {
                if p.exists() {
                    return Err(format!("{}: exists; not overwritten", p.display()));
                }
            }
            let seed = generate_seed()?;
            write_secret(&out, &key_hex(&seed))?;
            std::fs::write(&public, key_hex(&public_key(&seed)))
                .map_err(|e| format!("{}: {e}", public.display()))?;
            println!(
                "{}: secret key (keep it off the repository); {}: public key (SC6_FIRMWARE_PUBLIC_KEY)",
                out.display(),
                public.display()
            );
            Ok(())
        }
    }
}

/// Writes the secret key file, readable by its owner only (on Unix).
fn write_secret(path: &std::path::Path, text: &str) -> Result<(), String> {
    use std::io::Write;
    let mut opts = std::fs::OpenOptions::new();
    opts.write(true).create_new(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        opts.mode(0o600);
    }
    let mut f = opts.open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    f.write_all(text.as_bytes())
        .map_err(|e| format!("{}: {e}", path.display()))
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
