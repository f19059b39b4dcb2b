//! The DCP PDU on the wire: the header ([`Packet`], [`Header`]) and the blocks
//! ([`Blocks`], [`BlockType`], [`Value`], [`BlockRepr`], [`BlockWriter`]).
//!
//! A DCP PDU follows the 2-byte FrameID of a PROFINET frame:
//!
//! ```text
//! ServiceID u8 | ServiceType u8 | Xid u32 | ResponseDelay u16 | DCPDataLength u16 | blocks…
//! block: Option u8 | Suboption u8 | DCPBlockLength u16 | [BlockInfo|BlockQualifier u16] value | pad to even
//! ```
//!
//! The 2-byte prefix depends on the PDU: responses carry a BlockInfo, Set
//! requests a BlockQualifier, Identify filters and Control/Response blocks none.
//! [`Blocks`] hands out raw blocks; [`Value::parse`] gives a value its meaning.
//! Every length is checked before it is used; nothing here panics.

use core::net::Ipv4Addr;

use crate::wire::MacAddr;

/// Length of the DCP header (ServiceID … DCPDataLength).
pub const HEADER_LEN: usize = 10;
/// Length of a block header (Option, Suboption, DCPBlockLength).
pub const BLOCK_HEADER_LEN: usize = 4;

/// Why a PDU or block was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Error {
    /// The buffer is shorter than the header or than DCPDataLength says.
    Truncated,
    /// A block runs past DCPDataLength, or a value has the wrong length for
    /// its block type.
    Malformed,
    /// The output buffer is too small.
    Exhausted,
}

/// DCP ServiceID.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ServiceId {
    /// Get (3).
    Get,
    /// Set (4).
    Set,
    /// Identify (5).
    Identify,
    /// Hello (6).
    Hello,
    /// Any other value.
    Other(u8),
}

impl From<u8> for ServiceId {
    fn from(v: u8) -> Self {
        match v {
            3 => ServiceId::Get,
            4 => ServiceId::Set,
            5 => ServiceId::Identify,
            6 => ServiceId::Hello,
            o => ServiceId::Other(o),
        }
    }
}

impl From<ServiceId> for u8 {
    fn from(s: ServiceId) -> u8 {
        match s {
            ServiceId::Get => 3,
            ServiceId::Set => 4,
            ServiceId::Identify => 5,
            ServiceId::Hello => 6,
            ServiceId::Other(o) => o,
        }
    }
}

/// DCP ServiceType values.
pub mod service_type {
    /// A request.
    pub const REQUEST: u8 = 0x00;
    /// A response, success.
    pub const RESPONSE_SUCCESS: u8 = 0x01;
    /// A response: the service is not supported.
    pub const RESPONSE_NOT_SUPPORTED: u8 = 0x05;
}

/// DCP option numbers.
pub mod option {
    /// IP (MAC, IP parameter, full IP suite).
    pub const IP: u8 = 0x01;
    /// Device properties.
    pub const DEVICE: u8 = 0x02;
    /// DHCP.
    pub const DHCP: u8 = 0x03;
    /// Control.
    pub const CONTROL: u8 = 0x05;
    /// Device initiative.
    pub const DEVICE_INITIATIVE: u8 = 0x06;
    /// All selector (with suboption 0xFF).
    pub const ALL: u8 = 0xFF;
}

/// A block's (Option, Suboption) pair, named.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlockType {
    /// IP / MAC address (1,1).
    IpMac,
    /// IP / IP parameter: address, mask, gateway (1,2).
    IpParameter,
    /// IP / full IP suite: IP parameter and four DNS servers (1,3).
    IpFullSuite,
    /// Device / vendor, the "type of station" (2,1).
    DeviceVendor,
    /// Device / name of station (2,2).
    NameOfStation,
    /// Device / device ID: vendor ID and device ID (2,3).
    DeviceId,
    /// Device / device role (2,4).
    DeviceRole,
    /// Device / device options: the list of supported pairs (2,5).
    DeviceOptions,
    /// Device / alias name (2,6).
    AliasName,
    /// Device / device instance (2,7).
    DeviceInstance,
    /// DHCP, any suboption (3,x).
    Dhcp(u8),
    /// Control / start transaction (5,1).
    ControlStart,
    /// Control / stop transaction (5,2).
    ControlStop,
    /// Control / signal (5,3).
    ControlSignal,
    /// Control / response (5,4).
    ControlResponse,
    /// Control / factory reset (5,5).
    ControlFactoryReset,
    /// Control / reset to factory (5,6).
    ControlResetToFactory,
    /// Device initiative (6,1).
    DeviceInitiative,
    /// The All selector (0xFF,0xFF).
    All,
    /// Any other pair.
    Other(u8, u8),
}

