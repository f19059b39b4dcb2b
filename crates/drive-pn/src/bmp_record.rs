//! The standard PROFIdrive parameter record 0xB02E on the device (P-206):
//! a controller writes a parameter request to it and reads the response
//! back, as generic PROFIdrive tools and tshark's dissector expect. The
//! request is served by [`profidrive::bmp::serve`] over the profile's
//! parameter access (the same as the PKW channel: PNUs in PROFINET units,
//! CANopen objects in theirs).
//!
//! The record is accepted at any slot and subslot of the AR (the drive has
//! one drive object, axis A; DO-IDs 0 and 1 both name it). The device's
//! record hook only keeps the request ([`WithBmp`]); the drive serves it
//! right after the frame that carried it ([`crate::PnDrive::receive`]), so
//! the response is there for the controller's read. A read before any
//! request, or a second read of the same response, is refused with "state
//! conflict" (0xB5); a request of fewer than 4 or more than 240 bytes with
//! "write length error" (0xB1) and nothing changes.

use profidrive::bmp::RECORD_INDEX;
use profinet::cm::{RecordAddr, RecordError, RecordHook};

/// The longest parameter request or response (PROFIdrive: 240 bytes).
pub const MAX_BYTES: usize = 240;

/// What the record holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    /// Nothing (before the first request, after its response was read).
    Idle,
    /// A request waits for the drive.
    Request,
    /// The response waits for the controller's read.
    Response,
}

/// The record's buffer: the request, then its response in its place.
#[derive(Debug, Clone)]
pub struct BmpRecord {
    buf: [u8; MAX_BYTES],
    len: u8,
    state: State,
}

impl Default for BmpRecord {
    fn default() -> Self {
        BmpRecord {
            buf: [0; MAX_BYTES],
            len: 0,
            state: State::Idle,
        }
    }
}

impl BmpRecord {
    /// The waiting request (copied out: its response replaces it).
    pub fn take_request(&mut self) -> Option<([u8; MAX_BYTES], usize)> {
        if self.state != State::Request {
            return None;
        }
        self.state = State::Idle;
        Some((self.buf, usize::from(self.len)))
    }

    /// The response to the request taken.
    pub fn set_response(&mut self, response: &[u8]) {
        let n = response.len().min(MAX_BYTES);
        for (d, s) in self.buf.iter_mut().zip(response.iter().take(n)) {
            *d = *s;
        }
        self.len = n as u8;
        self.state = State::Response;
    }

    fn write(&mut self, data: &[u8]) -> Result<(), RecordError> {
        if data.len() < 4 || data.len() > MAX_BYTES {
            return Err(RecordError::WriteLength);
        }
        for (d, s) in self.buf.iter_mut().zip(data) {
            *d = *s;
        }
        self.len = data.len() as u8;
        self.state = State::Request;
        Ok(())
    }

    fn read(&mut self, out: &mut [u8]) -> Result<usize, RecordError> {
        if self.state != State::Response {
            return Err(RecordError::StateConflict);
        }
        let n = usize::from(self.len).min(out.len());
        for (d, s) in out.iter_mut().zip(self.buf.iter().take(n)) {
            *d = *s;
        }
        self.state = State::Idle;
        Ok(n)
    }
}

/// Record 0xB02E in front of the other records `H`.
#[derive(Debug, Clone, Default)]
pub struct WithBmp<H: RecordHook> {
    /// Record 0xB02E.
    pub bmp: BmpRecord,
    /// The other records.
    pub inner: H,
}

impl<H: RecordHook> RecordHook for WithBmp<H> {
    fn read(&mut self, addr: RecordAddr, out: &mut [u8]) -> Result<usize, RecordError> {
        if addr.index == RECORD_INDEX {
            self.bmp.read(out)
        } else {
            self.inner.read(addr, out)
        }
    }

    fn write(&mut self, addr: RecordAddr, data: &[u8]) -> Result<(), RecordError> {
        if addr.index == RECORD_INDEX {
            self.bmp.write(data)
        } else {
            self.inner.write(addr, data)
        }
    }
}
