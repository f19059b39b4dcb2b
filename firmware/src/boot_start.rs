//! The boot loaders' jump into an image.

/// Starts the image whose vector table is at `vtor` in place (direct
/// execute-in-place): VTOR set, barriers, stack pointer and reset vector
/// loaded from the table.
///
/// # Safety
/// `vtor` must hold a vector table whose stack pointer lies in RAM and whose
/// reset vector lies in the image (`bootloader::check_image` found it so);
/// nothing of the caller is used after the jump; no interrupt is enabled.
#[allow(unsafe_code)]
pub unsafe fn start_image(vtor: u32) -> ! {
    // SAFETY: as the caller promises.
    unsafe {
        (*cortex_m::peripheral::SCB::PTR).vtor.write(vtor);
        cortex_m::asm::dsb();
        cortex_m::asm::isb();
        cortex_m::asm::bootload(vtor as *const u32)
    }
}