impl BlockType {
    /// Names an (Option, Suboption) pair.
    pub const fn from_pair(option: u8, suboption: u8) -> BlockType {
        match (option, suboption) {
            (1, 1) => BlockType::IpMac,
            (1, 2) => BlockType::IpParameter,
            (1, 3) => BlockType::IpFullSuite,
            (2, 1) => BlockType::DeviceVendor,
            (2, 2) => BlockType::NameOfStation,
            (2, 3) => BlockType::DeviceId,
            (2, 4) => BlockType::DeviceRole,
            (2, 5) => BlockType::DeviceOptions,
            (2, 6) => BlockType::AliasName,
            (2, 7) => BlockType::DeviceInstance,
            (3, s) => BlockType::Dhcp(s),
            (5, 1) => BlockType::ControlStart,
            (5, 2) => BlockType::ControlStop,
            (5, 3) => BlockType::ControlSignal,
            (5, 4) => BlockType::ControlResponse,
            (5, 5) => BlockType::ControlFactoryReset,
            (5, 6) => BlockType::ControlResetToFactory,
            (6, 1) => BlockType::DeviceInitiative,
            (0xFF, 0xFF) => BlockType::All,
            (o, s) => BlockType::Other(o, s),
        }
    }

    /// The (Option, Suboption) pair.
    pub const fn pair(self) -> (u8, u8) {
        match self {
            BlockType::IpMac => (1, 1),
            BlockType::IpParameter => (1, 2),
            BlockType::IpFullSuite => (1, 3),
            BlockType::DeviceVendor => (2, 1),
            BlockType::NameOfStation => (2, 2),
            BlockType::DeviceId => (2, 3),
            BlockType::DeviceRole => (2, 4),
            BlockType::DeviceOptions => (2, 5),
            BlockType::AliasName => (2, 6),
            BlockType::DeviceInstance => (2, 7),
            BlockType::Dhcp(s) => (3, s),
            BlockType::ControlStart => (5, 1),
            BlockType::ControlStop => (5, 2),
            BlockType::ControlSignal => (5, 3),
            BlockType::ControlResponse => (5, 4),
            BlockType::ControlFactoryReset => (5, 5),
            BlockType::ControlResetToFactory => (5, 6),
            BlockType::DeviceInitiative => (6, 1),
            BlockType::All => (0xFF, 0xFF),
            BlockType::Other(o, s) => (o, s),
        }
    }
}

/// The BlockError of a Control/Response block (Set and Get responses).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlockError {
    /// 0x00: no error.
    NoError,
    /// 0x01: option not supported.
    OptionNotSupported,
    /// 0x02: suboption not supported, or no data set available.
    SuboptionNotSupported,
    /// 0x03: suboption not set (the value was refused).
    SuboptionNotSet,
    /// 0x04: resource error.
    ResourceError,
    /// 0x05: Set not possible by local reasons.
    SetNotPossible,
    /// 0x06: in operation, Set not possible.
    InOperation,
    /// Any other value.
    Other(u8),
}

impl From<u8> for BlockError {
    fn from(v: u8) -> Self {
        match v {
            0 => BlockError::NoError,
            1 => BlockError::OptionNotSupported,
            2 => BlockError::SuboptionNotSupported,
            3 => BlockError::SuboptionNotSet,
            4 => BlockError::ResourceError,
            5 => BlockError::SetNotPossible,
            6 => BlockError::InOperation,
            o => BlockError::Other(o),
        }
    }
}

impl From<BlockError> for u8 {
    fn from(e: BlockError) -> u8 {
        match e {
            BlockError::NoError => 0,
            BlockError::OptionNotSupported => 1,
            BlockError::SuboptionNotSupported => 2,
            BlockError::SuboptionNotSet => 3,
            BlockError::ResourceError => 4,
            BlockError::SetNotPossible => 5,
            BlockError::InOperation => 6,
            BlockError::Other(o) => o,
        }
    }
}

