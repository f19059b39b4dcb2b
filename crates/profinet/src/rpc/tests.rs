use super::server::{CLIENT_ATTEMPTS, CLIENT_RETRY};
use super::uuid::{pnio_object, EPM_INTERFACE, PNIO_CONTROLLER_INTERFACE, PNIO_DEVICE_INTERFACE};
use super::*;
use crate::ip::{Endpoint, Ipv4Addr};
use std::vec::Vec;

pub(crate) fn hex(s: &str) -> Vec<u8> {
    let s: std::string::String = s.split_whitespace().collect();
    (0..s.len() / 2)
        .map(|i| u8::from_str_radix(&s[2 * i..2 * i + 2], 16).unwrap())
        .collect()
}

const PEER: Endpoint = Endpoint {
    ip: Ipv4Addr::new(192, 168, 0, 10),
    port: 50000,
};
const OUR_IP: Ipv4Addr = Ipv4Addr::new(192, 168, 0, 50);

fn server() -> Server<4096> {
    Server::new(ServerConfig {
        boot_time: 0x1234_5678,
        epm: epm::EpmInfo {
            object: pnio_object(1, 0x0001, 0xFEFE),
            ip: OUR_IP,
            port: 34964,
            annotation: epm::annotation("smartServo BL 4000", "BL4000-C", 1, (b'V', 1, 0, 0)),
        },
    })
}

/// A handler that echoes the body, or answers `len` bytes of pattern, and
/// records the client results.
#[derive(Default)]
struct Echo {
    calls: Vec<(u16, Vec<u8>)>,
    answer_len: Option<usize>,
    outgoing: Option<Vec<u8>>,
    results: Vec<Result<Vec<u8>, ClientError>>,
}

impl Handler for Echo {
    fn call(&mut self, _now: Nanos, call: &Call, body: &[u8], out: &mut [u8]) -> Result<usize, CallError> {
        self.calls.push((call.opnum, body.to_vec()));
        if call.opnum == opnum::CONTROL {
            return Err(CallError::Fault(nca::OUT_ARGS_TOO_BIG));
        }
        let n = self.answer_len.unwrap_or(body.len());
        for (i, o) in out.iter_mut().take(n).enumerate() {
            *o = body.get(i).copied().unwrap_or(i as u8);
        }
        Ok(n)
    }

    fn request(&mut self, _now: Nanos, body: &mut [u8]) -> Option<Request> {
        let b = self.outgoing.take()?;
        body[..b.len()].copy_from_slice(&b);
        Some(Request {
            peer: Endpoint {
                ip: PEER.ip,
                port: 34964,
            },
            object: Uuid([7; 16]),
            interface: PNIO_CONTROLLER_INTERFACE,
            opnum: opnum::CONTROL,
            body_len: b.len(),
        })
    }

    fn response(&mut self, _now: Nanos, result: Result<(Endian, &[u8]), ClientError>) {
        self.results.push(result.map(|(_, b)| b.to_vec()));
    }
}

fn drain(s: &mut Server<4096>) -> Vec<(Endpoint, Vec<u8>)> {
    let mut v = Vec::new();
    let mut out = [0u8; 1500];
    while let Some((p, n)) = s.transmit(Nanos::ZERO, &mut out) {
        v.push((p, out[..n].to_vec()));
    }
    v
}

fn request(iface: Uuid, op: u16, drep: Drep, seq: u32, frag: Option<(u16, bool)>, body: &[u8]) -> Vec<u8> {
    let (flags, frag_num) = match frag {
        None => (flags1::IDEMPOTENT, 0),
        Some((n, last)) => (
            flags1::IDEMPOTENT | flags1::FRAG | if last { flags1::LASTFRAG } else { 0 },
            n,
        ),
    };
    let h = Header {
        ptype: PacketType::Request,
        flags1: flags,
        flags2: 0,
        drep,
        serial: 0,
        object: pnio_object(1, 1, 0xFEFE),
        interface: iface,
        activity: Uuid([0xA5; 16]),
        boot_time: 0,
        if_version: 1,
        seq,
        opnum: op,
        if_hint: 0xFFFF,
        act_hint: 0xFFFF,
        body_len: body.len() as u16,
        frag_num,
        auth_proto: 0,
    };
    let mut b = std::vec![0u8; HEADER_LEN + body.len()];
    h.emit(&mut b).unwrap();
    b[HEADER_LEN..].copy_from_slice(body);
    b
}

