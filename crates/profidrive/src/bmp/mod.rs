//! PROFIdrive Base Mode Parameter access (spec §9.3, P-206): the parameter
//! request written to record 0xB02E and the response read back from it,
//! over the same [`ParamAccess`] as the PKW channel.
//!
//! Request: request reference (1…255), request ID (0x01 request
//! parameter, 0x02 change parameter), DO-ID, number of parameters (1…39),
//! then per parameter attribute (0x10 value, 0x20 description, 0x30 text),
//! number of elements, PNU (U16), subindex (U16); a change request then
//! carries per parameter format, number of values and the values. Values
//! are big-endian; byte-sized values of odd count are followed by one pad
//! byte (word alignment).
//!
//! Response: reference, response ID (0x01/0x02, 0x81/0x82 when any
//! parameter failed), DO-ID, number of parameters; a read answers per
//! parameter format (the PROFIdrive data type), count, values, or format
//! 0x44 with one value, the error number; a change answers the header
//! only, or on a failure per parameter 0x40 0x00 (done) / 0x44 0x01 error.
//!
//! Checks: the whole request is parsed before anything is written
//! ([`Request::parse`]); a malformed one (reference 0, unknown request ID,
//! parameter count, lengths, an unknown value format) is answered with one
//! error block (0x65…0x68 ours, 0x17 illegal format) and changes nothing.
//! Per parameter: 0x16 attribute or elements, 0x18 values ≠ elements, 0x05
//! value format ≠ the parameter's type, then what the access answers. A
//! failed parameter of a change does not stop the others (PROFIdrive). The
//! description gives element 1 (the identifier: data type, bit 9 read
//! only) only, 0x09 for the others; text arrays 0x0F; 64-bit, REAL32 and
//! string parameters 0x05.

use crate::{decode_be, encode_be, fits, Addr, DataType, ParamAccess, PdError};

mod parse;
pub use parse::{Attribute, Malformed, ParamRef, Request, RequestId, Values};

/// The record index of the drive object's parameters.
pub const RECORD_INDEX: u16 = 0xB02E;
/// Most parameters in one request.
pub const MAX_PARAMETERS: usize = 39;
/// Format 0x40: zero (no values).
pub const FORMAT_ZERO: u8 = 0x40;
/// Format 0x41: byte.
pub const FORMAT_BYTE: u8 = 0x41;
/// Format 0x42: word.
pub const FORMAT_WORD: u8 = 0x42;
/// Format 0x43: double word.
pub const FORMAT_DWORD: u8 = 0x43;
/// Format 0x44: error.
pub const FORMAT_ERROR: u8 = 0x44;

/// Why no response could be built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refused {
    /// Shorter than the 4-byte header: the record write is refused
    /// (nothing to answer).
    TooShort,
    /// The response buffer cannot hold even the header and error blocks.
    BufferTooSmall,
}

/// The PROFIdrive data type code of `t` and its value size, for
/// parameters this access serves (integers up to 32 bits).
pub fn format_of(t: DataType) -> Option<(u8, usize)> {
    match t {
        DataType::Bool => Some((0x01, 1)),
        DataType::I8 => Some((0x02, 1)),
        DataType::I16 => Some((0x03, 2)),
        DataType::I32 => Some((0x04, 4)),
        DataType::U8 => Some((0x05, 1)),
        DataType::U16 => Some((0x06, 2)),
        DataType::U32 => Some((0x07, 4)),
        _ => None,
    }
}

struct Out<'a> {
    buf: &'a mut [u8],
    at: usize,
}

impl Out<'_> {
    fn put(&mut self, bytes: &[u8]) -> bool {
        match self.buf.get_mut(self.at..self.at + bytes.len()) {
            Some(d) => {
                d.copy_from_slice(bytes);
                self.at += bytes.len();
                true
            }
            None => false,
        }
    }

    fn error(&mut self, e: PdError) -> Result<(), Refused> {
        let [hi, lo] = e.0.to_be_bytes();
        if self.put(&[FORMAT_ERROR, 1, hi, lo]) {
            Ok(())
        } else {
            Err(Refused::BufferTooSmall)
        }
    }
}

/// Serves one parameter request `req` (the record written to 0xB02E):
/// executes it on `access` and writes the response into `out`, returning
/// its length.
pub fn serve(req: &[u8], access: &mut impl ParamAccess, out: &mut [u8]) -> Result<usize, Refused> {
    let request = match Request::parse(req) {
        Ok(r) => r,
        Err(Malformed::TooShort) => return Err(Refused::TooShort),
        Err(Malformed::Header {
            reference,
            id,
            do_id,
            error,
        }) => {
            let mut o = Out { buf: out, at: 0 };
            let rid = if id == RequestId::Change as u8 { 0x82 } else { 0x81 };
            if !o.put(&[reference, rid, do_id, 1]) {
                return Err(Refused::BufferTooSmall);
            }
            o.error(error)?;
            return Ok(o.at);
        }
    };
    let mut o = Out { buf: out, at: 4 };
    let do_ok = access.drive_object(request.do_id);
    let mut failed = false;
    match request.id {
        RequestId::Read => {
            for p in request.params() {
                let start = o.at;
                let r = if do_ok {
                    read_param(p, access, &mut o)
                } else {
                    Err(PdError::NO_DRIVE_OBJECT)
                };
                if let Err(e) = r {
                    o.at = start;
                    o.error(e)?;
                    failed = true;
                }
            }
        }
        RequestId::Change => {
            for (p, v) in request.params().zip(request.values()) {
                let r = if do_ok {
                    change_param(p, v, access)
                } else {
                    Err(PdError::NO_DRIVE_OBJECT)
                };
                match r {
                    Ok(()) => {
                        if !o.put(&[FORMAT_ZERO, 0]) {
                            return Err(Refused::BufferTooSmall);
                        }
                    }
                    Err(e) => {
                        o.error(e)?;
                        failed = true;
                    }
                }
            }
            if !failed {
                o.at = 4;
            }
        }
    }
    let rid = request.id as u8 | if failed { 0x80 } else { 0 };
    let head = [request.reference, rid, request.do_id, request.count];
    match o.buf.get_mut(..4) {
        Some(h) => h.copy_from_slice(&head),
        None => return Err(Refused::BufferTooSmall),
    }
    Ok(o.at)
}

