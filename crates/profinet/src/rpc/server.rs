//! The CL RPC engine of the device: server for the PNIO device interface and
//! the endpoint mapper, and client for the one call the device makes itself
//! (CControl ApplicationReady to the controller).
//!
//! Sans-IO: [`Server::receive`] takes a datagram, [`Server::poll`] runs the
//! timers and asks the [`Handler`] for a client call, [`Server::transmit`]
//! hands out the next datagram to send (call it until it returns `None`).

use heapless::Deque;
use nanos::Nanos;

use super::cursor::{Endian, Reader, Writer};
use super::epm::{self, EpmInfo};
use super::header::{flags1, Drep, Header, HeaderError, PacketType, HEADER_LEN, MUST_RECV_FRAG_SIZE};
use super::uuid::{
    Uuid, EPM_INTERFACE, EPM_INTERFACE_VERSION, PNIO_DEVICE_INTERFACE, PNIO_INTERFACE_VERSION,
};
use super::{nca, Call, CallError, ClientError, Handler, Request, MAX_PNIO_OPNUM};
use crate::ip::Endpoint;

/// Size of the buffer of the device's own (client) requests.
pub const CLIENT_BUF: usize = 256;
/// Time between transmissions of an unanswered client request.
pub const CLIENT_RETRY: Nanos = Nanos::from_ms(1000);
/// Transmissions of a client request before it times out.
pub const CLIENT_ATTEMPTS: u8 = 5;
/// Largest UDP payload that fits one untagged Ethernet frame.
const MAX_UDP_PAYLOAD: usize = 1472;
/// The longest PNIO Write request received (and answered with "write length
/// error") beyond the buffer: 64 KiB, the largest RecordDataLength a
/// controller's IODWriteReq can need in practice; longer ones are faults.
const MAX_TRUNCATED_WRITE: usize = 65_536;
/// Request and response buffer size of the device: an IODWriteMultiple
/// carrying one record of [`crate::model::MAX_RECORD_SIZE`] (NDR header,
/// two IODWriteReqHeaders, the record) fits whole.
pub const BUF: usize = crate::model::MAX_RECORD_SIZE + 2 * 64 + 20;

/// Static settings of the server.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ServerConfig {
    /// Our server boot time, different after every boot (e.g. a persisted boot
    /// counter or seconds of a real-time clock); a request naming another one
    /// (not 0) is rejected with `nca_wrong_boot_time`.
    pub boot_time: u32,
    /// What the endpoint mapper answers.
    pub epm: EpmInfo,
}

/// Counters of the RPC layer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RpcCounters {
    /// Datagrams refused by the header check.
    pub malformed: u32,
    /// Calls executed (PNIO and EPM).
    pub calls: u32,
    /// Calls rejected (unknown interface, opnum, boot time).
    pub rejects: u32,
    /// Requests too big for the reassembly buffer.
    pub too_big: u32,
    /// Request fragments dropped (out of order).
    pub fragments_dropped: u32,
    /// Responses sent again (duplicate request or ping).
    pub retransmissions: u32,
    /// Client calls that timed out.
    pub client_timeouts: u32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// Request fragments arriving: next expected fragment, bytes so far.
    Receiving { next: u16, len: usize },
    /// Executed: the cached answer's packet type and body length.
    Done { ptype: PacketType, len: usize },
}

#[derive(Clone, Copy, Debug)]
struct ServerCall {
    peer: Endpoint,
    req: Header,
    phase: Phase,
    /// Fragment body size of the answer.
    frag_body: usize,
    /// Next answer fragment to transmit, if any are due.
    send_from: Option<u16>,
    serial: u16,
}

