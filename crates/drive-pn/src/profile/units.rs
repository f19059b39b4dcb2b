//! The unit conversions of the cyclic path, cheap (issue 17, cycle cost):
//! the axis' CiA 402 user units read once per configuration generation
//! ([`UnitsCache`]) instead of from seven objects at every conversion, and
//! the PROFINET unit fractions ([`Fraction`]) and the rpm conversions of the
//! vl objects in 32/64-bit integers where their arguments allow, with
//! exactly the results of the general 128-bit / `f64` forms (which stay for
//! the arguments they do not cover). On a Cortex-M4F a 128-bit division or
//! an `f64` operation is a library call of hundreds of instructions.

use drive_core::axis::Axis;
use drive_core::user_units::UserUnits;
use drive_core::DriveObjects;
use motion::units::{Fraction, UnitError};
use motion::INCREMENTS_PER_REVOLUTION;

/// The user units of an axis with the configuration generation
/// ([`DriveObjects::config_generation`]) they were read at: any change of a
/// factor-group object (6091h, 6092h, 607Eh, A213, A310/A311) moves the
/// generation, so the next conversion reads them again. One cache serves
/// one dictionary. Lent by reference, not copied out (issue 36: the copy
/// of a `Cell` cost every converted telegram entry some 40 instructions on
/// QEMU).
///
/// With them a memo of the bus → object conversions done
/// ([`converted`](Self::converted)): a conversion depends on the PROFINET
/// units, which change with the configuration generation only (and are
/// forgotten when they do, [`forget_conversions`](Self::forget_conversions)),
/// the user units and the value (issue 36: telegram 0 converts the same five
/// record values every telegram).
#[derive(Debug, Default)]
pub struct UnitsCache {
    cached: Option<(u32, u8, UserUnits)>,
    /// `(generation, bus, object, axis, unit code)`, unit code 0 = free;
    /// values that fit 32 bits only.
    converted: [(u32, i32, i32, u8, u8); CONVERTED],
    next: u8,
}

/// Places of the conversion memo (telegram 0 converts five values).
const CONVERTED: usize = 5;

impl UnitsCache {
    /// An empty cache (the first use reads the objects).
    pub const fn new() -> Self {
        Self {
            cached: None,
            converted: [(0, 0, 0, 0, 0); CONVERTED],
            next: 0,
        }
    }

    /// The object value `bus` converted to, in unit `unit` (a code, never
    /// 0) on `axis` at generation `g`, when remembered.
    pub fn converted(&self, g: u32, axis: u8, unit: u8, bus: i64) -> Option<i64> {
        let bus = i32::try_from(bus).ok()?;
        self.converted
            .iter()
            .find(|c| c.0 == g && c.1 == bus && c.3 == axis && c.4 == unit)
            .map(|c| i64::from(c.2))
    }

    /// Remembers a conversion ([`converted`](Self::converted)).
    pub fn remember(&mut self, g: u32, axis: u8, unit: u8, bus: i64, object: i64) {
        let (Ok(bus), Ok(object)) = (i32::try_from(bus), i32::try_from(object)) else {
            return;
        };
        let at = usize::from(self.next) % CONVERTED;
        self.next = (at + 1) as u8;
        if let Some(c) = self.converted.get_mut(at) {
            *c = (g, bus, object, axis, unit);
        }
    }

    /// Forgets the conversions (the PROFINET units changed).
    pub fn forget_conversions(&mut self) {
        self.converted = [(0, 0, 0, 0, 0); CONVERTED];
    }

    /// The user units of `axis` as its objects say now.
    pub fn get(&mut self, objects: &DriveObjects, axis: &Axis) -> &UserUnits {
        let generation = objects.config_generation();
        let cached = &mut self.cached;
        if !matches!(cached, Some((g, a, _)) if *g == generation && *a == axis.index()) {
            *cached = Some((generation, axis.index(), UserUnits::read(objects, axis)));
        }
        let (_, _, u) =
            cached.get_or_insert_with(|| (generation, axis.index(), UserUnits::read(objects, axis)));
        u
    }
}

/// `m / d` rounded half away from zero (`m` < 2^96, so `m + d/2` cannot
/// overflow); a 32-bit division when the sum fits, `None` for d = 0. (Not
/// inlined: one copy of the 128-bit division for both directions.)
#[inline(never)]
fn div_round(m: u128, d: u32) -> Option<u128> {
    let n = m + u128::from(d / 2);
    match u32::try_from(n) {
        Ok(n) => n.checked_div(d).map(u128::from),
        Err(_) => n.checked_div(u128::from(d)),
    }
}

/// [`div_round`] of `m · k` by `d` where `m` and `m · k + d/2` fit 32 bits
/// (the telegrams' usual values): a 64-bit product and a 32-bit division,
/// no 128-bit arguments (issue 36). `None`: not so (the general path);
/// `Some(None)`: d = 0.
#[inline(always)]
fn div_round_32(m: u64, k: u32, d: u32) -> Option<Option<u32>> {
    let m = u32::try_from(m).ok()?;
    let n = u32::try_from(u64::from(m) * u64::from(k) + u64::from(d / 2)).ok()?;
    Some(n.checked_div(d))
}

