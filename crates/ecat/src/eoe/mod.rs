//! Ethernet over EtherCAT (ETG.1000.6 §5.7, spec §9): the EoE header, the
//! reassembly of Ethernet frames from mailbox fragments, the fragmentation of
//! outgoing frames, and the set-IP-parameter service (E-095..E-097, E-093).
//!
//! EoE header (4 bytes, two little-endian words):
//!
//! | word | bits | field |
//! |---|---|---|
//! | 0 | 0..3 | frame type ([`frame_type`]) |
//! | 0 | 4..7 | port |
//! | 0 | 8 | last fragment |
//! | 0 | 9 | time appended (4-byte time stamp after the last fragment's data) |
//! | 0 | 10 | time request |
//! | 1 | 0..5 | fragment number |
//! | 1 | 6..11 | fragment 0: complete size in 32-byte blocks, rounded up; else offset / 32 |
//! | 1 | 12..15 | frame number |
//!
//! In the responses (set IP / set address filter / get IP) word 1 is the
//! result code ([`result`]).
//!
//! The application sees only whole Ethernet frames, through [`EthernetPort`].

use crate::emcy::Emcy;
use crate::mailbox::MailboxError;

/// Length of the EoE header.
pub const HEADER_LEN: usize = 4;
/// Largest Ethernet frame (without FCS) the slave reassembles or sends.
pub const MAX_FRAME: usize = 1536;
/// Smallest frame delivered: destination, source, EtherType.
pub const MIN_FRAME: usize = 14;
/// Length of the time stamp a "time appended" last fragment carries.
pub const TIME_STAMP_LEN: usize = 4;
/// Length of the DNS name field of the set-IP-parameter request.
pub const DNS_NAME_LEN: usize = 32;

/// EoE frame types (word 0, bits 0..3).
pub mod frame_type {
    /// Fragment of an Ethernet frame.
    pub const FRAGMENT: u8 = 0;
    /// Set IP parameter request (master → slave).
    pub const SET_IP_REQUEST: u8 = 2;
    /// Set IP parameter response.
    pub const SET_IP_RESPONSE: u8 = 3;
    /// Set address filter request.
    pub const SET_FILTER_REQUEST: u8 = 4;
    /// Set address filter response.
    pub const SET_FILTER_RESPONSE: u8 = 5;
    /// Get IP parameter request.
    pub const GET_IP_REQUEST: u8 = 6;
    /// Get IP parameter response.
    pub const GET_IP_RESPONSE: u8 = 7;
}

/// EoE result codes (response word 1).
pub mod result {
    /// Success.
    pub const SUCCESS: u16 = 0x0000;
    /// Unspecified error (here: a refused IP configuration, E-097).
    pub const UNSPECIFIED_ERROR: u16 = 0x0001;
    /// Unsupported frame type.
    pub const UNSUPPORTED_FRAME_TYPE: u16 = 0x0002;
    /// No IP support.
    pub const NO_IP_SUPPORT: u16 = 0x0201;
    /// DHCP not supported.
    pub const NO_DHCP_SUPPORT: u16 = 0x0202;
    /// No address filter support.
    pub const NO_FILTER_SUPPORT: u16 = 0x0401;
}

mod frag;
mod ip;
#[cfg(test)]
pub(crate) mod tests;

pub use frag::{FragmentError, Fragmenter, Reassembly};
pub use ip::*;

/// The EoE header (checked view).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EoeHeader {
    /// Frame type ([`frame_type`]).
    pub frame_type: u8,
    /// Port (0..15).
    pub port: u8,
    /// Last fragment of the frame.
    pub last: bool,
    /// A 4-byte time stamp follows the data of the last fragment.
    pub time_appended: bool,
    /// The sender asks for a time stamp.
    pub time_request: bool,
    /// Word 1: fragment number / size or offset / frame number, or the result.
    pub info: u16,
}

impl EoeHeader {
    /// Parses the header at the start of `buf` (`None` when shorter).
    pub fn parse(buf: &[u8]) -> Option<Self> {
        match buf.get(..HEADER_LEN)? {
            &[b0, b1, i0, i1] => Some(Self {
                frame_type: b0 & 0x0F,
                port: b0 >> 4,
                last: b1 & 0x01 != 0,
                time_appended: b1 & 0x02 != 0,
                time_request: b1 & 0x04 != 0,
                info: u16::from_le_bytes([i0, i1]),
            }),
            _ => None,
        }
    }

    /// A fragment header: `size_or_offset` in 32-byte blocks.
    pub const fn fragment(last: bool, fragment: u8, size_or_offset: u8, frame_number: u8) -> Self {
        Self {
            frame_type: frame_type::FRAGMENT,
            port: 0,
            last,
            time_appended: false,
            time_request: false,
            info: (fragment as u16 & 0x3F)
                | ((size_or_offset as u16 & 0x3F) << 6)
                | ((frame_number as u16 & 0x0F) << 12),
        }
    }