#[derive(Clone, Copy, Debug)]
struct ClientCall {
    peer: Endpoint,
    hdr: Header,
    body_len: usize,
    attempts: u8,
    next_tx: Nanos,
    send_now: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Body {
    Empty,
    Status(u32),
    Fack,
}

#[derive(Clone, Copy, Debug)]
struct Control {
    peer: Endpoint,
    hdr: Header,
    body: Body,
}

/// The RPC engine, with a request reassembly buffer and a response buffer of
/// `N` bytes each (bodies, without headers).
#[derive(Debug)]
pub struct Server<const N: usize = BUF> {
    config: ServerConfig,
    call: Option<ServerCall>,
    req_buf: [u8; N],
    resp_buf: [u8; N],
    control: Deque<Control, 4>,
    client: Option<ClientCall>,
    client_buf: [u8; CLIENT_BUF],
    client_seq: u32,
    counters: RpcCounters,
}

fn reply_header(req: &Header, ptype: PacketType, boot_time: u32) -> Header {
    Header {
        ptype,
        flags1: 0,
        flags2: 0,
        serial: 0,
        boot_time,
        if_hint: 0xFFFF,
        act_hint: 0xFFFF,
        body_len: 0,
        ..*req
    }
}

impl<const N: usize> Server<N> {
    /// A server with `config`.
    pub fn new(config: ServerConfig) -> Server<N> {
        Server {
            config,
            call: None,
            req_buf: [0; N],
            resp_buf: [0; N],
            control: Deque::new(),
            client: None,
            client_buf: [0; CLIENT_BUF],
            client_seq: 0,
            counters: RpcCounters::default(),
        }
    }

    /// The settings.
    pub fn config(&self) -> &ServerConfig {
        &self.config
    }

    /// Changes the settings (e.g. the IP in the EPM tower after DCP Set).
    pub fn set_config(&mut self, config: ServerConfig) {
        self.config = config;
    }

    /// Counters since start.
    pub fn counters(&self) -> &RpcCounters {
        &self.counters
    }

    /// True while a client call of the device is unanswered.
    pub fn client_busy(&self) -> bool {
        self.client.is_some()
    }

    fn queue(&mut self, peer: Endpoint, hdr: Header, body: Body) {
        // A full queue drops the oldest: the peer retransmits what it misses.
        if self.control.is_full() {
            let _ = self.control.pop_front();
        }
        let _ = self.control.push_back(Control { peer, hdr, body });
    }

    fn reject(&mut self, peer: Endpoint, req: &Header, status: u32) {
        self.counters.rejects = self.counters.rejects.saturating_add(1);
        let hdr = reply_header(req, PacketType::Reject, self.config.boot_time);
        self.queue(peer, hdr, Body::Status(status));
    }

    /// Takes one datagram received from `peer` (the UDP payload).
    pub fn receive<H: Handler>(&mut self, now: Nanos, peer: Endpoint, datagram: &[u8], handler: &mut H) {
        let (h, body) = match Header::parse(datagram) {
            Ok(x) => x,
            Err(
                HeaderError::Truncated | HeaderError::Version | HeaderError::PacketType | HeaderError::Auth,
            ) => {
                self.counters.malformed = self.counters.malformed.saturating_add(1);
                return;
            }
        };
        match h.ptype {
            PacketType::Request => self.request(now, peer, &h, body, handler),
            PacketType::Ping => self.ping(peer, &h),
            PacketType::Ack => {
                if let Some(c) = &self.call {
                    if c.req.activity == h.activity && c.req.seq == h.seq {
                        self.call = None;
                    }
                }
            }
            PacketType::Fack => self.fack(&h, body),
            PacketType::Response
            | PacketType::Fault
            | PacketType::Reject
            | PacketType::Working
            | PacketType::Nocall => self.client_answer(now, peer, &h, body, handler),
            PacketType::ClCancel | PacketType::CancelAck => {}
        }
    }

    fn same_call(&self, h: &Header) -> Option<ServerCall> {
        self.call
            .filter(|c| c.req.activity == h.activity && c.req.seq == h.seq)
    }

