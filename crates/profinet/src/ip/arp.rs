//! ARP for IPv4 over Ethernet (RFC 826), with the probe/announcement forms of
//! RFC 5227 used for address conflict detection.

use super::Ipv4Addr;
use crate::wire::MacAddr;

/// Length of an ARP packet for IPv4 over Ethernet.
pub const ARP_LEN: usize = 28;

/// ARP operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArpOp {
    /// Who has `target_ip`?
    Request,
    /// `sender_ip` is at `sender_mac`.
    Reply,
}

/// An ARP packet (Ethernet/IPv4 only; others are refused by [`ArpPacket::parse`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ArpPacket {
    /// Request or reply.
    pub op: ArpOp,
    /// Sender hardware address.
    pub sender_mac: MacAddr,
    /// Sender protocol address (0.0.0.0 in a probe).
    pub sender_ip: Ipv4Addr,
    /// Target hardware address.
    pub target_mac: MacAddr,
    /// Target protocol address.
    pub target_ip: Ipv4Addr,
}

impl ArpPacket {
    /// Parses an ARP payload; `None` if it is short or not Ethernet/IPv4.
    pub fn parse(b: &[u8]) -> Option<ArpPacket> {
        let h = b.get(..ARP_LEN)?;
        if h.get(0..6)? != [0, 1, 0x08, 0x00, 6, 4] {
            return None;
        }
        let op = match h.get(6..8)? {
            [0, 1] => ArpOp::Request,
            [0, 2] => ArpOp::Reply,
            _ => return None,
        };
        let mac = |at: usize| -> Option<MacAddr> {
            let mut m = [0u8; 6];
            m.copy_from_slice(h.get(at..at + 6)?);
            Some(MacAddr(m))
        };
        let ip = |at: usize| -> Option<Ipv4Addr> {
            let mut a = [0u8; 4];
            a.copy_from_slice(h.get(at..at + 4)?);
            Some(Ipv4Addr::from(a))
        };
        Some(ArpPacket {
            op,
            sender_mac: mac(8)?,
            sender_ip: ip(14)?,
            target_mac: mac(18)?,
            target_ip: ip(24)?,
        })
    }

    /// Writes the packet into `buf` (at least [`ARP_LEN`] bytes).
    pub fn emit(&self, buf: &mut [u8]) -> Option<usize> {
        let h = buf.get_mut(..ARP_LEN)?;
        h.get_mut(0..6)?.copy_from_slice(&[0, 1, 0x08, 0x00, 6, 4]);
        let op: u16 = match self.op {
            ArpOp::Request => 1,
            ArpOp::Reply => 2,
        };
        h.get_mut(6..8)?.copy_from_slice(&op.to_be_bytes());
        h.get_mut(8..14)?.copy_from_slice(&self.sender_mac.0);
        h.get_mut(14..18)?.copy_from_slice(&self.sender_ip.octets());
        h.get_mut(18..24)?.copy_from_slice(&self.target_mac.0);
        h.get_mut(24..28)?.copy_from_slice(&self.target_ip.octets());
        Some(ARP_LEN)
    }

    /// An RFC 5227 probe (sender IP 0.0.0.0) from a host checking `target_ip`.
    pub fn is_probe(&self) -> bool {
        self.op == ArpOp::Request && self.sender_ip == Ipv4Addr::UNSPECIFIED
    }
}
