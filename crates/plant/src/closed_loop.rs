//! A current step through `foc::FocAxis` against the plant, reduced to figures on
//! the fly (no buffers): what the tests compare with closed form and what
//! `examples/step_bench` prints.

use crate::{Plant, PlantParams, Shaft};
use foc::{Dq, FocAxis, LoopParams, MotorData, PowerStage, Protection};

/// Figures of one iq step 0 → `iq_final`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepFigures {
    /// 10 %–90 % rise time of the plant's iq, s (linear interpolation between PWM
    /// periods; NaN if not reached).
    pub rise_s: f64,
    /// Largest iq over the final value, fraction of the step (0 = none).
    pub overshoot: f64,
    /// Largest |id| after the step, A.
    pub id_max_abs_a: f64,
    /// iq at the end, A.
    pub iq_end_a: f64,
    /// Shaft speed at the step, rad/s.
    pub speed_at_step_rad_s: f64,
    /// The axis' trip, if any.
    pub tripped: bool,
}

/// Runs `settle` PWM periods with iq = 0, then `after` periods with iq = `iq_step`,
/// the axis enabled throughout. `shaft` holds the rotor.
pub fn current_step(
    plant: PlantParams,
    motor: MotorData,
    params: LoopParams,
    shaft: Shaft,
    iq_step: f32,
    settle: u32,
    after: u32,
) -> Result<StepFigures, foc::ParamError> {
    let mut pp = plant;
    pp.mech.shaft = shaft;
    let mut pl = Plant::new(pp);
    // the step's figures, not the protection's: the current-deviation check
    // (an open phase) off, which a loop without decoupling at full speed
    // trips (its id runs far from 0: what the figures are to show)
    let protection = Protection {
        deviation: foc::protect::CurrentDeviation {
            share: f32::INFINITY,
            floor_a: f32::INFINITY,
        },
        ..Protection::default_stage()
    };
    let mut axis = FocAxis::new(motor, params, pp.scaling(), protection)?;
    axis.enable(true);
    let ts = pp.period_s();
    let target = f64::from(iq_step);
    let (lo, hi) = (0.1 * target, 0.9 * target);
    let (mut t10, mut t90) = (f64::NAN, f64::NAN);
    let mut peak = 0.0f64;
    let mut id_max = 0.0f64;
    let mut prev = 0.0f64;
    let mut speed_at_step = 0.0;
    for k in 0..settle + after {
        let reference = if k < settle {
            Dq::default()
        } else {
            Dq { d: 0.0, q: iq_step }
        };
        if k == settle {
            speed_at_step = pl.speed_rad_s();
        }
        let s = pl.sample();
        let out = axis.step(&s, reference);
        pl.apply(&out);
        pl.advance();
        if k >= settle {
            let t = f64::from(k - settle + 1) * ts;
            let iq = pl.iq();
            let cross = |level: f64| t - ts * (iq - level) / (iq - prev);
            if t10.is_nan() && iq >= lo {
                t10 = cross(lo);
            }
            if t90.is_nan() && iq >= hi {
                t90 = cross(hi);
            }
            peak = peak.max(iq);
            id_max = id_max.max(pl.id().abs());
            prev = iq;
        } else {
            prev = pl.iq();
        }
    }
    Ok(StepFigures {
        rise_s: t90 - t10,
        overshoot: ((peak - target) / target).max(0.0),
        id_max_abs_a: id_max,
        iq_end_a: pl.iq(),
        speed_at_step_rad_s: speed_at_step,
        tripped: axis.trip().is_some(),
    })
}
