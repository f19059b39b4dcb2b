//! The Example Function block's telegrams (spec §4.5, App. 7.1; P-071…P-074):
//! the shipped defaults. All 36 bytes (18 words) in both directions;
//! telegram 3 is left empty (identifier only, no CW1: free format, Q-09).

use super::{Entries, TelegramSet, CW1, MAX_ENTRIES, PAD16, PAD32, PAD8, PKW, UNUSED, ZSW1};
use crate::Addr;

const fn a(index: u16, sub: u8) -> Addr {
    Addr::new(index, sub)
}

/// Receive telegram 0 (positioning, 0xE0, P-071): homing method 1050.0,
/// CW1, target position 1001.0, profile velocity 1001.1, end velocity
/// 1001.2, all accelerations 1001.5, jog velocity 1040.0, PKW, current
/// limit 2415h.02.
const RX0: Entries = [
    a(1050, 0),
    CW1,
    a(1001, 0),
    a(1001, 1),
    a(1001, 2),
    a(1001, 5),
    a(1040, 0),
    PKW,
    a(0x2415, 2),
    UNUSED,
];

/// Receive telegram 1 (speed, 0xE1, P-072): placeholder, CW1, target
/// velocity 1010.0, two 4-byte placeholders, all accelerations 1011.2, jog
/// velocity 1040.0, PKW, current limit 2415h.02.
const RX1: Entries = [
    PAD8,
    CW1,
    a(1010, 0),
    PAD32,
    PAD32,
    a(1011, 2),
    a(1040, 0),
    PKW,
    a(0x2415, 2),
    UNUSED,
];

/// Receive telegram 2 (torque, 0xE2, P-073): placeholder (2010.0, E-15),
/// CW1, target torque 6071h, 2010.1, four 2010.2, PKW, speed limit 2416h.02.
const RX2: Entries = [
    PAD8,
    CW1,
    a(0x6071, 0),
    PAD16,
    PAD32,
    PAD32,
    PAD32,
    PAD32,
    PKW,
    a(0x2416, 2),
];

/// Response telegrams 0…2 (P-074): operating mode 1500.0, ZSW1, position
/// 1100.0, velocity 1101.0, torque 6077h, digital inputs 1141.0, 2010.1,
/// 2010.2, PKW, 2010.2.
const TX: Entries = [
    a(1500, 0),
    ZSW1,
    a(1100, 0),
    a(1101, 0),
    a(0x6077, 0),
    a(1141, 0),
    PAD16,
    PAD32,
    PKW,
    PAD32,
];

const EMPTY: Entries = [UNUSED; MAX_ENTRIES];

/// The shipped telegram set: the Example Function block's layouts; receive
/// n answered by response n.
pub const FB_DEFAULTS: TelegramSet = TelegramSet {
    receive: [RX0, RX1, RX2, EMPTY],
    response: [TX, TX, TX, EMPTY],
    associated: [0, 1, 2, 3],
};