/// `q` with the sign of `negative`, if it fits i64.
fn signed(negative: bool, q: u128) -> Option<i64> {
    let q = i128::try_from(q).ok()?;
    i64::try_from(if negative { -q } else { q }).ok()
}

/// [`Fraction::from_bus`]: bus → internal, rounded (its result for every
/// argument).
pub fn from_bus(f: &Fraction, bus: i64) -> Result<i64, UnitError> {
    let (num, den) = f.parts();
    if let Some(q) = div_round_32(bus.unsigned_abs(), den, num) {
        let q = i64::from(q.ok_or(UnitError::OutOfRange)?);
        return Ok(if bus < 0 { -q } else { q });
    }
    let m = u128::from(bus.unsigned_abs()) * u128::from(den);
    div_round(m, num)
        .and_then(|q| signed(bus < 0, q))
        .ok_or(UnitError::OutOfRange)
}

/// [`Fraction::to_bus`]: internal → bus, rounded, as INT32 (its result for
/// every argument).
pub fn to_bus(f: &Fraction, internal: i64) -> Result<i32, UnitError> {
    let (num, den) = f.parts();
    if let Some(q) = div_round_32(internal.unsigned_abs(), num, den) {
        let q = i64::from(q.ok_or(UnitError::OutOfRange)?);
        return i32::try_from(if internal < 0 { -q } else { q }).map_err(|_| UnitError::OutOfRange);
    }
    let m = u128::from(internal.unsigned_abs()) * u128::from(num);
    div_round(m, den)
        .and_then(|q| signed(internal < 0, q))
        .and_then(|v| i32::try_from(v).ok())
        .ok_or(UnitError::OutOfRange)
}

/// Largest |increments/s| the integer form of [`rpm_of`] takes (2^46: the
/// `f64` form is exact there too, 60 · 2^46 < 2^52).
const RPM_OF_LIMIT: u64 = 1 << 46;

/// Largest |rpm| the integer form of [`increments_of_rpm`] takes (2^24:
/// the quotient stays below 2^39, where the `f64` form rounds the same).
const INCREMENTS_OF_RPM_LIMIT: u64 = 1 << 24;

/// inc/s (or /s²) → rpm (or rpm/s), rounded half away from zero.
pub fn rpm_of(increments: i64) -> i64 {
    let m = increments.unsigned_abs();
    if m <= RPM_OF_LIMIT {
        let half = u64::from(INCREMENTS_PER_REVOLUTION / 2);
        let rpm = ((m * 60 + half) >> INCREMENTS_PER_REVOLUTION.trailing_zeros()) as i64;
        return if increments < 0 { -rpm } else { rpm };
    }
    let rpm = increments as f64 * 60.0 / f64::from(INCREMENTS_PER_REVOLUTION);
    round_i64(rpm)
}

/// rpm (or rpm/s) → inc/s (or /s²), rounded half away from zero.
pub fn increments_of_rpm(rpm: i64) -> i64 {
    let m = rpm.unsigned_abs();
    if m <= INCREMENTS_OF_RPM_LIMIT {
        let inc = ((m << INCREMENTS_PER_REVOLUTION.trailing_zeros()) + 30) / 60;
        let inc = inc as i64;
        return if rpm < 0 { -inc } else { inc };
    }
    round_i64(rpm as f64 * f64::from(INCREMENTS_PER_REVOLUTION) / 60.0)
}

/// Half away from zero; `as` saturates.
#[inline(never)]
pub fn round_i64(x: f64) -> i64 {
    (if x >= 0.0 { x + 0.5 } else { x - 0.5 }) as i64
}

/// Below this magnitude an integer is exact in `f64` with room for the
/// half of the rounding: the identity user units return it unchanged.
const EXACT: u64 = 1 << 52;

/// [`UserUnits::velocity_from_increments`] of an integer rate.
pub fn velocity_from_increments(u: &UserUnits, increments: i64) -> i64 {
    if u.is_identity() && increments.unsigned_abs() < EXACT {
        return increments;
    }
    u.velocity_from_increments(increments as f64)
}

/// [`UserUnits::acceleration_from_increments`] of an integer rate.
pub fn acceleration_from_increments(u: &UserUnits, increments: i64) -> i64 {
    if u.is_identity() && increments.unsigned_abs() < EXACT {
        return increments;
    }
    u.acceleration_from_increments(increments as f64)
}

/// [`UserUnits::velocity_to_increments`], rounded.
pub fn velocity_to_increments(u: &UserUnits, user: i64) -> i64 {
    if u.is_identity() && user.unsigned_abs() < EXACT {
        return user;
    }
    round_i64(u.velocity_to_increments(user))
}

/// [`UserUnits::acceleration_to_increments`], rounded.
pub fn acceleration_to_increments(u: &UserUnits, user: i64) -> i64 {
    if u.is_identity() && user.unsigned_abs() < EXACT {
        return user;
    }
    round_i64(u.acceleration_to_increments(user))
}

#[cfg(test)]
mod tests {
    use super::*;
    use motion::units::UnitProfile;

