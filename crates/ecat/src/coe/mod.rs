//! CAN application protocol over EtherCAT (spec §6–7, ETG.1000.6 §5.6): the
//! CoE header and the CoE server.
//!
//! [`CoeServer`] keeps the state that spans mailbox messages and answers:
//!
//! - SDO download: expedited, normal with the data in the initiate frame, and
//!   segmented (7-byte CAN-style segments and longer ones, segment data length =
//!   mailbox data length − 3); the value is written with one
//!   [`Dictionary::write`] once complete (at most [`MAX_TRANSFER`] bytes).
//! - SDO upload: expedited (≤ 4 bytes), normal (all data in the initiate
//!   response when it fits the mailbox), segmented otherwise; the value is read
//!   with one [`Dictionary::read`] at the initiate.
//! - Complete access to ARRAY and RECORD objects (see [`complete`]).
//! - Abort from the master (no reply), SDO protocol timeout ([`SDO_TIMEOUT`]).
//! - SDO Information (service 8, [`crate::sdo_info`]), fragmented OD lists.
//!
//! Requests are parsed into typed values first ([`SdoRequest`],
//! [`crate::sdo_info::InfoRequest`]) and acted on afterwards; no input panics.
//!
//! Design decisions and limits:
//!
//! - A segmented upload's initiate response carries the size only, no data
//!   (the shape of spec §6.4; ethercrab 0.7.1 drops data sent in a segmented
//!   initiate response). Segments are as long as the mailbox allows (mailbox
//!   data − 3 bytes), at least 7 bytes with n counting the unused ones.
//! - The server cannot send unsolicited frames: after the protocol timeout the
//!   abort 0504 0000h is the answer to the next segment request of that
//!   transfer. A new initiate always replaces the transfer in progress.
//! - Size mismatch between the announced and the received byte count: 0607 0010h.
//! - Objects larger than [`MAX_TRANSFER`]: 0504 0005h (download: at the
//!   initiate, before any write; upload: when the dictionary cannot fill the
//!   buffer).
//! - SDO Info fragments are produced as soon as the send mailbox is free; if
//!   the master loses one and asks for a repeat after the next fragment was
//!   produced, the repeat carries the newer fragment.

pub mod complete;
mod sdo;

use crate::mailbox::MailboxError;
use crate::sdo_info::{self, OdListCursor};
use esc::AlState;
use nanos::Nanos;

pub use od::{CommState, Dictionary, SdoAbort};
pub use sdo::SdoRequest;

/// Length of the CoE header.
pub const COE_HEADER_LEN: usize = 2;
/// Length of an SDO initiate/abort frame after the CoE header.
pub const SDO_LEN: usize = 8;
/// Largest value one SDO transfer moves (download buffer, upload buffer, one
/// complete access).
pub const MAX_TRANSFER: usize = 4096;
/// A segmented transfer that sees no segment request for this long is dropped;
/// the next segment request is answered with abort 0504 0000h.
pub const SDO_TIMEOUT: Nanos = Nanos::from_secs(1);

/// CoE services (CoE header bits 12..15).
pub mod service {
    /// Emergency.
    pub const EMERGENCY: u8 = 1;
    /// SDO request.
    pub const SDO_REQUEST: u8 = 2;
    /// SDO response.
    pub const SDO_RESPONSE: u8 = 3;
    /// SDO information.
    pub const SDO_INFO: u8 = 8;
}

/// The CoE header: number (bits 0..8), service (bits 12..15).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CoeHeader {
    /// Number (PDO number / EMCY: 0).
    pub number: u16,
    /// Service (see [`service`]).
    pub service: u8,
}

impl CoeHeader {
    /// Parses the first two bytes of `buf`.
    pub fn parse(buf: &[u8]) -> Option<Self> {
        match buf.get(..COE_HEADER_LEN)? {
            &[a, b] => {
                let raw = u16::from_le_bytes([a, b]);
                Some(Self {
                    number: raw & 0x01FF,
                    service: (raw >> 12) as u8,
                })
            }
            _ => None,
        }
    }

    /// The two header bytes.
    pub fn to_bytes(self) -> [u8; 2] {
        ((self.number & 0x01FF) | (u16::from(self.service & 0x0F) << 12)).to_le_bytes()
    }
}

/// What the CoE server offers, from the device description's CoE details
/// (SII general category, `desc::coe_details`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CoeConfig {
    /// SDO Information (service 8) is answered (E-079); otherwise service 8 gets
    /// the mailbox error "service not supported".
    pub sdo_info: bool,
    /// Complete access (command bit 4) is served (E-078); otherwise it is
    /// aborted with 0601 0000h.
    pub complete_access: bool,
}

