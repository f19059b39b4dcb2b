//! The motor data of an axis and its motor protection (issue 34).
//!
//! [`MotorData`] is read from the dictionary (group B, 6073h, 6075h, 6076h,
//! 6080h, U10/U11: `objects/motor.rs`) with the rest of the snapshot when the
//! configuration generation moves, and prepared there (the torque constant and
//! currents in SI units, the i²t model's step factor for the control cycle):
//! nothing of it is looked up per cycle.
//!
//! **Motor i²t.** The winding's temperature rise, normalised so that the
//! rated current 6075h held forever gives 1.0 (100 %), is a first-order lag
//! of the squared current with the thermal time constant τ (B73):
//!
//! ```text
//! dx/dt = ((i / I_rated)² − x) / τ
//! x(t)  = (i / I_rated)² · (1 − e^(−t/τ))             (cold start, constant i)
//! t₁₀₀  = −τ · ln(1 − (I_rated / i)²)                 (time to 100 %, i > I_rated)
//! ```
//!
//! stepped exactly for the mean of u over each step of about 4 ms
//! (x += (ū − x)·(1 − e^(−T/τ)); [`MotorI2t`]). The current is the current loop's measured
//! iq ([`AxisIo::current`]) or, without a measurement, the demand (torque/kt).
//! At 100 % (U10 ≥ 1) statusword bit 7 (warning) is set and the current is
//! limited to the rated current (so x tends back to 100 %: bit 11); the state
//! holds until x falls below 95 %. U10 = 3 faults at once, U10 = 2 after U11
//! at or above 100 %: event 45 "Overtemp.motor i2t" (4380h, error register
//! 08h temperature).
//!
//! **Current limit**: the lowest of 6073h (‰ of 6075h), 2415h.02 (P-133:
//! [`Axis::set_torque_limit_per_mille`]), the i²t limit (1000 ‰) and the
//! power stage's as the current loop reports it
//! ([`CurrentActual::stage_limit_a`]: its maximum current, its rated current
//! while its own i²t model limits; `foc::Protection`), as a torque limit
//! through kt (configure.rs), below 6072h. The stage's i²t warning sets
//! statusword bit 7 as the motor's does.
//!
//! **Trips of the current loop** ([`CurrentActual::trip`]) become the
//! manual's events in `monitor.rs`.

use super::*;
use crate::params::{B05, B10, B17, B52, B53, B62, B64, B73, U10, U11};
use core::cell::Cell;

/// Event 45 "Overtemp.motor i2t", cause 1: the motor's i²t model stayed at
/// or above 100 % for U11 (U10 = 2) or reached it (U10 = 3).
pub const MOTOR_I2T: Event = Event { number: 45, cause: 1 };

/// The x at which a reached 100 % counts as left again.
const I2T_RELEASE: f32 = 0.95;

/// The motor data of an axis, prepared (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorData {
    /// B10 pole pairs.
    pub pole_pairs: u8,
    /// B05 commutation offset, increments (2^20 per revolution).
    pub commutation_offset_inc: u32,
    /// B17 torque constant, N·m/A (dq amplitude).
    pub torque_constant_nm_per_a: f32,
    /// B53 phase resistance, Ω.
    pub r_ohm: f32,
    /// B52 d-axis inductance, H.
    pub ld_h: f32,
    /// B62 q-axis inductance, H.
    pub lq_h: f32,
    /// B64 current-controller bandwidth, Hz.
    pub bandwidth_hz: f32,
    /// B73 thermal time constant, s.
    pub thermal_time_constant_s: f32,
    /// 6075h rated current, A.
    pub rated_current_a: f32,
    /// 6073h max current, ‰ of the rated current.
    pub max_current_per_mille: u16,
    /// 6080h max motor speed, rpm.
    pub max_speed_rpm: u32,
    /// U10 i²t level (0 inactive, 1 message, 2 warning, 3 fault).
    pub i2t_level: u8,
    /// U11 time at or above 100 % before the fault (U10 = 2).
    pub i2t_warning: Nanos,
}

