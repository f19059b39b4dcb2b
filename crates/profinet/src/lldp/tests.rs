//! LLDP tests: the frame's TLVs byte for byte, the schedule, the neighbour.

use std::vec::Vec;

use super::*;

const IF_MAC: MacAddr = MacAddr([0x00, 0x40, 0x55, 0x40, 0x02, 0x2A]);
const P1_MAC: MacAddr = MacAddr([0x00, 0x40, 0x55, 0x49, 0x02, 0x2A]);
const P2_MAC: MacAddr = MacAddr([0x00, 0x40, 0x55, 0x50, 0x02, 0x2A]);

/// The TLVs of a frame as (type, value).
fn tlvs(frame: &[u8]) -> Vec<(u8, Vec<u8>)> {
    let mut rest = &frame[14..];
    let mut out = Vec::new();
    loop {
        let head = u16::from_be_bytes([rest[0], rest[1]]);
        let (ty, len) = ((head >> 9) as u8, usize::from(head & 0x1FF));
        out.push((ty, rest[2..2 + len].to_vec()));
        rest = &rest[2 + len..];
        if ty == 0 {
            return out;
        }
    }
}

fn build(name: &str, port: u16, mac: MacAddr, ip: Option<Ipv4Addr>, form: PortIdForm) -> Vec<u8> {
    let name: NameOfStation = name.parse().unwrap();
    let station = Station {
        name: &name,
        interface_mac: IF_MAC,
        ip,
        port_id_form: form,
    };
    let mut out = [0u8; 1514];
    let n = build_frame(&station, port, &PortInfo::fast_ethernet(mac), &mut out).unwrap();
    out[..n].to_vec()
}

/// "drive-1" at 192.168.0.86, short port IDs: the frame of `port`.
fn build_drive1(port: u16, mac: MacAddr) -> Vec<u8> {
    build(
        "drive-1",
        port,
        mac,
        Some(Ipv4Addr::new(192, 168, 0, 86)),
        PortIdForm::Short,
    )
}

#[test]
fn p037_lldp_frame_per_port_carries_the_profinet_tlvs() {
    for (port, mac, pid) in [(1, P1_MAC, b"port-001"), (2, P2_MAC, b"port-002")] {
        let f = build_drive1(port, mac);
        assert_eq!(&f[..6], &MacAddr::LLDP.0);
        assert_eq!(&f[6..12], &mac.0, "source is the port MAC (P-006)");
        assert_eq!(&f[12..14], &[0x88, 0xCC]);
        let t = tlvs(&f);
        let pid: &[u8] = pid;
        assert_eq!(t[0], (1, [&[7u8][..], b"drive-1"].concat()));
        assert_eq!(t[1], (2, [&[7u8][..], pid].concat()));
        assert_eq!(t[2], (3, std::vec![0, 20]));
        assert_eq!(t[3], (127, [&[0x00, 0x0E, 0xCF, 1][..], &[0; 20]].concat()));
        assert_eq!(t[4], (127, std::vec![0x00, 0x0E, 0xCF, 2, 0, 0, 0, 0]));
        assert_eq!(t[5], (127, [&[0x00, 0x0E, 0xCF, 5][..], &IF_MAC.0].concat()));
        assert_eq!(
            t[6],
            (127, std::vec![0x00, 0x12, 0x0F, 1, 0x03, 0x6C, 0x00, 0x00, 0x10])
        );
        assert_eq!(t[7], (8, std::vec![5, 1, 192, 168, 0, 86, 2, 0, 0, 0, 1, 0]));
        assert_eq!(t[8], (0, std::vec![]));
        assert_eq!(t.len(), 9);
    }
}

#[test]
fn p037_lldp_without_a_name_sends_the_mac_and_no_unset_ip() {
    let f = build("", 1, P1_MAC, Some(Ipv4Addr::UNSPECIFIED), PortIdForm::WithName);
    let t = tlvs(&f);
    assert_eq!(t[0], (1, [&[4u8][..], &IF_MAC.0].concat()));
    assert_eq!(t[1], (2, b"\x07port-001".to_vec()));
    assert!(t.iter().all(|(ty, _)| *ty != 8));
    assert!(f.len() >= 60);
    let f = build("drive-1", 2, P2_MAC, None, PortIdForm::WithName);
    assert_eq!(tlvs(&f)[1], (2, b"\x07port-002.drive-1".to_vec()));
}

