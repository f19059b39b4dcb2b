//! The SNMP agent (crates/snmp, P-038) with BER-encoded get, get-next,
//! get-bulk and set requests built from the input: version v1 or v2c, a
//! community (read, write, another, or bytes from the input), bindings whose
//! OIDs lie in, near and outside the MIB view (a chosen prefix plus arcs from
//! the input) with any value, then one byte of the encoded request changed at
//! a position the input chooses. Nothing may panic, and
//! - every answer is well-formed BER (one SEQUENCE: version, community,
//!   Response-PDU with request-id, error-status, error-index and a list of
//!   SEQUENCE { OID, value } with nothing left over) carrying the request's id;
//! - the agent's kept state changes only through a set (PDU tag 0xA3) with
//!   the write community, only in sysContact/sysName/sysLocation, and
//!   `Answer::changed` says so exactly.
#![no_main]

use libfuzzer_sys::fuzz_target;
use snmp::ber::{Reader, Writer};
use snmp::{message, Agent, Device};

const PREFIXES: &[&[u32]] = &[
    &[1, 3, 6, 1, 2, 1, 1],
    &[1, 3, 6, 1, 2, 1, 1, 5],
    &[1, 3, 6, 1, 2, 1, 1, 4, 0],
    &[1, 3, 6, 1, 2, 1, 1, 6, 0],
    &[1, 3, 6, 1, 2, 1, 2, 2, 1],
    &[1, 3, 6, 1, 2, 1, 2],
    &[1, 0, 8802, 1, 1, 2, 1, 3],
    &[1, 0, 8802, 1, 1, 2, 1, 4, 1, 1],
    &[1, 0, 8802, 1, 1, 2, 1, 1, 7, 1, 1, 1, 4],
    &[1, 0, 8802, 1, 1, 2, 1, 3, 8, 1, 3, 1, 4],
    &[1, 0, 8802, 1, 1, 2, 1, 4, 2, 1, 3, 0, 2, 1],
    &[1, 0, 8802, 1, 1, 2, 1, 5, 3791, 1, 2, 1, 1],
    &[1, 0, 8802, 1, 1, 2, 1, 5, 3791, 1, 3, 1, 1, 6, 0],
    &[1, 0, 8802, 1, 1, 2, 1, 5, 4623, 1, 2, 1, 1],
    &[1, 0, 8802, 1, 1, 2, 1, 5, 4623, 1, 3, 1, 1, 4, 0, 2],
    &[1, 3, 6, 1, 2, 1, 3],
    &[1, 3, 6, 1, 4, 1],
    &[0],
    &[2, 999],
    &[1, 3, 6, 1, 2, 1, 1, 7, 0, 1],
    &[],
];
const PDUS: [u8; 6] = [0xa0, 0xa1, 0xa5, 0xa3, 0xa3, 0xa2];

/// `snmp::testing`'s device with its neighbour on port 2 and port 1 empty (the
/// remote-table prefixes above name port 2).
fn device() -> Device<'static> {
    let mut d = snmp::testing::device();
    d.neighbors.swap(0, 1);
    d
}

/// The request's community, PDU tag and id as sent (after the byte change).
fn sent(msg: &[u8]) -> Option<(&[u8], u8, i32)> {
    let mut r = Reader::new(msg);
    let mut m = Reader::new(r.expect(0x30)?);
    m.int()?;
    let c = m.expect(4)?;
    let (tag, p) = m.tlv()?;
    Some((c, tag, Reader::new(p).int()?))
}

fn well_formed(ans: &[u8], id: i32) {
    let mut r = Reader::new(ans);
    let mut m = Reader::new(r.expect(0x30).expect("answer is a SEQUENCE"));
    assert!(r.is_empty(), "bytes after the message");
    m.int().expect("version");
    m.expect(4).expect("community");
    let mut p = Reader::new(m.expect(0xa2).expect("Response-PDU"));
    assert!(m.is_empty());
    assert_eq!(p.int(), Some(id), "the request's id");
    p.int().expect("error-status");
    p.int().expect("error-index");
    let mut l = Reader::new(p.expect(0x30).expect("binding list"));
    assert!(p.is_empty());
    while !l.is_empty() {
        let mut vb = Reader::new(l.expect(0x30).expect("binding"));
        vb.oid().expect("binding OID");
        vb.tlv().expect("binding value");
        assert!(vb.is_empty(), "bytes after a binding's value");
    }
}

fuzz_target!(|data: &[u8]| {
    let mut it = data.iter().copied();
    let mut next = || it.next().unwrap_or(0);
    let head = next();
    let version = i32::from(head & 1);
    let pdu = PDUS[usize::from(head >> 1) % PDUS.len()];
    let (a, b) = (i32::from(next() as i8), i32::from(next() as i8));
    let id = i32::from_le_bytes([next(), next(), next(), next()]);
    let mut community = [0u8; 8];
    let c: &[u8] = match next() % 4 {
        0 => b"public",
        1 => b"private",
        2 => b"privat",
        _ => {
            for x in community.iter_mut() {
                *x = next();
            }
            &community[..usize::from(next()) % 9]
        }
    };
    let mut msg = [0u8; 1600];
    let mut w = Writer::new(&mut msg);
    message(&mut w, version, c, pdu, [id, a, b], |w| {
        let l = w.open(0x30);
        for _ in 0..usize::from(next() % 6) {
            let sel = next();
            let mut oid = [0u32; 24];
            let pre = PREFIXES[usize::from(sel) % PREFIXES.len()];
            oid[..pre.len()].copy_from_slice(pre);
            let extra = usize::from(next() % 4);
            for k in 0..extra {
                let x = next();
                oid[pre.len() + k] = if x > 250 { u32::from_le_bytes([next(), next(), next(), next()]) } else { u32::from(x % 12) };
            }
            let m = w.open(0x30);
            w.oid(&oid[..pre.len() + extra]);
            let tag = [4u8, 5, 2, 6, 0x40, 0x43, 4, 4][usize::from(next() % 8)];
            let len = usize::from(next()) + if next() & 1 == 1 { 200 } else { 0 };
            let mut v = [0u8; 512];
            for x in v.iter_mut().take(len.min(8)) {
                *x = next();
            }
            w.prim(tag, &v[..len]);
            w.close(m);
        }
        w.close(l);
    });
    let Some(n) = w.finish() else { return };
    let (pos, flip) = (u16::from_le_bytes([next(), next()]), next());
    if flip != 0 {
        msg[usize::from(pos) % n] ^= flip;
    }
    let msg = &msg[..n];

    let mut agent = Agent::default();
    let _ = agent.sys_name;
    let before = agent.clone();
    let mut out = [0u8; 1500];
    let size = usize::from(next()) * 8 + 40;
    let out = &mut out[..size.min(1500)];
    let ans = agent.handle(msg, &device(), out);
    let changed = before.sys_contact != agent.sys_contact
        || before.sys_name != agent.sys_name
        || before.sys_location != agent.sys_location;
    assert_eq!(before.read_community, agent.read_community);
    assert_eq!(before.write_community, agent.write_community);
    match ans {
        None => assert!(!changed, "a dropped request changed the agent"),
        Some(ans) => {
            let (c, tag, id) = sent(msg).expect("an answered request parses");
            well_formed(&out[..ans.len], id);
            assert_eq!(ans.changed, changed, "Answer::changed tells the truth");
            if changed {
                assert_eq!(tag, 0xa3, "only a set changes the agent");
                assert_eq!(c, b"private", "only the write community sets");
            }
        }
    }
});
