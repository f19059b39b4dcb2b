//! A unit profile: the physical units a fieldbus profile uses for position,
//! velocity and acceleration values, converted exactly to and from the
//! drive's internal units (increments, increments/s, increments/s²; 2^20
//! increments per motor revolution). The PROFIdrive-style profile of the
//! Metronix manual (spec `profidrive.md` §11, P-207…P-214) uses one such
//! profile for its PNUs while CANopen objects keep the CiA 402 factor group
//! ([`crate::scaling`]); any fieldbus could use it.
//!
//! Each quantity is chosen on its own (P-208): a rotational unit (revolution
//! or degree of the output shaft, with a decimal exponent) or a
//! translational one (metre with a decimal exponent: mm = 10⁻³ m, µm = 10⁻⁶ m),
//! per second or per minute for velocities, per second for accelerations.
//! The gear ratio (motor revolutions : output revolutions, positive only,
//! P-213) always applies (P-209). The feed constant (distance per output
//! revolution, positive only) applies only to a translational unit (P-210):
//! a rotational unit ignores it, a unitless feed acts as a further gear
//! factor (distance units = the quantity's own), a feed in µm/rev against mm
//! is taken with factor 1000 because both are reduced to metres.
//!
//! Every conversion is one fraction bus = internal · num / den, reduced,
//! with num and den of at most 32 bits each (P-211); a choice whose
//! fraction does not fit is refused with [`UnitError::Overflow`] and the
//! previous profile stays (the drive reports it as error 22-4, P-212). A
//! value that does not fit the bus type at run time is an error too
//! (P-184: the actual position can overflow INT32).

use crate::INCREMENTS_PER_REVOLUTION;

/// Why a unit choice or a conversion is refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnitError {
    /// A gear or feed factor of 0 (P-213: positive only).
    Zero,
    /// The conversion fraction needs more than 32 bits in its numerator or
    /// denominator (P-211), or a decimal exponent out of range.
    Overflow,
    /// The converted value does not fit the bus type (INT32).
    OutOfRange,
}

/// What a distance is measured in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dimension {
    /// Revolutions of the output shaft × 10^exponent.
    Revolution,
    /// Degrees of the output shaft × 10^exponent.
    Degree,
    /// Metres × 10^exponent (mm: −3, µm: −6).
    Metre,
}

impl Dimension {
    fn is_rotational(self) -> bool {
        !matches!(self, Dimension::Metre)
    }
}

/// A distance unit: dimension × 10^exponent (exponent −9…0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Distance {
    /// The dimension.
    pub dimension: Dimension,
    /// The decimal exponent, −9…0 (1/1000 rev: −3).
    pub exponent: i8,
}

impl Distance {
    /// 1/1000 revolution, the manual's default position unit (P-207).
    pub const MILLI_REV: Distance = Distance {
        dimension: Dimension::Revolution,
        exponent: -3,
    };
    /// One revolution (rpm, rpm/s with [`Time::Minute`]).
    pub const REV: Distance = Distance {
        dimension: Dimension::Revolution,
        exponent: 0,
    };
}

/// The time base of a velocity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Time {
    /// Per second.
    Second,
    /// Per minute (rpm).
    Minute,
}

impl Time {
    const fn seconds(self) -> u64 {
        match self {
            Time::Second => 1,
            Time::Minute => 60,
        }
    }
}

/// The feed constant: distance per output revolution (P-210).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Feed {
    /// The amount, > 0.
    pub value: u32,
    /// Its unit; `None` = unitless (the quantity's own distance units).
    pub unit: Option<Distance>,
}

/// The unit choices (P-208) and the mechanics between motor and load.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UnitSettings {
    /// Position unit.
    pub position: Distance,
    /// Velocity unit: distance per `velocity_time`.
    pub velocity: Distance,
    /// The velocity's time base.
    pub velocity_time: Time,
    /// Acceleration unit: distance per `acceleration_time` per second.
    pub acceleration: Distance,
    /// The acceleration's first time base (rpm/s: minute).
    pub acceleration_time: Time,
    /// Gear: motor revolutions (input shaft), > 0.
    pub gear_in: u32,
    /// Gear: output revolutions, > 0.
    pub gear_out: u32,
    /// The feed constant.
    pub feed: Feed,
}