#[test]
fn p037_lldp_build_refuses_bad_ports_and_small_buffers() {
    let name: NameOfStation = "drive-1".parse().unwrap();
    let station = Station {
        name: &name,
        interface_mac: IF_MAC,
        ip: None,
        port_id_form: PortIdForm::Short,
    };
    let info = PortInfo::fast_ethernet(P1_MAC);
    let mut out = [0u8; 1514];
    assert!(build_frame(&station, 0, &info, &mut out).is_none());
    assert!(build_frame(&station, 3, &info, &mut out).is_none());
    let n = build_frame(&station, 1, &info, &mut out).unwrap();
    for short in 0..n {
        assert!(build_frame(&station, 1, &info, &mut out[..short]).is_none());
    }
    let long: std::string::String = [
        &"a".repeat(63)[..],
        &"b".repeat(63),
        &"c".repeat(63),
        &"d".repeat(48),
    ]
    .join(".");
    let name: NameOfStation = long.parse().unwrap();
    let station = Station {
        name: &name,
        port_id_form: PortIdForm::WithName,
        ..station
    };
    let n = build_frame(&station, 2, &info, &mut out).unwrap();
    let nb = Neighbor::parse(&EthFrame::parse(&out[..n]).unwrap()).unwrap();
    assert_eq!(nb.port_id.len(), 9 + 240);
}

#[test]
fn p037_lldp_every_5_s_on_both_ports() {
    let mut s = Schedule::default();
    let t0 = Nanos::from_secs(1);
    assert_eq!(s.due(t0), None);
    s.kick(t0);
    assert_eq!(s.due(t0), Some(1));
    s.sent(1, t0);
    assert_eq!(s.due(t0), Some(2));
    s.sent(2, t0 + Nanos::from_ms(1));
    assert_eq!(s.due(t0 + Nanos::from_ms(4999)), None);
    assert_eq!(s.next_deadline(), Some(t0 + TX_INTERVAL));
    assert_eq!(s.due(t0 + TX_INTERVAL), Some(1));
    s.stop_port(1);
    assert_eq!(s.due(t0 + Nanos::from_secs(60)), Some(2));
    s.kick_port(1, t0 + Nanos::from_secs(6));
    assert_eq!(s.due(t0 + Nanos::from_secs(6)), Some(1));
    s.kick_port(9, t0);
    s.sent(0, t0);
}

#[test]
fn neighbor_gives_the_alias_name() {
    let f = build("switch-1", 1, P1_MAC, None, PortIdForm::Short);
    let n = Neighbor::parse(&EthFrame::parse(&f).unwrap()).unwrap();
    assert_eq!(
        (n.chassis_id, n.port_id, n.ttl),
        (&b"switch-1"[..], &b"port-001"[..], 20)
    );
    let mut alias = heapless::Vec::new();
    n.alias(&mut alias).unwrap();
    assert_eq!(&alias[..], b"port-001.switch-1");
    let f = build("switch-1", 2, P2_MAC, None, PortIdForm::WithName);
    let n = Neighbor::parse(&EthFrame::parse(&f).unwrap()).unwrap();
    n.alias(&mut alias).unwrap();
    assert_eq!(&alias[..], b"port-002.switch-1");
    let f = build("", 1, P1_MAC, None, PortIdForm::Short);
    let n = Neighbor::parse(&EthFrame::parse(&f).unwrap()).unwrap();
    assert!(n.alias(&mut alias).is_none());
    // Truncations and other EtherTypes never panic and are refused.
    let f = build("switch-1", 1, P1_MAC, None, PortIdForm::Short);
    for cut in 14..30 {
        let e = EthFrame::parse(&f[..cut]).unwrap();
        assert!(Neighbor::parse(&e).is_none(), "cut {cut}");
    }
    let mut other = f.clone();
    other[13] = 0x92;
    assert!(Neighbor::parse(&EthFrame::parse(&other).unwrap()).is_none());
}

/// An LLDPDU as a neighbour (a controller port) would send it, written byte by
/// byte: chassis "plc-1", port "port-002", TTL 20, then `extra` TLVs, End.
fn peer_frame(extra: &[u8]) -> Vec<u8> {
    let mut f = std::vec![0x01, 0x80, 0xC2, 0, 0, 0x0E, 2, 0, 0, 0, 0, 0xC0, 0x88, 0xCC];
    f.extend_from_slice(&[0x02, 0x06, 7, b'p', b'l', b'c', b'-', b'1']);
    f.extend_from_slice(&[0x04, 0x09, 7]);
    f.extend_from_slice(b"port-002");
    f.extend_from_slice(&[0x06, 0x02, 0, 20]);
    f.extend_from_slice(extra);
    f.extend_from_slice(&[0, 0]);
    f
}

