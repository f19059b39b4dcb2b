//! Small conversions of the axis: cascade gains per control cycle, the
//! velocity override, the switch sources, jerk and ramp rates from the
//! objects' units, saturating roundings, E48.

use super::*;

/// The control cycle the cascade gains of [`AxisParams::cascade`] are meant
/// for (the [`CascadeConfig::DEFAULT`] range is 62.5 … 250 µs).
pub const GAIN_REFERENCE_CYCLE_NS: u32 = 250_000;

/// The gains of `c` for a control cycle of `dt_ns`: above
/// [`GAIN_REFERENCE_CYCLE_NS`] the velocity gain Kp shrinks by r =
/// reference / cycle and the integral time Ti grows by 1/r, so the velocity
/// loop keeps its phase margin with the longer dead time; the position gain
/// Kv shrinks only by √r (the position loop is slower than the velocity loop
/// by more than √r still) to keep the stiffness against friction (the
/// default A150 is 1 ms: Kv 50 /s, Kp 0.015 N·m·s/rad, Ti 32 ms).
pub fn scaled_gains(c: &CascadeConfig, dt_ns: u32) -> CascadeConfig {
    if dt_ns <= GAIN_REFERENCE_CYCLE_NS {
        return *c;
    }
    let r = GAIN_REFERENCE_CYCLE_NS as f32 / dt_ns as f32;
    CascadeConfig {
        position_gain_per_s: c.position_gain_per_s * sqrt(r),
        velocity_gain_nm_per_rad_per_s: c.velocity_gain_nm_per_rad_per_s * r,
        velocity_integral_time_ns: (c.velocity_integral_time_ns as f32 / r) as u32,
        ..*c
    }
}

/// The A340 velocity override as a factor (C-030).
pub(super) fn override_factor(o: &Snapshot) -> f32 {
    f32::from(o.override_percent) * 0.01
}

/// The switch signals after their sources (C-104): I101/I102/I103 = 2 take
/// them from I210 bits 0/1/2 (1 = actuated), 0 turns the reference switch
/// off; the limit switches with source 0 stay as wired (their evaluation is
/// off unless [`AxisParams::limits`] switches it on).
pub(super) fn sourced(io: &AxisIo, o: &Snapshot) -> AxisIo {
    let bit = |n: u16| o.i210 & (1 << n) != 0;
    let [pos, neg, reference] = o.switch_source;
    // latched edges belong to the hardware inputs only
    let mut switch_edges = io.switch_edges;
    for slot in &mut switch_edges {
        let hardware = match slot.map(|e| e.switch) {
            Some(SwitchId::PositiveLimit) => pos != 2,
            Some(SwitchId::NegativeLimit) => neg != 2,
            Some(SwitchId::Reference) => reference == 1,
            None => true,
        };
        if !hardware {
            *slot = None;
        }
    }
    AxisIo {
        switch_edges,
        limit_positive: if pos == 2 { bit(0) } else { io.limit_positive },
        limit_negative: if neg == 2 { bit(1) } else { io.limit_negative },
        reference: match reference {
            0 => false,
            2 => bit(2),
            _ => io.reference,
        },
        ..*io
    }
}

/// 60A4h:01 → jerk (0 = no limit).
pub(super) fn jerk(v: u32) -> f32 {
    if v == 0 {
        f32::INFINITY
    } else {
        v as f32
    }
}

/// A vl ramp (delta speed rpm, delta time s) in inc/s²; a zero time is a
/// step (very steep ramp).
pub(super) fn ramp_rate((rpm, s): (u32, u16)) -> f32 {
    let v = rpm as f32 * RPM_TO_INC_PER_S;
    if s == 0 {
        v.max(1.0) * 1000.0
    } else {
        (v / f32::from(s)).max(1.0)
    }
}

/// Round half away from zero, saturating (NaN → 0).
/// `v` saturated to `i32` (positions as the objects hold them: in range
/// by construction, saturated rather than dropped otherwise).
pub(super) fn sat_i32(v: i64) -> i32 {
    i32::try_from(v).unwrap_or(if v < 0 { i32::MIN } else { i32::MAX })
}

pub(super) fn round_i32(x: f32) -> i32 {
    (if x >= 0.0 { x + 0.5 } else { x - 0.5 }) as i32
}

/// E48 device state (SC6 numbering, assumed from the dictionary note "2
/// ready to switch on, 4 enabled, 7 quick stop"): 0 not ready (self-test),
/// 1 switch on disabled, 2 ready to switch on, 3 switched on, 4 operation
/// enabled, 5 fault, 6 fault reaction active, 7 quick stop active.
pub const fn e48(state: State) -> u8 {
    match state {
        State::NotReadyToSwitchOn => 0,
        State::SwitchOnDisabled => 1,
        State::ReadyToSwitchOn => 2,
        State::SwitchedOn => 3,
        State::OperationEnabled => 4,
        State::Fault => 5,
        State::FaultReactionActive => 6,
        State::QuickStopActive => 7,
    }
}

/// Square root without `std` (Newton steps from a bit-level first guess);
/// `x` ≤ 0 or not finite gives 0. The crate's one (the actions and tuning use it too).
pub(crate) fn sqrt(x: f32) -> f32 {
    if !(x.is_finite() && x > 0.0) {
        return 0.0;
    }
    let mut r = f32::from_bits((x.to_bits() >> 1) + 0x1FC0_0000);
    for _ in 0..4 {
        r = 0.5 * (r + x / r);
    }
    r
}
