//! Controlword 6040h: bit names and the device-control command decoder (spec §5.2).

/// Controlword bit 0: switch on.
pub const CW_SWITCH_ON: u16 = 1 << 0;
/// Controlword bit 1: enable voltage.
pub const CW_ENABLE_VOLTAGE: u16 = 1 << 1;
/// Controlword bit 2: quick stop (active **low**: 0 requests the quick stop).
pub const CW_QUICK_STOP: u16 = 1 << 2;
/// Controlword bit 3: enable operation.
pub const CW_ENABLE_OPERATION: u16 = 1 << 3;
/// Controlword bit 4: mode-specific (new set-point, enable interpolation, homing start, jog +).
pub const CW_MODE_BIT4: u16 = 1 << 4;
/// Controlword bit 5: mode-specific (change set immediately, jog −, …).
pub const CW_MODE_BIT5: u16 = 1 << 5;
/// Controlword bit 6: mode-specific (abs/rel, …).
pub const CW_MODE_BIT6: u16 = 1 << 6;
/// Controlword bit 7: fault reset (acts on the 0→1 edge).
pub const CW_FAULT_RESET: u16 = 1 << 7;
/// Controlword bit 8: halt (`[std]`, pp/pv/homing).
pub const CW_HALT: u16 = 1 << 8;

/// A device-control command decoded from the controlword (spec §5.2, Tab. 5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Command {
    /// `cw & 0x0087 == 0x0006`.
    Shutdown,
    /// `cw & 0x008F == 0x0007`: Switch on, or Disable operation in Operation enabled
    /// (the same pattern; the current state tells them apart).
    SwitchOn,
    /// `cw & 0x0082 == 0x0000`.
    DisableVoltage,
    /// `cw & 0x0086 == 0x0002`.
    QuickStop,
    /// `cw & 0x008F == 0x000F`.
    EnableOperation,
}

impl Command {
    /// Decodes bits 0..3 and 7 of a controlword in the `[std]` order Disable voltage →
    /// Quick stop → Shutdown → Switch on / Enable operation.
    ///
    /// Every pattern requires bit 7 = 0: while the fault-reset bit is set no command is
    /// decoded (`None`) and the device state is held. With bit 7 = 0 every controlword
    /// decodes to exactly one command.
    pub const fn decode(cw: u16) -> Option<Command> {
        if cw & 0x0082 == 0x0000 {
            Some(Command::DisableVoltage)
        } else if cw & 0x0086 == 0x0002 {
            Some(Command::QuickStop)
        } else if cw & 0x0087 == 0x0006 {
            Some(Command::Shutdown)
        } else if cw & 0x008F == 0x0007 {
            Some(Command::SwitchOn)
        } else if cw & 0x008F == 0x000F {
            Some(Command::EnableOperation)
        } else {
            None
        }
    }
}

/// The controlword a master writes to request each device-control command (spec §5.2,
/// Tab. 5): the command's pattern with every other bit 0, as [`Command::decode`] reads it.
pub mod controlword {
    use super::{CW_ENABLE_OPERATION, CW_ENABLE_VOLTAGE, CW_FAULT_RESET, CW_QUICK_STOP, CW_SWITCH_ON};

    /// Shutdown (transitions 2, 6, 8): `0x0006`.
    pub const SHUTDOWN: u16 = CW_QUICK_STOP | CW_ENABLE_VOLTAGE;
    /// Switch on (3), and Disable operation (5) in Operation enabled: `0x0007`.
    pub const SWITCH_ON: u16 = SHUTDOWN | CW_SWITCH_ON;
    /// Enable operation (4, 16; from Ready to switch on through Switched on): `0x000F`.
    pub const ENABLE_OPERATION: u16 = SWITCH_ON | CW_ENABLE_OPERATION;
    /// Disable voltage (7, 9, 10, 12): bit 1 clear, `0x0000`.
    pub const DISABLE_VOLTAGE: u16 = 0;
    /// Quick stop (7, 10, 11): bit 2 clear with bit 1 set, `0x0002`.
    pub const QUICK_STOP: u16 = CW_ENABLE_VOLTAGE;
    /// Fault reset (15, on the 0→1 edge of bit 7): `0x0080`; no command decodes while it is set.
    pub const FAULT_RESET: u16 = CW_FAULT_RESET;
}
