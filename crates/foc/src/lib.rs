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
//! - [`chopper`]: the brake chopper (device-level: on above its threshold, off
//!   below threshold − hysteresis) and its resistor's thermal model (P = V²/R
//!   against the rated power, τ): warning, then event 42.
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
pub mod chopper;
pub mod params;
pub mod pi;
pub mod protect;
pub mod seam;
pub mod svm;
pub mod transform;
pub mod trig;

pub use axis::{FocAxis, Measured, Protection};
pub use chopper::{BrakeChopper, ChopperParams};
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

    /// √x, correctly rounded (IEEE 754) like `libm::sqrtf`: on a hard-float Arm
    /// (the Cortex-M4F) the FPU's `vsqrt.f32`, one instruction (14 cycles) in a
    /// leaf function, instead of libm's integer digit-by-digit root (about 60
    /// instructions on the M4F: there is no stable way to reach LLVM's `sqrt` from
    /// `core`, and `asm!` cannot name an FPU register on this target); libm
    /// elsewhere (host tests). The same result on both.
    #[inline(always)]
    pub fn sqrt(x: f32) -> f32 {
        #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
        {
            // SAFETY: `__foc_vsqrtf` (global_asm below) reads s0, writes s0 and
            // returns: an AAPCS-VFP function f32 -> f32 that touches no memory.
            #[allow(unsafe_code)]
            unsafe {
                __foc_vsqrtf(x)
            }
        }
        #[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
        {
            libm::sqrtf(x)
        }
    }

    // the leaf function: two instructions, no stack, no memory
    #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
    #[allow(unsafe_code)]
    mod vsqrt {
        core::arch::global_asm!(
            ".section .text.__foc_vsqrtf,\"ax\",%progbits",
            ".global __foc_vsqrtf",
            ".type __foc_vsqrtf,%function",
            ".fpu fpv4-sp-d16",
            ".thumb_func",
            "__foc_vsqrtf:",
            "vsqrt.f32 s0, s0",
            "bx lr",
            ".size __foc_vsqrtf, . - __foc_vsqrtf",
        );
    }

    #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
    #[allow(unsafe_code)]
    unsafe extern "C" {
        fn __foc_vsqrtf(x: f32) -> f32;
    }

    /// `(clamp(a, -l, l), clamp(b, -l, l))`, the same values: one test each
    /// (|x| ≤ l) in the ordinary case that both are within, the compare-and-selects
    /// only otherwise (a NaN or a negative l also takes that way).
    #[inline(always)]
    pub fn clamp_sym2(a: f32, b: f32, l: f32) -> (f32, f32) {
        if a.abs() <= l && b.abs() <= l {
            (a, b)
        } else {
            (clamp(a, -l, l), clamp(b, -l, l))
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
