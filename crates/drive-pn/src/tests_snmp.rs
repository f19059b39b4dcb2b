//! The SNMP agent on the PROFINET interface (P-038): sysName/sysContact/sysLocation
//! set over UDP 161 are saved with the parameters and kept across a restart; a set
//! with the read community changes nothing; reset to factory clears them.

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

/// An SNMPv2c request (get 0xA0, set 0xA3) as an Ethernet frame to the drive's port 161.
fn request(community: &[u8], pdu: u8, bindings: &[(u32, &[u8])]) -> Vec<u8> {
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
    for (obj, v) in bindings {
        let m = w.open(0x30);
        w.oid(&oid(*obj));
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
    let mut out = Vec::new();
    d.receive(
        Nanos::from_ms(1),
        frame,
        &mut |f: &[u8]| out.push(f.to_vec()),
        &mut |_| {},
    );
    out.into_iter()
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
