//! The PDev records through the whole device: record reads and writes as
//! UDP frames, the real state behind them (port MACs, link, LLDP neighbour,
//! name and IP), and what tshark's pn_io dissector makes of the blocks.

use super::*;
use crate::cm::tests_vectors::READ_IM0;
use crate::cm::PnioStatus;
use crate::device::Device;
use crate::ip::UDP_PAYLOAD_OFFSET;
use crate::rpc::tests::hex;
use crate::testing::{self, connect_frame, udp_to_device};
use std::vec::Vec;

/// The AR UUID of profinet-py's Connect vector.
const AR_UUID: [u8; 16] = [
    0x10, 0x11, 0x12, 0x13, 0x14, 0x15, 0x16, 0x17, 0x18, 0x19, 0x1a, 0x1b, 0x1c, 0x1d, 0x1e, 0x1f,
];

/// A record read (opnum 2, `write` false) or write (opnum 3) as an RPC
/// request: READ_IM0's RPC header with new NDR arguments.
pub(crate) fn record_rpc(write: bool, seq: u32, slot: u16, subslot: u16, index: u16, data: &[u8]) -> Vec<u8> {
    let mut rpc = hex(READ_IM0)[..80].to_vec();
    rpc[64..68].copy_from_slice(&seq.to_be_bytes());
    rpc[68..70].copy_from_slice(&(if write { 3u16 } else { 2 }).to_be_bytes());
    let mut args = Vec::new();
    args.extend_from_slice(&(if write { 0x0008u16 } else { 0x0009 }).to_be_bytes());
    args.extend_from_slice(&[0x00, 0x3C, 0x01, 0x00]);
    args.extend_from_slice(&(seq as u16).to_be_bytes());
    args.extend_from_slice(&AR_UUID);
    args.extend_from_slice(&0u32.to_be_bytes());
    args.extend_from_slice(&slot.to_be_bytes());
    args.extend_from_slice(&subslot.to_be_bytes());
    args.extend_from_slice(&[0, 0]);
    args.extend_from_slice(&index.to_be_bytes());
    let len = if write { data.len() as u32 } else { 4096 };
    args.extend_from_slice(&len.to_be_bytes());
    args.resize(64, 0);
    if write {
        args.extend_from_slice(data);
    }
    let n = args.len() as u32;
    let mut ndr = Vec::new();
    for v in [4000u32, n, 4000, 0, n] {
        ndr.extend_from_slice(&v.to_be_bytes());
    }
    rpc.extend_from_slice(&ndr);
    rpc.extend_from_slice(&args);
    let body = (rpc.len() - 80) as u16;
    rpc[74..76].copy_from_slice(&body.to_be_bytes());
    rpc
}

/// A test rig: the device, the frames it sent, a sequence number.
pub(crate) struct Rig<H: crate::cm::RecordHook> {
    pub d: Device<H>,
    pub seq: u32,
    /// Every frame to and from the device, for the pcap.
    pub frames: Vec<Vec<u8>>,
}

impl<H: crate::cm::RecordHook> Rig<H> {
    pub fn new(d: Device<H>) -> Rig<H> {
        Rig {
            d,
            seq: 200,
            frames: Vec::new(),
        }
    }

    pub fn rx(&mut self, now: Nanos, frame: &[u8]) -> Vec<Vec<u8>> {
        let mut out = Vec::new();
        self.d.receive(now, frame, &mut |f: &[u8]| out.push(f.to_vec()));
        self.frames.push(frame.to_vec());
        self.frames.extend(out.iter().cloned());
        out
    }

    pub fn connect(&mut self) {
        let out = self.rx(Nanos::ZERO, &connect_frame());
        assert_eq!(out.len(), 1);
        while let Some(e) = self.d.take_event() {
            let _ = e;
        }
    }

    /// One record access; the PNIO status and the record data of the answer.
    pub fn record(
        &mut self,
        write: bool,
        slot: u16,
        subslot: u16,
        index: u16,
        data: &[u8],
    ) -> (PnioStatus, Vec<u8>) {
        self.seq += 1;
        let rpc = record_rpc(write, self.seq, slot, subslot, index, data);
        let out = self.rx(Nanos::ZERO, &udp_to_device(&rpc));
        assert_eq!(out.len(), 1, "one response");
        let p = &out[0][UDP_PAYLOAD_OFFSET..];
        let ndr = &p[80..];
        let status = PnioStatus::from_u32(u32::from_be_bytes(ndr[0..4].try_into().unwrap()));
        let args = &ndr[20..];
        if args.len() < 64 {
            return (status, Vec::new());
        }
        let len = u32::from_be_bytes(args[36..40].try_into().unwrap()) as usize;
        let data = if write {
            Vec::new()
        } else {
            args[64..64 + len].to_vec()
        };
        if write && status.is_ok() {
            assert_eq!(&args[44..48], &[0, 0, 0, 0]);
        }
        (status, data)
    }

