//! Ethernet frames into a line of one simulated drive (ESC datagram
//! processing, FMMUs, SyncManagers, SII interface, then the slave
//! firmware): nothing may panic, and a well-formed EtherCAT frame comes
//! back as the ESC rules say (ETG.1000.4):
//! - its length, the EtherCAT header and every datagram's command, index,
//!   length and flags are unchanged; ADP too, except auto-increment and
//!   broadcast commands (APxx, BRD/BWR/BRW, ARMW), which the slave counts
//!   up by one;
//! - the data of a write-only command (APWR, FPWR, BWR, LWR) is unchanged;
//! - the working counter grows by at most what one slave can add: 1 for a
//!   read or a write, 3 for a read-write (1 read + 2 write), 1 for ARMW/FRMW.
//!
//! A frame of another EtherType comes back byte for byte.
//!
//! The input's first byte chooses the start and the form: bit 0 the line
//! (0: in Pre-Op after a master's mailbox set-up; 1: in Op with DC SYNC0,
//! both axes enabled in csp, the PDOs mapped, as the scripted master of
//! the QEMU run leaves it), bit 1 the form of the rest (0: a frame as it
//! is, e.g. one the master sent, `scripts/fuzz-seeds`; 1: a list of
//! datagrams the target assembles into a well-formed frame, with the
//! drive's station address, the mapped logical addresses and the ESC's
//! registers and buffers as likely addresses, so every input gets past
//! the header checks).
#![no_main]

#[path = "common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;

/// One datagram's place in a frame: header offset, data length, command.
#[derive(Clone, Copy)]
struct Datagram {
    at: usize,
    len: usize,
    cmd: u8,
}

/// The datagrams of an EtherCAT frame whose header and datagram chain are
/// consistent (type 1, lengths adding up exactly), else `None`.
fn datagrams(f: &[u8]) -> Option<Vec<Datagram>> {
    if f.get(12..14)? != [0x88, 0xA4] {
        return None;
    }
    let h = u16::from_le_bytes([*f.get(14)?, *f.get(15)?]);
    if h >> 12 != 1 {
        return None;
    }
    let total = usize::from(h & 0x07FF);
    let end = 16usize.checked_add(total)?;
    if end > f.len() {
        return None;
    }
    let mut out = Vec::new();
    let mut at = 16usize;
    loop {
        let lf = u16::from_le_bytes([*f.get(at + 6)?, *f.get(at + 7)?]);
        let len = usize::from(lf & 0x07FF);
        let next = at + 10 + len + 2;
        if next > end {
            return None;
        }
        out.push(Datagram { at, len, cmd: f[at] });
        if lf & 0x8000 == 0 {
            return (next == end).then_some(out);
        }
        at = next;
    }
}

/// Registers and buffers a structured datagram addresses (+ 0…15).
const REGS: [u16; 24] = [
    0x0000, 0x0010, 0x0100, 0x0120, 0x0130, 0x0134, 0x0140, 0x0220, 0x0400, 0x0410, 0x0502, 0x0508, 0x0600,
    0x0610, 0x0800, 0x0808, 0x0810, 0x0818, 0x0900, 0x0910, 0x0981, 0x0990, 0x1000, 0x1100,
];

/// Assembles datagrams from `data` (command, address choice, length,
/// offset, payload; at most 8) into one well-formed EtherCAT frame for the
/// drive at `station`.
fn structured(mut data: &[u8], station: u16) -> Vec<u8> {
    let mut body = Vec::new();
    let mut n = 0;
    while data.len() >= 4 && n < 8 {
        let (cmd, sel, len, off) = (data[0] % 15, data[1], usize::from(data[2]), data[3]);
        data = &data[4..];
        let take = len.min(data.len());
        let (payload, rest) = data.split_at(take);
        data = rest;
        let reg = REGS[usize::from(sel) % REGS.len()].wrapping_add(u16::from(off & 0x0F));
        let (adp, ado) = match cmd {
            // logical: the mapped outputs (0x0000) and inputs (0x0800), or any
            10..=12 => {
                let logical: u32 = match sel & 3 {
                    0 => 0x0000,
                    1 => 0x0800,
                    _ => u32::from(sel) << 8 | u32::from(off),
                } + u32::from(off & 0x1F);
                ((logical & 0xFFFF) as u16, (logical >> 16) as u16)
            }
            // configured address: the drive's, or another
            4..=6 | 13 => (if sel & 0x80 == 0 { station } else { u16::from(off) }, reg),
            // auto-increment: the first slave (0) or a later one
            _ => (if sel & 0x80 == 0 { 0 } else { u16::from(off).wrapping_neg() }, reg),
        };
        let at = body.len();
        body.extend_from_slice(&[cmd, n as u8]);
        body.extend_from_slice(&adp.to_le_bytes());
        body.extend_from_slice(&ado.to_le_bytes());
        body.extend_from_slice(&(len as u16).to_le_bytes());
        body.extend_from_slice(&[0, 0]);
        body.extend_from_slice(payload);
        body.resize(body.len() + (len - take), 0);
        body.extend_from_slice(&[0, 0]); // WKC
        if n > 0 {
            // the previous datagram has a successor
            let prev = last_datagram(&body[..at]);
            body[prev + 7] |= 0x80;
        }
        n += 1;
        if body.len() > 1400 {
            break;
        }
    }
    let mut f = vec![0xFF; 6];
    f.extend_from_slice(&[0x02, 0, 0, 0, 0, 0x10]);
    f.extend_from_slice(&0x88A4u16.to_be_bytes());
    f.extend_from_slice(&((body.len() as u16 & 0x07FF) | 0x1000).to_le_bytes());
    f.extend_from_slice(&body);
    f.resize(f.len().max(60), 0);
    f
}

