//! The power stage's data and the DC-link window in the one declaration
//! (issue 34): device-level parameters of group A (drive controller,
//! `parameter_index(0, line)` = 2000h + line; the DC link and the brake
//! chopper are the device's, shared by its axes).
//!
//! - Settable and saved: A21 brake resistor R (0 = none: the chopper stays
//!   off), its rated power and thermal time constant, the DC-link under-voltage
//!   limit and the chopper's switch-on threshold.
//! - Read-only (constants: the power stage's hardware): its over-voltage trip
//!   level, maximum and rated current and thermal time constant.
//!
//! The seeds name only A21 ("A21 Brake resistor R: Value = 100 ohms", the
//! manual's example of a simple parameter, and its default here); the other
//! lines are assumed (each note says so). The window is checked where it is
//! written (`dictionary/mapping.rs`, `check_consistency`): the under-voltage
//! limit below the chopper's switch-off point (threshold − hysteresis), the
//! threshold below the over-voltage trip; a refusal (0609 0031h/0032h, the
//! PKW's error) changes nothing. The current loop and the chopper read them
//! through [`crate::stage::StageData`].
//!
//! Merged with the other manufacturer parameters into one sorted list
//! ([`super::MANUFACTURER_A`]).

use super::{Object, Value};
use crate::params::{A21, A22, A23, A35, A38, A40, A41, A42, A43};
use od::DataType::{U16, U32};
use od::{Access, DataType, EntryInfo};

const fn rw(name: &'static str, t: DataType) -> EntryInfo {
    EntryInfo::new(0, name, t, Access::RW)
}
const fn ro(name: &'static str, t: DataType) -> EntryInfo {
    EntryInfo::new(0, name, t, Access::RO)
}

/// The power stage's data and the DC-link window, sorted by index.
pub const PARAMS: [Object; 9] = [
    Object::var(
        A21,
        Value::Ram,
        entries![rw("Brake resistor R", U16)
            .range(0, 10_000)
            .default_value(100)
            .unit("Ω")
            .saved()],
    )
    .level(1)
    .note("A21 (the seeds' example: 100 Ω, the default): the brake resistor on the chopper; 0 = none fitted, the chopper stays off (regenerated energy then raises the DC link up to the over-voltage trip A40, event 36)"),
    Object::var(
        A22,
        Value::Ram,
        entries![rw("Brake resistor rated power", U32)
            .range(1, 100_000)
            .default_value(150)
            .unit("W")
            .saved()],
    )
    .level(1)
    .note("A22 (line assumed): the resistor's continuous power: its thermal model (P = V²/R while the chopper conducts, first order with A23) is 100 % when this power is held forever; 80 % warns (statusword bit 7), 100 % is event 42 \"TempBrakeRes\" (EMCY 7110h, error register 08h)"),
    Object::var(
        A23,
        Value::Ram,
        entries![rw("Brake resistor thermal time constant", U32)
            .range(100, 36_000_000)
            .default_value(40_000)
            .unit("ms")
            .saved()],
    )
    .level(1)
    .note("A23 (line assumed): τ of the brake resistor's first-order thermal model; default 40 s"),
    Object::var(
        A35,
        Value::Ram,
        entries![rw("Low voltage limit", U16)
            .range(0, 1000)
            .default_value(400)
            .unit("V")
            .saved()],
    )
    .level(1)
    .note("A35 (line assumed): the DC link below it with a power stage on is event 46 \"Low voltage\" (3120h); it must stay below the chopper's switch-off point A38 − 20 V (0609 0031h above)"),
    Object::var(
        A38,
        Value::Ram,
        entries![rw("Brake chopper threshold", U16)
            .range(0, 1000)
            .default_value(760)
            .unit("V")
            .saved()],
    )
    .level(1)
    .note("A38 (line assumed): the brake chopper switches the resistor A21 on at this DC-link voltage and off 20 V below it (fixed hysteresis); it must lie below the over-voltage trip A40 (0609 0031h at or above) and 20 V above the low voltage limit A35 (0609 0032h)"),
    Object::var(
        A40,
        Value::Const,
        entries![ro("Power stage over-voltage trip", U16).default_value(800).unit("V")],
    )
    .level(1)
    .note("A40 (line assumed; read only, the power stage's hardware): the DC link above it is event 36 \"High voltage\" (3110h), the power stages off within one PWM period"),
    Object::var(
        A41,
        Value::Const,
        entries![ro("Power stage maximum current", U32).default_value(8_000).unit("mA")],
    )
    .level(1)
    .note("A41 (line assumed; read only): the power stage's current limit (the dq amplitude), one of the limits whose lowest is in force (with 6073h, 2415h and the motor's i²t)"),
    Object::var(
        A42,
        Value::Const,
        entries![ro("Power stage rated current", U32).default_value(4_000).unit("mA")],
    )
    .level(1)
    .note("A42 (line assumed; read only): the power stage's continuous current: its i²t model's 100 %, to which the current is limited there; 110 % is event 39 (4280h)"),
    Object::var(
        A43,
        Value::Const,
        entries![ro("Power stage thermal time constant", U32).default_value(5_000).unit("ms")],
    )
    .level(1)
    .note("A43 (line assumed; read only): τ of the power stage's i²t model"),
];
