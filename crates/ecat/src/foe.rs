//! File access over EtherCAT (FoE, ETG.1000.6 §5.8): the server side of a file
//! download (write), the firmware update path.
//!
//! A transfer is a write request (opcode 2: password, file name), answered with
//! ACK 0, then DATA packets 1, 2, … (opcode 3), each answered with its ACK (opcode 4)
//! or BUSY (opcode 6: the data was not taken, the master sends the same packet
//! again). A DATA packet shorter than the mailbox allows ends the file. Errors go
//! out as opcode 5 with an ETG error code ([`FoeError`]) and end the transfer.
//!
//! The server only moves packets; what a file is and where its bytes go is the
//! application's [`FoeHandler`] (the drive's firmware slots). Rules of this server:
//! - write requests only in Bootstrap; elsewhere [`FoeError::BOOTSTRAP_ONLY`];
//! - read requests: no file can be read, [`FoeError::NOT_FOUND`];
//! - a DATA packet whose number is not the expected one: [`FoeError::PACKET_NUMBER`],
//!   the transfer ends; DATA or ACK/BUSY without a transfer: [`FoeError::ILLEGAL`];
//! - no packet for [`FOE_TIMEOUT`] during a transfer (a cut connection): the
//!   transfer is dropped ([`FoeHandler::abort`]), silently — nobody is listening.

use crate::mailbox::MailboxError;
use nanos::Nanos;

/// Length of the FoE header (opcode, reserved, 32-bit field).
pub const FOE_HEADER_LEN: usize = 6;

/// A transfer without a packet for this long is dropped (our choice: ETG.1000.6
/// names no slave-side timeout).
pub const FOE_TIMEOUT: Nanos = Nanos::from_secs(5);

/// FoE opcodes (ETG.1000.6 Table 89).
pub mod opcode {
    /// Read request.
    pub const READ: u8 = 1;
    /// Write request.
    pub const WRITE: u8 = 2;
    /// Data.
    pub const DATA: u8 = 3;
    /// Acknowledge.
    pub const ACK: u8 = 4;
    /// Error.
    pub const ERROR: u8 = 5;
    /// Busy.
    pub const BUSY: u8 = 6;
}

/// FoE error codes (ETG.1000.6 Table 92).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FoeError(pub u32);

impl FoeError {
    /// 8000h Not defined.
    pub const NOT_DEFINED: Self = Self(0x8000);
    /// 8001h Not found.
    pub const NOT_FOUND: Self = Self(0x8001);
    /// 8002h Access denied.
    pub const ACCESS_DENIED: Self = Self(0x8002);
    /// 8003h Disk full (the file does not fit).
    pub const DISK_FULL: Self = Self(0x8003);
    /// 8004h Illegal (operation not expected now).
    pub const ILLEGAL: Self = Self(0x8004);
    /// 8005h Packet number wrong.
    pub const PACKET_NUMBER: Self = Self(0x8005);
    /// 8006h Already exists.
    pub const EXISTS: Self = Self(0x8006);
    /// 8007h No user.
    pub const NO_USER: Self = Self(0x8007);
    /// 8008h Bootstrap only (the file can only be written in Bootstrap).
    pub const BOOTSTRAP_ONLY: Self = Self(0x8008);
    /// 8009h Not Bootstrap (the file cannot be written in Bootstrap).
    pub const NOT_BOOTSTRAP: Self = Self(0x8009);
    /// 800Ah No rights (password).
    pub const NO_RIGHTS: Self = Self(0x800A);
    /// 800Bh Program error (the file could not be stored).
    pub const PROGRAM_ERROR: Self = Self(0x800B);
    /// 800Ch Checksum error (the file's check failed).
    pub const CHECKSUM: Self = Self(0x800C);
}

/// How the handler took a DATA packet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Accept {
    /// Stored: ACK.
    Done,
    /// Not taken yet (e.g. erasing): BUSY with progress `done` of `entire`; the
    /// master repeats the packet.
    Busy {
        /// Progress so far.
        done: u16,
        /// Progress at the end.
        entire: u16,
    },
}

/// The application's side of FoE file downloads.
pub trait FoeHandler {
    /// A write request (in Bootstrap) for `name` with `password`.
    fn begin_write(&mut self, name: &[u8], password: u32) -> Result<(), FoeError>;
    /// The next bytes of the file.
    fn write(&mut self, data: &[u8]) -> Result<Accept, FoeError>;
    /// The file is complete (the last DATA packet was taken): check and commit it.
    fn end_write(&mut self) -> Result<(), FoeError>;
    /// The transfer ended without completion (error, timeout, state change).
    fn abort(&mut self);
}

