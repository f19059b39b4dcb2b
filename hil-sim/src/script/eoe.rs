//! The scripted master's EoE step (spec §9, E-096/E-097, docs/eoe.md): the
//! frames it tunnels to the drive and the checks on what comes back, built
//! and parsed here byte by byte (no IP stack on the master's side, so the
//! drive's smoltcp answers a peer that shares no code with it).
//!
//! The step: set the drive's IP parameters (EoE set-IP request), an ARP
//! request for the drive's address (the drive learns the master's MAC from
//! it and answers), an ICMP echo request, and a UDP parameter-service read
//! (`R A150`, port 5011).

use ecat::eoe::{frame_type, EoeHeader, HEADER_LEN};

/// The drive's address the master sets.
pub const DRIVE_IP: [u8; 4] = [192, 168, 10, 2];
/// The master's (the EoE gateway's) address.
pub const MASTER_IP: [u8; 4] = [192, 168, 10, 1];
/// Subnet mask of both.
pub const MASK: [u8; 4] = [255, 255, 255, 0];
/// The master's MAC on the tunnel.
pub const MASTER_MAC: [u8; 6] = [0x02, 0x00, 0x00, 0x00, 0x00, 0x01];
/// ICMP echo identifier and sequence number of the ping.
pub const PING_ID: u16 = 0x5C06;
const PING_SEQ: u16 = 1;
/// The ping's payload.
const PING_DATA: &[u8; 16] = b"sc6 eoe ping 123";
/// The UDP parameter request and the master's port.
pub const UDP_REQUEST: &[u8] = b"R A150";
const UDP_SRC_PORT: u16 = 40_001;
const PARAM_PORT: u16 = 5011;

const ETHERTYPE_IPV4: u16 = 0x0800;
const ETHERTYPE_ARP: u16 = 0x0806;
const ETH_LEN: usize = 14;
const IP_LEN: usize = 20;

/// Mailbox type of EoE.
pub const MBX_EOE: u8 = 2;

fn put(b: &mut [u8], at: usize, v: &[u8]) {
    if let Some(s) = b.get_mut(at..at + v.len()) {
        s.copy_from_slice(v);
    }
}

fn be16(b: &[u8], at: usize) -> u16 {
    match b.get(at..at + 2) {
        Some(&[h, l]) => u16::from_be_bytes([h, l]),
        _ => 0,
    }
}

/// The internet checksum (RFC 1071) of `data`, with `sum` carried in.
fn checksum(mut sum: u32, data: &[u8]) -> u16 {
    let mut chunks = data.chunks_exact(2);
    for c in &mut chunks {
        if let &[h, l] = c {
            sum += u32::from(u16::from_be_bytes([h, l]));
        }
    }
    if let Some(&last) = chunks.remainder().first() {
        sum += u32::from(last) << 8;
    }
    while sum > 0xFFFF {
        sum = (sum & 0xFFFF) + (sum >> 16);
    }
    !(sum as u16)
}

/// The EoE set-IP request (EoE header first): IP, mask, gateway = master,
/// each a little-endian UINT32 as SOEM writes them. Returns its length.
pub fn set_ip_request(out: &mut [u8]) -> usize {
    let le = |a: [u8; 4]| [a[3], a[2], a[1], a[0]];
    put(
        out,
        0,
        &EoeHeader::response(frame_type::SET_IP_REQUEST, 0, 0).to_bytes(),
    );
    put(out, HEADER_LEN, &0x0Eu32.to_le_bytes());
    put(out, HEADER_LEN + 4, &le(DRIVE_IP));
    put(out, HEADER_LEN + 8, &le(MASK));
    put(out, HEADER_LEN + 12, &le(MASTER_IP));
    HEADER_LEN + 16
}

/// The result of a set-IP response (`None`: not one).
pub fn set_ip_result(eoe: &[u8]) -> Option<u16> {
    let h = EoeHeader::parse(eoe)?;
    (h.frame_type == frame_type::SET_IP_RESPONSE).then(|| h.result())
}

/// One EoE fragment carrying all of `frame` (header first). Returns its length.
fn fragment(out: &mut [u8], frame: &[u8]) -> usize {
    let blocks = frame.len().div_ceil(32) as u8;
    put(out, 0, &EoeHeader::fragment(true, 0, blocks, 1).to_bytes());
    put(out, HEADER_LEN, frame);
    HEADER_LEN + frame.len()
}

