//! The LLDP management address tables and the PROFINET and IEEE 802.3 extensions (P-038):
//! values, lexicographic order, get-next across table boundaries, and no remote rows without
//! a neighbour (or without the TLV that fills them).

use super::*;

const LLDP: [u32; 7] = [1, 0, 8802, 1, 1, 2, 1];
const CONFIG_MAN: [u32; 11] = [1, 0, 8802, 1, 1, 2, 1, 1, 7, 1, 1];
const LOC_MAN: [u32; 11] = [1, 0, 8802, 1, 1, 2, 1, 3, 8, 1, 3];
const REM_MAN: [u32; 11] = [1, 0, 8802, 1, 1, 2, 1, 4, 2, 1, 3];
const PNO_LOC: [u32; 14] = [1, 0, 8802, 1, 1, 2, 1, 5, 3791, 1, 2, 1, 1, 1];
const PNO_REM: [u32; 14] = [1, 0, 8802, 1, 1, 2, 1, 5, 3791, 1, 3, 1, 1, 1];
const DOT3_LOC: [u32; 14] = [1, 0, 8802, 1, 1, 2, 1, 5, 4623, 1, 2, 1, 1, 1];
const DOT3_REM: [u32; 14] = [1, 0, 8802, 1, 1, 2, 1, 5, 4623, 1, 3, 1, 1, 1];

/// `base` with its last arc (the column) replaced by `col`, then `inst`.
pub(super) fn oid(base: &[u32], col: u32, inst: &[u32]) -> ber::Oid {
    let mut o = ber::Oid::from_arcs(&base[..base.len() - 1]).unwrap();
    o.push(col).unwrap();
    for &a in inst {
        o.push(a).unwrap();
    }
    o
}

/// A get-next (or get) of one OID against `d`: (answered OID, tag, value).
pub(super) fn one(d: &Device, pdu: u8, o: &[u32]) -> (ber::Oid, u8, [u8; 64], usize) {
    let mut a = Agent::default();
    let (q, n) = req(1, b"public", pdu, 1, 0, 0, &[(o, 5, &[])]);
    let mut out = [0u8; 1500];
    let ans = a.handle(&q[..n], d, &mut out).unwrap();
    let r = resp(&out[..ans.len]);
    assert_eq!((r.status, r.n), (0, 1));
    r.vbs[0]
}

pub(super) fn get_int(d: &Device, o: &[u32]) -> i32 {
    let v = one(d, GET, o);
    assert_eq!(v.1, 2, "INTEGER at {o:?}");
    ber::decode_int(&v.2[..v.3]).unwrap()
}

pub(super) fn get_gauge(d: &Device, o: &[u32]) -> u32 {
    let v = one(d, GET, o);
    assert_eq!(v.1, 0x42, "Unsigned32 at {o:?}");
    ber::decode_uint(&v.2[..v.3]).unwrap()
}

pub(super) fn get_str(d: &Device, o: &[u32]) -> ([u8; 64], usize) {
    let v = one(d, GET, o);
    assert_eq!(v.1, 4, "OCTET STRING at {o:?}");
    (v.2, v.3)
}

/// Every instance under `prefix` by get-next, strictly increasing.
pub(super) fn walk(d: &Device, prefix: &[u32]) -> usize {
    let mut cur = ber::Oid::from_arcs(prefix).unwrap();
    let mut n = 0;
    loop {
        let (o, t, _, _) = one(d, GET_NEXT, cur.arcs());
        if t == 0x82 || !o.arcs().starts_with(prefix) {
            return n;
        }
        assert!(o.arcs() > cur.arcs(), "{:?} after {:?}", o.arcs(), cur.arcs());
        cur = o;
        n += 1;
    }
}

/// No IP, no neighbours.
pub(super) fn lonely() -> Device<'static> {
    let mut d = dev();
    d.neighbors = [None, None];
    d.man_addr = None;
    d
}

