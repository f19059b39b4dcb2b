//! PDPortDataCheck (0x802B) through the whole device: written per port, read
//! back as written, bad records refused with nothing stored.

use super::tests::{rig, Rig};
use super::*;
use crate::cm::{NoRecords, PnioStatus};
use crate::rpc::tests::hex;
use std::vec::Vec;

/// A PDPortDataCheck for `subslot` with the given sub-blocks.
pub(crate) fn check(subslot: u16, subblocks: &[u8]) -> Vec<u8> {
    let mut v = hex("0200 0000 0100 0000 0000");
    v.extend_from_slice(&subslot.to_be_bytes());
    v.extend_from_slice(subblocks);
    let len = (v.len() - 4) as u16;
    v[2..4].copy_from_slice(&len.to_be_bytes());
    v
}

/// CheckPeers: port-003 of sw-1 (6 + 1 + 9 + 5 = 21 octets, 3 of padding).
pub(crate) const PEERS_SW1: &str = "020a 0014 0100 01 08 706f72742d303033 04 73772d31 000000";
/// CheckMAUType 100BASE-TX FD.
pub(crate) const MAU_TX_FD: &str = "020c 0004 0100 0010";
/// CheckLinkState up.
pub(crate) const LINK_UP_CHECK: &str = "021c 0004 0100 0001";

fn write(r: &mut Rig<NoRecords>, subslot: u16, data: &[u8]) -> PnioStatus {
    r.record(true, 0, subslot, index::PD_PORT_DATA_CHECK, data).0
}

#[test]
fn p040_pd_port_data_check_is_stored_per_port_and_read_back_as_written() {
    let mut r = rig();
    for sub in [0x8001, 0x8002] {
        assert_eq!(
            r.read(sub, index::PD_PORT_DATA_CHECK),
            (PnioStatus::OK, Vec::new())
        );
    }
    let mut subs = hex(PEERS_SW1);
    subs.extend_from_slice(&hex(MAU_TX_FD));
    subs.extend_from_slice(&hex(LINK_UP_CHECK));
    let rec = check(0x8001, &subs);
    assert_eq!(write(&mut r, 0x8001, &rec), PnioStatus::OK);
    assert_eq!(
        r.read(0x8001, index::PD_PORT_DATA_CHECK),
        (PnioStatus::OK, rec.clone())
    );
    // port 2 keeps its own (none)
    assert_eq!(
        r.read(0x8002, index::PD_PORT_DATA_CHECK),
        (PnioStatus::OK, Vec::new())
    );
    let link_only = check(0x8002, &hex(LINK_UP_CHECK));
    assert_eq!(write(&mut r, 0x8002, &link_only), PnioStatus::OK);
    assert_eq!(r.read(0x8002, index::PD_PORT_DATA_CHECK).1, link_only);
    assert_eq!(r.read(0x8001, index::PD_PORT_DATA_CHECK).1, rec);
    // a record with no sub-block withdraws the check
    assert_eq!(write(&mut r, 0x8002, &check(0x8002, &[])), PnioStatus::OK);
    assert_eq!(r.read(0x8002, index::PD_PORT_DATA_CHECK).1, Vec::<u8>::new());
    // at the interface: invalid index; tshark dissects the blocks
    assert_eq!(
        r.read(0x8000, index::PD_PORT_DATA_CHECK).0,
        PnioStatus::rw(0xDE, 0xB0)
    );
    let Some(text) = crate::tests_tshark::device_rpc(&r.frames) else {
        return;
    };
    assert!(text.contains("CheckPeers"), "not dissected");
}

