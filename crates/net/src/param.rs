//! The UDP parameter service: reads and writes parameters by their
//! coordinate (`A150`, `A199[1]`, `2.I10`) through the object dictionary
//! with exactly the SDO access rules and abort codes (docs/eoe.md).
//!
//! One request per datagram, ASCII, answered by one datagram:
//!
//! | request | answer |
//! |---|---|
//! | `R <coord>` | `OK <value>` or `ERR <abort code, 8 hex digits>` |
//! | `W <coord> <value>` | `OK` or `ERR <abort code>` |
//! | `M <coord>` | `OK <index hex>:<subindex hex>` (the CoE address, no access) |
//! | anything else | `ERR SYNTAX` (nothing read or written) |
//!
//! Coordinates: `[<axis>.]<group letter><line>[<element>]`: axis 1 (A,
//! default) or 2 (B), group A..Z, line 0..511, element 0..255. CoE address
//! per spec §2.6: index = 2000h + group·200h + line (+8000h for axis 2);
//! subindex 0 without element, else the element ("EtherCAT Rx") or the
//! element + 1 ("EtherCAT Rx SDO Info", [`od::Dictionary::sdo_info_enabled`]).
//!
//! Values: integers in decimal (or `0x` hex on writes), REAL32 as a decimal
//! fraction, VISIBLE_STRING as its text (the rest of the request on writes),
//! OCTET_STRING as hex digits.

use core::fmt::Write as _;
use od::{CommState, DataType, Dictionary, SdoAbort};

/// UDP port of the parameter service.
pub const PARAM_PORT: u16 = 5011;
/// Largest request and answer, bytes.
pub const MAX_MESSAGE: usize = 300;
/// Largest value read (a longer string is refused with 0504 0005h).
const MAX_VALUE: usize = 128;

/// What the service may do (docs/eoe.md, "Who may write"). Reads always
/// go through (with the dictionary's access level, A10\[2\]); writes only
/// when the device allows them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Policy {
    /// Writes allowed (the drive's A269 = 1); off: every `W` is refused
    /// with [`WRITES_OFF`] and nothing is written.
    pub writes: bool,
    /// An index the service never writes, whatever `writes` says (the
    /// switch itself: only CoE opens the service), 0601 0002h.
    pub guard: Option<u16>,
}

/// The abort a write gets while writes are off: 0601 0000h "unsupported
/// access to an object" (the object may be writable, not through here).
pub const WRITES_OFF: SdoAbort = SdoAbort(0x0601_0000);

/// How a request was answered (the stack counts them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Read, written or mapped, or refused by the dictionary with its abort.
    Served,
    /// Not a request (`ERR SYNTAX`).
    Malformed,
    /// A write refused by the [`Policy`].
    WriteRefused,
}

/// A parameter coordinate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Coordinate {
    /// Axis: 0 = A (and the global parameters), 1 = B.
    pub axis: u8,
    /// Group number (A = 0 … Z = 25).
    pub group: u8,
    /// Line 0..511.
    pub line: u16,
    /// Array/record element.
    pub element: Option<u8>,
}

impl Coordinate {
    /// Parses `[1.|2.]<letter><line>[<element>]` (`None` when malformed).
    pub fn parse(s: &str) -> Option<Self> {
        let b = s.as_bytes();
        let (axis, rest) = match b {
            [a @ (b'1' | b'2'), b'.', rest @ ..] => (a - b'1', rest),
            _ => (0, b),
        };
        let (&letter, rest) = rest.split_first()?;
        let letter = letter.to_ascii_uppercase();
        if !letter.is_ascii_uppercase() {
            return None;
        }
        let group = letter - b'A';
        let digits = rest.iter().take_while(|c| c.is_ascii_digit()).count();
        let (line, rest) = rest.split_at_checked(digits)?;
        let line = parse_dec(line).filter(|&l| l < 512)? as u16;
        let element = match rest {
            [] => None,
            [b'[', inner @ .., b']'] => Some(parse_dec(inner).filter(|&e| e < 256)? as u8),
            _ => return None,
        };
        Some(Self {
            axis,
            group,
            line,
            element,
        })
    }

