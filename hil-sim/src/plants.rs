//! Both axes' motor models below a simulated drive, for either fieldbus
//! ([`crate::sim::SimDrive`] on EtherCAT, [`crate::pn::PnSim`] on PROFINET):
//! the rigid rotor (torque in) or the electrical axis ([`crate::electrical`]:
//! the current loop on the PMSM plant), and the current seam between them and
//! the drive's axes: the loops' measurement in ([`Plants::measure`]), the
//! axes' commands and the dictionary's motor and stage data down
//! ([`Plants::step`]).

use crate::electrical::{ElectricalAxis, PlantModel};
use crate::motor::{Motor, MotorOutputs};
use drive_ecat::axis::{Axis, AxisCommand, AxisIo, CurrentControl};
use drive_ecat::stage::StageData;
use drive_ecat::DriveObjects;
use nanos::Nanos;

/// The plant methods of a simulated drive over its `electrical: Plants`
/// field, the same on either fieldbus ([`crate::sim::SimDrive`],
/// [`crate::pn::PnSim`]): `set_plant`, `set_plant_at`, `electrical`,
/// `electrical_mut`.
macro_rules! plant_methods {
    () => {
        /// Runs both axes on `model` from the next control cycle on (the
        /// motors' mechanics and position stay; an electrical axis starts
        /// with zero current): the electrical model's current loop at 16 kHz
        /// on the PMSM plant, 6077h and 6078h (PNU 1102 on PROFINET) from its
        /// measured iq, its trips the axes' faults. `seed` seeds the ADC
        /// noise (axis B gets `seed + 1`).
        pub fn set_plant(
            &mut self,
            model: $crate::electrical::PlantModel,
            seed: u64,
        ) -> Result<(), foc::ParamError> {
            self.set_plant_at(model, seed, 16_000.0)
        }

        /// [`Self::set_plant`] with the electrical model's PWM and current loop
        /// at `pwm_hz` (16 kHz by default; 8 kHz selectable, issue 34).
        pub fn set_plant_at(
            &mut self,
            model: $crate::electrical::PlantModel,
            seed: u64,
            pwm_hz: f32,
        ) -> Result<(), foc::ParamError> {
            self.electrical.set(model, seed, pwm_hz)
        }

        /// Axis `axis`' current loop and PMSM, if it runs the electrical model.
        pub fn electrical(&self, axis: usize) -> Option<&$crate::electrical::ElectricalAxis> {
            self.electrical.get(axis)
        }

        /// Axis `axis`' current loop and PMSM, for plant settings (a fault of
        /// the motor, its wiring or the DC link:
        /// [`ElectricalAxis::plant_mut`](crate::electrical::ElectricalAxis::plant_mut)).
        pub fn electrical_mut(&mut self, axis: usize) -> Option<&mut $crate::electrical::ElectricalAxis> {
            self.electrical.get_mut(axis)
        }
    };
}
pub(crate) use plant_methods;

/// A simulated drive's plants and motors, the same on either fieldbus
/// ([`crate::sim::SimDrive`], [`crate::pn::PnSim`]): what `serve` sets up on
/// every drive of its line (the motor model, a plant fault).
pub trait PlantDrive {
    /// Both axes' models ([`Plants`]).
    fn plants_mut(&mut self) -> &mut Plants;
    /// The motor of `axis` (0 = A).
    fn motor_mut(&mut self, axis: usize) -> Option<&mut Motor>;
}

/// [`PlantDrive`] for a simulated drive type with an `electrical: Plants`
/// and a `motors: [Motor; 2]` field.
macro_rules! plant_drive {
    ($drive:ty) => {
        impl $crate::plants::PlantDrive for $drive {
            fn plants_mut(&mut self) -> &mut $crate::plants::Plants {
                &mut self.electrical
            }

            fn motor_mut(&mut self, axis: usize) -> Option<&mut $crate::motor::Motor> {
                self.motors.get_mut(axis)
            }
        }
    };
}
pub(crate) use plant_drive;

/// Each axis' electrical model, or `None`: the rigid model.
#[derive(Clone, Default)]
pub struct Plants([Option<Box<ElectricalAxis>>; 2]);

impl Plants {
    /// Both axes on `model` from now on, the electrical model's PWM and
    /// current loop at `pwm_hz`; `seed` seeds the ADC noise (axis B gets
    /// `seed + 1`). An electrical axis starts with zero current.
    pub fn set(&mut self, model: PlantModel, seed: u64, pwm_hz: f32) -> Result<(), foc::ParamError> {
        for (k, el) in self.0.iter_mut().enumerate() {
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
    pub fn get(&self, axis: usize) -> Option<&ElectricalAxis> {
        self.0.get(axis).and_then(|e| e.as_deref())
    }

    /// The same, for plant settings (a fault of the motor, its wiring or the
    /// DC link: [`ElectricalAxis::plant_mut`]).
    pub fn get_mut(&mut self, axis: usize) -> Option<&mut ElectricalAxis> {
        self.0.get_mut(axis).and_then(|e| e.as_deref_mut())
    }

    /// The current seam: the electrical axes' measured iq (and a trip of
    /// their loop) into the axes' inputs; the rigid model measures nothing
    /// (the axes show their demand).
    pub fn measure(&self, io: &mut [AxisIo; 2]) {
        for (io, el) in io.iter_mut().zip(&self.0) {
            if let Some(el) = el {
                io.current = el.actual();
            }
        }
    }

    /// Axis A's measured DC link, mV, for 6079h (each axis' plant has its
    /// own); `None` with the rigid model (it has no DC link).
    pub fn dc_link_mv(&self) -> Option<u32> {
        self.get(0).map(|e| e.dc_link_mv())
    }

    /// One control cycle of length `dt` of both motors under the axes'
    /// commands `cmd`, each electrical axis with the motor data of the
    /// drive's `axes` (applied when they changed; a refused set keeps the
    /// loop's) and the power stage's data in its `objects`; the motors'
    /// outputs into `feedback`.
    pub fn step(
        &mut self,
        motors: &mut [Motor; 2],
        feedback: &mut [Option<MotorOutputs>; 2],
        cmd: [AxisCommand; 2],
        axes: &[Axis; 2],
        objects: &DriveObjects,
        dt: Nanos,
    ) {
        let data = axes.each_ref().map(|a| *a.motor());
        let stage = &StageData::read(objects);
        let axes = motors.iter_mut().zip(feedback.iter_mut());
        for ((((motor, fb), c), el), data) in axes.zip(cmd).zip(self.0.iter_mut()).zip(data) {
            *fb = Some(match el {
                Some(el) => {
                    let _ = el.set_motor_data(&data);
                    el.set_stage_data(stage);
                    el.command(&c);
                    el.run(motor, dt)
                }
                None => {
                    let torque = if c.power_stage {
                        f64::from(c.torque_nm)
                    } else {
                        0.0
                    };
                    motor.step(torque, !c.brake_release, dt)
                }
            });
        }
    }
}