#[test]
fn p038_loc_man_addr_table_is_the_interface_ipv4() {
    let d = dev();
    let inst = [1, 4, 192, 168, 0, 50];
    // lldpLocManAddrLen 5 (subtype + 4 octets), ifIndex numbering, interface 1
    assert_eq!(get_int(&d, oid(&LOC_MAN, 3, &inst).arcs()), 5);
    assert_eq!(get_int(&d, oid(&LOC_MAN, 4, &inst).arcs()), 2);
    assert_eq!(get_int(&d, oid(&LOC_MAN, 5, &inst).arcs()), 1);
    let v = one(&d, GET, oid(&LOC_MAN, 6, &inst).arcs());
    assert_eq!(
        (v.1, &v.2[..v.3]),
        (6, &[0u8][..]),
        "lldpLocManAddrOID zeroDotZero"
    );
    // the first instance after the table's entry is the length column's row
    let v = one(&d, GET_NEXT, &[1, 0, 8802, 1, 1, 2, 1, 3, 8]);
    assert_eq!(v.0.arcs(), oid(&LOC_MAN, 3, &inst).arcs());
    // another address is no instance
    let v = one(&d, GET, oid(&LOC_MAN, 3, &[1, 4, 192, 168, 0, 51]).arcs());
    assert_eq!(v.1, 0x81);
    // lldpConfigManAddrPortsTxEnable, same index: both ports send it (ports 1 and 2: 0xC0)
    let (s, n) = get_str(&d, &[&CONFIG_MAN[..], &inst].concat());
    assert_eq!(&s[..n], &[0xc0]);
    // the walk reaches it from the end of lldpPortConfigTable
    let v = one(&d, GET_NEXT, &[1, 0, 8802, 1, 1, 2, 1, 1, 6, 1, 4, 2]);
    assert_eq!(v.0.arcs(), &[&CONFIG_MAN[..], &inst].concat()[..]);
}

#[test]
fn p038_without_ip_the_loc_man_addr_table_is_empty_and_getnext_skips_it() {
    let mut d = dev();
    d.man_addr = None;
    assert_eq!(walk(&d, &[1, 0, 8802, 1, 1, 2, 1, 3, 8]), 0);
    assert_eq!(walk(&d, &[1, 0, 8802, 1, 1, 2, 1, 1, 7]), 0);
    // the last lldpLocPortDesc is followed by the first lldpRemTable cell
    let v = one(&d, GET_NEXT, &[1, 0, 8802, 1, 1, 2, 1, 3, 7, 1, 4, 2]);
    assert_eq!(v.0.arcs(), &[1, 0, 8802, 1, 1, 2, 1, 4, 1, 1, 4, 0, 1, 1]);
}

#[test]
fn p038_rem_man_addr_row_is_the_neighbours_address() {
    let d = dev();
    let inst = [0, 1, 1, 1, 4, 10, 0, 0, 1];
    assert_eq!(get_int(&d, oid(&REM_MAN, 3, &inst).arcs()), 3);
    assert_eq!(get_int(&d, oid(&REM_MAN, 4, &inst).arcs()), 9);
    assert_eq!(walk(&d, &[1, 0, 8802, 1, 1, 2, 1, 4, 2]), 3);
    // a neighbour that sent no address has no row
    let mut d = dev();
    if let Some(n) = d.neighbors[0].as_mut() {
        n.man_addr = None;
    }
    assert_eq!(walk(&d, &[1, 0, 8802, 1, 1, 2, 1, 4, 2]), 0);
    assert_eq!(walk(&d, &[1, 0, 8802, 1, 1, 2, 1, 4, 1]), 5);
}

#[test]
fn p038_pno_loc_table_has_each_ports_delays_status_and_the_name_of_station() {
    let d = dev();
    assert_eq!(walk(&d, &[1, 0, 8802, 1, 1, 2, 1, 5, 3791, 1, 2]), 12);
    for (port, tx) in [(1, 11), (2, 12)] {
        assert_eq!(get_gauge(&d, oid(&PNO_LOC, 1, &[port]).arcs()), 0);
        assert_eq!(get_gauge(&d, oid(&PNO_LOC, 2, &[port]).arcs()), tx);
        assert_eq!(get_gauge(&d, oid(&PNO_LOC, 3, &[port]).arcs()), 7);
        assert_eq!(get_int(&d, oid(&PNO_LOC, 4, &[port]).arcs()), 0);
        assert_eq!(get_int(&d, oid(&PNO_LOC, 5, &[port]).arcs()), 0);
        let (s, n) = get_str(&d, oid(&PNO_LOC, 6, &[port]).arcs());
        assert_eq!(&s[..n], b"drive-1");
    }
    assert_eq!(one(&d, GET, oid(&PNO_LOC, 1, &[3]).arcs()).1, 0x81);
    // column order: LPD of port 2 comes before port Tx delay of port 1
    let v = one(&d, GET_NEXT, oid(&PNO_LOC, 1, &[1]).arcs());
    assert_eq!(v.0.arcs(), oid(&PNO_LOC, 1, &[2]).arcs());
    let v = one(&d, GET_NEXT, oid(&PNO_LOC, 1, &[2]).arcs());
    assert_eq!(v.0.arcs(), oid(&PNO_LOC, 2, &[1]).arcs());
}

