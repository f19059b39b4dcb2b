extern crate std;
use super::*;
use std::vec::Vec;

fn frame(n: usize) -> Vec<u8> {
    (0..n).map(|i| (i * 7 + 3) as u8).collect()
}

/// Splits `f` as a master would: fragments of `chunk` bytes (a multiple of 32).
pub(crate) fn fragments(f: &[u8], chunk: usize, frame_no: u8) -> Vec<(EoeHeader, Vec<u8>)> {
    let chunks: Vec<&[u8]> = f.chunks(chunk).collect();
    let n = chunks.len();
    chunks
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let so = if i == 0 {
                f.len().div_ceil(32)
            } else {
                i * chunk / 32
            };
            (
                EoeHeader::fragment(i + 1 == n, i as u8, so as u8, frame_no),
                c.to_vec(),
            )
        })
        .collect()
}

#[test]
fn e095_header_round_trip() {
    let h = EoeHeader::fragment(true, 3, 7, 9);
    let b = h.to_bytes();
    assert_eq!(b, [0x00, 0x01, 0xC3, 0x91]);
    let p = EoeHeader::parse(&b).unwrap();
    assert_eq!(p, h);
    assert_eq!(
        (p.fragment_number(), p.size_or_offset(), p.frame_number()),
        (3, 7, 9)
    );
    let r = EoeHeader::parse(&[0x23, 0x05, 0x01, 0x02]).unwrap();
    assert_eq!(
        (r.frame_type, r.port, r.last, r.time_appended, r.time_request),
        (3, 2, true, false, true)
    );
    assert_eq!(r.result(), 0x0201);
    assert_eq!(EoeHeader::parse(&[0, 0, 0]), None);
}

#[test]
fn e095_reassembly_in_order() {
    let f = frame(300);
    let mut r = Reassembly::new();
    let frags = fragments(&f, 96, 5);
    assert_eq!(frags.len(), 4);
    for (i, (h, d)) in frags.iter().enumerate() {
        let got = r.push(h, d).unwrap();
        assert_eq!(got.is_some(), i == 3);
    }
    assert_eq!(r.frame(), &f[..]);
    assert_eq!(r.dropped(), 0);
    // a single-fragment frame, maximum size
    let f = frame(MAX_FRAME);
    let h = EoeHeader::fragment(true, 0, 48, 6);
    assert_eq!(r.push(&h, &f), Ok(Some(MAX_FRAME)));
}

#[test]
fn e095_reassembly_bad_fragments_drop_and_count() {
    let f = frame(200);
    let frags = fragments(&f, 64, 1);
    let mut r = Reassembly::new();
    // out-of-order fragment number
    r.push(&frags[0].0, &frags[0].1).unwrap();
    assert_eq!(r.push(&frags[2].0, &frags[2].1), Err(FragmentError::Sequence));
    assert_eq!(r.dropped(), 1);
    assert!(!r.active());
    // a later fragment with no frame in assembly
    assert_eq!(r.push(&frags[1].0, &frags[1].1), Err(FragmentError::NoFrame));
    assert_eq!(r.dropped(), 2);
    // wrong frame number
    r.push(&frags[0].0, &frags[0].1).unwrap();
    let other = fragments(&f, 64, 2);
    assert_eq!(r.push(&other[1].0, &other[1].1), Err(FragmentError::FrameNumber));
    // wrong offset
    r.push(&frags[0].0, &frags[0].1).unwrap();
    let bad = EoeHeader::fragment(false, 1, 3, 1);
    assert_eq!(r.push(&bad, &frags[1].1), Err(FragmentError::Offset));
    // more data than announced
    let h = EoeHeader::fragment(true, 0, 1, 3);
    assert_eq!(r.push(&h, &frame(40)), Err(FragmentError::TooLong));
    // beyond the buffer
    let h = EoeHeader::fragment(true, 0, 63, 3);
    assert_eq!(r.push(&h, &frame(MAX_FRAME + 1)), Err(FragmentError::TooLong));
    // shorter than an Ethernet header
    let h = EoeHeader::fragment(true, 0, 1, 3);
    assert_eq!(r.push(&h, &frame(10)), Err(FragmentError::TooShort));
    assert_eq!(r.dropped(), 7);
    // a new fragment 0 interrupts (and counts) the frame in assembly
    r.push(&frags[0].0, &frags[0].1).unwrap();
    r.push(&frags[0].0, &frags[0].1).unwrap();
    assert_eq!(r.dropped(), 8);
    for (h, d) in &frags[1..] {
        r.push(h, d).unwrap();
    }
    assert_eq!(r.frame(), &f[..]);
}

