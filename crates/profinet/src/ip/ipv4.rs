//! IPv4 header, ICMP echo and UDP: checked parse and emit.

use super::Ipv4Addr;

/// Length of an IPv4 header without options.
pub const IPV4_HEADER_LEN: usize = 20;
/// Length of a UDP header.
pub const UDP_HEADER_LEN: usize = 8;
/// IP protocol number of ICMP.
pub const PROTO_ICMP: u8 = 1;
/// IP protocol number of UDP.
pub const PROTO_UDP: u8 = 17;
/// Time to live of the packets we send.
pub const TTL: u8 = 64;

/// The Internet checksum (RFC 1071) one's-complement sum, not yet inverted,
/// continued from `acc`.
pub fn sum16(mut acc: u32, data: &[u8]) -> u32 {
    let mut chunks = data.chunks_exact(2);
    for c in &mut chunks {
        if let [a, b] = c {
            acc = acc.wrapping_add(u32::from(u16::from_be_bytes([*a, *b])));
        }
    }
    if let [last] = chunks.remainder() {
        acc = acc.wrapping_add(u32::from(*last) << 8);
    }
    acc
}

/// Folds and inverts a [`sum16`] into the 16-bit checksum.
pub fn fold(mut acc: u32) -> u16 {
    while acc > 0xFFFF {
        acc = (acc & 0xFFFF) + (acc >> 16);
    }
    !(acc as u16)
}

/// A received IPv4 packet, checked: version 4, header length, total length,
/// header checksum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ipv4Packet<'a> {
    /// Source address.
    pub src: Ipv4Addr,
    /// Destination address.
    pub dst: Ipv4Addr,
    /// Protocol number.
    pub protocol: u8,
    /// More-fragments flag set or fragment offset non-zero.
    pub is_fragment: bool,
    /// The payload (exactly total length minus header length; Ethernet padding cut).
    pub payload: &'a [u8],
}

/// Why an IPv4 packet was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ipv4Error {
    /// Shorter than its header or its total length.
    Truncated,
    /// Version not 4 or header length < 20.
    Malformed,
    /// Header checksum wrong.
    Checksum,
}

impl<'a> Ipv4Packet<'a> {
    /// Checks and parses a packet.
    pub fn parse(b: &'a [u8]) -> Result<Ipv4Packet<'a>, Ipv4Error> {
        let vihl = *b.first().ok_or(Ipv4Error::Truncated)?;
        if vihl >> 4 != 4 {
            return Err(Ipv4Error::Malformed);
        }
        let ihl = usize::from(vihl & 0x0F) * 4;
        if ihl < IPV4_HEADER_LEN {
            return Err(Ipv4Error::Malformed);
        }
        let header = b.get(..ihl).ok_or(Ipv4Error::Truncated)?;
        let be16 = |at: usize| -> Result<u16, Ipv4Error> {
            match header.get(at..at + 2) {
                Some([x, y]) => Ok(u16::from_be_bytes([*x, *y])),
                _ => Err(Ipv4Error::Truncated),
            }
        };
        let total = usize::from(be16(2)?);
        if total < ihl {
            return Err(Ipv4Error::Malformed);
        }
        let packet = b.get(..total).ok_or(Ipv4Error::Truncated)?;
        if fold(sum16(0, header)) != 0 {
            return Err(Ipv4Error::Checksum);
        }
        let frag = be16(6)?;
        let addr = |at: usize| -> Result<Ipv4Addr, Ipv4Error> {
            let mut a = [0u8; 4];
            a.copy_from_slice(header.get(at..at + 4).ok_or(Ipv4Error::Truncated)?);
            Ok(Ipv4Addr::from(a))
        };
        Ok(Ipv4Packet {
            src: addr(12)?,
            dst: addr(16)?,
            protocol: *header.get(9).ok_or(Ipv4Error::Truncated)?,
            is_fragment: frag & 0x2000 != 0 || frag & 0x1FFF != 0,
            payload: packet.get(ihl..).ok_or(Ipv4Error::Truncated)?,
        })
    }
}

/// Writes a 20-byte IPv4 header (DF set, no options) for `payload_len` bytes of
/// `protocol` payload at the start of `buf`; `None` if it does not fit.
pub fn emit_ipv4(
    buf: &mut [u8],
    src: Ipv4Addr,
    dst: Ipv4Addr,
    protocol: u8,
    ident: u16,
    payload_len: usize,
) -> Option<()> {
    let total = u16::try_from(payload_len.checked_add(IPV4_HEADER_LEN)?).ok()?;
    let h = buf.get_mut(..IPV4_HEADER_LEN)?;
    h.fill(0);
    h.get_mut(0..4)?.copy_from_slice(&[0x45, 0, 0, 0]);
    h.get_mut(2..4)?.copy_from_slice(&total.to_be_bytes());
    h.get_mut(4..6)?.copy_from_slice(&ident.to_be_bytes());
    h.get_mut(6..8)?.copy_from_slice(&0x4000u16.to_be_bytes());
    *h.get_mut(8)? = TTL;
    *h.get_mut(9)? = protocol;
    h.get_mut(12..16)?.copy_from_slice(&src.octets());
    h.get_mut(16..20)?.copy_from_slice(&dst.octets());
    let c = fold(sum16(0, h));
    h.get_mut(10..12)?.copy_from_slice(&c.to_be_bytes());
    Some(())
}

/// A received UDP datagram, checked (length, checksum when present).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UdpPacket<'a> {
    /// Source port.
    pub src_port: u16,
    /// Destination port.
    pub dst_port: u16,
    /// The payload.
    pub payload: &'a [u8],
}

