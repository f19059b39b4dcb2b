//! Protection building blocks: each is a small pure check or a model stepped with
//! its time argument; the axis step ([`crate::axis`]) combines them.

use crate::transform::Abc;

/// What ended the power stage's work. One-to-one a drive event; the personality
/// maps it to its bus (EMCY/603Fh, PROFIdrive fault, diagnosis).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Trip {
    /// A phase current beyond the trip threshold (software; the PWM unit's trap
    /// input does the same in hardware).
    OverCurrent,
    /// The three measured phase currents do not sum to zero: a shunt, an amplifier
    /// or a phase is broken.
    PhaseSum,
    /// DC link below its minimum.
    DcUnderVoltage,
    /// DC link above its maximum.
    DcOverVoltage,
    /// The encoder reports an error or stopped.
    EncoderLost,
    /// The motor's i²t model reached its fault level.
    MotorI2t,
    /// The power stage's i²t model reached its fault level (its current
    /// limit was not obeyed).
    StageI2t,
    /// The current does not follow its reference although the voltage has
    /// room ([`CurrentDeviation`]): an open motor phase or a lost motor
    /// connection.
    MotorConnection,
    /// The brake resistor's thermal model at 100 %
    /// ([`BrakeChopper::fault`](crate::BrakeChopper::fault)): the device's,
    /// which a shell reports on each axis. The current loop never trips
    /// with it itself.
    BrakeResistor,
}

/// Current-control plausibility: over a window, the mean square of the
/// current error (reference − measured, dq) against the mean square of the
/// reference, counted only in periods below half the speed at which the
/// back-EMF takes the whole voltage (above it the loop may rightly not
/// follow). A healthy first-order loop with
/// ω_c ≫ the reference's changes leaves a small share (a step's error decays
/// with 1/ω_c: 0.16 ms of a 16 ms window at 1 kHz); an open phase leaves the
/// reference's component along the missing phase, half of its mean square
/// on a turning rotor. The axis takes the healthy transients of the
/// reference's steps in the window off the error before it asks (twice
/// the first-order loop's ∑e² per step): a step late in a window, or a
/// short pulse, is judged against the little reference the window holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurrentDeviation {
    /// Largest share of the reference's mean square the error's may reach.
    pub share: f32,
    /// Error (rms) that never trips, A: the ADC's noise and small references.
    pub floor_a: f32,
}

impl CurrentDeviation {
    /// True when the window's mean squares (error, reference; A²) are
    /// implausible.
    #[inline]
    pub fn deviates(&self, error_sq: f32, reference_sq: f32) -> bool {
        error_sq > self.share * reference_sq + self.floor_a * self.floor_a
    }
}

/// Over-current: trips when any phase current's magnitude exceeds the threshold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OverCurrent {
    /// Trip threshold, A (phase current amplitude).
    pub threshold_a: f32,
}

impl OverCurrent {
    /// True when a phase is beyond the threshold.
    #[inline]
    pub fn tripped(&self, i: Abc) -> bool {
        i.a.abs() > self.threshold_a || i.b.abs() > self.threshold_a || i.c.abs() > self.threshold_a
    }
}

/// Phase-current plausibility: with a star point the three currents sum to zero; a
/// measured sum beyond the tolerance means a measurement or a phase is broken.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseSum {
    /// Largest allowed |a + b + c|, A (ADC noise and offsets).
    pub tolerance_a: f32,
}

impl PhaseSum {
    /// True when the sum is implausible.
    #[inline]
    pub fn implausible(&self, i: Abc) -> bool {
        (i.a + i.b + i.c).abs() > self.tolerance_a
    }
}

/// DC-link voltage window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DcLink {
    /// Lowest voltage to run at, V.
    pub min_v: f32,
    /// Highest voltage, V (beyond the brake chopper's threshold).
    pub max_v: f32,
}

impl DcLink {
    /// The trip for this voltage, if any.
    #[inline]
    pub fn check(&self, vdc: f32) -> Option<Trip> {
        if vdc < self.min_v {
            Some(Trip::DcUnderVoltage)
        } else if vdc > self.max_v {
            Some(Trip::DcOverVoltage)
        } else {
            None
        }
    }
}

