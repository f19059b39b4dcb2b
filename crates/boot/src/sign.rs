//! Signed images (issue 18): the image header v2 and its Ed25519 signature.
//!
//! The signature covers SHA-256(header bytes before the signature ‖ body): the
//! digest is computed in one pass over the body (as it streams in from flash,
//! [`ImageHasher`]) and the 32-byte digest is the Ed25519 message (the scheme
//! MCUboot uses for its ED25519 TLV). Verification ([`ed25519_verify`]) is
//! built on `salty`'s curve arithmetic (small, no_std, Cortex-M4 field
//! arithmetic); SHA-256 and SHA-512 are RustCrypto's `sha2` without its
//! default features. Signing (feature `sign`, host tools) is salty's.

use crate::{le32, Crc32, FlashError};
use salty::{CompressedY, EdwardsPoint, Scalar};
use sha2::{Digest, Sha256, Sha512};
use subtle::{Choice, ConditionallySelectable};

/// "SC6F": the image file's magic.
pub const IMAGE_MAGIC: u32 = 0x4636_4353;
/// The header format this crate writes and takes (offset 16 of the header).
pub const IMAGE_FORMAT: u32 = 2;
/// Length of the image file's header (v2), signature included.
pub const IMAGE_HEADER_LEN: usize = 96;
/// The header bytes the signature covers (everything before it).
pub const SIGNED_HEADER_LEN: usize = 32;
/// Length of an Ed25519 signature.
pub const SIGNATURE_LEN: usize = 64;
/// Length of an Ed25519 public key (and of its secret seed).
pub const KEY_LEN: usize = 32;

/// The public key of the **development** key pair (`keys/dev-ed25519.pub`):
/// its secret seed is in the repository, so it proves nothing about who made
/// an image. The simulator and QEMU use it; a production drive must be built
/// with a key of its own (docs/flashing.md).
pub const DEV_PUBLIC_KEY: [u8; KEY_LEN] = match parse_key_hex(include_str!("../../../keys/dev-ed25519.pub")) {
    Some(k) => k,
    // evaluated at compile time: a broken key file does not build
    #[allow(clippy::panic)]
    None => panic!("keys/dev-ed25519.pub is not 64 hex digits"),
};

/// The public key a firmware image must be signed with, chosen when this crate
/// is built: the 64 hex digits of the environment variable
/// `SC6_FIRMWARE_PUBLIC_KEY`, else the **development** key ([`DEV_PUBLIC_KEY`]),
/// which the simulator and the QEMU images use. One constant for the boot
/// loader (`bootloader::PUBLIC_KEY`) and the application's FoE path
/// (`drive_ecat::runtime::FIRMWARE_PUBLIC_KEY`). A malformed value does not build.
pub const FIRMWARE_PUBLIC_KEY: [u8; KEY_LEN] = match option_env!("SC6_FIRMWARE_PUBLIC_KEY") {
    Some(hex) => match parse_key_hex(hex) {
        Some(k) => k,
        // evaluated at compile time: a build error, never a run-time panic
        #[allow(clippy::panic)]
        None => panic!("SC6_FIRMWARE_PUBLIC_KEY is not 64 hex digits"),
    },
    None => DEV_PUBLIC_KEY,
};

/// Whether [`FIRMWARE_PUBLIC_KEY`] is the development key (never for a
/// production drive).
pub const FIRMWARE_KEY_IS_DEVELOPMENT: bool = option_env!("SC6_FIRMWARE_PUBLIC_KEY").is_none();

/// A key (public key or secret seed) from 64 hex digits; surrounding white
/// space (a trailing newline) is ignored. `const`, so a key can be chosen at
/// build time (`option_env!`).
pub const fn parse_key_hex(s: &str) -> Option<[u8; KEY_LEN]> {
    let mut b = s.as_bytes();
    while let [c, rest @ ..] = b {
        if !c.is_ascii_whitespace() {
            break;
        }
        b = rest;
    }
    while let [rest @ .., c] = b {
        if !c.is_ascii_whitespace() {
            break;
        }
        b = rest;
    }
    let mut key = [0u8; KEY_LEN];
    let mut out: &mut [u8] = &mut key;
    while let [hi, lo, rest @ ..] = b {
        let (Some(hi), Some(lo), [k, more @ ..]) = (hex_digit(*hi), hex_digit(*lo), out) else {
            return None;
        };
        *k = (hi << 4) | lo;
        out = more;
        b = rest;
    }
    if !b.is_empty() || !out.is_empty() {
        return None;
    }
    Some(key)
}

