//! The power stage's supply and the motor encoder, watched every cycle:
//! what the board's drivers report in [`AxisIo`] becomes the drive event
//! the manual's fault table names (spec §8.3, S Tab. 23).
//!
//! - The encoder reports a fault ([`AxisIo::encoder_ok`] false): event 37
//!   "Motor encoder" (7303h), in every state; the position is held at the
//!   last valid one and the fault stays while the encoder does (an
//!   acknowledge is refused, C-017).
//! - The supply drops while the power stage is on (Operation enabled,
//!   Quick stop active): event 46 "Low voltage" (3120h). With the power
//!   stage off a missing supply is only a cause of Switch on disabled
//!   (C-015, E47/E49).
//!
//! - The current loop tripped ([`CurrentActual::trip`]): its event
//!   ([`trip_event`]: over-current 33, earth fault 31, DC link 36/46,
//!   encoder 37, motor i²t 45), in every state.
//!
//! All coast (the power stage off at once, the brake engages): without
//! the DC link or the position there is no controlled stop to make.

use super::*;

/// Event 37 "Motor encoder", cause 1: the feedback driver reports the
/// encoder faulty.
pub const MOTOR_ENCODER: Event = Event { number: 37, cause: 1 };
/// Event 46 "Low voltage", cause 1: the supply dropped with the power
/// stage on.
pub const LOW_VOLTAGE: Event = Event { number: 46, cause: 1 };

impl Axis {
    /// Raises [`MOTOR_ENCODER`] or [`LOW_VOLTAGE`] for this cycle's `io`, a
    /// trip of the current loop as its event ([`trip_event`]), and
    /// steps the motor protection (`motor.rs`).
    pub(super) fn monitor(&mut self, io: &AxisIo, now: Nanos) {
        self.protect_motor(io, now);
        if let Some(trip) = io.current.and_then(|c| c.trip) {
            self.raise_with(trip_event(trip), Some(FaultReaction::Coast));
        } else if !io.encoder_ok {
            self.raise_with(MOTOR_ENCODER, Some(FaultReaction::Coast));
        } else if !io.supply_ok && matches!(self.dc.state(), State::OperationEnabled | State::QuickStopActive)
        {
            self.raise_with(LOW_VOLTAGE, Some(FaultReaction::Coast));
        }
    }
}