    pub fn read(&mut self, subslot: u16, index: u16) -> (PnioStatus, Vec<u8>) {
        self.record(false, 0, subslot, index, &[])
    }
}

pub(crate) fn rig() -> Rig<crate::cm::NoRecords> {
    let mut r = Rig::new(Device::plain(testing::device_config()));
    r.connect();
    r
}

/// An LLDPDU from a switch `sw-1` port `port-003` (V2.3 form), TTL 20 s.
pub(crate) fn lldp_from_switch() -> Vec<u8> {
    let mut f = Vec::new();
    f.extend_from_slice(&MacAddr::LLDP.0);
    f.extend_from_slice(&[0x02, 0, 0, 0, 0, 0x77]);
    f.extend_from_slice(&0x88CCu16.to_be_bytes());
    let tlv = |f: &mut Vec<u8>, ty: u16, v: &[u8]| {
        f.extend_from_slice(&((ty << 9) | v.len() as u16).to_be_bytes());
        f.extend_from_slice(v);
    };
    tlv(&mut f, 1, b"\x07sw-1");
    tlv(&mut f, 2, b"\x07port-003");
    tlv(&mut f, 3, &20u16.to_be_bytes());
    tlv(&mut f, 0, &[]);
    f.resize(60, 0);
    f
}

const OK: PnioStatus = PnioStatus::OK;

fn rw(code1: u8, write: bool) -> PnioStatus {
    PnioStatus::rw(if write { 0xDF } else { 0xDE }, code1)
}

/// A block of `head` (hex, from the block type on), the name, then `tail`
/// (hex), with its BlockLength filled in.
fn named_block(head: &str, name: &[u8], tail: &str) -> Vec<u8> {
    let mut b = hex(head);
    b.extend_from_slice(name);
    b.extend_from_slice(&hex(tail));
    let len = (b.len() - 4) as u16;
    b[2..4].copy_from_slice(&len.to_be_bytes());
    b
}

#[test]
fn p040_pd_port_data_real_reports_port_mac_link_mau_and_no_peer() {
    let mut r = rig();
    let (status, data) = r.read(0x8001, index::PD_PORT_DATA_REAL);
    assert_eq!(status, OK);
    // no peer, padding to 4, MAU type 16, padding, boundaries 0, link up, padding, copper
    let want = named_block(
        "020f 0000 0100 0000 0000 8001 08",
        b"port-001",
        "00 0000 0010 0000 00000000 00000000 0001 0000 00000001",
    );
    assert_eq!(data, want);
    // port 2: link down, MAU type 0
    let (status, data) = r.read(0x8002, index::PD_PORT_DATA_REAL);
    assert_eq!(status, OK);
    assert_eq!(&data[24..26], &[0, 0]);
    assert_eq!(&data[36..38], &[0, 2]);
    assert!(data.windows(8).any(|w| w == b"port-002"));
}

#[test]
fn p040_pd_port_data_real_names_the_lldp_neighbour_until_its_ttl_runs_out() {
    let mut r = rig();
    r.rx(Nanos::ZERO, &lldp_from_switch());
    let (status, data) = r.read(0x8001, index::PD_PORT_DATA_REAL);
    assert_eq!(status, OK);
    // one peer: port-003 of sw-1, line delay 0, its MAC
    assert_eq!(data[21], 1);
    let mut peer = std::vec![8u8];
    peer.extend_from_slice(b"port-003");
    peer.push(4);
    peer.extend_from_slice(b"sw-1");
    assert_eq!(&data[24..24 + peer.len()], &peer[..]);
    let at = 24 + peer.len() + 2; // aligned to 4 from the block start
    assert_eq!(at % 4, 0);
    assert_eq!(&data[at..at + 12], &hex("00000000 020000000077 0000")[..]);
    assert_eq!(&data[at + 12..at + 14], &[0, 0x10]);
    // after its 20 s TTL the neighbour is gone
    r.d.poll(Nanos::from_secs(21), &mut |_: &[u8]| {});
    let (_, data) = r.read(0x8001, index::PD_PORT_DATA_REAL);
    assert_eq!(data[21], 0);
}