/// Why a UDP datagram was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UdpError {
    /// Shorter than its header or its length field.
    Truncated,
    /// Checksum present and wrong.
    Checksum,
}

fn pseudo_sum(src: Ipv4Addr, dst: Ipv4Addr, protocol: u8, len: usize) -> u32 {
    let acc = sum16(sum16(0, &src.octets()), &dst.octets());
    acc.wrapping_add(u32::from(protocol))
        .wrapping_add((len & 0xFFFF) as u32)
}

impl<'a> UdpPacket<'a> {
    /// Checks and parses a datagram carried from `src` to `dst`.
    pub fn parse(b: &'a [u8], src: Ipv4Addr, dst: Ipv4Addr) -> Result<UdpPacket<'a>, UdpError> {
        let h = b.get(..UDP_HEADER_LEN).ok_or(UdpError::Truncated)?;
        let f = |at: usize| match h.get(at..at + 2) {
            Some([x, y]) => u16::from_be_bytes([*x, *y]),
            _ => 0,
        };
        let len = usize::from(f(4));
        if len < UDP_HEADER_LEN {
            return Err(UdpError::Truncated);
        }
        let dgram = b.get(..len).ok_or(UdpError::Truncated)?;
        if f(6) != 0 && fold(sum16(pseudo_sum(src, dst, PROTO_UDP, len), dgram)) != 0 {
            return Err(UdpError::Checksum);
        }
        Ok(UdpPacket {
            src_port: f(0),
            dst_port: f(2),
            payload: dgram.get(UDP_HEADER_LEN..).ok_or(UdpError::Truncated)?,
        })
    }
}

/// Writes a UDP header (with checksum) in front of the `payload_len` payload
/// bytes already at `buf[8..]`; `None` if they do not fit.
pub fn emit_udp(
    buf: &mut [u8],
    src: (Ipv4Addr, u16),
    dst: (Ipv4Addr, u16),
    payload_len: usize,
) -> Option<()> {
    let len = payload_len.checked_add(UDP_HEADER_LEN)?;
    let len16 = u16::try_from(len).ok()?;
    let d = buf.get_mut(..len)?;
    d.get_mut(0..2)?.copy_from_slice(&src.1.to_be_bytes());
    d.get_mut(2..4)?.copy_from_slice(&dst.1.to_be_bytes());
    d.get_mut(4..6)?.copy_from_slice(&len16.to_be_bytes());
    d.get_mut(6..8)?.copy_from_slice(&[0, 0]);
    let mut c = fold(sum16(pseudo_sum(src.0, dst.0, PROTO_UDP, len), d));
    if c == 0 {
        c = 0xFFFF;
    }
    d.get_mut(6..8)?.copy_from_slice(&c.to_be_bytes());
    Some(())
}

/// ICMP echo request type.
pub const ICMP_ECHO_REQUEST: u8 = 8;
/// ICMP echo reply type.
pub const ICMP_ECHO_REPLY: u8 = 0;

/// Checks an ICMP message (at least 8 bytes, checksum) and returns its type.
pub fn icmp_type(b: &[u8]) -> Option<u8> {
    if b.len() < 8 || fold(sum16(0, b)) != 0 {
        return None;
    }
    b.first().copied()
}

/// Writes the echo reply to the echo request `req` into `buf`; returns its length.
pub fn emit_echo_reply(buf: &mut [u8], req: &[u8]) -> Option<usize> {
    let out = buf.get_mut(..req.len())?;
    out.copy_from_slice(req);
    *out.get_mut(0)? = ICMP_ECHO_REPLY;
    *out.get_mut(1)? = 0;
    out.get_mut(2..4)?.copy_from_slice(&[0, 0]);
    let c = fold(sum16(0, out));
    out.get_mut(2..4)?.copy_from_slice(&c.to_be_bytes());
    Some(req.len())
}
