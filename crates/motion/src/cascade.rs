//! The control cascade: position controller → velocity PI controller →
//! torque limit (spec §6.5, §10.2; C-035, C-037, C-038, C-039, C-118, C-120).
//!
//! ```text
//!  position set-point ─┐  ┌────────┐   velocity FF × I25
//!  actual position ────┴─▶│ P (Kv) │──(+)──▶ clamp ±I10 ─┐
//!                         └────────┘                      │ (csv/pv enter here)
//!                                                          ▼
//!  actual velocity ──────────────────────────────▶ ┌──────────┐  torque FF (60B2h, J·a)
//!                                                   │ PI Kp,Ti │──(+)──▶ torque limit ─▶ torque
//!                                                   └──────────┘           ▲   (cst/pt enter here,
//!                                                                          │    through the speed
//!                                                                          │    limiter G472/G475)
//! ```
//!
//! [`ControlEntry`] picks where a mode enters: csp/pp/ip/homing at the
//! position controller, csv/pv/vl at the velocity controller, cst/pt at the
//! torque limit. In the torque entry a speed limiter caps |v| at the torque
//! mode velocity limits (G472 positive, G475 negative; C-039): it narrows the
//! allowed torque band to what a P velocity controller aiming at the limit
//! would command, so with a 0 % limit the axis does not move.
//!
//! Units: positions in increments (2^20 per revolution, wrap-around
//! arithmetic), velocities in increments/s, accelerations in increments/s²,
//! torques in N·m, the velocity gain in N·m per rad/s, times in ns. The
//! actual velocity is computed from positions by a differentiating filter
//! when the caller does not supply it.

use crate::float::clamp;
use crate::INCREMENTS_PER_REVOLUTION;

/// Radians per increment: 2π / 2^20.
pub const RAD_PER_INCREMENT: f32 = core::f32::consts::TAU / INCREMENTS_PER_REVOLUTION as f32;

/// Where a mode enters the cascade.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ControlEntry {
    /// Position controller (csp, pp, ip, homing, jog with I26 = 1).
    Position,
    /// Velocity controller (csv, pv, vl, jog with I26 = 0).
    Velocity,
    /// Torque limit, through the speed limiter (cst, pt).
    Torque,
}

impl ControlEntry {
    /// The entry of CiA 402 mode `mode_6060h` (6060h/6061h code); `None`
    /// for mode 0 (no mode, no control) and unknown codes. Jog (−1) is
    /// given the position entry (I26 = 1); with I26 = 0 the caller uses
    /// [`ControlEntry::Velocity`].
    pub const fn for_mode(mode_6060h: i8) -> Option<Self> {
        match mode_6060h {
            -1 | 1 | 6 | 7 | 8 => Some(ControlEntry::Position),
            2 | 3 | 9 => Some(ControlEntry::Velocity),
            4 | 10 => Some(ControlEntry::Torque),
            _ => None,
        }
    }
}

/// Why a [`CascadeConfig`] is refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CascadeError {
    /// A gain, limit or weight is negative or not finite.
    InvalidValue,
    /// I25 outside 0 … 100 %.
    FeedforwardWeight,
}

