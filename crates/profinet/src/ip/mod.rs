//! ARP, IPv4, ICMP echo and UDP for the RPC server: a minimal, checked,
//! panic-free path of our own (no smoltcp: its reachable panic sites fail the
//! board image gate, and the device needs only these four things).
//!
//! [`Stack::receive`] takes one Ethernet frame and either answers it itself
//! (ARP request for our address, ICMP echo: the reply frame is written into
//! `tx`), hands a UDP datagram up ([`Received::Rpc`] for port 34964,
//! [`Received::Udp`] for any other port), or drops it with a reason that is
//! also counted in [`Counters`]. [`Stack::emit_udp`] frames a UDP payload the
//! caller has written at [`UDP_PAYLOAD_OFFSET`].
//!
//! Not done here, by design: IP fragment reassembly (fragments are dropped and
//! counted), IP options on transmit, routing beyond "same subnet or gateway".

mod arp;
mod ipv4;
mod neighbour;
#[cfg(test)]
mod tests;

pub use arp::{ArpOp, ArpPacket, ARP_LEN};
pub use ipv4::{
    emit_echo_reply, emit_ipv4, emit_udp, fold, icmp_type, sum16, Ipv4Error, Ipv4Packet, UdpError, UdpPacket,
    ICMP_ECHO_REPLY, ICMP_ECHO_REQUEST, IPV4_HEADER_LEN, PROTO_ICMP, PROTO_UDP, TTL, UDP_HEADER_LEN,
};
pub use neighbour::{NeighbourCache, NEIGHBOUR_TTL};

use crate::wire::{self, ethertype, EthFrame, MacAddr};
use nanos::Nanos;

/// The PROFINET RPC port (0x8894), where controller and device both listen.
pub const RPC_PORT: u16 = 34964;
/// Where a UDP payload starts in an untagged frame built by [`Stack::emit_udp`].
pub const UDP_PAYLOAD_OFFSET: usize = wire::HEADER_LEN + IPV4_HEADER_LEN + UDP_HEADER_LEN;
/// Entries of the neighbour cache.
pub const NEIGHBOURS: usize = 4;

/// An IPv4 address (the one `core::net` type DCP, LLDP and IP share).
pub use core::net::Ipv4Addr;

/// The interface's addresses (set by DCP or from the stored static IP).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IpConfig {
    /// Our IP address; 0.0.0.0 = none (then only ARP probes are watched).
    pub addr: Ipv4Addr,
    /// Subnet mask.
    pub netmask: Ipv4Addr,
    /// Default gateway; 0.0.0.0 = none.
    pub gateway: Ipv4Addr,
}

impl Default for IpConfig {
    /// No address.
    fn default() -> Self {
        IpConfig {
            addr: Ipv4Addr::UNSPECIFIED,
            netmask: Ipv4Addr::UNSPECIFIED,
            gateway: Ipv4Addr::UNSPECIFIED,
        }
    }
}

impl IpConfig {
    fn same_subnet(&self, ip: Ipv4Addr) -> bool {
        let m = u32::from(self.netmask);
        u32::from(ip) & m == u32::from(self.addr) & m
    }

    fn is_subnet_broadcast(&self, ip: Ipv4Addr) -> bool {
        let m = u32::from(self.netmask);
        m != 0 && m != u32::MAX && u32::from(ip) == (u32::from(self.addr) | !m)
    }
}

/// Where a UDP datagram came from / goes to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Endpoint {
    /// IP address.
    pub ip: Ipv4Addr,
    /// UDP port.
    pub port: u16,
}

/// A UDP datagram addressed to us.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UdpDatagram<'a> {
    /// Sender's MAC (the controller's, for the AR check of the CM).
    pub src_mac: MacAddr,
    /// Sender.
    pub src: Endpoint,
    /// Destination port (our port).
    pub dst_port: u16,
    /// The payload.
    pub payload: &'a [u8],
}

/// Why a frame was dropped. Each variant has its counter in [`Counters`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DropReason {
    /// Not ARP or IPv4.
    NotIp,
    /// ARP that is malformed, not for us, or a reply we did not need.
    ArpIgnored,
    /// IPv4 header refused (short, version, header length).
    Ipv4Malformed,
    /// IPv4 header checksum wrong.
    Ipv4Checksum,
    /// Addressed to another host.
    NotForUs,
    /// A fragment (no reassembly).
    Fragment,
    /// A protocol other than ICMP/UDP, or ICMP other than echo request.
    Unsupported,
    /// ICMP checksum wrong or message short.
    IcmpMalformed,
    /// UDP short or checksum wrong.
    UdpMalformed,
    /// The reply did not fit `tx`.
    TxTooSmall,
    /// We have no IP address yet.
    NoAddress,
}

