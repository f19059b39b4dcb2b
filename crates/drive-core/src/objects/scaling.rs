//! The entries fieldbus scaling A213 acts on (E-059, E-143, C-142; spec
//! `ethercat.md` §15, `cia402.md` §4.3): the velocity objects of an axis
//! count in its user units / 10^A310, its acceleration, deceleration and
//! jerk objects in user units / 10^A311, when the representation in force is
//! "integer with decimal places" (0); in "native" (1, the default) they count
//! in user units, the unit the declaration names.
//!
//! A213 has two elements: \[0\] for the process data, which is also the
//! representation the dictionary keeps the values in (the PDO copy moves
//! them as they are, the axis converts them to increments), \[1\] for the
//! parameter channel (SDO, the UDP parameter service), which converts
//! between the two when they differ (`dictionary/scaling.rs`).
//!
//! Every other entry has its fixed unit. Positions take their decimal
//! places through the feed constant 6092h (C-109: the feed is counted in the
//! smallest user unit), not through a separate I06.
//!
//! The table is checked against the declaration (every entry in inc/s,
//! inc/s² or inc/s³ is here, with its quantity) and against the axis (it
//! converts exactly these entries): `tests_scaling.rs`.

use super::records::{J401, J404};
use crate::params::{C40, I10, I12, I13, I18, I44, I45};

/// Which decimal places an entry takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// A velocity: A310.
    Velocity,
    /// An acceleration, deceleration or jerk: A311.
    Acceleration,
}

use Quantity::{Acceleration as ACC, Velocity as VEL};

/// The scaled entries of axis A: index, subindex in the "EtherCAT Rx SDO
/// Info" numbering (J401 element k at k + 1), quantity. Axis B's are at
/// +800h (CiA 402) and +8000h (J401, J404). Sorted by index.
pub const SCALED: [(u16, u8, Quantity); 27] = [
    (C40, 0, VEL),    // velocity window
    (I10, 0, VEL),    // maximal speed
    (I12, 0, VEL),    // jog velocity
    (I13, 0, ACC),    // jog acceleration
    (I18, 0, ACC),    // jog jerk
    (I44, 0, ACC),    // referencing jerk
    (I45, 0, ACC),    // jog deceleration
    (J401, 2, VEL),   // record data [1] profile velocity
    (J401, 3, VEL),   // record data [2] end velocity
    (J401, 4, ACC),   // record data [3] acceleration
    (J401, 5, ACC),   // record data [4] deceleration
    (J401, 6, ACC),   // record data [5] all accelerations
    (J404, 0, VEL),   // set-up speed
    (0x606C, 0, VEL), // velocity actual value
    (0x607F, 0, VEL), // max profile velocity
    (0x6081, 0, VEL), // profile velocity
    (0x6083, 0, ACC), // profile acceleration
    (0x6084, 0, ACC), // profile deceleration
    (0x6085, 0, ACC), // quick stop deceleration
    (0x6099, 1, VEL), // homing speed: search for switch
    (0x6099, 2, VEL), // homing speed: search for zero
    (0x609A, 0, ACC), // homing acceleration
    (0x60A4, 1, ACC), // profile jerk 1
    (0x60B1, 0, VEL), // velocity offset
    (0x60C5, 0, ACC), // max acceleration
    (0x60C6, 0, ACC), // max deceleration
    (0x60FF, 0, VEL), // target velocity
];

/// The axis (0 = A, 1 = B) and the quantity of `index`:`sub` ("EtherCAT Rx
/// SDO Info" numbering), if fieldbus scaling acts on it.
pub fn scaled(index: u16, sub: u8) -> Option<(u8, Quantity)> {
    let (axis, a) = match index {
        0x6800..=0x6FFF => (1, index - crate::AXIS_B_CIA402),
        0xA000..=0xDFFF => (1, index - crate::AXIS_B_MANUFACTURER),
        _ => (0, index),
    };
    SCALED
        .iter()
        .find(|&&(i, s, _)| i == a && s == sub)
        .map(|&(_, _, q)| (axis, q))
}
