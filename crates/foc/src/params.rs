//! Motor data, loop parameters, their validation and the PI gains by pole-zero
//! cancellation.

use core::f32::consts::TAU;

/// The motor's electrical data (per phase, star equivalent).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorData {
    /// Phase resistance R, Ω.
    pub r_ohm: f32,
    /// d-axis inductance Ld, H.
    pub ld_h: f32,
    /// q-axis inductance Lq, H.
    pub lq_h: f32,
    /// Permanent-magnet flux linkage ψ (amplitude), V·s = Wb.
    pub psi_vs: f32,
    /// Pole pairs p.
    pub pole_pairs: u32,
    /// Rated current (dq amplitude), A: the reference of ‰ current values and of i²t.
    pub rated_current_a: f32,
    /// Maximum current (dq amplitude), A.
    pub max_current_a: f32,
    /// Thermal time constant of the winding, s (the i²t model).
    pub thermal_time_constant_s: f32,
}

impl MotorData {
    /// The simulated servo of hil-sim (`MotorParams::default_servo`: 1.3 N·m rated,
    /// 3.9 N·m peak, 1e-4 kg·m²) with the electrical data of a typical 400 V,
    /// 400 W-class servo motor (catalogue ranges: R 2–5 Ω, L 8–20 mH, 3–5 pole pairs):
    ///
    /// | value | |
    /// |---|---|
    /// | R | 3.6 Ω |
    /// | Ld = Lq | 12 mH (τ = L/R = 3.3 ms; surface magnets) |
    /// | pole pairs | 4 |
    /// | rated / max current | 2 A / 6 A (issue 34; dq amplitudes) |
    /// | ψ | 0.65/6 = 0.108 V·s, so kt = 1.5·p·ψ = 0.65 N·m/A and 2 A give the rated 1.3 N·m |
    /// | back-EMF | 55.6 V rms line-to-line per 1000 rpm |
    /// | thermal time constant | 600 s |
    pub const fn default_servo() -> Self {
        Self {
            r_ohm: 3.6,
            ld_h: 0.012,
            lq_h: 0.012,
            psi_vs: 0.65 / 6.0,
            pole_pairs: 4,
            rated_current_a: 2.0,
            max_current_a: 6.0,
            thermal_time_constant_s: 600.0,
        }
    }

    /// Torque constant kt = 1.5·p·ψ, N·m/A (dq amplitude).
    pub fn torque_constant(&self) -> f32 {
        1.5 * self.pole_pairs as f32 * self.psi_vs
    }
}

/// Parameters of the current loop itself.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopParams {
    /// PWM frequency, Hz (16 kHz default; 8 kHz selectable). One current-loop step
    /// per PWM period.
    pub pwm_hz: f32,
    /// Current-loop bandwidth ω_c, rad/s: at most 2π · `pwm_hz` / 5.
    pub omega_c_rad_s: f32,
    /// Largest voltage vector as a fraction of the SVM's linear range Vdc/√3
    /// (1.0 = the inscribed circle; up to 2/√3 ≈ 1.155 reaches the hexagon's corners,
    /// beyond 1.0 the modulator over-modulates).
    pub modulation_limit: f32,
    /// Inverter dead time, s (compensated in the duty cycles).
    pub dead_time_s: f32,
    /// Current below which the dead-time compensation is linear in the current
    /// (no chatter at the zero crossing), A.
    pub dead_time_band_a: f32,
    /// Feed forward the back-EMF and cross-coupling (ω·L·i, ω·ψ). On by default.
    pub decoupling: bool,
}

impl LoopParams {
    /// 16 kHz PWM, ω_c = 2π·1 kHz, the inscribed circle, 1 µs dead time, decoupling on.
    pub const fn default_16k() -> Self {
        Self {
            pwm_hz: 16_000.0,
            omega_c_rad_s: TAU * 1000.0,
            modulation_limit: 1.0,
            dead_time_s: 1.0e-6,
            dead_time_band_a: 0.05,
            decoupling: true,
        }
    }