/// What [`Stack::receive`] did with a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Received<'a> {
    /// Answered: a reply frame of this many bytes is in `tx`.
    Replied(usize),
    /// Consumed without a reply (e.g. an ARP reply we learned from).
    Consumed,
    /// A datagram for the RPC port.
    Rpc(UdpDatagram<'a>),
    /// A datagram for another UDP port (the caller may serve it or drop it).
    Udp(UdpDatagram<'a>),
    /// Dropped, counted.
    Dropped(DropReason),
}

/// Events of the address conflict detection.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// ARP requests for our address answered.
    pub arp_replies: u32,
    /// ARP packets from another host claiming our address (conflicts).
    pub arp_conflicts: u32,
    /// ICMP echo requests answered.
    pub echo_replies: u32,
    /// UDP datagrams handed up.
    pub udp_in: u32,
    /// UDP datagrams framed by [`Stack::emit_udp`].
    pub udp_out: u32,
    /// Dropped: not ARP/IPv4.
    pub not_ip: u32,
    /// Dropped: ARP ignored.
    pub arp_ignored: u32,
    /// Dropped: IPv4 malformed.
    pub ipv4_malformed: u32,
    /// Dropped: IPv4 checksum.
    pub ipv4_checksum: u32,
    /// Dropped: not for us.
    pub not_for_us: u32,
    /// Dropped: IP fragments.
    pub fragments: u32,
    /// Dropped: unsupported protocol or ICMP type.
    pub unsupported: u32,
    /// Dropped: ICMP malformed.
    pub icmp_malformed: u32,
    /// Dropped: UDP malformed.
    pub udp_malformed: u32,
    /// Dropped: reply did not fit.
    pub tx_too_small: u32,
    /// Dropped: no address configured.
    pub no_address: u32,
}

impl Counters {
    fn count(&mut self, d: DropReason) {
        let c = match d {
            DropReason::NotIp => &mut self.not_ip,
            DropReason::ArpIgnored => &mut self.arp_ignored,
            DropReason::Ipv4Malformed => &mut self.ipv4_malformed,
            DropReason::Ipv4Checksum => &mut self.ipv4_checksum,
            DropReason::NotForUs => &mut self.not_for_us,
            DropReason::Fragment => &mut self.fragments,
            DropReason::Unsupported => &mut self.unsupported,
            DropReason::IcmpMalformed => &mut self.icmp_malformed,
            DropReason::UdpMalformed => &mut self.udp_malformed,
            DropReason::TxTooSmall => &mut self.tx_too_small,
            DropReason::NoAddress => &mut self.no_address,
        };
        *c = c.saturating_add(1);
    }
}

/// What [`Stack::emit_udp`] put into `tx`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UdpTx {
    /// The UDP frame, this many bytes.
    Frame(usize),
    /// The destination's MAC is unknown: an ARP request of this many bytes is in
    /// `tx` instead; send it and retry the datagram later.
    ArpRequest(usize),
}

/// Why [`Stack::emit_udp`] produced nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TxError {
    /// We have no IP address.
    NoAddress,
    /// Off-subnet destination and no gateway.
    NoRoute,
    /// `tx` too small, or the payload longer than a datagram.
    TooLong,
}

/// The IP side of one interface: addresses, neighbour cache, counters.
#[derive(Clone, Debug)]
pub struct Stack {
    mac: MacAddr,
    config: IpConfig,
    neighbours: NeighbourCache<NEIGHBOURS>,
    counters: Counters,
    ident: u16,
    conflict: bool,
}

impl Stack {
    /// A stack for the interface MAC `mac` with addresses `config`.
    pub fn new(mac: MacAddr, config: IpConfig) -> Stack {
        Stack {
            mac,
            config,
            neighbours: NeighbourCache::default(),
            counters: Counters::default(),
            ident: 0,
            conflict: false,
        }
    }

    /// The current addresses.
    pub fn config(&self) -> IpConfig {
        self.config
    }

    /// Changes the addresses (DCP Set); clears the neighbour cache and the
    /// conflict flag. Follow with [`Stack::emit_gratuitous_arp`].
    pub fn set_config(&mut self, config: IpConfig) {
        self.config = config;
        self.neighbours.clear();
        self.conflict = false;
    }

    /// The interface MAC.
    pub fn mac(&self) -> MacAddr {
        self.mac
    }

    /// Counters since start.
    pub fn counters(&self) -> &Counters {
        &self.counters
    }

    /// True once another host was seen using our IP address (DCP reports it
    /// in the IP block info); cleared by [`Stack::set_config`].
    pub fn address_conflict(&self) -> bool {
        self.conflict
    }

    /// The MAC cached for `ip`.
    pub fn neighbour(&self, now: Nanos, ip: Ipv4Addr) -> Option<MacAddr> {
        self.neighbours.lookup(now, ip)
    }

