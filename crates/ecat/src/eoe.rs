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

/// Flags of the set/get-IP-parameter body (first 4 bytes after the header).
pub mod ip_flags {
    /// MAC address included.
    pub const MAC: u32 = 1 << 0;
    /// IP address included.
    pub const IP: u32 = 1 << 1;
    /// Subnet mask included.
    pub const MASK: u32 = 1 << 2;
    /// Default gateway included.
    pub const GATEWAY: u32 = 1 << 3;
    /// DNS server included.
    pub const DNS: u32 = 1 << 4;
    /// DNS name included.
    pub const DNS_NAME: u32 = 1 << 5;
}

/// Byte offsets of the set-IP-parameter fields in the EoE data (after the
/// header): fixed positions, a field not included is still there (ETG.1000.6
/// layout, as TwinCAT and the IgH master send it).
mod ip_offset {
    pub const FLAGS: usize = 0;
    pub const MAC: usize = 4;
    pub const IP: usize = 10;
    pub const MASK: usize = 14;
    pub const GATEWAY: usize = 18;
    pub const DNS: usize = 22;
    pub const DNS_NAME: usize = 26;
    pub const END: usize = 58;
}

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

/// Why a fragment was refused; the frame being assembled is dropped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FragmentError {
    /// A later fragment without a frame in assembly.
    NoFrame,
    /// Fragment number out of sequence.
    Sequence,
    /// Frame number differs from the frame in assembly.
    FrameNumber,
    /// Offset does not match the bytes received so far.
    Offset,
    /// More data than the complete size announced (or than [`MAX_FRAME`]).
    TooLong,
    /// The finished frame is shorter than an Ethernet header (or than its
    /// time stamp).
    TooShort,
}

/// Reassembly of one Ethernet frame from EoE fragments into a fixed buffer.
pub struct Reassembly {
    buf: [u8; MAX_FRAME],
    len: usize,
    /// Announced complete size, bytes (32-byte blocks × 32, capped at the buffer).
    size: usize,
    next_fragment: u8,
    frame_number: u8,
    active: bool,
    /// Frames dropped (bad or out-of-order fragments, interrupted frames).
    dropped: u32,
}

impl Default for Reassembly {
    fn default() -> Self {
        Self::new()
    }
}

impl Reassembly {
    /// Empty.
    pub const fn new() -> Self {
        Self {
            buf: [0; MAX_FRAME],
            len: 0,
            size: 0,
            next_fragment: 0,
            frame_number: 0,
            active: false,
            dropped: 0,
        }
    }

    /// Drops the frame in assembly (not counted).
    pub fn reset(&mut self) {
        self.active = false;
        self.len = 0;
    }

    /// Whether a frame is being assembled.
    pub fn active(&self) -> bool {
        self.active
    }

    /// Frames dropped so far.
    pub fn dropped(&self) -> u32 {
        self.dropped
    }

    /// Takes one fragment (`data`: the mailbox data after the EoE header).
    /// Returns the length of the finished frame (then in [`frame`](Self::frame))
    /// after the last fragment. A bad fragment drops the frame in assembly
    /// and counts it; a fragment 0 while a frame is in assembly drops that
    /// frame (counted) and starts the new one.
    pub fn push(&mut self, h: &EoeHeader, data: &[u8]) -> Result<Option<usize>, FragmentError> {
        let r = self.push_inner(h, data);
        if r.is_err() {
            self.fail();
        }
        r
    }

    fn fail(&mut self) {
        self.dropped = self.dropped.wrapping_add(1);
        self.reset();
    }