    fn rpm_of_f64(increments: f64) -> i64 {
        round_i64(increments * 60.0 / f64::from(INCREMENTS_PER_REVOLUTION))
    }

    fn increments_of_rpm_f64(rpm: i64) -> i64 {
        round_i64(rpm as f64 * f64::from(INCREMENTS_PER_REVOLUTION) / 60.0)
    }

    /// A deterministic spread of values: small ones, ties, the limits of
    /// the integer forms and beyond, both signs.
    fn values() -> impl Iterator<Item = i64> {
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        let random = (0..4000).map(move |k| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            // magnitudes of every size, 2^0 … 2^62
            (x >> (k % 63)) as i64 * if k % 2 == 0 { 1 } else { -1 }
        });
        let edges = [
            0i64,
            1,
            -1,
            8738, // 8738 · 60 / 2^20 = 0.49999…: rounds down
            8739,
            17_476,
            // where the fractions' 32-bit forms end (the default units)
            16_383,
            16_384,
            32_767,
            32_768,
            32_769,
            65_535,
            65_536,
            1 << 19,
            (1 << 40) - 1,
            1 << 40,
            (1 << 40) + 1,
            (1 << 46) - 1,
            1 << 46,
            (1 << 46) + 1,
            (1 << 24) - 1,
            1 << 24,
            (1 << 24) + 1,
            u32::MAX as i64,
            u32::MAX as i64 + 1,
            i32::MAX as i64,
            i32::MIN as i64,
            i64::MAX,
            i64::MIN,
            i64::MIN + 1,
        ];
        edges
            .into_iter()
            .flat_map(|v| [v, v.saturating_neg()])
            .chain(random)
    }

    /// P-211: the integer forms give the 128-bit fractions' results (the
    /// manual's default units and a few others, every argument size).
    #[test]
    fn p211_the_fast_fractions_equal_the_exact_ones() {
        let mut fractions = std::vec![];
        let p = UnitProfile::default_profile();
        fractions.extend([p.position, p.velocity, p.acceleration]);
        for (n, d) in [
            (1u128, 1u128),
            (1, 3),
            (7, 1),
            (u32::MAX as u128, 1),
            (1, u32::MAX as u128),
        ] {
            fractions.push(Fraction::new(n, d).unwrap());
        }
        for f in &fractions {
            for v in values() {
                assert_eq!(from_bus(f, v), f.from_bus(v), "{f:?} from_bus({v})");
                assert_eq!(to_bus(f, v), f.to_bus(v), "{f:?} to_bus({v})");
            }
        }
    }

    /// P-214: the integer rpm conversions give the `f64` forms' results.
    #[test]
    fn p214_the_integer_rpm_conversions_equal_the_f64_ones() {
        for v in values() {
            assert_eq!(rpm_of(v), rpm_of_f64(v as f64), "rpm_of({v})");
            assert_eq!(
                increments_of_rpm(v),
                increments_of_rpm_f64(v),
                "increments_of_rpm({v})"
            );
        }
        // every tie region of small values, exhaustively
        for v in -300_000..300_000 {
            assert_eq!(rpm_of(v), rpm_of_f64(v as f64), "rpm_of({v})");
            assert_eq!(
                increments_of_rpm(v),
                increments_of_rpm_f64(v),
                "increments_of_rpm({v})"
            );
        }
    }

    /// P-214: with the identity user units the rates pass unchanged, as the
    /// `f64` forms give them; other units take the `f64` forms.
    #[test]
    fn p214_identity_user_units_pass_rates_unchanged() {
        let od = DriveObjects::new();
        let axis = Axis::new(0);
        let u = UserUnits::read(&od, &axis);
        assert!(u.is_identity());
        for v in values() {
            let f = v as f64;
            assert_eq!(
                velocity_from_increments(&u, v),
                u.velocity_from_increments(f),
                "{v}"
            );
            assert_eq!(
                acceleration_from_increments(&u, v),
                u.acceleration_from_increments(f)
            );
            assert_eq!(
                velocity_to_increments(&u, v),
                round_i64(u.velocity_to_increments(v))
            );
            assert_eq!(
                acceleration_to_increments(&u, v),
                round_i64(u.acceleration_to_increments(v))
            );
        }
    }

    /// P-214: a changed factor group is read again at the next conversion.
    #[test]
    fn p214_the_cache_follows_a_factor_group_change() {
        let mut od = DriveObjects::new();
        let axis = Axis::new(0);
        let mut cache = UnitsCache::new();
        assert!(cache.get(&od, &axis).is_identity());
        od.set(0x6092, 1, 1000).unwrap();
        let u = *cache.get(&od, &axis);
        assert_eq!(u, UserUnits::read(&od, &axis));
        assert!(!u.is_identity());
        od.set(0x6092, 1, 1 << 20).unwrap();
        assert!(cache.get(&od, &axis).is_identity());
        // the other axis' units are its own
        let b = Axis::new(1);
        od.set(b.cia402_index(0x607E), 0, 0x80).unwrap();
        assert!(!cache.get(&od, &b).is_identity());
        assert!(cache.get(&od, &axis).is_identity());
    }
}
