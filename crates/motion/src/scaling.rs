//! Axis scaling (spec §7; C-108 – C-111).
//!
//! Increments (2^20 per motor revolution) ↔ user units through the gear
//! ratio 6091h (motor : shaft revolutions), the feed constant 6092h (feed per
//! shaft revolutions) and the position polarity 607Eh bit 7:
//!
//! user = ± increments · shaft_revs(6091h:02) · feed(6092h:01)
//!        / (2^20 · motor_revs(6091h:01) · shaft_revs(6092h:02))
//!
//! Conversions are exact integer fractions (`i128`) rounded to the nearest
//! unit. To keep many relative moves free of drift (C-109), accumulate
//! targets in user units and convert the absolute target, never the steps.
//! The feed is taken in the smallest user unit, i.e. with the decimals I06
//! already applied.

use crate::INCREMENTS_PER_REVOLUTION;

/// Why a scaling or modulo setting or conversion is refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScalingError {
    /// A gear or feed factor of 0, or a modulo length ≤ 0.
    Zero,
    /// The result does not fit in `i64`.
    Overflow,
}

/// Position scaling of one axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxisScaling {
    /// 6091h:01 motor revolutions (`A584[0]`).
    gear_motor_revs: u32,
    /// 6091h:02 shaft revolutions (`A584[1]`).
    gear_shaft_revs: u32,
    /// 6092h:01 feed, user units per `feed_shaft_revs` (`A585[0]`).
    feed: u32,
    /// 6092h:02 shaft revolutions of the feed (`A585[1]`).
    feed_shaft_revs: u32,
    /// 607Eh bit 7: position polarity inverted.
    inverted: bool,
    /// User units are increments (computed once: the conversions then skip
    /// the 128-bit and double-precision arithmetic).
    identity: bool,
}

/// 607Eh bit 7 (position polarity) is the only polarity bit with a function
/// (C-110): `true` = inverted.
pub const fn polarity_inverted(polarity_607e: u8) -> bool {
    polarity_607e & 0x80 != 0
}

/// Rounds num/den to the nearest integer, half away from zero (den > 0).
fn div_round(num: i128, den: i128) -> i128 {
    // a zero denominator (no scaling configured) gives 0, not a panic
    let half = den / 2;
    if num >= 0 {
        (num + half).checked_div(den).unwrap_or(0)
    } else {
        -(-num + half).checked_div(den).unwrap_or(0)
    }
}

impl AxisScaling {
    /// Incremental CiA 402 defaults (C-108): gear 1:1, feed 2^20 per
    /// revolution, polarity normal: user units are increments.
    pub const INCREMENTAL: AxisScaling = AxisScaling {
        gear_motor_revs: 1,
        gear_shaft_revs: 1,
        feed: INCREMENTS_PER_REVOLUTION,
        feed_shaft_revs: 1,
        inverted: false,
        identity: true,
    };

    /// Scaling from 6091h:01/02 (motor, shaft revolutions), 6092h:01/02
    /// (feed, shaft revolutions) and 607Eh; every factor must be > 0.
    pub fn new(
        gear_motor_revs: u32,
        gear_shaft_revs: u32,
        feed: u32,
        feed_shaft_revs: u32,
        polarity_607e: u8,
    ) -> Result<Self, ScalingError> {
        if gear_motor_revs == 0 || gear_shaft_revs == 0 || feed == 0 || feed_shaft_revs == 0 {
            return Err(ScalingError::Zero);
        }
        let mut s = Self {
            gear_motor_revs,
            gear_shaft_revs,
            feed,
            feed_shaft_revs,
            inverted: polarity_inverted(polarity_607e),
            identity: false,
        };
        let (num, den) = s.ratio();
        s.identity = !s.inverted && num == den;
        Ok(s)
    }

    /// Polarity inverted (607Eh bit 7).
    pub const fn is_inverted(&self) -> bool {
        self.inverted
    }

    /// User units per increment as num/den (both > 0).
    fn ratio(&self) -> (i128, i128) {
        let num = i128::from(self.gear_shaft_revs) * i128::from(self.feed);
        let den = i128::from(INCREMENTS_PER_REVOLUTION)
            * i128::from(self.gear_motor_revs)
            * i128::from(self.feed_shaft_revs);
        (num, den)
    }

    fn sign(&self) -> i128 {
        if self.inverted {
            -1
        } else {
            1
        }
    }

    /// Whether user units equal increments (num = den, polarity normal): the
    /// conversions are then the identity, without the 128-bit division
    /// (a few hundred instructions on a Cortex-M each).
    #[inline]
    fn is_identity(&self) -> bool {
        self.identity
    }

