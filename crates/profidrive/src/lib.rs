//! The PROFIdrive-style profile of the Metronix PROFINET manual
//! (`shared/spec/profidrive.md`), as a thin personality over the
//! fieldbus-neutral drive core (spec §16): what is PROFIdrive-only and does
//! not know the drive's objects.
//!
//! - [`telegram`]: the four receive and four response telegrams (P-047…P-075):
//!   configuration and its checks, layouts, the per-cycle receive/response
//!   path (big-endian, CW1 returned to be applied last), the Example Function
//!   block's layouts as the shipped defaults, a checked byte form for storage.
//! - [`pkw`]: the PNU 2000 mailbox over the cyclic channel (P-191…P-198).
//! - [`cw1`] / [`zsw1`]: control word 1 to the CiA 402 controlword bits and
//!   the mode-dependent commands; status word 1 from a fieldbus-neutral
//!   status (P-076…P-109).
//! - [`bmp`]: the standard PROFIdrive Base Mode Parameter access of record
//!   0xB02E (P-206).
//!
//! The seam to the drive is [`ParamAccess`]: describe, read and write an
//! address ([`Addr`]: PNUs below 0x1000 and CANopen indices from 0x1000 up
//! share one 16-bit index space, P-057) with PROFIdrive error numbers
//! ([`PdError`]). The placeholders 2010.x/2011.0 and the PKW channel 2000.0
//! are this crate's own and never reach the access.
//!
//! `#![no_std]`, heap-free; no path that bus bytes reach can panic.
#![no_std]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]
#![deny(missing_docs)]

pub mod bmp;
pub mod cw1;
pub mod pkw;
pub mod telegram;
pub mod zsw1;

pub use od::DataType;

#[cfg(test)]
extern crate std;
#[cfg(test)]
mod fake;
#[cfg(test)]
mod tests_bmp;
#[cfg(test)]
mod tests_cw;
#[cfg(test)]
mod tests_pkw;
#[cfg(test)]
mod tests_random;
#[cfg(test)]
mod tests_telegram;
#[cfg(test)]
mod tests_tshark;

/// A parameter address: PNU or CANopen index, and subindex (P-057).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub struct Addr {
    /// PNU (< 0x1000) or CANopen index (≥ 0x1000).
    pub index: u16,
    /// Subindex.
    pub sub: u8,
}

impl Addr {
    /// `index`.`sub`.
    pub const fn new(index: u16, sub: u8) -> Self {
        Self { index, sub }
    }
}

/// A PROFIdrive error number (spec §9.3; PROFIdrive 3.1 parameter access).
/// Numbers from 0x65 on are manufacturer-specific; the ones this crate uses
/// there are its own (docs/conformance.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PdError(pub u16);

