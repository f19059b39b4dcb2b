//! The controller side of the drive's Example Function block (TIA Portal,
//! spec §13, App. 7.1) as a Rust model: the FB's inputs become the 36-byte
//! receive telegram (§4.5: E0 positioning, E1 speed, E2 torque) and the
//! 36-byte response telegram (F0…F2) becomes its outputs. Field names follow
//! the FB's (including its spelling `change_immediatly`).
//!
//! - [`ExampleFb`]: the FB itself: [`ExampleFb::receive_telegram`] each cycle
//!   from [`FbInputs`], [`ExampleFb::response`] from the drive's bytes into
//!   [`FbOutputs`]; the enable sequence 0x0406 → 0x0407 → 0x040F steps on
//!   ZSW1 (§7.3: each command waits for its state); CW1 bit 10 is always set.
//! - [`pkw`]: a PKW (PNU 2000) read/write helper over the FB's `pkw_*`
//!   inputs and outputs, with the toggle rule (§9.2).
//! - [`controller`]: a scripted in-process controller (Connect, then one
//!   output frame per millisecond) in front of a [`crate::pn::PnSim`].
//! - [`sequence`]: the demo sequence of `hil-sim demo --fieldbus profinet`
//!   (enable, home, positioning chain, speed, jog, PKW, fault and reset),
//!   and what it tells ([`report`]).
//!
//! Multi-byte values are big-endian (§4.4, Q-01), as the drive's profile
//! reads them. Units are the PROFINET defaults (§11): position 1/1000 rev,
//! velocity rpm, acceleration rpm/s, current limit mA, torque ‰.
//!
//! Decisions where the manual leaves the FB's behaviour open: with
//! `drive_enable` = false the state bits are 0000 (coast stop: switching
//! on inhibited, power stage off; CW1 0x0430 at rest, as in the manual's
//! dump of §4.4 with ZSW1 in SOI), so enabling always runs the whole
//! sequence from SOI; in speed and torque mode CW1 bit 6
//! (enable setpoint) is set (the FB has no input for it) and bits 4/5 come
//! from `hold` / `intermediate_stop` as in positioning; torque mode (E2)
//! needs PNU 1500 = 0x04 written through PKW (§4.5), which the FB's caller
//! does with [`pkw::PkwClient`]; `following_error` is inverted ZSW1 bit 8
//! (E-09 corrected), `pos_task_ack` is ZSW1 bit 12 as sent (E-10).

pub mod alarms;
pub mod controller;
pub mod pkw;
pub mod report;
pub mod rig;
pub mod sequence;

use profidrive::cw1::CONTROL_BY_PLC;
use profidrive::telegram::Dir;
use profidrive::zsw1::{FAULT, OP, RTSO, SO, SOI, STATE_MASK};

/// The Example FB's telegram length, both directions (18 words, §4.5).
pub const TELEGRAM_BYTES: usize = 36;

/// `operation_mode` positioning (PNU 1500 = 0x10, telegram E0).
pub const OPMODE_POS: u8 = 0x10;
/// `operation_mode` speed control (0x08, telegram E1).
pub const OPMODE_VELO: u8 = 0x08;
/// `operation_mode` torque control (0x04, telegram E2).
pub const OPMODE_TORQUE: u8 = 0x04;

/// CW1 state bits while `drive_enable` = false: 0000 (coast stop, §7.2).
pub const CMD_DISABLED: u16 = 0x0000;
/// CW1 state command OFF (x110, §7.2).
pub const CMD_OFF: u16 = 0x0006;
/// CW1 state command ON (x111).
pub const CMD_ON: u16 = 0x0007;
/// CW1 state command enable operation (1111).
pub const CMD_ENABLE: u16 = 0x000F;

