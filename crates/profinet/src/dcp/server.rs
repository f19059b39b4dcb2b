//! The device side of DCP: [`DcpServer`] owns the station's identity, name and
//! IP suite and answers Identify, Get and Set (see the [module doc](super) for
//! the rules and the choices made).

use core::net::Ipv4Addr;

use heapless::Vec;
use nanos::Nanos;

use super::name::NameOfStation;
use super::pdu::{
    service_type, BlockError, BlockRepr, BlockType, BlockWriter, Blocks, Header, IpSuite, Packet, RawBlock,
    ServiceId, Value, HEADER_LEN,
};
use super::signal::Signal;
use crate::model;
use crate::wire::{emit_header, ethertype, split_frame_id, EthFrame, FrameKind, MacAddr};

/// DeviceRoleDetails bit of an IO device.
pub const ROLE_IO_DEVICE: u8 = 0x01;
/// A ResponseDelayFactor step.
pub const RESPONSE_DELAY_STEP: Nanos = Nanos::from_ms(10);
/// Largest ResponseDelayFactor the standard allows (0x1900: 64 s); larger
/// factors are clamped to it.
pub const MAX_RESPONSE_DELAY_FACTOR: u16 = 0x1900;
/// How long a Get/Set from one controller locks DCP Get/Set out for the others
/// (the "SAM" hold time).
pub const SAM_HOLD: Nanos = Nanos::from_secs(3);
/// Longest alias name: an LLDP port ID ("port-xyz-abcde"), `.`, a name of
/// station.
pub const MAX_ALIAS_LEN: usize = 14 + 1 + super::name::MAX_LEN;
/// Largest number of events one request can raise.
pub const MAX_EVENTS: usize = 6;

/// The (Option, Suboption) pairs this device supports, as the DeviceOptions
/// block lists them.
pub const DEVICE_OPTIONS: [u8; 34] = [
    1, 1, 1, 2, 1, 3, // IP: MAC, IP parameter, full IP suite
    2, 1, 2, 2, 2, 3, 2, 4, 2, 5, 2, 6, 2, 7, // device properties
    5, 1, 5, 2, 5, 3, 5, 5, 5, 6, // control
    6, 1, // device initiative
    0xFF, 0xFF, // all
];

/// What the device is, as DCP reports it (fixed at build time).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Identity {
    /// Vendor ID.
    pub vendor_id: u16,
    /// Device ID.
    pub device_id: u16,
    /// DeviceVendor, the "type of station".
    pub station_type: &'static str,
    /// DeviceRoleDetails ([`ROLE_IO_DEVICE`]).
    pub role: u8,
    /// DeviceInstance (high, low).
    pub instance: (u8, u8),
}

impl Identity {
    /// The drive's identity from [`crate::model`].
    pub const DRIVE: Identity = Identity {
        vendor_id: model::VENDOR_ID,
        device_id: model::DEVICE_ID,
        station_type: model::STATION_TYPE,
        role: ROLE_IO_DEVICE,
        instance: (0, 1),
    };
}

/// Which data a Reset to factory resets (BlockQualifier bits 15…1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ResetMode {
    /// Mode 1: application data. Name and IP stay; the caller resets its own
    /// data.
    ApplicationData,
    /// Mode 2: communication parameters. Name and IP are cleared.
    Communication,
    /// Modes 4 and 8, and the older Factory reset (5,5): all stored data.
    /// Name and IP are cleared; the caller resets everything else.
    All,
}

impl ResetMode {
    fn from_qualifier(q: u16) -> Option<ResetMode> {
        match q >> 1 {
            1 => Some(ResetMode::ApplicationData),
            2 => Some(ResetMode::Communication),
            4 | 8 => Some(ResetMode::All),
            _ => None,
        }
    }

    /// `true` if the mode clears the name of station and the IP suite.
    pub const fn clears_communication(self) -> bool {
        !matches!(self, ResetMode::ApplicationData)
    }
}