#[test]
fn e095_time_stamp_is_stripped() {
    let f = frame(64);
    let mut h = EoeHeader::fragment(true, 0, 2, 1);
    h.time_appended = true;
    let mut d = f.clone();
    d.extend_from_slice(&[1, 2, 3, 4]);
    let mut r = Reassembly::new();
    assert_eq!(r.push(&h, &d), Ok(Some(64)));
    assert_eq!(r.frame(), &f[..]);
}

#[test]
fn e095_fragmenter_round_trip() {
    for len in [14, 100, 246, 247, 1000, MAX_FRAME] {
        let f = frame(len);
        let mut tx = Fragmenter::new();
        assert!(tx.load(|b| {
            b[..len].copy_from_slice(&f);
            Some(len)
        }));
        let mut r = Reassembly::new();
        let mut out = [0u8; 250]; // 256-byte mailbox minus its header
        let mut done = None;
        let mut count = 0;
        while let Some(n) = tx.next(&mut out) {
            count += 1;
            let h = EoeHeader::parse(&out).unwrap();
            assert!(h.last || (n - HEADER_LEN) % 32 == 0);
            done = r.push(&h, &out[HEADER_LEN..n]).unwrap();
        }
        assert_eq!(done, Some(len), "len {len}");
        assert_eq!(r.frame(), &f[..]);
        let (mut rest, mut expected) = (len, 1);
        while rest > 246 {
            rest -= 224;
            expected += 1;
        }
        assert_eq!(count, expected, "len {len}");
        assert!(!tx.active());
    }
    // nothing to send, a bad length, a mailbox too small
    let mut tx = Fragmenter::new();
    assert!(!tx.load(|_| None));
    assert!(!tx.load(|_| Some(MAX_FRAME + 1)));
    assert!(tx.load(|_| Some(100)));
    assert_eq!(tx.next(&mut [0u8; 30]), None);
    assert!(!tx.active());
}

/// A set-IP request in the fixed layout (every field at its position),
/// addresses as little-endian UINT32s (the first octet last).
fn set_ip(flags: u32, mac: [u8; 6], ip: Ipv4, mask: Ipv4, gw: Ipv4) -> Vec<u8> {
    let le = |a: Ipv4| [a[3], a[2], a[1], a[0]];
    let mut b = EoeHeader::response(frame_type::SET_IP_REQUEST, 0, 0)
        .to_bytes()
        .to_vec();
    b.extend_from_slice(&flags.to_le_bytes());
    b.extend_from_slice(&mac);
    b.extend_from_slice(&le(ip));
    b.extend_from_slice(&le(mask));
    b.extend_from_slice(&le(gw));
    b.extend_from_slice(&[8, 8, 8, 8]);
    let mut name = [0u8; 32];
    name[..5].copy_from_slice(b"drive");
    b.extend_from_slice(&name);
    b
}

const ALL: u32 = 0x3F;
const MAC: [u8; 6] = [0x02, 0, 0, 0, 0, 1];
const MASK24: Ipv4 = [255, 255, 255, 0];

