//! Bus input at the IP stack: frames the master tunnels over EoE (E-095) that
//! are malformed, truncated or hostile, built byte by byte here (not with
//! smoltcp's emitters, which only make well-formed ones). Each is dropped or
//! answered as RFC 826/791/792/768 say, and the stack answers ping afterwards.
//! These are the inputs that reach the code paths firmware/patches/smoltcp made
//! panic-free (length fields beyond the frame, the neighbour cache when full,
//! ICMP errors carrying a truncated header, the port-unreachable answer).
#![allow(clippy::unwrap_used, clippy::indexing_slicing, missing_docs)]

use drive_ecat::dictionary::DriveObjects;
use ecat::eoe::{EthernetPort, IpParams};
use ecat::eoe_queue::EoeQueue;
use nanos::Nanos;
use net::smoltcp::iface::SocketStorage;
use net::{NetBuffers, NetConfig, NetSettings, NetStack, SOCKETS};
use od::CommState;

const DRIVE_MAC: [u8; 6] = [0x02, 0x5C, 0x06, 0, 0, 1];
const DRIVE_IP: [u8; 4] = [192, 168, 10, 2];
const HOST_MAC: [u8; 6] = [0x02, 0, 0, 0, 0, 0x10];
const HOST_IP: [u8; 4] = [192, 168, 10, 1];

fn checksum(data: &[u8]) -> u16 {
    let mut sum = 0u32;
    for c in data.chunks(2) {
        let w = u16::from_be_bytes([c[0], *c.get(1).unwrap_or(&0)]);
        sum += u32::from(w);
    }
    while sum > 0xFFFF {
        sum = (sum & 0xFFFF) + (sum >> 16);
    }
    !(sum as u16)
}

fn eth(dst: [u8; 6], src: [u8; 6], ethertype: u16, payload: &[u8]) -> Vec<u8> {
    let mut f = Vec::new();
    f.extend_from_slice(&dst);
    f.extend_from_slice(&src);
    f.extend_from_slice(&ethertype.to_be_bytes());
    f.extend_from_slice(payload);
    f
}

/// An IPv4 packet; `edit` may change the header before its checksum.
fn ipv4(src: [u8; 4], dst: [u8; 4], proto: u8, payload: &[u8], edit: impl FnOnce(&mut [u8])) -> Vec<u8> {
    let mut h = vec![0u8; 20];
    h[0] = 0x45;
    h[2..4].copy_from_slice(&((20 + payload.len()) as u16).to_be_bytes());
    h[6] = 0x40; // don't fragment
    h[8] = 64;
    h[9] = proto;
    h[12..16].copy_from_slice(&src);
    h[16..20].copy_from_slice(&dst);
    edit(&mut h);
    let c = checksum(&h);
    h[10..12].copy_from_slice(&c.to_be_bytes());
    h.extend_from_slice(payload);
    h
}

/// An IPv4 packet of protocol `proto` from the host to the drive, in its
/// Ethernet frame.
fn to_drive(proto: u8, payload: &[u8]) -> Vec<u8> {
    eth(
        DRIVE_MAC,
        HOST_MAC,
        0x0800,
        &ipv4(HOST_IP, DRIVE_IP, proto, payload, |_| {}),
    )
}

fn icmp(kind: u8, code: u8, rest: [u8; 4], data: &[u8]) -> Vec<u8> {
    let mut m = vec![kind, code, 0, 0];
    m.extend_from_slice(&rest);
    m.extend_from_slice(data);
    let c = checksum(&m);
    m[2..4].copy_from_slice(&c.to_be_bytes());
    m
}

/// A UDP datagram without checksum (0: none, RFC 768), `len` its length field.
fn udp(sport: u16, dport: u16, len: u16, payload: &[u8]) -> Vec<u8> {
    let mut d = Vec::new();
    d.extend_from_slice(&sport.to_be_bytes());
    d.extend_from_slice(&dport.to_be_bytes());
    d.extend_from_slice(&len.to_be_bytes());
    d.extend_from_slice(&[0, 0]);
    d.extend_from_slice(payload);
    d
}

fn arp(op: u16, sha: [u8; 6], spa: [u8; 4], tha: [u8; 6], tpa: [u8; 4]) -> Vec<u8> {
    let mut a = vec![0, 1, 8, 0, 6, 4];
    a.extend_from_slice(&op.to_be_bytes());
    a.extend_from_slice(&sha);
    a.extend_from_slice(&spa);
    a.extend_from_slice(&tha);
    a.extend_from_slice(&tpa);
    a
}