/// Offset of the last datagram in a chain of datagrams (`body` non-empty).
fn last_datagram(body: &[u8]) -> usize {
    let mut at = 0;
    loop {
        let len = usize::from(u16::from_le_bytes([body[at + 6], body[at + 7]]) & 0x07FF);
        let next = at + 10 + len + 2;
        if next >= body.len() {
            return at;
        }
        at = next;
    }
}

fuzz_target!(|input: &[u8]| {
    let Some((&mode, rest)) = input.split_first() else {
        return;
    };
    let (mut sim, station) = if mode & 1 == 0 {
        (common::preop_line(), common::PREOP_STATION)
    } else {
        (common::op_line(), hil_sim::script::STATION)
    };
    let owned;
    let data: &[u8] = if mode & 2 == 0 {
        rest
    } else {
        owned = structured(rest, station);
        &owned
    };
    let mut f = data.to_vec();
    sim.exchange(&mut f);
    assert_eq!(f.len(), data.len(), "the frame changed its length");
    // an IEEE 802.1Q tag before EtherType 0x88A4: the ESC processes the frame
    // as an EtherCAT frame (ETG.1000.4) and leaves the tag as it was; the
    // oracles below then see both frames without the tag
    let tagged = data.get(12..14) == Some(&[0x81, 0x00]) && data.get(16..18) == Some(&[0x88, 0xA4]);
    let untag = |x: &[u8]| [&x[..12], &x[16..]].concat();
    let (before, f) = if tagged {
        assert_eq!(f[12..16], data[12..16], "the VLAN tag changed");
        (untag(data), untag(&f))
    } else {
        (data.to_vec(), f)
    };
    let before = &before[..];
    if before.get(12..14) != Some(&[0x88, 0xA4]) {
        assert_eq!(f, before, "a frame of another EtherType changed");
        return;
    }
    let Some(list) = datagrams(before) else {
        return;
    };
    assert_eq!(f[14..16], before[14..16], "the EtherCAT header changed");
    for d in list {
        let (a, b) = (&f[d.at..], &before[d.at..]);
        assert_eq!(a[0..2], b[0..2], "command/index changed");
        assert_eq!(
            a[4..8],
            b[4..8],
            "ADO or length/flags changed (cmd {:#04x})",
            d.cmd
        );
        let adp_in = u16::from_le_bytes([b[2], b[3]]);
        let adp_out = u16::from_le_bytes([a[2], a[3]]);
        // auto-increment and broadcast commands: each slave counts ADP up
        let auto = matches!(d.cmd, 1..=3 | 7..=9 | 13);
        let want = if auto { adp_in.wrapping_add(1) } else { adp_in };
        assert_eq!(adp_out, want, "ADP of cmd {:#04x}", d.cmd);
        if matches!(d.cmd, 2 | 5 | 8 | 11) {
            assert_eq!(
                a[10..10 + d.len],
                b[10..10 + d.len],
                "write data changed (cmd {:#04x})",
                d.cmd
            );
        }
        let w = 10 + d.len;
        let wkc_in = u16::from_le_bytes([b[w], b[w + 1]]);
        let wkc_out = u16::from_le_bytes([a[w], a[w + 1]]);
        let most = match d.cmd {
            3 | 6 | 9 | 12 => 3,
            0 => 0,
            _ => 1,
        };
        let grew = wkc_out.wrapping_sub(wkc_in);
        assert!(grew <= most, "WKC of cmd {:#04x} grew by {grew}", d.cmd);
    }
});
