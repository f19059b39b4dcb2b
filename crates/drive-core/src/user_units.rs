//! The CiA 402 user units of one axis (the factor group 6091h/6092h, the
//! polarity 607Eh and the decimal places A310/A311 under A213), as a
//! personality needs them to convert its own units to the objects' and
//! back: the PROFIdrive-style profile writes set-points into CiA objects
//! from values in its PROFINET units (spec `profidrive.md` §11, P-214).
//!
//! The conversions are the axis' own (`Snapshot::to_increments` in `axis/snapshot.rs`:
//! positions through [`AxisScaling`] with the position polarity, rates
//! through the magnitude of user units per increment and the decimals);
//! `c109_user_units_agree_with_the_axis_snapshot` keeps the two together.

use crate::axis::Axis;
use crate::params::{A213, A310, A311};
use crate::DriveObjects;
use motion::scaling::polarity_inverted;
use motion::{AxisScaling, INCREMENTS_PER_REVOLUTION};

/// The user units of one axis, read from the objects.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UserUnits {
    scaling: AxisScaling,
    inverted: bool,
    /// 10^A310, 10^A311 (1 with native fieldbus scaling).
    decimals: (f64, f64),
    /// |user units per increment| of `scaling`, computed once by
    /// [`read`](Self::read) (a 128-bit fraction to `f64`: hundreds of
    /// instructions on a Cortex-M4F, where `f64` is software).
    per_increment: f64,
    /// Every conversion is the identity ([`is_identity`](Self::is_identity)).
    identity: bool,
}

/// Half away from zero.
fn round(x: f64) -> f64 {
    if x >= 0.0 {
        x + 0.5
    } else {
        x - 0.5
    }
}

fn saturate_i64(x: f64) -> i64 {
    if x.is_nan() {
        0
    } else {
        // `as` saturates at the bounds
        x as i64
    }
}

impl UserUnits {
    /// Increments (the CiA 402 defaults).
    pub const INCREMENTS: UserUnits = UserUnits {
        scaling: AxisScaling::INCREMENTAL,
        inverted: false,
        decimals: (1.0, 1.0),
        per_increment: 1.0,
        identity: true,
    };

    /// The units of `axis` as its objects say now (a factor of 0 counts as
    /// increments, as the axis takes it). (Not inlined: read once per
    /// configuration by a cache, its place is not the cyclic path.)
    #[inline(never)]
    pub fn read(objects: &DriveObjects, axis: &Axis) -> UserUnits {
        let get = |index: u16, sub: u8| objects.get(axis.cia402_index(index), sub).unwrap_or(0);
        let u32_ = |index: u16, sub: u8| u32::try_from(get(index, sub)).unwrap_or(0);
        let (motor, shaft, feed, feed_shaft) =
            (u32_(0x6091, 1), u32_(0x6091, 2), u32_(0x6092, 1), u32_(0x6092, 2));
        let (scaling, one) = match AxisScaling::new(motor, shaft, feed, feed_shaft, 0) {
            // user units per increment = shaft · feed / (2^20 · motor · feed shaft), exactly 1?
            Ok(s) => {
                let per_rev = u64::from(motor) * u64::from(feed_shaft);
                let one = per_rev <= u64::MAX / u64::from(INCREMENTS_PER_REVOLUTION)
                    && u64::from(shaft) * u64::from(feed) == per_rev * u64::from(INCREMENTS_PER_REVOLUTION);
                (s, one)
            }
            Err(_) => (AxisScaling::INCREMENTAL, true),
        };
        let polarity = u8::try_from(get(0x607E, 0)).unwrap_or(0);
        let decimals = if objects.get(A213, 1) == Ok(0) {
            let d = |i: u16| {
                let n = objects
                    .get(axis.manufacturer_index(i), 0)
                    .unwrap_or(0)
                    .clamp(0, 9);
                (0..n).fold(1.0f64, |f, _| f * 10.0)
            };
            (d(A310), d(A311))
        } else {
            (1.0, 1.0)
        };
        let inverted = polarity_inverted(polarity);
        UserUnits {
            scaling,
            inverted,
            decimals,
            per_increment: scaling.user_per_increment().abs(),
            identity: one && !inverted && decimals == (1.0, 1.0),
        }
    }

    /// Whether every conversion is the identity: user units are
    /// increments (gear and feed give exactly one user unit per increment),
    /// polarity normal, no decimal places. The conversions of positions then
    /// return their argument, those of rates their argument rounded (exact
    /// for integers below 2^52 in magnitude).
    pub fn is_identity(&self) -> bool {
        self.identity
    }

    fn sign(&self) -> i64 {
        if self.inverted {
            -1
        } else {
            1
        }
    }

    /// A position in user units → increments (`None` beyond i64).
    pub fn position_to_increments(&self, user: i64) -> Option<i64> {
        self.scaling
            .to_increments(user)
            .ok()
            .and_then(|i| i.checked_mul(self.sign()))
    }