impl CoeConfig {
    /// Everything on.
    pub const ALL: Self = Self {
        sdo_info: true,
        complete_access: true,
    };

    /// From the CoE details bits (`desc::coe_details::SDO_INFO`,
    /// `desc::coe_details::SDO_COMPLETE_ACCESS`).
    pub const fn from_details(bits: u8) -> Self {
        Self {
            sdo_info: bits & crate::desc::coe_details::SDO_INFO != 0,
            complete_access: bits & crate::desc::coe_details::SDO_COMPLETE_ACCESS != 0,
        }
    }
}

/// A segmented transfer in progress.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Transfer {
    Idle,
    Download {
        index: u16,
        sub: u8,
        complete_access: bool,
        /// Announced size (`None`: initiate without size indicator).
        size: Option<usize>,
        /// Toggle bit the next segment must carry.
        toggle: bool,
        last: Nanos,
    },
    Upload {
        index: u16,
        sub: u8,
        /// Bytes of `buf` already sent.
        pos: usize,
        toggle: bool,
        last: Nanos,
    },
    /// Dropped by the protocol timeout; the next segment request gets 0504 0000h.
    TimedOut {
        index: u16,
        sub: u8,
    },
}

/// A refused SDO request: index, subindex, abort code.
type Failure = (u16, u8, SdoAbort);

/// The CoE server: SDO transfers and SDO Information with the state that spans
/// mailbox messages. One per slave; [`crate::Slave`] holds it.
#[derive(Clone)]
pub struct CoeServer {
    config: CoeConfig,
    transfer: Transfer,
    /// Value of the transfer in progress (download: received so far; upload: the
    /// whole value read at the initiate).
    buf: [u8; MAX_TRANSFER],
    len: usize,
    /// An SDO Info OD list still being sent in fragments.
    od_list: Option<OdListCursor>,
}

impl CoeServer {
    /// An idle server offering `config`.
    pub const fn new(config: CoeConfig) -> Self {
        Self {
            config,
            transfer: Transfer::Idle,
            buf: [0; MAX_TRANSFER],
            len: 0,
            od_list: None,
        }
    }

    /// What the server offers.
    pub fn config(&self) -> CoeConfig {
        self.config
    }

    /// Drops every transfer and pending fragment (mailbox restarted or stopped).
    pub fn reset(&mut self) {
        self.transfer = Transfer::Idle;
        self.len = 0;
        self.od_list = None;
    }

    /// A segmented SDO transfer is in progress.
    pub fn transfer_in_progress(&self) -> bool {
        matches!(self.transfer, Transfer::Download { .. } | Transfer::Upload { .. })
    }

    /// More SDO Info fragments wait to be sent: call
    /// [`CoeServer::next_fragment`] whenever the send mailbox is free.
    pub fn has_fragments(&self) -> bool {
        self.od_list.is_some()
    }

    /// Writes the next SDO Info fragment (CoE header + data) into `out`
    /// (capacity = SM1 length − 6, the same as for the request that started
    /// it) and returns its length; `None` when nothing is pending.
    pub fn next_fragment<D: Dictionary>(&mut self, out: &mut [u8], dict: &mut D) -> Option<usize> {
        sdo_info::next_fragment(out, dict, &mut self.od_list)
    }

    /// Checks the SDO protocol timeout at `now`: a segmented transfer idle
    /// for more than [`SDO_TIMEOUT`] is dropped. [`CoeServer::handle`] calls it
    /// too.
    pub fn tick(&mut self, now: Nanos) {
        let (index, sub, last) = match self.transfer {
            Transfer::Download { index, sub, last, .. } | Transfer::Upload { index, sub, last, .. } => {
                (index, sub, last)
            }
            Transfer::Idle | Transfer::TimedOut { .. } => return,
        };
        if now.since(last) > SDO_TIMEOUT {
            self.transfer = Transfer::TimedOut { index, sub };
            self.len = 0;
        }
    }