    fn request<H: Handler>(&mut self, now: Nanos, peer: Endpoint, h: &Header, body: &[u8], handler: &mut H) {
        let major = h.if_version & 0xFFFF;
        let epm = h.interface == EPM_INTERFACE;
        if !(epm && major == EPM_INTERFACE_VERSION
            || h.interface == PNIO_DEVICE_INTERFACE && major == PNIO_INTERFACE_VERSION)
        {
            return self.reject(peer, h, nca::UNK_IF);
        }
        let op_ok = if epm {
            matches!(h.opnum, epm::OP_LOOKUP | epm::OP_LOOKUP_HANDLE_FREE)
        } else {
            h.opnum <= MAX_PNIO_OPNUM
        };
        if !op_ok {
            return self.reject(peer, h, nca::OP_RNG_ERROR);
        }
        if h.boot_time != 0 && h.boot_time != self.config.boot_time {
            return self.reject(peer, h, nca::WRONG_BOOT_TIME);
        }
        // Duplicates and continuations of the current call.
        let mut start = 0usize;
        if let Some(c) = self.call.filter(|c| c.req.activity == h.activity) {
            if h.seq < c.req.seq {
                return;
            }
            if h.seq == c.req.seq {
                match c.phase {
                    Phase::Done { .. } => {
                        self.counters.retransmissions = self.counters.retransmissions.saturating_add(1);
                        if let Some(c) = &mut self.call {
                            c.send_from = Some(0);
                        }
                        return;
                    }
                    Phase::Receiving { next, len } => {
                        if h.frag_num != next {
                            if h.frag_num > next {
                                self.counters.fragments_dropped =
                                    self.counters.fragments_dropped.saturating_add(1);
                            }
                            if !h.is_nofack() && next > 0 {
                                let mut f = reply_header(h, PacketType::Fack, self.config.boot_time);
                                f.frag_num = next - 1;
                                self.queue(peer, f, Body::Fack);
                            }
                            return;
                        }
                        start = len;
                    }
                }
            }
        }
        if start == 0 && h.is_frag() && h.frag_num != 0 {
            self.counters.fragments_dropped = self.counters.fragments_dropped.saturating_add(1);
            return;
        }
        let end = start.saturating_add(body.len());
        // A PNIO Write longer than the buffer is still received to its last
        // fragment (the excess dropped), so that the CM can answer the
        // record's header with "write length error"; any other request too
        // long is a fault (nca_s_fault_remote_no_memory).
        let write = !epm && h.opnum == crate::rpc::opnum::WRITE;
        if end > N {
            if !write || end > MAX_TRUNCATED_WRITE {
                self.counters.too_big = self.counters.too_big.saturating_add(1);
                self.call = None;
                let hdr = reply_header(h, PacketType::Fault, self.config.boot_time);
                self.queue(peer, hdr, Body::Status(nca::FAULT_REMOTE_NO_MEMORY));
                return;
            }
            if start <= N {
                self.counters.too_big = self.counters.too_big.saturating_add(1);
            }
        }
        if let Some(dst) = self.req_buf.get_mut(start.min(N)..end.min(N)) {
            for (d, s) in dst.iter_mut().zip(body) {
                *d = *s;
            }
        }
        // The answer's fragment size: the request's own when it came in fragments
        // (the client evidently handles PDUs that big), else MustRecvFragSize.
        let pdu = if h.is_frag() {
            (HEADER_LEN + body.len()).clamp(HEADER_LEN + 8, MAX_UDP_PAYLOAD)
        } else {
            MUST_RECV_FRAG_SIZE
        };
        let frag_body = match self.call.filter(|_| start > 0) {
            Some(c) => c.frag_body,
            None => pdu - HEADER_LEN,
        };
        let mut call = ServerCall {
            peer,
            req: *h,
            phase: Phase::Receiving {
                next: h.frag_num.saturating_add(1),
                len: end,
            },
            frag_body,
            send_from: None,
            serial: 0,
        };
        if h.is_frag() && !h.is_nofack() {
            let f = reply_header(h, PacketType::Fack, self.config.boot_time);
            self.queue(peer, f, Body::Fack);
        }
        if !h.is_last_frag() {
            self.call = Some(call);
            return;
        }
        // Execute.
        self.counters.calls = self.counters.calls.saturating_add(1);
        let endian = h.drep.endian();
        let req = self.req_buf.get(..end.min(N)).unwrap_or(&[]);
        let result = if epm {
            epm::answer(&self.config.epm, h.opnum, endian, req, &mut self.resp_buf)
                .ok_or(CallError::Reject(nca::PROTO_ERROR))
        } else {
            let info = Call {
                peer,
                opnum: h.opnum,
                endian,
                object: h.object,
                activity: h.activity,
                seq: h.seq,
                truncated: end > N,
            };
            handler.call(now, &info, req, &mut self.resp_buf)
        };
        let (ptype, len) = match result {
            Ok(n) => (PacketType::Response, n.min(N)),
            Err(e) => {
                let (ptype, status) = match e {
                    CallError::Reject(s) => (PacketType::Reject, s),
                    CallError::Fault(s) => (PacketType::Fault, s),
                };
                if ptype == PacketType::Reject {
                    self.counters.rejects = self.counters.rejects.saturating_add(1);
                }
                let mut w = Writer::new(&mut self.resp_buf, endian);
                let _ = w.u32(status);
                (ptype, 4)
            }
        };
        call.phase = Phase::Done { ptype, len };
        call.send_from = Some(0);
        self.call = Some(call);
    }