    /// Increments → user units (rounded to the nearest unit).
    ///
    /// Inline for the identity (the control cycle converts its actual
    /// values every cycle); the fraction is out of line.
    #[inline]
    pub fn to_user(&self, increments: i64) -> Result<i64, ScalingError> {
        if self.is_identity() {
            return Ok(increments);
        }
        self.scaled_user(increments)
    }

    #[inline(never)]
    fn scaled_user(&self, increments: i64) -> Result<i64, ScalingError> {
        let (num, den) = self.ratio();
        let u = div_round(self.sign() * i128::from(increments) * num, den);
        i64::try_from(u).map_err(|_| ScalingError::Overflow)
    }

    /// User units → increments (rounded to the nearest increment); inline
    /// for the identity like [`to_user`](Self::to_user).
    #[inline]
    pub fn to_increments(&self, user: i64) -> Result<i64, ScalingError> {
        if self.is_identity() {
            return Ok(user);
        }
        self.scaled_increments(user)
    }

    #[inline(never)]
    fn scaled_increments(&self, user: i64) -> Result<i64, ScalingError> {
        let (num, den) = self.ratio();
        let inc = div_round(self.sign() * i128::from(user) * den, num);
        i64::try_from(inc).map_err(|_| ScalingError::Overflow)
    }

    /// User units per increment (for velocities, accelerations, jerk).
    pub fn user_per_increment(&self) -> f64 {
        let (num, den) = self.ratio();
        self.sign() as f64 * num as f64 / den as f64
    }

    /// Velocity (or acceleration, jerk) in increments/s (/s², /s³) → user
    /// units/s (/s², /s³).
    #[inline]
    pub fn velocity_to_user(&self, increments_per_s: f32) -> f32 {
        if self.is_identity() {
            return increments_per_s;
        }
        (f64::from(increments_per_s) * self.user_per_increment()) as f32
    }

    /// Velocity (or acceleration, jerk) in user units/s (/s², /s³) →
    /// increments/s (/s², /s³).
    pub fn velocity_to_increments(&self, user_per_s: f32) -> f32 {
        if self.is_identity() {
            return user_per_s;
        }
        (f64::from(user_per_s) / self.user_per_increment()) as f32
    }
}

/// Direction of a move on an endless axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModuloDirection {
    /// The shorter way (positive on a tie).
    Shortest,
    /// Always positive (0 … length − 1).
    Positive,
    /// Always negative (−(length − 1) … 0).
    Negative,
}

/// An endless (modulo) axis (I00 = 1, C-111): positions wrap at the
/// revolution length 607Bh:02 (`A568[1]`); 607Bh:01 has no function. Works in
/// any one unit (user units or increments).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ModuloAxis {
    /// Revolution length, > 0.
    length: i64,
}

impl ModuloAxis {
    /// An endless axis with revolution length `length` (607Bh:02, > 0).
    pub fn new(length: i64) -> Result<Self, ScalingError> {
        if length <= 0 {
            return Err(ScalingError::Zero);
        }
        Ok(Self { length })
    }

    /// Revolution length.
    pub const fn length(&self) -> i64 {
        self.length
    }

    /// `position` wrapped into 0 … length − 1.
    pub const fn wrap(&self, position: i64) -> i64 {
        match position.checked_rem_euclid(self.length) {
            Some(p) => p,
            None => position,
        }
    }