fn ethernet(out: &mut [u8], dst: [u8; 6], ethertype: u16) {
    put(out, 0, &dst);
    put(out, 6, &MASTER_MAC);
    put(out, 12, &ethertype.to_be_bytes());
}

/// The ARP request "who has the drive's IP, tell the master", as one EoE
/// fragment. Returns its length.
pub fn arp_request(out: &mut [u8]) -> usize {
    let mut f = [0u8; ETH_LEN + 28];
    ethernet(&mut f, [0xFF; 6], ETHERTYPE_ARP);
    // Ethernet / IPv4, 6 / 4 bytes, request
    put(&mut f, ETH_LEN, &[0, 1, 8, 0, 6, 4, 0, 1]);
    put(&mut f, ETH_LEN + 8, &MASTER_MAC);
    put(&mut f, ETH_LEN + 14, &MASTER_IP);
    put(&mut f, ETH_LEN + 24, &DRIVE_IP);
    fragment(out, &f)
}

/// The drive's MAC from its ARP reply for [`DRIVE_IP`] to the master.
pub fn arp_reply(frame: &[u8]) -> Option<[u8; 6]> {
    let a = frame.get(ETH_LEN..ETH_LEN + 28)?;
    let ok = be16(frame, 12) == ETHERTYPE_ARP
        && a.get(..8) == Some(&[0, 1, 8, 0, 6, 4, 0, 2])
        && a.get(14..18) == Some(&DRIVE_IP)
        && a.get(18..24) == Some(&MASTER_MAC)
        && a.get(24..28) == Some(&MASTER_IP);
    let mut mac = [0u8; 6];
    mac.copy_from_slice(a.get(8..14)?);
    ok.then_some(mac)
}

/// An IPv4 packet from the master to the drive in `f` (Ethernet header
/// included) with `payload_len` bytes after the IP header.
fn ipv4(f: &mut [u8], drive_mac: [u8; 6], protocol: u8, payload_len: usize) {
    ethernet(f, drive_mac, ETHERTYPE_IPV4);
    let total = (IP_LEN + payload_len) as u16;
    let mut h = [0u8; IP_LEN];
    put(&mut h, 0, &[0x45, 0]);
    put(&mut h, 2, &total.to_be_bytes());
    put(&mut h, 4, &[0x12, 0x34, 0x40, 0]); // id, don't fragment
    put(&mut h, 8, &[64, protocol]);
    put(&mut h, 12, &MASTER_IP);
    put(&mut h, 16, &DRIVE_IP);
    let c = checksum(0, &h);
    put(&mut h, 10, &c.to_be_bytes());
    put(f, ETH_LEN, &h);
}

/// The IP payload of a frame from the drive to the master with `protocol`
/// (header checksum verified).
fn ipv4_payload(frame: &[u8], protocol: u8) -> Option<&[u8]> {
    let h = frame.get(ETH_LEN..ETH_LEN + IP_LEN)?;
    let total = usize::from(be16(h, 2));
    let ok = be16(frame, 12) == ETHERTYPE_IPV4
        && h.first() == Some(&0x45)
        && h.get(9) == Some(&protocol)
        && h.get(12..16) == Some(&DRIVE_IP)
        && h.get(16..20) == Some(&MASTER_IP)
        && checksum(0, h) == 0;
    let p = frame.get(ETH_LEN + IP_LEN..ETH_LEN + total.max(IP_LEN))?;
    ok.then_some(p)
}

/// An ICMP echo request to the drive as one EoE fragment.
pub fn echo_request(out: &mut [u8], drive_mac: [u8; 6]) -> usize {
    let mut f = [0u8; ETH_LEN + IP_LEN + 8 + PING_DATA.len()];
    ipv4(&mut f, drive_mac, 1, 8 + PING_DATA.len());
    let mut icmp = [0u8; 8 + PING_DATA.len()];
    put(&mut icmp, 0, &[8, 0]);
    put(&mut icmp, 4, &PING_ID.to_be_bytes());
    put(&mut icmp, 6, &PING_SEQ.to_be_bytes());
    put(&mut icmp, 8, PING_DATA);
    let c = checksum(0, &icmp);
    put(&mut icmp, 2, &c.to_be_bytes());
    put(&mut f, ETH_LEN + IP_LEN, &icmp);
    fragment(out, &f)
}

