//! The PROFINET unit choices (spec §11, P-208…P-213) from A279: the codes
//! of the one object declaration turned into [`UnitSettings`], and the
//! profile's rule for a setting that does not convert (P-212): the error
//! the manual calls 22-4 (here event 70 "Parameter consistency", cause 4)
//! and the previous units kept.

use drive_core::params::A279;
use drive_core::DriveObjects;
use motion::units::{Dimension, Distance, Feed, Time, UnitError, UnitProfile, UnitSettings};
use motion::Event;

/// The error of a unit setting that does not convert (the manual's 22-4,
/// docs/conformance.md).
pub const UNIT_OVERFLOW: Event = Event { number: 70, cause: 4 };

/// A279's code for "unitless" (the feed unit).
pub const UNITLESS: u16 = 0xFFFF;

/// The seven elements of A279 as they stand.
pub type Codes = [u32; 7];

/// Why A279 gives no units.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChoiceError {
    /// A unit code names no unit.
    BadCode,
    /// The conversion refuses it (a factor of 0, a fraction beyond 32 bits).
    Conversion(UnitError),
}

/// A279's elements (the SDO Info view: element k is subindex k + 1).
pub fn read_codes(objects: &DriveObjects) -> Codes {
    let mut codes = [0u32; 7];
    for (k, c) in codes.iter_mut().enumerate() {
        let v = objects.get(A279, k as u8 + 1).unwrap_or(0);
        *c = u32::try_from(v).unwrap_or(0);
    }
    codes
}

/// A distance code: dimension × 0x100 + decimals (0…9).
fn distance(code: u32) -> Option<Distance> {
    let decimals = (code & 0xFF) as i8;
    if decimals > 9 {
        return None;
    }
    let dimension = match code >> 8 & 0x0F {
        0 => Dimension::Revolution,
        1 => Dimension::Degree,
        2 => Dimension::Metre,
        _ => return None,
    };
    Some(Distance {
        dimension,
        exponent: -decimals,
    })
}

/// A velocity or acceleration code: the distance, time base bit 0x1000.
fn with_time(code: u32) -> Option<(Distance, Time)> {
    if code & !0x1FFF != 0 {
        return None;
    }
    let time = if code & 0x1000 != 0 {
        Time::Minute
    } else {
        Time::Second
    };
    Some((distance(code & 0x0FFF)?, time))
}

/// The settings `codes` name.
pub fn settings(codes: &Codes) -> Result<UnitSettings, ChoiceError> {
    let [position, velocity, acceleration, gear_in, gear_out, feed, feed_unit] = *codes;
    let bad = ChoiceError::BadCode;
    if position & !0x0FFF != 0 {
        return Err(bad);
    }
    let position = distance(position).ok_or(bad)?;
    let (velocity, velocity_time) = with_time(velocity).ok_or(bad)?;
    let (acceleration, acceleration_time) = with_time(acceleration).ok_or(bad)?;
    let unit = if feed_unit == u32::from(UNITLESS) {
        None
    } else if feed_unit & !0x0FFF != 0 {
        return Err(bad);
    } else {
        Some(distance(feed_unit).ok_or(bad)?)
    };
    Ok(UnitSettings {
        position,
        velocity,
        velocity_time,
        acceleration,
        acceleration_time,
        gear_in,
        gear_out,
        feed: Feed { value: feed, unit },
    })
}

/// The unit profile `codes` give.
pub fn profile(codes: &Codes) -> Result<UnitProfile, ChoiceError> {
    UnitProfile::new(settings(codes)?).map_err(ChoiceError::Conversion)
}

/// What the profile keeps of A279 between cycles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct UnitChoice {
    /// The configuration generation A279 was last looked at.
    generation: Option<u32>,
    /// The codes last looked at.
    codes: Option<Codes>,
}

impl UnitChoice {
    /// A279 looked at again if the dictionary's configuration moved: the
    /// new units when they convert (`Ok(Some)`), `Err` once for each new
    /// setting that does not (the caller raises [`UNIT_OVERFLOW`] and keeps
    /// its units), `Ok(None)` when nothing changed.
    pub fn refresh(&mut self, objects: &DriveObjects) -> Result<Option<UnitProfile>, ChoiceError> {
        let g = objects.config_generation();
        if self.generation == Some(g) {
            return Ok(None);
        }
        self.generation = Some(g);
        let codes = read_codes(objects);
        if self.codes == Some(codes) {
            return Ok(None);
        }
        self.codes = Some(codes);
        profile(&codes).map(Some)
    }
}