/// What a request changed, for the caller to act on. The server never persists
/// anything itself.
// The name variant carries its 240-byte name: no heap to box it in, and an
// event lives only until the caller has read it.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Event {
    /// The name of station is now `name`. `permanent`: store it. Temporary:
    /// the stored name must be cleared (a temporary name is gone after a
    /// restart and the one stored before it does not come back).
    NameOfStation {
        /// The new name (possibly empty).
        name: NameOfStation,
        /// BlockQualifier bit 0.
        permanent: bool,
    },
    /// The IP suite is now `suite` (the IP stack applies it at once). It
    /// replaces any stored static IP (P-009): `permanent`: store it;
    /// temporary: clear the stored one.
    IpSuite {
        /// The new suite (possibly unset).
        suite: IpSuite,
        /// BlockQualifier bit 0.
        permanent: bool,
    },
    /// DCP Signal: flash the SF LED until `until` ([`DcpServer::signal`]).
    Signal {
        /// End of the flashing.
        until: Nanos,
    },
    /// Reset to factory. For modes that clear the communication parameters the
    /// server has cleared name and IP and raised the matching permanent
    /// [`Event::NameOfStation`] and [`Event::IpSuite`] too.
    ResetToFactory(ResetMode),
}

/// The events of one request (at most one of each kind: a later block of the
/// same kind replaces the earlier event).
pub type Events = Vec<Event, MAX_EVENTS>;

/// A frame the caller must send.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reply {
    /// Length of the frame at the start of the output buffer (padded to 60).
    pub len: usize,
    /// When to send it: `now` for Get/Set; for Identify the response delay
    /// (an Identify that arrives before then replaces the pending one).
    pub send_at: Nanos,
}

/// What [`DcpServer::handle`] did with a frame.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Outcome {
    /// The answer, if any (`None`: dropped or not for us).
    pub reply: Option<Reply>,
    /// What changed.
    pub events: Events,
}

/// The device-side DCP server.
#[derive(Clone, Debug)]
pub struct DcpServer {
    identity: Identity,
    mac: MacAddr,
    name: NameOfStation,
    ip: IpSuite,
    aliases: [Vec<u8, MAX_ALIAS_LEN>; model::PORTS as usize],
    in_operation: bool,
    signal: Signal,
    sam: Option<(MacAddr, Nanos)>,
}

impl DcpServer {
    /// A server for the interface MAC `mac` with the stored name and IP suite
    /// (P-007, P-010).
    pub fn new(mac: MacAddr, identity: Identity, name: NameOfStation, ip: IpSuite) -> DcpServer {
        DcpServer {
            identity,
            mac,
            name,
            ip,
            aliases: Default::default(),
            in_operation: false,
            signal: Signal::default(),
            sam: None,
        }
    }

    /// The interface MAC.
    pub fn mac(&self) -> MacAddr {
        self.mac
    }

    /// The identity.
    pub fn identity(&self) -> &Identity {
        &self.identity
    }

    /// The current name of station.
    pub fn name_of_station(&self) -> &NameOfStation {
        &self.name
    }

    /// The current IP suite.
    pub fn ip_suite(&self) -> IpSuite {
        self.ip
    }

    /// The identification flash state (P-011).
    pub fn signal(&self) -> &Signal {
        &self.signal
    }

    /// Sets the alias name learned on `port` (0-based) from the neighbour's
    /// LLDP (`<its port ID>.<its chassis ID>`, see [`crate::lldp::Neighbor::alias`]), or clears it. `false` if the
    /// port does not exist or the alias is too long.
    pub fn set_alias(&mut self, port: usize, alias: Option<&[u8]>) -> bool {
        let Some(slot) = self.aliases.get_mut(port) else {
            return false;
        };
        slot.clear();
        match alias {
            Some(a) => slot.extend_from_slice(a).is_ok(),
            None => true,
        }
    }

    /// While an AR is in data exchange, Sets that would change the name or IP
    /// and resets to factory are refused with "in operation" (0x06).
    pub fn set_in_operation(&mut self, on: bool) {
        self.in_operation = on;
    }

    /// Handles a received frame; see [`DcpServer::handle`].
    pub fn handle_frame(&mut self, now: Nanos, frame: &[u8], out: &mut [u8]) -> Outcome {
        match EthFrame::parse(frame) {
            Some(f) => self.handle(now, &f, out),
            None => Outcome::default(),
        }
    }