    /// Handles one CoE mailbox payload (`req` = CoE header + service data) in
    /// ESM state `state` at `now` and writes the response's mailbox data into
    /// `out` (capacity = SM1 length − 6). Returns the response length, `None`
    /// when nothing is to be sent, or the mailbox error to reply with.
    ///
    /// Any request ends an SDO Info list still being fragmented.
    pub fn handle<D: Dictionary>(
        &mut self,
        req: &[u8],
        out: &mut [u8],
        dict: &mut D,
        state: AlState,
        now: Nanos,
    ) -> Result<Option<usize>, MailboxError> {
        self.tick(now);
        self.od_list = None;
        let header = CoeHeader::parse(req).ok_or(MailboxError::SIZE_TOO_SHORT)?;
        let body = req.get(COE_HEADER_LEN..).unwrap_or_default();
        match header.service {
            service::SDO_REQUEST => {
                let request = SdoRequest::parse(body).ok_or(MailboxError::SIZE_TOO_SHORT)?;
                match self.sdo(request, out, dict, comm_state(state), now) {
                    Ok(reply) => Ok(reply),
                    Err((index, sub, code)) => {
                        // an abort ends the transfer in progress
                        self.transfer = Transfer::Idle;
                        self.len = 0;
                        abort_frame(out, index, sub, code)
                            .map(Some)
                            .ok_or(MailboxError::NO_MORE_MEMORY)
                    }
                }
            }
            // E-079: only with the CoE detail and the "EtherCAT Rx SDO Info" template
            service::SDO_INFO if self.config.sdo_info && dict.sdo_info_enabled() => {
                sdo_info::handle(body, out, dict, &mut self.od_list)
            }
            _ => Err(MailboxError::SERVICE_NOT_SUPPORTED),
        }
    }
}

/// The access state of an ESM state (Bootstrap has no CoE; treated as Init).
pub fn comm_state(state: AlState) -> CommState {
    match state {
        AlState::Init | AlState::Bootstrap => CommState::Init,
        AlState::PreOp => CommState::PreOp,
        AlState::SafeOp => CommState::SafeOp,
        AlState::Op => CommState::Op,
    }
}

/// Checked little-endian writer over a response buffer.
pub(crate) struct Writer<'a> {
    buf: &'a mut [u8],
    pos: usize,
}

impl<'a> Writer<'a> {
    pub(crate) fn new(buf: &'a mut [u8]) -> Self {
        Self { buf, pos: 0 }
    }

    /// Appends `data`; `None` (nothing written) when it does not fit.
    pub(crate) fn bytes(&mut self, data: &[u8]) -> Option<()> {
        let end = self.pos.checked_add(data.len())?;
        self.buf.get_mut(self.pos..end)?.copy_from_slice(data);
        self.pos = end;
        Some(())
    }

    /// Appends as much of `data` as fits; returns the count.
    pub(crate) fn truncated(&mut self, data: &[u8]) -> usize {
        let n = data.len().min(self.remaining());
        match self.bytes(data.get(..n).unwrap_or_default()) {
            Some(()) => n,
            None => 0,
        }
    }

    pub(crate) fn zeros(&mut self, n: usize) -> Option<()> {
        let end = self.pos.checked_add(n)?;
        self.buf.get_mut(self.pos..end)?.fill(0);
        self.pos = end;
        Some(())
    }

    pub(crate) fn u8(&mut self, v: u8) -> Option<()> {
        self.bytes(&[v])
    }

    pub(crate) fn u16(&mut self, v: u16) -> Option<()> {
        self.bytes(&v.to_le_bytes())
    }

    pub(crate) fn u32(&mut self, v: u32) -> Option<()> {
        self.bytes(&v.to_le_bytes())
    }

    pub(crate) fn coe_header(&mut self, service: u8) -> Option<()> {
        self.bytes(&CoeHeader { number: 0, service }.to_bytes())
    }

    pub(crate) fn remaining(&self) -> usize {
        self.buf.len().saturating_sub(self.pos)
    }

    pub(crate) fn len(&self) -> usize {
        self.pos
    }
}

/// CoE header + 8-byte SDO frame (command, index, subindex, 4 data bytes).
fn sdo_frame(out: &mut [u8], service: u8, cmd: u8, index: u16, sub: u8, data: [u8; 4]) -> Option<usize> {
    let mut w = Writer::new(out);
    w.coe_header(service)?;
    w.u8(cmd)?;
    w.u16(index)?;
    w.u8(sub)?;
    w.bytes(&data)?;
    Some(w.len())
}

/// The abort frame (E-077): service 2, command 80h, index, subindex, code
/// (additional code, error code, error class: the code little-endian).
fn abort_frame(out: &mut [u8], index: u16, sub: u8, code: SdoAbort) -> Option<usize> {
    sdo_frame(out, service::SDO_REQUEST, 0x80, index, sub, code.0.to_le_bytes())
}

#[cfg(test)]
mod tests;
