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
//!
//! The drive is a copy of the one a master brought to PRE-OP on the
//! simulated line; its mailbox task runs behind [`MailboxEsc`] (the
//! mailbox SyncManagers only), so an input costs the firmware's work.

use crate::common;
use crate::mbx_esc::{MailboxEsc, LEN};
use hil_sim::sim::{FirmwareFlash, SimFlash};
use nanos::Nanos;

type Drive = drive_ecat::runtime::Drive<SimFlash, FirmwareFlash>;

thread_local! {
    /// The drive of [`common::build_preop_line`], once per process.
    static PREOP: Drive = common::build_preop_line().drives()[0].drive.clone();
}

/// CoE SDO request: mailbox type 3, CoE service 2.
fn sdo_request(m: &[u8]) -> bool {
    m[5] & 0x0F == 3 && u16::from_le_bytes([m[6], m[7]]) >> 12 == 2
}

/// A drive in PRE-OP and what its mailbox still owes.
pub struct Checked {
    pub drive: Drive,
    esc: MailboxEsc,
    now: Nanos,
    /// The index/subindex of initiate requests not answered yet, oldest first.
    waiting: Vec<[u8; 3]>,
}

impl Checked {
    /// A copy of the PRE-OP drive.
    pub fn new() -> Self {
        Self {
            drive: PREOP.with(Drive::clone),
            esc: MailboxEsc::new(),
            now: Nanos::from_ms(10),
            waiting: Vec::new(),
        }
    }

    /// One run of the drive's mailbox task, 200 µs later than the last.
    fn step(&mut self) {
        self.now = self.now + Nanos::from_us(200);
        let Ok(()) = self.drive.poll_mailbox(&mut self.esc, self.now);
    }

    /// Writes `buf` (one SM0 mailbox, 256 bytes) and reads SM1 until it is
    /// empty (at most 4 answers), checking each answer.
    pub fn request(&mut self, buf: &[u8; LEN]) {
        let state = self.drive.slave().state();
        // an initiate request (download 0x20, upload 0x40 in the command
        // specifier) whose mailbox length covers the SDO header
        let len_in = usize::from(u16::from_le_bytes([buf[0], buf[1]]));
        let initiate = sdo_request(buf) && len_in >= 10 && matches!(buf[8] & 0xE0, 0x20 | 0x40);
        let object = [buf[9], buf[10], buf[11]];
        let alone = initiate && buf[8] & 0xE0 == 0x20 && self.waiting.is_empty();
        let before = alone.then(|| self.drive.objects().clone());
        if initiate {
            self.waiting.push(object);
            if self.waiting.len() > 16 {
                self.waiting.remove(0);
            }
        }
        if !self.esc.master_write(buf) {
            // SM0 still full (the drive holds a request back while its
            // answer waits): one more run of the mailbox task, then again
            self.step();
            let _ = self.esc.master_write(buf);
        }
        for _ in 0..4 {
            self.step();
            let Some(answer) = self.esc.master_read() else {
                break;
            };
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
                                *self.drive.objects() == *before,
                                "an aborted download changed the dictionary: {:02x?}",
                                &answer[..16]
                            );
                        }
                    }
                }
            }
        }
        assert_eq!(
            self.drive.slave().state(),
            state,
            "a mailbox request changed the AL state"
        );
    }
}
