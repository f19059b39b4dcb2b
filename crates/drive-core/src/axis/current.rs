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

/// What the current loop measured, motor coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurrentActual {
    /// The torque of the measured current (kt·iq), N·m.
    pub torque_nm: f32,
    /// The measured torque-forming current iq, A (amplitude-invariant dq: the
    /// phase current's peak).
    pub current_a: f32,
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
