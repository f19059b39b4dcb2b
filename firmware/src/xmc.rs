//! What the reference board's images (`firmware` on EtherCAT, `firmware-pn`
//! on PROFINET) share: the PAC as RTIC wants it, the power stage's gate
//! enable and the panic stop.

/// The XMC4800 PAC as RTIC expects a device crate: svd2rust 0.14 output lacks
/// the `interrupt` alias of the `Interrupt` enum, so it is added here.
pub mod pac {
    pub use xmc4800::Interrupt as interrupt;
    pub use xmc4800::*;
}

/// The power stage's gate-driver enable: P5.9, push-pull, active high
/// (docs/flashing.md, wiring). Low from `init` until a control cycle
/// commands an axis' power stage on; the panic stop drives it low.
pub mod power {
    /// Port 5 (only its output-modification register, whose set/reset
    /// writes are atomic, and at `init` its pin 8–11 control register).
    #[allow(unsafe_code)]
    fn port() -> &'static xmc4800::port5::RegisterBlock {
        // SAFETY: PORT5 is a fixed peripheral address; OMR writes touch only
        // the bits written (no read-modify-write race with other users).
        unsafe { &*xmc4800::PORT5::ptr() }
    }

    /// P5.9 as a push-pull output, low.
    pub fn init() {
        port().omr().write(|w| w.pr9().set_bit());
        port().iocr8().modify(|_, w| w.pc9().value9());
    }

    /// Gate enable high (`on`) or low.
    #[inline]
    pub fn set(on: bool) {
        port()
            .omr()
            .write(|w| if on { w.ps9().set_bit() } else { w.pr9().set_bit() });
    }

    /// The gate enable after a control cycle: high while any axis' command
    /// wants its power stage on (one enable for both axes on this board).
    #[inline]
    pub fn follow(cmd: &[drive_ecat::axis::AxisCommand; 2]) {
        set(cmd.iter().any(|c| c.power_stage));
    }
}

/// The board images' panic: masks every interrupt first, so no task can
/// command the power stage again, switches the power stage off (gate enable
/// low), then reports over RTT and stops the core. `scripts/cross panics`
/// checks that no panic path is reachable from any task.
pub fn panic_stop() -> ! {
    cortex_m::interrupt::disable();
    power::set(false);
    defmt::error!("panic: interrupts masked, power stage off, halted");
    loop {
        cortex_m::asm::bkpt();
    }
}