impl Default for MotorData {
    /// The declared defaults: the simulated servo (4 pole pairs, 0.65 N·m/A,
    /// 3.6 Ω, 12 mH, 2 A rated = 1.3 N·m, 6 A max, τ = 600 s, 6000 rpm,
    /// ω_c = 2π·1 kHz, U10 = 2, U11 = 1 s).
    fn default() -> Self {
        Self {
            pole_pairs: 4,
            commutation_offset_inc: 0,
            torque_constant_nm_per_a: 0.65,
            r_ohm: 3.6,
            ld_h: 0.012,
            lq_h: 0.012,
            bandwidth_hz: 1000.0,
            thermal_time_constant_s: 600.0,
            rated_current_a: 2.0,
            max_current_per_mille: 3000,
            max_speed_rpm: 6000,
            i2t_level: 2,
            i2t_warning: Nanos::from_ms(1000),
        }
    }
}

impl MotorData {
    /// Reads the motor data of axis `w` (a missing entry counts in `m` and
    /// reads 0; zeroes the ranges refuse fall back to the defaults' meaning
    /// where a division needs them).
    pub(crate) fn read(od: &DriveObjects, w: Window, m: &Cell<u32>) -> Self {
        let p = |index: u16| w.param(od, index, 0, m);
        let d = Self::default();
        let pos = |v: i64, scale: f32, fallback: f32| if v > 0 { v as f32 * scale } else { fallback };
        Self {
            pole_pairs: u8::try_from(p(B10)).unwrap_or(d.pole_pairs),
            commutation_offset_inc: u32::try_from(p(B05)).unwrap_or(0),
            torque_constant_nm_per_a: pos(p(B17), 1e-3, d.torque_constant_nm_per_a),
            r_ohm: pos(p(B53), 1e-3, d.r_ohm),
            ld_h: pos(p(B52), 1e-6, d.ld_h),
            lq_h: pos(p(B62), 1e-6, d.lq_h),
            bandwidth_hz: pos(p(B64), 1.0, d.bandwidth_hz),
            thermal_time_constant_s: pos(p(B73), 1e-3, d.thermal_time_constant_s),
            rated_current_a: pos(w.get(od, 0x6075, 0, m), 1e-3, d.rated_current_a),
            max_current_per_mille: u16::try_from(w.get(od, 0x6073, 0, m)).unwrap_or(u16::MAX),
            max_speed_rpm: u32::try_from(w.get(od, 0x6080, 0, m)).unwrap_or(d.max_speed_rpm),
            i2t_level: u8::try_from(p(U10)).unwrap_or(d.i2t_level),
            i2t_warning: Nanos::from_ms(u64::try_from(p(U11)).unwrap_or(0)),
        }
    }

    /// The current loop's motor data (crate `foc`, the layer below): the
    /// flux linkage ψ = kt/(1.5·p) from B17 and B10, the maximum current
    /// 6075h × 6073h. One conversion for every shell that runs the loop
    /// (the simulator's electrical axis, the board's fast task).
    pub fn current_loop(&self) -> foc::MotorData {
        let p = u32::from(self.pole_pairs.max(1));
        foc::MotorData {
            r_ohm: self.r_ohm,
            ld_h: self.ld_h,
            lq_h: self.lq_h,
            psi_vs: self.torque_constant_nm_per_a / (1.5 * p as f32),
            pole_pairs: p,
            rated_current_a: self.rated_current_a,
            max_current_a: self.rated_current_a * f32::from(self.max_current_per_mille) * 1e-3,
            thermal_time_constant_s: self.thermal_time_constant_s,
        }
    }

    /// The current loop's parameters: `base` (the shell's PWM rate and dead
    /// time) with ω_c = 2π·B64.
    pub fn loop_params(&self, base: foc::LoopParams) -> foc::LoopParams {
        foc::LoopParams {
            omega_c_rad_s: core::f32::consts::TAU * self.bandwidth_hz,
            ..base
        }
    }