/// IP address, subnet mask and default gateway.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IpSuite {
    /// IP address.
    pub ip: Ipv4Addr,
    /// Subnet mask.
    pub mask: Ipv4Addr,
    /// Default gateway (0.0.0.0: none).
    pub gateway: Ipv4Addr,
}

impl IpSuite {
    /// All zero: no IP address assigned.
    pub const UNSET: IpSuite = IpSuite {
        ip: Ipv4Addr::UNSPECIFIED,
        mask: Ipv4Addr::UNSPECIFIED,
        gateway: Ipv4Addr::UNSPECIFIED,
    };

    /// `true` if all three are 0.0.0.0.
    pub fn is_unset(&self) -> bool {
        *self == IpSuite::UNSET
    }

    fn from_bytes(b: &[u8]) -> Option<IpSuite> {
        Some(IpSuite {
            ip: ipv4_at(b, 0)?,
            mask: ipv4_at(b, 4)?,
            gateway: ipv4_at(b, 8)?,
        })
    }

    fn octets(&self) -> [u8; 12] {
        let mut o = [0u8; 12];
        for (chunk, a) in o.chunks_exact_mut(4).zip([self.ip, self.mask, self.gateway]) {
            chunk.copy_from_slice(&a.octets());
        }
        o
    }
}

impl Default for IpSuite {
    fn default() -> Self {
        IpSuite::UNSET
    }
}

fn ipv4_at(b: &[u8], at: usize) -> Option<Ipv4Addr> {
    let s: [u8; 4] = b.get(at..at + 4)?.try_into().ok()?;
    Some(Ipv4Addr::from(s))
}

fn be16(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_be_bytes([*b.get(at)?, *b.get(at + 1)?]))
}

fn be32(b: &[u8], at: usize) -> Option<u32> {
    let s: [u8; 4] = b.get(at..at + 4)?.try_into().ok()?;
    Some(u32::from_be_bytes(s))
}

/// A DCP PDU (from ServiceID on) in a buffer; see [`Packet::new_checked`].
#[derive(Clone, Copy, Debug)]
pub struct Packet<T: AsRef<[u8]>> {
    buffer: T,
}

impl<T: AsRef<[u8]>> Packet<T> {
    /// Wraps a buffer without checking it; accessors return placeholder values
    /// (zero, empty) for missing bytes rather than panic.
    pub const fn new_unchecked(buffer: T) -> Packet<T> {
        Packet { buffer }
    }

    /// Wraps a buffer holding at least the header and the DCPDataLength bytes
    /// it announces (any further bytes, Ethernet padding, are ignored).
    pub fn new_checked(buffer: T) -> Result<Packet<T>, Error> {
        let p = Packet { buffer };
        let b = p.buffer.as_ref();
        let len = be16(b, 8).ok_or(Error::Truncated)?;
        if b.len() < HEADER_LEN + usize::from(len) {
            return Err(Error::Truncated);
        }
        Ok(p)
    }

    fn field16(&self, at: usize) -> u16 {
        be16(self.buffer.as_ref(), at).unwrap_or(0)
    }

    /// ServiceID.
    pub fn service_id(&self) -> ServiceId {
        ServiceId::from(self.buffer.as_ref().first().copied().unwrap_or(0))
    }

    /// ServiceType.
    pub fn service_type(&self) -> u8 {
        self.buffer.as_ref().get(1).copied().unwrap_or(0)
    }

    /// Xid, the transaction ID the response echoes.
    pub fn xid(&self) -> u32 {
        be32(self.buffer.as_ref(), 2).unwrap_or(0)
    }

    /// ResponseDelay: the ResponseDelayFactor of an Identify request, else
    /// reserved (0).
    pub fn response_delay(&self) -> u16 {
        self.field16(6)
    }

    /// DCPDataLength.
    pub fn data_length(&self) -> u16 {
        self.field16(8)
    }

    /// The DCPDataLength bytes after the header (empty if unchecked and short).
    pub fn data(&self) -> &[u8] {
        let end = HEADER_LEN + usize::from(self.data_length());
        self.buffer.as_ref().get(HEADER_LEN..end).unwrap_or(&[])
    }
}

/// The parsed DCP header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Header {
    /// ServiceID.
    pub service: ServiceId,
    /// ServiceType ([`service_type`]).
    pub service_type: u8,
    /// Xid.
    pub xid: u32,
    /// ResponseDelay (factor × 10 ms in an Identify request).
    pub response_delay: u16,
    /// DCPDataLength.
    pub data_length: u16,
}