    /// Handles a received frame: anything not a DCP request for this device is
    /// ignored. The answer is written to `out` (give it 1514 bytes), to be
    /// sent at [`Reply::send_at`].
    pub fn handle(&mut self, now: Nanos, frame: &EthFrame<'_>, out: &mut [u8]) -> Outcome {
        let mut outcome = Outcome::default();
        if frame.ethertype != ethertype::PROFINET || frame.src.is_multicast() {
            return outcome;
        }
        let Some((kind, pdu)) = split_frame_id(frame.payload) else {
            return outcome;
        };
        let Ok(packet) = Packet::new_checked(pdu) else {
            return outcome;
        };
        let header = Header::parse(&packet);
        if header.service_type != service_type::REQUEST {
            return outcome;
        }
        outcome.reply = match kind {
            FrameKind::DcpIdentifyRequest => {
                let for_us = frame.dst == MacAddr::DCP_IDENTIFY || frame.dst == self.mac;
                if !for_us || header.service != ServiceId::Identify {
                    return outcome;
                }
                self.identify(now, frame.src, &header, packet.data(), out)
            }
            FrameKind::DcpGetSet => {
                if frame.dst != self.mac || !self.sam_allows(now, frame.src) {
                    return outcome;
                }
                let reply = match header.service {
                    ServiceId::Get => self.get(frame.src, &header, packet.data(), out),
                    ServiceId::Set => {
                        self.set(now, frame.src, &header, packet.data(), out, &mut outcome.events)
                    }
                    _ => self.not_supported(frame.src, &header, out),
                };
                if reply.is_some() {
                    self.sam = Some((frame.src, now + SAM_HOLD));
                }
                reply.map(|len| Reply { len, send_at: now })
            }
            _ => None,
        };
        outcome
    }

    /// Builds a DCP Hello request (to 01:0e:cf:00:00:01) announcing the
    /// station; the caller decides when (the device does not send Hello by
    /// itself, DeviceInitiative = 0).
    pub fn hello(&self, out: &mut [u8]) -> Option<usize> {
        let header = Header {
            service: ServiceId::Hello,
            service_type: service_type::REQUEST,
            xid: u32::from_be_bytes([self.mac.0[2], self.mac.0[3], self.mac.0[4], self.mac.0[5]]),
            response_delay: 0,
            data_length: 0,
        };
        self.frame(out, MacAddr::DCP_HELLO, FrameKind::DcpHello, &header, |s, w| {
            for kind in [
                BlockType::NameOfStation,
                BlockType::IpParameter,
                BlockType::DeviceId,
                BlockType::DeviceRole,
                BlockType::DeviceInitiative,
            ] {
                w.push(&s.data_block(kind)?).ok()?;
            }
            Some(())
        })
    }

    fn sam_allows(&mut self, now: Nanos, src: MacAddr) -> bool {
        match self.sam {
            Some((holder, until)) if now < until => holder == src,
            _ => {
                self.sam = None;
                true
            }
        }
    }

    /// Writes Ethernet header, FrameID, DCP header and the blocks `body`
    /// appends; pads to the Ethernet minimum.
    fn frame(
        &self,
        out: &mut [u8],
        dst: MacAddr,
        kind: FrameKind,
        header: &Header,
        body: impl FnOnce(&Self, &mut BlockWriter<'_>) -> Option<()>,
    ) -> Option<usize> {
        let eth = emit_header(out, dst, self.mac, None, ethertype::PROFINET)?;
        let rest = out.get_mut(eth..)?;
        let (fid, rest) = rest.split_at_mut_checked(2)?;
        fid.copy_from_slice(&kind.frame_id().to_be_bytes());
        let (hdr, blocks) = rest.split_at_mut_checked(HEADER_LEN)?;
        let mut w = BlockWriter::new(blocks);
        body(self, &mut w)?;
        let data_len = w.len();
        let h = Header {
            data_length: u16::try_from(data_len).ok()?,
            ..*header
        };
        h.emit(hdr).ok()?;
        let len = eth + 2 + HEADER_LEN + data_len;
        let padded = len.max(crate::wire::MIN_FRAME_LEN);
        out.get_mut(len..padded)?.fill(0);
        Some(padded)
    }

    fn response_header(request: &Header, service_type: u8) -> Header {
        Header {
            service: request.service,
            service_type,
            xid: request.xid,
            response_delay: 0,
            data_length: 0,
        }
    }

    fn not_supported(&self, dst: MacAddr, request: &Header, out: &mut [u8]) -> Option<usize> {
        let h = Self::response_header(request, service_type::RESPONSE_NOT_SUPPORTED);
        self.frame(out, dst, FrameKind::DcpGetSet, &h, |_, _| Some(()))
    }

    /// The block that answers a Get (or an Identify) for `kind`, with its
    /// BlockInfo; `None` for what cannot be read.
    fn data_block(&self, kind: BlockType) -> Option<BlockRepr<'_>> {
        let id = &self.identity;
        let value = match kind {
            BlockType::IpMac => Value::Mac(self.mac),
            BlockType::IpParameter => Value::IpParameter(self.ip),
            BlockType::IpFullSuite => Value::IpFullSuite(self.ip, [Ipv4Addr::UNSPECIFIED; 4]),
            BlockType::DeviceVendor => Value::Bytes(id.station_type.as_bytes()),
            BlockType::NameOfStation => Value::Bytes(self.name.as_bytes()),
            BlockType::DeviceId => Value::DeviceId {
                vendor_id: id.vendor_id,
                device_id: id.device_id,
            },
            BlockType::DeviceRole => Value::DeviceRole(id.role),
            BlockType::DeviceOptions => Value::DeviceOptions(&DEVICE_OPTIONS),
            BlockType::AliasName => Value::Bytes(self.aliases.iter().find(|a| !a.is_empty())?.as_slice()),
            BlockType::DeviceInstance => Value::DeviceInstance(id.instance.0, id.instance.1),
            BlockType::DeviceInitiative => Value::DeviceInitiative(0),
            _ => return None,
        };
        let info = match kind {
            // BlockInfo of the IP blocks: bit 0 "IP set" (no DHCP, no
            // conflict detection).
            BlockType::IpParameter | BlockType::IpFullSuite => u16::from(!self.ip.is_unset()),
            _ => 0,
        };
        Some(BlockRepr {
            kind,
            prefix: Some(info),
            value,
        })
    }

