//! The PKW mailbox, PNU 2000 (spec §9.2, P-191…P-198): an expedited
//! parameter access over the cyclic channel, 8 bytes each way.
//!
//! | byte | request | response |
//! |---|---|---|
//! | 0 | 0x00 none, 0x41 read, 0x42 write | the request's code once executed; 0xC1/0xC2 when refused |
//! | 1–2 | index (PNU or CANopen index), big-endian | the same |
//! | 3 | subindex | the same |
//! | 4–7 | write data | read data; the PROFIdrive error number when refused |
//!
//! - An access starts when byte 0 changes to 0x41 or 0x42 (the toggle rule,
//!   P-193): two accesses of the same type need 0x00 in between, which the
//!   response mirrors (bytes 1–7 keep the last result). A request with the
//!   code of the one before is not a new access: the response stays.
//! - Data: a 32-bit big-endian value, right-aligned; 8/16-bit values
//!   sign-extended (signed types) or zero-extended. A write value must fit
//!   the object's type (else 0x02); 64-bit objects are 0x05.
//! - Errors (Q-02, an extension of the manual): 0xC1 (read) / 0xC2 (write),
//!   index and subindex, and the PROFIdrive error number in bytes 4–7.
//! - Reserved codes (P-195) start nothing: the response stays as it was
//!   and [`Pkw::reserved_requests`] counts them.
//! - An access that takes more than one cycle (a write answering
//!   [`Completion::Pending`], e.g. PNU 971) keeps the previous response
//!   until it is done; meanwhile the request is not looked at.

use crate::{decode_be, encode_be, fits, int_size, Addr, Completion, ParamAccess, PdError};

/// No access.
pub const NONE: u8 = 0x00;
/// Read.
pub const READ: u8 = 0x41;
/// Write.
pub const WRITE: u8 = 0x42;
/// A refused read (ours, Q-02).
pub const READ_ERROR: u8 = 0xC1;
/// A refused write (ours, Q-02).
pub const WRITE_ERROR: u8 = 0xC2;

/// The mailbox state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pkw {
    response: [u8; 8],
    /// The code of the previous request (the toggle rule).
    last_code: u8,
    /// A write still running.
    pending: Option<(Addr, [u8; 8])>,
    reserved: u32,
    /// Write requests served so far (wrapping).
    writes: u32,
}

impl Default for Pkw {
    fn default() -> Self {
        Self::new()
    }
}

impl Pkw {
    /// Idle: the response is all zero.
    pub const fn new() -> Self {
        Self {
            response: [0; 8],
            last_code: NONE,
            pending: None,
            reserved: 0,
            writes: 0,
        }
    }

    /// One cycle with the request bytes `req`; returns the response to send.
    pub fn step(&mut self, req: [u8; 8], access: &mut impl ParamAccess) -> [u8; 8] {
        if let Some((addr, done)) = self.pending {
            match access.poll_write(addr) {
                Ok(Completion::Pending) => return self.response,
                Ok(Completion::Done) => self.response = done,
                Err(e) => self.response = error(WRITE_ERROR, &done, e),
            }
            self.pending = None;
            return self.response;
        }
        let code = req[0];
        let previous = core::mem::replace(&mut self.last_code, code);
        match code {
            NONE => self.response[0] = NONE,
            READ | WRITE if code == previous => {}
            READ => self.response = read(req, access),
            WRITE => self.write(req, access),
            _ => self.reserved = self.reserved.wrapping_add(1),
        }
        self.response
    }

    /// The response of the last step.
    pub fn response(&self) -> [u8; 8] {
        self.response
    }

    /// Is a write still running?
    pub fn busy(&self) -> bool {
        self.pending.is_some()
    }

    /// Write requests served so far (wrapping): a caller that acts on
    /// written values only when one was written compares it with the last
    /// count it saw.
    pub fn writes(&self) -> u32 {
        self.writes
    }

    /// Requests with a reserved code so far.
    pub fn reserved_requests(&self) -> u32 {
        self.reserved
    }

    fn write(&mut self, req: [u8; 8], access: &mut impl ParamAccess) {
        self.writes = self.writes.wrapping_add(1);
        let addr = address(&req);
        let result = access
            .describe(addr)
            .and_then(|d| {
                if !d.writable {
                    return Err(PdError::CANNOT_CHANGE);
                }
                let size = int_size(d.data_type)?;
                if size > 4 {
                    return Err(PdError::INCORRECT_DATA_TYPE);
                }
                let t = if d.data_type.signed() {
                    od::DataType::I32
                } else {
                    od::DataType::U32
                };
                let v = decode_be(t, req.get(4..8).unwrap_or(&[]));
                if !fits(d.data_type, v) {
                    return Err(PdError::LIMIT_EXCEEDED);
                }
                Ok(v)
            })
            .and_then(|v| access.write(addr, v, false));
        match result {
            Ok(Completion::Done) => self.response = req,
            Ok(Completion::Pending) => self.pending = Some((addr, req)),
            Err(e) => self.response = error(WRITE_ERROR, &req, e),
        }
    }
}

fn address(req: &[u8; 8]) -> Addr {
    Addr::new(u16::from_be_bytes([req[1], req[2]]), req[3])
}

fn error(code: u8, req: &[u8; 8], e: PdError) -> [u8; 8] {
    let mut r = *req;
    r[0] = code;
    r[4..8].copy_from_slice(&u32::from(e.0).to_be_bytes());
    r
}

fn read(req: [u8; 8], access: &mut impl ParamAccess) -> [u8; 8] {
    let addr = address(&req);
    let result = access.describe(addr).and_then(|d| {
        if !d.readable {
            return Err(PdError::IMPERMISSIBLE_PNU);
        }
        if int_size(d.data_type)? > 4 {
            return Err(PdError::INCORRECT_DATA_TYPE);
        }
        access.read(addr)
    });
    match result {
        Ok(v) => {
            let mut r = req;
            encode_be(v, &mut r[4..8]);
            r
        }
        Err(e) => error(READ_ERROR, &req, e),
    }
}