/// profinet-py 0.6.6 `epm_lookup()`: little-endian drep, its short request
/// form (inquiry 0, nil UUIDs, 4-byte entry handle, max_ents 100).
const PY_EPM_LOOKUP: &str =
    "0400200010000000000000000000000000000000000000000883afe11f5dc91191a408002b14a0fa\
b0b1b2b3b4b5b6b7b8b9babbbcbdbebf0000000003000000000000000200ffffffff340000000000000000000000\
0000000000000000000000000000000000000000000000000000000000000000000000000000000000000064000000";

#[test]
fn p041_header_parses_both_byte_orders_and_round_trips() {
    let d = hex(PY_EPM_LOOKUP);
    let (h, body) = Header::parse(&d).unwrap();
    assert_eq!(h.drep.endian(), Endian::Little);
    assert_eq!(
        (h.ptype, h.interface, h.if_version, h.opnum, h.body_len),
        (PacketType::Request, EPM_INTERFACE, 3, 2, 52)
    );
    assert_eq!(body.len(), 52);
    let mut again = [0u8; 80];
    h.emit(&mut again).unwrap();
    assert_eq!(&again[..], &d[..80]);
    // The same header big-endian.
    let be = Header { drep: Drep::BIG, ..h };
    be.emit(&mut again).unwrap();
    assert_eq!(&again[24..28], &[0xE1, 0xAF, 0x83, 0x08]);
    assert_eq!(Header::parse(&[&again[..], body].concat()).unwrap().0, be);
    // Refusals.
    assert_eq!(Header::parse(&d[..79]), Err(HeaderError::Truncated));
    assert_eq!(Header::parse(&d[..100]), Err(HeaderError::Truncated));
    let mut v5 = d.clone();
    v5[0] = 5;
    assert_eq!(Header::parse(&v5), Err(HeaderError::Version));
    for n in 0..d.len() {
        let _ = Header::parse(&d[..n]);
    }
}

#[test]
fn p041_epm_lookup_returns_the_pnio_tower_then_no_more_entries() {
    let mut s = server();
    let mut h = Echo::default();
    s.receive(Nanos::ZERO, PEER, &hex(PY_EPM_LOOKUP), &mut h);
    let out = drain(&mut s);
    assert_eq!(out.len(), 1);
    let (hdr, body) = Header::parse(&out[0].1).unwrap();
    assert_eq!(
        (hdr.ptype, hdr.drep, hdr.seq, hdr.opnum, hdr.boot_time),
        (PacketType::Response, Drep::LITTLE, 0, 2, 0x1234_5678)
    );
    assert_eq!(
        hdr.activity,
        Uuid::from_fields(
            0xB3B2_B1B0,
            0xB5B4,
            0xB7B6,
            0xB8B9,
            [0xBA, 0xBB, 0xBC, 0xBD, 0xBE, 0xBF]
        )
    );
    // handle(20) num_ents max_count offset actual_count object(16) referent
    assert_eq!(&body[0..4], &[0; 4]);
    assert_eq!(&body[20..36], &hex("01000000 01000000 00000000 01000000")[..]);
    assert_eq!(&body[36..52], &pnio_object(1, 1, 0xFEFE).to_wire(Endian::Little));
    assert_eq!(&body[56..64], &hex("00000000 40000000")[..]);
    assert_eq!(&body[64..89], b"smartServo BL 4000       ");
    assert_eq!(body[127], 0);
    // tower: conformance, length, 5 floors; the first is the PNIO device interface v1.
    assert_eq!(&body[128..138], &hex("4b000000 4b000000 0500")[..]);
    assert_eq!(&body[138..143], &hex("1300 0d 0100a0de")[..5]);
    assert_eq!(&body[141..157], &PNIO_DEVICE_INTERFACE.to_wire(Endian::Little));
    assert_eq!(
        &body[188..211],
        &hex("0100 0a 0200 0000 0100 08 0200 8894 0100 09 0400 c0a80032")[..]
    );
    assert_eq!(&body[212..216], &[0; 4]); // status
    assert_eq!(body.len(), 216);
    // The continuation call with our handle: no more entries.
    let mut next = hex(PY_EPM_LOOKUP);
    let l = next.len();
    next[l - 24..l - 4].copy_from_slice(&body[0..20]);
    next[64] = 1; // seq 1
    s.receive(Nanos::ZERO, PEER, &next, &mut h);
    let out = drain(&mut s);
    let (_, body) = Header::parse(&out[0].1).unwrap();
    assert_eq!(
        body,
        &hex("00000000 00000000000000000000000000000000 00000000 00000000 00000000 00000000 d6a0c916")[..]
    );
    assert!(h.calls.is_empty());
}