    fn identify(
        &self,
        now: Nanos,
        dst: MacAddr,
        request: &Header,
        data: &[u8],
        out: &mut [u8],
    ) -> Option<Reply> {
        let alias = self.identify_match(data)?;
        let h = Self::response_header(request, service_type::RESPONSE_SUCCESS);
        let len = self.frame(out, dst, FrameKind::DcpIdentifyResponse, &h, |s, w| {
            for kind in [
                BlockType::DeviceVendor,
                BlockType::NameOfStation,
                BlockType::DeviceId,
                BlockType::DeviceRole,
                BlockType::DeviceOptions,
            ] {
                w.push(&s.data_block(kind)?).ok()?;
            }
            if let Some(a) = alias {
                w.push(&BlockRepr {
                    kind: BlockType::AliasName,
                    prefix: Some(0),
                    value: Value::Bytes(a),
                })
                .ok()?;
            }
            for kind in [BlockType::DeviceInstance, BlockType::IpParameter] {
                w.push(&s.data_block(kind)?).ok()?;
            }
            Some(())
        })?;
        Some(Reply {
            len,
            send_at: now + self.response_delay(request.response_delay),
        })
    }

    /// The spread of an Identify answer: 10 ms × (MAC hash mod factor); factor
    /// 0 and 1 answer at once.
    pub fn response_delay(&self, factor: u16) -> Nanos {
        let factor = factor.min(MAX_RESPONSE_DELAY_FACTOR);
        if factor <= 1 {
            return Nanos::ZERO;
        }
        let m = self.mac.0;
        let hash = u16::from_be_bytes([m[0], m[1]])
            ^ u16::from_be_bytes([m[2], m[3]])
            ^ u16::from_be_bytes([m[4], m[5]]);
        RESPONSE_DELAY_STEP.saturating_mul(u64::from(hash % factor))
    }

    /// `Some(alias)` if the Identify filter selects this device (`Some(None)`
    /// unless it matched by alias name); `None` if not, or if it is malformed.
    fn identify_match<'d>(&'d self, data: &'d [u8]) -> Option<Option<&'d [u8]>> {
        let mut alias = None;
        let mut blocks = 0usize;
        let mut all = false;
        for block in Blocks::new(data) {
            let RawBlock { kind, data } = block.ok()?;
            blocks += 1;
            let hit = match Value::parse(kind, data).ok()? {
                Value::Empty if kind == BlockType::All => {
                    all = true;
                    true
                }
                Value::Bytes(v) => match kind {
                    BlockType::NameOfStation => !self.name.is_empty() && v == self.name.as_bytes(),
                    BlockType::DeviceVendor => v == self.identity.station_type.as_bytes(),
                    BlockType::AliasName => {
                        let found = self.aliases.iter().find(|a| !a.is_empty() && a.as_slice() == v);
                        alias = found.map(|a| a.as_slice());
                        found.is_some()
                    }
                    _ => false,
                },
                Value::DeviceId { vendor_id, device_id } => {
                    (vendor_id, device_id) == (self.identity.vendor_id, self.identity.device_id)
                }
                Value::DeviceRole(r) => r & self.identity.role != 0,
                Value::DeviceInstance(h, l) => (h, l) == self.identity.instance,
                Value::IpParameter(s) => s == self.ip,
                _ => false,
            };
            if !hit {
                return None;
            }
        }
        // An empty filter selects nobody; All stands alone.
        if blocks == 0 || (all && blocks != 1) {
            return None;
        }
        Some(alias)
    }