/// CW1 bits the FB sets beyond the state command (§5; `profidrive::cw1`
/// keeps its own copies private, the tests check these against its decoder).
pub mod cw1_bits {
    /// Bit 4: positioning "do not reject traversing task", speed "enable
    /// ramp generator"; cleared by `hold`.
    pub const NO_REJECT: u16 = 1 << 4;
    /// Bit 5: positioning "no intermediate stop", speed "unfreeze ramp";
    /// inverted `intermediate_stop`.
    pub const NO_STOP: u16 = 1 << 5;
    /// Bit 6: positioning "activate traversing task" (`start_pos`), speed
    /// "enable setpoint".
    pub const ACTIVATE: u16 = 1 << 6;
    /// Bit 7: fault acknowledge (`fault_reset`, rising edge).
    pub const FAULT_ACK: u16 = 1 << 7;
    /// Bit 8: jog 1 (positive, `jog_pos`).
    pub const JOG_POS: u16 = 1 << 8;
    /// Bit 9: jog 2 (negative, `jog_neg`).
    pub const JOG_NEG: u16 = 1 << 9;
    /// Bit 11: start homing (`start_homing`).
    pub const START_HOMING: u16 = 1 << 11;
    /// Bit 12: relative (`relative`).
    pub const RELATIVE: u16 = 1 << 12;
    /// Bit 13: change immediately (`change_immediatly`).
    pub const IMMEDIATE: u16 = 1 << 13;
}

/// ZSW1 bits the FB reads beyond the state (§6).
pub mod zsw1_bits {
    /// Bit 7: warning present.
    pub const WARNING: u16 = 1 << 7;
    /// Bit 8: positioning: no following error; speed: speed within window.
    pub const TOLERANCE: u16 = 1 << 8;
    /// Bit 9: control requested (mirror of CW1 bit 10).
    pub const CONTROL_REQUESTED: u16 = 1 << 9;
    /// Bit 10: positioning: target reached; speed: speed reached/exceeded.
    pub const REACHED: u16 = 1 << 10;
    /// Bit 11: home position valid.
    pub const HOMED: u16 = 1 << 11;
    /// Bit 12: traversing task acknowledgement.
    pub const TASK_ACK: u16 = 1 << 12;
    /// Bit 13: drive stopped.
    pub const STOPPED: u16 = 1 << 13;
}

/// The FB's inputs (spec §13.1), as the PLC program sets them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FbInputs {
    /// [`OPMODE_POS`], [`OPMODE_VELO`] or [`OPMODE_TORQUE`]: selects the
    /// telegram E0 / E1 / E2.
    pub operation_mode: u8,
    /// Enable the drive (the enable sequence while true).
    pub drive_enable: bool,
    /// CW1 bit 7 (a rising edge acknowledges).
    pub fault_reset: bool,
    /// CW1 bit 11 (rising edge starts, falling edge cancels).
    pub start_homing: bool,
    /// CW1 bit 6 (rising edge starts the PROFINET record).
    pub start_pos: bool,
    /// CW1 bit 12.
    pub relative: bool,
    /// CW1 bit 13 (the FB's spelling).
    pub change_immediatly: bool,
    /// Inverted CW1 bit 5.
    pub intermediate_stop: bool,
    /// Clears CW1 bits 4, 8, 9.
    pub hold: bool,
    /// PNU 1050 (receive byte 1 of E0).
    pub homing_method: i8,
    /// PNU 1001.0, 1/1000 rev.
    pub target_position: i32,
    /// PNU 1001.1, rpm.
    pub profile_velocity: i32,
    /// PNU 1001.2, rpm.
    pub end_velocity: i32,
    /// PNU 1001.5, rpm/s.
    pub all_accelerations_positioning: u32,
    /// PNU 1010.0, rpm.
    pub target_velocity: i32,
    /// PNU 1011.2, rpm/s (E1 bytes 16–19; not in §13.1's list, the
    /// telegram carries it).
    pub all_accelerations_velocity: u32,
    /// 2415h.02, mA (E0 and E1).
    pub current_limit: i32,
    /// 6071h, ‰ of rated torque (E2).
    pub target_torque: i16,
    /// 2416h.02, CANopen speed units (E2).
    pub velocity_limit: i32,
    /// CW1 bit 8.
    pub jog_pos: bool,
    /// CW1 bit 9.
    pub jog_neg: bool,
    /// PNU 1040.0, rpm.
    pub jogging_velocity: i32,
    /// PKW request byte 0: 0x00, 0x41 read, 0x42 write.
    pub pkw_access_control: u8,
    /// PKW request bytes 1–2: PNU or CANopen index.
    pub pkw_object_main_index: u16,
    /// PKW request byte 3.
    pub pkw_object_sub_index: u8,
    /// PKW request bytes 4–7.
    pub pkw_write_value: u32,
}