#[test]
fn p038_pno_rem_table_is_what_the_neighbour_sent() {
    let d = dev();
    let inst = [0, 1, 1];
    assert_eq!(walk(&d, &[1, 0, 8802, 1, 1, 2, 1, 5, 3791, 1, 3]), 6);
    assert_eq!(get_gauge(&d, oid(&PNO_REM, 1, &inst).arcs()), 55);
    assert_eq!(get_gauge(&d, oid(&PNO_REM, 2, &inst).arcs()), 1123);
    assert_eq!(get_gauge(&d, oid(&PNO_REM, 3, &inst).arcs()), 444);
    assert_eq!(get_int(&d, oid(&PNO_REM, 4, &inst).arcs()), 2);
    assert_eq!(get_int(&d, oid(&PNO_REM, 5, &inst).arcs()), 0);
    let (s, n) = get_str(&d, oid(&PNO_REM, 6, &inst).arcs());
    assert_eq!(&s[..n], b"plc");
    // port 2 has no neighbour
    assert_eq!(one(&d, GET, oid(&PNO_REM, 1, &[0, 2, 1]).arcs()).1, 0x81);
    // a neighbour without PROFINET TLVs (a plain switch) has an lldpRemTable row only
    let mut d = dev();
    if let Some(n) = d.neighbors[0].as_mut() {
        n.pno = None;
    }
    assert_eq!(walk(&d, &[1, 0, 8802, 1, 1, 2, 1, 5, 3791, 1, 3]), 0);
    assert_eq!(walk(&d, &[1, 0, 8802, 1, 1, 2, 1, 4, 1]), 5);
}

#[test]
fn p038_dot3_tables_have_autoneg_advertised_and_mau_type() {
    let d = dev();
    assert_eq!(walk(&d, &[1, 0, 8802, 1, 1, 2, 1, 5, 4623, 1, 2]), 8);
    for (port, mau) in [(1, 16), (2, 0)] {
        assert_eq!(get_int(&d, oid(&DOT3_LOC, 1, &[port]).arcs()), 1);
        assert_eq!(get_int(&d, oid(&DOT3_LOC, 2, &[port]).arcs()), 1);
        let (s, n) = get_str(&d, oid(&DOT3_LOC, 3, &[port]).arcs());
        assert_eq!(&s[..n], &[0x6c, 0x00]);
        assert_eq!(get_int(&d, oid(&DOT3_LOC, 4, &[port]).arcs()), mau);
    }
    let inst = [0, 1, 1];
    assert_eq!(walk(&d, &[1, 0, 8802, 1, 1, 2, 1, 5, 4623, 1, 3]), 4);
    // supported (true 1), not enabled (false 2)
    assert_eq!(get_int(&d, oid(&DOT3_REM, 1, &inst).arcs()), 1);
    assert_eq!(get_int(&d, oid(&DOT3_REM, 2, &inst).arcs()), 2);
    let (s, n) = get_str(&d, oid(&DOT3_REM, 3, &inst).arcs());
    assert_eq!(&s[..n], &[0x04, 0x00]);
    assert_eq!(get_int(&d, oid(&DOT3_REM, 4, &inst).arcs()), 30);
    // the last 802.3 cell is followed by MIB-II's sysDescr.0
    let v = one(&d, GET_NEXT, oid(&DOT3_REM, 4, &inst).arcs());
    assert_eq!(v.0.arcs(), &[1, 3, 6, 1, 2, 1, 1, 1, 0]);
}