    /// Records a neighbour learned elsewhere (e.g. the CM initiator MAC).
    pub fn learn(&mut self, now: Nanos, ip: Ipv4Addr, mac: MacAddr) {
        self.neighbours.learn(now, ip, mac);
    }

    fn drop_(&mut self, d: DropReason) -> Received<'static> {
        self.counters.count(d);
        Received::Dropped(d)
    }

    /// Handles one received Ethernet frame (without FCS). Replies go into `tx`.
    pub fn receive<'a>(&mut self, now: Nanos, frame: &'a [u8], tx: &mut [u8]) -> Received<'a> {
        let Some(eth) = EthFrame::parse(frame) else {
            return self.drop_(DropReason::NotIp);
        };
        match eth.ethertype {
            ethertype::ARP => self.receive_arp(now, &eth, tx),
            ethertype::IPV4 => self.receive_ipv4(now, &eth, tx),
            _ => self.drop_(DropReason::NotIp),
        }
    }

    fn receive_arp(&mut self, now: Nanos, eth: &EthFrame<'_>, tx: &mut [u8]) -> Received<'static> {
        let Some(arp) = ArpPacket::parse(eth.payload) else {
            return self.drop_(DropReason::ArpIgnored);
        };
        let ours = self.config.addr;
        if ours == Ipv4Addr::UNSPECIFIED {
            return self.drop_(DropReason::NoAddress);
        }
        if arp.sender_ip == ours && arp.sender_mac != self.mac {
            // Someone else uses our address (RFC 5227 conflict).
            self.conflict = true;
            self.counters.arp_conflicts = self.counters.arp_conflicts.saturating_add(1);
        } else if arp.target_ip == ours || arp.sender_ip != Ipv4Addr::UNSPECIFIED {
            self.neighbours.learn(now, arp.sender_ip, arp.sender_mac);
        }
        if arp.op != ArpOp::Request || arp.target_ip != ours {
            return if arp.op == ArpOp::Reply {
                Received::Consumed
            } else {
                self.drop_(DropReason::ArpIgnored)
            };
        }
        let reply = ArpPacket {
            op: ArpOp::Reply,
            sender_mac: self.mac,
            sender_ip: ours,
            target_mac: arp.sender_mac,
            target_ip: arp.sender_ip,
        };
        // A probe (sender 0.0.0.0) is answered too: that defends our address.
        let dst = if arp.is_probe() {
            MacAddr::BROADCAST
        } else {
            arp.sender_mac
        };
        match self.frame_arp(tx, dst, eth.vlan_tci, &reply) {
            Some(n) => {
                self.counters.arp_replies = self.counters.arp_replies.saturating_add(1);
                Received::Replied(n)
            }
            None => self.drop_(DropReason::TxTooSmall),
        }
    }

    fn frame_arp(&self, tx: &mut [u8], dst: MacAddr, vlan: Option<u16>, arp: &ArpPacket) -> Option<usize> {
        let h = wire::emit_header(tx, dst, self.mac, vlan, ethertype::ARP)?;
        let n = arp.emit(tx.get_mut(h..)?)?;
        pad(tx, h + n)
    }

    /// Writes a gratuitous ARP announcement of our address into `tx` (send
    /// after an address was set); `None` without an address or room.
    pub fn emit_gratuitous_arp(&self, tx: &mut [u8]) -> Option<usize> {
        if self.config.addr == Ipv4Addr::UNSPECIFIED {
            return None;
        }
        let arp = ArpPacket {
            op: ArpOp::Request,
            sender_mac: self.mac,
            sender_ip: self.config.addr,
            target_mac: MacAddr::default(),
            target_ip: self.config.addr,
        };
        self.frame_arp(tx, MacAddr::BROADCAST, None, &arp)
    }

    fn receive_ipv4<'a>(&mut self, now: Nanos, eth: &EthFrame<'a>, tx: &mut [u8]) -> Received<'a> {
        let ip = match Ipv4Packet::parse(eth.payload) {
            Ok(ip) => ip,
            Err(Ipv4Error::Checksum) => return self.drop_(DropReason::Ipv4Checksum),
            Err(_) => return self.drop_(DropReason::Ipv4Malformed),
        };
        let ours = self.config.addr;
        if ours == Ipv4Addr::UNSPECIFIED {
            return self.drop_(DropReason::NoAddress);
        }
        let unicast = ip.dst == ours;
        let broadcast = ip.dst == Ipv4Addr::BROADCAST || self.config.is_subnet_broadcast(ip.dst);
        if !unicast && !broadcast {
            return self.drop_(DropReason::NotForUs);
        }
        if ip.is_fragment {
            return self.drop_(DropReason::Fragment);
        }
        if unicast && self.config.same_subnet(ip.src) {
            self.neighbours.learn(now, ip.src, eth.src);
        }
        match ip.protocol {
            PROTO_ICMP if unicast => self.receive_icmp(eth, &ip, tx),
            PROTO_UDP => match UdpPacket::parse(ip.payload, ip.src, ip.dst) {
                Ok(udp) => {
                    self.counters.udp_in = self.counters.udp_in.saturating_add(1);
                    let d = UdpDatagram {
                        src_mac: eth.src,
                        src: Endpoint {
                            ip: ip.src,
                            port: udp.src_port,
                        },
                        dst_port: udp.dst_port,
                        payload: udp.payload,
                    };
                    if udp.dst_port == RPC_PORT {
                        Received::Rpc(d)
                    } else {
                        Received::Udp(d)
                    }
                }
                Err(_) => self.drop_(DropReason::UdpMalformed),
            },
            _ => self.drop_(DropReason::Unsupported),
        }
    }

    fn receive_icmp(&mut self, eth: &EthFrame<'_>, ip: &Ipv4Packet<'_>, tx: &mut [u8]) -> Received<'static> {
        match icmp_type(ip.payload) {
            None => return self.drop_(DropReason::IcmpMalformed),
            Some(ICMP_ECHO_REQUEST) => {}
            Some(_) => return self.drop_(DropReason::Unsupported),
        }
        let ident = self.next_ident();
        let n = (|| {
            let h = wire::emit_header(tx, eth.src, self.mac, eth.vlan_tci, ethertype::IPV4)?;
            let body = tx.get_mut(h + IPV4_HEADER_LEN..)?;
            let n = emit_echo_reply(body, ip.payload)?;
            emit_ipv4(tx.get_mut(h..)?, self.config.addr, ip.src, PROTO_ICMP, ident, n)?;
            pad(tx, h + IPV4_HEADER_LEN + n)
        })();
        match n {
            Some(n) => {
                self.counters.echo_replies = self.counters.echo_replies.saturating_add(1);
                Received::Replied(n)
            }
            None => self.drop_(DropReason::TxTooSmall),
        }
    }

    fn next_ident(&mut self) -> u16 {
        self.ident = self.ident.wrapping_add(1);
        self.ident
    }

    /// Frames a UDP datagram whose `payload_len` payload bytes the caller has
    /// already written at `tx[UDP_PAYLOAD_OFFSET..]`, from our `src_port` to
    /// `dst`. The next hop's MAC comes from the neighbour cache; when it is
    /// unknown an ARP request replaces the datagram in `tx` ([`UdpTx::ArpRequest`]).
    pub fn emit_udp(
        &mut self,
        now: Nanos,
        tx: &mut [u8],
        src_port: u16,
        dst: Endpoint,
        payload_len: usize,
    ) -> Result<UdpTx, TxError> {
        let ours = self.config.addr;
        if ours == Ipv4Addr::UNSPECIFIED {
            return Err(TxError::NoAddress);
        }
        let hop = if self.config.same_subnet(dst.ip) {
            dst.ip
        } else if self.config.gateway != Ipv4Addr::UNSPECIFIED {
            self.config.gateway
        } else {
            return Err(TxError::NoRoute);
        };
        let Some(mac) = self.neighbours.lookup(now, hop) else {
            let arp = ArpPacket {
                op: ArpOp::Request,
                sender_mac: self.mac,
                sender_ip: ours,
                target_mac: MacAddr::default(),
                target_ip: hop,
            };
            return self
                .frame_arp(tx, MacAddr::BROADCAST, None, &arp)
                .map(UdpTx::ArpRequest)
                .ok_or(TxError::TooLong);
        };
        let ident = self.next_ident();
        let n = (|| {
            let h = wire::emit_header(tx, mac, self.mac, None, ethertype::IPV4)?;
            let ip_at = h;
            let udp_at = ip_at + IPV4_HEADER_LEN;
            emit_udp(
                tx.get_mut(udp_at..)?,
                (ours, src_port),
                (dst.ip, dst.port),
                payload_len,
            )?;
            emit_ipv4(
                tx.get_mut(ip_at..)?,
                ours,
                dst.ip,
                PROTO_UDP,
                ident,
                payload_len.checked_add(UDP_HEADER_LEN)?,
            )?;
            pad(tx, udp_at + UDP_HEADER_LEN + payload_len)
        })();
        match n {
            Some(n) => {
                self.counters.udp_out = self.counters.udp_out.saturating_add(1);
                Ok(UdpTx::Frame(n))
            }
            None => Err(TxError::TooLong),
        }
    }
}

/// Zero-pads a frame of `len` bytes to the Ethernet minimum; returns the new length.
fn pad(tx: &mut [u8], len: usize) -> Option<usize> {
    if len >= wire::MIN_FRAME_LEN {
        return Some(len);
    }
    tx.get_mut(len..wire::MIN_FRAME_LEN)?.fill(0);
    Some(wire::MIN_FRAME_LEN)
}
