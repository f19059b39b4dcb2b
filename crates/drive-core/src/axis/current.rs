//! The seam below the axis: the current control.
//!
//! The axis' cascade ends at a torque; what makes that torque is the current
//! loop below it (crate `foc` on the board's fast task, or a simulated plant),
//! which the drive core does not know. Each control cycle the shell that runs
//! the axis hands the loop the axis' command ([`CurrentControl::command`]: the
//! torque reference, motor coordinates, the power stage and the brake) and
//! puts what the loop last measured ([`CurrentControl::actual`]) into the next
//! cycle's [`AxisIo::current`](super::AxisIo::current). The actual torque
//! 6077h and the actual current 6078h (PNU 1102) come from it: the measured
//! torque-forming current iq and the torque it makes (kt·iq), not the demand.
//!
//! A shell without a current measurement (the rigid "torque-in" model that
//! acts the commanded torque exactly, or a board before its current loop runs)
//! leaves [`AxisIo::current`](super::AxisIo::current) `None`: the axis then
//! shows its own demand, as an ideal current loop would.

use super::AxisCommand;
use motion::Event;

/// What the current loop measured, motor coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurrentActual {
    /// The torque of the measured current (kt·iq), N·m.
    pub torque_nm: f32,
    /// The measured torque-forming current iq, A (amplitude-invariant dq: the
    /// phase current's peak).
    pub current_a: f32,
    /// The loop's latched protection trip, if any (its gates are off): the
    /// axis faults with the trip's event ([`trip_event`]) and
    /// coasts. The loop clears it once the axis commands the power stage
    /// off: a cause that lasts with the gates off (an encoder loss, an
    /// over-voltage) trips again at once and holds the Fault, one that
    /// needs the gates (a short, an under-voltage) trips again when the
    /// acknowledged axis switches them on.
    pub trip: Option<CurrentTrip>,
    /// The power stage's own current limit in force, A (its maximum
    /// current, or its rated current while its i²t model is at or above
    /// 100 %); infinite where the loop has none. The axis' current limit is
    /// the lowest of it, 6073h, 2415h and the motor's i²t limit.
    pub stage_limit_a: f32,
    /// The power stage's i²t model, or the brake resistor's thermal model,
    /// at or above its warning level (statusword bit 7).
    pub stage_warning: bool,
    /// The d axis over the last control cycle (the motor actions' measurement,
    /// [`DAxisMeans`]); `None` where the loop does not report it.
    pub d_axis: Option<DAxisMeans>,
}

impl CurrentActual {
    /// A measurement without a trip and without a power-stage limit.
    pub const fn measured(torque_nm: f32, current_a: f32) -> Self {
        Self {
            torque_nm,
            current_a,
            trip: None,
            stage_limit_a: f32::INFINITY,
            stage_warning: false,
            d_axis: None,
        }
    }
}

/// The d-axis voltage the loop applied and the d current it measured, each
/// the time mean over the same interval of (about) one control cycle, and that
/// interval's length: ∫u·dt and ∫i·dt of the winding equation
/// u = R·i + L·di/dt (at standstill), as far as the loop can tell (the board
/// and the simulator pair each PWM period's voltage with the current sampled
/// at its centre, the period's mean to second order).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DAxisMeans {
    /// Mean d voltage, V (amplitude-invariant dq).
    pub voltage_v: f32,
    /// Mean measured d current, A.
    pub current_a: f32,
    /// The interval, s.
    pub interval_s: f32,
}

/// A motor action's injection (B41, B42/B49, `crate::actions`): the loop
/// applies this d-axis voltage open loop (q voltage 0) instead of the output
/// of its current controllers, with its protection as always: in the frame
/// of its encoder and commutation offset, or at a fixed electrical angle
/// (then [`DAxisMeans`] are in that frame too).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Injection {
    /// d voltage, V.
    pub ud_v: f32,
    /// The frame's electrical angle (a full turn = 2^32, 0 = along phase a);
    /// `None`: the rotor's, from the encoder.
    pub angle: Option<u32>,
}

impl Injection {
    /// One PWM period of `foc` with this injection: the d voltage open loop
    /// in the encoder's frame or at the fixed angle (the shells' fast loops,
    /// board and simulator, all apply it so).
    #[inline]
    pub fn step(&self, foc: &mut foc::FocAxis, s: &foc::Sample) -> foc::PwmOut {
        let v = foc::Dq { d: self.ud_v, q: 0.0 };
        match self.angle {
            Some(a) => foc.step_voltage_at(s, v, a),
            None => foc.step_voltage(s, v),
        }
    }
}

/// A trip of the current loop's protection (the power stage is off within
/// the PWM period that saw it): [`foc::Trip`], the loop's own name for it,
/// with [`foc::Trip::BrakeResistor`] for the device's brake resistor; the
/// drive event of each is [`trip_event`].
pub use foc::Trip as CurrentTrip;

/// The drive event (E82 number, cause 2) of a current-loop trip (spec §8.3,
/// S Tab. 23): over-current 33 (2310h), phase sum 31 "Short/ground" (2110h),
/// DC link under 46 (3120h) and over 36 (3110h), encoder lost 37 (7303h),
/// motor i²t 45 (4380h), power stage i²t 39 (4280h), motor connection 69
/// (7120h), brake resistor 42 "TempBrakeRes" (7110h, error register 08h,
/// E-090).
pub const fn trip_event(trip: CurrentTrip) -> Event {
    let number = match trip {
        CurrentTrip::OverCurrent => 33,
        CurrentTrip::PhaseSum => 31,
        CurrentTrip::DcUnderVoltage => 46,
        CurrentTrip::DcOverVoltage => 36,
        CurrentTrip::EncoderLost => 37,
        CurrentTrip::MotorI2t => 45,
        CurrentTrip::StageI2t => 39,
        CurrentTrip::MotorConnection => 69,
        CurrentTrip::BrakeResistor => 42,
    };
    Event { number, cause: 2 }
}

/// One axis' current control as the drive core sees it: a reference in, a
/// measurement out. Implemented by the board (the fast task's current loop) and
/// by the simulator's plants.
pub trait CurrentControl {
    /// The command of this control cycle: the torque reference (N·m, motor
    /// coordinates; iq = torque/kt, id = 0), the power stage and the brake.
    /// It holds until the next call.
    fn command(&mut self, command: &AxisCommand);
    /// The latest measurement, `None` where the loop measures nothing (the axis
    /// then shows its demand).
    fn actual(&self) -> Option<CurrentActual>;
}
