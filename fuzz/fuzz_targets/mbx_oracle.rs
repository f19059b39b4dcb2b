//! One mailbox request into SM0 of a drive in PRE-OP and its answers read
//! back from SM1, with the oracles of the mailbox targets:
//! - each answer is a well-formed mailbox (a length that fits the mailbox,
//!   a type the stack speaks);
//! - no mailbox request changes the AL state;
//! - an SDO initiate response names the object of a request made (the
//!   stack queues its answers, so one may come in a later window, in
//!   request order);
//! - an aborted download with nothing else outstanding leaves the object
//!   dictionary as it was.

use crate::common;
use hil_sim::sim::Simulation;

/// CoE SDO request: mailbox type 3, CoE service 2.
fn sdo_request(m: &[u8]) -> bool {
    m[5] & 0x0F == 3 && u16::from_le_bytes([m[6], m[7]]) >> 12 == 2
}

/// A line in PRE-OP and what its mailbox still owes.
pub struct Checked {
    pub sim: Simulation,
    /// The index/subindex of initiate requests not answered yet, oldest first.
    waiting: Vec<[u8; 3]>,
}

impl Checked {
    /// A copy of the PRE-OP line.
    pub fn new() -> Self {
        Self {
            sim: common::preop_line(),
            waiting: Vec::new(),
        }
    }

    /// Writes `buf` (one SM0 mailbox, 256 bytes) and reads SM1 until it is
    /// empty (at most 4 answers), checking each answer.
    pub fn request(&mut self, buf: &[u8; 256]) {
        let sim = &mut self.sim;
        let state = sim.drives()[0].drive.slave().state();
        // an initiate request (download 0x20, upload 0x40 in the command
        // specifier) whose mailbox length covers the SDO header
        let len_in = usize::from(u16::from_le_bytes([buf[0], buf[1]]));
        let initiate = sdo_request(buf) && len_in >= 10 && matches!(buf[8] & 0xE0, 0x20 | 0x40);
        let object = [buf[9], buf[10], buf[11]];
        let alone = initiate && buf[8] & 0xE0 == 0x20 && self.waiting.is_empty();
        let before = alone.then(|| sim.drives()[0].drive.objects().clone());
        if initiate {
            self.waiting.push(object);
            if self.waiting.len() > 16 {
                self.waiting.remove(0);
            }
        }
        let mut w = common::frame(5, 0x1000, 0x1000, buf); // FPWR into SM0
        sim.exchange(&mut w);
        for _ in 0..4 {
            let t = sim.now() + nanos::Nanos::from_us(200);
            sim.advance_to(t);
            let mut r = common::frame(4, 0x1000, 0x1100, &[0u8; 256]); // FPRD of SM1
            sim.exchange(&mut r);
            let (answer, wkc) = common::reply(&r);
            if wkc != 1 {
                break;
            }
            let len = usize::from(u16::from_le_bytes([answer[0], answer[1]]));
            let kind = answer[5] & 0x0F;
            assert!(len <= 256 - 6, "answer length {len}");
            assert!(matches!(kind, 0 | 2 | 3 | 4), "answer type {kind}");
            let service = u16::from_le_bytes([answer[6], answer[7]]) >> 12;
            if kind != 3 || !matches!(service, 2 | 3) || len < 10 {
                continue;
            }
            let scs = answer[8] & 0xE0;
            let named = [answer[9], answer[10], answer[11]];
            if matches!(scs, 0x40 | 0x60) {
                let at = self.waiting.iter().position(|o| *o == named);
                assert!(
                    at.is_some(),
                    "an initiate response ({scs:#04x}) for {named:02x?}, asked {:02x?}",
                    self.waiting
                );
                self.waiting.drain(..=at.unwrap_or(0));
            } else if scs == 0x80 {
                if let Some(at) = self.waiting.iter().position(|o| *o == named) {
                    self.waiting.drain(..=at);
                    if let Some(before) = &before {
                        if named == object && self.waiting.is_empty() {
                            assert!(
                                *sim.drives()[0].drive.objects() == *before,
                                "an aborted download changed the dictionary: {:02x?}",
                                &answer[..16]
                            );
                        }
                    }
                }
            }
        }
        assert_eq!(
            sim.drives()[0].drive.slave().state(),
            state,
            "a mailbox request changed the AL state"
        );
    }
}