    fn push_inner(&mut self, h: &EoeHeader, data: &[u8]) -> Result<Option<usize>, FragmentError> {
        let blocks = usize::from(h.size_or_offset()) * 32;
        if h.fragment_number() == 0 {
            if self.active {
                // the previous frame never finished
                self.fail();
            }
            if blocks == 0 {
                return Err(FragmentError::TooLong);
            }
            self.active = true;
            self.len = 0;
            self.size = blocks.min(MAX_FRAME);
            self.frame_number = h.frame_number();
            self.next_fragment = 0;
        } else {
            if !self.active {
                // counted, nothing to drop
                return Err(FragmentError::NoFrame);
            }
            if h.fragment_number() != self.next_fragment {
                return Err(FragmentError::Sequence);
            }
            if h.frame_number() != self.frame_number {
                return Err(FragmentError::FrameNumber);
            }
            if blocks != self.len {
                return Err(FragmentError::Offset);
            }
        }
        let end = self.len.checked_add(data.len()).ok_or(FragmentError::TooLong)?;
        // the time stamp of the last fragment may exceed the announced size
        let stamp = if h.last && h.time_appended {
            TIME_STAMP_LEN
        } else {
            0
        };
        if end > self.size.saturating_add(stamp) || end > MAX_FRAME + stamp {
            return Err(FragmentError::TooLong);
        }
        if !h.last {
            let dst = self.buf.get_mut(self.len..end).ok_or(FragmentError::TooLong)?;
            dst.copy_from_slice(data);
            self.len = end;
            self.next_fragment = (self.next_fragment + 1) & 0x3F;
            return Ok(None);
        }
        let data = data
            .get(..data.len().checked_sub(stamp).ok_or(FragmentError::TooShort)?)
            .ok_or(FragmentError::TooShort)?;
        let end = self.len + data.len();
        let dst = self.buf.get_mut(self.len..end).ok_or(FragmentError::TooLong)?;
        dst.copy_from_slice(data);
        if end < MIN_FRAME {
            return Err(FragmentError::TooShort);
        }
        self.len = end;
        self.active = false;
        Ok(Some(end))
    }

    /// The last finished frame.
    pub fn frame(&self) -> &[u8] {
        self.buf.get(..self.len).unwrap_or_default()
    }
}

/// Fragmentation of one outgoing Ethernet frame into mailbox-sized EoE
/// fragments (one per mailbox message).
pub struct Fragmenter {
    buf: [u8; MAX_FRAME],
    len: usize,
    sent: usize,
    fragment: u8,
    frame_number: u8,
    active: bool,
}

impl Default for Fragmenter {
    fn default() -> Self {
        Self::new()
    }
}

impl Fragmenter {
    /// Idle.
    pub const fn new() -> Self {
        Self {
            buf: [0; MAX_FRAME],
            len: 0,
            sent: 0,
            fragment: 0,
            frame_number: 0,
            active: false,
        }
    }

    /// Whether a frame is being sent.
    pub fn active(&self) -> bool {
        self.active
    }

    /// Drops the frame being sent.
    pub fn reset(&mut self) {
        self.active = false;
    }

    /// Loads the next frame from `fill` (which writes it into the buffer
    /// and returns its length) when idle; a length of 0 or beyond the
    /// buffer sends nothing. Returns whether a frame is being sent.
    pub fn load(&mut self, fill: impl FnOnce(&mut [u8]) -> Option<usize>) -> bool {
        if !self.active {
            if let Some(n) = fill(&mut self.buf).filter(|&n| n > 0 && n <= MAX_FRAME) {
                self.len = n;
                self.sent = 0;
                self.fragment = 0;
                self.frame_number = (self.frame_number + 1) & 0x0F;
                self.active = true;
            }
        }
        self.active
    }

    /// Writes the next fragment (EoE header + data) into `out` (the mailbox
    /// data area) and returns its length; `None` when idle or `out` cannot
    /// hold a header and 32 bytes (the frame is then dropped). Fragments but
    /// the last carry a multiple of 32 bytes.
    pub fn next(&mut self, out: &mut [u8]) -> Option<usize> {
        if !self.active {
            return None;
        }
        let room = out.len().saturating_sub(HEADER_LEN);
        let rest = self.len.saturating_sub(self.sent);
        let (n, last) = if rest <= room {
            (rest, true)
        } else {
            (room / 32 * 32, false)
        };
        if n == 0 && !last {
            self.active = false;
            return None;
        }
        let size_or_offset = if self.fragment == 0 {
            self.len.div_ceil(32)
        } else {
            self.sent / 32
        };
        let h = EoeHeader::fragment(last, self.fragment, size_or_offset as u8, self.frame_number);
        let src = self.buf.get(self.sent..self.sent + n)?;
        out.get_mut(..HEADER_LEN)?.copy_from_slice(&h.to_bytes());
        out.get_mut(HEADER_LEN..HEADER_LEN + n)?.copy_from_slice(src);
        self.sent += n;
        self.fragment = (self.fragment + 1) & 0x3F;
        if last {
            self.active = false;
        }
        Some(HEADER_LEN + n)
    }
}