impl PdError {
    /// 0x00 impermissible parameter number (no such object).
    pub const IMPERMISSIBLE_PNU: Self = Self(0x00);
    /// 0x01 parameter value cannot be changed (read-only).
    pub const CANNOT_CHANGE: Self = Self(0x01);
    /// 0x02 low or high limit exceeded.
    pub const LIMIT_EXCEEDED: Self = Self(0x02);
    /// 0x03 faulty subindex.
    pub const FAULTY_SUBINDEX: Self = Self(0x03);
    /// 0x04 no array.
    pub const NO_ARRAY: Self = Self(0x04);
    /// 0x05 incorrect data type.
    pub const INCORRECT_DATA_TYPE: Self = Self(0x05);
    /// 0x06 setting not permitted (may only be reset).
    pub const ONLY_RESET: Self = Self(0x06);
    /// 0x07 description element cannot be changed.
    pub const DESCRIPTION_READ_ONLY: Self = Self(0x07);
    /// 0x09 no description data available.
    pub const NO_DESCRIPTION: Self = Self(0x09);
    /// 0x0B no operation priority.
    pub const NO_PRIORITY: Self = Self(0x0B);
    /// 0x0F no text array available.
    pub const NO_TEXT: Self = Self(0x0F);
    /// 0x11 request not executable in the current operating state.
    pub const NOT_IN_STATE: Self = Self(0x11);
    /// 0x14 value impermissible.
    pub const VALUE_IMPERMISSIBLE: Self = Self(0x14);
    /// 0x15 response too long.
    pub const RESPONSE_TOO_LONG: Self = Self(0x15);
    /// 0x16 parameter address impermissible (attribute, number of elements,
    /// PNU or subindex).
    pub const ADDRESS_IMPERMISSIBLE: Self = Self(0x16);
    /// 0x17 illegal format.
    pub const ILLEGAL_FORMAT: Self = Self(0x17);
    /// 0x18 number of values inconsistent.
    pub const VALUES_INCONSISTENT: Self = Self(0x18);
    /// 0x19 drive object does not exist.
    pub const NO_DRIVE_OBJECT: Self = Self(0x19);
    /// 0x65 (ours) request reference 0.
    pub const BAD_REFERENCE: Self = Self(0x65);
    /// 0x66 (ours) request ID other than 0x01/0x02.
    pub const BAD_REQUEST_ID: Self = Self(0x66);
    /// 0x67 (ours) number of parameters 0 or more than 39.
    pub const BAD_PARAMETER_COUNT: Self = Self(0x67);
    /// 0x68 (ours) request length does not match its addresses and values.
    pub const BAD_LENGTH: Self = Self(0x68);
}

/// What [`ParamAccess::describe`] tells about an address.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Describe {
    /// Data type (its size is the size in the telegram: 1, 2, 4 or 8 bytes).
    pub data_type: DataType,
    /// Readable over the bus.
    pub readable: bool,
    /// Writable over the bus.
    pub writable: bool,
}

/// How far a write got.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Completion {
    /// Done.
    Done,
    /// Accepted and still running (e.g. PNU 971 save): ask again with
    /// [`ParamAccess::poll_write`].
    Pending,
}

/// The drive's parameters as the profile sees them.
///
/// Values are integers, sign- or zero-extended by the data type from
/// [`describe`](Self::describe); the crate checks the value fits the type
/// before a write (0x02 otherwise). The implementation checks range,
/// state and everything else and answers with a PROFIdrive error number;
/// a refused write changes nothing.
pub trait ParamAccess {
    /// Type and access rights of `addr`; 0x00 when the object does not
    /// exist, 0x03 when the object exists without this subindex.
    fn describe(&self, addr: Addr) -> Result<Describe, PdError>;

    /// The value of `addr`.
    fn read(&mut self, addr: Addr) -> Result<i64, PdError>;

    /// Writes `value` to `addr`. `cyclic`: from a receive telegram, every
    /// cycle: RAM only, never non-volatile memory (P-067).
    fn write(&mut self, addr: Addr, value: i64, cyclic: bool) -> Result<Completion, PdError>;

    /// Asks again about a write that answered [`Completion::Pending`].
    fn poll_write(&mut self, addr: Addr) -> Result<Completion, PdError> {
        let _ = addr;
        Ok(Completion::Done)
    }

    /// Does drive object `do_id` exist (BMP request, P-206)? The
    /// implementation may select the axis it stands for. Default: 0 and 1.
    fn drive_object(&mut self, do_id: u8) -> bool {
        do_id <= 1
    }
}

/// Size in bytes of `t` in telegrams and the PKW channel: integers only
/// (BOOLEAN takes one byte); anything else is 0x05.
pub(crate) fn int_size(t: DataType) -> Result<usize, PdError> {
    match t {
        DataType::Bool | DataType::I8 | DataType::U8 => Ok(1),
        DataType::I16 | DataType::U16 => Ok(2),
        DataType::I32 | DataType::U32 => Ok(4),
        DataType::I64 | DataType::U64 => Ok(8),
        _ => Err(PdError::INCORRECT_DATA_TYPE),
    }
}