#[test]
fn p040_pd_interface_data_real_has_the_name_mac_and_ip_in_force() {
    let mut r = rig();
    let (status, data) = r.read(0x8000, index::PD_INTERFACE_DATA_REAL);
    assert_eq!(status, OK);
    let want = named_block(
        "0240 0000 0100 07",
        b"drive-1",
        "0000 020000000050 0000 c0a80032 ffffff00 00000000",
    );
    assert_eq!(data, want);
}

#[test]
fn p040_pdev_records_at_the_wrong_subslot_are_refused_and_other_indices_stay_invalid() {
    let mut r = rig();
    assert_eq!(r.read(0x8000, index::PD_PORT_DATA_REAL).0, rw(0xB0, false));
    assert_eq!(r.read(0x8001, index::PD_INTERFACE_DATA_REAL).0, rw(0xB0, false));
    assert_eq!(r.read(0x8003, index::PD_PORT_DATA_REAL).0, rw(0xB2, false));
    // PDInterfaceAdjust only at the interface, PDPortStatistic not at the DAP's subslot 1
    assert_eq!(r.read(0x8001, 0x8071).0, rw(0xB0, false));
    assert_eq!(r.read(1, 0x8072).0, rw(0xB0, false));
    assert_eq!(
        r.record(true, 0, 0x8001, index::PD_PORT_DATA_REAL, &[0; 8]).0,
        rw(0xB6, true)
    );
}

/// PDPortDataAdjust for port 1 with the given sub-blocks.
fn adjust(subblocks: &[u8]) -> Vec<u8> {
    let mut v = hex("0202 0000 0100 0000 0000 8001");
    v.extend_from_slice(subblocks);
    let len = (v.len() - 4) as u16;
    v[2..4].copy_from_slice(&len.to_be_bytes());
    v
}

/// AdjustPeerToPeerBoundary: no LLDP. AdjustDomainBoundary 1.1, AdjustDCPBoundary.
const P2P_NO_LLDP: &str = "0224 000c 0100 0000 00000001 0000 0000";
const DOMAIN: &str = "0209 0010 0101 0000 00000001 00000001 0000 0000";
const DCP: &str = "0225 000c 0100 0000 00000003 0000 0000";

#[test]
fn p040_pd_port_data_adjust_reads_empty_then_what_the_controller_wrote() {
    let mut r = rig();
    assert_eq!(r.read(0x8001, index::PD_PORT_DATA_ADJUST), (OK, Vec::new()));
    let mut subs = hex(DOMAIN);
    subs.extend(hex(DCP));
    subs.extend(hex("020e 0008 0100 0000 0010 0000"));
    subs.extend(hex(P2P_NO_LLDP));
    let rec = adjust(&subs);
    assert_eq!(r.record(true, 0, 0x8001, index::PD_PORT_DATA_ADJUST, &rec).0, OK);
    let p = &r.d.cm().pdev().ports[0].adjust;
    assert_eq!(p.peer_to_peer_boundary, Some((1, 0)));
    assert_eq!(p.domain_boundary, Some(((1, 1), 0, 1)));
    // read back in the device's order: domain, MAU type, peer-to-peer, DCP
    let (status, data) = r.read(0x8001, index::PD_PORT_DATA_ADJUST);
    assert_eq!(status, OK);
    let mut want = hex(DOMAIN);
    want.extend(hex("020e 0008 0100 0000 0010 0000"));
    want.extend(hex(P2P_NO_LLDP));
    want.extend(hex(DCP));
    assert_eq!(data, adjust(&want));
    // the domain boundary shows in PDPortDataReal; port 2 is not adjusted
    let (_, real) = r.read(0x8001, index::PD_PORT_DATA_REAL);
    assert_eq!(&real[28..32], &[0, 0, 0, 1]);
    assert_eq!(r.read(0x8002, index::PD_PORT_DATA_ADJUST), (OK, Vec::new()));
}

#[test]
fn p037_p040_a_peer_to_peer_boundary_stops_lldp_on_its_port() {
    let mut r = rig();
    let rec = adjust(&hex(P2P_NO_LLDP));
    assert_eq!(r.record(true, 0, 0x8001, index::PD_PORT_DATA_ADJUST, &rec).0, OK);
    let mut out = Vec::new();
    r.d.poll(Nanos::ZERO, &mut |f: &[u8]| out.push(f.to_vec()));
    let lldp: Vec<_> = out.iter().filter(|f| f[12..14] == [0x88, 0xCC]).collect();
    assert_eq!(lldp.len(), 1, "only port 2 sends");
    assert_eq!(&lldp[0][6..12], &[0x02, 0, 0, 0, 0, 0x52]);
}