const fn hex_digit(c: u8) -> Option<u8> {
    match c {
        b'0'..=b'9' => Some(c - b'0'),
        b'a'..=b'f' => Some(c - b'a' + 10),
        b'A'..=b'F' => Some(c - b'A' + 10),
        _ => None,
    }
}

/// The image file's header (v2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ImageHeader {
    /// Body length in bytes.
    pub length: u32,
    /// CRC-32/ISO-HDLC of the body.
    pub crc: u32,
    /// Version of the image (informational).
    pub version: u32,
    /// The address the body is linked to run from: the CPU address of its
    /// first byte in the slot it executes in place from
    /// ([`BootSlots::load_address`](crate::BootSlots::load_address)).
    pub load_address: u32,
    /// Security counter: an image below the running one's (or the board's
    /// minimum) is refused (downgrade protection, docs/flashing.md).
    pub security_counter: u32,
    /// Ed25519 signature of [`ImageHeader::digest`] (all zero: unsigned).
    pub signature: [u8; SIGNATURE_LEN],
}

impl ImageHeader {
    /// The unsigned header of `body` (signature all zero): sign it with
    /// `ImageHeader::sign` (feature `sign`).
    pub fn for_body(body: &[u8], version: u32, load_address: u32, security_counter: u32) -> Self {
        Self {
            length: u32::try_from(body.len()).unwrap_or(u32::MAX),
            crc: crate::crc32(body),
            version,
            load_address,
            security_counter,
            signature: [0; SIGNATURE_LEN],
        }
    }

    /// The header's bytes.
    pub fn to_bytes(&self) -> [u8; IMAGE_HEADER_LEN] {
        let mut b = [0u8; IMAGE_HEADER_LEN];
        let (signed, sig) = b.split_at_mut(SIGNED_HEADER_LEN);
        signed.copy_from_slice(&self.signed_bytes());
        sig.copy_from_slice(&self.signature);
        b
    }

    /// The bytes the signature covers: magic, length, CRC, version, format,
    /// load address, security counter, reserved (0), all u32 LE.
    pub fn signed_bytes(&self) -> [u8; SIGNED_HEADER_LEN] {
        let mut b = [0u8; SIGNED_HEADER_LEN];
        let fields = [
            IMAGE_MAGIC,
            self.length,
            self.crc,
            self.version,
            IMAGE_FORMAT,
            self.load_address,
            self.security_counter,
            0,
        ];
        for (dst, v) in b.chunks_exact_mut(4).zip(fields) {
            dst.copy_from_slice(&v.to_le_bytes());
        }
        b
    }

    /// Parses a header; `None` when the magic, the format (a v1 header) or
    /// the reserved word is wrong, or `b` is short.
    pub fn parse(b: &[u8]) -> Option<Self> {
        let ok = le32(b, 0)? == IMAGE_MAGIC && le32(b, 16)? == IMAGE_FORMAT && le32(b, 28)? == 0;
        let signature = <[u8; SIGNATURE_LEN]>::try_from(b.get(SIGNED_HEADER_LEN..IMAGE_HEADER_LEN)?).ok()?;
        ok.then_some(Self {
            length: le32(b, 4)?,
            crc: le32(b, 8)?,
            version: le32(b, 12)?,
            load_address: le32(b, 20)?,
            security_counter: le32(b, 24)?,
            signature,
        })
    }

    /// SHA-256(signed header bytes ‖ `body`), the signed message.
    pub fn digest(&self, body: &[u8]) -> [u8; 32] {
        let mut h = ImageHasher::new(self);
        h.update(body);
        h.finish().0
    }

    /// Signs the header for `body` with the secret `seed` (host tools and
    /// tests; feature `sign`).
    #[cfg(feature = "sign")]
    pub fn sign(&mut self, body: &[u8], seed: &[u8; KEY_LEN]) {
        let pair = salty::Keypair::from(seed);
        self.signature = pair.sign(&self.digest(body)).to_bytes();
    }
}

