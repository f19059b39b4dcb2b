//! The SNMP agent on the PROFINET interface (P-038): sysName/sysContact/sysLocation
//! set over UDP 161 are saved with the parameters and kept across a restart; a set
//! with the read community changes nothing; reset to factory clears them. The
//! LLDP extension tables show what the drive sends and what its neighbour's
//! LLDPDU said.

use super::tests::{commissioned, hardware, TestFlash, OUR};
use super::*;
use core::net::Ipv4Addr;
use profinet::ip::{Endpoint, IpConfig, Stack, UdpTx, UDP_PAYLOAD_OFFSET};
use profinet::wire::{EthFrame, MacAddr};
use snmp::ber::{Reader, Writer};
use std::vec::Vec;

const PLC: MacAddr = MacAddr([2, 0, 0, 0, 0, 0xC0]);
const SYS: [u32; 8] = [1, 3, 6, 1, 2, 1, 1, 0];

fn oid(obj: u32) -> [u32; 9] {
    let mut o = [0; 9];
    o[..8].copy_from_slice(&SYS);
    o[7] = obj;
    o
}

/// An SNMPv2c request (get 0xA0, set 0xA3) of system objects as an Ethernet frame to the
/// drive's port 161.
fn request(community: &[u8], pdu: u8, bindings: &[(u32, &[u8])]) -> Vec<u8> {
    let oids: Vec<([u32; 9], &[u8])> = bindings.iter().map(|(o, v)| (oid(*o), *v)).collect();
    let refs: Vec<(&[u32], &[u8])> = oids.iter().map(|(o, v)| (&o[..], *v)).collect();
    request_oids(community, pdu, &refs)
}

/// An SNMPv2c request of any OIDs as an Ethernet frame to the drive's port 161.
fn request_oids(community: &[u8], pdu: u8, bindings: &[(&[u32], &[u8])]) -> Vec<u8> {
    let mut msg = [0u8; 1400];
    let mut w = Writer::new(&mut msg);
    let t = w.open(0x30);
    w.int(2, 1);
    w.prim(4, community);
    let p = w.open(pdu);
    w.int(2, 99);
    w.int(2, 0);
    w.int(2, 0);
    let l = w.open(0x30);
    for (o, v) in bindings {
        let m = w.open(0x30);
        w.oid(o);
        if pdu == 0xA3 {
            w.prim(4, v);
        } else {
            w.prim(5, &[]);
        }
        w.close(m);
    }
    w.close(l);
    w.close(p);
    w.close(t);
    let n = w.finish().unwrap();
    let mut plc = Stack::new(
        PLC,
        IpConfig {
            addr: Ipv4Addr::new(192, 168, 0, 1),
            netmask: Ipv4Addr::new(255, 255, 255, 0),
            gateway: Ipv4Addr::UNSPECIFIED,
        },
    );
    let drive = Ipv4Addr::new(192, 168, 0, 50);
    plc.learn(Nanos::ZERO, drive, OUR);
    let mut tx = [0u8; 1514];
    tx[UDP_PAYLOAD_OFFSET..UDP_PAYLOAD_OFFSET + n].copy_from_slice(&msg[..n]);
    let ep = Endpoint { ip: drive, port: 161 };
    match plc.emit_udp(Nanos::ZERO, &mut tx, 40000, ep, n).unwrap() {
        UdpTx::Frame(len) => tx[..len].to_vec(),
        UdpTx::ArpRequest(_) => panic!("the drive's MAC was learnt"),
    }
}

/// The SNMP answers (UDP payloads from port 161) to one frame.
fn send(d: &mut PnDrive<TestFlash>, frame: &[u8]) -> Vec<Vec<u8>> {
    super::tests::send(d, frame)
        .into_iter()
        .filter(|f| EthFrame::parse(f).is_some_and(|e| e.dst == PLC))
        .filter(|f| f.get(34..36) == Some(&[0, 161]))
        .map(|f| f[UDP_PAYLOAD_OFFSET..].to_vec())
        .collect()
}

