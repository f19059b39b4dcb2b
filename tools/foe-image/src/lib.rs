//! The update file of the drive's firmware download (FoE, `docs/flashing.md`):
//! the image header v2 of `crates/boot` (magic "SC6F", body length, CRC-32 of
//! the body, version, format 2, load address, security counter, and the
//! Ed25519 signature of SHA-256(header bytes 0..32 ‖ body)) followed by the
//! body, the flash contents of the image. Key pairs: [`generate_seed`],
//! [`read_key`], [`key_hex`].
//!
//! The body comes from a flat binary as it is, or from an ELF: its loadable
//! segments (program headers of type `PT_LOAD` with file contents) laid out
//! at their load (physical) addresses, from the lowest one, gaps filled with
//! FFh (erased flash). `objcopy -O binary` writes the same bytes, except
//! that it fills the gaps with 00h (checked on the board image: 8 gap bytes
//! differ, nothing else).
#![forbid(unsafe_code)]

use boot::{ImageHeader, VerifyError, IMAGE_HEADER_LEN, KEY_LEN};
use object::read::elf::{ElfFile32, ProgramHeader as _};
use object::{elf, Endianness};
use std::path::{Path, PathBuf};

/// The name a file must start with for the drive to take it
/// (`drive_ecat::runtime::FIRMWARE_FILE`); masters send the file name they are given.
pub const FILE_PREFIX: &str = "firmware";

/// The firmware slots the tool knows, by the CPU address of each slot's body
/// (the load address an image linked for the slot has): the reference board
/// (XMC4800, cached alias; `bootloader::xmc4800::LAYOUT`), QEMU's mps2-an386
/// (`bootloader::mps2::LAYOUT`) and the simulated drive of `hil-sim`
/// (`hil_sim::sim::FirmwareSlots`). An image runs only from the slot it is
/// linked for; the drive refuses one for the other slot with FoE 8004h.
pub const KNOWN_SLOTS: &[(&str, [u32; 2])] = &[
    ("board XMC4800", [0x0804_0400, 0x080C_0400]),
    ("QEMU mps2-an386", [0x0000_8400, 0x0001_8400]),
    ("hil-sim", [0x0000_0400, 0x0004_2400]),
];

/// The slot (0 = A, 1 = B) an image with this load address is linked for,
/// and the layout it belongs to; `None`: no known slot (a standalone link).
pub fn slot_of(load_address: u32) -> Option<(&'static str, usize)> {
    KNOWN_SLOTS.iter().find_map(|(layout, bodies)| {
        bodies
            .iter()
            .position(|&b| b == load_address)
            .map(|slot| (*layout, slot))
    })
}

/// The update file's name for slot `slot` (0 = A, 1 = B):
/// `firmware-slot-a.sc6f` / `firmware-slot-b.sc6f` (it starts with
/// [`FILE_PREFIX`], so it is also the FoE name the drive takes).
pub fn slot_file_name(slot: usize) -> String {
    let letter = if slot == 0 { 'a' } else { 'b' };
    format!("{FILE_PREFIX}-slot-{letter}.sc6f")
}

/// The name `foe-image make` gives an update file by default: named for
/// the slot its load address is in ([`slot_file_name`]), else
/// `firmware.sc6f` (an image linked for no known slot).
pub fn default_file_name(load_address: u32) -> String {
    slot_of(load_address).map_or_else(|| format!("{FILE_PREFIX}.sc6f"), |(_, s)| slot_file_name(s))
}

/// Largest body the tool writes (a slot of the reference board is smaller;
/// the drive refuses what does not fit with FoE 8003h).
pub const MAX_BODY: usize = 4 << 20;

/// Why no update file was made.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ImageError {
    /// Not an ELF the tool can read (32-bit little-endian).
    Elf(String),
    /// The ELF has no loadable segment with contents.
    NoSegments,
    /// Loadable segments overlap.
    Overlap {
        /// Load address of the later segment.
        at: u32,
    },
    /// The body would be larger than [`MAX_BODY`].
    TooLarge(u64),
    /// The input is empty.
    Empty,
}