#[test]
fn e096_set_ip_stores_parameters() {
    let mut s = EoeServer::new();
    let mut out = [0u8; 250];
    let req = set_ip(ALL, MAC, [10, 0, 0, 5], MASK24, [10, 0, 0, 1]);
    let n = s.handle(&req, &mut out, &mut NoEthernet).unwrap().unwrap();
    assert_eq!(&out[..n], &[0x03, 0x01, 0x00, 0x00]); // set IP response, success
    let p = s.params();
    assert_eq!(p.mac, Some(MAC));
    assert_eq!(p.ip, Some([10, 0, 0, 5]));
    assert_eq!(p.mask, Some(MASK24));
    assert_eq!(p.gateway, Some([10, 0, 0, 1]));
    assert_eq!(p.dns, Some([8, 8, 8, 8]));
    assert_eq!(p.dns_name.unwrap().as_bytes(), b"drive");
    assert_eq!(s.take_emcy(), None);
    // only the IP: the rest stays
    let req = set_ip(ip_flags::IP, [0; 6], [10, 0, 0, 6], [0; 4], [0; 4]);
    s.handle(&req, &mut out, &mut NoEthernet).unwrap();
    assert_eq!(s.params().ip, Some([10, 0, 0, 6]));
    assert_eq!(s.params().gateway, Some([10, 0, 0, 1]));
    // get IP returns them
    let n = s
        .handle(
            &EoeHeader::response(6, 0, 0).to_bytes(),
            &mut out,
            &mut NoEthernet,
        )
        .unwrap()
        .unwrap();
    assert_eq!(out[0], 0x07);
    assert_eq!(u32::from_le_bytes(out[4..8].try_into().unwrap()), ALL);
    assert_eq!(parse_set_ip(&out[4..n]).unwrap(), *s.params());
    // a truncated request
    let req = set_ip(ALL, MAC, [10, 0, 0, 5], MASK24, [10, 0, 0, 1]);
    assert_eq!(parse_set_ip(&req[4..20]), Err(IpError::TooShort));
    assert_eq!(parse_set_ip(&req[4..7]), Err(IpError::TooShort));
}

/// SOEM's `ecx_EOEsetIp` for 10.77.0.2/24, gateway 10.77.0.1: only the
/// flagged fields, packed, each address a little-endian UINT32.
const SOEM_SET_IP: [u8; 20] = [
    0x02, 0x01, 0x00, 0x00, // set IP request, last fragment
    0x0e, 0x00, 0x00, 0x00, // IP, mask, gateway
    0x02, 0x00, 0x4d, 0x0a, // 10.77.0.2
    0x00, 0xff, 0xff, 0xff, // 255.255.255.0
    0x01, 0x00, 0x4d, 0x0a, // 10.77.0.1
];

#[test]
fn e096_set_ip_from_soem_packed_little_endian() {
    let mut s = EoeServer::new();
    let mut out = [0u8; 250];
    let n = s
        .handle(&SOEM_SET_IP, &mut out, &mut NoEthernet)
        .unwrap()
        .unwrap();
    assert_eq!(&out[..n], &[0x03, 0x01, 0x00, 0x00], "success");
    let p = s.params();
    assert_eq!(p.ip, Some([10, 77, 0, 2]));
    assert_eq!(p.mask, Some([255, 255, 255, 0]));
    assert_eq!(p.gateway, Some([10, 77, 0, 1]));
    assert_eq!((p.mac, p.dns, p.dns_name), (None, None, None));
    assert_eq!(ip_layout(0x0e, 16), IpLayout::Packed);
    // packed with a MAC and a DNS name after a gap (no DNS server)
    let mut req = SOEM_SET_IP[..4].to_vec();
    req.extend_from_slice(&(ip_flags::MAC | ip_flags::IP | ip_flags::DNS_NAME).to_le_bytes());
    req.extend_from_slice(&MAC);
    req.extend_from_slice(&[0x05, 0x00, 0x4d, 0x0a]);
    let mut name = [0u8; 32];
    name[..4].copy_from_slice(b"axis");
    req.extend_from_slice(&name);
    let mut s = EoeServer::new();
    s.handle(&req, &mut out, &mut NoEthernet).unwrap();
    assert_eq!(s.params().mac, Some(MAC));
    assert_eq!(s.params().ip, Some([10, 77, 0, 5]));
    assert_eq!(s.params().dns_name.unwrap().as_bytes(), b"axis");
    // cut inside the gateway: too short in both layouts, nothing changes
    let mut s = EoeServer::new();
    let n = s
        .handle(&SOEM_SET_IP[..18], &mut out, &mut NoEthernet)
        .unwrap()
        .unwrap();
    assert_eq!(
        EoeHeader::parse(&out[..n]).unwrap().result(),
        result::UNSPECIFIED_ERROR
    );
    assert_eq!(*s.params(), IpParams::default());
}

