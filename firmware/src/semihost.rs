//! The end of a QEMU image: its exit status through semihosting.

use cortex_m_semihosting::debug;

/// Exits QEMU with success (`ok`) or failure, then sleeps (should the
/// debugger not stop the machine).
pub fn exit(ok: bool) -> ! {
    debug::exit(if ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    loop {
        cortex_m::asm::wfi();
    }
}

/// The QEMU images' panic: reports it over defmt and exits with failure.
pub fn panic_exit(info: &core::panic::PanicInfo) -> ! {
    defmt::error!("panic: {}", defmt::Display2Format(info));
    exit(false)
}
