//! The checked view of a parameter request.

use super::{FORMAT_BYTE, FORMAT_DWORD, FORMAT_WORD, MAX_PARAMETERS};
use crate::PdError;

/// Request ID.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RequestId {
    /// 0x01 request parameter (read).
    Read = 0x01,
    /// 0x02 change parameter (write).
    Change = 0x02,
}

/// Attribute of a parameter address.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Attribute {
    /// 0x10 value.
    Value,
    /// 0x20 description.
    Description,
    /// 0x30 text.
    Text,
    /// Anything else (answered 0x16 for that parameter).
    Invalid(u8),
}

impl Attribute {
    fn of(b: u8) -> Self {
        match b {
            0x10 => Attribute::Value,
            0x20 => Attribute::Description,
            0x30 => Attribute::Text,
            other => Attribute::Invalid(other),
        }
    }
}

/// One parameter address of a request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ParamRef {
    /// Attribute.
    pub attribute: Attribute,
    /// Number of elements (0 is taken as 1).
    pub elements: u8,
    /// PNU.
    pub pnu: u16,
    /// Subindex of the first element.
    pub sub: u16,
}

/// The values of one parameter of a change request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Values<'a> {
    /// Format byte.
    pub format: u8,
    /// Number of values.
    pub count: u8,
    /// Size of one value in bytes.
    pub size: usize,
    data: &'a [u8],
}

impl<'a> Values<'a> {
    /// Value `i` (big-endian bytes).
    pub fn value(&self, i: u8) -> Option<&'a [u8]> {
        let at = usize::from(i) * self.size;
        self.data.get(at..at + self.size)
    }
}

/// A request that cannot be executed as a whole.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Malformed {
    /// Shorter than the header.
    TooShort,
    /// A header, length or format fault: answered with one error block.
    Header {
        /// The request reference, mirrored.
        reference: u8,
        /// The request ID as received.
        id: u8,
        /// The DO-ID, mirrored.
        do_id: u8,
        /// The error number.
        error: PdError,
    },
}

/// A parsed, checked request.
#[derive(Debug, Clone, Copy)]
pub struct Request<'a> {
    /// Request reference.
    pub reference: u8,
    /// Request ID.
    pub id: RequestId,
    /// DO-ID.
    pub do_id: u8,
    /// Number of parameters (1…39).
    pub count: u8,
    params: [ParamRef; MAX_PARAMETERS],
    values: [Values<'a>; MAX_PARAMETERS],
}

/// The size of one value of `format` (`None`: not a value format).
fn value_size(format: u8) -> Option<usize> {
    match format {
        0x01 | 0x02 | 0x05 | FORMAT_BYTE => Some(1),
        0x03 | 0x06 | FORMAT_WORD => Some(2),
        0x04 | 0x07 | 0x08 | FORMAT_DWORD => Some(4),
        _ => None,
    }
}

impl<'a> Request<'a> {
    /// Parses `req` completely: addresses and, for a change, every value
    /// block; the request must end exactly after its last block.
    pub fn parse(req: &'a [u8]) -> Result<Self, Malformed> {
        let [reference, id, do_id, count] = match req.get(..4) {
            Some(&[a, b, c, d]) => [a, b, c, d],
            _ => return Err(Malformed::TooShort),
        };
        let bad = |error| Malformed::Header {
            reference,
            id,
            do_id,
            error,
        };
        if reference == 0 {
            return Err(bad(PdError::BAD_REFERENCE));
        }
        let rid = match id {
            0x01 => RequestId::Read,
            0x02 => RequestId::Change,
            _ => return Err(bad(PdError::BAD_REQUEST_ID)),
        };
        let n = usize::from(count);
        if n == 0 || n > MAX_PARAMETERS {
            return Err(bad(PdError::BAD_PARAMETER_COUNT));
        }
        let empty = ParamRef {
            attribute: Attribute::Value,
            elements: 0,
            pnu: 0,
            sub: 0,
        };
        let none = Values {
            format: 0,
            count: 0,
            size: 1,
            data: &[],
        };
        let mut r = Request {
            reference,
            id: rid,
            do_id,
            count,
            params: [empty; MAX_PARAMETERS],
            values: [none; MAX_PARAMETERS],
        };
        let mut at = 4;
        for p in r.params.iter_mut().take(n) {
            let Some(&[attr, elements, p0, p1, s0, s1]) = req.get(at..at + 6) else {
                return Err(bad(PdError::BAD_LENGTH));
            };
            *p = ParamRef {
                attribute: Attribute::of(attr),
                elements,
                pnu: u16::from_be_bytes([p0, p1]),
                sub: u16::from_be_bytes([s0, s1]),
            };
            at += 6;
        }
        if rid == RequestId::Change {
            for v in r.values.iter_mut().take(n) {
                let Some(&[format, cnt]) = req.get(at..at + 2) else {
                    return Err(bad(PdError::BAD_LENGTH));
                };
                let size = value_size(format).ok_or(bad(PdError::ILLEGAL_FORMAT))?;
                let len = size * usize::from(cnt);
                let data = req.get(at + 2..at + 2 + len).ok_or(bad(PdError::BAD_LENGTH))?;
                at += 2 + len;
                // the pad byte after an odd number of bytes (a last
                // parameter may leave it out)
                if size == 1 && cnt % 2 == 1 && at < req.len() {
                    at += 1;
                }
                *v = Values {
                    format,
                    count: cnt,
                    size,
                    data,
                };
            }
        }
        if at != req.len() {
            return Err(bad(PdError::BAD_LENGTH));
        }
        Ok(r)
    }

    /// The parameter addresses.
    pub fn params(&self) -> impl Iterator<Item = ParamRef> + '_ {
        self.params.iter().copied().take(usize::from(self.count))
    }

    /// The value blocks (change requests; empty blocks for a read).
    pub fn values(&self) -> impl Iterator<Item = Values<'a>> + '_ {
        self.values.iter().copied().take(usize::from(self.count))
    }
}
