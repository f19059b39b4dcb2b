//! Emergency messages (spec §8): the 8 EMCY bytes, the ones the slave stack
//! sends itself (state transition, EoE), the mailbox frame (CoE service 1) and a
//! bounded queue for the slave to drain into SM1. The application's device
//! faults (the drive: its E82 event table, §8.3) are its own.
//!
//! Byte layout (spec §8.2, manual bytes 1–8):
//!
//! | bytes | 1–2 | 3 | 4 | 5 | 6–7 | 8 |
//! |---|---|---|---|---|---|---|
//! | device fault (the application's) | error code (LE) | error register | manufacturer data (5 bytes) ||||
//! | state transition | A000h/A001h | ESM state 1–4 | diag code | diag data (4 bytes) ||
//! | EoE error | FFF0h | 23h | 0 | 0 | 0 | 0 |

use crate::coe::{service, CoeHeader, COE_HEADER_LEN};
use crate::mailbox::{MailboxHeader, MailboxType, HEADER_LEN};
use heapless::Deque;

/// Length of the EMCY data after the CoE header.
pub const EMCY_LEN: usize = 8;
/// Length of a whole EMCY mailbox frame: mailbox header, CoE header, EMCY.
pub const FRAME_LEN: usize = HEADER_LEN + COE_HEADER_LEN + EMCY_LEN;

/// Error codes used outside the device fault table.
pub mod code {
    /// 0000h: no error / fault cleared.
    pub const NO_ERROR: u16 = 0x0000;
    /// 1000h: generic error.
    pub const GENERIC: u16 = 0x1000;
    /// A000h: transition Pre-Op → Safe-Op failed (spec §8.4).
    pub const PREOP_TO_SAFEOP: u16 = 0xA000;
    /// A001h: transition Safe-Op → Pre-Op failed (as printed in S, spec §8.4).
    pub const SAFEOP_TO_PREOP: u16 = 0xA001;
    /// FFF0h: EoE error (spec §8.5).
    pub const EOE: u16 = 0xFFF0;
}

/// Error register values (CiA 301 bit masks, except the EoE sub-code).
pub mod register {
    pub use od::error_register::*;
    /// 23h "EoE address occupied": a sub-code, not a bit mask (spec §8.5).
    pub const EOE_ADDRESS_OCCUPIED: u8 = 0x23;
}

/// SyncManager fault kinds of the state-transition diag code (spec §8.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SmFault {
    /// SM at a non-permitted address.
    Address = 0,
    /// SM at a non-permitted address, second variant (uncertain: likely length/end).
    Address2 = 1,
    /// PDO length not correct.
    Length = 2,
    /// SM parameterised incorrectly.
    Settings = 3,
}

/// Diag code of a state-transition EMCY: 4 × SM number (0..3) + fault kind.
pub const fn diag_code(sm: u8, fault: SmFault) -> u8 {
    (sm & 0x03) * 4 + fault as u8
}

/// One emergency message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Emcy {
    /// Error code (bytes 1–2, little-endian on the wire).
    pub code: u16,
    /// Error register (byte 3).
    pub register: u8,
    /// Bytes 4–8.
    pub data: [u8; 5],
}

impl Emcy {
    /// An emergency with `code`, error register `register` and the five
    /// manufacturer bytes `data` (bytes 4–8).
    pub const fn new(code: u16, register: u8, data: [u8; 5]) -> Self {
        Self { code, register, data }
    }

    /// State-transition error: `code` A000h/A001h, error register = ESM state at sending
    /// time (1 Init, 2 Pre-Op, 3 Safe-Op, 4 Op), byte 4 = diag code (see [`diag_code`]),
    /// bytes 5–8 = diag data. The positions of diag code and data are uncertain (spec
    /// §8.2, §22.4); this follows the column order of the spec's table.
    pub const fn state_transition(code: u16, esm_state: u8, diag_code: u8, diag_data: [u8; 4]) -> Self {
        let [d0, d1, d2, d3] = diag_data;
        Self {
            code,
            register: esm_state,
            data: [diag_code, d0, d1, d2, d3],
        }
    }

    /// EoE error: FFF0h, 23h "EoE address occupied" (spec §8.5).
    pub const fn eoe_error() -> Self {
        Self {
            code: code::EOE,
            register: register::EOE_ADDRESS_OCCUPIED,
            data: [0; 5],
        }
    }

    /// EoE "no error": 0000h, 00h (spec §8.5).
    pub const fn eoe_cleared() -> Self {
        Self {
            code: code::NO_ERROR,
            register: 0,
            data: [0; 5],
        }
    }

    /// The 8 EMCY bytes.
    pub fn to_bytes(&self) -> [u8; EMCY_LEN] {
        let [c0, c1] = self.code.to_le_bytes();
        let [d0, d1, d2, d3, d4] = self.data;
        [c0, c1, self.register, d0, d1, d2, d3, d4]
    }

    /// Parses the 8 EMCY bytes at the start of `buf`.
    pub fn parse(buf: &[u8]) -> Option<Self> {
        match buf.get(..EMCY_LEN)? {
            &[c0, c1, register, d0, d1, d2, d3, d4] => Some(Self {
                code: u16::from_le_bytes([c0, c1]),
                register,
                data: [d0, d1, d2, d3, d4],
            }),
            _ => None,
        }
    }