/// A device without files: every write request is refused with
/// [`FoeError::ACCESS_DENIED`].
#[derive(Debug, Clone, Copy, Default)]
pub struct NoFiles;

impl FoeHandler for NoFiles {
    fn begin_write(&mut self, _name: &[u8], _password: u32) -> Result<(), FoeError> {
        Err(FoeError::ACCESS_DENIED)
    }
    fn write(&mut self, _data: &[u8]) -> Result<Accept, FoeError> {
        Err(FoeError::ILLEGAL)
    }
    fn end_write(&mut self) -> Result<(), FoeError> {
        Err(FoeError::ILLEGAL)
    }
    fn abort(&mut self) {}
}

/// The FoE server: one write transfer at a time.
#[derive(Debug, Clone, Copy, Default)]
pub struct FoeServer {
    /// Number of the next DATA packet of the write in progress.
    next: Option<u32>,
    /// Time of the last packet of the transfer.
    last: Nanos,
    /// Transfers dropped by the timeout.
    timeouts: u32,
}

fn reply(out: &mut [u8], op: u8, field: u32) -> Result<Option<usize>, MailboxError> {
    let [f0, f1, f2, f3] = field.to_le_bytes();
    let dst = out
        .get_mut(..FOE_HEADER_LEN)
        .ok_or(MailboxError::NO_MORE_MEMORY)?;
    dst.copy_from_slice(&[op, 0, f0, f1, f2, f3]);
    Ok(Some(FOE_HEADER_LEN))
}

fn le32(b: &[u8], at: usize) -> u32 {
    match b.get(at..at + 4) {
        Some(&[a, b, c, d]) => u32::from_le_bytes([a, b, c, d]),
        _ => 0,
    }
}

impl FoeServer {
    /// An idle server.
    pub const fn new() -> Self {
        Self {
            next: None,
            last: Nanos::ZERO,
            timeouts: 0,
        }
    }

    /// Whether a write transfer is in progress.
    pub fn busy(&self) -> bool {
        self.next.is_some()
    }

    /// Transfers dropped by the timeout so far.
    pub fn timeouts(&self) -> u32 {
        self.timeouts
    }

    /// Ends a transfer in progress (state change, mailbox reset).
    pub fn reset<H: FoeHandler>(&mut self, handler: &mut H) {
        if self.next.take().is_some() {
            handler.abort();
        }
    }

    /// Drops a transfer that saw no packet for [`FOE_TIMEOUT`]; returns whether
    /// it did now.
    pub fn tick<H: FoeHandler>(&mut self, handler: &mut H, now: Nanos) -> bool {
        if self.next.is_some() && now.wrapping_sub(self.last) > FOE_TIMEOUT {
            self.reset(handler);
            self.timeouts = self.timeouts.saturating_add(1);
            true
        } else {
            false
        }
    }

    fn fail<H: FoeHandler>(
        &mut self,
        handler: &mut H,
        out: &mut [u8],
        e: FoeError,
    ) -> Result<Option<usize>, MailboxError> {
        self.reset(handler);
        reply(out, opcode::ERROR, e.0)
    }