/// error-status and the first binding's value of a response.
fn answer(msg: &[u8]) -> (i32, Vec<u8>) {
    let mut r = Reader::new(msg);
    let mut m = Reader::new(r.expect(0x30).unwrap());
    m.int().unwrap();
    m.expect(4).unwrap();
    let mut p = Reader::new(m.expect(0xA2).unwrap());
    assert_eq!(p.int(), Some(99), "the request's id");
    let status = p.int().unwrap();
    p.int().unwrap();
    let mut l = Reader::new(p.expect(0x30).unwrap());
    let mut vb = Reader::new(l.expect(0x30).unwrap());
    vb.oid().unwrap();
    (status, vb.tlv().unwrap().1.to_vec())
}

fn get(d: &mut PnDrive<TestFlash>, obj: u32) -> Vec<u8> {
    let a = send(d, &request(b"public", 0xA0, &[(obj, &[])]));
    assert_eq!(a.len(), 1, "one answer");
    answer(&a[0]).1
}

#[test]
fn p038_snmp_set_system_strings_are_kept_across_a_restart() {
    let mut d = commissioned();
    assert_eq!(get(&mut d, 5), b"", "sysName empty when shipped");
    let a = send(
        &mut d,
        &request(b"private", 0xA3, &[(4, b"ops"), (5, b"axis-1"), (6, b"hall 3")]),
    );
    assert_eq!(answer(&a[0]).0, 0, "set answered noError");
    let mut d = PnDrive::new(d.into_flash(), hardware());
    assert_eq!(get(&mut d, 4), b"ops");
    assert_eq!(get(&mut d, 5), b"axis-1");
    assert_eq!(get(&mut d, 6), b"hall 3");
}

#[test]
fn p038_snmp_set_with_the_read_community_changes_nothing() {
    let mut d = commissioned();
    let a = send(&mut d, &request(b"public", 0xA3, &[(5, b"evil")]));
    assert!(a.is_empty(), "dropped");
    let mut d = PnDrive::new(d.into_flash(), hardware());
    assert_eq!(get(&mut d, 5), b"");
}

/// The value (tag, bytes) of one OID.
fn get_oid(d: &mut PnDrive<TestFlash>, o: &[u32]) -> (u8, Vec<u8>) {
    let a = send(d, &request_oids(b"public", 0xA0, &[(o, &[])]));
    assert_eq!(a.len(), 1, "one answer");
    let mut r = Reader::new(&a[0]);
    let mut m = Reader::new(r.expect(0x30).unwrap());
    m.int().unwrap();
    m.expect(4).unwrap();
    let mut p = Reader::new(m.expect(0xA2).unwrap());
    p.int().unwrap();
    assert_eq!(p.int(), Some(0), "noError");
    p.int().unwrap();
    let mut l = Reader::new(p.expect(0x30).unwrap());
    let mut vb = Reader::new(l.expect(0x30).unwrap());
    vb.oid().unwrap();
    let (t, v) = vb.tlv().unwrap();
    (t, v.to_vec())
}

/// `prefix`, column `col`, then `inst`.
fn cell(prefix: &[u32], col: u32, inst: &[u32]) -> Vec<u32> {
    [prefix, &[col], inst].concat()
}