/// The public key of a secret `seed` (host tools and tests; feature `sign`).
#[cfg(feature = "sign")]
pub fn public_key(seed: &[u8; KEY_LEN]) -> [u8; KEY_LEN] {
    *salty::Keypair::from(seed).public.as_bytes()
}

/// The CRC-32 and the signed digest of an image, fed with its body in pieces.
#[derive(Clone)]
pub struct ImageHasher {
    sha: Sha256,
    crc: Crc32,
}

impl ImageHasher {
    /// Starts with the signed bytes of `header`.
    pub fn new(header: &ImageHeader) -> Self {
        let mut sha = Sha256::new();
        sha.update(header.signed_bytes());
        Self {
            sha,
            crc: Crc32::new(),
        }
    }

    /// The next body bytes.
    pub fn update(&mut self, body: &[u8]) {
        self.sha.update(body);
        self.crc.update(body);
    }

    /// (digest, CRC-32 of the body).
    pub fn finish(self) -> ([u8; 32], u32) {
        (self.sha.finalize().into(), self.crc.finish())
    }
}

/// Why an image is not accepted as signed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VerifyError {
    /// Not a v2 header (magic, format), or the body does not fit the slot.
    Header,
    /// The body's CRC-32 is not the header's.
    Crc,
    /// The signature does not verify with the key (another key, a changed
    /// header or body, or no signature at all).
    Signature,
    /// The public key is not a valid Ed25519 point.
    Key,
    /// The load address is not the one of the slot the image is in.
    LoadAddress,
    /// The flash failed.
    Flash(FlashError),
}

impl From<FlashError> for VerifyError {
    fn from(e: FlashError) -> Self {
        VerifyError::Flash(e)
    }
}

/// The group order L of Ed25519, little-endian: a signature's S must be below
/// it (a non-canonical S is a second signature of the
/// same message).
const ORDER: [u8; 32] = [
    0xed, 0xd3, 0xf5, 0x5c, 0x1a, 0x63, 0x12, 0x58, 0xd6, 0x9c, 0xf7, 0xa2, 0xde, 0xf9, 0xde, 0x14, 0, 0, 0,
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x10,
];

fn canonical(s: &[u8]) -> bool {
    // compare little-endian numbers from the most significant byte
    for (a, l) in s.iter().rev().zip(ORDER.iter().rev()) {
        if a != l {
            return a < l;
        }
    }
    false
}

/// Checks the Ed25519 signature of `header` over `digest` with `public_key`.
pub fn verify_digest(
    header: &ImageHeader,
    digest: &[u8; 32],
    public_key: &[u8; KEY_LEN],
) -> Result<(), VerifyError> {
    ed25519_verify(public_key, digest, &header.signature)
}

/// Ed25519 verification (RFC 8032 §5.1.7, cofactorless, as salty's
/// `PublicKey::verify`) of `signature` = R ‖ S over `message`: S must be
/// canonical (below L), A = `public_key` must decode to a curve point, and
/// the encoding of \[S\]B − \[k\]A must be R, k = SHA-512(R ‖ A ‖ message)
/// mod L.
///
/// Built from salty's curve and scalar arithmetic with two parts of our own,
/// so that no panic site is reachable (`scripts/cross panics`): the SHA-512 is
/// RustCrypto's `sha2` (salty's own indexes and unwraps where the compiler
/// cannot prove the bounds), and `mul` replaces salty's `Scalar *
/// EdwardsPoint` (an indexed bit loop) with the same ladder over iterators.
pub fn ed25519_verify(
    public_key: &[u8; KEY_LEN],
    message: &[u8],
    signature: &[u8; SIGNATURE_LEN],
) -> Result<(), VerifyError> {
    #[cfg(feature = "external-ed25519")]
    {
        extern "Rust" {
            fn sc6_ed25519_verify(
                public_key: &[u8; KEY_LEN],
                message: &[u8],
                signature: &[u8; SIGNATURE_LEN],
            ) -> Result<(), VerifyError>;
        }
        // SAFETY: the feature's contract (see `BootApi`): the binary defines
        // `sc6_ed25519_verify` as a safe Rust function of exactly this
        // signature, so the call is an ordinary safe call across crates.
        #[allow(unsafe_code)]
        unsafe {
            sc6_ed25519_verify(public_key, message, signature)
        }
    }
    #[cfg(not(feature = "external-ed25519"))]
    ed25519_verify_builtin(public_key, message, signature)
}

