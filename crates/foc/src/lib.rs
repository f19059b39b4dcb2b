//! Field-oriented current control of a permanent-magnet synchronous motor, one axis
//! per [`FocAxis`], one step per PWM period.
//!
//! - [`trig`]: sin/cos of the electrical angle (a 512-entry table, interpolated).
//! - [`transform`]: Clarke and Park, and their inverses (amplitude-invariant).
//! - [`params`]: motor data, loop parameters, their validation ([`ParamError`], one
//!   SDO abort code each) and the gains by pole-zero cancellation ([`Gains`]).
//! - [`pi`]: the dq PI current controllers: decoupling (ω·L·i, ω·ψ), anti-windup by
//!   clamping, the voltage-circle limit (d first, then q).
//! - [`svm`]: space-vector modulation by min/max injection, over-modulation scaled
//!   onto the hexagon, dead-time compensation.
//! - [`protect`]: over-current, phase-sum plausibility, DC-link window, motor i²t,
//!   current limit = the lowest of several.
//! - [`seam`]: what a power board (or the simulated plant, crate `plant`) gives and
//!   takes per axis: [`Sample`] in (ADC counts, encoder), [`PwmOut`] out (compare
//!   values, gate enable), the [`PowerStage`] trait, the [`Scaling`] applied once.
//! - [`axis`]: [`FocAxis`], all of it in one step, with the torque → iq reference
//!   (id = 0: field weakening is future work).
//!
//! The step computes in `f32` (the Cortex-M4F's FPU); ADC counts and compare values
//! stay integers at the seam. `no_std`, no heap, no panics on any input: a sample's
//! counts, a NaN reference or a zero DC link give compare values and trips, never a
//! panic. The default motor ([`MotorData::default_servo`]) is hil-sim's simulated
//! servo with the electrical data written down there.
#![no_std]
#![deny(missing_docs)]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]

pub mod axis;
pub mod params;
pub mod pi;
pub mod protect;
pub mod seam;
pub mod svm;
pub mod transform;
pub mod trig;

pub use axis::{FocAxis, Measured, Protection};
pub use params::{Gains, LoopParams, MotorData, Param, ParamError, Violation};
pub use protect::{I2tState, Trip};
pub use seam::{PowerStage, PwmOut, Sample, Scaling, Shunts};
pub use transform::{Abc, AlphaBeta, Dq};

/// f32 helpers that compile to a compare and a conditional move on the M4F (core's
/// `f32::max`/`min` call `fmaxf`/`fminf`, and `clamp` has a panic path for bounds it
/// cannot prove ordered). NaN passes through `clamp`; callers' outputs are bounded
/// again where they become integers (`as` saturates, NaN → 0).
pub mod fmath {
    /// The larger of two (b if a is NaN).
    #[inline(always)]
    pub fn max(a: f32, b: f32) -> f32 {
        if a > b {
            a
        } else {
            b
        }
    }

    /// The smaller of two (b if a is NaN).
    #[inline(always)]
    pub fn min(a: f32, b: f32) -> f32 {
        if a < b {
            a
        } else {
            b
        }
    }

    /// x limited to [lo, hi] (no panic when lo > hi: hi wins).
    #[inline(always)]
    pub fn clamp(x: f32, lo: f32, hi: f32) -> f32 {
        if x > hi {
            hi
        } else if x < lo {
            lo
        } else {
            x
        }
    }
}
