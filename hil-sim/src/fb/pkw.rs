//! A PKW (PNU 2000) access through the FB's `pkw_*` inputs and outputs
//! (spec §9.2, P-226), as a PLC program would make it:
//!
//! 1. if the previous access had the same code (0x41 or 0x42), first
//!    0x00 until the drive mirrors 0x00 (the toggle rule);
//! 2. the code with index, subindex (and the value), held until the
//!    response's byte 0 mirrors it for this index and subindex (done) or
//!    carries the refusal code 0xC1/0xC2 (the drive's extension, Q-02:
//!    the PROFIdrive error number in bytes 4–7);
//! 3. then 0x00 again, so the next access of any type starts cleanly.

use super::{FbInputs, FbOutputs};
use profidrive::pkw::{NONE, READ, READ_ERROR, WRITE, WRITE_ERROR};

/// One access to make.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    /// Read `index`.`sub`.
    Read {
        /// PNU or CANopen index.
        index: u16,
        /// Subindex.
        sub: u8,
    },
    /// Write `value` (its 32-bit big-endian form) to `index`.`sub`.
    Write {
        /// PNU or CANopen index.
        index: u16,
        /// Subindex.
        sub: u8,
        /// The value.
        value: u32,
    },
}

impl Access {
    fn code(&self) -> u8 {
        match self {
            Access::Read { .. } => READ,
            Access::Write { .. } => WRITE,
        }
    }

    fn address(&self) -> (u16, u8) {
        match *self {
            Access::Read { index, sub } | Access::Write { index, sub, .. } => (index, sub),
        }
    }
}

/// How an access ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Done: the value read (for a write, the value as mirrored).
    Done(u32),
    /// Refused with this PROFIdrive error number.
    Refused(u32),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Idle,
    /// Waiting for the 0x00 mirror before `Access`.
    Clearing(Access),
    /// The request is out; waiting for its mirror.
    Requesting(Access),
}

/// The PKW client: one access at a time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PkwClient {
    phase: Phase,
    /// The code of the last access sent (the toggle rule).
    last_code: u8,
    result: Option<Outcome>,
}

impl Default for PkwClient {
    fn default() -> Self {
        Self::new()
    }
}

impl PkwClient {
    /// Idle, no access made yet.
    pub const fn new() -> Self {
        PkwClient {
            phase: Phase::Idle,
            last_code: NONE,
            result: None,
        }
    }

    /// Starts `access` (replacing one still running).
    pub fn start(&mut self, access: Access) {
        self.result = None;
        self.phase = if access.code() == self.last_code {
            Phase::Clearing(access)
        } else {
            Phase::Requesting(access)
        };
    }

    /// Is an access running?
    pub fn busy(&self) -> bool {
        self.phase != Phase::Idle
    }

    /// The outcome of the last access once it has ended (taken).
    pub fn take_result(&mut self) -> Option<Outcome> {
        self.result.take()
    }

    /// Sets the FB's `pkw_*` inputs for this cycle.
    pub fn inputs(&self, i: &mut FbInputs) {
        let (code, access) = match self.phase {
            Phase::Idle | Phase::Clearing(_) => (NONE, None),
            Phase::Requesting(a) => (a.code(), Some(a)),
        };
        i.pkw_access_control = code;
        if let Some(a) = access {
            let (index, sub) = a.address();
            i.pkw_object_main_index = index;
            i.pkw_object_sub_index = sub;
            i.pkw_write_value = match a {
                Access::Write { value, .. } => value,
                Access::Read { .. } => 0,
            };
        }
    }

    /// Takes the FB's outputs of the response to the last inputs.
    pub fn outputs(&mut self, o: &FbOutputs) {
        match self.phase {
            Phase::Idle => {}
            Phase::Clearing(a) => {
                if o.pkw_access_status == NONE {
                    self.last_code = NONE;
                    self.phase = Phase::Requesting(a);
                }
            }
            Phase::Requesting(a) => {
                let (index, sub) = a.address();
                let ours = o.pkw_main_index == index && o.pkw_sub_index == sub;
                let refused = if a.code() == READ { READ_ERROR } else { WRITE_ERROR };
                let status = o.pkw_access_status;
                if ours && status == a.code() {
                    self.result = Some(Outcome::Done(o.pkw_read_value));
                } else if ours && status == refused {
                    self.result = Some(Outcome::Refused(o.pkw_read_value));
                } else {
                    return;
                }
                self.last_code = a.code();
                self.phase = Phase::Idle;
            }
        }
    }
}
