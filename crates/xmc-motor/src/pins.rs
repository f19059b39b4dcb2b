//! The PWM pins: a disabled axis' six outputs are general-purpose outputs
//! held low (the passive level: both switches of every phase off), an
//! enabled axis' are the CCU8's (alternate function 3). The pins are those
//! XMClib's XMC4 pin maps give for CCU80/CCU81.OUTy0/OUTy1 on ALT3; on the
//! KIT_XMC48_RELAX_ECAT_V1 several of them are the ESC's MII pins, so a
//! power board must be laid out around them (docs/hardware.md).

use crate::regs::*;
use crate::Regs;

/// A port pin.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pin {
    /// Port number.
    pub port: u32,
    /// Pin number (0…15).
    pub pin: u32,
}

/// `Pin { port, pin }`.
pub const fn pin(port: u32, pin: u32) -> Pin {
    Pin { port, pin }
}

/// Axis A: CCU80.OUT00/01, OUT10/11, OUT20/21 (U high/low, V, W).
pub const AXIS_A: [Pin; 6] = [pin(0, 5), pin(0, 2), pin(0, 4), pin(0, 1), pin(0, 3), pin(0, 0)];
/// Axis B: CCU81.OUT00/01, OUT10/11, OUT20/21.
pub const AXIS_B: [Pin; 6] = [
    pin(1, 15),
    pin(1, 12),
    pin(1, 14),
    pin(1, 11),
    pin(1, 13),
    pin(1, 10),
];

/// Sets a pin's 5-bit control field.
fn set_pc<R: Regs>(r: &mut R, p: Pin, pc: u32) {
    let reg = port(p.port) + IOCR0 + 4 * (p.pin / 4);
    let at = 8 * (p.pin % 4) + 3;
    r.modify(reg, 0x1F << at, pc << at);
}

/// The pins to the CCU8 (`on`) or low as plain outputs.
pub fn set_axis<R: Regs>(r: &mut R, pins: &[Pin; 6], on: bool) {
    for &p in pins {
        if on {
            set_pc(r, p, PC_ALT3);
        } else {
            // output latch low first, then the pin to it: no glitch high
            r.write(port(p.port) + OMR, 1 << (p.pin + 16));
            set_pc(r, p, PC_GPIO_OUT);
        }
    }
}