/// The i²t model's verdict.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum I2tState {
    /// Below the warning level.
    Normal,
    /// At or above the warning level.
    Warning,
    /// At or above 100 %: the current is limited to the rated current.
    Limiting,
    /// At or above the fault level.
    Fault,
}

/// The motor's thermal model: the winding's temperature rise, normalised so that
/// the rated current held forever gives 1.0 (100 %), is a first-order lag of the
/// squared current with the thermal time constant τ:
///
/// ```text
/// dx/dt = ((i / I_rated)² − x) / τ,   x(t) = x∞ + (x0 − x∞)·e^(−t/τ)
/// ```
///
/// Stepped exactly for a constant current over the step (x += (u − x)·(1 − e^(−dt/τ))).
/// Warning at [`I2t::warning_level`], current limited to the rated current at
/// 100 % (so x tends back to at most 1.0), fault at [`I2t::fault_level`] (reached
/// only when the limit is not obeyed, e.g. a current the loop cannot hold).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct I2t {
    x: f64,
    inv_rated_sq: f64,
    tau_s: f64,
    /// Level of the warning (fraction of 100 %), default 0.8.
    pub warning_level: f32,
    /// Level of the fault, default 1.1.
    pub fault_level: f32,
}

impl I2t {
    /// A cold motor (x = 0) of this rated current (A) and thermal time constant (s).
    /// Both are positive (validated with the motor data).
    pub fn new(rated_current_a: f32, tau_s: f32) -> Self {
        Self {
            x: 0.0,
            inv_rated_sq: 1.0 / f64::from(rated_current_a * rated_current_a),
            tau_s: f64::from(tau_s),
            warning_level: 0.8,
            fault_level: 1.1,
        }
    }

    /// The model's value, fraction of 100 %.
    pub fn level(&self) -> f32 {
        self.x as f32
    }

    /// Sets the model's value (fraction of 100 %), e.g. a warm start.
    pub fn set_level(&mut self, x: f32) {
        self.x = f64::from(x);
    }

    /// One step of `dt_s` seconds with the current amplitude `i_a` held over it.
    /// Use [`I2t::step_alpha`] with a precomputed α in a fixed-rate loop.
    pub fn step(&mut self, i_a: f32, dt_s: f32) -> I2tState {
        let alpha = self.alpha(dt_s);
        self.step_alpha(i_a * i_a, alpha)
    }

    /// One step with the squared current (A²) and α = 1 − e^(−dt/τ).
    ///
    /// The state is f64: at a step of 1 ms and τ = 600 s, α is 1.7·10⁻⁶ and an f32
    /// state would lose the increments below its 6·10⁻⁸ resolution (the
    /// firmware steps it once per 256 PWM periods, where f64's software cost is
    /// negligible).
    pub fn step_alpha(&mut self, i_sq: f32, alpha: f64) -> I2tState {
        self.x += (f64::from(i_sq) * self.inv_rated_sq - self.x) * alpha;
        self.state()
    }

    /// The verdict at the present level.
    pub fn state(&self) -> I2tState {
        if self.x >= f64::from(self.fault_level) {
            I2tState::Fault
        } else if self.x >= 1.0 {
            I2tState::Limiting
        } else if self.x >= f64::from(self.warning_level) {
            I2tState::Warning
        } else {
            I2tState::Normal
        }
    }

    /// α = 1 − e^(−dt/τ) for a fixed step.
    pub fn alpha(&self, dt_s: f32) -> f64 {
        -libm::expm1(-f64::from(dt_s) / self.tau_s)
    }
}

/// The current limit: the lowest of several (max current 6073h, the speed mode's
/// 2415h (P-133), the i²t limit, the power stage's), never negative. A list without
/// a finite entry, or a NaN entry, gives 0 (no current): a limit that cannot be read
/// is no licence.
pub fn current_limit(limits: &[f32]) -> f32 {
    let mut lowest = f32::INFINITY;
    for &l in limits {
        if l.is_nan() {
            return 0.0;
        }
        lowest = crate::fmath::min(l, lowest);
    }
    if lowest.is_finite() {
        crate::fmath::max(lowest, 0.0)
    } else {
        0.0
    }
}