/// Runs `body` on a rig with an IP address whose neighbour cache knows the
/// host (an ARP request from it answered).
fn with_host<T>(body: impl FnOnce(&mut Rig<'_>) -> T) -> T {
    let mut bufs = NetBuffers::new();
    let mut slots = [SocketStorage::EMPTY; SOCKETS];
    let mut r = Rig::new(&mut bufs, &mut slots);
    r.arp_from(HOST_MAC, HOST_IP);
    body(&mut r)
}

struct Rig<'a> {
    q: EoeQueue,
    net: NetStack<'a>,
    d: DriveObjects,
    t_us: u64,
}

impl<'a> Rig<'a> {
    /// With the address the master set over EoE (E-096).
    fn new(bufs: &'a mut NetBuffers, slots: &'a mut [SocketStorage<'a>; SOCKETS]) -> Self {
        let mut rig = Self::without_ip(bufs, slots);
        rig.set_ip();
        rig
    }

    /// Without an address yet (for DHCP).
    fn without_ip(bufs: &'a mut NetBuffers, slots: &'a mut [SocketStorage<'a>; SOCKETS]) -> Self {
        let mut q = EoeQueue::new();
        let cfg = NetConfig {
            mac: DRIVE_MAC,
            seed: 7,
        };
        let net = NetStack::new(cfg, bufs, slots, &mut q, Nanos::ZERO);
        Rig {
            q,
            net,
            d: DriveObjects::new(),
            t_us: 1,
        }
    }

    /// The master sets the drive's address over EoE (E-096).
    fn set_ip(&mut self) {
        let p = IpParams {
            ip: Some(DRIVE_IP),
            mask: Some([255, 255, 255, 0]),
            ..IpParams::default()
        };
        self.q.ip_changed(&p);
        self.poll();
        assert_eq!(self.net.ip(), Some((DRIVE_IP, 24)));
    }

    fn poll(&mut self) -> Vec<Vec<u8>> {
        self.poll_with(&NetSettings {
            tunnel_open: true,
            ..NetSettings::default()
        })
    }

    fn poll_with(&mut self, s: &NetSettings) -> Vec<Vec<u8>> {
        self.t_us += 1_000;
        let now = Nanos::from_us(self.t_us);
        self.net.poll(now, &mut self.q, &mut self.d, CommState::PreOp, s);
        let mut out = Vec::new();
        let mut buf = [0u8; 1536];
        while let Some(n) = self.q.transmit(&mut buf) {
            out.push(buf[..n].to_vec());
            self.net.poll(now, &mut self.q, &mut self.d, CommState::PreOp, s);
        }
        out
    }

    /// `frame` in from the master; what the stack sends back.
    fn send(&mut self, frame: &[u8]) -> Vec<Vec<u8>> {
        self.q.receive(frame);
        self.poll()
    }

    /// The host's ARP request for the drive (fills the drive's neighbour
    /// cache with `ip`); the reply it gets.
    fn arp_from(&mut self, mac: [u8; 6], ip: [u8; 4]) -> Vec<Vec<u8>> {
        let a = arp(1, mac, ip, [0; 6], DRIVE_IP);
        self.send(&eth([0xFF; 6], mac, 0x0806, &a))
    }

    /// Echo request from the host; the echo reply's payload if one came.
    fn ping(&mut self, seq: u16, data: &[u8]) -> Option<Vec<u8>> {
        let m = icmp(8, 0, [0x12, 0x34, (seq >> 8) as u8, seq as u8], data);
        let out = self.send(&to_drive(1, &m));
        out.iter().find_map(|f| {
            let ip = &f[14..];
            let icmp = &ip[20..];
            (f[12..14] == [8, 0] && ip[9] == 1 && icmp[0] == 0 && icmp[6..8] == seq.to_be_bytes())
                .then(|| icmp[8..].to_vec())
        })
    }
}

#[test]
fn e095_e096_hostile_frames_are_dropped_and_ping_still_answers() {
    let mut bufs = NetBuffers::new();
    let mut slots = [SocketStorage::EMPTY; SOCKETS];
    let mut r = Rig::new(&mut bufs, &mut slots);
    let reply = r.arp_from(HOST_MAC, HOST_IP);
    assert_eq!(reply.len(), 1, "ARP reply");
    assert_eq!(&reply[0][12..14], &[8, 6]);
    assert_eq!(&reply[0][14 + 14..14 + 18], &DRIVE_IP, "sender protocol address");
    assert_eq!(r.ping(1, b"before").as_deref(), Some(&b"before"[..]));

    let valid_arp = arp(1, HOST_MAC, HOST_IP, [0; 6], DRIVE_IP);
    let mut odd_lengths = valid_arp.clone();
    odd_lengths[4] = 255; // hardware address length
    odd_lengths[5] = 255; // protocol address length
    let m = icmp(8, 0, [0, 1, 0, 9], b"payload");
    let hostile: Vec<(&str, Vec<u8>)> = vec![
        ("empty frame", vec![]),
        ("Ethernet header cut short", DRIVE_MAC[..5].to_vec()),
        (
            "ARP cut after the sender's address",
            eth(DRIVE_MAC, HOST_MAC, 0x0806, &valid_arp[..20]),
        ),
        (
            "ARP with address lengths 255/255",
            eth(DRIVE_MAC, HOST_MAC, 0x0806, &odd_lengths),
        ),
        (
            "IPv4 header length 60 in a 20-byte packet",
            eth(
                DRIVE_MAC,
                HOST_MAC,
                0x0800,
                &ipv4(HOST_IP, DRIVE_IP, 1, &m, |h| {
                    h[0] = 0x4F;
                    h[2..4].copy_from_slice(&20u16.to_be_bytes());
                }),
            ),
        ),
        (
            "IPv4 total length beyond the frame",
            eth(
                DRIVE_MAC,
                HOST_MAC,
                0x0800,
                &ipv4(HOST_IP, DRIVE_IP, 1, &m, |h| {
                    h[2..4].copy_from_slice(&1400u16.to_be_bytes())
                }),
            ),
        ),
        (
            "IPv4 header length below 20",
            eth(
                DRIVE_MAC,
                HOST_MAC,
                0x0800,
                &ipv4(HOST_IP, DRIVE_IP, 1, &m, |h| h[0] = 0x41),
            ),
        ),
        (
            "UDP length 65535 in a short datagram",
            to_drive(17, &udp(5000, 6000, 0xFFFF, b"R A150")),
        ),
        (
            "UDP length below its header",
            to_drive(17, &udp(5000, 6000, 3, b"R A150")),
        ),
        (
            "ICMP destination unreachable with 8 bytes of the original header",
            to_drive(1, &icmp(3, 3, [0; 4], &[0x45, 0, 0, 28, 0, 0, 0, 0])),
        ),
        (
            "ICMP time exceeded with an original header of length 60 and 20 bytes",
            to_drive(
                1,
                &icmp(11, 0, [0; 4], &ipv4(DRIVE_IP, HOST_IP, 17, &[], |h| h[0] = 0x4F)),
            ),
        ),
        (
            "a full-size frame of 0xFF after an IPv4 Ethernet header",
            eth(DRIVE_MAC, HOST_MAC, 0x0800, &[0xFF; 1500]),
        ),
    ];
    for (i, (what, frame)) in hostile.iter().enumerate() {
        let out = r.send(frame);
        assert!(out.is_empty(), "{what}: no answer, got {out:02X?}");
        let seq = 100 + i as u16;
        assert_eq!(
            r.ping(seq, b"after").as_deref(),
            Some(&b"after"[..]),
            "ping after {what}"
        );
    }
    assert_eq!(r.net.ip(), Some((DRIVE_IP, 24)), "the address stays");
    assert_eq!(r.q.stats().rx_overflow, 0);
}

#[test]
fn e095_udp_to_a_closed_port_gets_port_unreachable_with_the_header() {
    with_host(|r| {
        let dgram = ipv4(HOST_IP, DRIVE_IP, 17, &udp(5000, 9, 12, b"test"), |_| {});
        let out = r.send(&eth(DRIVE_MAC, HOST_MAC, 0x0800, &dgram));
        assert_eq!(out.len(), 1, "one ICMP error");
        let ip = &out[0][14..];
        assert_eq!(ip[9], 1, "ICMP");
        assert_eq!(&ip[16..20], &HOST_IP);
        let m = &ip[20..];
        assert_eq!((m[0], m[1]), (3, 3), "destination unreachable, port unreachable");
        assert_eq!(checksum(m), 0, "ICMP checksum");
        assert_eq!(checksum(&ip[..20]), 0, "IPv4 header checksum");
        // RFC 792: the original IP header and the first 8 bytes of its data
        assert_eq!(&m[8..8 + 28], &dgram[..28]);
    });
}

#[test]
fn e095_large_echo_request_is_answered_whole() {
    with_host(|r| {
        let data: Vec<u8> = (0..1472u32).map(|i| (i * 7) as u8).collect();
        assert_eq!(r.ping(1, &data), Some(data));
    });
}

#[test]
fn e095_arp_flood_replaces_the_oldest_neighbour() {
    with_host(|r| {
        assert!(r.ping(1, b"x").is_some());
        // more neighbours than the cache holds (smoltcp's default: 8)
        for n in 0..24u8 {
            let out = r.arp_from([0x02, 0, 0, 0, 1, n], [192, 168, 10, 100 + n]);
            assert_eq!(out.len(), 1, "ARP reply to neighbour {n}");
            assert_eq!(&out[0][0..6], &[0x02, 0, 0, 0, 1, n]);
        }
        // the host's entry was the oldest: the drive asks for it before answering
        let m = icmp(8, 0, [0x12, 0x34, 0, 2], b"y");
        let out = r.send(&to_drive(1, &m));
        assert_eq!(out.len(), 1);
        assert_eq!(&out[0][12..14], &[8, 6], "an ARP request");
        assert_eq!(&out[0][14 + 24..14 + 28], &HOST_IP, "for the host");
        // once the host has answered, ping works again
        let reply = arp(2, HOST_MAC, HOST_IP, DRIVE_MAC, DRIVE_IP);
        assert!(r.send(&eth(DRIVE_MAC, HOST_MAC, 0x0806, &reply)).is_empty());
        assert_eq!(r.ping(3, b"z").as_deref(), Some(&b"z"[..]));
    });
}

/// E-098 with a server whose renewal time T1 (7200 s) is beyond its lease
/// (3600 s): the lease is taken (with the default T1/T2). crates.io's smoltcp 0.12.0 panics
/// on this ACK (`lease - T1` underflows, "overflow when subtracting
/// durations"); the firmware's smoltcp has the fix, so the test runs only
/// against it (`scripts/cross smoltcp-test`).
#[cfg(feature = "patched-smoltcp")]
#[test]
fn e098_dhcp_ack_with_renewal_time_beyond_the_lease_is_taken() {
    use net::smoltcp::wire::{DhcpMessageType, DhcpOption, DhcpPacket, DhcpRepr};
    use net::testing::DhcpLease;
    let mut bufs = NetBuffers::new();
    let mut slots = [SocketStorage::EMPTY; SOCKETS];
    let mut r = Rig::without_ip(&mut bufs, &mut slots);
    let s = NetSettings {
        dhcp: true,
        tunnel_open: true,
        ..NetSettings::default()
    };
    let offered = [192, 168, 10, 50];
    let t1 = 7200u32.to_be_bytes();
    let options = [DhcpOption {
        kind: 58, // renewal time value
        data: &t1,
    }];
    let lease = DhcpLease {
        server: HOST_IP,
        offer: offered,
        mask: [255, 255, 255, 0],
        router: None,
        options: &options,
    };
    let mut answered = Vec::new();
    for _ in 0..20_000 {
        for f in r.poll_with(&s) {
            // a DHCP client message: UDP 68 -> 67 in IPv4 in Ethernet
            if f[12..14] != [8, 0] || f[14 + 9] != 17 || f[14 + 22..14 + 24] != [0, 67] {
                continue;
            }
            let pkt = DhcpPacket::new_checked(&f[14 + 28..]).unwrap();
            let req = DhcpRepr::parse(&pkt).unwrap();
            let mut buf = [0u8; 576];
            let Some((kind, dhcp)) = lease.answer(&req, &mut buf) else {
                continue;
            };
            let dgram = udp(67, 68, (8 + dhcp.len()) as u16, dhcp);
            let frame = eth(
                [0xFF; 6],
                HOST_MAC,
                0x0800,
                &ipv4(HOST_IP, [255; 4], 17, &dgram, |_| {}),
            );
            r.q.receive(&frame);
            answered.push(kind);
        }
        if r.net.ip().is_some() {
            break;
        }
    }
    assert_eq!(answered, [DhcpMessageType::Offer, DhcpMessageType::Ack]);
    assert_eq!(r.net.ip(), Some((offered, 24)));
    assert!(r.net.address_from_dhcp());
}