    fn ping(&mut self, peer: Endpoint, h: &Header) {
        match self.same_call(h).map(|c| c.phase) {
            Some(Phase::Done { .. }) => {
                self.counters.retransmissions = self.counters.retransmissions.saturating_add(1);
                if let Some(c) = &mut self.call {
                    c.send_from = Some(0);
                }
            }
            Some(Phase::Receiving { .. }) => {
                let w = reply_header(h, PacketType::Working, self.config.boot_time);
                self.queue(peer, w, Body::Empty);
            }
            None => {
                let n = reply_header(h, PacketType::Nocall, self.config.boot_time);
                self.queue(peer, n, Body::Empty);
            }
        }
    }

    fn fack(&mut self, h: &Header, body: &[u8]) {
        // The client's max_frag_size (if it sent a body) bounds our fragments.
        let mut r = Reader::new(body, h.drep.endian());
        let max_frag = (|| {
            r.skip(4)?;
            let _max_tsdu = r.u32()?;
            r.u32()
        })();
        if let (Some(c), Some(m)) = (&mut self.call, max_frag) {
            if c.req.activity == h.activity && c.req.seq == h.seq {
                let m = usize::try_from(m).unwrap_or(usize::MAX);
                if m >= HEADER_LEN + 8 && m - HEADER_LEN < c.frag_body {
                    c.frag_body = m - HEADER_LEN;
                }
            }
        }
    }

    fn client_answer<H: Handler>(
        &mut self,
        now: Nanos,
        peer: Endpoint,
        h: &Header,
        body: &[u8],
        handler: &mut H,
    ) {
        let Some(c) = self.client else { return };
        if c.hdr.activity != h.activity || c.hdr.seq != h.seq {
            return;
        }
        let status = || Reader::new(body, h.drep.endian()).u32().unwrap_or(0);
        match h.ptype {
            PacketType::Response => {
                self.client = None;
                let mut ack = reply_header(h, PacketType::Ack, h.boot_time);
                ack.if_hint = 0xFFFF;
                self.queue(peer, ack, Body::Empty);
                if h.is_frag() {
                    handler.response(now, Err(ClientError::Fragmented));
                } else {
                    handler.response(now, Ok((h.drep.endian(), body)));
                }
            }
            PacketType::Fault => {
                self.client = None;
                handler.response(now, Err(ClientError::Fault(status())));
            }
            PacketType::Reject => {
                self.client = None;
                handler.response(now, Err(ClientError::Reject(status())));
            }
            PacketType::Working => {
                if let Some(c) = &mut self.client {
                    c.next_tx = now + CLIENT_RETRY;
                }
            }
            _ => {
                if let Some(c) = &mut self.client {
                    c.send_now = true;
                }
            }
        }
    }

    /// Runs the client timers and, when idle, asks `handler` for a call to make.
    pub fn poll<H: Handler>(&mut self, now: Nanos, handler: &mut H) {
        if let Some(c) = &mut self.client {
            if now >= c.next_tx && !c.send_now {
                if c.attempts >= CLIENT_ATTEMPTS {
                    self.client = None;
                    self.counters.client_timeouts = self.counters.client_timeouts.saturating_add(1);
                    handler.response(now, Err(ClientError::Timeout));
                } else {
                    c.send_now = true;
                }
            }
            return;
        }
        let Some(req) = handler.request(now, &mut self.client_buf) else {
            return;
        };
        self.start_call(now, req);
    }

    fn start_call(&mut self, now: Nanos, req: Request) {
        let seq = self.client_seq;
        self.client_seq = self.client_seq.wrapping_add(1);
        let mut activity = self.config.epm.object;
        if let Some(a) = activity.0.get_mut(0..4) {
            a.copy_from_slice(&self.config.boot_time.to_be_bytes());
        }
        let hdr = Header {
            ptype: PacketType::Request,
            flags1: flags1::IDEMPOTENT,
            flags2: 0,
            drep: Drep::LITTLE,
            serial: 0,
            object: req.object,
            interface: req.interface,
            activity,
            boot_time: 0,
            if_version: PNIO_INTERFACE_VERSION,
            seq,
            opnum: req.opnum,
            if_hint: 0xFFFF,
            act_hint: 0xFFFF,
            body_len: u16::try_from(req.body_len.min(CLIENT_BUF)).unwrap_or(0),
            frag_num: 0,
            auth_proto: 0,
        };
        self.client = Some(ClientCall {
            peer: req.peer,
            hdr,
            body_len: req.body_len.min(CLIENT_BUF),
            attempts: 0,
            next_tx: now,
            send_now: true,
        });
    }

