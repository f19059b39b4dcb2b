//! ZSW1 from the core's state (P-095…P-109): the device state, the CiA 402
//! statusword 6041h of the axis and its record positioning.

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
/// run the profile started.
pub fn zsw1(objects: &DriveObjects, axis: &Axis, cw1: u16, homing: bool) -> u16 {
    let sw = objects.get(axis.cia402_index(0x6041), 0).unwrap_or(0);
    let mode = objects.get(axis.cia402_index(0x6061), 0).unwrap_or(0);
    let speed = matches!(mode, 2 | 3);
    let records = axis.record_status();
    let velocity = axis.actual_velocity();
    let at_rest = velocity.abs() < 1.0e3;
    let status = Status {
        state: state(axis.state()),
        // a warning, or a limit switch locking the set-point (P-100)
        warning: sw & (SW_WARNING | SW_INTERNAL_LIMIT) != 0,
        coast_stop: cw1 & 0x0002 == 0,
        quick_stop: cw1 & 0x0004 == 0 || axis.state() == Cia::QuickStopActive,
        within_tolerance: if speed {
            // vl / pv: the speed inside its window (the target reached bit)
            sw & SW_TARGET_REACHED != 0
        } else {
            sw & SW_FOLLOWING_ERROR == 0
        },
        control_requested: cw1 & CONTROL_BY_PLC != 0,
        reached: if speed {
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