    /// A response header (single fragment) with `result`.
    pub const fn response(frame_type: u8, port: u8, result: u16) -> Self {
        Self {
            frame_type,
            port,
            last: true,
            time_appended: false,
            time_request: false,
            info: result,
        }
    }

    /// Fragment number (word 1 bits 0..5).
    pub const fn fragment_number(&self) -> u8 {
        (self.info & 0x3F) as u8
    }

    /// Fragment 0: complete size; others: offset; in 32-byte blocks.
    pub const fn size_or_offset(&self) -> u8 {
        ((self.info >> 6) & 0x3F) as u8
    }

    /// Frame number (word 1 bits 12..15).
    pub const fn frame_number(&self) -> u8 {
        (self.info >> 12) as u8
    }

    /// Result code of a response.
    pub const fn result(&self) -> u16 {
        self.info
    }

    /// The 4 header bytes.
    pub fn to_bytes(&self) -> [u8; HEADER_LEN] {
        let [i0, i1] = self.info.to_le_bytes();
        [
            (self.frame_type & 0x0F) | (self.port << 4),
            u8::from(self.last) | (u8::from(self.time_appended) << 1) | (u8::from(self.time_request) << 2),
            i0,
            i1,
        ]
    }
}

/// The application's side of the EoE interface: whole Ethernet frames.
pub trait EthernetPort {
    /// A complete Ethernet frame (destination MAC first, no FCS) arrived.
    fn receive(&mut self, frame: &[u8]);
    /// The next frame to send: written into `buf`, its length returned;
    /// `None` when there is nothing to send. Asked only when SM1 is free and
    /// the previous frame has gone out completely.
    fn transmit(&mut self, buf: &mut [u8]) -> Option<usize>;
    /// The master set new IP parameters (E-096).
    fn ip_changed(&mut self, _params: &IpParams) {}
}

/// A port that drops what it receives and sends nothing.
pub struct NoEthernet;

impl EthernetPort for NoEthernet {
    fn receive(&mut self, _frame: &[u8]) {}
    fn transmit(&mut self, _buf: &mut [u8]) -> Option<usize> {
        None
    }
}

/// A port that counts the frames it receives (and keeps the length and an
/// FNV-1a hash of the last one), sends nothing: the drive's EoE interface
/// until an IP stack is bound to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FrameCounter {
    /// Frames received.
    pub frames: u32,
    /// Length of the last frame.
    pub last_len: usize,
    /// FNV-1a (32 bit) of the last frame.
    pub last_hash: u32,
}

/// FNV-1a, 32 bit.
pub fn fnv1a(data: &[u8]) -> u32 {
    data.iter().fold(0x811C_9DC5u32, |h, &b| {
        (h ^ u32::from(b)).wrapping_mul(0x0100_0193)
    })
}

impl EthernetPort for FrameCounter {
    fn receive(&mut self, frame: &[u8]) {
        self.frames = self.frames.wrapping_add(1);
        self.last_len = frame.len();
        self.last_hash = fnv1a(frame);
    }
    fn transmit(&mut self, _buf: &mut [u8]) -> Option<usize> {
        None
    }
}

/// EoE counters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct EoeStats {
    /// Frames handed to the application.
    pub frames_received: u32,
    /// Frames sent completely.
    pub frames_sent: u32,
    /// Frames dropped in reassembly.
    pub frames_dropped: u32,
    /// Set-IP-parameter requests refused.
    pub ip_rejected: u32,
}

/// The EoE server of the slave: one port (port numbers are not checked).
#[derive(Clone)]
pub struct EoeServer {
    rx: Reassembly,
    tx: Fragmenter,
    params: IpParams,
    /// The last set-IP request was refused and EMCY FFF0h sent.
    address_error: bool,
    /// An emergency for the slave to queue.
    emcy: Option<Emcy>,
    frames_received: u32,
    frames_sent: u32,
    ip_rejected: u32,
    last_error: Option<FragmentError>,
    /// The master has sent an EoE message since the mailbox was set up
    /// (E-098): only then does the slave originate EoE traffic.
    master_active: bool,
}

impl Default for EoeServer {
    fn default() -> Self {
        Self::new()
    }
}

impl EoeServer {
    /// No IP parameters, nothing in transit.
    pub const fn new() -> Self {
        Self {
            rx: Reassembly::new(),
            tx: Fragmenter::new(),
            params: IpParams {
                mac: None,
                ip: None,
                mask: None,
                gateway: None,
                dns: None,
                dns_name: None,
            },
            address_error: false,
            emcy: None,
            frames_received: 0,
            frames_sent: 0,
            ip_rejected: 0,
            last_error: None,
            master_active: false,
        }
    }

    /// Drops the frames in assembly and in transmission (leaving Pre-Op
    /// for Init or Bootstrap). The IP parameters stay; the master has to
    /// show again that it uses EoE before the slave sends (E-098).
    pub fn reset(&mut self) {
        self.rx.reset();
        self.tx.reset();
        self.master_active = false;
    }

