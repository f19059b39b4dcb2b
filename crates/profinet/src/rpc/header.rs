//! The DCE/RPC connectionless (CL) PDU header: 80 bytes, integers in the
//! sender's `drep` byte order (both orders handled), see DCE 1.1 RPC §12.5.

use super::cursor::{Endian, Reader, Writer};
use super::uuid::Uuid;

/// Length of the CL header.
pub const HEADER_LEN: usize = 80;
/// Largest CL PDU (header + body) every implementation must receive
/// (DCE 1.1 "MustRecvFragSize"); responses are fragmented to fit it.
pub const MUST_RECV_FRAG_SIZE: usize = 1464;

/// CL packet types.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PacketType {
    /// A call (client → server).
    Request,
    /// Is my call still alive? (client → server).
    Ping,
    /// The call's result.
    Response,
    /// The call failed in the server (status in the body).
    Fault,
    /// The server is still working on the call (answer to a ping).
    Working,
    /// The server has no such call (answer to a ping).
    Nocall,
    /// The call was refused before execution (status in the body).
    Reject,
    /// The client got the whole response.
    Ack,
    /// Cancel request.
    ClCancel,
    /// Fragment acknowledgement.
    Fack,
    /// Cancel acknowledgement.
    CancelAck,
}

impl PacketType {
    /// From the PTYPE octet.
    pub const fn from_u8(v: u8) -> Option<PacketType> {
        Some(match v {
            0 => PacketType::Request,
            1 => PacketType::Ping,
            2 => PacketType::Response,
            3 => PacketType::Fault,
            4 => PacketType::Working,
            5 => PacketType::Nocall,
            6 => PacketType::Reject,
            7 => PacketType::Ack,
            8 => PacketType::ClCancel,
            9 => PacketType::Fack,
            10 => PacketType::CancelAck,
            _ => return None,
        })
    }

    /// The PTYPE octet.
    pub const fn to_u8(self) -> u8 {
        match self {
            PacketType::Request => 0,
            PacketType::Ping => 1,
            PacketType::Response => 2,
            PacketType::Fault => 3,
            PacketType::Working => 4,
            PacketType::Nocall => 5,
            PacketType::Reject => 6,
            PacketType::Ack => 7,
            PacketType::ClCancel => 8,
            PacketType::Fack => 9,
            PacketType::CancelAck => 10,
        }
    }
}

/// Bits of the first flags octet.
pub mod flags1 {
    /// More fragments follow… this is the last one.
    pub const LASTFRAG: u8 = 0x02;
    /// The PDU is a fragment.
    pub const FRAG: u8 = 0x04;
    /// No fragment acknowledgement wanted.
    pub const NOFACK: u8 = 0x08;
    /// "Maybe" call semantics.
    pub const MAYBE: u8 = 0x10;
    /// Idempotent call.
    pub const IDEMPOTENT: u8 = 0x20;
    /// Broadcast call.
    pub const BROADCAST: u8 = 0x40;
}

/// The data representation label: integer byte order (high nibble of octet 0),
/// character set, float format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Drep(pub [u8; 3]);

impl Drep {
    /// Big-endian, ASCII, IEEE float (what profinet-py and many PLCs send).
    pub const BIG: Drep = Drep([0x00, 0x00, 0x00]);
    /// Little-endian, ASCII, IEEE float.
    pub const LITTLE: Drep = Drep([0x10, 0x00, 0x00]);

    /// The integer byte order.
    pub const fn endian(self) -> Endian {
        if self.0[0] & 0xF0 == 0x10 {
            Endian::Little
        } else {
            Endian::Big
        }
    }

    /// The label for `endian`.
    pub const fn of(endian: Endian) -> Drep {
        match endian {
            Endian::Big => Drep::BIG,
            Endian::Little => Drep::LITTLE,
        }
    }
}

/// A parsed CL header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Header {
    /// Packet type.
    pub ptype: PacketType,
    /// Flags octet 1 ([`flags1`]).
    pub flags1: u8,
    /// Flags octet 2 (bit 1 = cancel pending).
    pub flags2: u8,
    /// Data representation of this PDU.
    pub drep: Drep,
    /// Serial number (high and low octets joined).
    pub serial: u16,
    /// Object UUID.
    pub object: Uuid,
    /// Interface UUID.
    pub interface: Uuid,
    /// Activity UUID (the client's conversation).
    pub activity: Uuid,
    /// Server boot time.
    pub boot_time: u32,
    /// Interface version (major in the low 16 bits).
    pub if_version: u32,
    /// Sequence number of the call within the activity.
    pub seq: u32,
    /// Operation number.
    pub opnum: u16,
    /// Interface hint.
    pub if_hint: u16,
    /// Activity hint.
    pub act_hint: u16,
    /// Body length.
    pub body_len: u16,
    /// Fragment number.
    pub frag_num: u16,
    /// Authentication protocol (0 = none; others are refused).
    pub auth_proto: u8,
}

