use super::*;
use std::vec::Vec;

const OUR_MAC: MacAddr = MacAddr([0x02, 0, 0, 0, 0, 0x01]);
const PEER_MAC: MacAddr = MacAddr([0x02, 0, 0, 0, 0, 0xC0]);
const OUR_IP: Ipv4Addr = Ipv4Addr::new(192, 168, 0, 50);
const PEER_IP: Ipv4Addr = Ipv4Addr::new(192, 168, 0, 10);

fn stack() -> Stack {
    Stack::new(
        OUR_MAC,
        IpConfig {
            addr: OUR_IP,
            netmask: Ipv4Addr::new(255, 255, 255, 0),
            gateway: Ipv4Addr::UNSPECIFIED,
        },
    )
}

fn hex(s: &str) -> Vec<u8> {
    let s: std::string::String = s.split_whitespace().collect();
    (0..s.len() / 2)
        .map(|i| u8::from_str_radix(&s[2 * i..2 * i + 2], 16).unwrap())
        .collect()
}

/// A Linux ARP request "who has 192.168.0.50 tell 192.168.0.10".
fn arp_request() -> Vec<u8> {
    hex(
        "ffffffffffff 0200000000c0 0806 0001 0800 06 04 0001 0200000000c0 c0a8000a 000000000000 c0a80032
         000000000000000000000000000000000000",
    )
}

#[test]
fn arp_request_for_our_address_is_answered() {
    let mut s = stack();
    let mut tx = [0u8; 128];
    let Received::Replied(n) = s.receive(Nanos::ZERO, &arp_request(), &mut tx) else {
        panic!()
    };
    assert_eq!(n, 60);
    assert_eq!(
        &tx[..42],
        &hex(
            "0200000000c0 020000000001 0806 0001 0800 0604 0002 020000000001 c0a80032 0200000000c0 c0a8000a"
        )[..]
    );
    assert_eq!(s.neighbour(Nanos::ZERO, PEER_IP), Some(PEER_MAC));
    assert_eq!(s.counters().arp_replies, 1);
}

#[test]
fn arp_for_another_host_is_ignored_and_conflicts_are_detected() {
    let mut s = stack();
    let mut tx = [0u8; 128];
    let mut other = arp_request();
    other[41] = 99;
    assert_eq!(
        s.receive(Nanos::ZERO, &other, &mut tx),
        Received::Dropped(DropReason::ArpIgnored)
    );
    // A gratuitous ARP from another MAC claiming our IP.
    let mut claim = arp_request();
    claim[28..32].copy_from_slice(&OUR_IP.octets());
    assert!(!s.address_conflict());
    s.receive(Nanos::ZERO, &claim, &mut tx);
    assert!(s.address_conflict());
    assert_eq!(s.counters().arp_conflicts, 1);
    // A probe for our address is answered (defended), broadcast.
    let mut probe = arp_request();
    probe[28..32].fill(0);
    let Received::Replied(_) = s.receive(Nanos::ZERO, &probe, &mut tx) else {
        panic!()
    };
    assert_eq!(&tx[..6], &[0xFF; 6]);
    // Our own announcement.
    let n = s.emit_gratuitous_arp(&mut tx).unwrap();
    let arp = ArpPacket::parse(&tx[14..n]).unwrap();
    assert_eq!(
        (arp.sender_ip, arp.target_ip, arp.op),
        (OUR_IP, OUR_IP, ArpOp::Request)
    );
}

/// `ping -c1 192.168.0.50` from Linux (id 0x1234, seq 1, 8 bytes of data).
fn echo_request() -> Vec<u8> {
    let mut f = hex("020000000001 0200000000c0 0800");
    let mut icmp = hex("08 00 0000 1234 0001 0102030405060708");
    let c = fold(sum16(0, &icmp));
    icmp[2..4].copy_from_slice(&c.to_be_bytes());
    let mut ip = [0u8; 20];
    emit_ipv4(&mut ip, PEER_IP, OUR_IP, PROTO_ICMP, 7, icmp.len()).unwrap();
    f.extend_from_slice(&ip);
    f.extend_from_slice(&icmp);
    f.resize(60, 0);
    f
}

#[test]
fn icmp_echo_is_answered() {
    let mut s = stack();
    let mut tx = [0u8; 128];
    let Received::Replied(n) = s.receive(Nanos::ZERO, &echo_request(), &mut tx) else {
        panic!()
    };
    let eth = EthFrame::parse(&tx[..n]).unwrap();
    assert_eq!((eth.dst, eth.src), (PEER_MAC, OUR_MAC));
    let ip = Ipv4Packet::parse(eth.payload).unwrap();
    assert_eq!((ip.src, ip.dst, ip.protocol), (OUR_IP, PEER_IP, PROTO_ICMP));
    assert_eq!(icmp_type(ip.payload), Some(ICMP_ECHO_REPLY));
    assert_eq!(&ip.payload[4..], &hex("1234 0001 0102030405060708")[..]);
}