#[test]
fn p040_bad_pd_port_data_check_blocks_are_refused_and_nothing_is_stored() {
    let mut r = rig();
    let good = check(0x8001, &hex(MAU_TX_FD));
    assert_eq!(write(&mut r, 0x8001, &good), PnioStatus::OK);
    let invalid = PnioStatus::rw(0xDF, 0xB8);
    let length = PnioStatus::rw(0xDF, 0xB1);
    let mut peers2 = hex(PEERS_SW1);
    peers2[6] = 2; // NumberOfPeers 2
    let mut peers_long = hex(PEERS_SW1);
    peers_long[7] = 9; // PeerPortID runs into the chassis ID
    let mut dup = hex(MAU_TX_FD);
    dup.extend_from_slice(&hex(MAU_TX_FD));
    let mut wrong_outer = check(0x8001, &hex(MAU_TX_FD));
    wrong_outer[1] = 0x02; // PDPortDataAdjust's block type
    let mut cut = check(0x8001, &hex(MAU_TX_FD));
    cut[3] += 2; // block length beyond the record
    let cases: [(Vec<u8>, PnioStatus); 9] = [
        (check(0x8002, &hex(MAU_TX_FD)), invalid), // another port's block
        (check(0x8001, &peers2), invalid),         // NumberOfPeers 2
        (check(0x8001, &hex("020c 0004 0100 0000")), invalid), // MAU type 0
        (check(0x8001, &hex("021c 0004 0100 0002")), invalid), // link down
        (check(0x8001, &hex("020b 0008 0100 0000 00000010")), invalid), // CheckLineDelay
        (check(0x8001, &dup), invalid),            // repeated
        (wrong_outer, invalid),
        (check(0x8001, &peers_long), length),
        (cut, length),
    ];
    for (k, (rec, want)) in cases.iter().enumerate() {
        assert_eq!(write(&mut r, 0x8001, rec), *want, "case {k}");
        assert_eq!(
            r.read(0x8001, index::PD_PORT_DATA_CHECK).1,
            good,
            "case {k} changed the check"
        );
    }
    // a write to the interface subslot or a missing port
    assert_eq!(write(&mut r, 0x8000, &good), PnioStatus::rw(0xDF, 0xB0));
    assert_eq!(write(&mut r, 0x8003, &good), PnioStatus::rw(0xDF, 0xB2));
}

/// The LLDP frames `poll` sends at `now`.
/// The LLDP frames sent at `now`: polls until none is due then (one port's
/// LLDPDU per poll; each poll that sent one returns `now` as its deadline).
fn lldp_at(r: &mut Rig<NoRecords>, now: nanos::Nanos) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    for _ in 0..4 {
        if r.d.poll(now, &mut |f: &[u8]| out.push(f.to_vec())) > now {
            break;
        }
    }
    out.into_iter().filter(|f| f[12..14] == [0x88, 0xCC]).collect()
}

fn has(f: &[u8], s: &[u8]) -> bool {
    f.windows(s.len()).any(|w| w == s)
}

#[test]
fn p037_p040_pd_interface_adjust_name_of_device_puts_the_name_into_the_lldp_port_id() {
    let mut r = rig();
    assert_eq!(
        r.read(0x8000, index::PD_INTERFACE_ADJUST),
        (PnioStatus::OK, Vec::new())
    );
    let f = lldp_at(&mut r, nanos::Nanos::ZERO);
    assert_eq!(f.len(), 2);
    assert!(has(&f[0], b"\x07port-001\x06") && !has(&f[0], b"port-001.drive-1"));
    // NameOfDevice: the Port ID becomes port-00n.<name of station>
    let rec = hex("0250 0008 0100 0000 00000001");
    let w = r.record(true, 0, 0x8000, index::PD_INTERFACE_ADJUST, &rec);
    assert_eq!(w.0, PnioStatus::OK);
    assert_eq!(r.read(0x8000, index::PD_INTERFACE_ADJUST).1, rec);
    let f = lldp_at(&mut r, nanos::Nanos::from_secs(5));
    assert_eq!(f.len(), 2);
    assert!(has(&f[0], b"port-001.drive-1") && has(&f[1], b"port-002.drive-1"));
    assert!(has(&f[0], b"\x07drive-1"), "chassis ID stays the name");
    // refused: a reserved bit, another block, a wrong length, a port subslot; nothing changes
    for (data, code1) in [
        (hex("0250 0008 0100 0000 00000002"), 0xB8),
        (hex("0251 0008 0100 0000 00000000"), 0xB8),
        (hex("0250 000a 0100 0000 00000000 0000"), 0xB1),
        (hex("0250 0008 0100 0000 0000"), 0xB1),
    ] {
        let w = r.record(true, 0, 0x8000, index::PD_INTERFACE_ADJUST, &data);
        assert_eq!(w.0, PnioStatus::rw(0xDF, code1));
    }
    let w = r.record(true, 0, 0x8001, index::PD_INTERFACE_ADJUST, &rec);
    assert_eq!(w.0, PnioStatus::rw(0xDF, 0xB0));
    assert_eq!(r.read(0x8000, index::PD_INTERFACE_ADJUST).1, rec);
    // back to NameOfDevice 0: port-001 again
    let zero = hex("0250 0008 0100 0000 00000000");
    assert_eq!(
        r.record(true, 0, 0x8000, index::PD_INTERFACE_ADJUST, &zero).0,
        PnioStatus::OK
    );
    let f = lldp_at(&mut r, nanos::Nanos::from_secs(10));
    assert!(!has(&f[0], b"port-001.drive-1"));
    let Some(text) = crate::tests_tshark::device_rpc(&r.frames) else {
        return;
    };
    assert!(text.contains("PDInterfaceAdjust"), "not dissected");
}