    /// PWM period, s.
    pub fn period_s(&self) -> f32 {
        1.0 / self.pwm_hz
    }
}

/// Which parameter a [`ParamError`] is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Param {
    /// Phase resistance.
    Resistance,
    /// d-axis inductance.
    Ld,
    /// q-axis inductance.
    Lq,
    /// Magnet flux linkage.
    Flux,
    /// Pole pairs.
    PolePairs,
    /// Rated current.
    RatedCurrent,
    /// Maximum current.
    MaxCurrent,
    /// Thermal time constant.
    ThermalTimeConstant,
    /// PWM frequency.
    PwmFrequency,
    /// Current-loop bandwidth.
    Bandwidth,
    /// Modulation limit.
    ModulationLimit,
    /// Dead time.
    DeadTime,
}

/// How a parameter is wrong: one-to-one an SDO abort code (and a PKW error).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Violation {
    /// Not a number or infinite: SDO abort 0609 0030h (value range exceeded).
    OutOfRange,
    /// Above what the loop allows (ω_c above a fifth of the PWM rate): 0609 0031h.
    TooHigh,
    /// Zero or negative where it must be positive (R, L, ψ, pole pairs): 0609 0032h.
    TooLow,
}

/// A parameter set refused: the loop would be unstable or impossible.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ParamError {
    /// The offending parameter.
    pub param: Param,
    /// How it is wrong.
    pub violation: Violation,
}

impl ParamError {
    /// The CiA 301 SDO abort code a bus answers with.
    pub const fn sdo_abort_code(&self) -> u32 {
        match self.violation {
            Violation::OutOfRange => 0x0609_0030,
            Violation::TooHigh => 0x0609_0031,
            Violation::TooLow => 0x0609_0032,
        }
    }
}

fn positive(param: Param, x: f32) -> Result<(), ParamError> {
    if !x.is_finite() {
        Err(ParamError {
            param,
            violation: Violation::OutOfRange,
        })
    } else if x <= 0.0 {
        Err(ParamError {
            param,
            violation: Violation::TooLow,
        })
    } else {
        Ok(())
    }
}

/// PI gains of both axes and the constants the step needs, in the discrete form at
/// the PWM period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gains {
    /// Proportional gain of d, V/A: ω_c·Ld.
    pub kp_d: f32,
    /// Proportional gain of q, V/A: ω_c·Lq.
    pub kp_q: f32,
    /// Integral gain of d times the period, V/A per step.
    pub ki_ts_d: f32,
    /// Integral gain of q times the period, V/A per step.
    pub ki_ts_q: f32,
    /// Ld, H (decoupling).
    pub ld_h: f32,
    /// Lq, H (decoupling).
    pub lq_h: f32,
    /// ψ, V·s (back-EMF feed forward).
    pub psi_vs: f32,
    /// Ld/2, H: the decoupling's current is the mean of measurement and
    /// reference, the halving folded in here (exact: a power of two).
    pub half_ld_h: f32,
    /// Lq/2, H.
    pub half_lq_h: f32,
    /// Electrical speed per angle difference over one period, rad/s per
    /// [`Angle`](crate::trig::Angle) unit: 2π/2³² · f_pwm.
    pub omega_per_angle: f32,
    /// PWM period, s.
    pub ts_s: f32,
    /// 1/Ts, 1/s.
    pub inv_ts: f32,
    /// Pole pairs.
    pub pole_pairs: u32,
    /// Torque constant 1.5·p·ψ, N·m/A.
    pub kt_nm_per_a: f32,
    /// Largest voltage vector as a fraction of Vdc: modulation limit / √3.
    pub v_limit_per_vdc: f32,
    /// Dead time as a fraction of the period (duty added per phase).
    pub dead_time_duty: f32,
    /// 1 / dead-time band, 1/A.
    pub inv_dead_time_band: f32,
    /// Decoupling on.
    pub decoupling: bool,
}