/// An IPv4 address (network byte order, as on the wire).
pub type Ipv4 = [u8; 4];

/// The DNS name of the set-IP-parameter request (up to 32 bytes, NUL padded).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DnsName {
    bytes: [u8; DNS_NAME_LEN],
    len: u8,
}

impl DnsName {
    /// From the request's field (cut at the first NUL).
    pub fn from_field(field: &[u8]) -> Self {
        let mut bytes = [0; DNS_NAME_LEN];
        let mut len = 0;
        for (dst, &b) in bytes.iter_mut().zip(field.iter().take_while(|&&b| b != 0)) {
            *dst = b;
            len += 1;
        }
        Self { bytes, len }
    }

    /// The name's bytes.
    pub fn as_bytes(&self) -> &[u8] {
        self.bytes.get(..usize::from(self.len)).unwrap_or_default()
    }
}

/// The IP parameters the master handed over (E-096); `None` = never set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct IpParams {
    /// Virtual MAC address of the EoE interface.
    pub mac: Option<[u8; 6]>,
    /// IP address.
    pub ip: Option<Ipv4>,
    /// Subnet mask.
    pub mask: Option<Ipv4>,
    /// Default gateway.
    pub gateway: Option<Ipv4>,
    /// DNS server.
    pub dns: Option<Ipv4>,
    /// DNS name.
    pub dns_name: Option<DnsName>,
}

/// Why a set-IP-parameter request is refused (result
/// [`result::UNSPECIFIED_ERROR`], EMCY FFF0h/23h).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IpError {
    /// The request is shorter than its included fields.
    TooShort,
    /// Subnet mask not contiguous, or without room for two hosts (/31, /32).
    BadMask,
    /// IP address is the first (network) or last (broadcast) address of its
    /// subnet, 0.0.0.0 / 255.255.255.255, or multicast (E-097).
    HostAddress,
    /// Default gateway outside the subnet or not a host address.
    Gateway,
    /// MAC address is multicast or all zero.
    Mac,
}

/// Prefix length of a contiguous mask, `None` otherwise.
pub fn prefix_len(mask: Ipv4) -> Option<u32> {
    let m = u32::from_be_bytes(mask);
    let ones = m.leading_ones();
    (m.checked_shl(ones).unwrap_or(0) == 0).then_some(ones)
}

/// E-097 / C-150: `ip` is a usable host of the subnet `mask` (not its first
/// or last address). Masks of /31 and /32 have no such host.
pub fn is_host(ip: Ipv4, mask: Ipv4) -> bool {
    let (a, m) = (u32::from_be_bytes(ip), u32::from_be_bytes(mask));
    match prefix_len(mask) {
        Some(p) if p <= 30 => {
            let host = a & !m;
            host != 0 && host != !m
        }
        _ => false,
    }
}