#[test]
fn e096_set_ip_fixed_layout_with_unflagged_fields() {
    // TwinCAT style: all 58 bytes, only IP, mask and gateway flagged
    let req = set_ip(0x0e, [0xAA; 6], [10, 77, 0, 2], MASK24, [10, 77, 0, 1]);
    assert_eq!(req.len(), 4 + IP_BODY_LEN);
    assert_eq!(ip_layout(0x0e, IP_BODY_LEN), IpLayout::Fixed);
    let p = parse_set_ip(&req[4..]).unwrap();
    assert_eq!(
        (p.ip, p.mask, p.gateway),
        (Some([10, 77, 0, 2]), Some(MASK24), Some([10, 77, 0, 1]))
    );
    assert_eq!((p.mac, p.dns, p.dns_name), (None, None, None));
    // ending after the gateway (22 bytes of data): still the fixed layout
    let p = parse_set_ip(&req[4..26]).unwrap();
    assert_eq!(p.gateway, Some([10, 77, 0, 1]));
    // every field flagged: both layouts are the same bytes
    assert_eq!(ip_layout(ALL, IP_BODY_LEN), IpLayout::Packed);
}

#[test]
fn e096_get_ip_answers_packed_as_soem_reads_it() {
    let mut s = EoeServer::new();
    let mut out = [0u8; 250];
    s.handle(&SOEM_SET_IP, &mut out, &mut NoEthernet).unwrap();
    let get = EoeHeader::response(frame_type::GET_IP_REQUEST, 0, 0).to_bytes();
    let n = s.handle(&get, &mut out, &mut NoEthernet).unwrap().unwrap();
    // header, flags 0Eh, then the three addresses as SOEM wrote them
    assert_eq!(out[0], 0x07);
    assert_eq!(&out[4..n], &SOEM_SET_IP[4..]);
}

#[test]
fn e097_c150_first_and_last_subnet_address_rejected() {
    let cur = IpParams::default();
    let req = |ip: Ipv4, mask: Ipv4| IpParams {
        ip: Some(ip),
        mask: Some(mask),
        ..IpParams::default()
    };
    assert_eq!(
        apply_set_ip(&cur, &req([10, 0, 0, 0], MASK24)),
        Err(IpError::HostAddress)
    );
    assert_eq!(
        apply_set_ip(&cur, &req([10, 0, 0, 255], MASK24)),
        Err(IpError::HostAddress)
    );
    assert!(apply_set_ip(&cur, &req([10, 0, 0, 1], MASK24)).is_ok());
    assert!(apply_set_ip(&cur, &req([10, 0, 0, 254], MASK24)).is_ok());
    let m28 = [255, 255, 255, 240];
    assert_eq!(
        apply_set_ip(&cur, &req([192, 168, 3, 16], m28)),
        Err(IpError::HostAddress)
    );
    assert_eq!(
        apply_set_ip(&cur, &req([192, 168, 3, 31], m28)),
        Err(IpError::HostAddress)
    );
    assert!(apply_set_ip(&cur, &req([192, 168, 3, 17], m28)).is_ok());
    assert_eq!(
        apply_set_ip(&cur, &req([10, 0, 0, 5], [255, 0, 255, 0])),
        Err(IpError::BadMask)
    );
    assert_eq!(
        apply_set_ip(&cur, &req([10, 0, 0, 5], [255; 4])),
        Err(IpError::BadMask)
    );
    // gateway outside the subnet; multicast MAC
    let mut r = req([10, 0, 0, 5], MASK24);
    r.gateway = Some([10, 0, 1, 1]);
    assert_eq!(apply_set_ip(&cur, &r), Err(IpError::Gateway));
    r.gateway = Some([0; 4]);
    assert!(apply_set_ip(&cur, &r).is_ok());
    r.mac = Some([1, 0, 0, 0, 0, 1]);
    assert_eq!(apply_set_ip(&cur, &r), Err(IpError::Mac));
    // a multicast address is no host address
    assert_eq!(
        apply_set_ip(&cur, &req([224, 0, 0, 5], MASK24)),
        Err(IpError::HostAddress)
    );
    assert_eq!(
        apply_set_ip(
            &cur,
            &IpParams {
                ip: Some([239, 1, 2, 3]),
                ..IpParams::default()
            }
        ),
        Err(IpError::HostAddress)
    );
    // a new mask alone that makes the kept IP the broadcast address
    let kept = apply_set_ip(&cur, &req([10, 0, 0, 127], MASK24)).unwrap();
    let m25 = IpParams {
        mask: Some([255, 255, 255, 128]),
        ..IpParams::default()
    };
    assert_eq!(apply_set_ip(&kept, &m25), Err(IpError::HostAddress));
}