    /// Writes the whole mailbox frame (mailbox header: length 10, address 0, channel 0,
    /// priority 0, type CoE, `counter` (1..7, 0 = unused); CoE header: number 0, service
    /// 1 = emergency; the 8 EMCY bytes) into `out`. Returns [`FRAME_LEN`], or `None` when
    /// `out` is shorter. The rest of `out` is left as it is.
    pub fn to_mailbox(&self, out: &mut [u8], counter: u8) -> Option<usize> {
        let frame = out.get_mut(..FRAME_LEN)?;
        let header = MailboxHeader {
            length: (COE_HEADER_LEN + EMCY_LEN) as u16,
            address: 0,
            channel: 0,
            priority: 0,
            kind: MailboxType::Coe,
            counter,
        };
        let coe = CoeHeader {
            number: 0,
            service: service::EMERGENCY,
        };
        let bytes = header
            .to_bytes()
            .into_iter()
            .chain(coe.to_bytes())
            .chain(self.to_bytes());
        for (dst, src) in frame.iter_mut().zip(bytes) {
            *dst = src;
        }
        Some(FRAME_LEN)
    }
}

/// Bounded FIFO of pending EMCYs (`N` ≥ 1). When full, [`EmcyQueue::push`] drops the
/// oldest message and counts it in [`EmcyQueue::dropped`].
#[derive(Clone, Debug)]
pub struct EmcyQueue<const N: usize> {
    queue: Deque<Emcy, N>,
    dropped: u32,
}

impl<const N: usize> Default for EmcyQueue<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> EmcyQueue<N> {
    /// An empty queue.
    pub const fn new() -> Self {
        Self {
            queue: Deque::new(),
            dropped: 0,
        }
    }

    /// Appends `emcy`, dropping the oldest message when the queue is full.
    pub fn push(&mut self, emcy: Emcy) {
        if self.queue.is_full() && self.queue.pop_front().is_some() {
            self.dropped = self.dropped.saturating_add(1);
        }
        if self.queue.push_back(emcy).is_err() {
            // Cannot happen after the pop above; counted all the same.
            self.dropped = self.dropped.saturating_add(1);
        }
    }

    /// Takes the oldest message.
    pub fn pop(&mut self) -> Option<Emcy> {
        self.queue.pop_front()
    }

    /// The oldest message, left in the queue (send it, then [`EmcyQueue::pop`]).
    pub fn peek(&self) -> Option<&Emcy> {
        self.queue.front()
    }

    /// Messages waiting.
    pub fn len(&self) -> usize {
        self.queue.len()
    }

    /// No message waiting.
    pub fn is_empty(&self) -> bool {
        self.queue.is_empty()
    }

    /// Messages dropped because the queue was full (saturating).
    pub fn dropped(&self) -> u32 {
        self.dropped
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mailbox::MailboxHeader;

    #[test]
    fn e091_state_transition_layout() {
        assert_eq!(diag_code(0, SmFault::Address), 0x0);
        assert_eq!(diag_code(1, SmFault::Settings), 0x7);
        assert_eq!(diag_code(2, SmFault::Length), 0xA);
        assert_eq!(diag_code(3, SmFault::Length), 0xE);
        assert_eq!(diag_code(3, SmFault::Settings), 0xF);
        let e = Emcy::state_transition(code::PREOP_TO_SAFEOP, 2, 0xA, [1, 2, 3, 4]);
        assert_eq!(e.to_bytes(), [0x00, 0xA0, 0x02, 0x0A, 1, 2, 3, 4]);
        let e = Emcy::state_transition(code::SAFEOP_TO_PREOP, 3, 0, [0; 4]);
        assert_eq!(e.to_bytes(), [0x01, 0xA0, 0x03, 0, 0, 0, 0, 0]);
    }

    /// E-092: SM misparameterisation at start-up (e.g. SM3 length wrong on P→S).
    #[test]
    fn e092_sm_misparameterisation() {
        let e = Emcy::state_transition(code::PREOP_TO_SAFEOP, 2, diag_code(3, SmFault::Length), [0; 4]);
        assert_eq!(e.to_bytes()[..4], [0x00, 0xA0, 0x02, 0x0E]);
    }

    #[test]
    fn e093_eoe_error() {
        assert_eq!(Emcy::eoe_error().to_bytes(), [0xF0, 0xFF, 0x23, 0, 0, 0, 0, 0]);
        assert_eq!(Emcy::eoe_cleared().to_bytes(), [0; 8]);
    }

    #[test]
    fn e094_mailbox_frame() {
        let e = Emcy::new(0x7500, register::COMMUNICATION, [52, 7, 0, 0, 1]);
        let mut out = [0xAAu8; 32];
        assert_eq!(e.to_mailbox(&mut out, 3), Some(FRAME_LEN));
        assert_eq!(
            out[..FRAME_LEN],
            [10, 0, 0, 0, 0, 0x33, 0x00, 0x10, 0x00, 0x75, 0x10, 52, 7, 0, 0, 1]
        );
        assert_eq!(out[FRAME_LEN], 0xAA);
        let h = MailboxHeader::parse(&out).unwrap();
        assert_eq!((h.length, h.kind, h.counter), (10, MailboxType::Coe, 3));
        let coe = CoeHeader::parse(&out[HEADER_LEN..]).unwrap();
        assert_eq!((coe.number, coe.service), (0, service::EMERGENCY));
        assert_eq!(Emcy::parse(&out[HEADER_LEN + COE_HEADER_LEN..]), Some(e));
        assert_eq!(e.to_mailbox(&mut [0u8; FRAME_LEN - 1], 1), None);
    }

    #[test]
    fn queue_drops_oldest() {
        let mut q = EmcyQueue::<3>::new();
        assert!(q.is_empty());
        for axis in 0..5 {
            q.push(Emcy::new(0, 0, [30, 0, 0, 0, axis]));
        }
        assert_eq!((q.len(), q.dropped()), (3, 2));
        assert_eq!(q.peek().map(|e| e.data[4]), Some(2));
        let order: [u8; 3] = core::array::from_fn(|_| q.pop().unwrap().data[4]);
        assert_eq!(order, [2, 3, 4]);
        assert_eq!(q.pop(), None);
    }
}