    /// Distance to travel from `from` to the modulo position `to` (both taken
    /// modulo the length) in the given direction.
    pub fn distance(&self, from: i64, to: i64, direction: ModuloDirection) -> i64 {
        let d = (i128::from(to) - i128::from(from))
            .checked_rem_euclid(i128::from(self.length))
            .unwrap_or(0);
        // 0 ≤ d < length ≤ i64::MAX.
        let d = d as i64;
        match direction {
            ModuloDirection::Positive => d,
            ModuloDirection::Negative => {
                if d == 0 {
                    0
                } else {
                    d - self.length
                }
            }
            ModuloDirection::Shortest => {
                if d > self.length / 2 {
                    d - self.length
                } else {
                    d
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn c108_incremental_defaults_are_identity() {
        let s = AxisScaling::INCREMENTAL;
        for x in [0i64, 1, -1, 1 << 20, i64::from(i32::MAX), i64::from(i32::MIN)] {
            assert_eq!(s.to_user(x), Ok(x));
            assert_eq!(s.to_increments(x), Ok(x));
        }
        assert_eq!(s.velocity_to_user(1000.0), 1000.0);
        assert_eq!(
            AxisScaling::new(1, 1, 1 << 20, 1, 0),
            Ok(AxisScaling::INCREMENTAL)
        );
    }

    #[test]
    fn c109_gear_and_feed_scale_positions() {
        // Gear 3:1 (motor:shaft), 360000 units (0.001°) per shaft revolution.
        let s = AxisScaling::new(3, 1, 360_000, 1, 0).unwrap();
        // One shaft revolution = 3 motor revolutions = 3·2^20 increments.
        assert_eq!(s.to_user(3 << 20), Ok(360_000));
        assert_eq!(s.to_increments(360_000), Ok(3 << 20));
        assert_eq!(s.to_increments(-90_000), Ok(-(3 << 18)));
        // 1 unit = 3·2^20 / 360000 = 8.738 increments → 9.
        assert_eq!(s.to_increments(1), Ok(9));
        assert!((s.velocity_to_increments(360_000.0) - 3.0 * 1_048_576.0).abs() < 1.0);
    }

    #[test]
    fn c109_no_cumulative_drift_over_relative_moves() {
        let s = AxisScaling::new(3, 1, 360_000, 1, 0).unwrap();
        // 100 000 additive moves of 1 unit, accumulated in user units and
        // converted absolute: the increments match the exact value.
        let mut user = 0i64;
        for _ in 0..100_000 {
            user += 1;
        }
        let exact = (user as i128 * (3 << 20) as i128 * 2 + 360_000) / (2 * 360_000);
        assert_eq!(s.to_increments(user), Ok(exact as i64));
        // Round trip: increments are finer than units, so units survive.
        for u in [-1_000_001i64, -7, 0, 1, 2, 359_999, 123_456_789] {
            assert_eq!(s.to_user(s.to_increments(u).unwrap()), Ok(u));
        }
    }

    #[test]
    fn c110_only_bit7_inverts_polarity() {
        assert!(polarity_inverted(0x80));
        assert!(polarity_inverted(0xFF));
        assert!(!polarity_inverted(0x7F));
        assert!(!polarity_inverted(0x40));
        let s = AxisScaling::new(1, 1, 1 << 20, 1, 0x80).unwrap();
        assert_eq!(s.to_user(1000), Ok(-1000));
        assert_eq!(s.to_increments(-5), Ok(5));
        assert_eq!(s.velocity_to_user(10.0), -10.0);
        let s = AxisScaling::new(1, 1, 1 << 20, 1, 0x40).unwrap();
        assert_eq!(s.to_user(1000), Ok(1000));
    }

    #[test]
    fn c109_zero_factors_refused_and_overflow_reported() {
        assert_eq!(AxisScaling::new(0, 1, 1, 1, 0), Err(ScalingError::Zero));
        assert_eq!(AxisScaling::new(1, 0, 1, 1, 0), Err(ScalingError::Zero));
        assert_eq!(AxisScaling::new(1, 1, 0, 1, 0), Err(ScalingError::Zero));
        assert_eq!(AxisScaling::new(1, 1, 1, 0, 0), Err(ScalingError::Zero));
        // 1 unit per 2^32 motor revolutions: i64::MAX units overflow.
        let s = AxisScaling::new(u32::MAX, 1, 1, 1, 0).unwrap();
        assert_eq!(s.to_increments(i64::MAX), Err(ScalingError::Overflow));
    }

    #[test]
    fn c111_endless_axis_wraps_at_revolution_length() {
        let m = ModuloAxis::new(360_000).unwrap();
        assert_eq!(m.wrap(370_000), 10_000);
        assert_eq!(m.wrap(-10_000), 350_000);
        assert_eq!(m.wrap(360_000), 0);
        assert_eq!(m.distance(350_000, 10_000, ModuloDirection::Shortest), 20_000);
        assert_eq!(m.distance(10_000, 350_000, ModuloDirection::Shortest), -20_000);
        assert_eq!(m.distance(350_000, 10_000, ModuloDirection::Positive), 20_000);
        assert_eq!(m.distance(350_000, 10_000, ModuloDirection::Negative), -340_000);
        assert_eq!(m.distance(5, 5, ModuloDirection::Negative), 0);
        assert_eq!(m.distance(0, 180_000, ModuloDirection::Shortest), 180_000);
        assert!(m.distance(i64::MIN, i64::MAX, ModuloDirection::Positive) >= 0);
        assert_eq!(ModuloAxis::new(0), Err(ScalingError::Zero));
        assert_eq!(ModuloAxis::new(-1), Err(ScalingError::Zero));
    }
}
