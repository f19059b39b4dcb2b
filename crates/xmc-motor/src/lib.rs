//! The power stage of the XMC4800 reference board: CCU8 centre-aligned PWM
//! (three phases per axis, dead time, the trap input forcing the outputs to
//! their passive level), VADC (both axes' phase currents and the DC link,
//! converted on CCU8's trigger at the PWM centre), POSIF (quadrature encoder
//! with index, counted by a CCU4 slice), the CCU4 control-cycle timer and the
//! ERU1 route of the ESC's SYNC0 to its interrupt.
//!
//! `#![no_std]`, heap-free and panic-free. Registers are reached through
//! [`Regs`] (32-bit accesses at absolute addresses): [`Mmio`] on the chip, a
//! model of the register behaviour on the host (the tests). Written from the
//! XMC4800 reference manual without the hardware: docs/hardware.md of the
//! repository lists what is not verified and the bring-up order.
//!
//! Clocks and resets (SCU) and the global start (SCU_GENERAL.CCUCON) are the
//! image's: it uses the PAC's typed registers for them.
#![no_std]
#![deny(missing_docs)]

pub mod adc;
pub mod enc;
pub mod pins;
pub mod pwm;
pub mod regs;
pub mod timer;

#[cfg(test)]
extern crate std;
#[cfg(test)]
mod model;
#[cfg(test)]
mod tests;

/// 32-bit register access at absolute addresses.
pub trait Regs {
    /// Reads the register at `addr`.
    fn read(&mut self, addr: u32) -> u32;
    /// Writes `value` to the register at `addr`.
    fn write(&mut self, addr: u32, value: u32);
    /// Read-modify-write: clears `clear`, then sets `set`.
    fn modify(&mut self, addr: u32, clear: u32, set: u32) {
        let v = self.read(addr);
        self.write(addr, (v & !clear) | set);
    }
}

/// The chip's registers.
#[derive(Debug)]
pub struct Mmio(());

impl Mmio {
    /// The peripherals of this crate, in the address space.
    ///
    /// # Safety
    /// The CCU80/81, CCU40/41, POSIF0/1, VADC, ERU1 and the ports named in
    /// [`pins`] must be clocked and out of reset, and the values of this
    /// type their only users (each RTIC task holding one touches only its
    /// own registers, or holds them under a lock).
    #[allow(unsafe_code)]
    pub const unsafe fn new() -> Mmio {
        Mmio(())
    }
}

#[allow(unsafe_code)]
impl Regs for Mmio {
    #[inline]
    fn read(&mut self, addr: u32) -> u32 {
        // SAFETY: an aligned peripheral register (`new`'s contract).
        unsafe { core::ptr::read_volatile(addr as usize as *const u32) }
    }
    #[inline]
    fn write(&mut self, addr: u32, value: u32) {
        // SAFETY: as in `read`.
        unsafe { core::ptr::write_volatile(addr as usize as *mut u32, value) }
    }
}

/// Clock of the CCU4/CCU8 modules (fCCU = fSYS after the boot ROM: 144 MHz).
pub const F_CCU_HZ: u32 = 144_000_000;