    /// Whether the master has used EoE since the mailbox was set up (any
    /// EoE message: a fragment, a set- or get-IP request). Until then the
    /// slave originates no EoE traffic: a master without an EoE handler
    /// would read an unasked fragment as the answer to its next request
    /// (E-098, docs/conformance.md).
    pub fn master_active(&self) -> bool {
        self.master_active
    }

    /// The IP parameters the master set (E-096).
    pub fn params(&self) -> &IpParams {
        &self.params
    }

    /// Whether the last set-IP request was refused (the address cannot be
    /// opened, EMCY FFF0h/23h sent).
    pub fn address_error(&self) -> bool {
        self.address_error
    }

    /// Counters.
    pub fn stats(&self) -> EoeStats {
        EoeStats {
            frames_received: self.frames_received,
            frames_sent: self.frames_sent,
            frames_dropped: self.rx.dropped(),
            ip_rejected: self.ip_rejected,
        }
    }

    /// Why the last fragment was refused.
    pub fn last_fragment_error(&self) -> Option<FragmentError> {
        self.last_error
    }

    /// The emergency to queue after the last request (E-093).
    pub fn take_emcy(&mut self) -> Option<Emcy> {
        self.emcy.take()
    }

    /// Handles one EoE mailbox message (`payload`: the mailbox data); a
    /// response goes to `out` (the mailbox data area) and its length is
    /// returned. Fragments have no response.
    pub fn handle<E: EthernetPort>(
        &mut self,
        payload: &[u8],
        out: &mut [u8],
        port: &mut E,
    ) -> Result<Option<usize>, MailboxError> {
        let h = EoeHeader::parse(payload).ok_or(MailboxError::SIZE_TOO_SHORT)?;
        let data = payload.get(HEADER_LEN..).unwrap_or_default();
        self.master_active = true;
        match h.frame_type {
            frame_type::FRAGMENT => {
                match self.rx.push(&h, data) {
                    Ok(Some(_)) => {
                        self.frames_received = self.frames_received.wrapping_add(1);
                        port.receive(self.rx.frame());
                    }
                    Ok(None) => {}
                    Err(e) => self.last_error = Some(e),
                }
                Ok(None)
            }
            frame_type::SET_IP_REQUEST => {
                let code = match parse_set_ip(data).and_then(|req| apply_set_ip(&self.params, &req)) {
                    Ok(p) => {
                        self.params = p;
                        if core::mem::take(&mut self.address_error) {
                            self.emcy = Some(Emcy::eoe_cleared());
                        }
                        port.ip_changed(&self.params);
                        result::SUCCESS
                    }
                    Err(_) => {
                        // E-093: the address cannot be opened
                        self.address_error = true;
                        self.ip_rejected = self.ip_rejected.wrapping_add(1);
                        self.emcy = Some(Emcy::eoe_error());
                        result::UNSPECIFIED_ERROR
                    }
                };
                respond(out, frame_type::SET_IP_RESPONSE, h.port, code, &[])
            }
            frame_type::SET_FILTER_REQUEST => respond(
                out,
                frame_type::SET_FILTER_RESPONSE,
                h.port,
                result::NO_FILTER_SUPPORT,
                &[],
            ),
            frame_type::GET_IP_REQUEST => {
                let (body, len) = get_ip_body(&self.params);
                let body = body.get(..len).unwrap_or_default();
                respond(out, frame_type::GET_IP_RESPONSE, h.port, result::SUCCESS, body)
            }
            // a response type from the master, or an unknown type
            t => respond(out, t, h.port, result::UNSUPPORTED_FRAME_TYPE, &[]),
        }
    }

    /// The next outgoing fragment into `out` (the mailbox data area), asking
    /// `port` for a new frame when the previous one has gone out.
    /// Nothing before the master has used EoE ([`Self::master_active`]).
    pub fn next_fragment<E: EthernetPort>(&mut self, out: &mut [u8], port: &mut E) -> Option<usize> {
        if !self.master_active {
            return None;
        }
        if !self.tx.load(|buf| port.transmit(buf)) {
            return None;
        }
        let n = self.tx.next(out)?;
        if !self.tx.active() {
            self.frames_sent = self.frames_sent.wrapping_add(1);
        }
        Some(n)
    }

    /// Whether a frame is being sent in fragments.
    pub fn sending(&self) -> bool {
        self.tx.active()
    }
}

/// Writes a response header (+ `body`) into `out`.
fn respond(
    out: &mut [u8],
    frame_type: u8,
    port: u8,
    code: u16,
    body: &[u8],
) -> Result<Option<usize>, MailboxError> {
    let h = EoeHeader::response(frame_type, port, code).to_bytes();
    let len = HEADER_LEN + body.len();
    let dst = out.get_mut(..len).ok_or(MailboxError::NO_MORE_MEMORY)?;
    for (d, s) in dst.iter_mut().zip(h.iter().chain(body)) {
        *d = *s;
    }
    Ok(Some(len))
}