/// Gains and limits of the cascade. [`CascadeConfig::DEFAULT`] suits a
/// small servo (J ≈ 1e-4 kg·m², rated torque ≈ 1.3 N·m) at a control cycle of
/// 62.5 … 250 µs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CascadeConfig {
    /// Position controller gain Kv in 1/s (velocity command in increments/s
    /// per increment of following error).
    pub position_gain_per_s: f32,
    /// I23 dead band of the position controller in increments (PROFINET
    /// PNU 1270.2, P-157): while |following error| is within it, the position
    /// controller adds no velocity command (the feedforward still passes),
    /// so a gear's backlash does not make the axis hunt. 0 = off.
    pub position_dead_band_inc: u32,
    /// I25 speed feedforward weight in % (0 … 100; 0 disables, C-120),
    /// applied to the velocity feedforward in the position entry. The
    /// [`FineInterpolator`](crate::FineInterpolator) output is already
    /// weighted by I25: keep 100 % here when feeding it in.
    pub velocity_feedforward_percent: f32,
    /// Velocity controller proportional gain Kp in N·m per rad/s.
    pub velocity_gain_nm_per_rad_per_s: f32,
    /// Velocity controller integral time Ti in ns (0 = no integral part).
    pub velocity_integral_time_ns: u32,
    /// Time constant of the differentiating filter's low pass in ns (0 = raw
    /// difference quotient); used only when no actual velocity is supplied.
    pub velocity_filter_time_ns: u32,
    /// Velocity command limit (I10 max. speed) in increments/s, position and
    /// velocity entries.
    pub max_velocity_inc_per_s: f32,
    /// Torque limit in the positive direction, N·m (magnitude, e.g. from
    /// 6072h/60E0h).
    pub torque_limit_positive_nm: f32,
    /// Torque limit in the negative direction, N·m (magnitude, e.g. from
    /// 6072h/60E1h).
    pub torque_limit_negative_nm: f32,
    /// Speed limit of the torque entry in the positive direction (G472), in
    /// increments/s; 0 (the 0 % default) keeps the axis from moving (C-039).
    pub torque_mode_velocity_limit_positive_inc_per_s: f32,
    /// Speed limit of the torque entry in the negative direction (G475), in
    /// increments/s (magnitude).
    pub torque_mode_velocity_limit_negative_inc_per_s: f32,
    /// Moment of inertia in kg·m² for the acceleration (torque) feedforward
    /// J·a; 0 disables it.
    pub inertia_kg_m2: f32,
    /// Coulomb friction feedforward, N·m: `Fc·s(v_ref)` added to the torque
    /// in the position and velocity entries, with s a sign smoothed over
    /// ±[`FRICTION_BAND_INC_PER_S`] (no chatter at standstill); 0 disables it.
    pub coulomb_friction_nm: f32,
    /// Viscous friction feedforward, N·m per rad/s: `B·v_ref`; 0 disables it.
    pub viscous_friction_nm_per_rad_per_s: f32,
    /// Derive the acceleration feedforward from the change of the velocity
    /// feedforward when the set-point generator supplies none (csp/ip with
    /// linear interpolation: a = Δv_ff/Δt of successive cycles, from the
    /// third cycle after a reset on: the first carries the jump from the
    /// actual position to the set-point). Off: only the generator's
    /// acceleration feeds J·a.
    pub derive_acceleration: bool,
    /// Compare the speed set-point with the measured speed advanced by the
    /// generator's acceleration feedforward (the input's, not one derived
    /// from the set-points) over the measurement's lag (half a cycle of
    /// the difference plus the velocity filter's time constant): with an
    /// accurate J·a the shaft's speed is the set-point's, the measured one
    /// lags it by a·lag, and the uncompensated controller would make a
    /// following error of a·lag/Kv out of that lag.
    pub compensate_velocity_lag: bool,
}

/// The band of the smoothed sign of the Coulomb friction feedforward,
/// increments/s (0.02 rev/s): below it the feedforward shrinks linearly to 0.
pub const FRICTION_BAND_INC_PER_S: f32 = 0.02 * INCREMENTS_PER_REVOLUTION as f32;

impl CascadeConfig {
    /// Defaults for a small servo: Kv = 100 /s, I25 = 100 %, Kp = 0.06 N·m
    /// per rad/s (≈ 100 Hz velocity bandwidth at J = 1e-4 kg·m²), Ti = 8 ms,
    /// velocity filter 0.25 ms, I10 = 3000 rpm, torque limits ±3.9 N·m
    /// (300 % of 1.3 N·m), torque-mode speed limits 0 (the G472/G475 default
    /// of 0 %), no acceleration feedforward.
    pub const DEFAULT: CascadeConfig = CascadeConfig {
        position_gain_per_s: 100.0,
        position_dead_band_inc: 0,
        velocity_feedforward_percent: 100.0,
        velocity_gain_nm_per_rad_per_s: 0.06,
        velocity_integral_time_ns: 8_000_000,
        velocity_filter_time_ns: 250_000,
        max_velocity_inc_per_s: 50.0 * INCREMENTS_PER_REVOLUTION as f32,
        torque_limit_positive_nm: 3.9,
        torque_limit_negative_nm: 3.9,
        torque_mode_velocity_limit_positive_inc_per_s: 0.0,
        torque_mode_velocity_limit_negative_inc_per_s: 0.0,
        inertia_kg_m2: 0.0,
        coulomb_friction_nm: 0.0,
        viscous_friction_nm_per_rad_per_s: 0.0,
        derive_acceleration: false,
        compensate_velocity_lag: false,
    };