impl Default for FbInputs {
    /// Positioning, disabled, the manual's default speeds (1000 rpm,
    /// 10 000 rpm/s, jog 100 rpm), homing method 34 (current position).
    fn default() -> Self {
        FbInputs {
            operation_mode: OPMODE_POS,
            drive_enable: false,
            fault_reset: false,
            start_homing: false,
            start_pos: false,
            relative: false,
            change_immediatly: false,
            intermediate_stop: false,
            hold: false,
            homing_method: 34,
            target_position: 0,
            profile_velocity: 1000,
            end_velocity: 0,
            all_accelerations_positioning: 10_000,
            target_velocity: 0,
            all_accelerations_velocity: 14_100,
            current_limit: 0,
            target_torque: 0,
            velocity_limit: 0,
            jog_pos: false,
            jog_neg: false,
            jogging_velocity: 100,
            pkw_access_control: profidrive::pkw::NONE,
            pkw_object_main_index: 0,
            pkw_object_sub_index: 0,
            pkw_write_value: 0,
        }
    }
}

/// The FB's outputs (spec §13.2), from the last response telegram.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FbOutputs {
    /// The response identifier (0xF0…0xF2; 0 before any response).
    pub identifier: u8,
    /// ZSW1 as received.
    pub zsw1: u16,
    /// ZSW1 bit 9.
    pub control_by_plc: bool,
    /// Response byte 1 (PNU 1500).
    pub operation_mode_actual: u8,
    /// ZSW1 state = operation (0x07 under mask 0x47).
    pub drive_is_enabled: bool,
    /// ZSW1 bit 3.
    pub fault: bool,
    /// ZSW1 bit 7.
    pub warning: bool,
    /// PNU 1141 (response bytes 14–17).
    pub digital_inputs: u32,
    /// ZSW1 bit 13.
    pub velo_zero: bool,
    /// ZSW1 bit 8 in speed mode.
    pub velo_reached: bool,
    /// ZSW1 bit 10 in speed mode.
    pub velo_exceeded: bool,
    /// PNU 1100, 1/1000 rev.
    pub position_actual_value: i32,
    /// PNU 1101, rpm.
    pub velocity_actual_value: i32,
    /// 6077h, ‰ of rated torque (E-20: the telegram carries 6077h).
    pub current_actual_value: i16,
    /// ZSW1 bit 11.
    pub home_valid: bool,
    /// ZSW1 bit 10 in positioning.
    pub target_reached: bool,
    /// Inverted ZSW1 bit 8 in positioning (E-09).
    pub following_error: bool,
    /// ZSW1 bit 12 (E-10).
    pub pos_task_ack: bool,
    /// PKW response bytes 4–7.
    pub pkw_read_value: u32,
    /// PKW response byte 0.
    pub pkw_access_status: u8,
    /// PKW response bytes 1–2.
    pub pkw_main_index: u16,
    /// PKW response byte 3.
    pub pkw_sub_index: u8,
}

/// Why a response telegram was not taken.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ResponseError {
    /// Fewer than [`TELEGRAM_BYTES`] bytes.
    TooShort(usize),
    /// Byte 0 is no response identifier 0xF0…0xF2.
    Identifier(u8),
}

/// Where the enable sequence is (spec §7.3: each command waits for the
/// state it asks for).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EnableStep {
    /// OFF (0x0406) until ZSW1 shows ready to switch on.
    Off,
    /// ON (0x0407) until switched on.
    On,
    /// Enable operation (0x040F) until operation, and then held.
    Enable,
}

