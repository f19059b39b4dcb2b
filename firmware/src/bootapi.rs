//! The boot loader's service table (`boot::BootApi`): the boot loaders
//! (`boot-xmc`, `boot-mps2`) put it at a fixed address, right after their
//! vector table (`.boot_api`, placed by build.rs); the images built with
//! `boot/external-ed25519` (the board image, the QEMU test image) verify
//! downloads with the boot loader's Ed25519 code through it instead of
//! linking a second copy (docs/flashing.md, "Signed images").

#[cfg(any(feature = "boot-board", feature = "boot-mps2"))]
mod provide {
    use bootloader::{
        boot_api_code, ed25519_verify_builtin, BootApi, BOOT_API_MAGIC, KEY_LEN, SIGNATURE_LEN,
    };

    /// The table, at the boot loader's start + `BOOT_API_OFFSET`.
    #[link_section = ".boot_api"]
    #[used]
    #[no_mangle]
    pub static BOOT_API: BootApi = BootApi {
        magic: BOOT_API_MAGIC,
        ed25519_verify: Some(ed25519_verify),
    };

    /// `BootApi::ed25519_verify`: the boot loader's own verifier.
    ///
    /// # Safety
    ///
    /// `public_key` and `signature` point to 32 and 64 readable bytes,
    /// `message` to `message_len` (the table's contract).
    #[allow(unsafe_code)]
    unsafe extern "C" fn ed25519_verify(
        public_key: *const u8,
        message: *const u8,
        message_len: usize,
        signature: *const u8,
    ) -> u32 {
        // SAFETY: the caller's contract above.
        let (key, message, signature) = unsafe {
            (
                &*public_key.cast::<[u8; KEY_LEN]>(),
                core::slice::from_raw_parts(message, message_len),
                &*signature.cast::<[u8; SIGNATURE_LEN]>(),
            )
        };
        boot_api_code(ed25519_verify_builtin(key, message, signature))
    }
}

#[cfg(any(feature = "board", feature = "mps2-slot"))]
mod call {
    use boot::{
        boot_api_result, BootApi, VerifyError, BOOT_API_MAGIC, BOOT_API_OFFSET, KEY_LEN, SIGNATURE_LEN,
    };

    /// Where the boot loader starts (its table is `BOOT_API_OFFSET` further).
    #[cfg(feature = "board")]
    const BOOT_LOADER: u32 = 0x0C00_0000;
    #[cfg(all(feature = "mps2-slot", not(feature = "board")))]
    const BOOT_LOADER: u32 = 0x0000_0000;

    /// The address of the boot loader's table.
    pub const BOOT_API_AT: u32 = BOOT_LOADER + BOOT_API_OFFSET;

    /// `boot::ed25519_verify` of this image (feature `boot/external-ed25519`):
    /// the boot loader's verifier through its table; without a boot loader (a
    /// standalone link, an older one: no magic) every signature is refused.
    #[no_mangle]
    fn sc6_ed25519_verify(
        public_key: &[u8; KEY_LEN],
        message: &[u8],
        signature: &[u8; SIGNATURE_LEN],
    ) -> Result<(), VerifyError> {
        let api = BOOT_API_AT as *const BootApi;
        // SAFETY: the boot loader's flash is memory-mapped and always
        // readable; the magic is read first, the function pointer only when
        // it matches (an `Option`: a null pointer reads as `None`).
        #[allow(unsafe_code)]
        let magic = unsafe { core::ptr::read_volatile(core::ptr::addr_of!((*api).magic)) };
        if magic != BOOT_API_MAGIC {
            return Err(VerifyError::Key);
        }
        // SAFETY: as above; the boot loader with this magic wrote the table.
        #[allow(unsafe_code)]
        let Some(f) = (unsafe { core::ptr::read_volatile(core::ptr::addr_of!((*api).ed25519_verify)) }) else {
            return Err(VerifyError::Key);
        };
        // SAFETY: the table's contract: three readable buffers of the lengths given.
        #[allow(unsafe_code)]
        let code = unsafe {
            f(
                public_key.as_ptr(),
                message.as_ptr(),
                message.len(),
                signature.as_ptr(),
            )
        };
        boot_api_result(code)
    }
}

#[cfg(any(feature = "board", feature = "mps2-slot"))]
#[allow(unused_imports)]
pub use call::BOOT_API_AT;
