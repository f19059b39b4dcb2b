//! The Example Function block's receive telegrams 0…2 as a controller writes
//! them ([`FB_DEFAULTS`](super::FB_DEFAULTS), spec §4.5, P-071…P-073): one
//! value per entry of the layout, placeholders 0 (P-064).
//!
//! For the host side of the drive (benchmarks, tests, the QEMU runs' scripted
//! controller): each `write` fills a caller's buffer and says how many bytes
//! it wrote, or `None` when the buffer is shorter than [`FB_RECEIVE_BYTES`].

use super::Dir;

/// The length of each of the Example Function block's receive telegrams 0…2
/// (18 words).
pub const FB_RECEIVE_BYTES: usize = 36;

/// Receive telegram 0 (positioning, 0xE0, P-071).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FbPositioning {
    /// Homing method (1050.0).
    pub homing_method: i8,
    /// CW1 (967.0).
    pub cw1: u16,
    /// Target position (1001.0).
    pub target: i32,
    /// Profile velocity (1001.1).
    pub profile_velocity: i32,
    /// End velocity (1001.2).
    pub end_velocity: i32,
    /// All accelerations (1001.5).
    pub accelerations: u32,
    /// Jog velocity (1040.0).
    pub jog_velocity: i32,
    /// The PKW request (2000.0).
    pub pkw: [u8; 8],
    /// Current limit (2415h.02).
    pub current_limit: i32,
}

/// Receive telegram 1 (speed, 0xE1, P-072).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FbSpeed {
    /// CW1 (967.0).
    pub cw1: u16,
    /// Target velocity (1010.0).
    pub velocity: i32,
    /// All accelerations (1011.2).
    pub accelerations: u32,
    /// Jog velocity (1040.0).
    pub jog_velocity: i32,
    /// The PKW request (2000.0).
    pub pkw: [u8; 8],
    /// Current limit (2415h.02).
    pub current_limit: i32,
}

/// Receive telegram 2 (torque, 0xE2, P-073).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FbTorque {
    /// CW1 (967.0).
    pub cw1: u16,
    /// Target torque (6071h).
    pub torque: i16,
    /// The PKW request (2000.0).
    pub pkw: [u8; 8],
    /// Speed limit (2416h.02).
    pub speed_limit: i32,
}

/// Telegrams 0…2 on their common grid (P-071…P-073): identifier `0xE0 + n`, a
/// 1-byte entry at 1, CW1 at 2, five 4-byte words at 4…23 (an entry or
/// placeholders), PKW at 24, a 4-byte entry at 32. All 36 bytes are written.
fn grid(
    out: &mut [u8],
    n: u8,
    byte1: i8,
    cw1: u16,
    words: [[u8; 4]; 5],
    pkw: [u8; 8],
    last: i32,
) -> Option<usize> {
    let t = out.get_mut(..FB_RECEIVE_BYTES)?;
    let ([b1], [c0, c1]) = (byte1.to_be_bytes(), cw1.to_be_bytes());
    t.get_mut(..4)?
        .copy_from_slice(&[Dir::Receive.identifier(n), b1, c0, c1]);
    for (at, w) in t.get_mut(4..24)?.chunks_exact_mut(4).zip(words) {
        at.copy_from_slice(&w);
    }
    t.get_mut(24..32)?.copy_from_slice(&pkw);
    t.get_mut(32..)?.copy_from_slice(&last.to_be_bytes());
    Some(FB_RECEIVE_BYTES)
}

impl FbPositioning {
    /// Writes the telegram into `out`: [`FB_RECEIVE_BYTES`], or `None` when
    /// `out` is shorter.
    pub fn write(&self, out: &mut [u8]) -> Option<usize> {
        let be = i32::to_be_bytes;
        let (target, v, end) = (be(self.target), be(self.profile_velocity), be(self.end_velocity));
        let words = [
            target,
            v,
            end,
            self.accelerations.to_be_bytes(),
            be(self.jog_velocity),
        ];
        grid(
            out,
            0,
            self.homing_method,
            self.cw1,
            words,
            self.pkw,
            self.current_limit,
        )
    }
}

impl FbSpeed {
    /// Writes the telegram into `out` (placeholders at 1, 8 and 12):
    /// [`FB_RECEIVE_BYTES`], or `None` when `out` is shorter.
    pub fn write(&self, out: &mut [u8]) -> Option<usize> {
        let acc = self.accelerations.to_be_bytes();
        let words = [
            self.velocity.to_be_bytes(),
            [0; 4],
            [0; 4],
            acc,
            self.jog_velocity.to_be_bytes(),
        ];
        grid(out, 1, 0, self.cw1, words, self.pkw, self.current_limit)
    }
}

impl FbTorque {
    /// Writes the telegram into `out` (placeholders at 1 and 6…23):
    /// [`FB_RECEIVE_BYTES`], or `None` when `out` is shorter.
    pub fn write(&self, out: &mut [u8]) -> Option<usize> {
        let [t0, t1] = self.torque.to_be_bytes();
        let words = [[t0, t1, 0, 0], [0; 4], [0; 4], [0; 4], [0; 4]];
        grid(out, 2, 0, self.cw1, words, self.pkw, self.speed_limit)
    }
}