    /// The CoE address (spec §2.6) in the template `sdo_info`; `None` when
    /// the element has no subindex (element 255 with SDO Info).
    pub fn address(&self, sdo_info: bool) -> Option<(u16, u8)> {
        let index = 0x2000u16 + u16::from(self.group) * 0x200 + self.line;
        let index = if self.axis == 1 { index + 0x8000 } else { index };
        let sub = match self.element {
            None => 0,
            Some(e) if sdo_info => e.checked_add(1)?,
            Some(e) => e,
        };
        Some((index, sub))
    }
}

/// Decimal digits (1..=6 of them) as a number.
fn parse_dec(d: &[u8]) -> Option<u32> {
    if d.is_empty() || d.len() > 6 || !d.iter().all(u8::is_ascii_digit) {
        return None;
    }
    Some(d.iter().fold(0u32, |v, c| v * 10 + u32::from(c - b'0')))
}

/// An integer in decimal or `0x` hex, optionally negative.
fn parse_int(s: &str) -> Option<i128> {
    let (neg, s) = match s.strip_prefix('-') {
        Some(r) => (true, r),
        None => (false, s),
    };
    let v = match s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")) {
        Some(h) if !h.is_empty() && h.len() <= 16 => u64::from_str_radix(h, 16).ok()?,
        Some(_) => return None,
        None if !s.is_empty() && s.len() <= 20 => s.parse::<u64>().ok()?,
        None => return None,
    };
    let v = i128::from(v);
    Some(if neg { -v } else { v })
}

/// An answer being written into a fixed buffer.
struct Out<'a> {
    buf: &'a mut [u8],
    len: usize,
}

impl core::fmt::Write for Out<'_> {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        let end = self.len.checked_add(s.len()).ok_or(core::fmt::Error)?;
        let dst = self.buf.get_mut(self.len..end).ok_or(core::fmt::Error)?;
        dst.copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}

/// Handles one request under `policy` and writes the answer into `out`;
/// returns its length (0 only when `out` cannot hold even an error answer)
/// and how it was answered.
pub fn handle<D: Dictionary + ?Sized>(
    request: &[u8],
    out: &mut [u8],
    dict: &mut D,
    state: CommState,
    policy: Policy,
) -> (usize, Outcome) {
    let mut o = Out { buf: out, len: 0 };
    let r = answer(request, &mut o, dict, state, policy);
    let mut outcome = Outcome::Served;
    let r = match r {
        Ok(()) => Ok(()),
        Err(e) => {
            o.len = 0;
            match e {
                Error::Syntax => {
                    outcome = Outcome::Malformed;
                    o.write_str("ERR SYNTAX")
                }
                Error::Refused(a) => {
                    outcome = Outcome::WriteRefused;
                    write!(o, "ERR {:08X}", a.0)
                }
                Error::Abort(a) => write!(o, "ERR {:08X}", a.0),
            }
        }
    };
    if r.is_err() {
        o.len = 0;
        if o.write_str("ERR 05040005").is_err() {
            return (0, outcome);
        }
    }
    (o.len, outcome)
}

enum Error {
    Syntax,
    Abort(SdoAbort),
    /// A write the policy refuses.
    Refused(SdoAbort),
}

impl From<SdoAbort> for Error {
    fn from(a: SdoAbort) -> Self {
        Error::Abort(a)
    }
}

impl From<core::fmt::Error> for Error {
    fn from(_: core::fmt::Error) -> Self {
        Error::Abort(SdoAbort::OUT_OF_MEMORY)
    }
}