const PEER_DELAY: [u8; 26] = [
    0xFE, 24, 0x00, 0x0E, 0xCF, 1, // PNIO delay
    0, 0, 0x01, 0xBC, // PortRxDelayLocal 444
    0, 0, 0, 0, // PortRxDelayRemote
    0, 0, 0x04, 0x63, // PortTxDelayLocal 1123
    0, 0, 0, 0, // PortTxDelayRemote
    0, 0, 0, 55, // CableDelayLocal
];
const PEER_STATUS: [u8; 10] = [0xFE, 8, 0x00, 0x0E, 0xCF, 2, 0, 2, 0, 4];
const PEER_MAC_PHY: [u8; 11] = [0xFE, 9, 0x00, 0x12, 0x0F, 1, 0x01, 0x04, 0x00, 0, 30];
const PEER_MAN_ADDR: [u8; 14] = [0x10, 12, 5, 1, 10, 0, 0, 1, 3, 0, 0, 0, 9, 0];

#[test]
fn p038_received_lldpdu_gives_the_neighbours_pnio_mac_phy_and_management_address() {
    let f = peer_frame(&[&PEER_DELAY[..], &PEER_STATUS, &PEER_MAC_PHY, &PEER_MAN_ADDR].concat());
    let n = Neighbor::parse(&EthFrame::parse(&f).unwrap()).unwrap();
    assert_eq!(
        (n.chassis_id, n.port_id, n.ttl),
        (&b"plc-1"[..], &b"port-002"[..], 20)
    );
    assert_eq!(
        n.delay,
        Some(PnioDelay {
            rx_local: 444,
            rx_remote: 0,
            tx_local: 1123,
            tx_remote: 0,
            cable_local: 55
        })
    );
    assert_eq!(n.port_status, Some((2, 4)));
    assert_eq!(
        n.mac_phy,
        Some(MacPhy {
            autoneg: 1,
            advertised: 0x0400,
            mau_type: 30
        })
    );
    assert_eq!(
        n.man_addr,
        Some(ManAddr {
            ip: Ipv4Addr::new(10, 0, 0, 1),
            if_subtype: 3,
            if_id: 9
        })
    );
    // a plain switch: the mandatory TLVs only
    let f = peer_frame(&[]);
    let n = Neighbor::parse(&EthFrame::parse(&f).unwrap()).unwrap();
    assert_eq!(
        (n.delay, n.port_status, n.mac_phy, n.man_addr),
        (None, None, None, None)
    );
}

#[test]
fn p038_our_own_lldpdu_parses_back_to_what_was_sent() {
    let f = build_drive1(1, P1_MAC);
    let n = Neighbor::parse(&EthFrame::parse(&f).unwrap()).unwrap();
    let info = PortInfo::fast_ethernet(P1_MAC);
    assert_eq!(n.delay, Some(info.delay));
    assert_eq!(n.port_status, Some(info.rt_status));
    assert_eq!(
        n.mac_phy,
        Some(MacPhy {
            autoneg: info.autoneg,
            advertised: info.advertised,
            mau_type: info.mau_type
        })
    );
    assert_eq!(
        n.man_addr,
        Some(ManAddr {
            ip: Ipv4Addr::new(192, 168, 0, 86),
            if_subtype: MAN_ADDR_IF_SUBTYPE,
            if_id: MAN_ADDR_IF_ID
        })
    );
}

#[test]
fn p038_odd_optional_tlvs_are_skipped_and_the_neighbour_kept() {
    // wrong lengths, an IPv6 management address, a truncated last TLV: nothing taken,
    // the mandatory part still parsed, never a panic
    let odd = [
        &[0xFE, 5, 0x00, 0x0E, 0xCF, 1, 0][..],
        &[0xFE, 6, 0x00, 0x12, 0x0F, 1, 0, 0],
        &[0x10, 24, 17, 2],
        &[0; 16],
        &[0, 0, 0, 1, 0, 0],
        &[0x10, 12, 5, 1, 10, 0, 0, 1, 3, 0, 0, 0, 9, 1], // OID length past the TLV
    ]
    .concat();
    let f = peer_frame(&odd);
    let n = Neighbor::parse(&EthFrame::parse(&f).unwrap()).unwrap();
    assert_eq!((n.delay, n.mac_phy, n.man_addr), (None, None, None));
    let full = peer_frame(&[&PEER_DELAY[..], &PEER_STATUS, &PEER_MAC_PHY, &PEER_MAN_ADDR].concat());
    let end = full.len() - 2;
    for cut in 37..end {
        let n = Neighbor::parse(&EthFrame::parse(&full[..cut]).unwrap()).unwrap();
        assert_eq!(n.chassis_id, b"plc-1", "cut {cut}");
    }
}

/// Prints both ports' frames as hex for a tshark check (`cargo test -p
/// profinet lldp_dump -- --ignored --nocapture`).
#[test]
#[ignore]
fn lldp_dump() {
    for (port, mac) in [(1, P1_MAC), (2, P2_MAC)] {
        let f = build_drive1(port, mac);
        let h: Vec<std::string::String> = f.iter().map(|b| std::format!("{b:02x}")).collect();
        std::println!("{}", h.concat());
    }
}