impl core::fmt::Display for ImageError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ImageError::Elf(e) => write!(f, "not a 32-bit little-endian ELF: {e}"),
            ImageError::NoSegments => write!(f, "the ELF has no loadable segment with contents"),
            ImageError::Overlap { at } => write!(f, "loadable segments overlap at {at:#010x}"),
            ImageError::TooLarge(n) => write!(f, "the body would be {n} bytes, more than {MAX_BODY}"),
            ImageError::Empty => write!(f, "the input is empty"),
        }
    }
}

impl std::error::Error for ImageError {}

/// The flash contents of an ELF: the body and its load address.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Body {
    /// Load address of the first byte.
    pub address: u32,
    /// The bytes, gaps filled with FFh.
    pub bytes: Vec<u8>,
}

/// Lays out the loadable segments of `elf` (see the crate docs).
pub fn body_from_elf(data: &[u8]) -> Result<Body, ImageError> {
    let file = ElfFile32::<Endianness>::parse(data).map_err(|e| ImageError::Elf(e.to_string()))?;
    let endian = file.endian();
    let mut segments: Vec<(u32, &[u8])> = Vec::new();
    for ph in file.elf_program_headers() {
        if ph.p_type(endian) != elf::PT_LOAD || ph.p_filesz(endian) == 0 {
            continue;
        }
        let bytes = ph
            .data(endian, data)
            .map_err(|()| ImageError::Elf("a segment lies outside the file".into()))?;
        segments.push((ph.p_paddr(endian), bytes));
    }
    segments.sort_by_key(|s| s.0);
    let (first, last) = match (segments.first(), segments.last()) {
        (Some(f), Some(l)) => (f.0, l),
        _ => return Err(ImageError::NoSegments),
    };
    let end = u64::from(last.0) + last.1.len() as u64;
    let len = end - u64::from(first);
    if len > MAX_BODY as u64 {
        return Err(ImageError::TooLarge(len));
    }
    let mut bytes = vec![0xFF; len as usize];
    let mut filled = 0usize;
    for (addr, seg) in segments {
        let at = (addr - first) as usize;
        if at < filled {
            return Err(ImageError::Overlap { at: addr });
        }
        let dst = bytes
            .get_mut(at..at + seg.len())
            .ok_or(ImageError::Overlap { at: addr })?;
        dst.copy_from_slice(seg);
        filled = at + seg.len();
    }
    Ok(Body {
        address: first,
        bytes,
    })
}

/// Whether `data` starts like an ELF file.
pub fn is_elf(data: &[u8]) -> bool {
    data.starts_with(&[0x7F, b'E', b'L', b'F'])
}

/// What goes into the header besides length and CRC.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ImageInfo {
    /// Version (informational).
    pub version: u32,
    /// The address the body is linked to run from (the body of the slot it
    /// goes to: the drive refuses another with FoE 8004h).
    pub load_address: u32,
    /// Security counter (the drive refuses one below its running image's
    /// with FoE 800Ah).
    pub security_counter: u32,
}

/// The update file of `body`: header signed with the secret `seed`, then the body.
pub fn update_file(body: &[u8], info: ImageInfo, seed: &[u8; KEY_LEN]) -> Result<Vec<u8>, ImageError> {
    if body.is_empty() {
        return Err(ImageError::Empty);
    }
    if body.len() > MAX_BODY {
        return Err(ImageError::TooLarge(body.len() as u64));
    }
    let mut h = ImageHeader::for_body(body, info.version, info.load_address, info.security_counter);
    h.sign(body, seed);
    let mut f = Vec::with_capacity(IMAGE_HEADER_LEN + body.len());
    f.extend_from_slice(&h.to_bytes());
    f.extend_from_slice(body);
    Ok(f)
}