    fn get(&self, dst: MacAddr, request: &Header, data: &[u8], out: &mut [u8]) -> Option<usize> {
        if data.len() % 2 != 0 || data.is_empty() {
            return None;
        }
        let h = Self::response_header(request, service_type::RESPONSE_SUCCESS);
        self.frame(out, dst, FrameKind::DcpGetSet, &h, |s, w| {
            for pair in data.chunks_exact(2) {
                let (o, sub) = (*pair.first()?, *pair.get(1)?);
                let kind = BlockType::from_pair(o, sub);
                let kinds: &[BlockType] = if kind == BlockType::All {
                    &ALL_READABLE
                } else {
                    core::slice::from_ref(&kind)
                };
                for &k in kinds {
                    let block = match s.data_block(k) {
                        Some(b) => b,
                        None => negative(k, read_error(k)),
                    };
                    // A full buffer truncates the answer (1514 bytes hold all).
                    if w.push(&block).is_err() {
                        return Some(());
                    }
                }
            }
            Some(())
        })
    }

    fn set(
        &mut self,
        now: Nanos,
        dst: MacAddr,
        request: &Header,
        data: &[u8],
        out: &mut [u8],
        events: &mut Events,
    ) -> Option<usize> {
        // Check the whole request first: a malformed one changes nothing and
        // is dropped, and the answer (8 bytes a block) must fit.
        let mut count = 0usize;
        for block in Blocks::new(data) {
            block.ok()?.split_prefix().ok()?;
            count += 1;
        }
        let need = crate::wire::HEADER_LEN + 2 + HEADER_LEN + 8 * count;
        if count == 0 || out.len() < need {
            return None;
        }
        let h = Self::response_header(request, service_type::RESPONSE_SUCCESS);
        // Apply block by block, in order, answering each.
        let eth = emit_header(out, dst, self.mac, None, ethertype::PROFINET)?;
        let body = out.get_mut(eth + 2 + HEADER_LEN..)?;
        let mut w = BlockWriter::new(body);
        for block in Blocks::new(data).flatten() {
            let err = self.set_block(now, block, events);
            w.push(&negative(block.kind, err)).ok()?;
        }
        let data_len = w.len();
        let fid = out.get_mut(eth..eth + 2)?;
        fid.copy_from_slice(&FrameKind::DcpGetSet.frame_id().to_be_bytes());
        Header {
            data_length: u16::try_from(data_len).ok()?,
            ..h
        }
        .emit(out.get_mut(eth + 2..)?)
        .ok()?;
        let len = eth + 2 + HEADER_LEN + data_len;
        let padded = len.max(crate::wire::MIN_FRAME_LEN);
        out.get_mut(len..padded)?.fill(0);
        Some(padded)
    }

