//! The axes' motor models below the drive, the current seam's shell: the
//! rigid rotor (torque in) or the electrical axis (`crate::electrical`: the
//! current loop on the PMSM plant). Per control cycle the electrical axes'
//! measurement goes into the axes' inputs ([`SimDrive::measure_currents`]),
//! and the axes' commands and the dictionary's motor data go down
//! ([`SimDrive::step_motors`]).

use super::SimDrive;
use drive_ecat::axis::{AxisCommand, AxisIo};

crate::plants::plant_drive!(SimDrive);

impl SimDrive {
    crate::plants::plant_methods!();

    /// The current seam: the electrical axes' measured iq (and a trip of
    /// their loop) into the axes' inputs ([`Plants::measure`](crate::plants::Plants::measure)).
    pub(super) fn measure_currents(&self, io: &mut [AxisIo; 2]) {
        self.electrical.measure(io);
    }

    /// 6079h "DC link circuit voltage" (A566): axis A's measured link (each
    /// axis' plant has its own, `crate::electrical`); nothing with the rigid
    /// model (it has no DC link).
    pub(super) fn show_dc_link(&mut self) {
        if let Some(mv) = self.electrical.dc_link_mv() {
            drive_ecat::stage::set_dc_link_voltage(self.drive.objects_mut(), mv);
        }
    }

    /// One control cycle of both motors under the axes' commands `cmd`
    /// (length `self.cycle`), with the motor and stage data the drive has.
    pub(super) fn step_motors(&mut self, cmd: [AxisCommand; 2]) {
        self.electrical.step(
            &mut self.motors,
            &mut self.feedback,
            cmd,
            self.drive.axes(),
            self.drive.objects(),
            self.cycle,
        );
    }
}