#[test]
fn p038_without_neighbours_no_remote_rows_and_getnext_crosses_tables() {
    let d = lonely();
    for t in [
        &[1, 0, 8802, 1, 1, 2, 1, 4][..],
        &[1, 0, 8802, 1, 1, 2, 1, 5, 3791, 1, 3],
        &[1, 0, 8802, 1, 1, 2, 1, 5, 4623, 1, 3],
        &[1, 0, 8802, 1, 1, 2, 1, 3, 8],
        &[1, 0, 8802, 1, 1, 2, 1, 1, 7],
    ] {
        assert_eq!(walk(&d, t), 0, "{t:?}");
    }
    // 5 config scalars, 6 port config, 5 stats scalars, 2 tx and 12 rx stats cells;
    // 4 scalars, 6 local port, 12 PROFINET and 8 802.3 local cells
    assert_eq!(walk(&d, &LLDP), 5 + 6 + 5 + 2 + 12 + 4 + 6 + 12 + 8);
    // from the local port table straight into the PROFINET local table
    let v = one(&d, GET_NEXT, &[1, 0, 8802, 1, 1, 2, 1, 3, 7, 1, 4, 2]);
    assert_eq!(v.0.arcs(), oid(&PNO_LOC, 1, &[1]).arcs());
    // from the last PROFINET local cell into the 802.3 local table
    let v = one(&d, GET_NEXT, oid(&PNO_LOC, 6, &[2]).arcs());
    assert_eq!(v.0.arcs(), oid(&DOT3_LOC, 1, &[1]).arcs());
    // and from the last 802.3 local cell out of LLDP-MIB
    let v = one(&d, GET_NEXT, oid(&DOT3_LOC, 4, &[2]).arcs());
    assert_eq!(v.0.arcs(), &[1, 3, 6, 1, 2, 1, 1, 1, 0]);
}

#[test]
fn p038_whole_lldp_walk_with_neighbours_on_both_ports_never_repeats() {
    let mut d = dev();
    d.neighbors[1] = d.neighbors[0];
    // rows of port 1 come before rows of port 2 in every remote column
    let v = one(&d, GET_NEXT, oid(&PNO_REM, 6, &[0, 1, 1]).arcs());
    assert_eq!(v.0.arcs(), oid(&PNO_REM, 6, &[0, 2, 1]).arcs());
    let v = one(
        &d,
        GET_NEXT,
        oid(&REM_MAN, 3, &[0, 1, 1, 1, 4, 10, 0, 0, 1]).arcs(),
    );
    assert_eq!(v.0.arcs(), oid(&REM_MAN, 3, &[0, 2, 1, 1, 4, 10, 0, 0, 1]).arcs());
    // 5 + 6 config, 1 config man addr, 5 + 2 + 12 statistics, 4 + 6 + 4 local;
    // 2x(5 + 3) remote; 12 + 2x6 PROFINET; 8 + 2x4 802.3
    assert_eq!(
        walk(&d, &LLDP),
        5 + 6 + 1 + 5 + 2 + 12 + 4 + 6 + 4 + 16 + 12 + 12 + 8 + 8
    );
}

/// P-038: lldpLocChassisIdSubtype/lldpLocChassisId say what the LLDPDU's
/// chassis ID TLV sends: the NameOfStation as local(7) once the device is
/// named, the interface MAC as macAddress(4) before (a topology tool compares
/// the neighbours' LLDPDUs with these).
#[test]
fn p038_loc_chassis_id_is_what_the_lldpdu_sends() {
    let named = dev();
    let subtype = [1, 0, 8802, 1, 1, 2, 1, 3, 1, 0];
    let id = [1, 0, 8802, 1, 1, 2, 1, 3, 2, 0];
    assert_eq!(get_int(&named, &subtype), 7);
    let v = one(&named, GET, &id);
    assert_eq!((v.1, &v.2[..v.3]), (4, &b"drive-1"[..]));
    let unnamed = Device {
        name_of_station: b"",
        ..dev()
    };
    assert_eq!(get_int(&unnamed, &subtype), 4);
    let v = one(&unnamed, GET, &id);
    assert_eq!((v.1, &v.2[..v.3]), (4, &[2u8, 0, 0, 0, 0, 1][..]));
}
