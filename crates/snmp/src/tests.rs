//! RFC behaviour of the agent (spec P-038).
#![allow(clippy::indexing_slicing, clippy::unwrap_used, clippy::type_complexity)]

use super::*;
use crate::testing::device as dev;

mod lldp;
mod lldp_config;

/// A request: version, community, pdu tag, id, a, b, bindings (oid, tag, value).
fn req(
    v: i32,
    c: &[u8],
    pdu: u8,
    id: i32,
    a: i32,
    b: i32,
    vbs: &[(&[u32], u8, &[u8])],
) -> ([u8; 1600], usize) {
    let mut buf = [0u8; 1600];
    let mut w = Writer::new(&mut buf);
    message(&mut w, v, c, pdu, [id, a, b], |w| {
        let l = w.open(0x30);
        for (o, tag, val) in vbs {
            let m = w.open(0x30);
            w.oid(o);
            w.prim(*tag, val);
            w.close(m);
        }
        w.close(l);
    });
    let n = w.finish().unwrap();
    (buf, n)
}

/// Decoded response: id, status, index, bindings.
struct Resp {
    id: i32,
    status: i32,
    index: i32,
    vbs: [(ber::Oid, u8, [u8; 64], usize); 40],
    n: usize,
}

fn resp(b: &[u8]) -> Resp {
    let mut r = Reader::new(b);
    let mut m = Reader::new(r.expect(0x30).unwrap());
    assert!(r.is_empty());
    m.int().unwrap();
    m.expect(4).unwrap();
    let mut p = Reader::new(m.expect(RESPONSE).unwrap());
    let (id, status, index) = (p.int().unwrap(), p.int().unwrap(), p.int().unwrap());
    let mut out = Resp {
        id,
        status,
        index,
        vbs: [(ber::Oid::empty(), 0, [0; 64], 0); 40],
        n: 0,
    };
    for (o, t, v) in varbinds(p.expect(0x30).unwrap()) {
        let k = v.len().min(64);
        out.vbs[out.n].0 = o;
        out.vbs[out.n].1 = t;
        out.vbs[out.n].2[..k].copy_from_slice(&v[..k]);
        out.vbs[out.n].3 = k;
        out.n += 1;
    }
    out
}

fn run(a: &mut Agent, q: &[u8]) -> Option<(Resp, bool)> {
    let mut out = [0u8; 1500];
    let ans = a.handle(q, &dev(), &mut out)?;
    Some((resp(&out[..ans.len]), ans.changed))
}

const SYSDESCR: &[u32] = &[1, 3, 6, 1, 2, 1, 1, 1, 0];
const SYSNAME: &[u32] = &[1, 3, 6, 1, 2, 1, 1, 5, 0];

#[test]
fn p038_objects_are_in_oid_order() {
    for w in mib::OBJECTS.windows(2) {
        let (a, b) = (mib::full(&w[0], &[]).unwrap(), mib::full(&w[1], &[]).unwrap());
        assert!(a.arcs() < b.arcs(), "{:?} !< {:?}", a.arcs(), b.arcs());
        // no object's OID is a prefix of another's (instances could collide)
        assert!(!b.arcs().starts_with(a.arcs()));
    }
}

#[test]
fn p038_get_answers_sysdescr_and_uptime() {
    let mut a = Agent::default();
    let (q, n) = req(
        1,
        b"public",
        GET,
        7,
        0,
        0,
        &[(SYSDESCR, 5, &[]), (&[1, 3, 6, 1, 2, 1, 1, 3, 0], 5, &[])],
    );
    let (r, ch) = run(&mut a, &q[..n]).unwrap();
    assert_eq!((r.id, r.status, r.n, ch), (7, 0, 2, false));
    assert_eq!(&r.vbs[0].2[..r.vbs[0].3], b"drive");
    assert_eq!(
        (r.vbs[1].1, ber::decode_uint(&r.vbs[1].2[..r.vbs[1].3])),
        (0x43, Some(4242))
    );
}

#[test]
fn p038_get_missing_is_nosuchobject_or_instance_v2c_and_nosuchname_v1() {
    let mut a = Agent::default();
    let (q, n) = req(
        1,
        b"public",
        GET,
        1,
        0,
        0,
        &[(&[1, 3, 6, 1, 2, 1, 1, 1, 1], 5, &[]), (&[1, 3, 6, 1, 9], 5, &[])],
    );
    let (r, _) = run(&mut a, &q[..n]).unwrap();
    assert_eq!((r.status, r.vbs[0].1, r.vbs[1].1), (0, 0x81, 0x80));
    let (q, n) = req(
        0,
        b"public",
        GET,
        1,
        0,
        0,
        &[(SYSDESCR, 5, &[]), (&[1, 3, 6, 1, 9], 5, &[])],
    );
    let (r, _) = run(&mut a, &q[..n]).unwrap();
    assert_eq!((r.status, r.index, r.n), (err::NO_SUCH_NAME, 2, 2));
}