#[test]
fn e093_rejected_ip_answers_error_and_emcy_fff0() {
    let mut s = EoeServer::new();
    let mut out = [0u8; 250];
    let ok = set_ip(ALL, MAC, [10, 0, 0, 5], MASK24, [10, 0, 0, 1]);
    s.handle(&ok, &mut out, &mut NoEthernet).unwrap();
    let bad = set_ip(ALL, MAC, [10, 0, 0, 255], MASK24, [10, 0, 0, 1]);
    let n = s.handle(&bad, &mut out, &mut NoEthernet).unwrap().unwrap();
    let h = EoeHeader::parse(&out[..n]).unwrap();
    assert_eq!(
        (h.frame_type, h.result()),
        (frame_type::SET_IP_RESPONSE, result::UNSPECIFIED_ERROR)
    );
    let e = s.take_emcy().unwrap();
    assert_eq!((e.code, e.register), (0xFFF0, 0x23));
    assert!(s.address_error());
    // the previous parameters stay
    assert_eq!(s.params().ip, Some([10, 0, 0, 5]));
    assert_eq!(s.stats().ip_rejected, 1);
    // a good request afterwards clears the error (EMCY 0000h)
    s.handle(&ok, &mut out, &mut NoEthernet).unwrap();
    assert_eq!(s.take_emcy().unwrap().code, 0x0000);
    assert!(!s.address_error());
}

#[test]
fn e095_server_delivers_frames_and_answers_other_types() {
    let mut s = EoeServer::new();
    let mut port = FrameCounter::default();
    let mut out = [0u8; 250];
    let f = frame(500);
    for (h, d) in fragments(&f, 224, 4) {
        let mut msg = h.to_bytes().to_vec();
        msg.extend_from_slice(&d);
        assert_eq!(s.handle(&msg, &mut out, &mut port), Ok(None));
    }
    assert_eq!((port.frames, port.last_len, port.last_hash), (1, 500, fnv1a(&f)));
    assert_eq!(s.stats().frames_received, 1);
    // address filter: not supported
    let n = s
        .handle(&EoeHeader::response(4, 0, 0).to_bytes(), &mut out, &mut port)
        .unwrap()
        .unwrap();
    assert_eq!(
        EoeHeader::parse(&out[..n]).unwrap().result(),
        result::NO_FILTER_SUPPORT
    );
    let n = s
        .handle(&EoeHeader::response(9, 0, 0).to_bytes(), &mut out, &mut port)
        .unwrap()
        .unwrap();
    assert_eq!(
        EoeHeader::parse(&out[..n]).unwrap().result(),
        result::UNSUPPORTED_FRAME_TYPE
    );
    assert_eq!(
        s.handle(&[0, 0], &mut out, &mut port),
        Err(MailboxError::SIZE_TOO_SHORT)
    );
}