impl Header {
    /// Reads the header of a checked packet.
    pub fn parse<T: AsRef<[u8]>>(p: &Packet<T>) -> Header {
        Header {
            service: p.service_id(),
            service_type: p.service_type(),
            xid: p.xid(),
            response_delay: p.response_delay(),
            data_length: p.data_length(),
        }
    }

    /// Writes the header into the first [`HEADER_LEN`] bytes of `buf`.
    pub fn emit(&self, buf: &mut [u8]) -> Result<(), Error> {
        let h = buf.get_mut(..HEADER_LEN).ok_or(Error::Exhausted)?;
        let mut b = [0u8; HEADER_LEN];
        b[0] = self.service.into();
        b[1] = self.service_type;
        b[2..6].copy_from_slice(&self.xid.to_be_bytes());
        b[6..8].copy_from_slice(&self.response_delay.to_be_bytes());
        b[8..10].copy_from_slice(&self.data_length.to_be_bytes());
        h.copy_from_slice(&b);
        Ok(())
    }
}

/// One block as it stands in the PDU: its type and its DCPBlockLength bytes
/// (prefix included, padding excluded).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RawBlock<'a> {
    /// The (Option, Suboption) pair.
    pub kind: BlockType,
    /// The block's bytes (BlockInfo/BlockQualifier, if any, then the value).
    pub data: &'a [u8],
}

impl<'a> RawBlock<'a> {
    /// Splits off the 2-byte BlockInfo or BlockQualifier: `(prefix, value)`.
    pub fn split_prefix(&self) -> Result<(u16, &'a [u8]), Error> {
        let p = be16(self.data, 0).ok_or(Error::Malformed)?;
        Ok((p, self.data.get(2..).unwrap_or(&[])))
    }
}

/// Iterator over the blocks of a PDU's data; yields `Err(Malformed)` once and
/// stops if a block runs past the end. A trailing pad byte after the last
/// block may be present or not (controllers differ).
#[derive(Clone, Debug)]
pub struct Blocks<'a> {
    rest: &'a [u8],
    failed: bool,
}

impl<'a> Blocks<'a> {
    /// Blocks of `data` (a packet's [`Packet::data`]).
    pub const fn new(data: &'a [u8]) -> Blocks<'a> {
        Blocks {
            rest: data,
            failed: false,
        }
    }
}

impl<'a> Iterator for Blocks<'a> {
    type Item = Result<RawBlock<'a>, Error>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed || self.rest.is_empty() {
            return None;
        }
        let parsed = (|| {
            let option = *self.rest.first()?;
            let suboption = *self.rest.get(1)?;
            let len = usize::from(be16(self.rest, 2)?);
            let data = self.rest.get(BLOCK_HEADER_LEN..BLOCK_HEADER_LEN + len)?;
            let padded = (BLOCK_HEADER_LEN + len + 1) & !1;
            let rest = self.rest.get(padded..).unwrap_or(&[]);
            Some((BlockType::from_pair(option, suboption), data, rest))
        })();
        match parsed {
            Some((kind, data, rest)) => {
                self.rest = rest;
                Some(Ok(RawBlock { kind, data }))
            }
            None => {
                self.failed = true;
                Some(Err(Error::Malformed))
            }
        }
    }
}