    /// Checks that every gain and limit is finite and not negative and that
    /// I25 is within 0 … 100 %.
    pub fn validate(&self) -> Result<(), CascadeError> {
        let values = [
            self.position_gain_per_s,
            self.velocity_gain_nm_per_rad_per_s,
            self.max_velocity_inc_per_s,
            self.torque_limit_positive_nm,
            self.torque_limit_negative_nm,
            self.torque_mode_velocity_limit_positive_inc_per_s,
            self.torque_mode_velocity_limit_negative_inc_per_s,
            self.inertia_kg_m2,
            self.coulomb_friction_nm,
            self.viscous_friction_nm_per_rad_per_s,
        ];
        if values.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(CascadeError::InvalidValue);
        }
        let w = self.velocity_feedforward_percent;
        if !(w.is_finite() && (0.0..=100.0).contains(&w)) {
            return Err(CascadeError::FeedforwardWeight);
        }
        Ok(())
    }
}

impl Default for CascadeConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Torque in N·m from a per-mille value of the rated torque (6072h max.
/// torque, 6071h target torque, 60B2h offset: 0.1 % of 6076h).
pub fn torque_from_per_mille(rated_torque_nm: f32, per_mille: i32) -> f32 {
    rated_torque_nm * per_mille as f32 * 0.001
}

/// One control cycle's inputs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CascadeInput {
    /// Entry point of the active mode.
    pub entry: ControlEntry,
    /// Position set-point in increments (position entry; e.g. interpolator or
    /// profile output).
    pub position_setpoint_inc: i32,
    /// Velocity in increments/s: the feedforward in the position entry
    /// (weighted by I25 here), the set-point in the velocity entry (60FFh,
    /// profile velocity, + 60B1h offset).
    pub velocity_inc_per_s: f32,
    /// Acceleration feedforward in increments/s² (J·a added to the torque in
    /// the position and velocity entries; 0 if unused).
    pub acceleration_feedforward_inc_per_s2: f32,
    /// Torque in N·m: the feedforward (60B2h offset) in the position and
    /// velocity entries, the set-point (6071h + 60B2h) in the torque entry.
    pub torque_nm: f32,
    /// Actual position in increments (6064h).
    pub actual_position_inc: i32,
    /// Actual velocity in increments/s if the encoder supplies it; `None`
    /// (or non-finite) → the differentiating filter computes it.
    pub actual_velocity_inc_per_s: Option<f32>,
}

/// One control cycle's outputs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CascadeOutput {
    /// Torque set-point for the current controller, N·m.
    pub torque_nm: f32,
    /// Velocity command in increments/s (input of the velocity controller,
    /// after the I10 clamp); 0 in the torque entry.
    pub velocity_command_inc_per_s: f32,
    /// Actual velocity used, increments/s (606Ch).
    pub actual_velocity_inc_per_s: f32,
    /// Following error set-point − actual position, increments (60F4h); 0
    /// outside the position entry.
    pub following_error_inc: i32,
    /// The velocity command was clamped at I10.
    pub velocity_limited: bool,
    /// The torque was clamped at a torque limit.
    pub torque_limited: bool,
    /// The speed limiter of the torque entry reduced the torque (C-039).
    pub speed_limited: bool,
    /// Statusword bit 11 "internal limit active": any of the three above.
    pub internal_limit: bool,
}

/// The control cascade of one axis (position P → velocity PI → torque limit).
#[derive(Debug, Clone)]
pub struct Cascade {
    config: CascadeConfig,
    /// Integral part of the velocity controller, N·m.
    integral_nm: f32,
    /// Last actual position for the differentiating filter.
    last_position: Option<i32>,
    /// Filtered actual velocity, increments/s.
    velocity_inc_per_s: f32,
    /// The last cycle's velocity feedforward, increments/s
    /// ([`CascadeConfig::derive_acceleration`]), and the cycles since the
    /// reset (the first feedforward after an enable carries the jump from
    /// the actual position to the set-point: not differentiated).
    last_feedforward: Option<f32>,
    feedforward_cycles: u8,
    /// How far the measured speed lags the set-point's by the given
    /// acceleration: τ·a through a first-order lag of τ (half a cycle plus
    /// the velocity filter's time constant), increments/s
    /// ([`CascadeConfig::compensate_velocity_lag`]).
    velocity_lag: f32,
    /// The given acceleration of the cycle before, increments/s².
    last_given: f32,
}

impl Cascade {
    /// A cascade with `config` (validated) at rest at `actual_position_inc`.
    pub fn new(config: CascadeConfig, actual_position_inc: i32) -> Result<Self, CascadeError> {
        config.validate()?;
        let mut c = Self {
            config,
            integral_nm: 0.0,
            last_position: None,
            velocity_inc_per_s: 0.0,
            last_feedforward: None,
            feedforward_cycles: 0,
            velocity_lag: 0.0,
            last_given: 0.0,
        };
        c.reset(actual_position_inc);
        Ok(c)
    }

