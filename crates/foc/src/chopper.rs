//! The brake chopper: a device-level block (the DC link is the drive's, shared
//! by its axes), stepped once per PWM period with the measured DC-link voltage.
//!
//! - **Switching**: on at or above the threshold, off again below threshold −
//!   hysteresis (a two-point controller: the link oscillates inside the
//!   hysteresis band while the motor regenerates more than the mains takes).
//!   Its output is the chopper transistor's gate for the next period. Without a
//!   resistor (R = 0) the chopper never switches.
//! - **The resistor's thermal model**: `foc`'s first-order i²t model
//!   ([`I2t`]) fed with the dissipated power instead of a squared current:
//!   P = V²/R while the chopper conducts, averaged over [`DECIMATION`] periods,
//!   normalised by the resistor's rated power (the rated power held forever
//!   gives 100 %), with its thermal time constant τ:
//!
//!   ```text
//!   dx/dt = (P / P_rated − x) / τ
//!   ```
//!
//!   Warning at 80 %, fault at 100 % ([`BrakeChopper::fault`]: event 42
//!   "TempBrakeRes", EMCY 7110h with error register 08h). The chopper keeps
//!   switching after the fault (the drive switches its power stages off, so no
//!   more energy is regenerated; a link left above the threshold is discharged
//!   instead of tripping over-voltage); the fault is latched until
//!   [`BrakeChopper::reset_fault`] and the model has cooled below the warning.
//!
//! The over- and under-voltage trips are each axis' ([`crate::protect::DcLink`],
//! with the window of [`ChopperParams`]' stage).

use crate::protect::{I2t, I2tState};

/// PWM periods per step of the resistor's thermal model (16 ms at 16 kHz).
pub const DECIMATION: u32 = 256;

/// The brake chopper's and its resistor's data (the dictionary's A21, A22,
/// A23 and the switch-on threshold).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChopperParams {
    /// Brake resistor, Ω; 0 = none fitted (the chopper stays off).
    pub resistor_ohm: f32,
    /// The resistor's rated (continuous) power, W.
    pub rated_power_w: f32,
    /// The resistor's thermal time constant, s.
    pub tau_s: f32,
    /// Switch-on threshold, V.
    pub on_v: f32,
    /// Hysteresis, V: off below `on_v − hysteresis_v`.
    pub hysteresis_v: f32,
}

impl ChopperParams {
    /// 100 Ω (the manual's example of A21), 150 W, τ = 40 s, on at 760 V,
    /// 20 V hysteresis (the SC6's figures are not in the sources: assumed).
    pub const fn default_stage() -> Self {
        Self {
            resistor_ohm: 100.0,
            rated_power_w: 150.0,
            tau_s: 40.0,
            on_v: 760.0,
            hysteresis_v: HYSTERESIS_V,
        }
    }
}

/// The chopper's hysteresis, V (fixed: not a setting).
pub const HYSTERESIS_V: f32 = 20.0;

/// The chopper and its resistor's thermal model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BrakeChopper {
    p: ChopperParams,
    /// 1/R, S (0 without a resistor).
    conductance: f32,
    model: I2t,
    alpha: f64,
    period_s: f32,
    on: bool,
    sum_w: f32,
    count: u32,
    state: I2tState,
    fault: bool,
    on_periods: u64,
}

impl BrakeChopper {
    /// A cold resistor, the chopper off, for a PWM period of `period_s`.
    /// Non-positive or NaN data are taken as "no resistor" (the dictionary's
    /// ranges refuse them where they are written).
    pub fn new(p: ChopperParams, period_s: f32) -> Self {
        let rated = if p.rated_power_w > 0.0 {
            p.rated_power_w
        } else {
            1.0
        };
        let tau = if p.tau_s > 0.0 { p.tau_s } else { 1.0 };
        // the i²t model's "current" is √P: (√P)² / (√P_rated)² = P / P_rated
        let mut model = I2t::new(crate::fmath::sqrt(rated), tau);
        model.fault_level = 1.0;
        let alpha = model.alpha(period_s * DECIMATION as f32);
        Self {
            conductance: if p.resistor_ohm > 0.0 {
                1.0 / p.resistor_ohm
            } else {
                0.0
            },
            p,
            model,
            alpha,
            period_s,
            on: false,
            sum_w: 0.0,
            count: 0,
            state: I2tState::Normal,
            fault: false,
            on_periods: 0,
        }
    }

    /// New data from now on; the resistor's heat (the model's level) stays.
    pub fn set_params(&mut self, p: ChopperParams) {
        if p == self.p {
            return;
        }
        let (level, on, fault) = (self.model.level(), self.on, self.fault);
        *self = Self::new(p, self.period_s);
        self.model.set_level(level);
        self.on = on && self.conductance > 0.0;
        self.fault = fault;
        self.state = self.model.state();
    }

    /// The data in force.
    pub fn params(&self) -> &ChopperParams {
        &self.p
    }

    /// One PWM period with the DC link measured at its centre, V: the gate of
    /// the chopper for the next period (true = conducting).
    pub fn step(&mut self, vdc: f32) -> bool {
        if self.conductance <= 0.0 {
            self.on = false;
        } else if vdc >= self.p.on_v {
            self.on = true;
        } else if vdc < self.p.on_v - self.p.hysteresis_v {
            self.on = false;
        }
        if self.on {
            self.sum_w += vdc * vdc * self.conductance;
            self.on_periods += 1;
        }
        self.count += 1;
        if self.count >= DECIMATION {
            self.model_step();
        }
        self.on
    }

    #[inline(never)]
    fn model_step(&mut self) {
        // the model's input is the mean power (W) in place of i²
        let mean_w = self.sum_w * (1.0 / DECIMATION as f32);
        self.state = self.model.step_alpha(mean_w, self.alpha);
        if self.state == I2tState::Fault {
            self.fault = true;
        }
        self.sum_w = 0.0;
        self.count = 0;
    }

    /// The gate in force (true = conducting).
    pub fn is_on(&self) -> bool {
        self.on
    }

    /// PWM periods the chopper conducted since start.
    pub fn on_periods(&self) -> u64 {
        self.on_periods
    }

    /// The resistor's thermal model, fraction of its rated power held forever.
    pub fn level(&self) -> f32 {
        self.model.level()
    }

    /// The model's verdict (Normal, Warning at 80 %, Fault at 100 %).
    pub fn state(&self) -> I2tState {
        self.state
    }

    /// At or above the warning level.
    pub fn warning(&self) -> bool {
        self.state != I2tState::Normal
    }

    /// The resistor's overload (latched): event 42 "TempBrakeRes".
    pub fn fault(&self) -> bool {
        self.fault
    }

    /// Acknowledges the fault: cleared once the model is below the warning
    /// level again (a resistor still hot faults on).
    pub fn reset_fault(&mut self) {
        if self.state == I2tState::Normal {
            self.fault = false;
        }
    }
}
