//! The motion core: what turns set-points into one position set-point per
//! control cycle.
//!
//! - [`cycle`]: cycle times (A150 application cycle, 60C2h/A291 master cycle)
//!   and their integer ratio N (spec §10.1, §12).
//! - [`interp`]: the fine interpolator of ip and csp ([`FineInterpolator`]:
//!   linear, quadratic, cubic; internal or external velocity feedforward;
//!   extrapolation of a missing set-point and event 78 cause 3) and the
//!   velocity interpolator of csv ([`VelocityInterpolator`]) (spec §10).
//! - [`profile`]: the jerk-limited profile generator of the drive-generated
//!   modes pp and pv, with halt and quick-stop ramps ([`ProfileGenerator`])
//!   (spec §6.5.5, §6.5.7).
//! - [`scaling`]: increments ↔ user units (feed constant, gear ratio,
//!   polarity) and endless (modulo) axes (spec §7).
//!
//! Units: positions are `i32` increments, 2^20 per motor revolution, with
//! wrap-around (two's complement) arithmetic; velocities in increments per
//! second, accelerations in increments per second², jerk in increments per
//! second³ (`f32` at the API). Time is always an argument: instants and spans as
//! [`nanos::Nanos`], the control cycle `dt` as `u32` ns (A150).
#![no_std]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]
#![deny(missing_docs)]

pub mod cascade;
pub mod cycle;
pub mod float;
pub mod homing;
pub mod interp;
pub mod limits;
pub mod profile;
pub mod scaling;
pub mod touch_probe;
pub mod units;
pub mod windows;

pub use cycle::{CycleError, CycleRatio};
pub use interp::{
    FeedforwardSource, FineInterpolator, InterpolationFault, InterpolationOrder, InterpolatorConfig,
    InterpolatorOutput, MasterSetpoint, VelocityInterpolator, VelocityOutput,
};
pub use profile::{PositionTarget, ProfileError, ProfileGenerator, ProfileLimits, ProfileSample, SetMode};
pub use scaling::{AxisScaling, ModuloAxis, ModuloDirection, ScalingError};

/// Increments per motor revolution (6092h default feed, spec §7): 2^20.
pub const INCREMENTS_PER_REVOLUTION: u32 = 1 << 20;

/// A drive event with its cause, as the fault handling reports it (spec §13).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Event {
    /// Event number, e.g. 78 "Cyclical position limit".
    pub number: u16,
    /// Cause within the event, e.g. 3 "Overrun of max. extrapolation period I423".
    pub cause: u8,
}

impl Event {
    /// Event 78 "Cyclical position limit", cause 3 "Overrun of max.
    /// extrapolation period I423" (spec §10.1, C-117).
    pub const EXTRAPOLATION_OVERRUN: Event = Event { number: 78, cause: 3 };
    /// Event 78 "Cyclical position limit", cause 4 "excessive set value
    /// jump" (set-value monitoring, spec §13, C-148; the spec gives no
    /// number, the cause is ours).
    pub const SET_VALUE_JUMP: Event = Event { number: 78, cause: 4 };
}