#[test]
fn p041_unknown_interfaces_opnums_and_boot_times_are_rejected() {
    let mut s = server();
    let mut h = Echo::default();
    // `r` is rejected; the reject's status
    let rejected = |s: &mut Server<4096>, h: &mut Echo, r: &[u8]| {
        s.receive(Nanos::ZERO, PEER, r, h);
        let out = drain(s);
        let (hdr, body) = Header::parse(&out[0].1).unwrap();
        assert_eq!(hdr.ptype, PacketType::Reject);
        u32::from_be_bytes(body.try_into().unwrap())
    };
    let r = request(PNIO_CONTROLLER_INTERFACE, 0, Drep::BIG, 0, None, &[]);
    assert_eq!(rejected(&mut s, &mut h, &r), nca::UNK_IF);
    let r = request(PNIO_DEVICE_INTERFACE, 6, Drep::BIG, 1, None, &[]);
    assert_eq!(rejected(&mut s, &mut h, &r), nca::OP_RNG_ERROR);
    let mut r = request(PNIO_DEVICE_INTERFACE, 0, Drep::BIG, 2, None, &[]);
    r[56..60].copy_from_slice(&7u32.to_be_bytes());
    assert_eq!(rejected(&mut s, &mut h, &r), nca::WRONG_BOOT_TIME);
    assert!(h.calls.is_empty());
    assert_eq!(s.counters().rejects, 3);
    // A handler's fault travels as a fault PDU.
    s.receive(
        Nanos::ZERO,
        PEER,
        &request(PNIO_DEVICE_INTERFACE, opnum::CONTROL, Drep::BIG, 3, None, &[]),
        &mut h,
    );
    let out = drain(&mut s);
    let (hdr, body) = Header::parse(&out[0].1).unwrap();
    assert_eq!(
        (hdr.ptype, body),
        (PacketType::Fault, &nca::OUT_ARGS_TOO_BIG.to_be_bytes()[..])
    );
}

#[test]
fn p041_fragmented_requests_are_reassembled_and_acknowledged() {
    let mut s = server();
    let mut h = Echo {
        answer_len: Some(4),
        ..Echo::default()
    };
    let body: Vec<u8> = (0..2000u32).map(|i| i as u8).collect();
    for (n, chunk) in body.chunks(1000).enumerate() {
        let last = n == 1;
        s.receive(
            Nanos::ZERO,
            PEER,
            &request(
                PNIO_DEVICE_INTERFACE,
                0,
                Drep::LITTLE,
                9,
                Some((n as u16, last)),
                chunk,
            ),
            &mut h,
        );
        let out = drain(&mut s);
        let (f, fb) = Header::parse(&out[0].1).unwrap();
        assert_eq!((f.ptype, f.frag_num, fb.len()), (PacketType::Fack, n as u16, 16));
        if last {
            let (r, rb) = Header::parse(&out[1].1).unwrap();
            assert_eq!(
                (r.ptype, r.seq, r.drep, rb),
                (PacketType::Response, 9, Drep::LITTLE, &body[..4])
            );
        }
    }
    assert_eq!(h.calls, std::vec![(0, body.clone())]);
    // An out-of-order first fragment is dropped.
    s.receive(
        Nanos::ZERO,
        PEER,
        &request(PNIO_DEVICE_INTERFACE, 0, Drep::BIG, 10, Some((1, true)), &[1]),
        &mut h,
    );
    assert!(drain(&mut s).is_empty());
    // Too big for the buffer: a fault, nothing executed.
    let big = std::vec![0u8; 1400];
    for n in 0..3 {
        s.receive(
            Nanos::ZERO,
            PEER,
            &request(PNIO_DEVICE_INTERFACE, 0, Drep::BIG, 11, Some((n, n == 2)), &big),
            &mut h,
        );
    }
    let out = drain(&mut s);
    let (f, fb) = Header::parse(&out.last().unwrap().1).unwrap();
    assert_eq!(
        (f.ptype, fb),
        (PacketType::Fault, &nca::FAULT_REMOTE_NO_MEMORY.to_be_bytes()[..])
    );
    assert_eq!(h.calls.len(), 1);
}