/// Parses a set-IP-parameter request body (the EoE data after the header)
/// into the included fields.
pub fn parse_set_ip(data: &[u8]) -> Result<IpParams, IpError> {
    let field = |off: usize, len: usize| data.get(off..off + len).ok_or(IpError::TooShort);
    let ip4 = |off: usize| -> Result<Ipv4, IpError> {
        let mut a = [0; 4];
        a.copy_from_slice(field(off, 4)?);
        Ok(a)
    };
    let flags = u32::from_le_bytes(ip4(ip_offset::FLAGS)?);
    let mut p = IpParams::default();
    if flags & ip_flags::MAC != 0 {
        let mut mac = [0; 6];
        mac.copy_from_slice(field(ip_offset::MAC, 6)?);
        p.mac = Some(mac);
    }
    if flags & ip_flags::IP != 0 {
        p.ip = Some(ip4(ip_offset::IP)?);
    }
    if flags & ip_flags::MASK != 0 {
        p.mask = Some(ip4(ip_offset::MASK)?);
    }
    if flags & ip_flags::GATEWAY != 0 {
        p.gateway = Some(ip4(ip_offset::GATEWAY)?);
    }
    if flags & ip_flags::DNS != 0 {
        p.dns = Some(ip4(ip_offset::DNS)?);
    }
    if flags & ip_flags::DNS_NAME != 0 {
        // up to 32 bytes; a shorter (but non-empty) name field is accepted
        let name = data.get(ip_offset::DNS_NAME..).unwrap_or_default();
        if name.is_empty() {
            return Err(IpError::TooShort);
        }
        p.dns_name = Some(DnsName::from_field(name));
    }
    Ok(p)
}