/// The Example Function block: its CW1 enable sequence and its last outputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ExampleFb {
    step: EnableStep,
    outputs: FbOutputs,
}

impl Default for ExampleFb {
    fn default() -> Self {
        Self::new()
    }
}

/// The state bits of `zsw1` (mask 0x47).
pub fn zsw1_state(zsw1: u16) -> u16 {
    zsw1 & STATE_MASK
}

/// The state name of `zsw1` (§7.1): "SOI", "RTSO", "SO", "OP", "fault"
/// (SOI with bit 3) or "?".
pub fn state_name(zsw1: u16) -> &'static str {
    match (zsw1_state(zsw1), zsw1 & FAULT != 0) {
        (SOI, true) => "fault",
        (SOI, false) => "SOI",
        (RTSO, _) => "RTSO",
        (SO, _) => "SO",
        (OP, _) => "OP",
        _ => "?",
    }
}

impl ExampleFb {
    /// Nothing received yet: the sequence starts at OFF.
    pub const fn new() -> Self {
        ExampleFb {
            step: EnableStep::Off,
            outputs: FbOutputs {
                identifier: 0,
                zsw1: 0,
                control_by_plc: false,
                operation_mode_actual: 0,
                drive_is_enabled: false,
                fault: false,
                warning: false,
                digital_inputs: 0,
                velo_zero: false,
                velo_reached: false,
                velo_exceeded: false,
                position_actual_value: 0,
                velocity_actual_value: 0,
                current_actual_value: 0,
                home_valid: false,
                target_reached: false,
                following_error: false,
                pos_task_ack: false,
                pkw_read_value: 0,
                pkw_access_status: 0,
                pkw_main_index: 0,
                pkw_sub_index: 0,
            },
        }
    }

    /// The enable sequence's step.
    pub fn enable_step(&self) -> EnableStep {
        self.step
    }

    /// The outputs of the last response taken.
    pub fn outputs(&self) -> &FbOutputs {
        &self.outputs
    }

    /// CW1 for `i` (§5, §13.1): the state command of the enable sequence,
    /// bit 10 always, the mode bits.
    pub fn cw1(&self, i: &FbInputs) -> u16 {
        use cw1_bits::*;
        let state = if i.drive_enable {
            match self.step {
                EnableStep::Off => CMD_OFF,
                EnableStep::On => CMD_ON,
                EnableStep::Enable => CMD_ENABLE,
            }
        } else {
            CMD_DISABLED
        };
        let bit = |on: bool, b: u16| if on { b } else { 0 };
        let activate = if i.operation_mode == OPMODE_POS {
            i.start_pos
        } else {
            true
        };
        state
            | CONTROL_BY_PLC
            | bit(!i.hold, NO_REJECT)
            | bit(!i.intermediate_stop, NO_STOP)
            | bit(activate, ACTIVATE)
            | bit(i.fault_reset, FAULT_ACK)
            | bit(i.jog_pos && !i.hold, JOG_POS)
            | bit(i.jog_neg && !i.hold, JOG_NEG)
            | bit(i.start_homing, START_HOMING)
            | bit(i.relative, RELATIVE)
            | bit(i.change_immediatly, IMMEDIATE)
    }