/// The meaning of a block's value (after any BlockInfo/BlockQualifier).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Value<'a> {
    /// IP / MAC address.
    Mac(MacAddr),
    /// IP / IP parameter.
    IpParameter(IpSuite),
    /// IP / full IP suite: IP parameter and four DNS server addresses.
    IpFullSuite(IpSuite, [Ipv4Addr; 4]),
    /// Device / vendor ("type of station"), or any other string-like value
    /// (name of station, alias name, DHCP data) as raw bytes.
    Bytes(&'a [u8]),
    /// Device / device ID.
    DeviceId {
        /// Vendor ID.
        vendor_id: u16,
        /// Device ID.
        device_id: u16,
    },
    /// Device / device role (DeviceRoleDetails; bit 0 = IO device).
    DeviceRole(u8),
    /// Device / device options: (Option, Suboption) pairs, 2 bytes each.
    DeviceOptions(&'a [u8]),
    /// Device / device instance (high, low).
    DeviceInstance(u8, u8),
    /// Device initiative (bit 0: the device sends Hello after power-on).
    DeviceInitiative(u16),
    /// Control / signal: SignalValue (0x0100 = flash once).
    Signal(u16),
    /// Control / response: the block answered and its error.
    Response(BlockType, BlockError),
    /// No value (start/stop transaction, reset, the All selector, a Get's
    /// empty filter).
    Empty,
}

impl<'a> Value<'a> {
    /// Gives `value` (prefix already removed) its meaning for `kind`;
    /// `Malformed` if its length does not fit.
    pub fn parse(kind: BlockType, value: &'a [u8]) -> Result<Value<'a>, Error> {
        let exact = |n: usize| {
            if value.len() == n {
                Ok(())
            } else {
                Err(Error::Malformed)
            }
        };
        let byte = |i: usize| value.get(i).copied().ok_or(Error::Malformed);
        Ok(match kind {
            BlockType::IpMac => {
                exact(6)?;
                let m: [u8; 6] = value.try_into().map_err(|_| Error::Malformed)?;
                Value::Mac(MacAddr(m))
            }
            BlockType::IpParameter => {
                exact(12)?;
                Value::IpParameter(IpSuite::from_bytes(value).ok_or(Error::Malformed)?)
            }
            BlockType::IpFullSuite => {
                exact(28)?;
                let suite = IpSuite::from_bytes(value).ok_or(Error::Malformed)?;
                let mut dns = [Ipv4Addr::UNSPECIFIED; 4];
                for (i, d) in dns.iter_mut().enumerate() {
                    *d = ipv4_at(value, 12 + 4 * i).ok_or(Error::Malformed)?;
                }
                Value::IpFullSuite(suite, dns)
            }
            BlockType::DeviceId => {
                exact(4)?;
                Value::DeviceId {
                    vendor_id: be16(value, 0).ok_or(Error::Malformed)?,
                    device_id: be16(value, 2).ok_or(Error::Malformed)?,
                }
            }
            BlockType::DeviceRole => {
                exact(2)?;
                Value::DeviceRole(byte(0)?)
            }
            BlockType::DeviceOptions => {
                if value.len() % 2 != 0 {
                    return Err(Error::Malformed);
                }
                Value::DeviceOptions(value)
            }
            BlockType::DeviceInstance => {
                exact(2)?;
                Value::DeviceInstance(byte(0)?, byte(1)?)
            }
            BlockType::DeviceInitiative => {
                exact(2)?;
                Value::DeviceInitiative(be16(value, 0).ok_or(Error::Malformed)?)
            }
            BlockType::ControlSignal => {
                exact(2)?;
                Value::Signal(be16(value, 0).ok_or(Error::Malformed)?)
            }
            BlockType::ControlResponse => {
                exact(3)?;
                Value::Response(
                    BlockType::from_pair(byte(0)?, byte(1)?),
                    BlockError::from(byte(2)?),
                )
            }
            BlockType::ControlStart
            | BlockType::ControlStop
            | BlockType::ControlFactoryReset
            | BlockType::ControlResetToFactory
            | BlockType::All => {
                exact(0)?;
                Value::Empty
            }
            BlockType::DeviceVendor
            | BlockType::NameOfStation
            | BlockType::AliasName
            | BlockType::Dhcp(_)
            | BlockType::Other(..) => Value::Bytes(value),
        })
    }

    /// Length of the value on the wire.
    pub fn len(&self) -> usize {
        match self {
            Value::Mac(_) => 6,
            Value::IpParameter(_) => 12,
            Value::IpFullSuite(..) => 28,
            Value::Bytes(b) | Value::DeviceOptions(b) => b.len(),
            Value::DeviceId { .. } => 4,
            Value::DeviceRole(_)
            | Value::DeviceInstance(..)
            | Value::DeviceInitiative(_)
            | Value::Signal(_) => 2,
            Value::Response(..) => 3,
            Value::Empty => 0,
        }
    }

    /// `true` for a value of no bytes.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Writes the value into `buf` (exactly [`Value::len`] bytes).
    pub fn emit(&self, buf: &mut [u8]) -> Result<(), Error> {
        let out = buf.get_mut(..self.len()).ok_or(Error::Exhausted)?;
        match self {
            Value::Mac(m) => put(out, &m.0),
            Value::IpParameter(s) => put(out, &s.octets()),
            Value::IpFullSuite(s, dns) => {
                let (head, tail) = out.split_at_mut_checked(12).ok_or(Error::Exhausted)?;
                put(head, &s.octets());
                for (chunk, d) in tail.chunks_exact_mut(4).zip(dns) {
                    put(chunk, &d.octets());
                }
            }
            Value::Bytes(b) | Value::DeviceOptions(b) => put(out, b),
            Value::DeviceId { vendor_id, device_id } => {
                let [v0, v1] = vendor_id.to_be_bytes();
                let [d0, d1] = device_id.to_be_bytes();
                put(out, &[v0, v1, d0, d1]);
            }
            Value::DeviceRole(r) => put(out, &[*r, 0]),
            Value::DeviceInstance(h, l) => put(out, &[*h, *l]),
            Value::DeviceInitiative(v) | Value::Signal(v) => put(out, &v.to_be_bytes()),
            Value::Response(kind, err) => {
                let (o, s) = kind.pair();
                put(out, &[o, s, u8::from(*err)]);
            }
            Value::Empty => {}
        }
        Ok(())
    }
}

/// Copies `src` into the start of `dst` (as far as both go; the callers
/// cut `dst` to the value's length first): no length-mismatch panic path.
fn put(dst: &mut [u8], src: &[u8]) {
    for (d, s) in dst.iter_mut().zip(src) {
        *d = *s;
    }
}

/// A block to emit: type, optional BlockInfo/BlockQualifier, value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlockRepr<'a> {
    /// The (Option, Suboption) pair.
    pub kind: BlockType,
    /// BlockInfo (responses) or BlockQualifier (Set requests); `None` for
    /// Control/Response blocks and Identify filters.
    pub prefix: Option<u16>,
    /// The value.
    pub value: Value<'a>,
}

impl BlockRepr<'_> {
    /// DCPBlockLength: prefix and value, without padding.
    pub fn block_length(&self) -> usize {
        self.value.len() + if self.prefix.is_some() { 2 } else { 0 }
    }

    /// Bytes the block takes on the wire: header, block length, padding.
    pub fn buffer_len(&self) -> usize {
        (BLOCK_HEADER_LEN + self.block_length() + 1) & !1
    }

    /// Writes the block (with its pad byte) at the start of `buf`.
    pub fn emit(&self, buf: &mut [u8]) -> Result<usize, Error> {
        let n = self.buffer_len();
        let out = buf.get_mut(..n).ok_or(Error::Exhausted)?;
        let len = u16::try_from(self.block_length()).map_err(|_| Error::Malformed)?;
        let (o, s) = self.kind.pair();
        let (head, rest) = out
            .split_at_mut_checked(BLOCK_HEADER_LEN)
            .ok_or(Error::Exhausted)?;
        put(head, &[o, s, (len >> 8) as u8, len as u8]);
        let rest = match self.prefix {
            Some(p) => {
                let (pre, rest) = rest.split_at_mut_checked(2).ok_or(Error::Exhausted)?;
                put(pre, &p.to_be_bytes());
                rest
            }
            None => rest,
        };
        self.value.emit(rest)?;
        if let Some(pad) = rest.get_mut(self.value.len()..) {
            pad.fill(0);
        }
        Ok(n)
    }
}

/// Appends blocks to a buffer and counts DCPDataLength.
#[derive(Debug)]
pub struct BlockWriter<'a> {
    buf: &'a mut [u8],
    pos: usize,
}

impl<'a> BlockWriter<'a> {
    /// Writes into `buf` (the bytes after the DCP header).
    pub fn new(buf: &'a mut [u8]) -> BlockWriter<'a> {
        BlockWriter { buf, pos: 0 }
    }

    /// Appends a block; `Exhausted` (and nothing written) if it does not fit.
    pub fn push(&mut self, block: &BlockRepr<'_>) -> Result<(), Error> {
        let rest = self.buf.get_mut(self.pos..).ok_or(Error::Exhausted)?;
        let n = block.emit(rest)?;
        self.pos += n;
        Ok(())
    }

    /// Bytes written so far (the DCPDataLength).
    pub fn len(&self) -> usize {
        self.pos
    }

    /// `true` if nothing was written.
    pub fn is_empty(&self) -> bool {
        self.pos == 0
    }
}