impl UnitSettings {
    /// The manual's defaults (P-207): position 1/1000 rev, velocity rpm,
    /// acceleration rpm/s, gear 1 : 1, feed 1 (ignored for rotational units).
    pub const DEFAULT: UnitSettings = UnitSettings {
        position: Distance::MILLI_REV,
        velocity: Distance::REV,
        velocity_time: Time::Minute,
        acceleration: Distance::REV,
        acceleration_time: Time::Minute,
        gear_in: 1,
        gear_out: 1,
        feed: Feed { value: 1, unit: None },
    };
}

/// bus = internal · num / den, reduced, each part ≤ 32 bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fraction {
    num: u32,
    den: u32,
}

/// Binary GCD (Stein) in `$t`: shifts and subtractions only; a 128-bit `%`
/// is a long library loop on a 32-bit MCU. gcd(0, b) = b.
macro_rules! binary_gcd {
    ($(#[$doc:meta])* $name:ident, $t:ty) => {
        $(#[$doc])*
        const fn $name(mut a: $t, mut b: $t) -> $t {
            if a == 0 {
                return b;
            }
            if b == 0 {
                return a;
            }
            let shift = (a | b).trailing_zeros();
            a >>= a.trailing_zeros();
            loop {
                b >>= b.trailing_zeros();
                if a > b {
                    let t = a;
                    a = b;
                    b = t;
                }
                b -= a;
                if b == 0 {
                    return a << shift;
                }
            }
        }
    };
}

binary_gcd!(
    /// [`gcd`] in 64 bits.
    gcd64,
    u64
);
binary_gcd!(
    /// Binary GCD (Stein) of two 128-bit values; gcd(0, b) = b.
    gcd,
    u128
);

/// `x · num / den` rounded half away from zero, exactly, in 64-bit
/// arithmetic (a 128-bit division is a long library routine on the MCU):
/// |x| = q · den + r, so |x| · num / den = q · num + r · num / den, where
/// r · num < 2^64 − 2^33 leaves room for the rounding half. `None` when
/// the result does not fit i64 (or den = 0).
fn scale_round(x: i64, num: u32, den: u32) -> Option<i64> {
    let (num, den) = (u64::from(num), u64::from(den));
    let m = x.unsigned_abs();
    let q = m.checked_div(den)?;
    let r = m.checked_rem(den)?;
    let frac = (r * num + den / 2).checked_div(den)?;
    let v = q.checked_mul(num)?.checked_add(frac)?;
    if x < 0 {
        0i64.checked_sub_unsigned(v)
    } else {
        i64::try_from(v).ok()
    }
}

/// Rounds n/d to the nearest integer, half away from zero (d > 0).
#[cfg(test)]
fn div_round(n: i128, d: i128) -> Option<i128> {
    let half = d / 2;
    if n >= 0 {
        n.checked_add(half)?.checked_div(d)
    } else {
        Some(-(n.checked_neg()?.checked_add(half)?.checked_div(d)?))
    }
}

impl Fraction {
    /// num/den reduced; refused when a part is 0 or does not fit 32 bits.
    /// Not inlined: one copy serves the three quantities (flash).
    #[inline(never)]
    pub fn new(num: u128, den: u128) -> Result<Fraction, UnitError> {
        if num == 0 || den == 0 {
            return Err(UnitError::Zero);
        }
        // both parts in 64 bits (the usual settings): the same reduction
        // without 128-bit divisions, each a long library loop on a 32-bit
        // MCU (issue 36: ~7,000 instructions for a profile's three
        // fractions on QEMU)
        if let (Ok(num), Ok(den)) = (u64::try_from(num), u64::try_from(den)) {
            let g = gcd64(num, den);
            let (Some(n), Some(d)) = (num.checked_div(g), den.checked_div(g)) else {
                return Err(UnitError::Zero);
            };
            return match (u32::try_from(n), u32::try_from(d)) {
                (Ok(num), Ok(den)) => Ok(Fraction { num, den }),
                _ => Err(UnitError::Overflow),
            };
        }
        let g = gcd(num, den);
        // g ≥ 1 here; checked so the MCU build has no panic path
        let (Some(n), Some(d)) = (num.checked_div(g), den.checked_div(g)) else {
            return Err(UnitError::Zero);
        };
        match (u32::try_from(n), u32::try_from(d)) {
            (Ok(num), Ok(den)) => Ok(Fraction { num, den }),
            _ => Err(UnitError::Overflow),
        }
    }

    /// Numerator and denominator.
    pub const fn parts(&self) -> (u32, u32) {
        (self.num, self.den)
    }

    /// internal → bus, rounded, as INT32.
    pub fn to_bus(&self, internal: i64) -> Result<i32, UnitError> {
        let v = scale_round(internal, self.num, self.den).ok_or(UnitError::OutOfRange)?;
        i32::try_from(v).map_err(|_| UnitError::OutOfRange)
    }

    /// bus → internal, rounded.
    pub fn from_bus(&self, bus: i64) -> Result<i64, UnitError> {
        scale_round(bus, self.den, self.num).ok_or(UnitError::OutOfRange)
    }

    /// internal → bus for a real value (velocities and accelerations are
    /// `f32` in the core), rounded, as INT32.
    pub fn to_bus_f32(&self, internal: f32) -> Result<i32, UnitError> {
        let v = f64::from(internal) * f64::from(self.num) / f64::from(self.den);
        // half away from zero (no `round` without std); `as` truncates toward zero
        let v = if v >= 0.0 { v + 0.5 } else { v - 0.5 };
        if v.is_finite() && v > f64::from(i32::MIN) - 1.0 && v < f64::from(i32::MAX) + 1.0 {
            Ok(v as i32)
        } else {
            Err(UnitError::OutOfRange)
        }
    }

    /// bus → internal as a real value.
    pub fn from_bus_f32(&self, bus: i64) -> f32 {
        (bus as f64 * f64::from(self.den) / f64::from(self.num)) as f32
    }
}

/// A converted unit profile: one fraction per quantity (bus per internal).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UnitProfile {
    settings: UnitSettings,
    /// bus position units per increment.
    pub position: Fraction,
    /// bus velocity units per increment/s.
    pub velocity: Fraction,
    /// bus acceleration units per increment/s².
    pub acceleration: Fraction,
}

/// 10^|e| for e in −9…0.
fn pow10(exponent: i8) -> Result<u128, UnitError> {
    if !(-9..=0).contains(&exponent) {
        return Err(UnitError::Overflow);
    }
    Ok(10u128.pow(u32::from(exponent.unsigned_abs())))
}

/// Distance units of `d` per output revolution as num/den, through the
/// feed for a translational unit.
fn per_output_rev(d: Distance, feed: Feed) -> Result<(u128, u128), UnitError> {
    let scale = pow10(d.exponent)?; // units = dimension · 10^exponent
    match d.dimension {
        Dimension::Revolution => Ok((scale, 1)),
        Dimension::Degree => Ok((360 * scale, 1)),
        Dimension::Metre => {
            if feed.value == 0 {
                return Err(UnitError::Zero);
            }
            let value = u128::from(feed.value);
            match feed.unit {
                // the quantity's own units per output revolution: a further gear factor
                None => Ok((value, 1)),
                // rotational feed units make no sense against a distance: the feed counts as unitless
                Some(f) if f.dimension.is_rotational() => Ok((value, 1)),
                // value · 10^f metres per rev = value · 10^f / 10^d units per rev
                Some(f) => {
                    let feed_scale = pow10(f.exponent)?;
                    Ok((value * scale, feed_scale))
                }
            }
        }
    }
}

/// Bus units of distance `d` (per `time` seconds) per increment:
/// (units per output rev) · gear_out / (gear_in · 2^20). Not inlined (one
/// copy for the three quantities).
#[inline(never)]
fn fraction_of(s: &UnitSettings, d: Distance, time: u64) -> Result<Fraction, UnitError> {
    let inc = u128::from(INCREMENTS_PER_REVOLUTION);
    let (gi, go) = (u128::from(s.gear_in), u128::from(s.gear_out));
    let (n, den) = per_output_rev(d, s.feed)?;
    Fraction::new(n * go * u128::from(time), den * gi * inc)
}

impl UnitProfile {
    /// The manual's defaults.
    pub fn default_profile() -> UnitProfile {
        // the defaults always fit (a test keeps it so)
        UnitProfile::new(UnitSettings::DEFAULT).unwrap_or(UnitProfile {
            settings: UnitSettings::DEFAULT,
            position: Fraction {
                num: 125,
                den: 131_072,
            },
            velocity: Fraction {
                num: 15,
                den: 262_144,
            },
            acceleration: Fraction {
                num: 15,
                den: 262_144,
            },
        })
    }

    /// Converts `s` (P-208…P-213); refused with [`UnitError`] when a factor
    /// is 0 or a fraction does not fit 32 bits (P-211).
    pub fn new(s: UnitSettings) -> Result<UnitProfile, UnitError> {
        if s.gear_in == 0 || s.gear_out == 0 || s.feed.value == 0 {
            return Err(UnitError::Zero);
        }
        Ok(UnitProfile {
            settings: s,
            position: fraction_of(&s, s.position, 1)?,
            velocity: fraction_of(&s, s.velocity, s.velocity_time.seconds())?,
            acceleration: fraction_of(&s, s.acceleration, s.acceleration_time.seconds())?,
        })
    }

    /// The settings this profile was made from.
    pub fn settings(&self) -> &UnitSettings {
        &self.settings
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 64-bit reduction gives the 128-bit one's fraction or error.
    #[test]
    fn fraction_64_bit_path_answers_as_the_128_bit_one() {
        let reference = |num: u128, den: u128| -> Result<Fraction, UnitError> {
            if num == 0 || den == 0 {
                return Err(UnitError::Zero);
            }
            let g = gcd(num, den);
            match (u32::try_from(num / g), u32::try_from(den / g)) {
                (Ok(num), Ok(den)) => Ok(Fraction { num, den }),
                _ => Err(UnitError::Overflow),
            }
        };
        let parts: [u128; 12] = [
            0,
            1,
            2,
            3,
            1 << 20,
            60 * (1 << 20),
            1000,
            360_000,
            u128::from(u32::MAX),
            u128::from(u64::MAX),
            u128::from(u64::MAX) - 1,
            (1 << 70) + 6,
        ];
        for &n in &parts {
            for &d in &parts {
                for k in [1u128, 7, 1 << 12] {
                    let (n, d) = (n.saturating_mul(k), d.saturating_mul(k));
                    assert_eq!(Fraction::new(n, d), reference(n, d), "{n}/{d}");
                }
            }
        }
        assert_eq!(gcd64(48, 180), 12);
        assert_eq!(gcd64(0, 5), 5);
    }

    /// Metres times 10^`exponent`.
    fn metres(exponent: i8) -> Distance {
        Distance {
            dimension: Dimension::Metre,
            exponent,
        }
    }

    /// The 64-bit scaling gives exactly what the 128-bit form gives
    /// (where that fits i64), over edge and pseudo-random arguments.
    #[test]
    fn p211_scale_round_equals_the_128_bit_form() {
        let reference = |x: i64, num: u32, den: u32| {
            div_round(i128::from(x) * i128::from(num), i128::from(den)).and_then(|v| i64::try_from(v).ok())
        };
        let xs = [
            0,
            1,
            -1,
            2,
            -2,
            i64::MAX,
            i64::MIN,
            i64::MAX - 1,
            i64::MIN + 1,
            1 << 40,
            -(1 << 40),
        ];
        let nds = [
            (1u32, 1u32),
            (u32::MAX, 1),
            (1, u32::MAX),
            (u32::MAX, u32::MAX - 1),
            (125, 131_072),
            (3, 2),
            (2, 3),
        ];
        for &x in &xs {
            for &(n, d) in &nds {
                assert_eq!(scale_round(x, n, d), reference(x, n, d), "{x} * {n} / {d}");
            }
        }
        let mut seed = 0x1234_5678_9abc_def0u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        for _ in 0..200_000 {
            let x = next() as i64 >> (next() % 64);
            let n = ((next() as u32) >> (next() % 32)).max(1);
            let d = ((next() as u32) >> (next() % 32)).max(1);
            assert_eq!(scale_round(x, n, d), reference(x, n, d), "{x} * {n} / {d}");
        }
    }

    const REV: i64 = INCREMENTS_PER_REVOLUTION as i64;

    #[test]
    fn p207_default_units_are_milli_rev_rpm_and_rpm_per_s() {
        let p = UnitProfile::default_profile();
        assert_eq!(p, UnitProfile::new(UnitSettings::DEFAULT).unwrap());
        assert_eq!(p.position.to_bus(5 * REV).unwrap(), 5000);
        assert_eq!(p.position.from_bus(5000).unwrap(), 5 * REV);
        // 1000 rpm = 1000/60 rev/s
        let v = 1000.0 / 60.0 * REV as f32;
        assert_eq!(p.velocity.to_bus_f32(v).unwrap(), 1000);
        assert!((p.velocity.from_bus_f32(1000) - v).abs() < 1.0);
        // 10 000 rpm/s
        let a = 10_000.0 / 60.0 * REV as f32;
        assert_eq!(p.acceleration.to_bus_f32(a).unwrap(), 10_000);
    }

    #[test]
    fn p208_position_velocity_and_acceleration_are_chosen_independently() {
        let mut s = UnitSettings::DEFAULT;
        s.position = Distance {
            dimension: Dimension::Degree,
            exponent: -1,
        };
        s.velocity_time = Time::Second;
        let p = UnitProfile::new(s).unwrap();
        assert_eq!(p.position.to_bus(REV / 2).unwrap(), 1800, "0.1° units");
        assert_eq!(p.velocity.to_bus_f32(2.0 * REV as f32).unwrap(), 2, "rev/s");
        assert_eq!(
            p.acceleration.to_bus_f32(REV as f32).unwrap(),
            60,
            "rpm/s unchanged"
        );
    }

    #[test]
    fn p209_the_gear_ratio_applies_to_every_quantity() {
        let mut s = UnitSettings::DEFAULT;
        s.gear_in = 10; // 10 motor revolutions per output revolution
        s.gear_out = 1;
        let p = UnitProfile::new(s).unwrap();
        assert_eq!(
            p.position.to_bus(10 * REV).unwrap(),
            1000,
            "one output revolution"
        );
        assert_eq!(p.velocity.to_bus_f32(10.0 * REV as f32 / 60.0).unwrap(), 1);
    }

    #[test]
    fn p210_the_feed_applies_to_translational_units_only() {
        let mut s = UnitSettings::DEFAULT;
        // rotational position: a feed of 5 mm/rev is ignored
        s.feed = Feed {
            value: 5,
            unit: Some(metres(-3)),
        };
        assert_eq!(UnitProfile::new(s).unwrap().position.to_bus(REV).unwrap(), 1000);
        // position in mm, feed in µm/rev: 5000 µm = 5 mm per revolution (factor 1000)
        s.position = metres(-3);
        s.feed = Feed {
            value: 5000,
            unit: Some(metres(-6)),
        };
        assert_eq!(UnitProfile::new(s).unwrap().position.to_bus(2 * REV).unwrap(), 10);
        // position in mm, unitless feed 7: used like a gear factor (7 mm per revolution)
        s.feed = Feed { value: 7, unit: None };
        assert_eq!(UnitProfile::new(s).unwrap().position.to_bus(2 * REV).unwrap(), 14);
    }

    #[test]
    fn p211_a_fraction_beyond_32_bits_is_refused() {
        let mut s = UnitSettings::DEFAULT;
        // nanometres against a feed of 4 294 967 291 µm (a prime) per
        // revolution and a prime gear: the fraction cannot be reduced to 32 bits
        s.position = metres(-9);
        s.feed = Feed {
            value: 4_294_967_291,
            unit: Some(metres(-6)),
        };
        s.gear_in = 4_294_967_279;
        assert_eq!(UnitProfile::new(s), Err(UnitError::Overflow));
        // an exponent outside −9…0
        let mut t = UnitSettings::DEFAULT;
        t.position.exponent = -10;
        assert_eq!(UnitProfile::new(t), Err(UnitError::Overflow));
    }

    #[test]
    fn p213_gear_and_feed_take_positive_values_only() {
        for (gi, go, feed) in [(0, 1, 1), (1, 0, 1), (1, 1, 0)] {
            let mut s = UnitSettings::DEFAULT;
            s.gear_in = gi;
            s.gear_out = go;
            s.feed.value = feed;
            assert_eq!(UnitProfile::new(s), Err(UnitError::Zero), "{gi}:{go} feed {feed}");
        }
    }

    #[test]
    fn a_position_beyond_int32_is_an_error_not_a_wrap() {
        let p = UnitProfile::default_profile();
        // 2^31 milli-revolutions = 2 147 484 revolutions
        let far = 2_147_484 * REV;
        assert_eq!(p.position.to_bus(far), Err(UnitError::OutOfRange));
        assert_eq!(p.position.to_bus(-far), Err(UnitError::OutOfRange));
        assert_eq!(p.velocity.to_bus_f32(f32::INFINITY), Err(UnitError::OutOfRange));
    }

    #[test]
    fn negative_values_round_half_away_from_zero() {
        let p = UnitProfile::default_profile();
        // one milli-revolution is 1048.576 increments
        assert_eq!(p.position.to_bus(-1049).unwrap(), -1);
        assert_eq!(p.position.to_bus(-524).unwrap(), 0);
        assert_eq!(p.position.from_bus(-1).unwrap(), -1049);
    }
}