#[test]
fn p040_unsupported_or_malformed_adjust_writes_are_refused_and_change_nothing() {
    let mut r = rig();
    let good = adjust(&hex(DCP));
    let cases: [(Vec<u8>, u8); 8] = [
        // AdjustMAUType 10BASE-T FD: invalid parameter
        (adjust(&hex("020e 0008 0100 0000 000b 0000")), 0xB8),
        // AdjustLinkState (forcing the link): invalid parameter
        (adjust(&hex("021b 0008 0100 0000 0002 0000")), 0xB8),
        // an unknown sub-block
        (adjust(&hex("0226 0008 0100 0000 0001 0000")), 0xB8),
        // the block for port 2 written to port 1
        (
            {
                let mut v = good.clone();
                v[11] = 2;
                v
            },
            0xB8,
        ),
        // wrong outer block type
        (
            {
                let mut v = good.clone();
                v[1] = 0x03;
                v
            },
            0xB8,
        ),
        // a sub-block cut short, the outer length still matching
        (adjust(&hex("0225 000a 0100 0000 00000003 0000")), 0xB1),
        // the outer block length beyond the record
        (good[..good.len() - 2].to_vec(), 0xB1),
        // shorter than a block header
        (std::vec![0x02, 0x02, 0x00], 0xB1),
    ];
    for (i, (rec, code)) in cases.iter().enumerate() {
        let before = without_counters(r.d.cm().pdev());
        let status = r.record(true, 0, 0x8001, index::PD_PORT_DATA_ADJUST, rec).0;
        assert_eq!(status, rw(*code, true), "case {i}");
        assert_eq!(
            without_counters(r.d.cm().pdev()),
            before,
            "case {i} changed the state"
        );
    }
    // a good sub-block with a bad one: nothing of it applies
    let mut subs = hex(DCP);
    subs.extend(hex("021b 0008 0100 0000 0002 0000"));
    assert_eq!(
        r.record(true, 0, 0x8001, index::PD_PORT_DATA_ADJUST, &adjust(&subs))
            .0,
        rw(0xB8, true)
    );
    assert_eq!(r.read(0x8001, index::PD_PORT_DATA_ADJUST), (OK, Vec::new()));
    assert!(r.d.cm().ar().is_some(), "the AR survives every refusal");
}

#[test]
fn p040_a_short_record_request_is_refused_without_a_state_change() {
    let mut r = rig();
    // a read request cut inside its IODReadReqHeader: faulty record (0xDE 0x81 0x08)
    r.seq += 1;
    let mut rpc = record_rpc(false, r.seq, 0, 0x8001, index::PD_PORT_DATA_REAL, &[]);
    rpc.truncate(80 + 20 + 40);
    let n = 40u32;
    rpc[84..88].copy_from_slice(&n.to_be_bytes());
    rpc[96..100].copy_from_slice(&n.to_be_bytes());
    rpc[74..76].copy_from_slice(&60u16.to_be_bytes());
    let before = without_counters(r.d.cm().pdev());
    let out = r.rx(Nanos::ZERO, &udp_to_device(&rpc));
    let ndr = &out[0][UDP_PAYLOAD_OFFSET + 80..];
    assert_eq!(&ndr[..4], &[0xDE, 0x81, 0x08, 0x00]);
    assert_eq!(without_counters(r.d.cm().pdev()), before);
    assert!(r.d.cm().ar().is_some());
}

#[test]
fn p040_name_and_ip_set_by_dcp_show_in_pd_interface_data_real() {
    let mut d = Device::plain(crate::device::DeviceConfig {
        name: crate::dcp::NameOfStation::EMPTY,
        ..testing::device_config()
    });
    assert!(d.cm().pdev().name.is_empty());
    let name = crate::dcp::NameOfStation::new(b"axis-7").unwrap();
    let ip = IpSuite {
        ip: core::net::Ipv4Addr::new(10, 0, 0, 9),
        mask: core::net::Ipv4Addr::new(255, 0, 0, 0),
        gateway: core::net::Ipv4Addr::UNSPECIFIED,
    };
    // what a DCP Set raises reaches the PDev
    d.on_dcp_event(
        Nanos::ZERO,
        &crate::dcp::Event::NameOfStation {
            name: name.clone(),
            permanent: true,
        },
        &mut |_: &[u8]| {},
    );
    d.on_dcp_event(
        Nanos::ZERO,
        &crate::dcp::Event::IpSuite {
            suite: ip,
            permanent: true,
        },
        &mut |_: &[u8]| {},
    );
    assert_eq!((&d.cm().pdev().name, d.cm().pdev().ip), (&name, ip));
    d.set_link(false);
    assert!(!d.cm().pdev().any_link_up());
}

