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

#[test]
fn p037_lldp_frame_per_port_carries_the_profinet_tlvs() {
    for (port, mac, pid) in [(1, P1_MAC, b"port-001"), (2, P2_MAC, b"port-002")] {
        let f = build(
            "drive-1",
            port,
            mac,
            Some(Ipv4Addr::new(192, 168, 0, 86)),
            PortIdForm::Short,
        );
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

/// Prints both ports' frames as hex for a tshark check (`cargo test -p
/// profinet lldp_dump -- --ignored --nocapture`).
#[test]
#[ignore]
fn lldp_dump() {
    for (port, mac) in [(1, P1_MAC), (2, P2_MAC)] {
        let f = build(
            "drive-1",
            port,
            mac,
            Some(Ipv4Addr::new(192, 168, 0, 86)),
            PortIdForm::Short,
        );
        let h: Vec<std::string::String> = f.iter().map(|b| std::format!("{b:02x}")).collect();
        std::println!("{}", h.concat());
    }
}