    /// This cycle's receive telegram for `i` (§4.5): E0 / E1 / E2 by
    /// `operation_mode` (anything else: E0).
    pub fn receive_telegram(&self, i: &FbInputs) -> [u8; TELEGRAM_BYTES] {
        let mut t = [0u8; TELEGRAM_BYTES];
        let n = match i.operation_mode {
            OPMODE_VELO => 1,
            OPMODE_TORQUE => 2,
            _ => 0,
        };
        t[0] = Dir::Receive.identifier(n);
        t[2..4].copy_from_slice(&self.cw1(i).to_be_bytes());
        match n {
            0 => {
                t[1] = i.homing_method as u8;
                t[4..8].copy_from_slice(&i.target_position.to_be_bytes());
                t[8..12].copy_from_slice(&i.profile_velocity.to_be_bytes());
                t[12..16].copy_from_slice(&i.end_velocity.to_be_bytes());
                t[16..20].copy_from_slice(&i.all_accelerations_positioning.to_be_bytes());
                t[20..24].copy_from_slice(&i.jogging_velocity.to_be_bytes());
                t[32..36].copy_from_slice(&i.current_limit.to_be_bytes());
            }
            1 => {
                t[4..8].copy_from_slice(&i.target_velocity.to_be_bytes());
                t[16..20].copy_from_slice(&i.all_accelerations_velocity.to_be_bytes());
                t[20..24].copy_from_slice(&i.jogging_velocity.to_be_bytes());
                t[32..36].copy_from_slice(&i.current_limit.to_be_bytes());
            }
            _ => {
                t[4..6].copy_from_slice(&i.target_torque.to_be_bytes());
                t[32..36].copy_from_slice(&i.velocity_limit.to_be_bytes());
            }
        }
        t[24] = i.pkw_access_control;
        t[25..27].copy_from_slice(&i.pkw_object_main_index.to_be_bytes());
        t[27] = i.pkw_object_sub_index;
        t[28..32].copy_from_slice(&i.pkw_write_value.to_be_bytes());
        t
    }

    /// Takes a response telegram: the outputs, and the enable sequence's
    /// next step (a state reached moves it on; a state lost, e.g. by a
    /// fault, starts it again at OFF). `drive_enable` = false resets it.
    pub fn response(&mut self, bytes: &[u8], drive_enable: bool) -> Result<&FbOutputs, ResponseError> {
        let t = bytes
            .get(..TELEGRAM_BYTES)
            .ok_or(ResponseError::TooShort(bytes.len()))?;
        let id = t[0];
        if !(Dir::Response.identifier(0)..=Dir::Response.identifier(2)).contains(&id) {
            return Err(ResponseError::Identifier(id));
        }
        let be32 = |k: usize| [t[k], t[k + 1], t[k + 2], t[k + 3]];
        let zsw1 = u16::from_be_bytes([t[2], t[3]]);
        let mode = t[1];
        let on = |b: u16| zsw1 & b != 0;
        let speed = mode == OPMODE_VELO;
        let pos = mode == OPMODE_POS;
        use zsw1_bits::*;
        self.outputs = FbOutputs {
            identifier: id,
            zsw1,
            control_by_plc: on(CONTROL_REQUESTED),
            operation_mode_actual: mode,
            drive_is_enabled: zsw1_state(zsw1) == OP,
            fault: on(FAULT),
            warning: on(WARNING),
            digital_inputs: u32::from_be_bytes(be32(14)),
            velo_zero: on(STOPPED),
            velo_reached: speed && on(TOLERANCE),
            velo_exceeded: speed && on(REACHED),
            position_actual_value: i32::from_be_bytes(be32(4)),
            velocity_actual_value: i32::from_be_bytes(be32(8)),
            current_actual_value: i16::from_be_bytes([t[12], t[13]]),
            home_valid: on(HOMED),
            target_reached: pos && on(REACHED),
            following_error: pos && !on(TOLERANCE),
            pos_task_ack: on(TASK_ACK),
            pkw_read_value: u32::from_be_bytes(be32(28)),
            pkw_access_status: t[24],
            pkw_main_index: u16::from_be_bytes([t[25], t[26]]),
            pkw_sub_index: t[27],
        };
        let state = zsw1_state(zsw1);
        self.step = if !drive_enable {
            EnableStep::Off
        } else {
            match (self.step, state) {
                (EnableStep::Off, RTSO) => EnableStep::On,
                (EnableStep::On, SO) => EnableStep::Enable,
                (EnableStep::On, RTSO) => EnableStep::On,
                (EnableStep::Enable, SO | OP) => EnableStep::Enable,
                (EnableStep::Off, _) => EnableStep::Off,
                // the state went away (fault, coast stop): start again
                _ => EnableStep::Off,
            }
        };
        Ok(&self.outputs)
    }
}

#[cfg(test)]
mod tests;