    /// Byte order of the device's own requests (their NDR bodies follow it).
    pub const CLIENT_ENDIAN: Endian = Endian::Little;

    /// Writes the next datagram to send into `out` and returns its destination
    /// and length; `None` when nothing is due. `out` should hold a whole
    /// fragment ([`MUST_RECV_FRAG_SIZE`], up to 1472 bytes).
    pub fn transmit(&mut self, now: Nanos, out: &mut [u8]) -> Option<(Endpoint, usize)> {
        if let Some(c) = self.control.pop_front() {
            let body_len = match c.body {
                Body::Empty => 0,
                Body::Status(_) => 4,
                Body::Fack => 16,
            };
            let mut hdr = c.hdr;
            hdr.body_len = body_len;
            hdr.emit(out)?;
            let mut w = Writer::new(out.get_mut(HEADER_LEN..)?, hdr.drep.endian());
            match c.body {
                Body::Empty => {}
                Body::Status(s) => w.u32(s)?,
                Body::Fack => {
                    w.u8(0)?; // version
                    w.u8(0)?;
                    w.u16(0)?; // window size: none held back
                    w.u32(u32::try_from(N).unwrap_or(u32::MAX))?; // max_tsdu
                    w.u32(MUST_RECV_FRAG_SIZE as u32)?; // max_frag_size
                    w.u16(hdr.serial)?;
                    w.u16(0)?; // no selective acks
                }
            }
            return Some((c.peer, HEADER_LEN + usize::from(body_len)));
        }
        if let Some(n) = self.transmit_answer(out) {
            return Some(n);
        }
        let c = self.client.as_mut().filter(|c| c.send_now)?;
        c.send_now = false;
        c.attempts = c.attempts.saturating_add(1);
        c.next_tx = now + CLIENT_RETRY;
        let (peer, hdr, len) = (c.peer, c.hdr, c.body_len);
        hdr.emit(out)?;
        out.get_mut(HEADER_LEN..HEADER_LEN + len)?
            .copy_from_slice(self.client_buf.get(..len)?);
        Some((peer, HEADER_LEN + len))
    }

    fn transmit_answer(&mut self, out: &mut [u8]) -> Option<(Endpoint, usize)> {
        let boot_time = self.config.boot_time;
        let c = self.call.as_mut()?;
        let k = c.send_from?;
        let Phase::Done { ptype, len } = c.phase else {
            return None;
        };
        let fb = c.frag_body.max(8);
        let frags = len.div_ceil(fb).max(1);
        let start = usize::from(k).saturating_mul(fb);
        let end = start.saturating_add(fb).min(len);
        let body = self.resp_buf.get(start..end)?;
        let last = usize::from(k) + 1 >= frags;
        let mut hdr = reply_header(&c.req, ptype, boot_time);
        hdr.flags1 = match (frags > 1, last) {
            (false, _) => flags1::LASTFRAG | flags1::NOFACK,
            (true, false) => flags1::FRAG | flags1::NOFACK,
            (true, true) => flags1::FRAG | flags1::LASTFRAG,
        };
        hdr.frag_num = k;
        hdr.serial = c.serial;
        hdr.body_len = u16::try_from(body.len()).ok()?;
        c.serial = c.serial.wrapping_add(1);
        c.send_from = if last { None } else { Some(k.saturating_add(1)) };
        let peer = c.peer;
        hdr.emit(out)?;
        out.get_mut(HEADER_LEN..HEADER_LEN + body.len())?
            .copy_from_slice(body);
        Some((peer, HEADER_LEN + body.len()))
    }

    /// Our header for a call the device makes (for tests and captures).
    pub fn client_header(&self) -> Option<Header> {
        self.client.map(|c| c.hdr)
    }

    /// The activity UUID the device's client calls use.
    pub fn client_activity(&self) -> Uuid {
        let mut activity = self.config.epm.object;
        if let Some(a) = activity.0.get_mut(0..4) {
            a.copy_from_slice(&self.config.boot_time.to_be_bytes());
        }
        activity
    }
}