fn answer<D: Dictionary + ?Sized>(
    request: &[u8],
    o: &mut Out<'_>,
    dict: &mut D,
    state: CommState,
    policy: Policy,
) -> Result<(), Error> {
    let text = core::str::from_utf8(request).map_err(|_| Error::Syntax)?;
    let text = text.trim_end_matches(['\r', '\n', '\0']);
    let (cmd, rest) = text.split_once(' ').unwrap_or((text, ""));
    let (coord, value) = rest.split_once(' ').unwrap_or((rest, ""));
    let coord = Coordinate::parse(coord).ok_or(Error::Syntax)?;
    let (index, sub) = coord
        .address(dict.sdo_info_enabled())
        .ok_or(Error::Abort(SdoAbort::NO_SUBINDEX))?;
    let ty = dict.object(index).and_then(|o| o.entry(sub)).map(|e| e.data_type);
    match cmd {
        "R" | "r" if value.is_empty() => {
            let mut buf = [0u8; MAX_VALUE];
            let n = dict.read(index, sub, &mut buf, state)?;
            let data = buf.get(..n).ok_or(Error::Abort(SdoAbort::OUT_OF_MEMORY))?;
            o.write_str("OK ")?;
            format_value(o, ty, data)
        }
        "W" | "w" if !value.is_empty() => {
            if policy.guard == Some(index) {
                return Err(Error::Refused(SdoAbort::READ_ONLY));
            }
            if !policy.writes {
                return Err(Error::Refused(WRITES_OFF));
            }
            let mut buf = [0u8; MAX_VALUE];
            let n = encode_value(ty, value, &mut buf)?;
            let data = buf.get(..n).ok_or(Error::Abort(SdoAbort::OUT_OF_MEMORY))?;
            dict.write(index, sub, data, state)?;
            Ok(o.write_str("OK")?)
        }
        "M" | "m" if value.is_empty() => {
            // only an address the device has (as an SDO would find it): not
            // one of a hidden parameter or of axis B on the single-axis device
            let object = dict.object(index).ok_or(Error::Abort(SdoAbort::NO_OBJECT))?;
            object.entry(sub).ok_or(Error::Abort(SdoAbort::NO_SUBINDEX))?;
            Ok(write!(o, "OK {index:04X}:{sub:02X}")?)
        }
        _ => Err(Error::Syntax),
    }
}

fn format_value(o: &mut Out<'_>, ty: Option<DataType>, data: &[u8]) -> Result<(), Error> {
    match ty {
        Some(DataType::VisibleString(_)) => {
            let end = data.iter().position(|&b| b == 0).unwrap_or(data.len());
            for &b in data.get(..end).unwrap_or_default() {
                let c = if b.is_ascii_graphic() || b == b' ' {
                    b as char
                } else {
                    '?'
                };
                o.write_char(c)?;
            }
            Ok(())
        }
        Some(DataType::F32) => {
            let v = u32::from_le_bytes(le4(data));
            Ok(crate::real::write_f32(o, f32::from_bits(v))?)
        }
        Some(DataType::U64) => {
            let mut raw = [0u8; 8];
            for (d, s) in raw.iter_mut().zip(data) {
                *d = *s;
            }
            Ok(write!(o, "{}", u64::from_le_bytes(raw))?)
        }
        Some(t) if t.is_integer() => {
            let v = t.decode(data)?;
            Ok(write!(o, "{v}")?)
        }
        // OCTET_STRING, or no metadata: hex
        _ => {
            for b in data {
                write!(o, "{b:02X}")?;
            }
            Ok(())
        }
    }
}

fn le4(data: &[u8]) -> [u8; 4] {
    let mut raw = [0u8; 4];
    for (d, s) in raw.iter_mut().zip(data) {
        *d = *s;
    }
    raw
}