    /// 6076h rated torque = kt × 6075h, N·m.
    pub fn rated_torque_nm(&self) -> f32 {
        self.torque_constant_nm_per_a * self.rated_current_a
    }

    /// 6075h in mA.
    pub fn rated_current_ma(&self) -> u32 {
        (self.rated_current_a * 1000.0 + 0.5) as u32
    }

    /// 6080h in increments per second (2^20 per motor revolution).
    pub fn max_speed_inc_per_s(&self) -> f32 {
        self.max_speed_rpm as f32 * RPM_TO_INC_PER_S
    }
}

/// The motor's i²t model and what it asks for.
///
/// Per control cycle only the squared current is summed (f32: a multiply
/// and an add); every [`I2T_STEP`] or so the mean of the sums steps the model
/// exactly for a constant mean, and only then are the warning, the limit and
/// the fault decided. At τ = 600 s and a 4 ms step the increment's factor α
/// is 7·10⁻⁶: an f32 x near 1 (resolution 6·10⁻⁸) would lose the increments'
/// low digits, so x is an f32 with a compensation term (Kahan summation:
/// about 14 significant digits, on the M4F's single-precision FPU; f64 is
/// software there and cost ≈ 600 instructions per step and axis).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct MotorI2t {
    /// The model's value, fraction of 100 %.
    x: f32,
    /// What the last additions to `x` lost (Kahan).
    x_lost: f32,
    /// 1 − e^(−T/τ) of the model step T.
    alpha: f32,
    /// 1 / I_rated², 1/A².
    inv_rated_sq: f32,
    /// Sum of (i / I_rated)² of the cycles since the last model step.
    sum: f32,
    /// Cycles summed.
    count: u16,
    /// Cycles per model step.
    every: u16,
    /// Since when the model is at or above 100 % (until it falls below 95 %).
    over_since: Option<Nanos>,
    /// U10 ≥ 1 and at or above 100 %.
    limiting: bool,
    /// U10 of the configuration.
    level: u8,
    /// U11 of the configuration.
    warning_time: Nanos,
}

/// The model's step: about 4 ms (a whole number of control cycles).
pub const I2T_STEP: Nanos = Nanos::from_ms(4);

/// 1 − e^(−h), h ≥ 0, for the configuration (not per cycle): the series of
/// e^(−h/1024) squared ten times (the relative error stays near 10⁻¹²).
fn one_minus_exp_neg(h: f64) -> f64 {
    if h < 1e-3 {
        return h * (1.0 - h * (0.5 - h * (1.0 / 6.0 - h / 24.0)));
    }
    let y = h / 1024.0;
    let mut e = 1.0 - y * (1.0 - y * (0.5 - y * (1.0 / 6.0 - y / 24.0)));
    for _ in 0..10 {
        e *= e;
    }
    1.0 - e
}

impl MotorI2t {
    /// Prepares the model for the motor data and the control cycle `dt_ns`
    /// (the level x and the cycles summed so far are kept: the winding keeps
    /// its heat).
    pub fn configure(&mut self, m: &MotorData, dt_ns: u32) {
        let dt = u64::from(dt_ns.max(1));
        let every = ((I2T_STEP.as_ns() + dt / 2) / dt).clamp(1, u64::from(u16::MAX));
        self.every = every as u16;
        let step_s = (every * dt) as f64 * 1e-9;
        self.alpha = one_minus_exp_neg(step_s / f64::from(m.thermal_time_constant_s.max(1e-3))) as f32;
        let ir = m.rated_current_a;
        self.inv_rated_sq = 1.0 / (ir * ir).max(1e-12);
        self.level = m.i2t_level;
        self.warning_time = m.i2t_warning;
        self.limiting = self.level >= 1 && self.over_since.is_some();
    }