/// Why a datagram is not a CL PDU we can take.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HeaderError {
    /// Shorter than the header or than header + body length.
    Truncated,
    /// RPC version is not 4.
    Version,
    /// Unknown packet type.
    PacketType,
    /// Authenticated PDU (not supported).
    Auth,
}

impl Header {
    /// Parses the header of a datagram and returns it with its body
    /// (exactly `body_len` bytes).
    pub fn parse(d: &[u8]) -> Result<(Header, &[u8]), HeaderError> {
        let mut r = Reader::new(d, Endian::Big);
        let version = r.u8().ok_or(HeaderError::Truncated)?;
        let ptype = r.u8().ok_or(HeaderError::Truncated)?;
        let flags1 = r.u8().ok_or(HeaderError::Truncated)?;
        let flags2 = r.u8().ok_or(HeaderError::Truncated)?;
        let drep = Drep(r.array::<3>().ok_or(HeaderError::Truncated)?);
        let serial_hi = r.u8().ok_or(HeaderError::Truncated)?;
        if version != 4 {
            return Err(HeaderError::Version);
        }
        let ptype = PacketType::from_u8(ptype).ok_or(HeaderError::PacketType)?;
        let e = drep.endian();
        let mut r = Reader::new(r.rest(), e);
        let h = (|| {
            let object = Uuid::from_wire(r.array()?, e);
            let interface = Uuid::from_wire(r.array()?, e);
            let activity = Uuid::from_wire(r.array()?, e);
            Some(Header {
                ptype,
                flags1,
                flags2,
                drep,
                serial: 0,
                object,
                interface,
                activity,
                boot_time: r.u32()?,
                if_version: r.u32()?,
                seq: r.u32()?,
                opnum: r.u16()?,
                if_hint: r.u16()?,
                act_hint: r.u16()?,
                body_len: r.u16()?,
                frag_num: r.u16()?,
                auth_proto: r.u8()?,
            })
        })();
        let mut h = h.ok_or(HeaderError::Truncated)?;
        let serial_lo = r.u8().ok_or(HeaderError::Truncated)?;
        h.serial = u16::from_be_bytes([serial_hi, serial_lo]);
        if h.auth_proto != 0 {
            return Err(HeaderError::Auth);
        }
        let body = r.bytes(usize::from(h.body_len)).ok_or(HeaderError::Truncated)?;
        Ok((h, body))
    }

    /// Writes the header into `buf` (at least [`HEADER_LEN`] bytes) in the
    /// byte order of `self.drep`.
    pub fn emit(&self, buf: &mut [u8]) -> Option<usize> {
        let e = self.drep.endian();
        let [s_hi, s_lo] = self.serial.to_be_bytes();
        let mut w = Writer::new(buf.get_mut(..HEADER_LEN)?, e);
        w.u8(4)?;
        w.u8(self.ptype.to_u8())?;
        w.u8(self.flags1)?;
        w.u8(self.flags2)?;
        w.bytes(&self.drep.0)?;
        w.u8(s_hi)?;
        w.bytes(&self.object.to_wire(e))?;
        w.bytes(&self.interface.to_wire(e))?;
        w.bytes(&self.activity.to_wire(e))?;
        w.u32(self.boot_time)?;
        w.u32(self.if_version)?;
        w.u32(self.seq)?;
        w.u16(self.opnum)?;
        w.u16(self.if_hint)?;
        w.u16(self.act_hint)?;
        w.u16(self.body_len)?;
        w.u16(self.frag_num)?;
        w.u8(self.auth_proto)?;
        w.u8(s_lo)?;
        Some(HEADER_LEN)
    }

    /// Fragment flag set.
    pub const fn is_frag(&self) -> bool {
        self.flags1 & flags1::FRAG != 0
    }

    /// Last-fragment flag set (or not fragmented at all).
    pub const fn is_last_frag(&self) -> bool {
        !self.is_frag() || self.flags1 & flags1::LASTFRAG != 0
    }

    /// The sender wants no fragment acknowledgement.
    pub const fn is_nofack(&self) -> bool {
        self.flags1 & flags1::NOFACK != 0
    }
}