/// Every PDev answer through tshark's pn_io dissector (when installed): no
/// malformed frame, no expert warning or error, the blocks named.
#[test]
fn p040_pdev_answers_dissect_without_malformed_packets() {
    let mut r = rig();
    r.rx(Nanos::ZERO, &lldp_from_switch());
    let mut subs = hex(DOMAIN);
    subs.extend(hex(P2P_NO_LLDP));
    r.record(true, 0, 0x8001, index::PD_PORT_DATA_ADJUST, &adjust(&subs));
    for (sub, i) in [
        (0x8001, index::PD_PORT_DATA_REAL),
        (0x8002, index::PD_PORT_DATA_REAL),
        (0x8001, index::PD_PORT_DATA_ADJUST),
        (0x8000, index::PD_INTERFACE_DATA_REAL),
    ] {
        assert_eq!(r.read(sub, i).0, OK);
    }
    let Some(text) = crate::tests_tshark::device_rpc(&r.frames) else {
        return;
    };
    for name in [
        "PDPortDataReal",
        "PDPortDataAdjust",
        "PDInterfaceDataReal",
        "AdjustDomainBoundary",
    ] {
        assert!(text.contains(name), "{name} not dissected");
    }
    assert!(text.contains("sw-1") && text.contains("port-003"));
}

#[test]
fn p039_im0_filter_data_names_the_dap_submodule_and_dissects() {
    let mut r = rig();
    let (status, data) = r.read(1, crate::cm::record::index::IM0_FILTER_DATA);
    assert_eq!(status, OK);
    // I&M0FilterDataSubmodule and I&M0FilterDataDevice: API 0, slot 0 (DAP
    // module ident 1), subslot 1 (submodule ident 1)
    let one = "0001 00000000 0001 0000 00000001 0001 0001 00000001";
    let mut want = hex(&std::format!("0030 0018 0100 {one}"));
    want.extend(hex(&std::format!("0032 0018 0100 {one}")));
    assert_eq!(data, want);
    // device scope: the same at the interface; a missing subslot: invalid slot/subslot
    assert_eq!(r.read(0x8000, crate::cm::record::index::IM0_FILTER_DATA).1, want);
    assert_eq!(
        r.read(0x9000, crate::cm::record::index::IM0_FILTER_DATA).0,
        rw(0xB2, false)
    );
    // read only
    let w = r.record(true, 0, 1, crate::cm::record::index::IM0_FILTER_DATA, &want);
    assert_eq!(w.0, rw(0xB6, true));
    let Some(text) = crate::tests_tshark::device_rpc(&r.frames) else {
        return;
    };
    assert!(
        text.contains("I&M0FilterData") || text.contains("IM0FilterData"),
        "not dissected"
    );
}

#[test]
fn p029_p040_real_identification_data_lists_the_dap_and_the_plugged_modules() {
    let mut r = rig();
    let (status, data) = r.read(1, crate::cm::record::index::REAL_IDENTIFICATION_DATA);
    assert_eq!(status, OK);
    // version 1.1: API 0, 3 slots; the DAP with its subslots (each port its
    // own ident), slot 1 OUT 18 words (0x212), slot 2 IN 18 words (0x112)
    let body = "0001 00000000 0003
        0000 00000001 0004 0001 00000001 8000 00008000 8001 00008001 8002 00008002
        0001 00000212 0001 0001 00000001
        0002 00000112 0001 0001 00000001";
    let mut want = hex(&std::format!("0013 0000 0101 {body}"));
    let len = (want.len() - 4) as u16;
    want[2..4].copy_from_slice(&len.to_be_bytes());
    assert_eq!(data, want);
    let w = r.record(
        true,
        0,
        1,
        crate::cm::record::index::REAL_IDENTIFICATION_DATA,
        &want,
    );
    assert_eq!(w.0, rw(0xB6, true));
    let Some(text) = crate::tests_tshark::device_rpc(&r.frames) else {
        return;
    };
    assert!(text.contains("RealIdentificationData"), "not dissected");
}

/// The PDev's state without its frame counters (which every request moves).
fn without_counters(p: &Pdev) -> Pdev {
    let mut p = p.clone();
    p.stats = Default::default();
    p
}