#[test]
fn p041_large_responses_are_fragmented_and_resent_on_ping() {
    let mut s = server();
    let mut h = Echo {
        answer_len: Some(3000),
        ..Echo::default()
    };
    s.receive(
        Nanos::ZERO,
        PEER,
        &request(PNIO_DEVICE_INTERFACE, 2, Drep::BIG, 4, None, &[]),
        &mut h,
    );
    let out = drain(&mut s);
    assert_eq!(out.len(), 3);
    let mut all = Vec::new();
    for (k, (_, d)) in out.iter().enumerate() {
        assert!(d.len() <= MUST_RECV_FRAG_SIZE);
        let (hdr, body) = Header::parse(d).unwrap();
        assert_eq!(hdr.frag_num, k as u16);
        assert!(hdr.is_frag());
        assert_eq!(hdr.is_last_frag(), k == 2);
        all.extend_from_slice(body);
    }
    assert_eq!(all.len(), 3000);
    assert_eq!(all[1500], (1500 % 256) as u8);
    // A duplicate request or a ping resends it, without executing again.
    s.receive(
        Nanos::ZERO,
        PEER,
        &request(PNIO_DEVICE_INTERFACE, 2, Drep::BIG, 4, None, &[]),
        &mut h,
    );
    assert_eq!(drain(&mut s).len(), 3);
    let mut ping = request(PNIO_DEVICE_INTERFACE, 2, Drep::BIG, 4, None, &[]);
    ping[1] = 1;
    s.receive(Nanos::ZERO, PEER, &ping, &mut h);
    assert_eq!(drain(&mut s).len(), 3);
    assert_eq!(h.calls.len(), 1);
    // Ack frees it: a later ping finds no call.
    let mut ack = ping.clone();
    ack[1] = 7;
    s.receive(Nanos::ZERO, PEER, &ack, &mut h);
    s.receive(Nanos::ZERO, PEER, &ping, &mut h);
    let out = drain(&mut s);
    assert_eq!(Header::parse(&out[0].1).unwrap().0.ptype, PacketType::Nocall);
    // A request fragmented at 500 bytes gets 500-byte fragments back.
    let mut h = Echo {
        answer_len: Some(1000),
        ..Echo::default()
    };
    s.receive(
        Nanos::ZERO,
        PEER,
        &request(PNIO_DEVICE_INTERFACE, 2, Drep::BIG, 5, Some((0, true)), &[0; 420]),
        &mut h,
    );
    let out = drain(&mut s);
    assert_eq!(out.len(), 1 + 3); // fack + 420+420+160
    assert!(out[1..].iter().all(|(_, d)| d.len() <= 500));
}

#[test]
fn p041_device_client_call_is_sent_retried_and_acknowledged() {
    let mut s = server();
    let mut h = Echo {
        outgoing: Some(std::vec![1, 2, 3, 4]),
        ..Echo::default()
    };
    s.poll(Nanos::ZERO, &mut h);
    let out = drain(&mut s);
    assert_eq!(out.len(), 1);
    let (req, body) = Header::parse(&out[0].1).unwrap();
    assert_eq!(out[0].0.port, 34964);
    assert_eq!(
        (req.ptype, req.interface, req.opnum, req.drep, body),
        (
            PacketType::Request,
            PNIO_CONTROLLER_INTERFACE,
            4,
            Drep::LITTLE,
            &[1, 2, 3, 4][..]
        )
    );
    // Nothing before the retry time, then the same request again.
    s.poll(Nanos::from_ms(500), &mut h);
    assert!(drain(&mut s).is_empty());
    s.poll(CLIENT_RETRY, &mut h);
    let mut out = [0u8; 200];
    let (_, n) = s.transmit(CLIENT_RETRY, &mut out).unwrap();
    assert_eq!(Header::parse(&out[..n]).unwrap().0.seq, req.seq);
    // The controller's response (echoing our header, as profinet-py does).
    let mut resp = Header {
        ptype: PacketType::Response,
        flags1: 0x0A,
        body_len: 2,
        ..req
    };
    resp.boot_time = 0;
    let mut d = [0u8; 82];
    resp.emit(&mut d).unwrap();
    d[80..].copy_from_slice(&[9, 9]);
    s.receive(CLIENT_RETRY, PEER, &d, &mut h);
    assert_eq!(h.results, std::vec![Ok(std::vec![9, 9])]);
    let out = drain(&mut s);
    assert_eq!(Header::parse(&out[0].1).unwrap().0.ptype, PacketType::Ack);
    assert!(!s.client_busy());
    // A call nobody answers times out after CLIENT_ATTEMPTS transmissions.
    h.outgoing = Some(std::vec![5]);
    let mut t = Nanos::from_secs(10);
    let mut sent = 0;
    for _ in 0..20 {
        s.poll(t, &mut h);
        sent += drain(&mut s).len();
        t += CLIENT_RETRY;
    }
    assert_eq!(sent, CLIENT_ATTEMPTS as usize);
    assert_eq!(h.results[1], Err(ClientError::Timeout));
}