impl Gains {
    /// Gains by pole-zero cancellation: Kp = ω_c·L and Ki = ω_c·R, so the PI's zero
    /// cancels the winding's pole R/L and the closed loop is first order with
    /// bandwidth ω_c. Discrete form (backward-Euler integrator, one step per PWM
    /// period Ts): the PI zero z = Kp/(Kp + Ki·Ts) is placed on the discrete plant
    /// pole e^(−R·Ts/L), i.e. Ki·Ts = Kp·(e^(R·Ts/L) − 1) (= ω_c·R·Ts to first order).
    ///
    /// Refuses (changing nothing, there is nothing to change) R, Ld, Lq, ψ ≤ 0, pole
    /// pairs 0, ω_c ≤ 0 or above a fifth of the PWM rate (f_c = ω_c/2π > f_pwm/5:
    /// the one-period delay would leave too little phase margin), a modulation limit
    /// outside (0, 2/√3], a dead time that is negative or above a tenth of the period.
    pub fn from_motor(m: &MotorData, l: &LoopParams) -> Result<Self, ParamError> {
        positive(Param::Resistance, m.r_ohm)?;
        positive(Param::Ld, m.ld_h)?;
        positive(Param::Lq, m.lq_h)?;
        positive(Param::Flux, m.psi_vs)?;
        if m.pole_pairs == 0 {
            return Err(ParamError {
                param: Param::PolePairs,
                violation: Violation::TooLow,
            });
        }
        positive(Param::RatedCurrent, m.rated_current_a)?;
        positive(Param::MaxCurrent, m.max_current_a)?;
        positive(Param::ThermalTimeConstant, m.thermal_time_constant_s)?;
        positive(Param::PwmFrequency, l.pwm_hz)?;
        positive(Param::Bandwidth, l.omega_c_rad_s)?;
        if l.omega_c_rad_s > TAU * l.pwm_hz / 5.0 {
            return Err(ParamError {
                param: Param::Bandwidth,
                violation: Violation::TooHigh,
            });
        }
        positive(Param::ModulationLimit, l.modulation_limit)?;
        if l.modulation_limit > 2.0 * crate::transform::FRAC_1_SQRT_3 + 1.0e-6 {
            return Err(ParamError {
                param: Param::ModulationLimit,
                violation: Violation::TooHigh,
            });
        }
        let ts = l.period_s();
        if !l.dead_time_s.is_finite() {
            return Err(ParamError {
                param: Param::DeadTime,
                violation: Violation::OutOfRange,
            });
        }
        if l.dead_time_s < 0.0 {
            return Err(ParamError {
                param: Param::DeadTime,
                violation: Violation::TooLow,
            });
        }
        if l.dead_time_s > 0.1 * ts {
            return Err(ParamError {
                param: Param::DeadTime,
                violation: Violation::TooHigh,
            });
        }
        positive(Param::DeadTime, l.dead_time_band_a).map_err(|e| ParamError {
            param: Param::DeadTime,
            ..e
        })?;
        let ki_ts = |kp: f32, lh: f32| kp * (libm::expf(m.r_ohm * ts / lh) - 1.0);
        let kp_d = l.omega_c_rad_s * m.ld_h;
        let kp_q = l.omega_c_rad_s * m.lq_h;
        Ok(Self {
            kp_d,
            kp_q,
            ki_ts_d: ki_ts(kp_d, m.ld_h),
            ki_ts_q: ki_ts(kp_q, m.lq_h),
            ld_h: m.ld_h,
            lq_h: m.lq_h,
            psi_vs: m.psi_vs,
            half_ld_h: 0.5 * m.ld_h,
            half_lq_h: 0.5 * m.lq_h,
            omega_per_angle: crate::trig::RAD_PER_ANGLE * l.pwm_hz,
            ts_s: ts,
            inv_ts: l.pwm_hz,
            pole_pairs: m.pole_pairs,
            kt_nm_per_a: m.torque_constant(),
            v_limit_per_vdc: l.modulation_limit * crate::transform::FRAC_1_SQRT_3,
            dead_time_duty: l.dead_time_s * l.pwm_hz,
            inv_dead_time_band: 1.0 / l.dead_time_band_a,
            decoupling: l.decoupling,
        })
    }
}