#[test]
fn p038_snmp_lldp_extension_tables_show_what_lldp_sends_and_what_the_neighbour_sent() {
    let mut d = commissioned();
    let pno_loc = [1, 0, 8802, 1, 1, 2, 1, 5, 3791, 1, 2, 1, 1];
    let pno_rem = [1, 0, 8802, 1, 1, 2, 1, 5, 3791, 1, 3, 1, 1];
    let dot3_loc = [1, 0, 8802, 1, 1, 2, 1, 5, 4623, 1, 2, 1, 1];
    let dot3_rem = [1, 0, 8802, 1, 1, 2, 1, 5, 4623, 1, 3, 1, 1];
    let rem = [0, 1, 1];
    // nothing heard yet: no remote row
    assert_eq!(get_oid(&mut d, &cell(&pno_rem, 6, &rem)).0, 0x81);
    // the PLC's LLDPDU on port 1: chassis "plc-1", port "port-002", PNIO delays
    // (Rx 444, Tx 1123, cable 55 ns), port status RT2 up, MAC/PHY (MAU 30),
    // management address 192.168.0.1 (ifIndex 3)
    let mut f = std::vec![0x01, 0x80, 0xC2, 0, 0, 0x0E];
    f.extend_from_slice(&PLC.0);
    f.extend_from_slice(&[0x88, 0xCC, 0x02, 0x06, 7]);
    f.extend_from_slice(b"plc-1");
    f.extend_from_slice(&[0x04, 0x09, 7]);
    f.extend_from_slice(b"port-002");
    f.extend_from_slice(&[0x06, 0x02, 0, 20]);
    f.extend_from_slice(&[0xFE, 24, 0x00, 0x0E, 0xCF, 1, 0, 0, 1, 0xBC, 0, 0, 0, 0]);
    f.extend_from_slice(&[0, 0, 4, 0x63, 0, 0, 0, 0, 0, 0, 0, 55]);
    f.extend_from_slice(&[0xFE, 8, 0x00, 0x0E, 0xCF, 2, 0, 2, 0, 0]);
    f.extend_from_slice(&[0xFE, 9, 0x00, 0x12, 0x0F, 1, 3, 0x6C, 0, 0, 30]);
    f.extend_from_slice(&[0x10, 12, 5, 1, 192, 168, 0, 1, 2, 0, 0, 0, 3, 0, 0, 0]);
    send(&mut d, &f);

    // local: the name of station on both ports, 100BASE-TX FD on port 1 (link up), none on 2
    assert_eq!(
        get_oid(&mut d, &cell(&pno_loc, 6, &[1])),
        (4, b"drive-1".to_vec())
    );
    assert_eq!(
        get_oid(&mut d, &cell(&pno_loc, 6, &[2])),
        (4, b"drive-1".to_vec())
    );
    assert_eq!(get_oid(&mut d, &cell(&dot3_loc, 4, &[1])), (2, std::vec![16]));
    assert_eq!(get_oid(&mut d, &cell(&dot3_loc, 4, &[2])), (2, std::vec![0]));
    assert_eq!(
        get_oid(&mut d, &cell(&dot3_loc, 3, &[1])),
        (4, std::vec![0x6C, 0])
    );
    // the interface's management address row (ifIndex numbering, interface 1)
    let man = [1, 0, 8802, 1, 1, 2, 1, 3, 8, 1, 5, 1, 4, 192, 168, 0, 50];
    assert_eq!(get_oid(&mut d, &man), (2, std::vec![1]));
    // remote, as the PLC sent it
    assert_eq!(get_oid(&mut d, &cell(&pno_rem, 6, &rem)), (4, b"plc-1".to_vec()));
    assert_eq!(get_oid(&mut d, &cell(&pno_rem, 1, &rem)), (0x42, std::vec![55]));
    assert_eq!(
        get_oid(&mut d, &cell(&pno_rem, 2, &rem)),
        (0x42, std::vec![4, 0x63])
    );
    assert_eq!(
        get_oid(&mut d, &cell(&pno_rem, 3, &rem)),
        (0x42, std::vec![1, 0xBC])
    );
    assert_eq!(get_oid(&mut d, &cell(&pno_rem, 4, &rem)), (2, std::vec![2]));
    assert_eq!(get_oid(&mut d, &cell(&dot3_rem, 4, &rem)), (2, std::vec![30]));
    let rem_man = [1, 0, 8802, 1, 1, 2, 1, 4, 2, 1, 4, 0, 1, 1, 1, 4, 192, 168, 0, 1];
    assert_eq!(get_oid(&mut d, &rem_man), (2, std::vec![3]));
}