    /// The configuration.
    pub const fn config(&self) -> &CascadeConfig {
        &self.config
    }

    /// Replaces the gains and limits (validated) without touching the state,
    /// e.g. a changed 6072h at run time. The integral part is kept within
    /// the new torque limits.
    pub fn set_config(&mut self, config: CascadeConfig) -> Result<(), CascadeError> {
        config.validate()?;
        self.config = config;
        self.integral_nm = clamp(
            self.integral_nm,
            -config.torque_limit_negative_nm,
            config.torque_limit_positive_nm,
        );
        Ok(())
    }

    /// Bumpless enable: clears the integral part and the velocity filter and
    /// takes `actual_position_inc` as the last position, so the first cycle
    /// after enabling (set-point = actual position) commands zero torque.
    pub fn reset(&mut self, actual_position_inc: i32) {
        self.integral_nm = 0.0;
        self.last_position = Some(actual_position_inc);
        self.velocity_inc_per_s = 0.0;
        self.last_feedforward = None;
        self.velocity_lag = 0.0;
        self.last_given = 0.0;
        self.feedforward_cycles = 0;
    }

    /// The velocity controller's integral part in N·m.
    pub const fn integral_nm(&self) -> f32 {
        self.integral_nm
    }

    /// The actual velocity of the differentiating filter (or the supplied
    /// one) after the last cycle, increments/s.
    pub const fn actual_velocity_inc_per_s(&self) -> f32 {
        self.velocity_inc_per_s
    }

    /// Runs one control cycle of `dt_ns` ns.
    pub fn cycle(&mut self, input: &CascadeInput, dt_ns: u32) -> CascadeOutput {
        let dt_s = dt_ns as f32 * 1e-9;
        let actual_velocity = self.actual_velocity(input, dt_ns, dt_s);
        // borrowed, not copied (the whole configuration, every cycle)
        let cfg = &self.config;

        let mut velocity_limited = false;
        let mut speed_limited = false;
        let mut following_error_inc = 0;
        let kp = cfg.velocity_gain_nm_per_rad_per_s;
        let lim_pos = cfg.torque_limit_positive_nm;
        let lim_neg = cfg.torque_limit_negative_nm;

        let (velocity_command, torque_unlimited) = match input.entry {
            ControlEntry::Position | ControlEntry::Velocity => {
                let v_in = finite_or_zero(input.velocity_inc_per_s);
                let given = finite_or_zero(input.acceleration_feedforward_inc_per_s2);
                let mut acceleration = given;
                let v_ref = v_in;
                if cfg.derive_acceleration {
                    let last = self.last_feedforward.replace(v_in);
                    self.feedforward_cycles = self.feedforward_cycles.saturating_add(1);
                    if acceleration == 0.0 && dt_s > 0.0 && self.feedforward_cycles > 2 {
                        if let Some(l) = last {
                            acceleration = (v_in - l) / dt_s;
                        }
                    }
                }
                let raw_command = if input.entry == ControlEntry::Position {
                    following_error_inc = input
                        .position_setpoint_inc
                        .wrapping_sub(input.actual_position_inc);
                    let ff = v_ref * cfg.velocity_feedforward_percent * 0.01;
                    // P-157: no correction inside the dead band (|0| ≤ 0 when off)
                    let corrected = if following_error_inc.unsigned_abs() <= cfg.position_dead_band_inc {
                        0
                    } else {
                        following_error_inc
                    };
                    cfg.position_gain_per_s * corrected as f32 + ff
                } else {
                    v_ref
                };
                let vmax = cfg.max_velocity_inc_per_s;
                let command = clamp(raw_command, -vmax, vmax);
                velocity_limited = command != raw_command;

                // the measured speed lags the shaft's by half a cycle (the
                // difference) and the filter's time constant τ: with the
                // generator's acceleration fed forward the controller
                // compares with the speed that lag predicts (else it would
                // fight J·a). The lag is τ·a through a first-order lag of τ
                // (the set-point's speed less its own lagged value): τ·a
                // while the acceleration holds, decaying as the measurement
                // catches up once it ends (taken away at once, it would push
                // the shaft past the set-point's speed). The acceleration
                // given leads the set-point's speed by a cycle (the drive's
                // own profiles, `drive_core` axis/shift.rs): the lag follows
                // the speed, so the last cycle's acceleration. A derived
                // acceleration (csp, ip) is a cycle late itself: only the
                // given one counts
                let predicted = if cfg.compensate_velocity_lag {
                    let lag_s = 0.5 * dt_s + cfg.velocity_filter_time_ns as f32 * 1e-9;
                    let alpha = if lag_s + dt_s > 0.0 {
                        dt_s / (lag_s + dt_s)
                    } else {
                        1.0
                    };
                    let last = core::mem::replace(&mut self.last_given, given);
                    self.velocity_lag += alpha * (last * lag_s - self.velocity_lag);
                    actual_velocity + self.velocity_lag
                } else {
                    actual_velocity
                };
                let error_rad_per_s = (command - predicted) * RAD_PER_INCREMENT;
                let proportional = kp * error_rad_per_s;
                let feedforward = finite_or_zero(input.torque_nm)
                    + cfg.inertia_kg_m2 * acceleration * RAD_PER_INCREMENT
                    + friction_feedforward(cfg, v_ref);
                let unsaturated = proportional + self.integral_nm + feedforward;

                // Anti-windup: conditional integration (no integration further
                // into a saturated output), integral part bounded by the limits.
                if cfg.velocity_integral_time_ns > 0 {
                    let ti_s = cfg.velocity_integral_time_ns as f32 * 1e-9;
                    let increment = proportional * dt_s / ti_s;
                    let winds_up = (unsaturated >= lim_pos && increment > 0.0)
                        || (unsaturated <= -lim_neg && increment < 0.0);
                    if !winds_up {
                        self.integral_nm = clamp(self.integral_nm + increment, -lim_neg, lim_pos);
                    }
                } else {
                    self.integral_nm = 0.0;
                }
                (command, proportional + self.integral_nm + feedforward)
            }
            ControlEntry::Torque => {
                let demand = finite_or_zero(input.torque_nm);
                // Speed limiter: the torque band a P velocity controller would
                // allow when aiming at +G472 (upper bound) or −G475 (lower).
                let upper = kp
                    * (cfg.torque_mode_velocity_limit_positive_inc_per_s - actual_velocity)
                    * RAD_PER_INCREMENT;
                let lower = kp
                    * (-cfg.torque_mode_velocity_limit_negative_inc_per_s - actual_velocity)
                    * RAD_PER_INCREMENT;
                let limited = if demand > upper {
                    upper
                } else if demand < lower {
                    lower
                } else {
                    demand
                };
                speed_limited = limited != demand;
                (0.0, limited)
            }
        };

        let torque = clamp(torque_unlimited, -lim_neg, lim_pos);
        let torque_limited = torque != torque_unlimited;
        if input.entry == ControlEntry::Torque {
            // Track the output so a later switch to the velocity entry starts
            // from the present torque.
            self.integral_nm = torque;
        }

        CascadeOutput {
            torque_nm: torque,
            velocity_command_inc_per_s: velocity_command,
            actual_velocity_inc_per_s: actual_velocity,
            following_error_inc,
            velocity_limited,
            torque_limited,
            speed_limited,
            internal_limit: velocity_limited || torque_limited || speed_limited,
        }
    }

