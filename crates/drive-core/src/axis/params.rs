//! The axis' fixed parameters ([`AxisParams`]): what the board or the
//! configuration gives it besides the object dictionary.

use super::*;

/// The axis' working settings, with their defaults. Those the dictionary
/// declares (issue 40: A44, I00, I04, jog I12/I13/I45/I18/I26, homing
/// I28/I29/I30/I43/I44/I53, I25/I425/I423, I87, I10, C40, the following
/// error reaction I470, the set-value monitoring I471; the gains and
/// G472/G475 go straight into the cascade, F00/F06 to the brake output) are
/// overwritten from it at every configuration change, and so are the
/// limit-switch evaluation flags (I101/I102 ≠ 0): set them by SDO/PNU, a
/// [`Axis::params_mut`] change of them lasts only until the next
/// configuration change. The motor data (rated torque and current, issue 34)
/// are the dictionary's alone ([`Axis::motor`]). The rest (the inertia, the
/// velocity filter, 606Eh's time, the software-limit reaction, C-050's
/// reference rule, the stop settle time) are not declared
/// (docs/conformance.md, "AxisParams after issue 40"): [`Axis::params_mut`]
/// changes them, effective in the next cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisParams {
    /// Cascade gains and limits. The torque limits are replaced by 6072h,
    /// the gains Kv, Kp, Ti by I20, C31, C32 (issue 40),
    /// the torque modes' speed limits by G472/G475 (0.1 % of
    /// `max_velocity_inc_per_s`, I10), the speed feedforward weight is
    /// applied by the interpolator (I25 below);
    /// the inertia (motor data) turns the generators' acceleration into
    /// torque feedforward.
    pub cascade: CascadeConfig,
    /// I25 speed feedforward of ip/csp, % (0 … 100).
    pub feedforward_percent: f32,
    /// I425 speed feedforward – interpolation (0, 1, 3, 4, 5).
    pub interpolation_i425: u8,
    /// I423 maximum extrapolation period (C-117).
    pub max_extrapolation_ns: Nanos,
    /// C40 velocity window, inc/s (standstill I199, pv window).
    pub velocity_window_inc_per_s: f32,
    /// 606Eh velocity window time.
    pub velocity_window_time_ns: Nanos,
    /// I87 time in the position window.
    pub position_window_time_ns: Nanos,
    /// I470 = 1: a following error (6065h/6066h) is a fault (event 54
    /// cause 1), not only statusword bit 13 (from the dictionary).
    pub following_error_fault: bool,
    /// Limit switches and axis type (I101/I102, I00, I04, software-limit
    /// reaction). The software limits come from 607Dh, the window from I22;
    /// the switch polarity is the board's (see [`AxisIo::limit_positive`]).
    pub limits: LimitConfig,
    /// C-050: absolute pp moves need a referenced axis.
    pub absolute_needs_reference: bool,
    /// I471, C-148 set-value monitoring (from the dictionary): a cyclic
    /// position set-point further from the previous one than twice 607Fh
    /// over the time between them trips event 78 cause 4 "excessive set
    /// value jump".
    pub set_value_monitoring: bool,
    /// Jog (I12, I13, I45, I18, I26): taken from the dictionary at every
    /// configuration change (issue 40); what is set here is overwritten.
    /// I12 jog velocity, inc/s.
    pub jog_velocity: f32,
    /// I13 jog acceleration, inc/s².
    pub jog_acceleration: f32,
    /// I45 jog deceleration, inc/s².
    pub jog_deceleration: f32,
    /// I18 jog jerk, inc/s³ (`f32::INFINITY` = none).
    pub jog_jerk: f32,
    /// I26 = 1: jog under position control (stops before a software limit).
    pub jog_position_control: bool,
    /// I44 referencing jerk, inc/s³.
    pub homing_jerk: f32,
    /// I43: after referencing, position on 607Ch.
    pub homing_move_to_home: bool,
    /// I53 index search offset, inc.
    pub homing_index_offset: u32,
    /// I28 torque limit while homing, 0.1 % of the rated torque (also the
    /// "torque at the limit" threshold of the torque methods; 6072h caps it).
    pub homing_torque_limit_per_mille: u16,
    /// I29 time at the torque limit for the torque methods.
    pub homing_torque_hold_ns: Nanos,
    /// I30 = 2: the limit switch serves as the reference switch.
    pub homing_limit_as_reference: bool,
    /// A44 = 1: losing A60 in Operation enabled gives a quick stop.
    pub quick_stop_on_enable_loss: bool,
    /// How long the axis must stand still (I199) after a stop ramp before
    /// the stop counts as finished (T12, T14, T5/T8 with ramp).
    pub stop_settle_ns: Nanos,
}

impl Default for AxisParams {
    /// The cascade defaults with an inertia of 1e-4
    /// kg·m² (the simulated servo), I25 = 100 %, I425 = 0,
    /// I423 = 10 ms, C40 = 0.1 rev/s, following error as
    /// bit 13 only, no limit switches, jog 1 rev/s with 10 rev/s², I26 = 1,
    /// no jerk limits, stops settle 10 ms.
    fn default() -> Self {
        Self {
            cascade: CascadeConfig {
                inertia_kg_m2: 1.0e-4,
                ..CascadeConfig::DEFAULT
            },
            feedforward_percent: 100.0,
            interpolation_i425: 0,
            max_extrapolation_ns: Nanos::from_ms(10),
            velocity_window_inc_per_s: 0.1 * REV,
            velocity_window_time_ns: Nanos::ZERO,
            position_window_time_ns: Nanos::ZERO,
            following_error_fault: false,
            limits: LimitConfig::default(),
            absolute_needs_reference: true,
            set_value_monitoring: true,
            jog_velocity: REV,
            jog_acceleration: 10.0 * REV,
            jog_deceleration: 10.0 * REV,
            jog_jerk: f32::INFINITY,
            jog_position_control: true,
            homing_jerk: f32::INFINITY,
            homing_move_to_home: false,
            homing_index_offset: 0,
            homing_torque_limit_per_mille: 1000,
            homing_torque_hold_ns: Nanos::from_ms(100),
            homing_limit_as_reference: false,
            quick_stop_on_enable_loss: false,
            stop_settle_ns: Nanos::from_ms(10),
        }
    }
}
