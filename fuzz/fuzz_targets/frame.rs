//! Arbitrary bytes as Ethernet frames into a line of one simulated drive in
//! PRE-OP (ESC datagram processing, FMMUs, SyncManagers, SII interface, then
//! the slave firmware): nothing may panic, and a well-formed EtherCAT frame
//! comes back as the ESC rules say (ETG.1000.4):
//! - its length, the EtherCAT header and every datagram's command, index,
//!   length and flags are unchanged; ADP too, except auto-increment and
//!   broadcast commands (APxx, BRD/BWR/BRW, ARMW), which the slave counts
//!   up by one;
//! - the data of a write-only command (APWR, FPWR, BWR, LWR) is unchanged;
//! - the working counter grows by at most what one slave can add: 1 for a
//!   read or a write, 3 for a read-write (1 read + 2 write), 1 for ARMW/FRMW.
//!
//! A frame of another EtherType comes back byte for byte.
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

fuzz_target!(|data: &[u8]| {
    let mut sim = common::preop_line();
    let mut f = data.to_vec();
    sim.exchange(&mut f);
    let before = data;
    assert_eq!(f.len(), before.len(), "the frame changed its length");
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
