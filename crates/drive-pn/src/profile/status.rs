//! ZSW1 from the core's state (P-095…P-109): the device state, the CiA 402
//! statusword 6041h of the axis and its record positioning.

use super::lookup::{Core, CoreSlots};
use cia402::State as Cia;
use drive_core::axis::Axis;
use drive_core::DriveObjects;
use profidrive::cw1::CONTROL_BY_PLC;
use profidrive::zsw1::{self, State, Status};

/// 6041h bits.
const SW_WARNING: i64 = 1 << 7;
const SW_TARGET_REACHED: i64 = 1 << 10;
const SW_INTERNAL_LIMIT: i64 = 1 << 11;
const SW_SPEED_ZERO: i64 = 1 << 12;
const SW_FOLLOWING_ERROR: i64 = 1 << 13;

/// rpm → increments per second.
const RPM_TO_INC_PER_S: f32 = motion::INCREMENTS_PER_REVOLUTION as f32 / 60.0;

/// ZSW1 bits 8 and 10 in speed control (vl) from the actual velocity and
/// the set-point: bit 8 the actual speed inside the velocity window around
/// the set-point (P-102), bit 10 the set-point reached or exceeded, signed
/// (P-106: actual ≥ set-point − window). The window is the core's C40 (the
/// manual names no PNU for the "speed signal" settings; docs/conformance.md).
/// The set-point is 6042h while CW1 bits 4 and 6 enable it, else 0.
pub fn speed_bits(target_rpm: i64, cw1: u16, actual_inc_per_s: f32, window_inc_per_s: f32) -> (bool, bool) {
    let enabled = cw1 & 0x0050 == 0x0050;
    let target = if enabled {
        target_rpm as f32 * RPM_TO_INC_PER_S
    } else {
        0.0
    };
    let within = (actual_inc_per_s - target).abs() <= window_inc_per_s;
    let reached = actual_inc_per_s >= target - window_inc_per_s;
    (within, reached)
}

fn state(s: Cia) -> State {
    match s {
        Cia::NotReadyToSwitchOn => State::NotReady,
        Cia::SwitchOnDisabled => State::SwitchOnDisabled,
        Cia::ReadyToSwitchOn => State::ReadyToSwitchOn,
        Cia::SwitchedOn => State::SwitchedOn,
        Cia::OperationEnabled => State::OperationEnabled,
        Cia::QuickStopActive => State::QuickStopActive,
        Cia::FaultReactionActive => State::FaultReactionActive,
        Cia::Fault => State::Fault,
    }
}

/// ZSW1 of `axis` with `cw1` the last evaluated CW1 and `homing` a homing
/// run the profile started; 6041h and 6061h through `core`'s slots.
pub fn zsw1(objects: &DriveObjects, core: &CoreSlots, axis: &Axis, cw1: u16, homing: bool) -> u16 {
    let sw = core.get(objects, axis, Core::Statusword);
    let mode = core.get(objects, axis, Core::ModeDisplay);
    let speed = matches!(mode, 2 | 3);
    let records = axis.record_status();
    let velocity = axis.actual_velocity();
    // vl has no statusword mode bits (C-053): its speed signals come from
    // the velocity here; pv reports them in 6041h bit 10
    let vl = (mode == 2).then(|| {
        let target = objects.get(axis.cia402_index(0x6042), 0).unwrap_or(0);
        speed_bits(target, cw1, velocity, axis.params().velocity_window_inc_per_s)
    });
    let at_rest = velocity.abs() < 1.0e3;
    let status = Status {
        state: state(axis.state()),
        // a warning, or a limit switch locking the set-point (P-100)
        warning: sw & (SW_WARNING | SW_INTERNAL_LIMIT) != 0,
        coast_stop: cw1 & 0x0002 == 0,
        quick_stop: cw1 & 0x0004 == 0 || axis.state() == Cia::QuickStopActive,
        within_tolerance: if let Some((within, _)) = vl {
            within
        } else if speed {
            // pv: the speed inside its window (the target reached bit)
            sw & SW_TARGET_REACHED != 0
        } else {
            sw & SW_FOLLOWING_ERROR == 0
        },
        control_requested: cw1 & CONTROL_BY_PLC != 0,
        reached: if let Some((_, reached)) = vl {
            reached
        } else if speed {
            sw & SW_TARGET_REACHED != 0
        } else {
            records.target_reached
        },
        homed: axis.is_referenced() && !homing,
        task_ack: records.acknowledge,
        stopped: if speed {
            sw & SW_SPEED_ZERO != 0 || at_rest
        } else {
            records.stopped && at_rest
        },
    };
    zsw1::encode(&status)
}