/// A new secret seed (32 bytes) from the operating system's random source.
pub fn generate_seed() -> Result<[u8; KEY_LEN], String> {
    let mut seed = [0u8; KEY_LEN];
    getrandom::fill(&mut seed).map_err(|e| format!("no random numbers from the OS: {e}"))?;
    Ok(seed)
}

/// The public key of a secret seed.
pub fn public_key(seed: &[u8; KEY_LEN]) -> [u8; KEY_LEN] {
    boot::public_key(seed)
}

/// A key as the key files hold it: 64 lower-case hex digits and a newline.
pub fn key_hex(key: &[u8; KEY_LEN]) -> String {
    let mut s: String = key.iter().map(|b| format!("{b:02x}")).collect();
    s.push('\n');
    s
}

/// Reads a key file (a secret seed or a public key: 64 hex digits).
pub fn read_key(path: &Path) -> Result<[u8; KEY_LEN], String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    boot::parse_key_hex(&String::from_utf8_lossy(&bytes))
        .ok_or_else(|| format!("{}: not a key file (64 hex digits)", path.display()))
}

/// The public key file beside the secret `key` file: `NAME.pub` for
/// `NAME.key`, else `key` with `.pub` appended.
pub fn pub_path(key: &Path) -> PathBuf {
    if key.extension().is_some_and(|e| e == "key") {
        key.with_extension("pub")
    } else {
        let mut s = key.as_os_str().to_owned();
        s.push(".pub");
        PathBuf::from(s)
    }
}

/// What is wrong with an update file, as the drive would find it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CheckError {
    /// Shorter than the header, not the magic "SC6F" or not the header
    /// format 2 (e.g. an unsigned v1 file; the drive: FoE 8004h).
    Header,
    /// The body is shorter or longer than the header says (800Ch).
    Length {
        /// Body length the header names.
        expected: u32,
        /// Body bytes in the file.
        found: usize,
    },
    /// The body's CRC-32 is not the header's (800Ch).
    Crc {
        /// CRC in the header.
        expected: u32,
        /// CRC of the body.
        found: u32,
    },
    /// The signature does not verify with the public key (800Ch).
    Signature,
}

impl core::fmt::Display for CheckError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            CheckError::Header => write!(
                f,
                "no image header v2 (magic \"SC6F\", format 2): the drive refuses it with FoE 8004h"
            ),
            CheckError::Length { expected, found } => write!(
                f,
                "the header names {expected} body bytes, the file has {found}: the drive refuses it with FoE 800Ch"
            ),
            CheckError::Crc { expected, found } => write!(
                f,
                "body CRC-32 {found:#010x}, header {expected:#010x}: the drive refuses it with FoE 800Ch"
            ),
            CheckError::Signature => write!(
                f,
                "the signature does not verify with the public key: a drive with that key refuses it with FoE 800Ch"
            ),
        }
    }
}

impl std::error::Error for CheckError {}

/// Checks an update file as the drive does at the end of the download
/// (header, length, CRC-32 and, with `public_key`, the signature; not the
/// load address and the security counter, which depend on the drive);
/// returns its header.
pub fn check(file: &[u8], public_key: Option<&[u8; KEY_LEN]>) -> Result<ImageHeader, CheckError> {
    let h = ImageHeader::parse(file).ok_or(CheckError::Header)?;
    let body = file.get(IMAGE_HEADER_LEN..).unwrap_or_default();
    if usize::try_from(h.length).ok() != Some(body.len()) {
        return Err(CheckError::Length {
            expected: h.length,
            found: body.len(),
        });
    }
    let crc = boot::crc32(body);
    if crc != h.crc {
        return Err(CheckError::Crc {
            expected: h.crc,
            found: crc,
        });
    }
    if let Some(key) = public_key {
        match boot::verify_file(file, key) {
            Ok(_) => {}
            Err(VerifyError::Crc) => {
                return Err(CheckError::Crc {
                    expected: h.crc,
                    found: crc,
                })
            }
            Err(_) => return Err(CheckError::Signature),
        }
    }
    Ok(h)
}