#[test]
fn p040_pd_real_data_holds_the_interface_and_each_port_real_data() {
    let mut r = rig();
    r.rx(nanos::Nanos::ZERO, &super::tests::lldp_from_switch());
    let (status, data) = r.read(1, index::PD_REAL_DATA);
    assert_eq!(status, PnioStatus::OK);
    let iface = r.read(0x8000, index::PD_INTERFACE_DATA_REAL).1;
    let p1 = r.read(0x8001, index::PD_PORT_DATA_REAL).1;
    let p2 = r.read(0x8002, index::PD_PORT_DATA_REAL).1;
    let mut want = Vec::new();
    for (sub, inner) in [(0x8000u16, &iface), (0x8001, &p1), (0x8002, &p2)] {
        let len = (12 + inner.len()) as u16;
        want.extend_from_slice(&hex("0400"));
        want.extend_from_slice(&len.to_be_bytes());
        want.extend_from_slice(&hex("0100 0000 00000000 0000"));
        want.extend_from_slice(&sub.to_be_bytes());
        want.extend_from_slice(inner);
    }
    assert_eq!(data, want);
    assert!(has(&data, b"sw-1"), "port 1's neighbour is in it");
    // device scope: at the interface too; a missing submodule; read only
    assert_eq!(r.read(0x8000, index::PD_REAL_DATA).1, want);
    assert_eq!(r.read(0x8009, index::PD_REAL_DATA).0, PnioStatus::rw(0xDE, 0xB2));
    let w = r.record(true, 0, 1, index::PD_REAL_DATA, &want);
    assert_eq!(w.0, PnioStatus::rw(0xDF, 0xB6));
    let Some(text) = crate::tests_tshark::device_rpc(&r.frames) else {
        return;
    };
    assert!(text.contains("MultipleBlockHeader"), "not dissected");
    assert!(!text.contains("Malformed"), "{text}");
}

fn counters(data: &[u8]) -> [u32; 6] {
    assert_eq!(&data[..8], &hex("0251 001c 0100 0000")[..]);
    core::array::from_fn(|k| u32::from_be_bytes(data[8 + 4 * k..12 + 4 * k].try_into().unwrap()))
}

#[test]
fn p040_pd_port_statistic_counts_the_octets_and_errors_of_the_interface_and_ports() {
    let mut r = rig();
    let lldp = lldp_at(&mut r, nanos::Nanos::ZERO);
    let (status, data) = r.read(0x8000, index::PD_PORT_STATISTIC);
    assert_eq!(status, PnioStatus::OK);
    let c0 = counters(&data);
    let n = r.frames.len();
    r.rx(nanos::Nanos::ZERO, &super::tests::lldp_from_switch());
    r.rx(nanos::Nanos::ZERO, &[0u8; 10]); // too short for Ethernet: an input error
    let c1 = counters(&r.read(0x8000, index::PD_PORT_STATISTIC).1);
    // frames since: the answer to the first read, the LLDP frame, the runt, the second read
    let f = &r.frames[n - 1..];
    let (resp0, neighbour, runt, req1) = (f[0].len(), f[1].len(), f[2].len(), f[3].len());
    assert_eq!(c1[0] - c0[0], (neighbour + runt + req1) as u32, "ifInOctets");
    assert_eq!(c1[1] - c0[1], resp0 as u32, "ifOutOctets");
    assert_eq!(c1[4] - c0[4], 1, "ifInErrors");
    assert_eq!((c1[2], c1[3], c1[5]), (0, 0, 0), "no discards, no output errors");
    // port 2 sent only its LLDP frame and received nothing; port 1 the rest
    let p2 = counters(&r.read(0x8002, index::PD_PORT_STATISTIC).1);
    assert_eq!(p2, [0, lldp[1].len() as u32, 0, 0, 0, 0]);
    let pdev = r.d.cm().pdev();
    let (i, p1) = (pdev.counters(0x8000).unwrap(), pdev.counters(0x8001).unwrap());
    assert_eq!(p1.in_octets, i.in_octets);
    assert_eq!(p1.out_octets + lldp[1].len() as u32, i.out_octets);
    // read only; not on other subslots
    let w = r.record(true, 0, 0x8001, index::PD_PORT_STATISTIC, &data);
    assert_eq!(w.0, PnioStatus::rw(0xDF, 0xB6));
    assert_eq!(
        r.read(0x8003, index::PD_PORT_STATISTIC).0,
        PnioStatus::rw(0xDE, 0xB2)
    );
    let Some(text) = crate::tests_tshark::device_rpc(&r.frames) else {
        return;
    };
    assert!(text.contains("PDPortStatistic"), "not dissected");
}
