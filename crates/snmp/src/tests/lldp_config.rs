//! lldpConfiguration and lldpStatistics (P-038): the transmitter's timing, the per-port
//! configuration and the counters, read-only, in order, get-next across their boundaries.

use super::lldp::{get_gauge, get_int, get_str, lonely, one, walk};
use super::*;

const CONFIG: [u32; 8] = [1, 0, 8802, 1, 1, 2, 1, 1];
const PORT_CONFIG: [u32; 10] = [1, 0, 8802, 1, 1, 2, 1, 1, 6, 1];
const STATS: [u32; 8] = [1, 0, 8802, 1, 1, 2, 1, 2];
const STATS_TX: [u32; 10] = [1, 0, 8802, 1, 1, 2, 1, 2, 6, 1];
const STATS_RX: [u32; 10] = [1, 0, 8802, 1, 1, 2, 1, 2, 7, 1];

fn at(base: &[u32], tail: &[u32]) -> ber::Oid {
    let mut o = ber::Oid::from_arcs(base).unwrap();
    for &a in tail {
        o.push(a).unwrap();
    }
    o
}

fn get_tagged(d: &Device, o: &ber::Oid, tag: u8) -> u32 {
    let v = one(d, GET, o.arcs());
    assert_eq!(v.1, tag, "tag at {:?}", o.arcs());
    ber::decode_uint(&v.2[..v.3]).unwrap()
}

#[test]
fn p038_lldp_config_scalars_are_the_transmitters_timing() {
    let d = dev();
    let want = [(1, 5), (2, 4), (3, 2), (4, 1), (5, 5)];
    for (c, v) in want {
        assert_eq!(get_int(&d, at(&CONFIG, &[c, 0]).arcs()), v, "scalar {c}");
    }
    // no instance other than .0
    let v = one(&d, GET, at(&CONFIG, &[1, 1]).arcs());
    assert_eq!(v.1, 0x81);
}

#[test]
fn p038_lldp_port_config_table_is_tx_and_rx_without_notifications() {
    let d = dev();
    for port in 1..=2 {
        assert_eq!(get_int(&d, at(&PORT_CONFIG, &[2, port]).arcs()), 3);
        assert_eq!(get_int(&d, at(&PORT_CONFIG, &[3, port]).arcs()), 2);
        let (s, n) = get_str(&d, at(&PORT_CONFIG, &[4, port]).arcs());
        assert_eq!(&s[..n], &[0]);
    }
    let mut d2 = dev();
    d2.lldp.tlvs_tx = 0x60;
    let (s, n) = get_str(&d2, at(&PORT_CONFIG, &[4, 1]).arcs());
    assert_eq!(&s[..n], &[0x60]);
    // there is no port 3 (and no port 0)
    assert_eq!(one(&d, GET, at(&PORT_CONFIG, &[2, 3]).arcs()).1, 0x81);
    assert_eq!(one(&d, GET, at(&PORT_CONFIG, &[2, 0]).arcs()).1, 0x81);
}

#[test]
fn p038_lldp_config_is_read_only_not_writable() {
    let mut a = Agent::default();
    for o in [at(&CONFIG, &[1, 0]), at(&PORT_CONFIG, &[2, 1])] {
        let (q, n) = req(1, b"private", SET, 3, 0, 0, &[(o.arcs(), 2, &[30])]);
        let (r, ch) = run(&mut a, &q[..n]).unwrap();
        assert_eq!((r.status, r.index, ch), (err::NOT_WRITABLE, 1, false));
    }
}

#[test]
fn p038_lldp_statistics_scalars_and_port_counters() {
    let d = dev();
    assert_eq!(get_tagged(&d, &at(&STATS, &[1, 0]), 0x43), 1200);
    assert_eq!(get_gauge(&d, at(&STATS, &[2, 0]).arcs()), 3);
    assert_eq!(get_gauge(&d, at(&STATS, &[3, 0]).arcs()), 1);
    assert_eq!(get_gauge(&d, at(&STATS, &[4, 0]).arcs()), 0);
    assert_eq!(get_gauge(&d, at(&STATS, &[5, 0]).arcs()), 1);
    assert_eq!(get_tagged(&d, &at(&STATS_TX, &[2, 1]), 0x41), 17);
    assert_eq!(get_tagged(&d, &at(&STATS_TX, &[2, 2]), 0x41), 0);
    for (c, v) in [(2, 2), (3, 2), (4, 9), (5, 0), (6, 4)] {
        assert_eq!(get_tagged(&d, &at(&STATS_RX, &[c, 1]), 0x41), v, "rx column {c}");
        assert_eq!(get_tagged(&d, &at(&STATS_RX, &[c, 2]), 0x41), 0);
    }
    // lldpStatsRxPortAgeoutsTotal is a ZeroBasedCounter32 (Gauge32)
    assert_eq!(get_gauge(&d, at(&STATS_RX, &[7, 1]).arcs()), 1);
}

#[test]
fn p038_getnext_crosses_config_and_statistics_boundaries() {
    let d = lonely();
    let cases: [(ber::Oid, ber::Oid); 7] = [
        // from lldpObjects to the first scalar
        (at(&[1, 0, 8802, 1, 1, 2, 1], &[]), at(&CONFIG, &[1, 0])),
        // last scalar into the port config table
        (at(&CONFIG, &[5, 0]), at(&PORT_CONFIG, &[2, 1])),
        // end of the port config table: no man addr row without an IP, so statistics
        (at(&PORT_CONFIG, &[4, 2]), at(&STATS, &[1, 0])),
        (at(&STATS, &[5, 0]), at(&STATS_TX, &[2, 1])),
        (at(&STATS_TX, &[2, 2]), at(&STATS_RX, &[2, 1])),
        (at(&STATS_RX, &[2, 2]), at(&STATS_RX, &[3, 1])),
        // out of the statistics into the local system data
        (at(&STATS_RX, &[7, 2]), at(&[1, 0, 8802, 1, 1, 2, 1, 3], &[1, 0])),
    ];
    for (from, to) in cases {
        assert_eq!(
            one(&d, GET_NEXT, from.arcs()).0.arcs(),
            to.arcs(),
            "after {:?}",
            from.arcs()
        );
    }
    // with the IP, lldpConfigManAddrTable sits between the port config table and statistics
    let d = dev();
    let v = one(&d, GET_NEXT, at(&PORT_CONFIG, &[4, 2]).arcs());
    assert_eq!(
        v.0.arcs(),
        at(&[1, 0, 8802, 1, 1, 2, 1, 1, 7, 1, 1], &[1, 4, 192, 168, 0, 50]).arcs()
    );
    assert_eq!(walk(&d, &CONFIG), 5 + 6 + 1);
    assert_eq!(walk(&d, &STATS), 5 + 2 + 12);
}