/// Big-endian decode of `bytes` (1…8) as `t`: sign-extended for signed
/// types, zero-extended otherwise. Two and four bytes (nearly every
/// telegram entry) without the byte loop's 64-bit shifts (issue 36).
pub(crate) fn decode_be(t: DataType, bytes: &[u8]) -> i64 {
    match *bytes {
        [a, b] => {
            let v = u16::from_be_bytes([a, b]);
            if t.signed() {
                i64::from(v as i16)
            } else {
                i64::from(v)
            }
        }
        [a, b, c, d] => {
            let v = u32::from_be_bytes([a, b, c, d]);
            if t.signed() {
                i64::from(v as i32)
            } else {
                i64::from(v)
            }
        }
        _ => decode_be_any(t, bytes),
    }
}

/// [`decode_be`] of any length, byte by byte.
fn decode_be_any(t: DataType, bytes: &[u8]) -> i64 {
    let mut v: u64 = 0;
    for b in bytes.iter().take(8) {
        v = (v << 8) | u64::from(*b);
    }
    let n = bytes.len().min(8) as u32;
    if t.signed() && (1..8).contains(&n) {
        let shift = 64 - 8 * n;
        ((v << shift) as i64) >> shift
    } else {
        v as i64
    }
}

/// Big-endian encode of `value` into `out` (its low `out.len()` bytes);
/// two and four bytes without the byte loop (issue 36).
pub(crate) fn encode_be(value: i64, out: &mut [u8]) {
    if let Ok(o) = <&mut [u8; 2]>::try_from(&mut *out) {
        *o = (value as u16).to_be_bytes();
    } else if let Ok(o) = <&mut [u8; 4]>::try_from(&mut *out) {
        *o = (value as u32).to_be_bytes();
    } else {
        encode_be_any(value, out);
    }
}

/// [`encode_be`] of any length, byte by byte.
fn encode_be_any(value: i64, out: &mut [u8]) {
    let n = out.len();
    for (i, b) in out.iter_mut().enumerate() {
        let shift = 8 * (n - 1 - i);
        *b = if shift < 64 { (value >> shift) as u8 } else { 0 };
    }
}

/// Does `value` fit `t` (integers; BOOLEAN is 0 or 1)? (Inlined: every
/// entry of a receive telegram asks, every cycle.)
#[inline]
pub(crate) fn fits(t: DataType, value: i64) -> bool {
    match t {
        DataType::Bool => value == 0 || value == 1,
        DataType::U64 => true,
        _ => t.is_integer() && value >= t.min_value() && value <= t.max_value(),
    }
}

#[cfg(test)]
mod tests_be {
    use super::*;

    /// The types a telegram slot can hold (BOOLEAN and the integers).
    pub(crate) const SLOT_TYPES: [DataType; 9] = [
        DataType::Bool,
        DataType::I8,
        DataType::U8,
        DataType::I16,
        DataType::U16,
        DataType::I32,
        DataType::U32,
        DataType::I64,
        DataType::U64,
    ];

    /// The two- and four-byte paths decode and encode as the byte loop.
    #[test]
    fn be_widths_answer_as_the_byte_loop() {
        let types = SLOT_TYPES;
        let values = [
            0i64,
            1,
            -1,
            0x7F,
            0x80,
            0x7FFF,
            0x8000,
            -0x8000,
            0xFFFF,
            0x1234_5678,
            i64::from(i32::MIN),
            i64::from(u32::MAX),
            i64::MIN,
            i64::MAX,
        ];
        for v in values {
            for n in 1..=8 {
                let (mut fast, mut slow) = ([0u8; 8], [0u8; 8]);
                encode_be(v, &mut fast[..n]);
                encode_be_any(v, &mut slow[..n]);
                assert_eq!(fast, slow, "{v} in {n}");
                for t in types {
                    assert_eq!(
                        decode_be(t, &fast[..n]),
                        decode_be_any(t, &fast[..n]),
                        "{t:?} {n} {v}"
                    );
                }
            }
        }
    }
}