/// The addresses of `p`'s elements, checked.
fn element_addr(p: ParamRef, i: u8) -> Result<Addr, PdError> {
    let sub = p.sub.checked_add(u16::from(i)).ok_or(PdError::FAULTY_SUBINDEX)?;
    let sub = u8::try_from(sub).map_err(|_| PdError::FAULTY_SUBINDEX)?;
    Ok(Addr::new(p.pnu, sub))
}

fn read_param(p: ParamRef, access: &mut impl ParamAccess, o: &mut Out) -> Result<(), PdError> {
    let n = p.elements.max(1);
    match p.attribute {
        Attribute::Value => {}
        Attribute::Description => {
            if n != 1 {
                return Err(PdError::ADDRESS_IMPERMISSIBLE);
            }
            // the element is the subindex; the parameter is its sub 0
            let d = access.describe(Addr::new(p.pnu, 0))?;
            if p.sub != 1 {
                return Err(PdError::NO_DESCRIPTION);
            }
            let code = format_of(d.data_type).map_or(0, |f| f.0);
            let id = u16::from(code) | if d.writable { 0 } else { 1 << 9 };
            let [hi, lo] = id.to_be_bytes();
            return if o.put(&[FORMAT_WORD, 1, hi, lo]) {
                Ok(())
            } else {
                Err(PdError::RESPONSE_TOO_LONG)
            };
        }
        Attribute::Text => return Err(PdError::NO_TEXT),
        Attribute::Invalid(_) => return Err(PdError::ADDRESS_IMPERMISSIBLE),
    }
    let first = access.describe(element_addr(p, 0)?)?;
    let (code, size) = format_of(first.data_type).ok_or(PdError::INCORRECT_DATA_TYPE)?;
    if !o.put(&[code, n]) {
        return Err(PdError::RESPONSE_TOO_LONG);
    }
    for i in 0..n {
        let addr = element_addr(p, i)?;
        let d = access.describe(addr)?;
        if d.data_type != first.data_type {
            return Err(PdError::ADDRESS_IMPERMISSIBLE);
        }
        if !d.readable {
            return Err(PdError::IMPERMISSIBLE_PNU);
        }
        let v = access.read(addr)?;
        let mut b = [0u8; 4];
        let b = b.get_mut(..size).ok_or(PdError::INCORRECT_DATA_TYPE)?;
        encode_be(v, b);
        if !o.put(b) {
            return Err(PdError::RESPONSE_TOO_LONG);
        }
    }
    if size == 1 && n % 2 == 1 && !o.put(&[0]) {
        return Err(PdError::RESPONSE_TOO_LONG);
    }
    Ok(())
}

fn change_param(p: ParamRef, v: Values, access: &mut impl ParamAccess) -> Result<(), PdError> {
    match p.attribute {
        Attribute::Value => {}
        Attribute::Description => return Err(PdError::DESCRIPTION_READ_ONLY),
        Attribute::Text => return Err(PdError::NO_TEXT),
        Attribute::Invalid(_) => return Err(PdError::ADDRESS_IMPERMISSIBLE),
    }
    let n = p.elements.max(1);
    if v.count != n {
        return Err(PdError::VALUES_INCONSISTENT);
    }
    // every element checked before the first write
    let mut types = [DataType::U8; 256];
    for i in 0..n {
        let addr = element_addr(p, i)?;
        let d = access.describe(addr)?;
        if !d.writable {
            return Err(PdError::CANNOT_CHANGE);
        }
        let (code, size) = format_of(d.data_type).ok_or(PdError::INCORRECT_DATA_TYPE)?;
        let generic = match size {
            1 => FORMAT_BYTE,
            2 => FORMAT_WORD,
            _ => FORMAT_DWORD,
        };
        if (v.format != code && v.format != generic) || v.size != size {
            return Err(PdError::INCORRECT_DATA_TYPE);
        }
        let value = decode_be(d.data_type, v.value(i).ok_or(PdError::VALUES_INCONSISTENT)?);
        if !fits(d.data_type, value) {
            return Err(PdError::LIMIT_EXCEEDED);
        }
        if let Some(t) = types.get_mut(usize::from(i)) {
            *t = d.data_type;
        }
    }
    for i in 0..n {
        let addr = element_addr(p, i)?;
        let t = types.get(usize::from(i)).copied().unwrap_or(DataType::U8);
        let value = decode_be(t, v.value(i).ok_or(PdError::VALUES_INCONSISTENT)?);
        access.write(addr, value, false)?;
    }
    Ok(())
}