/// [`ed25519_verify`] with this crate's own verifier, whatever the features:
/// what a boot loader offers the running image through its [`BootApi`].
pub fn ed25519_verify_builtin(
    public_key: &[u8; KEY_LEN],
    message: &[u8],
    signature: &[u8; SIGNATURE_LEN],
) -> Result<(), VerifyError> {
    let Some((r, s)) = signature.split_first_chunk::<32>() else {
        return Err(VerifyError::Signature);
    };
    let s: &[u8; 32] = s.try_into().map_err(|_| VerifyError::Signature)?;
    if !canonical(s) {
        return Err(VerifyError::Signature);
    }
    let mut h = Sha512::new();
    h.update(r);
    h.update(public_key);
    h.update(message);
    let mut wide = [0u8; 64];
    wide.copy_from_slice(&h.finalize());
    #[cfg(fuzzing)]
    if let Some(result) = fuzz_memo::get(public_key, signature, &wide) {
        return result;
    }
    let result = (|| {
        let a = CompressedY(*public_key)
            .decompressed()
            .map_err(|_| VerifyError::Key)?;
        let k = Scalar::from_u512_le(&wide);
        let check = &mul(&Scalar(*s), &EdwardsPoint::basepoint()) + &mul(&k, &-&a);
        if check.compressed() == CompressedY(*r) {
            Ok(())
        } else {
            Err(VerifyError::Signature)
        }
    })();
    #[cfg(fuzzing)]
    fuzz_memo::put(public_key, signature, &wide, result);
    result
}

/// Fuzz builds only (`cargo fuzz` sets `--cfg fuzzing`): the last
/// verification's result, keyed by the key, the signature and the hash of
/// R ‖ A ‖ message, so the same image verified again (the `foe` target
/// downloads the same signed image input after input) does not run the
/// curve arithmetic again: the same inputs give the same result, so nothing
/// the fuzzer explores changes, only the cost (nine tenths of the target's
/// time). Never in a firmware or test build.
#[cfg(fuzzing)]
mod fuzz_memo {
    extern crate std;
    use super::{VerifyError, KEY_LEN, SIGNATURE_LEN};
    use core::cell::RefCell;

    type Key = ([u8; KEY_LEN], [u8; SIGNATURE_LEN], [u8; 64]);

    std::thread_local! {
        static LAST: RefCell<Option<(Key, Result<(), VerifyError>)>> = const { RefCell::new(None) };
    }

    pub(super) fn get(
        key: &[u8; KEY_LEN],
        sig: &[u8; SIGNATURE_LEN],
        hash: &[u8; 64],
    ) -> Option<Result<(), VerifyError>> {
        LAST.with(|l| match &*l.borrow() {
            Some(((k, s, h), r)) if k == key && s == sig && h == hash => Some(*r),
            _ => None,
        })
    }

    pub(super) fn put(
        key: &[u8; KEY_LEN],
        sig: &[u8; SIGNATURE_LEN],
        hash: &[u8; 64],
        r: Result<(), VerifyError>,
    ) {
        LAST.with(|l| *l.borrow_mut() = Some(((*key, *sig, *hash), r)));
    }
}

/// \[scalar\]·point: the constant-time Montgomery ladder of salty's
/// `Scalar * EdwardsPoint`, the scalar's bits from the most significant one,
/// read with `get` instead of an index (one loop of 256 steps: the point
/// addition is large, so the loop must not be unrolled).
#[inline(never)]
fn mul(scalar: &Scalar, point: &EdwardsPoint) -> EdwardsPoint {
    let mut p = EdwardsPoint::neutral_element();
    let mut q = *point;
    for i in (0..256usize).rev() {
        let byte = scalar.0.get(i / 8).copied().unwrap_or(0);
        let b = Choice::from((byte >> (i & 7)) & 1);
        EdwardsPoint::conditional_swap(&mut p, &mut q, b);
        q = &q + &p;
        p = &p + &p;
        EdwardsPoint::conditional_swap(&mut p, &mut q, b);
    }
    p
}

