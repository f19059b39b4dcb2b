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
}

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
        let cfg = self.config;
        let dt_s = dt_ns as f32 * 1e-9;
        let actual_velocity = self.actual_velocity(input, dt_ns, dt_s);

        let mut velocity_limited = false;
        let mut speed_limited = false;
        let mut following_error_inc = 0;
        let kp = cfg.velocity_gain_nm_per_rad_per_s;
        let lim_pos = cfg.torque_limit_positive_nm;
        let lim_neg = cfg.torque_limit_negative_nm;

        let (velocity_command, torque_unlimited) = match input.entry {
            ControlEntry::Position | ControlEntry::Velocity => {
                let raw_command = if input.entry == ControlEntry::Position {
                    following_error_inc = input
                        .position_setpoint_inc
                        .wrapping_sub(input.actual_position_inc);
                    let ff =
                        finite_or_zero(input.velocity_inc_per_s) * cfg.velocity_feedforward_percent * 0.01;
                    // P-157: no correction inside the dead band (|0| ≤ 0 when off)
                    let corrected = if following_error_inc.unsigned_abs() <= cfg.position_dead_band_inc {
                        0
                    } else {
                        following_error_inc
                    };
                    cfg.position_gain_per_s * corrected as f32 + ff
                } else {
                    finite_or_zero(input.velocity_inc_per_s)
                };
                let vmax = cfg.max_velocity_inc_per_s;
                let command = clamp(raw_command, -vmax, vmax);
                velocity_limited = command != raw_command;

                let error_rad_per_s = (command - actual_velocity) * RAD_PER_INCREMENT;
                let proportional = kp * error_rad_per_s;
                let feedforward = finite_or_zero(input.torque_nm)
                    + cfg.inertia_kg_m2
                        * finite_or_zero(input.acceleration_feedforward_inc_per_s2)
                        * RAD_PER_INCREMENT;
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

fn finite_or_zero(v: f32) -> f32 {
    if v.is_finite() {
        v
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const REV: f32 = INCREMENTS_PER_REVOLUTION as f32;
    const DT_NS: u32 = 125_000;

    /// Rigid body J·dω/dt = T − b·ω, integrated with 10 sub-steps per cycle.
    struct Plant {
        j: f64,
        b: f64,
        /// Position, rad.
        theta: f64,
        /// Velocity, rad/s.
        omega: f64,
    }

    impl Plant {
        fn new() -> Self {
            Plant {
                j: 1e-4,
                b: 1e-4,
                theta: 0.0,
                omega: 0.0,
            }
        }
        fn step(&mut self, torque: f32, dt_ns: u32) {
            let h = f64::from(dt_ns) * 1e-9 / 10.0;
            for _ in 0..10 {
                let acc = (f64::from(torque) - self.b * self.omega) / self.j;
                self.omega += acc * h;
                self.theta += self.omega * h;
            }
        }
        fn position_inc(&self) -> i32 {
            let inc = self.theta / f64::from(RAD_PER_INCREMENT);
            (inc.round() as i64) as i32
        }
        fn velocity_inc_per_s(&self) -> f32 {
            (self.omega / f64::from(RAD_PER_INCREMENT)) as f32
        }
    }

    fn input(entry: ControlEntry, plant: &Plant) -> CascadeInput {
        CascadeInput {
            entry,
            position_setpoint_inc: 0,
            velocity_inc_per_s: 0.0,
            acceleration_feedforward_inc_per_s2: 0.0,
            torque_nm: 0.0,
            actual_position_inc: plant.position_inc(),
            actual_velocity_inc_per_s: None,
        }
    }

    #[test]
    fn modes_enter_at_the_spec_entry_points() {
        assert_eq!(ControlEntry::for_mode(8), Some(ControlEntry::Position));
        assert_eq!(ControlEntry::for_mode(1), Some(ControlEntry::Position));
        assert_eq!(ControlEntry::for_mode(7), Some(ControlEntry::Position));
        assert_eq!(ControlEntry::for_mode(6), Some(ControlEntry::Position));
        assert_eq!(ControlEntry::for_mode(9), Some(ControlEntry::Velocity));
        assert_eq!(ControlEntry::for_mode(3), Some(ControlEntry::Velocity));
        assert_eq!(ControlEntry::for_mode(10), Some(ControlEntry::Torque));
        assert_eq!(ControlEntry::for_mode(4), Some(ControlEntry::Torque));
        assert_eq!(ControlEntry::for_mode(0), None);
        assert_eq!(ControlEntry::for_mode(5), None);
    }

    #[test]
    fn config_validation_refuses_bad_values() {
        assert!(CascadeConfig::DEFAULT.validate().is_ok());
        let mut c = CascadeConfig::DEFAULT;
        c.torque_limit_negative_nm = -1.0;
        assert_eq!(c.validate(), Err(CascadeError::InvalidValue));
        let mut c = CascadeConfig::DEFAULT;
        c.velocity_gain_nm_per_rad_per_s = f32::NAN;
        assert_eq!(c.validate(), Err(CascadeError::InvalidValue));
        let mut c = CascadeConfig::DEFAULT;
        c.velocity_feedforward_percent = 120.0;
        assert_eq!(c.validate(), Err(CascadeError::FeedforwardWeight));
        assert!(Cascade::new(c, 0).is_err());
    }

    #[test]
    fn c035_position_step_settles_without_large_overshoot() {
        let mut plant = Plant::new();
        let mut cascade = Cascade::new(CascadeConfig::DEFAULT, plant.position_inc()).unwrap();
        let step = 10_000; // ≈ 3.4°
        let mut max_pos = i32::MIN;
        let mut settled_at = None;
        for k in 0..2400u32 {
            // 300 ms
            let mut inp = input(ControlEntry::Position, &plant);
            inp.position_setpoint_inc = step;
            let out = cascade.cycle(&inp, DT_NS);
            assert!(out.torque_nm.is_finite());
            plant.step(out.torque_nm, DT_NS);
            let p = plant.position_inc();
            max_pos = max_pos.max(p);
            if (p - step).abs() <= step / 100 {
                settled_at.get_or_insert(k);
            } else {
                settled_at = None;
            }
        }
        let overshoot = max_pos - step;
        assert!(overshoot <= step / 20, "overshoot {overshoot} inc above 5 %");
        let settled_at = settled_at.expect("never settled within 1 %");
        assert!(
            settled_at < 800,
            "settled only after {settled_at} cycles (100 ms bound)"
        );
        assert!((plant.position_inc() - step).abs() <= 5, "residual error");
    }

    #[test]
    fn c035_bumpless_enable_gives_zero_torque_on_the_first_cycle() {
        let mut cascade = Cascade::new(CascadeConfig::DEFAULT, 0).unwrap();
        // Axis parked elsewhere: reset to its position, set-point = actual.
        cascade.reset(123_456);
        let out = cascade.cycle(
            &CascadeInput {
                entry: ControlEntry::Position,
                position_setpoint_inc: 123_456,
                velocity_inc_per_s: 0.0,
                acceleration_feedforward_inc_per_s2: 0.0,
                torque_nm: 0.0,
                actual_position_inc: 123_456,
                actual_velocity_inc_per_s: None,
            },
            DT_NS,
        );
        assert_eq!(out.torque_nm, 0.0);
        assert_eq!(out.following_error_inc, 0);
        assert!(!out.internal_limit);
    }

    /// P-157: inside the dead band the position controller's output is only
    /// the feedforward; one increment beyond it Kv·error comes back.
    #[test]
    fn p157_no_position_correction_inside_the_dead_band() {
        let cfg = CascadeConfig {
            position_dead_band_inc: 100,
            ..CascadeConfig::DEFAULT
        };
        let command = |error: i32, ff: f32| {
            let mut cascade = Cascade::new(cfg, 0).unwrap();
            let out = cascade.cycle(
                &CascadeInput {
                    entry: ControlEntry::Position,
                    position_setpoint_inc: error,
                    velocity_inc_per_s: ff,
                    acceleration_feedforward_inc_per_s2: 0.0,
                    torque_nm: 0.0,
                    actual_position_inc: 0,
                    actual_velocity_inc_per_s: Some(0.0),
                },
                DT_NS,
            );
            assert_eq!(out.following_error_inc, error, "reported unchanged");
            out.velocity_command_inc_per_s
        };
        assert_eq!(command(100, 0.0), 0.0);
        assert_eq!(command(-100, 0.0), 0.0);
        assert_eq!(command(60, 5000.0), 5000.0, "feedforward passes");
        assert_eq!(command(101, 0.0), 100.0 * 101.0);
        assert_eq!(command(-101, 0.0), -100.0 * 101.0);
        // off (the default): any error is corrected
        let mut cascade = Cascade::new(CascadeConfig::DEFAULT, 0).unwrap();
        let out = cascade.cycle(
            &CascadeInput {
                entry: ControlEntry::Position,
                position_setpoint_inc: 1,
                velocity_inc_per_s: 0.0,
                acceleration_feedforward_inc_per_s2: 0.0,
                torque_nm: 0.0,
                actual_position_inc: 0,
                actual_velocity_inc_per_s: Some(0.0),
            },
            DT_NS,
        );
        assert_eq!(out.velocity_command_inc_per_s, 100.0);
    }

    #[test]
    fn c035_following_error_wraps_around_i32() {
        let mut cascade = Cascade::new(CascadeConfig::DEFAULT, i32::MAX - 10).unwrap();
        let out = cascade.cycle(
            &CascadeInput {
                entry: ControlEntry::Position,
                position_setpoint_inc: i32::MIN + 9, // 20 increments ahead
                velocity_inc_per_s: 0.0,
                acceleration_feedforward_inc_per_s2: 0.0,
                torque_nm: 0.0,
                actual_position_inc: i32::MAX - 10,
                actual_velocity_inc_per_s: Some(0.0),
            },
            DT_NS,
        );
        assert_eq!(out.following_error_inc, 20);
        assert!(out.torque_nm > 0.0);
    }

    #[test]
    fn c037_velocity_follows_a_ramp_with_bounded_error() {
        let mut plant = Plant::new();
        let mut cascade = Cascade::new(CascadeConfig::DEFAULT, 0).unwrap();
        let acc = 100.0 * REV; // 100 rev/s²
        let mut worst = 0.0f32;
        for k in 0..3200u32 {
            // ramp to 20 rev/s in 200 ms, then hold for 200 ms
            let t = (k + 1) as f32 * DT_NS as f32 * 1e-9;
            let v_set = (acc * t).min(20.0 * REV);
            let mut inp = input(ControlEntry::Velocity, &plant);
            inp.velocity_inc_per_s = v_set;
            let out = cascade.cycle(&inp, DT_NS);
            plant.step(out.torque_nm, DT_NS);
            assert!(!out.torque_limited, "ramp needs far less than the torque limit");
            if k > 160 {
                worst = worst.max((v_set - plant.velocity_inc_per_s()).abs());
            }
        }
        assert!(worst < 0.2 * REV, "velocity error {} rev/s", worst / REV);
        let end = (20.0 * REV - plant.velocity_inc_per_s()).abs();
        assert!(end < 0.01 * REV, "final velocity error {} rev/s", end / REV);
    }

    #[test]
    fn c035_velocity_feedforward_weight_i25_reduces_lag() {
        // C-118/C-120: with I25 = 100 % a constant-velocity track has a
        // smaller following error than with I25 = 0 %.
        let lag = |percent: f32| {
            let mut plant = Plant::new();
            let mut cfg = CascadeConfig::DEFAULT;
            cfg.velocity_feedforward_percent = percent;
            let mut cascade = Cascade::new(cfg, 0).unwrap();
            let v = 5.0 * REV;
            let mut last = 0;
            for k in 0..1600u32 {
                let t = (k + 1) as f64 * f64::from(DT_NS) * 1e-9;
                let mut inp = input(ControlEntry::Position, &plant);
                inp.position_setpoint_inc = (f64::from(v) * t).round() as i32;
                inp.velocity_inc_per_s = v;
                let out = cascade.cycle(&inp, DT_NS);
                plant.step(out.torque_nm, DT_NS);
                last = out.following_error_inc;
            }
            last.abs()
        };
        let with = lag(100.0);
        let without = lag(0.0);
        assert!(with * 10 < without, "I25 100 %: {with} inc, 0 %: {without} inc");
    }

    #[test]
    fn c039_torque_clamps_at_the_limits_and_reports_internal_limit() {
        let mut cfg = CascadeConfig::DEFAULT;
        cfg.torque_limit_positive_nm = 1.0;
        cfg.torque_limit_negative_nm = 0.5;
        let mut plant = Plant::new();
        let mut cascade = Cascade::new(cfg, 0).unwrap();
        // A step of 1/20 revolution forward, then back: the velocity command
        // (Kv·e ≈ 5 rev/s) asks for more torque than either limit allows.
        let step = INCREMENTS_PER_REVOLUTION as i32 / 20;
        for (target, limit) in [(step, 1.0f32), (0, -0.5f32)] {
            let start = plant.position_inc();
            let mut saw_limit = false;
            let mut overshoot = 0;
            for _ in 0..2400 {
                let mut inp = input(ControlEntry::Position, &plant);
                inp.position_setpoint_inc = target;
                let out = cascade.cycle(&inp, DT_NS);
                assert!(
                    out.torque_nm <= 1.0 && out.torque_nm >= -0.5,
                    "torque {}",
                    out.torque_nm
                );
                assert_eq!(out.internal_limit, out.torque_limited || out.velocity_limited);
                saw_limit |= out.torque_limited && out.internal_limit && out.torque_nm == limit;
                plant.step(out.torque_nm, DT_NS);
                let beyond = if target > start {
                    plant.position_inc() - target
                } else {
                    target - plant.position_inc()
                };
                overshoot = overshoot.max(beyond);
            }
            assert!(saw_limit, "the torque never clamped at {limit} N·m");
            // Anti-windup: the saturated start does not wind the integral up
            // into a large overshoot.
            assert!(overshoot < step / 10, "overshoot {overshoot} inc");
            assert!((plant.position_inc() - target).abs() < 20);
            assert!(cascade.integral_nm().abs() < 0.05);
        }
    }

    #[test]
    fn c039_anti_windup_limits_overshoot_after_long_saturation() {
        // csv step to 20 rev/s with only 0.2 N·m: ≈ 60 ms at the torque
        // limit. Without anti-windup the integral would grow to tens of N·m
        // and the velocity would overshoot by several rev/s.
        let mut cfg = CascadeConfig::DEFAULT;
        cfg.torque_limit_positive_nm = 0.2;
        cfg.torque_limit_negative_nm = 0.2;
        let mut plant = Plant::new();
        let mut cascade = Cascade::new(cfg, 0).unwrap();
        let v_set = 20.0 * REV;
        let mut limited_cycles = 0;
        let mut peak = 0.0f32;
        for _ in 0..4000 {
            let mut inp = input(ControlEntry::Velocity, &plant);
            inp.velocity_inc_per_s = v_set;
            let out = cascade.cycle(&inp, DT_NS);
            if out.torque_limited {
                limited_cycles += 1;
                assert!(out.internal_limit);
            }
            assert!(cascade.integral_nm().abs() <= 0.2);
            plant.step(out.torque_nm, DT_NS);
            peak = peak.max(plant.velocity_inc_per_s());
        }
        assert!(limited_cycles > 400, "saturated for {limited_cycles} cycles");
        assert!(peak < 21.0 * REV, "peak {} rev/s", peak / REV);
        assert!((plant.velocity_inc_per_s() - v_set).abs() < 0.05 * REV);
    }

    #[test]
    fn c039_cst_with_zero_velocity_limit_does_not_move() {
        let mut plant = Plant::new();
        let mut cascade = Cascade::new(CascadeConfig::DEFAULT, 0).unwrap();
        let mut limited = false;
        for _ in 0..4000 {
            let mut inp = input(ControlEntry::Torque, &plant);
            inp.torque_nm = 0.5;
            let out = cascade.cycle(&inp, DT_NS);
            limited |= out.speed_limited && out.internal_limit;
            plant.step(out.torque_nm, DT_NS);
        }
        assert!(limited);
        // Less than 1/100 revolution in 0.5 s with 0.5 N·m commanded (free
        // run would be ≈ 300 revolutions).
        assert!(plant.position_inc().abs() < INCREMENTS_PER_REVOLUTION as i32 / 100);
        assert!(plant.velocity_inc_per_s().abs() < 0.01 * REV);
    }

    #[test]
    fn c039_cst_speed_limiter_caps_velocity() {
        let mut cfg = CascadeConfig::DEFAULT;
        cfg.torque_mode_velocity_limit_positive_inc_per_s = 5.0 * REV;
        cfg.torque_mode_velocity_limit_negative_inc_per_s = 2.0 * REV;
        let mut plant = Plant::new();
        let mut cascade = Cascade::new(cfg, 0).unwrap();
        let mut max_v = 0.0f32;
        let mut out = None;
        for _ in 0..4000 {
            let mut inp = input(ControlEntry::Torque, &plant);
            inp.torque_nm = 0.5;
            let o = cascade.cycle(&inp, DT_NS);
            plant.step(o.torque_nm, DT_NS);
            max_v = max_v.max(plant.velocity_inc_per_s());
            out = Some(o);
        }
        let v = plant.velocity_inc_per_s();
        assert!(max_v < 5.1 * REV, "peak {} rev/s", max_v / REV);
        assert!(v > 4.5 * REV, "speed {} rev/s", v / REV);
        assert!(out.unwrap().speed_limited && out.unwrap().internal_limit);
        // Negative direction: capped at the (different) negative limit.
        for _ in 0..8000 {
            let mut inp = input(ControlEntry::Torque, &plant);
            inp.torque_nm = -0.5;
            let o = cascade.cycle(&inp, DT_NS);
            plant.step(o.torque_nm, DT_NS);
        }
        let v = plant.velocity_inc_per_s();
        assert!(v < -1.8 * REV && v > -2.05 * REV, "speed {} rev/s", v / REV);
    }

    #[test]
    fn c038_cst_below_the_speed_limit_passes_the_torque_through() {
        let mut cfg = CascadeConfig::DEFAULT;
        cfg.torque_mode_velocity_limit_positive_inc_per_s = 50.0 * REV;
        cfg.torque_mode_velocity_limit_negative_inc_per_s = 50.0 * REV;
        cfg.torque_limit_positive_nm = 1.0;
        let mut cascade = Cascade::new(cfg, 0).unwrap();
        let mut inp = CascadeInput {
            entry: ControlEntry::Torque,
            position_setpoint_inc: 0,
            velocity_inc_per_s: 0.0,
            acceleration_feedforward_inc_per_s2: 0.0,
            torque_nm: 0.3,
            actual_position_inc: 0,
            actual_velocity_inc_per_s: Some(0.0),
        };
        let out = cascade.cycle(&inp, DT_NS);
        assert_eq!(out.torque_nm, 0.3);
        assert!(!out.internal_limit);
        inp.torque_nm = 2.0;
        let out = cascade.cycle(&inp, DT_NS);
        assert_eq!(out.torque_nm, 1.0);
        assert!(out.torque_limited && out.internal_limit);
    }

    #[test]
    fn differentiating_filter_estimates_velocity() {
        let mut cascade = Cascade::new(CascadeConfig::DEFAULT, 0).unwrap();
        let v = 10.0 * REV;
        let mut est = 0.0;
        for k in 1..=200u32 {
            let p = (f64::from(v) * f64::from(k) * 125e-6).round() as i64 as i32;
            let inp = CascadeInput {
                entry: ControlEntry::Velocity,
                position_setpoint_inc: 0,
                velocity_inc_per_s: v,
                acceleration_feedforward_inc_per_s2: 0.0,
                torque_nm: 0.0,
                actual_position_inc: p,
                actual_velocity_inc_per_s: None,
            };
            est = cascade.cycle(&inp, DT_NS).actual_velocity_inc_per_s;
        }
        assert!((est - v).abs() < 0.001 * v, "estimate {est}");
    }
}
