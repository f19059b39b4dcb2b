//! Control word 1 (PNU 967, spec §5, P-076…P-094): pure translation.
//!
//! Bits 0–3 and 7 are the CiA 402 controlword bits of the same numbers
//! (spec §7.2, §16.1: Shutdown x110, Switch on x111, Enable operation 1111,
//! Disable operation 0111, Disable voltage xx0x, Quick stop x01x, fault
//! reset on a rising edge of bit 7), so the core's device state machine
//! decodes them unchanged. The other bits become mode-dependent commands:
//! [`PosCommands`] in positioning, [`SpeedCommands`] in speed control.
//!
//! Decisions: bit 5 in speed mode has the PROFIdrive polarity, 1 = the ramp
//! runs, 0 = frozen; a falling edge of bit 6 in positioning has no
//! effect; with bit 10 = 0 CW1 is not evaluated: the last evaluated
//! state is kept, no edge is seen, only the ZSW1 bit 9 mirror follows
//! . Edges are taken against the last evaluated CW1. Bits 14/15 are
//! ignored (P-094).

/// Bit 10: control by PLC.
pub const CONTROL_BY_PLC: u16 = 1 << 10;
/// The bits that are CiA 402 controlword bits (0–3, 7).
pub const CIA402_BITS: u16 = 0x008F;

const B4: u16 = 1 << 4;
const B5: u16 = 1 << 5;
const B6: u16 = 1 << 6;
const B8: u16 = 1 << 8;
const B9: u16 = 1 << 9;
const B11: u16 = 1 << 11;
const B12: u16 = 1 << 12;
const B13: u16 = 1 << 13;

/// The operating mode CW1 is read in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Positioning (PNU 1500 = 0x10; homing and jog inside it).
    Positioning,
    /// Speed control (0x08).
    Speed,
    /// Torque control (0x04) or anything else: no mode bits.
    Other,
}

/// What the drive tells the decoder.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Context {
    /// The mode in force.
    pub mode: Mode,
    /// A homing run is active (start and jog are ignored, bit 11 falling
    /// cancels).
    pub homing_active: bool,
}

/// Positioning commands (levels and edges of one cycle).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PosCommands {
    /// Bit 4 = 0: a running traversing task is cancelled (level, P-078).
    pub cancel: bool,
    /// Bit 5 = 0: intermediate stop, the task is kept (level, P-080).
    pub intermediate_stop: bool,
    /// Bit 6 rising with bits 4 and 5 = 1 and no homing: start the record
    /// PNU 1002 selects (edge, P-082).
    pub start: bool,
    /// Bit 12 (sampled at start): relative to the position set-point (P-091).
    pub relative: bool,
    /// Bit 13 (sampled at start): change immediately, else append (P-092).
    pub immediate: bool,
    /// Bit 11 rising: start homing (edge, P-090).
    pub homing_start: bool,
    /// Bit 11 falling during a homing run: cancel without error (edge).
    pub homing_cancel: bool,
    /// Bit 8: jog positive (level; off during homing, P-086, P-088).
    pub jog_positive: bool,
    /// Bit 9: jog negative (level; off during homing, P-087, P-088).
    pub jog_negative: bool,
}

/// Speed-control commands (levels).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SpeedCommands {
    /// Bit 4: ramp generator enabled; 0 = every set-point disabled, its
    /// rising edge ramps to the target, its falling edge to 0 (P-079).
    pub rfg_enable: bool,
    /// Bit 5 = 0: ramp output frozen; bit 4 then has no effect (P-081, Q-04).
    pub rfg_freeze: bool,
    /// Bit 6: set-point enabled; 0 = set-point 0 at once, no ramp (P-084).
    pub setpoint_enable: bool,
}

/// The mode-dependent part.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModeCommands {
    /// Positioning.
    Positioning(PosCommands),
    /// Speed control.
    Speed(SpeedCommands),
    /// No mode bits.
    Other,
}

/// One cycle's translation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Translated {
    /// The CiA 402 controlword for the core's state machine (bits 0–3, 7).
    pub controlword: u16,
    /// This cycle's CW1 was evaluated (bit 10 = 1).
    pub evaluated: bool,
    /// ZSW1 bit 9: the received CW1's bit 10 (P-103).
    pub control_requested: bool,
    /// The mode bits.
    pub mode: ModeCommands,
}

/// Edge detection over the evaluated CW1.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Cw1Decoder {
    last: u16,
}

impl Cw1Decoder {
    /// Nothing evaluated yet (the last state is CW1 = 0).
    pub const fn new() -> Self {
        Self { last: 0 }
    }

    /// The last evaluated CW1.
    pub fn last(&self) -> u16 {
        self.last
    }

    /// Translates `cw1` (this cycle's, `None` = none received: the last
    /// state stays, like bit 10 = 0).
    pub fn decode(&mut self, cw1: Option<u16>, ctx: Context) -> Translated {
        let control_requested = cw1.is_some_and(|c| c & CONTROL_BY_PLC != 0);
        let prev = self.last;
        let (now, evaluated) = match cw1 {
            Some(c) if c & CONTROL_BY_PLC != 0 => (c, true),
            _ => (prev, false),
        };
        self.last = now;
        let rose = |b: u16| now & b != 0 && prev & b == 0;
        let fell = |b: u16| now & b == 0 && prev & b != 0;
        let on = |b: u16| now & b != 0;
        let mode = match ctx.mode {
            Mode::Positioning => ModeCommands::Positioning(PosCommands {
                cancel: !on(B4),
                intermediate_stop: !on(B5),
                start: rose(B6) && on(B4) && on(B5) && !ctx.homing_active,
                relative: on(B12),
                immediate: on(B13),
                homing_start: rose(B11),
                homing_cancel: fell(B11) && ctx.homing_active,
                jog_positive: on(B8) && !ctx.homing_active,
                jog_negative: on(B9) && !ctx.homing_active,
            }),
            Mode::Speed => ModeCommands::Speed(SpeedCommands {
                rfg_enable: on(B4),
                rfg_freeze: !on(B5),
                setpoint_enable: on(B6),
            }),
            Mode::Other => ModeCommands::Other,
        };
        Translated {
            controlword: now & CIA402_BITS,
            evaluated,
            control_requested,
            mode,
        }
    }
}
