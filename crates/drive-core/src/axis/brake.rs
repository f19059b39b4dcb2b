//! The holding brake (C-020…C-022, spec cia402.md §5.1 and §14): the device
//! control decides when the brake opens and closes; brake control F00 and
//! the release override F06 (issue 40) decide whether the drive acts on it.
//!
//! | F00 | F06 | brake output |
//! |---|---|---|
//! | 1 (active, default) | 0 | by the device state: released in Operation enabled on the first motion command (C-021), kept released in Quick stop active, per the fault reaction, applied in the de-energised states (C-020) |
//! | 1 | 1 | released in every state (C-020's "unless the release override is active", E-129) |
//! | 0 (inactive) | any | off: the brake stays applied, the drive does not control it |

use super::*;

impl Axis {
    /// Takes F00/F06 from the configuration snapshot.
    pub(super) fn configure_brake(&mut self, o: &Snapshot) {
        self.brake = (o.brake.0 == 1, o.brake.1 == 1);
    }

    /// The release override the device control sees: F06 with F00 active.
    pub(super) fn brake_override(&self) -> bool {
        self.brake == (true, true)
    }

    /// The brake output from the device control's: nothing without brake
    /// control (F00 = 0).
    pub(super) fn brake_output(&self, released: bool) -> bool {
        self.brake.0 && released
    }

    /// Whether the mode has an active motion command (brake release, C-021).
    pub(super) fn motion_command(&self, o: &Snapshot) -> bool {
        match self.dc.mode() {
            Mode::CyclicPosition | Mode::CyclicVelocity | Mode::CyclicTorque => true,
            Mode::ProfileVelocity => o.target_velocity != 0,
            Mode::ProfileTorque => o.target_torque != 0,
            Mode::Velocity => o.vl_target != 0,
            _ => false,
        }
    }
}
