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
    /// axis faults with the trip's event ([`CurrentTrip::event`]) and
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
/// the PWM period that saw it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CurrentTrip {
    /// A phase current beyond the trip threshold (software, or the PWM
    /// unit's trap input): event 33 "Overcurrent" (2310h).
    OverCurrent,
    /// The three phase currents do not sum to zero (a current to earth, a
    /// broken shunt): event 31 "Short/ground" (2110h).
    PhaseSum,
    /// DC link below its minimum with the gates on: event 46 "Low voltage"
    /// (3120h).
    DcUnderVoltage,
    /// DC link above its maximum: event 36 "High voltage" (3110h).
    DcOverVoltage,
    /// The encoder stopped answering the fast task: event 37 "Motor
    /// encoder" (7303h).
    EncoderLost,
    /// The loop's own i²t backstop: event 45 "Overtemp.motor i2t" (4380h).
    MotorI2t,
    /// The power stage's i²t model at its fault level (its limit not
    /// obeyed): event 39 "Overtemperature drive controller i2t" (4280h).
    StageI2t,
    /// The current does not follow its reference although the voltage has
    /// room (an open motor phase): event 69 "Motor connection" (7120h).
    MotorConnection,
    /// The brake resistor's thermal model at 100 % (`foc::BrakeChopper`, the
    /// device's: the shell reports it on each axis): event 42
    /// "TempBrakeRes" (7110h, error register 08h temperature, E-090).
    BrakeResistor,
}

impl From<foc::Trip> for CurrentTrip {
    /// The drive core's name of the current loop's trip (every shell that
    /// runs `foc` reports it so).
    fn from(t: foc::Trip) -> Self {
        match t {
            foc::Trip::OverCurrent => Self::OverCurrent,
            foc::Trip::PhaseSum => Self::PhaseSum,
            foc::Trip::DcUnderVoltage => Self::DcUnderVoltage,
            foc::Trip::DcOverVoltage => Self::DcOverVoltage,
            foc::Trip::EncoderLost => Self::EncoderLost,
            foc::Trip::MotorI2t => Self::MotorI2t,
            foc::Trip::StageI2t => Self::StageI2t,
            foc::Trip::MotorConnection => Self::MotorConnection,
        }
    }
}

impl CurrentTrip {
    /// The drive event (E82 number, cause) of the trip (spec §8.3, S Tab. 23).
    pub const fn event(self) -> Event {
        let number = match self {
            Self::OverCurrent => 33,
            Self::PhaseSum => 31,
            Self::DcUnderVoltage => 46,
            Self::DcOverVoltage => 36,
            Self::EncoderLost => 37,
            Self::MotorI2t => 45,
            Self::StageI2t => 39,
            Self::MotorConnection => 69,
            Self::BrakeResistor => 42,
        };
        Event { number, cause: 2 }
    }
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