#[test]
fn bad_checksums_and_fragments_are_dropped_and_counted() {
    let mut s = stack();
    let mut tx = [0u8; 128];
    let mut f = echo_request();
    f[14 + 10] ^= 1;
    assert_eq!(
        s.receive(Nanos::ZERO, &f, &mut tx),
        Received::Dropped(DropReason::Ipv4Checksum)
    );
    let mut f = echo_request();
    f[14 + 6] = 0x20; // MF
    f[14 + 10..14 + 12].fill(0);
    let c = fold(sum16(0, &f[14..34]));
    f[14 + 10..14 + 12].copy_from_slice(&c.to_be_bytes());
    assert_eq!(
        s.receive(Nanos::ZERO, &f, &mut tx),
        Received::Dropped(DropReason::Fragment)
    );
    assert_eq!(s.counters().fragments, 1);
    let mut f = echo_request();
    f[34 + 9] ^= 0xFF;
    assert_eq!(
        s.receive(Nanos::ZERO, &f, &mut tx),
        Received::Dropped(DropReason::IcmpMalformed)
    );
    for len in 0..60 {
        let _ = s.receive(Nanos::ZERO, &echo_request()[..len], &mut tx);
    }
    assert_eq!(
        s.receive(Nanos::ZERO, &echo_request(), &mut [0u8; 10]),
        Received::Dropped(DropReason::TxTooSmall)
    );
}

#[test]
fn udp_round_trip_through_the_rpc_port() {
    let mut s = stack();
    let mut tx = [0u8; 256];
    // Learn the peer, then frame a datagram to it.
    s.learn(Nanos::ZERO, PEER_IP, PEER_MAC);
    tx[UDP_PAYLOAD_OFFSET..UDP_PAYLOAD_OFFSET + 5].copy_from_slice(b"hello");
    let peer = Endpoint {
        ip: PEER_IP,
        port: 50000,
    };
    let UdpTx::Frame(n) = s.emit_udp(Nanos::ZERO, &mut tx, RPC_PORT, peer, 5).unwrap() else {
        panic!()
    };
    // Feed it back with the addresses swapped: a valid datagram for the peer.
    let mut s2 = Stack::new(
        PEER_MAC,
        IpConfig {
            addr: PEER_IP,
            netmask: Ipv4Addr::new(255, 255, 255, 0),
            gateway: Ipv4Addr::UNSPECIFIED,
        },
    );
    let frame = tx[..n].to_vec();
    let Received::Udp(d) = s2.receive(Nanos::ZERO, &frame, &mut [0u8; 64]) else {
        panic!()
    };
    assert_eq!(
        (d.src, d.dst_port, d.payload, d.src_mac),
        (
            Endpoint {
                ip: OUR_IP,
                port: RPC_PORT
            },
            50000,
            &b"hello"[..],
            OUR_MAC
        )
    );
    // The same datagram to port 34964 is the RPC one.
    let mut f = frame.clone();
    f[36..38].copy_from_slice(&RPC_PORT.to_be_bytes());
    f[40..42].fill(0); // checksum 0 = none
    assert!(matches!(
        s2.receive(Nanos::ZERO, &f, &mut [0u8; 64]),
        Received::Rpc(_)
    ));
    f[40] = 1;
    assert_eq!(
        s2.receive(Nanos::ZERO, &f, &mut [0u8; 64]),
        Received::Dropped(DropReason::UdpMalformed)
    );
    // Unknown neighbour: an ARP request instead.
    let far = Endpoint {
        ip: Ipv4Addr::new(192, 168, 0, 77),
        port: 1,
    };
    assert!(matches!(
        s.emit_udp(Nanos::ZERO, &mut tx, RPC_PORT, far, 5),
        Ok(UdpTx::ArpRequest(60))
    ));
    let off = Endpoint {
        ip: Ipv4Addr::new(10, 0, 0, 1),
        port: 1,
    };
    assert_eq!(
        s.emit_udp(Nanos::ZERO, &mut tx, RPC_PORT, off, 5),
        Err(TxError::NoRoute)
    );
}

#[test]
fn neighbour_cache_is_bounded_and_expires() {
    let mut c = NeighbourCache::<2>::default();
    let ip = |n| Ipv4Addr::from([10, 0, 0, n]);
    c.learn(Nanos::from_secs(1), ip(1), PEER_MAC);
    c.learn(Nanos::from_secs(2), ip(2), PEER_MAC);
    c.learn(Nanos::from_secs(3), ip(3), OUR_MAC);
    assert_eq!(c.lookup(Nanos::from_secs(3), ip(1)), None);
    assert_eq!(c.lookup(Nanos::from_secs(3), ip(3)), Some(OUR_MAC));
    assert_eq!(c.lookup(Nanos::from_secs(400), ip(3)), None);
}