/// The boot loader's services for the running image: a table at a fixed flash
/// address ([`BOOT_API_OFFSET`] from the boot loader's start), so the image can
/// verify a download with the boot loader's Ed25519 code instead of linking a
/// second copy (the board image's flash goal, docs/flashing.md "Signed
/// images"). An image built with the feature `external-ed25519` defines
///
/// ```text
/// #[no_mangle]
/// fn sc6_ed25519_verify(public_key: &[u8; 32], message: &[u8], signature: &[u8; 64])
///     -> Result<(), boot::VerifyError>
/// ```
///
/// which reads this table, checks [`BootApi::magic`] (a missing or older boot
/// loader: refused, [`VerifyError::Key`]) and calls
/// [`BootApi::ed25519_verify`]. The boot loader's flash is never erased in the
/// field, so the table stays where the image expects it.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct BootApi {
    /// [`BOOT_API_MAGIC`]: the table's layout and calling convention.
    pub magic: [u8; 8],
    /// [`ed25519_verify_builtin`] of the boot loader: `public_key` (32 bytes),
    /// `message` (`message_len` bytes), `signature` (64 bytes) must be readable
    /// for the call; returns 0 (verified), 1 (signature), 2 (key).
    pub ed25519_verify: Option<
        unsafe extern "C" fn(
            public_key: *const u8,
            message: *const u8,
            message_len: usize,
            signature: *const u8,
        ) -> u32,
    >,
}

/// Magic and version of the [`BootApi`] table.
pub const BOOT_API_MAGIC: [u8; 8] = *b"SC6BAPI1";

/// Offset of the [`BootApi`] table from the boot loader's first byte: right
/// after a vector table of 256 words.
pub const BOOT_API_OFFSET: u32 = 0x400;

/// The [`BootApi::ed25519_verify`] result of a verification.
pub const fn boot_api_code(r: Result<(), VerifyError>) -> u32 {
    match r {
        Ok(()) => 0,
        Err(VerifyError::Key) => 2,
        Err(_) => 1,
    }
}

/// The verification result of a [`BootApi::ed25519_verify`] code (anything
/// but 0 is a refusal).
pub const fn boot_api_result(code: u32) -> Result<(), VerifyError> {
    match code {
        0 => Ok(()),
        2 => Err(VerifyError::Key),
        _ => Err(VerifyError::Signature),
    }
}

/// Read chunk for the streamed checks (stack).
pub(crate) const CHUNK: usize = 256;

/// Verifies an image: `header_bytes` (at least [`IMAGE_HEADER_LEN`]) and its
/// body, read through `read_body(offset, buf)` in chunks of at most 256 bytes
/// (no heap; a flash, or a slice in memory). Checks the header format, the
/// CRC-32 and the signature (not the load address: that depends on the slot,
/// see [`BootSlots::verify`](crate::BootSlots::verify)). Returns the header.
pub fn verify_image(
    header_bytes: &[u8],
    mut read_body: impl FnMut(usize, &mut [u8]) -> Result<(), FlashError>,
    public_key: &[u8; KEY_LEN],
) -> Result<ImageHeader, VerifyError> {
    let header = ImageHeader::parse(header_bytes).ok_or(VerifyError::Header)?;
    let mut hasher = ImageHasher::new(&header);
    let len = header.length as usize;
    let mut buf = [0u8; CHUNK];
    let mut done = 0;
    while done < len {
        let n = (len - done).min(CHUNK);
        let chunk = buf.get_mut(..n).ok_or(VerifyError::Header)?;
        read_body(done, chunk)?;
        hasher.update(chunk);
        done += n;
    }
    let (digest, crc) = hasher.finish();
    if crc != header.crc {
        return Err(VerifyError::Crc);
    }
    verify_digest(&header, &digest, public_key)?;
    Ok(header)
}

/// [`verify_image`] of a whole update file in memory (header, then exactly
/// the body).
pub fn verify_file(file: &[u8], public_key: &[u8; KEY_LEN]) -> Result<ImageHeader, VerifyError> {
    let (head, body) = file
        .split_at_checked(IMAGE_HEADER_LEN)
        .ok_or(VerifyError::Header)?;
    let header = ImageHeader::parse(head).ok_or(VerifyError::Header)?;
    if usize::try_from(header.length).ok() != Some(body.len()) {
        return Err(VerifyError::Header);
    }
    verify_image(
        head,
        |at, buf| {
            let src = body.get(at..at + buf.len()).ok_or(FlashError::OutOfRange)?;
            buf.copy_from_slice(src);
            Ok(())
        },
        public_key,
    )
}
