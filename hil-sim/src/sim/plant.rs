//! The axes' motor models below the drive, the current seam's shell: the
//! rigid rotor (torque in) or the electrical axis (`crate::electrical`: the
//! current loop on the PMSM plant). Per control cycle the electrical axes'
//! measurement goes into the axes' inputs ([`SimDrive::measure_currents`]),
//! and the axes' commands and the dictionary's motor data go down
//! ([`SimDrive::step_motors`]).

use super::SimDrive;
use crate::electrical::{ElectricalAxis, PlantModel};
use drive_ecat::axis::{AxisCommand, AxisIo};

impl SimDrive {
    /// Runs both axes on `model` from the next control cycle on (the motors'
    /// mechanics and position stay; an electrical axis starts with zero current).
    /// `seed` seeds the ADC noise (axis B gets `seed + 1`).
    pub fn set_plant(&mut self, model: PlantModel, seed: u64) -> Result<(), foc::ParamError> {
        self.set_plant_at(model, seed, 16_000.0)
    }

    /// [`Self::set_plant`] with the electrical model's PWM and current loop
    /// at `pwm_hz` (16 kHz by default; 8 kHz selectable, issue 34).
    pub fn set_plant_at(&mut self, model: PlantModel, seed: u64, pwm_hz: f32) -> Result<(), foc::ParamError> {
        self.electrical.set(model, seed, pwm_hz)
    }

    /// Axis `axis`' current loop and PMSM, if it runs the electrical model.
    pub fn electrical(&self, axis: usize) -> Option<&ElectricalAxis> {
        self.electrical.get(axis)
    }

    /// Axis `axis`' current loop and PMSM, for plant settings (a fault of the
    /// motor, its wiring or the DC link: [`ElectricalAxis::plant_mut`]).
    pub fn electrical_mut(&mut self, axis: usize) -> Option<&mut ElectricalAxis> {
        self.electrical.get_mut(axis)
    }

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
        let data = self.drive.axes().each_ref().map(|a| *a.motor());
        let stage = drive_ecat::stage::StageData::read(self.drive.objects());
        self.electrical.step(
            &mut self.motors,
            &mut self.feedback,
            cmd,
            data,
            &stage,
            self.cycle,
        );
    }
}