    /// Increments → a position in user units.
    pub fn position_from_increments(&self, increments: i64) -> Option<i64> {
        increments
            .checked_mul(self.sign())
            .and_then(|i| self.scaling.to_user(i).ok())
    }

    fn per_increment(&self) -> f64 {
        self.per_increment
    }

    /// A velocity object's value (user units/s × 10^A310) → increments/s.
    pub fn velocity_to_increments(&self, user: i64) -> f64 {
        user as f64 / (self.per_increment() * self.decimals.0)
    }

    /// Increments/s → a velocity object's value, rounded.
    pub fn velocity_from_increments(&self, increments_per_s: f64) -> i64 {
        saturate_i64(round(increments_per_s * self.per_increment() * self.decimals.0))
    }

    /// An acceleration object's value (user units/s² × 10^A311) →
    /// increments/s².
    pub fn acceleration_to_increments(&self, user: i64) -> f64 {
        user as f64 / (self.per_increment() * self.decimals.1)
    }

    /// Increments/s² → an acceleration object's value, rounded.
    pub fn acceleration_from_increments(&self, increments_per_s2: f64) -> i64 {
        saturate_i64(round(increments_per_s2 * self.per_increment() * self.decimals.1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::axis::{Snapshot, Window};

    /// The same objects through the axis' snapshot and through these units
    /// give the same increments (a gear 3 : 2, a feed 1000 per 7 revs, two
    /// velocity and three acceleration decimals).
    #[test]
    fn c109_user_units_agree_with_the_axis_snapshot() {
        let mut od = DriveObjects::new();
        let axis = Axis::new(0);
        for (i, s, v) in [
            (0x6091, 1, 3),
            (0x6091, 2, 2),
            (0x6092, 1, 1000),
            (0x6092, 2, 7),
            (0x607A, 0, -12_345),
            (0x6081, 0, 777),
            (0x6083, 0, 4321),
        ] {
            od.set(i, s, v).unwrap();
        }
        od.set(A213, 1, 0).unwrap();
        od.set(A310, 0, 2).unwrap();
        od.set(A311, 0, 3).unwrap();
        let snap = Snapshot::read(&od, Window { axis: 0 });
        let inc = snap.to_increments(&snap.scaling());
        let u = UserUnits::read(&od, &axis);
        assert_eq!(
            u.position_to_increments(-12_345),
            Some(i64::from(inc.target_position))
        );
        assert_eq!(round(u.velocity_to_increments(777)) as u32, inc.profile_velocity);
        assert_eq!(round(u.acceleration_to_increments(4321)) as u32, inc.acceleration);
        // and back
        let back = u
            .position_from_increments(i64::from(inc.target_position))
            .unwrap();
        assert!((back + 12_345).abs() <= 1, "{back}");
        assert!((u.velocity_from_increments(f64::from(inc.profile_velocity)) - 777).abs() <= 1);
    }

    #[test]
    fn the_defaults_are_increments() {
        let od = DriveObjects::new();
        let u = UserUnits::read(&od, &Axis::new(0));
        assert_eq!(u, UserUnits::INCREMENTS);
        assert_eq!(u.position_to_increments(1 << 20), Some(1 << 20));
        assert_eq!(u.velocity_from_increments(1234.4), 1234);
    }

    /// The identity takes exactly one user unit per increment, normal
    /// polarity and no decimals; the conversions agree with it.
    #[test]
    fn c108_user_units_are_the_identity_only_at_one_unit_per_increment() {
        let axis = Axis::new(0);
        let units = |set: &[(u16, u8, i64)]| {
            let mut od = DriveObjects::new();
            for &(i, s, v) in set {
                od.set(i, s, v).unwrap();
            }
            UserUnits::read(&od, &axis)
        };
        assert!(units(&[]).is_identity());
        // gear 2 : 2 and a feed of 2^21 per 2 revolutions: still 1 per increment
        let same = units(&[
            (0x6091, 1, 2),
            (0x6091, 2, 2),
            (0x6092, 1, 1 << 21),
            (0x6092, 2, 2),
        ]);
        assert!(same.is_identity());
        assert_eq!(same.position_to_increments(-77), Some(-77));
        assert_eq!(same.velocity_from_increments(-1234.0), -1234);
        for u in [
            units(&[(0x6092, 1, 1000)]),
            units(&[(0x607E, 0, 0x80)]),
            units(&[(A213, 1, 0), (A310, 0, 1)]),
        ] {
            assert!(!u.is_identity(), "{u:?}");
        }
        // decimals 0 with A213 = 0: the identity again
        assert!(units(&[(A213, 1, 0)]).is_identity());
    }

    #[test]
    fn c110_position_polarity_inverts_positions() {
        let mut od = DriveObjects::new();
        od.set(0x607E, 0, 0x80).unwrap();
        let u = UserUnits::read(&od, &Axis::new(0));
        assert_eq!(u.position_to_increments(1000), Some(-1000));
        assert_eq!(u.position_from_increments(-1000), Some(1000));
    }
}