    fn set_block(&mut self, now: Nanos, block: RawBlock<'_>, events: &mut Events) -> BlockError {
        let Ok((qualifier, raw)) = block.split_prefix() else {
            return BlockError::SuboptionNotSet;
        };
        let permanent = qualifier & 1 != 0;
        let value = Value::parse(block.kind, raw);
        match block.kind {
            BlockType::NameOfStation => {
                let Ok(name) = NameOfStation::new(raw) else {
                    return BlockError::SuboptionNotSet;
                };
                if self.in_operation && name != self.name {
                    return BlockError::InOperation;
                }
                self.name = name.clone();
                push_event(events, Event::NameOfStation { name, permanent });
                BlockError::NoError
            }
            BlockType::IpParameter => {
                let Ok(Value::IpParameter(suite)) = value else {
                    return BlockError::SuboptionNotSet;
                };
                if !ip_suite_valid(&suite) {
                    return BlockError::SuboptionNotSet;
                }
                if self.in_operation && suite != self.ip {
                    return BlockError::InOperation;
                }
                self.ip = suite;
                push_event(events, Event::IpSuite { suite, permanent });
                BlockError::NoError
            }
            BlockType::ControlStart | BlockType::ControlStop => match value {
                Ok(Value::Empty) => BlockError::NoError,
                _ => BlockError::SuboptionNotSet,
            },
            BlockType::ControlSignal => match value {
                Ok(Value::Signal(0x0100)) if qualifier == 0 => {
                    let until = self.signal.trigger(now);
                    push_event(events, Event::Signal { until });
                    BlockError::NoError
                }
                _ => BlockError::SuboptionNotSet,
            },
            BlockType::ControlFactoryReset | BlockType::ControlResetToFactory => {
                if !matches!(value, Ok(Value::Empty)) {
                    return BlockError::SuboptionNotSet;
                }
                let mode = if block.kind == BlockType::ControlFactoryReset {
                    ResetMode::All
                } else {
                    match ResetMode::from_qualifier(qualifier) {
                        Some(m) => m,
                        None => return BlockError::SuboptionNotSupported,
                    }
                };
                if self.in_operation {
                    return BlockError::InOperation;
                }
                push_event(events, Event::ResetToFactory(mode));
                if mode.clears_communication() {
                    self.name = NameOfStation::EMPTY;
                    self.ip = IpSuite::UNSET;
                    let name = NameOfStation::EMPTY;
                    push_event(
                        events,
                        Event::NameOfStation {
                            name,
                            permanent: true,
                        },
                    );
                    let suite = IpSuite::UNSET;
                    push_event(
                        events,
                        Event::IpSuite {
                            suite,
                            permanent: true,
                        },
                    );
                }
                BlockError::NoError
            }
            other => write_error(other),
        }
    }
}

/// Every block a Get of All returns.
const ALL_READABLE: [BlockType; 11] = [
    BlockType::IpMac,
    BlockType::IpParameter,
    BlockType::IpFullSuite,
    BlockType::DeviceVendor,
    BlockType::NameOfStation,
    BlockType::DeviceId,
    BlockType::DeviceRole,
    BlockType::DeviceOptions,
    BlockType::AliasName,
    BlockType::DeviceInstance,
    BlockType::DeviceInitiative,
];

/// A Control/Response block for `kind` with `err`.
fn negative(kind: BlockType, err: BlockError) -> BlockRepr<'static> {
    BlockRepr {
        kind: BlockType::ControlResponse,
        prefix: None,
        value: Value::Response(kind, err),
    }
}

/// Why `kind` cannot be read.
fn read_error(kind: BlockType) -> BlockError {
    match kind {
        // No alias learned yet: "no data set available".
        BlockType::AliasName => BlockError::SuboptionNotSupported,
        other => write_error(other),
    }
}

/// Why `kind` cannot be written (or read): an option this device does not
/// have, or a suboption of one it has.
fn write_error(kind: BlockType) -> BlockError {
    match kind.pair().0 {
        1 | 2 | 5 | 6 => BlockError::SuboptionNotSupported,
        _ => BlockError::OptionNotSupported,
    }
}

fn push_event(events: &mut Events, e: Event) {
    let same = |a: &Event| core::mem::discriminant(a) == core::mem::discriminant(&e);
    if let Some(slot) = events.iter_mut().find(|a| same(a)) {
        *slot = e;
    } else {
        // MAX_EVENTS covers one of each kind.
        let _ = events.push(e);
    }
}

/// The IP suite rules: all zero (no address) or a unicast address with a
/// contiguous mask, host part neither all zeros nor all ones (for prefixes up
/// to /30), and a gateway that is 0.0.0.0 or inside the subnet (the address
/// itself included: "no gateway" by convention).
pub fn ip_suite_valid(s: &IpSuite) -> bool {
    if s.is_unset() {
        return true;
    }
    let ip = u32::from(s.ip);
    let mask = u32::from(s.mask);
    let gw = u32::from(s.gateway);
    let inv = !mask;
    let contiguous = inv & inv.wrapping_add(1) == 0;
    let first = s.ip.octets()[0];
    if !contiguous || mask == 0 || first == 0 || first == 127 || first >= 224 {
        return false;
    }
    let host = ip & inv;
    if mask.leading_ones() <= 30 && (host == 0 || host == inv) {
        return false;
    }
    gw == 0 || (gw & mask == ip & mask && gw & inv != inv)
}