    /// One control cycle at `now` with the current amplitude `i_a` (A);
    /// returns whether the limit changed and the fault, if any (both only at
    /// a model step).
    #[inline]
    pub fn step(&mut self, i_a: f32, now: Nanos) -> (bool, Option<Event>) {
        self.sum += i_a * i_a * self.inv_rated_sq;
        self.count = self.count.saturating_add(1);
        if self.count < self.every {
            return (false, None);
        }
        self.model_step(now)
    }

    fn model_step(&mut self, now: Nanos) -> (bool, Option<Event>) {
        // count ≥ 1 (a reconfiguration keeps the count, which may then be
        // above a new, smaller `every` once)
        let u = self.sum / f32::from(self.count.max(1));
        self.sum = 0.0;
        self.count = 0;
        // x += (u − x)·α, compensated
        let d = (u - self.x) * self.alpha - self.x_lost;
        let x = self.x + d;
        self.x_lost = (x - self.x) - d;
        self.x = x;
        if self.x >= 1.0 && self.over_since.is_none() {
            self.over_since = Some(now);
        } else if self.x < I2T_RELEASE {
            self.over_since = None;
        }
        let was = self.limiting;
        self.limiting = self.level >= 1 && self.over_since.is_some();
        let fault = match (self.level, self.over_since) {
            (3, Some(_)) => Some(MOTOR_I2T),
            (2, Some(t)) if now.since(t) >= self.warning_time => Some(MOTOR_I2T),
            _ => None,
        };
        (self.limiting != was, fault)
    }

    /// The model's value, fraction of 100 %.
    pub fn level(&self) -> f32 {
        self.x
    }

    /// At or above 100 % with U10 ≥ 1: the warning (statusword bit 7) and the
    /// current limited to the rated current.
    #[inline]
    pub fn limiting(&self) -> bool {
        self.limiting
    }
}

impl Axis {
    /// The motor data in force.
    pub fn motor(&self) -> &MotorData {
        &self.motor
    }

    /// The motor's i²t model, fraction of 100 % (1.0 = the rated current
    /// held forever).
    pub fn motor_i2t(&self) -> f32 {
        self.i2t.level()
    }

    /// The motor protection of this cycle: the i²t model with the measured
    /// current (else the last demand's), its fault and its limit (a change of
    /// the limit reconfigures the cascade in the next cycle).
    pub(super) fn protect_motor(&mut self, io: &AxisIo, now: Nanos) {
        let i = match io.current {
            Some(m) => m.current_a,
            None => self.last_out.map_or(0.0, |c| c.torque_nm) / self.motor.torque_constant_nm_per_a,
        };
        let (changed, fault) = self.i2t.step(i, now);
        // the power stage's limit in ‰ of 6075h (a NaN reads 0: no licence)
        let (stage, warning) = io.current.map_or((u16::MAX, false), |m| {
            let pm = m.stage_limit_a / self.motor.rated_current_a * 1000.0;
            let pm = if pm >= f32::from(u16::MAX) {
                u16::MAX
            } else {
                pm as u16
            };
            (pm, m.stage_warning)
        });
        if changed || stage != self.stage_limit_per_mille {
            self.configured = None;
        }
        self.stage_limit_per_mille = stage;
        self.stage_warning = warning;
        if let Some(ev) = fault {
            self.raise(ev);
        }
    }

    /// The current limit in ‰ of the rated current (= of the rated torque):
    /// the lowest of 6073h, 2415h.02 (P-133), the motor's i²t limit and the
    /// power stage's (its maximum, or its rated current while its own i²t
    /// model limits: [`CurrentActual::stage_limit_a`]).
    pub(super) fn current_limit_per_mille(&self) -> u16 {
        let i2t = if self.i2t.limiting() { 1000 } else { u16::MAX };
        self.motor
            .max_current_per_mille
            .min(self.torque_limit_per_mille)
            .min(i2t)
            .min(self.stage_limit_per_mille)
    }
}