#[test]
fn p038_walk_is_strictly_increasing_and_ends_with_end_of_mib_view() {
    let mut a = Agent::default();
    let mut cur = ber::Oid::from_arcs(&[0]).unwrap();
    let mut count = 0;
    loop {
        let (q, n) = req(1, b"public", GET_NEXT, count, 0, 0, &[(cur.arcs(), 5, &[])]);
        let (r, _) = run(&mut a, &q[..n]).unwrap();
        if r.vbs[0].1 == 0x82 {
            break;
        }
        assert!(r.vbs[0].0.arcs() > cur.arcs());
        cur = r.vbs[0].0;
        count += 1;
    }
    // 5 lldpConfiguration scalars, 3x2 port config cells, lldpConfigManAddrPortsTxEnable,
    // 5 lldpStatistics scalars, 2 tx and 6x2 rx port counters, 4 local LLDP scalars, 3x2 local port cells, 4 local
    // management address cells,
    // 5 remote cells (one neighbour), 3 remote management address cells, 6x2 local and 6
    // remote PROFINET cells, 4x2 local and 4 remote 802.3 cells, 7 system, ifNumber, 8x3 ifTable
    assert_eq!(
        count,
        5 + 6 + 1 + 5 + 2 + 12 + 4 + 6 + 4 + 5 + 3 + 12 + 6 + 8 + 4 + 7 + 1 + 24
    );
    let (q, n) = req(0, b"public", GET_NEXT, 9, 0, 0, &[(cur.arcs(), 5, &[])]);
    let (r, _) = run(&mut a, &q[..n]).unwrap();
    assert_eq!((r.status, r.index), (err::NO_SUCH_NAME, 1));
}

#[test]
fn p038_set_needs_write_community_and_is_kept() {
    let mut a = Agent::default();
    let (q, n) = req(1, b"public", SET, 3, 0, 0, &[(SYSNAME, 4, b"x")]);
    assert!(run(&mut a, &q[..n]).is_none());
    assert_eq!(a.sys_name.get(), b"");
    let (q, n) = req(1, b"private", SET, 3, 0, 0, &[(SYSNAME, 4, b"axis-1")]);
    let (r, ch) = run(&mut a, &q[..n]).unwrap();
    assert_eq!((r.status, ch), (0, true));
    assert_eq!(a.sys_name.get(), b"axis-1");
    let (q, n) = req(1, b"nope", GET, 3, 0, 0, &[(SYSNAME, 5, &[])]);
    assert!(run(&mut a, &q[..n]).is_none());
}

#[test]
fn p038_set_errors_change_nothing() {
    let mut a = Agent::default();
    let cases: [(i32, &[u32], u8, &[u8], i32); 5] = [
        (1, SYSDESCR, 4, b"x", err::NOT_WRITABLE),
        (0, SYSDESCR, 4, b"x", err::READ_ONLY),
        (1, SYSNAME, 2, &[1], err::WRONG_TYPE),
        (1, SYSNAME, 4, &[b'a'; 256], err::WRONG_LENGTH),
        (1, &[1, 3, 6, 1, 2, 1, 1, 5, 1], 4, b"x", err::NO_CREATION),
    ];
    for (v, o, t, val, e) in cases {
        // a good binding first: the whole set must fail atomically
        let (q, n) = req(
            v,
            b"private",
            SET,
            5,
            0,
            0,
            &[(&[1, 3, 6, 1, 2, 1, 1, 4, 0], 4, b"c"), (o, t, val)],
        );
        let (r, ch) = run(&mut a, &q[..n]).unwrap();
        assert_eq!((r.status, r.index, ch), (e, 2, false));
        assert_eq!(a.sys_contact.get(), b"");
    }
}

#[test]
fn p038_get_bulk_repeats_and_truncates() {
    let mut a = Agent::default();
    let (q, n) = req(
        1,
        b"public",
        GET_BULK,
        4,
        1,
        3,
        &[
            (&[1, 3, 6, 1, 2, 1, 1], 5, &[]),
            (&[1, 3, 6, 1, 2, 1, 2, 2, 1, 2], 5, &[]),
        ],
    );
    let (r, _) = run(&mut a, &q[..n]).unwrap();
    assert_eq!((r.status, r.n), (0, 4));
    assert_eq!(r.vbs[3].0.arcs(), &[1, 3, 6, 1, 2, 1, 2, 2, 1, 2, 3]);
    let (q, n) = req(1, b"public", GET_BULK, 4, 0, 1000, &[(&[0], 5, &[])]);
    let mut out = [0u8; 300];
    let ans = a.handle(&q[..n], &dev(), &mut out).unwrap();
    let r = resp(&out[..ans.len]);
    assert!(r.status == 0 && r.n > 3 && r.n < 20);
}

#[test]
fn p038_too_big_answers_empty_list() {
    let mut a = Agent::default();
    let (q, n) = req(1, b"public", GET, 11, 0, 0, &[(SYSDESCR, 5u8, &[][..]); 8]);
    let mut out = [0u8; 60];
    let ans = a.handle(&q[..n], &dev(), &mut out).unwrap();
    let r = resp(&out[..ans.len]);
    assert_eq!((r.id, r.status, r.n), (11, err::TOO_BIG, 0));
}

#[test]
fn p038_malformed_is_dropped() {
    let mut a = Agent::default();
    let (q, n) = req(1, b"private", SET, 3, 0, 0, &[(SYSNAME, 4, b"y")]);
    for cut in 0..n {
        assert!(a.handle(&q[..cut], &dev(), &mut [0u8; 1500]).is_none());
    }
    let (q, n) = req(3, b"public", GET, 3, 0, 0, &[(SYSNAME, 5, &[])]);
    assert!(a.handle(&q[..n], &dev(), &mut [0u8; 1500]).is_none());
    assert_eq!(a.sys_name.get(), b"");
}

#[test]
fn p038_a_set_that_writes_back_the_old_value_reports_no_change() {
    let mut a = Agent::default();
    let (q, n) = req(
        1,
        b"private",
        SET,
        3,
        0,
        0,
        &[(SYSNAME, 4, b"x"), (SYSNAME, 4, b"")],
    );
    let (r, ch) = run(&mut a, &q[..n]).unwrap();
    assert_eq!((r.status, ch), (0, false));
    assert_eq!(a.sys_name.get(), b"");
}