    /// The actual velocity: supplied, or the low-pass-filtered difference
    /// quotient of the positions (wrap-around safe).
    fn actual_velocity(&mut self, input: &CascadeInput, dt_ns: u32, dt_s: f32) -> f32 {
        let last = self.last_position.replace(input.actual_position_inc);
        if let Some(v) = input.actual_velocity_inc_per_s.filter(|v| v.is_finite()) {
            self.velocity_inc_per_s = v;
            return v;
        }
        if dt_ns == 0 {
            return self.velocity_inc_per_s;
        }
        let raw = match last {
            Some(p) => input.actual_position_inc.wrapping_sub(p) as f32 / dt_s,
            None => 0.0,
        };
        let tau = self.config.velocity_filter_time_ns as f32;
        let alpha = dt_ns as f32 / (tau + dt_ns as f32);
        self.velocity_inc_per_s += alpha * (raw - self.velocity_inc_per_s);
        self.velocity_inc_per_s
    }
}

/// The friction feedforward of `cfg` at the reference velocity `v_ref`
/// (increments/s), N·m: `Fc·s + B·v_ref`, s = v_ref/band within ±1
/// ([`FRICTION_BAND_INC_PER_S`]).
pub fn friction_feedforward(cfg: &CascadeConfig, v_ref: f32) -> f32 {
    let s = clamp(v_ref / FRICTION_BAND_INC_PER_S, -1.0, 1.0);
    let t = cfg.coulomb_friction_nm * s + cfg.viscous_friction_nm_per_rad_per_s * v_ref * RAD_PER_INCREMENT;
    finite_or_zero(t)
}

fn finite_or_zero(v: f32) -> f32 {
    if v.is_finite() {
        v
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests;