    /// Handles one FoE request (`req`: the mailbox data) in Bootstrap (`boot`) or
    /// another mailbox state; the reply goes to `out`. `max_data` is the largest
    /// DATA payload the receive mailbox carries (a shorter packet is the last).
    /// `Ok(None)`: no reply (the master's own error request).
    pub fn handle<H: FoeHandler>(
        &mut self,
        req: &[u8],
        out: &mut [u8],
        handler: &mut H,
        boot: bool,
        max_data: usize,
        now: Nanos,
    ) -> Result<Option<usize>, MailboxError> {
        if req.len() < FOE_HEADER_LEN {
            return Err(MailboxError::SIZE_TOO_SHORT);
        }
        let op = req.first().copied().unwrap_or(0);
        let field = le32(req, 2);
        let rest = req.get(FOE_HEADER_LEN..).unwrap_or_default();
        self.last = now;
        match op {
            opcode::WRITE => {
                self.reset(handler);
                if !boot {
                    return reply(out, opcode::ERROR, FoeError::BOOTSTRAP_ONLY.0);
                }
                match handler.begin_write(rest, field) {
                    Ok(()) => {
                        self.next = Some(1);
                        reply(out, opcode::ACK, 0)
                    }
                    Err(e) => reply(out, opcode::ERROR, e.0),
                }
            }
            opcode::DATA => {
                let Some(next) = self.next else {
                    return reply(out, opcode::ERROR, FoeError::ILLEGAL.0);
                };
                if field != next {
                    return self.fail(handler, out, FoeError::PACKET_NUMBER);
                }
                match handler.write(rest) {
                    Err(e) => self.fail(handler, out, e),
                    Ok(Accept::Busy { done, entire }) => {
                        reply(out, opcode::BUSY, u32::from(done) | (u32::from(entire) << 16))
                    }
                    Ok(Accept::Done) if rest.len() < max_data => {
                        self.next = None;
                        match handler.end_write() {
                            Ok(()) => reply(out, opcode::ACK, field),
                            Err(e) => self.fail(handler, out, e),
                        }
                    }
                    Ok(Accept::Done) => {
                        self.next = Some(next.wrapping_add(1));
                        reply(out, opcode::ACK, field)
                    }
                }
            }
            opcode::ERROR => {
                // the master gives up: no reply
                self.reset(handler);
                Ok(None)
            }
            opcode::READ => self.fail(handler, out, FoeError::NOT_FOUND),
            _ => self.fail(handler, out, FoeError::ILLEGAL),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate std;
    use std::vec::Vec;

    /// Collects the file; `busy` packets are answered BUSY once each.
    #[derive(Default)]
    struct Sink {
        data: Vec<u8>,
        began: u32,
        ended: u32,
        aborted: u32,
        busy_once: bool,
        fail_end: Option<FoeError>,
    }

    impl FoeHandler for Sink {
        fn begin_write(&mut self, name: &[u8], _password: u32) -> Result<(), FoeError> {
            if name != b"firmware.bin" {
                return Err(FoeError::NOT_FOUND);
            }
            self.began += 1;
            self.data.clear();
            Ok(())
        }
        fn write(&mut self, data: &[u8]) -> Result<Accept, FoeError> {
            if std::mem::take(&mut self.busy_once) {
                return Ok(Accept::Busy { done: 3, entire: 10 });
            }
            self.data.extend_from_slice(data);
            Ok(Accept::Done)
        }
        fn end_write(&mut self) -> Result<(), FoeError> {
            self.ended += 1;
            self.fail_end.map_or(Ok(()), Err)
        }
        fn abort(&mut self) {
            self.aborted += 1;
        }
    }

    const MAX: usize = 8;

    fn send(s: &mut FoeServer, h: &mut Sink, req: &[u8], boot: bool, t: u64) -> Option<Vec<u8>> {
        let mut out = [0u8; 64];
        s.handle(req, &mut out, h, boot, MAX, Nanos::from_ns(t))
            .unwrap()
            .map(|n| out[..n].to_vec())
    }

    fn wrq(name: &[u8]) -> Vec<u8> {
        let mut r = std::vec![2, 0, 0, 0, 0, 0];
        r.extend_from_slice(name);
        r
    }

    fn data(n: u32, d: &[u8]) -> Vec<u8> {
        let mut r = std::vec![3, 0];
        r.extend_from_slice(&n.to_le_bytes());
        r.extend_from_slice(d);
        r
    }

    fn ack(n: u32) -> Vec<u8> {
        let mut r = std::vec![4, 0];
        r.extend_from_slice(&n.to_le_bytes());
        r
    }

    fn err(code: FoeError) -> Vec<u8> {
        let mut r = std::vec![5, 0];
        r.extend_from_slice(&code.0.to_le_bytes());
        r
    }

    #[test]
    fn write_with_packet_numbers_and_short_last_packet() {
        let (mut s, mut h) = (FoeServer::new(), Sink::default());
        assert_eq!(send(&mut s, &mut h, &wrq(b"firmware.bin"), true, 0), Some(ack(0)));
        assert_eq!(send(&mut s, &mut h, &data(1, &[1; MAX]), true, 1), Some(ack(1)));
        assert!(s.busy());
        assert_eq!(send(&mut s, &mut h, &data(2, &[2; 3]), true, 2), Some(ack(2)));
        assert!(!s.busy());
        assert_eq!(h.data.len(), MAX + 3);
        assert_eq!((h.began, h.ended, h.aborted), (1, 1, 0));
        // a full last packet needs an empty one after it
        send(&mut s, &mut h, &wrq(b"firmware.bin"), true, 3);
        assert_eq!(send(&mut s, &mut h, &data(1, &[1; MAX]), true, 4), Some(ack(1)));
        assert_eq!(send(&mut s, &mut h, &data(2, &[]), true, 5), Some(ack(2)));
        assert_eq!(h.ended, 2);
    }

    #[test]
    fn write_outside_bootstrap_is_bootstrap_only() {
        let (mut s, mut h) = (FoeServer::new(), Sink::default());
        assert_eq!(
            send(&mut s, &mut h, &wrq(b"firmware.bin"), false, 0),
            Some(err(FoeError::BOOTSTRAP_ONLY))
        );
        assert_eq!(h.began, 0);
        assert!(!s.busy());
    }

    #[test]
    fn wrong_packet_number_ends_the_transfer() {
        let (mut s, mut h) = (FoeServer::new(), Sink::default());
        send(&mut s, &mut h, &wrq(b"firmware.bin"), true, 0);
        assert_eq!(
            send(&mut s, &mut h, &data(2, &[1; MAX]), true, 1),
            Some(err(FoeError::PACKET_NUMBER))
        );
        assert_eq!(h.aborted, 1);
        assert_eq!(
            send(&mut s, &mut h, &data(1, &[1; MAX]), true, 2),
            Some(err(FoeError::ILLEGAL)),
            "no transfer any more"
        );
    }

    #[test]
    fn busy_keeps_the_packet_number() {
        let (mut s, mut h) = (FoeServer::new(), Sink::default());
        send(&mut s, &mut h, &wrq(b"firmware.bin"), true, 0);
        h.busy_once = true;
        let busy = send(&mut s, &mut h, &data(1, &[1; MAX]), true, 1).unwrap();
        assert_eq!(busy, [6, 0, 3, 0, 10, 0]);
        assert_eq!(send(&mut s, &mut h, &data(1, &[1; MAX]), true, 2), Some(ack(1)));
        assert_eq!(h.data.len(), MAX);
    }

    #[test]
    fn timeout_drops_the_transfer() {
        let (mut s, mut h) = (FoeServer::new(), Sink::default());
        send(&mut s, &mut h, &wrq(b"firmware.bin"), true, 1000);
        send(&mut s, &mut h, &data(1, &[1; MAX]), true, 2000);
        assert!(!s.tick(&mut h, Nanos::from_ns(2000) + FOE_TIMEOUT));
        assert!(s.tick(&mut h, Nanos::from_ns(2001) + FOE_TIMEOUT));
        assert_eq!((h.aborted, s.timeouts()), (1, 1));
        assert!(!s.busy());
    }

    #[test]
    fn errors_read_and_unknown_opcodes() {
        let (mut s, mut h) = (FoeServer::new(), Sink::default());
        assert_eq!(
            send(&mut s, &mut h, &wrq(b"other"), true, 0),
            Some(err(FoeError::NOT_FOUND))
        );
        let mut rrq = wrq(b"firmware.bin");
        rrq[0] = 1;
        assert_eq!(
            send(&mut s, &mut h, &rrq, true, 0),
            Some(err(FoeError::NOT_FOUND))
        );
        assert_eq!(
            send(&mut s, &mut h, &ack(0), true, 0),
            Some(err(FoeError::ILLEGAL))
        );
        assert_eq!(
            send(&mut s, &mut h, &[9, 0, 0, 0, 0, 0], true, 0),
            Some(err(FoeError::ILLEGAL))
        );
        // the master's error ends a transfer without reply
        send(&mut s, &mut h, &wrq(b"firmware.bin"), true, 0);
        assert_eq!(send(&mut s, &mut h, &err(FoeError::NOT_DEFINED), true, 0), None);
        assert_eq!(h.aborted, 1);
        // a failed check at the end is reported
        h.fail_end = Some(FoeError::CHECKSUM);
        send(&mut s, &mut h, &wrq(b"firmware.bin"), true, 0);
        assert_eq!(
            send(&mut s, &mut h, &data(1, &[1]), true, 0),
            Some(err(FoeError::CHECKSUM))
        );
        let mut out = [0u8; 8];
        assert_eq!(
            s.handle(&[2, 0, 0], &mut out, &mut h, true, MAX, Nanos::ZERO),
            Err(MailboxError::SIZE_TOO_SHORT)
        );
    }
}