/// Encodes the value text for an entry of type `ty` (unknown entry: a
/// 4-byte integer, which the dictionary refuses with its abort code).
fn encode_value(ty: Option<DataType>, value: &str, buf: &mut [u8]) -> Result<usize, Error> {
    match ty {
        Some(DataType::VisibleString(_)) => {
            let dst = buf
                .get_mut(..value.len())
                .ok_or(Error::Abort(SdoAbort::LENGTH_TOO_HIGH))?;
            dst.copy_from_slice(value.as_bytes());
            Ok(value.len())
        }
        Some(DataType::OctetString(_)) => {
            let hex = value.as_bytes();
            if hex.len() % 2 != 0 {
                return Err(Error::Syntax);
            }
            let n = hex.len() / 2;
            let dst = buf.get_mut(..n).ok_or(Error::Abort(SdoAbort::LENGTH_TOO_HIGH))?;
            for (d, pair) in dst.iter_mut().zip(hex.chunks_exact(2)) {
                let s = core::str::from_utf8(pair).map_err(|_| Error::Syntax)?;
                *d = u8::from_str_radix(s, 16).map_err(|_| Error::Syntax)?;
            }
            Ok(n)
        }
        Some(DataType::F32) => {
            let v = crate::real::parse_f32(value).ok_or(Error::Syntax)?;
            let dst = buf.get_mut(..4).ok_or(Error::Abort(SdoAbort::OUT_OF_MEMORY))?;
            dst.copy_from_slice(&v.to_bits().to_le_bytes());
            Ok(4)
        }
        ty => {
            let t = ty.unwrap_or(DataType::I32);
            let v = parse_int(value).ok_or(Error::Syntax)?;
            let (lo, hi) = match t {
                DataType::U64 => (0, i128::from(u64::MAX)),
                t => (i128::from(t.min_value()), i128::from(t.max_value())),
            };
            if v < lo || v > hi {
                // does not fit the type: refused like an out-of-range value
                return Err(Error::Abort(if v < lo {
                    SdoAbort::VALUE_TOO_LOW
                } else {
                    SdoAbort::VALUE_TOO_HIGH
                }));
            }
            let n = t.bytes();
            let bytes = (v as u64).to_le_bytes();
            let dst = buf.get_mut(..n).ok_or(Error::Abort(SdoAbort::OUT_OF_MEMORY))?;
            dst.copy_from_slice(bytes.get(..n).ok_or(Error::Abort(SdoAbort::OUT_OF_MEMORY))?);
            Ok(n)
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    extern crate std;
    use super::*;
    use drive_ecat::dictionary::DriveObjects;
    use std::string::String;

    const OPEN: Policy = Policy {
        writes: true,
        guard: None,
    };

    fn ask_with(d: &mut DriveObjects, req: &str, state: CommState, policy: Policy) -> (String, Outcome) {
        let mut out = [0u8; MAX_MESSAGE];
        let (n, outcome) = handle(req.as_bytes(), &mut out, d, state, policy);
        (String::from_utf8(out[..n].to_vec()).unwrap(), outcome)
    }

    fn ask(d: &mut DriveObjects, req: &str, state: CommState) -> String {
        ask_with(d, req, state, OPEN).0
    }

    /// E-101 (the service DS6's role takes over the gateway): reads always,
    /// writes only with the policy's consent, the guard never; a refused
    /// write changes nothing and is told apart from a malformed request.
    #[test]
    fn e101_writes_only_when_the_policy_allows_and_never_the_guard() {
        let mut d = DriveObjects::new();
        let pre = CommState::PreOp;
        let closed = Policy {
            writes: false,
            guard: Some(0x2000 + 269),
        };
        assert_eq!(
            ask_with(&mut d, "R A150", pre, closed),
            ("OK 1000".into(), Outcome::Served)
        );
        assert_eq!(
            ask_with(&mut d, "W A150 2000", pre, closed),
            ("ERR 06010000".into(), Outcome::WriteRefused)
        );
        assert_eq!(ask(&mut d, "R A150", pre), "OK 1000", "nothing written");
        assert_eq!(
            ask_with(&mut d, "W A150", pre, closed),
            ("ERR SYNTAX".into(), Outcome::Malformed)
        );
        let open = Policy {
            writes: true,
            ..closed
        };
        assert_eq!(
            ask_with(&mut d, "W A150 2000", pre, open),
            ("OK".into(), Outcome::Served)
        );
        assert_eq!(ask(&mut d, "R A150", pre), "OK 2000");
        // the switch itself: never through here, open or not
        for p in [closed, open] {
            assert_eq!(
                ask_with(&mut d, "W A269 1", pre, p),
                ("ERR 06010002".into(), Outcome::WriteRefused)
            );
        }
        assert_eq!(ask(&mut d, "R A269", pre), "OK 0");
        // a refused dictionary write is served (its abort), not a policy refusal
        assert_eq!(
            ask_with(&mut d, "W E50 XY", pre, open),
            ("ERR 06010002".into(), Outcome::Served)
        );
    }

    #[test]
    fn e009_e010_e012_e013_coordinates_map_to_coe_addresses() {
        let c = Coordinate::parse("A150").unwrap();
        assert_eq!(c.address(true), Some((0x2096, 0)));
        let c = Coordinate::parse("A199[1]").unwrap();
        assert_eq!(c.address(true), Some((0x20C7, 2)));
        assert_eq!(c.address(false), Some((0x20C7, 1)));
        // E200[0] -> 28C8h / A8C8h (spec §2.6 example)
        for (text, sdo_info, address) in [
            ("E200[0]", false, (0x28C8, 0)),
            ("2.E200[0]", true, (0xA8C8, 1)),
            ("2.I10", true, (0xB00A, 0)),
            ("1.z511", true, (0x53FF, 0)),
        ] {
            assert_eq!(
                Coordinate::parse(text).unwrap().address(sdo_info),
                Some(address),
                "{text}"
            );
        }
        assert_eq!(Coordinate::parse("A1[255]").unwrap().address(true), None);
        for bad in [
            "", "A", "3.A1", "A512", "AA1", "A1[", "A1[256]", "A1[]", "A1x", "1A1", "A-1", "é1", "A1[1]x",
        ] {
            assert_eq!(Coordinate::parse(bad), None, "{bad}");
        }
    }

    #[test]
    fn e096_parameter_service_reads_and_writes_through_the_dictionary() {
        let mut d = DriveObjects::new();
        let pre = CommState::PreOp;
        assert_eq!(ask(&mut d, "R A150", pre), "OK 1000");
        assert_eq!(ask(&mut d, "M A199[1]", pre), "OK 20C7:02");
        assert_eq!(ask(&mut d, "W A199[1] 0x0A000002\n", pre), "OK");
        assert_eq!(ask(&mut d, "R A199[1]", pre), "OK 167772162");
        // unknown object, unknown element
        assert_eq!(ask(&mut d, "R A511", pre), "ERR 06020000");
        assert_eq!(ask(&mut d, "W A511 1", pre), "ERR 06020000");
        assert_eq!(ask(&mut d, "R A199[9]", pre), "ERR 06090011");
        // does not fit the type (U8): refused, nothing changed
        assert_eq!(ask(&mut d, "W A166 256", pre), "ERR 06090031");
        assert_eq!(ask(&mut d, "W A166 -1", pre), "ERR 06090032");
        // the dictionary's range check
        assert_eq!(ask(&mut d, "W A166 3", pre), "ERR 06090031");
        assert_eq!(ask(&mut d, "R A166", pre), "OK 2");
        // malformed requests change nothing
        for bad in [
            "",
            "X A166",
            "W A166",
            "W A166 x",
            "R A166 1",
            "W A166 0x",
            "W",
            "\u{0}\u{ff}",
        ] {
            assert_eq!(ask(&mut d, bad, pre), "ERR SYNTAX", "{bad:?}");
        }
        let mut out = [0u8; MAX_MESSAGE];
        assert_eq!(
            handle(&[0xFF, 0xFE], &mut out, &mut d, pre, OPEN),
            (10, Outcome::Malformed)
        );
        assert_eq!(ask(&mut d, "R A166", pre), "OK 2");
        // a string
        assert_eq!(ask(&mut d, "R E50", pre), "OK SC6");
        assert_eq!(ask(&mut d, "W E50 XY", pre), "ERR 06010002");
        // global parameters only in the axis-A window
        assert_eq!(ask(&mut d, "R 2.A150", pre), "ERR 06020000");
        // the state rule: A225 (= 1600h) is writable in Pre-Op only, and the
        // answer is the abort an SDO download gets
        let sdo = d
            .write(0x20E1, 1, &0x6040_0010u32.to_le_bytes(), CommState::Op)
            .unwrap_err();
        assert_eq!(
            ask(&mut d, "W A225[0] 0x60400010", CommState::Op),
            std::format!("ERR {:08X}", sdo.0)
        );
        assert_eq!(sdo, SdoAbort::DEVICE_STATE);
        // an answer buffer too small
        assert_eq!(handle(b"R A150", &mut [0u8; 4], &mut d, pre, OPEN).0, 0);
    }

    #[test]
    fn e096_mapping_answers_only_addresses_the_device_has() {
        let pre = CommState::PreOp;
        let mut double = DriveObjects::new();
        assert_eq!(ask(&mut double, "M 2.E200[0]", pre), "OK A8C8:01");
        assert_eq!(ask(&mut double, "M A511", pre), "ERR 06020000");
        assert_eq!(ask(&mut double, "M A199[9]", pre), "ERR 06090011");
        assert_eq!(ask(&mut double, "M 2.A150", pre), "ERR 06020000");
        // the single-axis device has no axis-B window (issue 20)
        let mut single = DriveObjects::for_variant(drive_ecat::Variant::Single);
        assert_eq!(ask(&mut single, "M E200[0]", pre), "OK 28C8:01");
        assert_eq!(ask(&mut single, "M 2.E200[0]", pre), "ERR 06020000");
        assert_eq!(ask(&mut single, "R 2.E200[0]", pre), "ERR 06020000");
    }
}
