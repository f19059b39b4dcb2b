//! Fieldbus scaling on the parameter channel (E-143, E-086; spec
//! `ethercat.md` §15): the values of the entries of
//! [`crate::objects::scaling::SCALED`] are kept in the representation of
//! A213\[0\] (the process data's); a parameter-channel access
//! ([`DriveObjects::parameter_channel`]: SDO, the UDP parameter service)
//! sees them in the representation of A213\[1\]. The two differ by a power of
//! ten, the decimal places A310 (velocities) or A311 (accelerations) of the
//! entry's axis; with A213\[0\] = A213\[1\] (both native by default) nothing
//! is converted.
//!
//! - Read: the kept value × 10^shift, saturated at the entry type's bounds
//!   (shift > 0), or ÷ 10^−shift rounded half away from zero (shift < 0).
//! - Write: the inverse; a product beyond the type is refused with 0609 0031h
//!   / 0609 0032h and changes nothing; a write of exactly what a read returns
//!   keeps the value (a read-modify-write or a refused complete access
//!   putting entries back loses no decimal).

use super::*;
use crate::objects::scaling::{scaled, Quantity};
use crate::params::{A213, A310, A311};

/// 10^0 … 10^9 (A310/A311 range 0…9).
const POW10: [i64; 10] = [
    1,
    10,
    100,
    1_000,
    10_000,
    100_000,
    1_000_000,
    10_000_000,
    100_000_000,
    1_000_000_000,
];

fn pow10(k: u32) -> i64 {
    POW10.get(k as usize).copied().unwrap_or(1_000_000_000)
}

/// `v` / `p` rounded half away from zero (`p` ≥ 1; checked, so no
/// division can panic: `p` < 1 gives `v`).
fn div_round(v: i64, p: i64) -> i64 {
    let (Some(q), Some(r)) = (v.checked_div(p), v.checked_rem(p)) else {
        return v;
    };
    if r.unsigned_abs() >= p.unsigned_abs() - r.unsigned_abs() {
        q.saturating_add(v.signum())
    } else {
        q
    }
}

/// The parameter channel's value of a kept value `stored` of type `t`
/// (channel = kept × 10^`shift`, saturated at the type's bounds).
fn to_channel(stored: i64, shift: i32, t: DataType) -> i64 {
    if shift >= 0 {
        stored
            .saturating_mul(pow10(shift.unsigned_abs()))
            .clamp(t.min_value(), t.max_value())
    } else {
        div_round(stored, pow10(shift.unsigned_abs()))
    }
}

/// The kept value of a parameter-channel value `value` (rounded half away
/// from zero for shift > 0; may lie beyond the entry's type for shift < 0,
/// which the range check then refuses).
fn from_channel(value: i64, shift: i32) -> i64 {
    if shift >= 0 {
        div_round(value, pow10(shift.unsigned_abs()))
    } else {
        value.saturating_mul(pow10(shift.unsigned_abs()))
    }
}

impl DriveObjects {
    /// The decimal shift of the parameter channel for the entry `index`:`sub`
    /// ("EtherCAT Rx SDO Info" numbering, aliases followed): its channel
    /// value is the kept value × 10^shift. 0 when A213\[0\] = A213\[1\] (a
    /// compare of two values, the common case) or the entry is not scaled.
    pub fn channel_shift(&self, index: u16, sub: u8) -> i32 {
        let process_data = self.get(A213, 1).unwrap_or(1);
        let channel = self.get(A213, 2).unwrap_or(1);
        if process_data == channel {
            return 0;
        }
        let Some((axis, quantity)) = scaled(index, sub) else {
            return 0;
        };
        let line = match quantity {
            Quantity::Velocity => A310,
            Quantity::Acceleration => A311,
        };
        let line = if axis == 0 {
            line
        } else {
            line.wrapping_add(crate::AXIS_B_MANUFACTURER)
        };
        let decimals = self.get(line, 0).unwrap_or(0).clamp(0, 9) as i32;
        let of = |a213: i64| if a213 == 0 { decimals } else { 0 };
        of(channel) - of(process_data)
    }

    /// A parameter-channel read's bytes `buf[..n]` of an entry of type `t`
    /// converted in place by `shift`; the byte count is the type's.
    pub(super) fn channel_read(buf: &mut [u8], n: usize, shift: i32, t: DataType) -> Result<usize, SdoAbort> {
        let kept = t.decode(buf.get(..n).ok_or(SdoAbort::GENERAL)?)?;
        t.encode(to_channel(kept, shift, t), buf)
    }

    /// The value to keep for a parameter-channel write of `value` to
    /// `target` (of type `t`) under `shift`: the present value when `value`
    /// is what a read returns now, else the converted value.
    pub(super) fn channel_write(
        &self,
        target: Loc,
        t: DataType,
        value: i64,
        shift: i32,
    ) -> Result<i64, SdoAbort> {
        let mut now = [0u8; 8];
        let n = self.read_loc(target, &mut now)?;
        let kept = t.decode(now.get(..n).ok_or(SdoAbort::GENERAL)?)?;
        Ok(if to_channel(kept, shift, t) == value {
            kept
        } else {
            from_channel(value, shift)
        })
    }
}
