//! The axes' motor models below the drive, the current seam's shell: the
//! rigid rotor (torque in) or the electrical axis (`crate::electrical`: the
//! current loop on the PMSM plant). Per control cycle the electrical axes'
//! measurement goes into the axes' inputs ([`SimDrive::measure_currents`]),
//! and the axes' commands and the dictionary's motor data go down
//! ([`SimDrive::step_motors`]).

use super::SimDrive;
use crate::electrical::{ElectricalAxis, PlantModel};
use drive_ecat::axis::{AxisCommand, AxisIo, CurrentControl};

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
        for (k, el) in self.electrical.iter_mut().enumerate() {
            *el = match model {
                PlantModel::Rigid => None,
                PlantModel::Electrical => Some(Box::new(ElectricalAxis::default_servo_at(
                    seed.wrapping_add(k as u64),
                    pwm_hz,
                )?)),
            };
        }
        Ok(())
    }

    /// Axis `axis`' current loop and PMSM, if it runs the electrical model.
    pub fn electrical(&self, axis: usize) -> Option<&ElectricalAxis> {
        self.electrical.get(axis).and_then(|e| e.as_deref())
    }

    /// Axis `axis`' current loop and PMSM, for plant settings (a fault of the
    /// motor, its wiring or the DC link: [`ElectricalAxis::plant_mut`]).
    pub fn electrical_mut(&mut self, axis: usize) -> Option<&mut ElectricalAxis> {
        self.electrical.get_mut(axis).and_then(|e| e.as_deref_mut())
    }

    /// The current seam: the electrical axes' measured iq (and a trip of
    /// their loop) into the axes' inputs; the rigid model measures nothing
    /// (the axes show their demand).
    pub(super) fn measure_currents(&self, io: &mut [AxisIo; 2]) {
        for (io, el) in io.iter_mut().zip(&self.electrical) {
            if let Some(el) = el {
                io.current = el.actual();
            }
        }
    }

    /// 6079h "DC link circuit voltage" (A566): axis A's measured link (each
    /// axis' plant has its own, `crate::electrical`); nothing with the rigid
    /// model (it has no DC link).
    pub(super) fn show_dc_link(&mut self) {
        if let Some(mv) = self.electrical(0).map(|e| e.dc_link_mv()) {
            drive_ecat::stage::set_dc_link_voltage(self.drive.objects_mut(), mv);
        }
    }

    /// One control cycle of both motors under the axes' commands `cmd`
    /// (length `self.cycle`).
    pub(super) fn step_motors(&mut self, cmd: [AxisCommand; 2]) {
        let axes = self.motors.iter_mut().zip(self.feedback.iter_mut());
        let data = self.drive.axes().each_ref().map(|a| *a.motor());
        let stage = drive_ecat::stage::StageData::read(self.drive.objects());
        for ((((motor, fb), c), el), data) in axes.zip(cmd).zip(self.electrical.iter_mut()).zip(data) {
            *fb = Some(match el {
                Some(el) => {
                    // the motor data as the drive has them (applied when
                    // they changed; a refused set keeps the loop's)
                    let _ = el.set_motor_data(&data);
                    el.set_stage_data(&stage);
                    el.command(&c);
                    el.run(motor, self.cycle)
                }
                None => {
                    let torque = if c.power_stage {
                        f64::from(c.torque_nm)
                    } else {
                        0.0
                    };
                    motor.step(torque, !c.brake_release, self.cycle)
                }
            });
        }
    }
}
