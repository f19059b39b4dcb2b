//! The power stage's data and the DC-link window as the current loop and the
//! brake chopper need them (issue 34; declared in [`crate::objects::stage`]):
//! read from the dictionary in SI units ([`StageData::read`]), and the
//! measured DC link into 6079h ([`set_dc_link_voltage`]).
//!
//! The shell that runs the current loops (the board's fast task, the
//! simulator's electrical axes) reads them as it reads the axes' motor data
//! (`Axis::motor`), applies them to each axis' loop (`foc::FocAxis::set_protection`:
//! the window and the stage's currents) and to the device's brake chopper
//! (`foc::BrakeChopper::set_params`), and maps the chopper's resistor fault to
//! [`crate::axis::CurrentTrip::BrakeResistor`] (event 42).

use crate::params::{A21, A22, A23, A35, A38, A40, A41, A42, A43};
use crate::DriveObjects;

/// The brake chopper's fixed hysteresis, V: it switches off at A38 − this.
pub const CHOPPER_HYSTERESIS_V: u16 = 20;

/// The power stage's data and the DC-link window (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StageData {
    /// A21 brake resistor, Ω (0 = none: the chopper stays off).
    pub brake_resistor_ohm: f32,
    /// A22 its rated power, W.
    pub brake_resistor_rated_w: f32,
    /// A23 its thermal time constant, s.
    pub brake_resistor_tau_s: f32,
    /// A35 the DC link's under-voltage limit, V.
    pub under_voltage_v: f32,
    /// A38 the chopper's switch-on threshold, V.
    pub chopper_on_v: f32,
    /// The chopper's hysteresis, V ([`CHOPPER_HYSTERESIS_V`]).
    pub chopper_hysteresis_v: f32,
    /// A40 the over-voltage trip, V.
    pub over_voltage_v: f32,
    /// A41 the stage's maximum current, A.
    pub max_current_a: f32,
    /// A42 its rated current, A.
    pub rated_current_a: f32,
    /// A43 its thermal time constant, s.
    pub tau_s: f32,
}

impl Default for StageData {
    /// The declared defaults (`foc::Protection::default_stage` and
    /// `foc::ChopperParams::default_stage` hold the same numbers).
    fn default() -> Self {
        Self {
            brake_resistor_ohm: 100.0,
            brake_resistor_rated_w: 150.0,
            brake_resistor_tau_s: 40.0,
            under_voltage_v: 400.0,
            chopper_on_v: 760.0,
            chopper_hysteresis_v: f32::from(CHOPPER_HYSTERESIS_V),
            over_voltage_v: 800.0,
            max_current_a: 8.0,
            rated_current_a: 4.0,
            tau_s: 5.0,
        }
    }
}

impl StageData {
    /// Reads them from the dictionary (an entry that cannot be read keeps
    /// the default's value).
    pub fn read(od: &DriveObjects) -> Self {
        let d = Self::default();
        let get = |index: u16, scale: f32, fallback: f32| match od.get(index, 0) {
            Ok(v) => v as f32 * scale,
            Err(_) => fallback,
        };
        Self {
            brake_resistor_ohm: get(A21, 1.0, d.brake_resistor_ohm),
            brake_resistor_rated_w: get(A22, 1.0, d.brake_resistor_rated_w),
            brake_resistor_tau_s: get(A23, 1e-3, d.brake_resistor_tau_s),
            under_voltage_v: get(A35, 1.0, d.under_voltage_v),
            chopper_on_v: get(A38, 1.0, d.chopper_on_v),
            chopper_hysteresis_v: d.chopper_hysteresis_v,
            over_voltage_v: get(A40, 1.0, d.over_voltage_v),
            max_current_a: get(A41, 1e-3, d.max_current_a),
            rated_current_a: get(A42, 1e-3, d.rated_current_a),
            tau_s: get(A43, 1e-3, d.tau_s),
        }
    }
}

impl StageData {
    /// The current loop's protection with this stage (the DC-link window,
    /// the stage's maximum and rated current and its thermal time
    /// constant); the rest (trip threshold, phase sum, deviation, the i²t
    /// policy) as in `base`. One conversion for every shell.
    pub fn protection(&self, base: foc::Protection) -> foc::Protection {
        foc::Protection {
            dc_link: foc::protect::DcLink {
                min_v: self.under_voltage_v,
                max_v: self.over_voltage_v,
            },
            stage_current_a: self.max_current_a,
            stage_rated_a: self.rated_current_a,
            stage_tau_s: self.tau_s,
            ..base
        }
    }

    /// The brake chopper's parameters.
    pub fn chopper(&self) -> foc::ChopperParams {
        foc::ChopperParams {
            resistor_ohm: self.brake_resistor_ohm,
            rated_power_w: self.brake_resistor_rated_w,
            tau_s: self.brake_resistor_tau_s,
            on_v: self.chopper_on_v,
            hysteresis_v: self.chopper_hysteresis_v,
        }
    }
}

/// The measured DC link (mV) into 6079h "DC link circuit voltage" (A566) of
/// both axes (the SC6's two axes share one DC link).
pub fn set_dc_link_voltage(od: &mut DriveObjects, millivolts: u32) {
    for index in [0x6079, 0x6079 + crate::AXIS_B_CIA402] {
        let _ = od.set(index, 0, i64::from(millivolts));
    }
}

/// The DC-link window's consistency, checked where A35 or A38 is written
/// (the other read from `od`): A35 < A38 − hysteresis < A38 < A40. `None`:
/// consistent (or another index).
pub(crate) fn window_violation(od: &DriveObjects, index: u16, v: i64) -> Option<od::SdoAbort> {
    let hyst = i64::from(CHOPPER_HYSTERESIS_V);
    let get = |i: u16| od.get(i, 0).ok();
    match index {
        A35 => match get(A38) {
            Some(on) if v >= on - hyst => Some(od::SdoAbort::VALUE_TOO_HIGH),
            _ => None,
        },
        A38 => {
            if get(A40).is_some_and(|ov| v >= ov) {
                Some(od::SdoAbort::VALUE_TOO_HIGH)
            } else if get(A35).is_some_and(|uv| v - hyst <= uv) {
                Some(od::SdoAbort::VALUE_TOO_LOW)
            } else {
                None
            }
        }
        _ => None,
    }
}