/// Applies the included fields of `req` over `current` with the checks of
/// E-097 (all or nothing): the result is what the slave keeps.
pub fn apply_set_ip(current: &IpParams, req: &IpParams) -> Result<IpParams, IpError> {
    let next = IpParams {
        mac: req.mac.or(current.mac),
        ip: req.ip.or(current.ip),
        mask: req.mask.or(current.mask),
        gateway: req.gateway.or(current.gateway),
        dns: req.dns.or(current.dns),
        dns_name: req.dns_name.or(current.dns_name),
    };
    if let Some(mac) = req.mac {
        if mac.first().is_some_and(|b| b & 1 != 0) || mac == [0; 6] {
            return Err(IpError::Mac);
        }
    }
    if let Some(mask) = next.mask {
        if prefix_len(mask).is_none_or(|p| p > 30) {
            return Err(IpError::BadMask);
        }
    }
    if let Some(ip) = next.ip {
        // a multicast (224/4) address cannot be an interface's address
        let multicast = ip.first().is_some_and(|a| (224..=239).contains(a));
        let ok = !multicast
            && match next.mask {
                Some(mask) => is_host(ip, mask),
                // no mask known: only the all-zero and all-ones addresses are refused
                None => ip != [0; 4] && ip != [255; 4],
            };
        if !ok {
            return Err(IpError::HostAddress);
        }
    }
    if let (Some(gw), Some(ip), Some(mask)) = (next.gateway, next.ip, next.mask) {
        // 0.0.0.0 = no gateway
        let m = u32::from_be_bytes(mask);
        let same_net = u32::from_be_bytes(gw) & m == u32::from_be_bytes(ip) & m;
        if gw != [0; 4] && !(same_net && is_host(gw, mask)) {
            return Err(IpError::Gateway);
        }
    }
    Ok(next)
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
        }
    }

    /// Drops the frames in assembly and in transmission (leaving Pre-Op
    /// for Init or Bootstrap). The IP parameters stay.
    pub fn reset(&mut self) {
        self.rx.reset();
        self.tx.reset();
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
                let body = self.get_ip_body();
                respond(out, frame_type::GET_IP_RESPONSE, h.port, result::SUCCESS, &body)
            }
            // a response type from the master, or an unknown type
            t => respond(out, t, h.port, result::UNSUPPORTED_FRAME_TYPE, &[]),
        }
    }

    /// The get-IP-parameter response body (same layout as the request).
    fn get_ip_body(&self) -> [u8; ip_offset::END] {
        let mut b = [0u8; ip_offset::END];
        let p = &self.params;
        let mut flags = 0u32;
        let mut put = |off: usize, src: &[u8]| {
            if let Some(dst) = b.get_mut(off..off + src.len()) {
                dst.copy_from_slice(src);
            }
        };
        if let Some(mac) = &p.mac {
            flags |= ip_flags::MAC;
            put(ip_offset::MAC, mac);
        }
        for (flag, off, v) in [
            (ip_flags::IP, ip_offset::IP, p.ip),
            (ip_flags::MASK, ip_offset::MASK, p.mask),
            (ip_flags::GATEWAY, ip_offset::GATEWAY, p.gateway),
            (ip_flags::DNS, ip_offset::DNS, p.dns),
        ] {
            if let Some(v) = v {
                flags |= flag;
                put(off, &v);
            }
        }
        if let Some(name) = &p.dns_name {
            flags |= ip_flags::DNS_NAME;
            put(ip_offset::DNS_NAME, name.as_bytes());
        }
        put(ip_offset::FLAGS, &flags.to_le_bytes());
        b
    }

    /// The next outgoing fragment into `out` (the mailbox data area), asking
    /// `port` for a new frame when the previous one has gone out.
    pub fn next_fragment<E: EthernetPort>(&mut self, out: &mut [u8], port: &mut E) -> Option<usize> {
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

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    fn frame(n: usize) -> Vec<u8> {
        (0..n).map(|i| (i * 7 + 3) as u8).collect()
    }

    /// Splits `f` as a master would: fragments of `chunk` bytes (a multiple of 32).
    fn fragments(f: &[u8], chunk: usize, frame_no: u8) -> Vec<(EoeHeader, Vec<u8>)> {
        let chunks: Vec<&[u8]> = f.chunks(chunk).collect();
        let n = chunks.len();
        chunks
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let so = if i == 0 {
                    f.len().div_ceil(32)
                } else {
                    i * chunk / 32
                };
                (
                    EoeHeader::fragment(i + 1 == n, i as u8, so as u8, frame_no),
                    c.to_vec(),
                )
            })
            .collect()
    }

    #[test]
    fn e095_header_round_trip() {
        let h = EoeHeader::fragment(true, 3, 7, 9);
        let b = h.to_bytes();
        assert_eq!(b, [0x00, 0x01, 0xC3, 0x91]);
        let p = EoeHeader::parse(&b).unwrap();
        assert_eq!(p, h);
        assert_eq!(
            (p.fragment_number(), p.size_or_offset(), p.frame_number()),
            (3, 7, 9)
        );
        let r = EoeHeader::parse(&[0x23, 0x05, 0x01, 0x02]).unwrap();
        assert_eq!(
            (r.frame_type, r.port, r.last, r.time_appended, r.time_request),
            (3, 2, true, false, true)
        );
        assert_eq!(r.result(), 0x0201);
        assert_eq!(EoeHeader::parse(&[0, 0, 0]), None);
    }

    #[test]
    fn e095_reassembly_in_order() {
        let f = frame(300);
        let mut r = Reassembly::new();
        let frags = fragments(&f, 96, 5);
        assert_eq!(frags.len(), 4);
        for (i, (h, d)) in frags.iter().enumerate() {
            let got = r.push(h, d).unwrap();
            assert_eq!(got.is_some(), i == 3);
        }
        assert_eq!(r.frame(), &f[..]);
        assert_eq!(r.dropped(), 0);
        // a single-fragment frame, maximum size
        let f = frame(MAX_FRAME);
        let h = EoeHeader::fragment(true, 0, 48, 6);
        assert_eq!(r.push(&h, &f), Ok(Some(MAX_FRAME)));
    }

    #[test]
    fn e095_reassembly_bad_fragments_drop_and_count() {
        let f = frame(200);
        let frags = fragments(&f, 64, 1);
        let mut r = Reassembly::new();
        // out-of-order fragment number
        r.push(&frags[0].0, &frags[0].1).unwrap();
        assert_eq!(r.push(&frags[2].0, &frags[2].1), Err(FragmentError::Sequence));
        assert_eq!(r.dropped(), 1);
        assert!(!r.active());
        // a later fragment with no frame in assembly
        assert_eq!(r.push(&frags[1].0, &frags[1].1), Err(FragmentError::NoFrame));
        assert_eq!(r.dropped(), 2);
        // wrong frame number
        r.push(&frags[0].0, &frags[0].1).unwrap();
        let other = fragments(&f, 64, 2);
        assert_eq!(r.push(&other[1].0, &other[1].1), Err(FragmentError::FrameNumber));
        // wrong offset
        r.push(&frags[0].0, &frags[0].1).unwrap();
        let bad = EoeHeader::fragment(false, 1, 3, 1);
        assert_eq!(r.push(&bad, &frags[1].1), Err(FragmentError::Offset));
        // more data than announced
        let h = EoeHeader::fragment(true, 0, 1, 3);
        assert_eq!(r.push(&h, &frame(40)), Err(FragmentError::TooLong));
        // beyond the buffer
        let h = EoeHeader::fragment(true, 0, 63, 3);
        assert_eq!(r.push(&h, &frame(MAX_FRAME + 1)), Err(FragmentError::TooLong));
        // shorter than an Ethernet header
        let h = EoeHeader::fragment(true, 0, 1, 3);
        assert_eq!(r.push(&h, &frame(10)), Err(FragmentError::TooShort));
        assert_eq!(r.dropped(), 7);
        // a new fragment 0 interrupts (and counts) the frame in assembly
        r.push(&frags[0].0, &frags[0].1).unwrap();
        r.push(&frags[0].0, &frags[0].1).unwrap();
        assert_eq!(r.dropped(), 8);
        for (h, d) in &frags[1..] {
            r.push(h, d).unwrap();
        }
        assert_eq!(r.frame(), &f[..]);
    }

    #[test]
    fn e095_time_stamp_is_stripped() {
        let f = frame(64);
        let mut h = EoeHeader::fragment(true, 0, 2, 1);
        h.time_appended = true;
        let mut d = f.clone();
        d.extend_from_slice(&[1, 2, 3, 4]);
        let mut r = Reassembly::new();
        assert_eq!(r.push(&h, &d), Ok(Some(64)));
        assert_eq!(r.frame(), &f[..]);
    }

    #[test]
    fn e095_fragmenter_round_trip() {
        for len in [14, 100, 246, 247, 1000, MAX_FRAME] {
            let f = frame(len);
            let mut tx = Fragmenter::new();
            assert!(tx.load(|b| {
                b[..len].copy_from_slice(&f);
                Some(len)
            }));
            let mut r = Reassembly::new();
            let mut out = [0u8; 250]; // 256-byte mailbox minus its header
            let mut done = None;
            let mut count = 0;
            while let Some(n) = tx.next(&mut out) {
                count += 1;
                let h = EoeHeader::parse(&out).unwrap();
                assert!(h.last || (n - HEADER_LEN) % 32 == 0);
                done = r.push(&h, &out[HEADER_LEN..n]).unwrap();
            }
            assert_eq!(done, Some(len), "len {len}");
            assert_eq!(r.frame(), &f[..]);
            let (mut rest, mut expected) = (len, 1);
            while rest > 246 {
                rest -= 224;
                expected += 1;
            }
            assert_eq!(count, expected, "len {len}");
            assert!(!tx.active());
        }
        // nothing to send, a bad length, a mailbox too small
        let mut tx = Fragmenter::new();
        assert!(!tx.load(|_| None));
        assert!(!tx.load(|_| Some(MAX_FRAME + 1)));
        assert!(tx.load(|_| Some(100)));
        assert_eq!(tx.next(&mut [0u8; 30]), None);
        assert!(!tx.active());
    }

    fn set_ip(flags: u32, mac: [u8; 6], ip: Ipv4, mask: Ipv4, gw: Ipv4) -> Vec<u8> {
        let mut b = EoeHeader::response(frame_type::SET_IP_REQUEST, 0, 0)
            .to_bytes()
            .to_vec();
        b.extend_from_slice(&flags.to_le_bytes());
        b.extend_from_slice(&mac);
        b.extend_from_slice(&ip);
        b.extend_from_slice(&mask);
        b.extend_from_slice(&gw);
        b.extend_from_slice(&[8, 8, 8, 8]);
        let mut name = [0u8; 32];
        name[..5].copy_from_slice(b"drive");
        b.extend_from_slice(&name);
        b
    }

    const ALL: u32 = 0x3F;
    const MAC: [u8; 6] = [0x02, 0, 0, 0, 0, 1];
    const MASK24: Ipv4 = [255, 255, 255, 0];

    #[test]
    fn e096_set_ip_stores_parameters() {
        let mut s = EoeServer::new();
        let mut out = [0u8; 250];
        let req = set_ip(ALL, MAC, [10, 0, 0, 5], MASK24, [10, 0, 0, 1]);
        let n = s.handle(&req, &mut out, &mut NoEthernet).unwrap().unwrap();
        assert_eq!(&out[..n], &[0x03, 0x01, 0x00, 0x00]); // set IP response, success
        let p = s.params();
        assert_eq!(p.mac, Some(MAC));
        assert_eq!(p.ip, Some([10, 0, 0, 5]));
        assert_eq!(p.mask, Some(MASK24));
        assert_eq!(p.gateway, Some([10, 0, 0, 1]));
        assert_eq!(p.dns, Some([8, 8, 8, 8]));
        assert_eq!(p.dns_name.unwrap().as_bytes(), b"drive");
        assert_eq!(s.take_emcy(), None);
        // only the IP: the rest stays
        let req = set_ip(ip_flags::IP, [0; 6], [10, 0, 0, 6], [0; 4], [0; 4]);
        s.handle(&req, &mut out, &mut NoEthernet).unwrap();
        assert_eq!(s.params().ip, Some([10, 0, 0, 6]));
        assert_eq!(s.params().gateway, Some([10, 0, 0, 1]));
        // get IP returns them
        let n = s
            .handle(
                &EoeHeader::response(6, 0, 0).to_bytes(),
                &mut out,
                &mut NoEthernet,
            )
            .unwrap()
            .unwrap();
        assert_eq!(out[0], 0x07);
        assert_eq!(u32::from_le_bytes(out[4..8].try_into().unwrap()), ALL);
        assert_eq!(parse_set_ip(&out[4..n]).unwrap(), *s.params());
        // a truncated request
        let req = set_ip(ALL, MAC, [10, 0, 0, 5], MASK24, [10, 0, 0, 1]);
        assert_eq!(parse_set_ip(&req[4..20]), Err(IpError::TooShort));
    }

    #[test]
    fn e097_c150_first_and_last_subnet_address_rejected() {
        let cur = IpParams::default();
        let req = |ip: Ipv4, mask: Ipv4| IpParams {
            ip: Some(ip),
            mask: Some(mask),
            ..IpParams::default()
        };
        assert_eq!(
            apply_set_ip(&cur, &req([10, 0, 0, 0], MASK24)),
            Err(IpError::HostAddress)
        );
        assert_eq!(
            apply_set_ip(&cur, &req([10, 0, 0, 255], MASK24)),
            Err(IpError::HostAddress)
        );
        assert!(apply_set_ip(&cur, &req([10, 0, 0, 1], MASK24)).is_ok());
        assert!(apply_set_ip(&cur, &req([10, 0, 0, 254], MASK24)).is_ok());
        let m28 = [255, 255, 255, 240];
        assert_eq!(
            apply_set_ip(&cur, &req([192, 168, 3, 16], m28)),
            Err(IpError::HostAddress)
        );
        assert_eq!(
            apply_set_ip(&cur, &req([192, 168, 3, 31], m28)),
            Err(IpError::HostAddress)
        );
        assert!(apply_set_ip(&cur, &req([192, 168, 3, 17], m28)).is_ok());
        assert_eq!(
            apply_set_ip(&cur, &req([10, 0, 0, 5], [255, 0, 255, 0])),
            Err(IpError::BadMask)
        );
        assert_eq!(
            apply_set_ip(&cur, &req([10, 0, 0, 5], [255; 4])),
            Err(IpError::BadMask)
        );
        // gateway outside the subnet; multicast MAC
        let mut r = req([10, 0, 0, 5], MASK24);
        r.gateway = Some([10, 0, 1, 1]);
        assert_eq!(apply_set_ip(&cur, &r), Err(IpError::Gateway));
        r.gateway = Some([0; 4]);
        assert!(apply_set_ip(&cur, &r).is_ok());
        r.mac = Some([1, 0, 0, 0, 0, 1]);
        assert_eq!(apply_set_ip(&cur, &r), Err(IpError::Mac));
        // a multicast address is no host address
        assert_eq!(
            apply_set_ip(&cur, &req([224, 0, 0, 5], MASK24)),
            Err(IpError::HostAddress)
        );
        assert_eq!(
            apply_set_ip(
                &cur,
                &IpParams {
                    ip: Some([239, 1, 2, 3]),
                    ..IpParams::default()
                }
            ),
            Err(IpError::HostAddress)
        );
        // a new mask alone that makes the kept IP the broadcast address
        let kept = apply_set_ip(&cur, &req([10, 0, 0, 127], MASK24)).unwrap();
        let m25 = IpParams {
            mask: Some([255, 255, 255, 128]),
            ..IpParams::default()
        };
        assert_eq!(apply_set_ip(&kept, &m25), Err(IpError::HostAddress));
    }

    #[test]
    fn e093_rejected_ip_answers_error_and_emcy_fff0() {
        let mut s = EoeServer::new();
        let mut out = [0u8; 250];
        let ok = set_ip(ALL, MAC, [10, 0, 0, 5], MASK24, [10, 0, 0, 1]);
        s.handle(&ok, &mut out, &mut NoEthernet).unwrap();
        let bad = set_ip(ALL, MAC, [10, 0, 0, 255], MASK24, [10, 0, 0, 1]);
        let n = s.handle(&bad, &mut out, &mut NoEthernet).unwrap().unwrap();
        let h = EoeHeader::parse(&out[..n]).unwrap();
        assert_eq!(
            (h.frame_type, h.result()),
            (frame_type::SET_IP_RESPONSE, result::UNSPECIFIED_ERROR)
        );
        let e = s.take_emcy().unwrap();
        assert_eq!((e.code, e.register), (0xFFF0, 0x23));
        assert!(s.address_error());
        // the previous parameters stay
        assert_eq!(s.params().ip, Some([10, 0, 0, 5]));
        assert_eq!(s.stats().ip_rejected, 1);
        // a good request afterwards clears the error (EMCY 0000h)
        s.handle(&ok, &mut out, &mut NoEthernet).unwrap();
        assert_eq!(s.take_emcy().unwrap().code, 0x0000);
        assert!(!s.address_error());
    }

    #[test]
    fn e095_server_delivers_frames_and_answers_other_types() {
        let mut s = EoeServer::new();
        let mut port = FrameCounter::default();
        let mut out = [0u8; 250];
        let f = frame(500);
        for (h, d) in fragments(&f, 224, 4) {
            let mut msg = h.to_bytes().to_vec();
            msg.extend_from_slice(&d);
            assert_eq!(s.handle(&msg, &mut out, &mut port), Ok(None));
        }
        assert_eq!((port.frames, port.last_len, port.last_hash), (1, 500, fnv1a(&f)));
        assert_eq!(s.stats().frames_received, 1);
        // address filter: not supported
        let n = s
            .handle(&EoeHeader::response(4, 0, 0).to_bytes(), &mut out, &mut port)
            .unwrap()
            .unwrap();
        assert_eq!(
            EoeHeader::parse(&out[..n]).unwrap().result(),
            result::NO_FILTER_SUPPORT
        );
        let n = s
            .handle(&EoeHeader::response(9, 0, 0).to_bytes(), &mut out, &mut port)
            .unwrap()
            .unwrap();
        assert_eq!(
            EoeHeader::parse(&out[..n]).unwrap().result(),
            result::UNSUPPORTED_FRAME_TYPE
        );
        assert_eq!(
            s.handle(&[0, 0], &mut out, &mut port),
            Err(MailboxError::SIZE_TOO_SHORT)
        );
    }
}