/// Whether `frame` is the drive's echo reply to [`echo_request`]: same
/// identifier, sequence and data, a valid ICMP checksum.
pub fn is_echo_reply(frame: &[u8]) -> bool {
    let Some(icmp) = ipv4_payload(frame, 1) else {
        return false;
    };
    icmp.get(..2) == Some(&[0, 0])
        && be16(icmp, 4) == PING_ID
        && be16(icmp, 6) == PING_SEQ
        && icmp.get(8..) == Some(PING_DATA.as_slice())
        && checksum(0, icmp) == 0
}

/// The UDP pseudo-header sum of a datagram `src` → `dst` of `len` bytes.
fn pseudo(src: [u8; 4], dst: [u8; 4], len: usize) -> u32 {
    let w = |a: [u8; 4]| {
        u32::from(u16::from_be_bytes([a[0], a[1]])) + u32::from(u16::from_be_bytes([a[2], a[3]]))
    };
    w(src) + w(dst) + 17 + len as u32
}

/// The UDP parameter request [`UDP_REQUEST`] to the drive as one EoE fragment.
pub fn param_request(out: &mut [u8], drive_mac: [u8; 6]) -> usize {
    const N: usize = 8 + UDP_REQUEST.len();
    let mut f = [0u8; ETH_LEN + IP_LEN + N];
    ipv4(&mut f, drive_mac, 17, N);
    let mut u = [0u8; N];
    put(&mut u, 0, &UDP_SRC_PORT.to_be_bytes());
    put(&mut u, 2, &PARAM_PORT.to_be_bytes());
    put(&mut u, 4, &(N as u16).to_be_bytes());
    put(&mut u, 8, UDP_REQUEST);
    let c = checksum(pseudo(MASTER_IP, DRIVE_IP, N), &u);
    put(&mut u, 6, &c.to_be_bytes());
    put(&mut f, ETH_LEN + IP_LEN, &u);
    fragment(out, &f)
}

/// The value of the drive's `OK <value>` answer to [`param_request`] (UDP
/// checksum verified); `Err(())` for any other answer from port 5011.
pub fn param_answer(frame: &[u8]) -> Option<Result<i32, ()>> {
    let u = ipv4_payload(frame, 17)?;
    let len = usize::from(be16(u, 4));
    let u = u.get(..len)?;
    if be16(u, 0) != PARAM_PORT || be16(u, 2) != UDP_SRC_PORT {
        return None;
    }
    if be16(u, 6) != 0 && checksum(pseudo(DRIVE_IP, MASTER_IP, len), u) != 0 {
        return Some(Err(()));
    }
    let text = u.get(8..)?.strip_prefix(b"OK ");
    Some(text.and_then(parse_i32).ok_or(()))
}

fn parse_i32(t: &[u8]) -> Option<i32> {
    let t = t.strip_suffix(b"\n").unwrap_or(t);
    let (neg, digits) = match t.strip_prefix(b"-") {
        Some(d) => (true, d),
        None => (false, t),
    };
    if digits.is_empty() {
        return None;
    }
    let mut v: i32 = 0;
    for &c in digits {
        let d = c.checked_sub(b'0').filter(|d| *d < 10)?;
        v = v.checked_mul(10)?.checked_add(i32::from(d))?;
    }
    Some(if neg { -v } else { v })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The checksum of a header with its checksum in place is 0 (RFC 1071).
    #[test]
    fn e095_master_frames_carry_valid_checksums() {
        let mut out = [0u8; 128];
        let n = echo_request(&mut out, [2, 0, 0, 0, 0, 9]);
        let f = &out[HEADER_LEN..n];
        assert_eq!(checksum(0, &f[ETH_LEN..ETH_LEN + IP_LEN]), 0);
        assert_eq!(checksum(0, &f[ETH_LEN + IP_LEN..]), 0);
        assert_eq!(parse_i32(b"1000"), Some(1000));
        assert_eq!(parse_i32(b"-7"), Some(-7));
        assert_eq!(parse_i32(b"1x"), None);
    }
}
