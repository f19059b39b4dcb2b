extern crate std;
use super::testutil::*;
use super::*;
use crate::esc::{Esc, EscConfig};
use ::esc::{regs, Fmmu, SmControl, SmDirection, SmMode, SyncManager};
use std::vec::Vec;

fn esc_with_type(t: u8) -> Esc {
    Esc::new(
        EscConfig {
            esc_type: t,
            ..EscConfig::default()
        },
        &[],
    )
}

#[test]
fn command_codes_round_trip() {
    for c in 0..=255u8 {
        assert_eq!(Command::from_code(c).code(), c);
    }
    assert_eq!(Command::from_code(12), Command::Lrw);
    assert_eq!(Command::from_code(14), Command::Frmw);
    assert!(Command::Lrd.is_logical());
    assert!(!Command::Fprd.is_logical());
}

#[test]
fn aprd_on_three_slaves_addresses_by_position() {
    let (mut a, mut b, mut c) = (esc_with_type(0x11), esc_with_type(0x22), esc_with_type(0x33));
    let mut f = build(&[
        (Command::Aprd, phys(pos(0), regs::TYPE), &[0]),
        (Command::Aprd, phys(pos(1), regs::TYPE), &[0]),
        (Command::Aprd, phys(pos(2), regs::TYPE), &[0]),
        (Command::Aprd, phys(pos(3), regs::TYPE), &[0xAB]),
    ]);
    process_frame(&mut [&mut a, &mut b, &mut c], &mut f, Nanos::from_ns(0)).unwrap();
    let r = parse(&mut f);
    assert_eq!(r[0].data, [0x11]);
    assert_eq!(r[1].data, [0x22]);
    assert_eq!(r[2].data, [0x33]);
    for d in &r[..3] {
        assert_eq!(d.wkc, 1);
    }
    // nobody at position 3: data untouched, WKC 0
    assert_eq!(r[3].data, [0xAB]);
    assert_eq!(r[3].wkc, 0);
    // every slave counted ADP up once
    assert_eq!(r[0].addr & 0xFFFF, 3);
    assert_eq!(r[1].addr & 0xFFFF, 2);
}

#[test]
fn brd_wkc_counts_every_slave_and_ors_data() {
    let (mut a, mut b, mut c) = (esc_with_type(0x01), esc_with_type(0x02), esc_with_type(0x04));
    let (data, wkc) = xfer(
        &mut [&mut a, &mut b, &mut c],
        Command::Brd,
        phys(0, regs::TYPE),
        &[0],
        0,
    );
    assert_eq!(wkc, 3);
    assert_eq!(data, [0x07]);
}

#[test]
fn bwr_then_brd_wkc() {
    let (mut a, mut b) = (esc_with_type(1), esc_with_type(1));
    let mut line = [&mut a, &mut b];
    let (_, wkc) = xfer(&mut line, Command::Bwr, phys(0, 0x0F00), &[0x5A, 0xA5], 0);
    assert_eq!(wkc, 2);
    let (data, wkc) = xfer(&mut line, Command::Brd, phys(0, 0x0F00), &[0, 0], 0);
    assert_eq!(wkc, 2);
    assert_eq!(data, [0x5A, 0xA5]);
    let mut buf = [0u8; 2];
    b.read_reg(0x0F00, &mut buf);
    assert_eq!(buf, [0x5A, 0xA5]);
}

#[test]
fn apwr_station_address_then_fprd() {
    let (mut a, mut b) = (esc_with_type(0x11), esc_with_type(0x22));
    let mut line = [&mut a, &mut b];
    let (_, wkc) = xfer(
        &mut line,
        Command::Apwr,
        phys(pos(0), regs::STATION_ADDRESS),
        &0x1000u16.to_le_bytes(),
        0,
    );
    assert_eq!(wkc, 1);
    let (_, wkc) = xfer(
        &mut line,
        Command::Apwr,
        phys(pos(1), regs::STATION_ADDRESS),
        &0x1001u16.to_le_bytes(),
        0,
    );
    assert_eq!(wkc, 1);
    let (data, wkc) = xfer(&mut line, Command::Fprd, phys(0x1001, regs::TYPE), &[0], 0);
    assert_eq!((data.as_slice(), wkc), (&[0x22u8][..], 1));
    let (data, wkc) = xfer(&mut line, Command::Fprd, phys(0x1000, regs::TYPE), &[0], 0);
    assert_eq!((data.as_slice(), wkc), (&[0x11u8][..], 1));
    let (_, wkc) = xfer(&mut line, Command::Fprd, phys(0x1002, regs::TYPE), &[0], 0);
    assert_eq!(wkc, 0);
    assert_eq!(a.station_address(), 0x1000);
    assert_eq!(b.station_address(), 0x1001);
}

#[test]
fn fprd_matches_alias_only_when_enabled() {
    let mut sii = [0u8; 16];
    sii[8..10].copy_from_slice(&0x0042u16.to_le_bytes()); // word 4: alias
    let mut a = Esc::new(EscConfig::default(), &sii);
    let (_, wkc) = xfer1(&mut a, Command::Fprd, phys(0x0042, regs::TYPE), &[0], 0);
    assert_eq!(wkc, 0);
    // DL control bit 24: station alias addressing
    xfer1(
        &mut a,
        Command::Apwr,
        phys(0, regs::DL_CONTROL),
        &0x0100_0001u32.to_le_bytes(),
        0,
    );
    let (_, wkc) = xfer1(&mut a, Command::Fprd, phys(0x0042, regs::TYPE), &[0], 0);
    assert_eq!(wkc, 1);
}

#[test]
fn fprw_counts_three() {
    let mut a = esc_with_type(1);
    xfer1(
        &mut a,
        Command::Apwr,
        phys(0, regs::STATION_ADDRESS),
        &0x1000u16.to_le_bytes(),
        0,
    );
    a.write_reg(0x0F10, &[1, 2]);
    let (data, wkc) = xfer1(&mut a, Command::Fprw, phys(0x1000, 0x0F10), &[9, 8], 0);
    assert_eq!(wkc, 3);
    assert_eq!(data, [1, 2], "read-write returns the old value");
    let mut buf = [0u8; 2];
    a.read_reg(0x0F10, &mut buf);
    assert_eq!(buf, [9, 8]);
    // APRW on a read-only register: still read and "written" (+3), value unchanged
    let (data, wkc) = xfer1(&mut a, Command::Aprw, phys(0, regs::TYPE), &[0x99], 0);
    assert_eq!((data[0], wkc), (1, 3));
    let mut t = [0u8; 1];
    a.read_reg(regs::TYPE, &mut t);
    assert_eq!(t[0], 1);
}

#[test]
fn armw_distributes_reference_value() {
    let (mut a, mut b, mut c) = (esc_with_type(1), esc_with_type(1), esc_with_type(1));
    b.write_reg(0x0F20, &0xDEAD_BEEFu32.to_le_bytes());
    // reference is position 1
    let (data, wkc) = xfer(
        &mut [&mut a, &mut b, &mut c],
        Command::Armw,
        phys(pos(1), 0x0F20),
        &[0; 4],
        0,
    );
    assert_eq!(data, 0xDEAD_BEEFu32.to_le_bytes());
    assert_eq!(wkc, 3);
    let mut buf = [0u8; 4];
    c.read_reg(0x0F20, &mut buf);
    assert_eq!(u32::from_le_bytes(buf), 0xDEAD_BEEF);
    // slave 0 comes before the reference: it writes what the master sent
    a.read_reg(0x0F20, &mut buf);
    assert_eq!(u32::from_le_bytes(buf), 0);
}

#[test]
fn frmw_reads_at_configured_slave_writes_others() {
    let (mut a, mut b) = (esc_with_type(1), esc_with_type(1));
    let mut line = [&mut a, &mut b];
    xfer(
        &mut line,
        Command::Apwr,
        phys(pos(0), regs::STATION_ADDRESS),
        &0x1000u16.to_le_bytes(),
        0,
    );
    xfer(
        &mut line,
        Command::Apwr,
        phys(pos(1), regs::STATION_ADDRESS),
        &0x1001u16.to_le_bytes(),
        0,
    );
    a.write_reg(0x0F20, &[7, 7]);
    let (data, wkc) = xfer(
        &mut [&mut a, &mut b],
        Command::Frmw,
        phys(0x1000, 0x0F20),
        &[0, 0],
        0,
    );
    assert_eq!((data.as_slice(), wkc), (&[7u8, 7][..], 2));
    let mut buf = [0u8; 2];
    b.read_reg(0x0F20, &mut buf);
    assert_eq!(buf, [7, 7]);
}

/// Configures SM2 (outputs, 3-buffer) at 0x1100 and SM3 (inputs) at 0x1400,
/// and FMMU0 (write) / FMMU1 (read) at `log_out` / `log_in`.
fn configure_pd(esc: &mut Esc, log_out: u32, log_in: u32, len: u16) {
    let sm2 = SyncManager {
        start: 0x1100,
        length: len,
        control: SmControl::new(SmMode::Buffered, SmDirection::MasterWrite, true, true).0,
        status: 0,
        activate: 1,
        pdi_control: 0,
    };
    let sm3 = SyncManager {
        start: 0x1400,
        length: len,
        control: SmControl::new(SmMode::Buffered, SmDirection::MasterRead, true, false).0,
        ..sm2
    };
    let f0 = Fmmu {
        logical_start: log_out,
        length: len,
        logical_start_bit: 0,
        logical_stop_bit: 7,
        physical_start: 0x1100,
        physical_start_bit: 0,
        kind: Fmmu::WRITE,
        activate: 1,
    };
    let f1 = Fmmu {
        logical_start: log_in,
        physical_start: 0x1400,
        kind: Fmmu::READ,
        ..f0
    };
    for (addr, bytes) in [
        (regs::sm(2), &sm2.to_bytes()[..]),
        (regs::sm(3), &sm3.to_bytes()[..]),
        (regs::fmmu(0), &f0.to_bytes()[..]),
        (regs::fmmu(1), &f1.to_bytes()[..]),
    ] {
        let (_, wkc) = xfer1(esc, Command::Apwr, phys(0, addr), bytes, 0);
        assert_eq!(wkc, 1);
    }
}

#[test]
fn lrw_through_fmmus_on_two_slaves() {
    use ::esc::Pdi;
    let (mut a, mut b) = (esc_with_type(1), esc_with_type(1));
    // logical image: outputs a[0..4] b[4..8], inputs a[8..12] b[12..16]
    configure_pd(&mut a, 0x0001_0000, 0x0001_0008, 4);
    configure_pd(&mut b, 0x0001_0004, 0x0001_000C, 4);
    a.write(0x1400, &[0xA0, 0xA1, 0xA2, 0xA3]).unwrap();
    b.write(0x1400, &[0xB0, 0xB1, 0xB2, 0xB3]).unwrap();
    let mut image: Vec<u8> = (1..=8).collect();
    image.extend_from_slice(&[0; 8]);
    let mut f = build(&[(Command::Lrw, 0x0001_0000, &image)]);
    process_frame(&mut [&mut a, &mut b], &mut f, Nanos::from_ns(0)).unwrap();
    let r = parse(&mut f).remove(0);
    assert_eq!(r.wkc, 6, "each slave: +1 read, +2 write");
    assert_eq!(&r.data[..8], &[1, 2, 3, 4, 5, 6, 7, 8], "outputs pass through");
    assert_eq!(&r.data[8..], &[0xA0, 0xA1, 0xA2, 0xA3, 0xB0, 0xB1, 0xB2, 0xB3]);
    let mut out = [0u8; 4];
    a.read(0x1100, &mut out).unwrap();
    assert_eq!(out, [1, 2, 3, 4]);
    b.read(0x1100, &mut out).unwrap();
    assert_eq!(out, [5, 6, 7, 8]);

    // LRD sees only the inputs (+1 each), LWR only the outputs (+1 each)
    let (_, wkc) = xfer(&mut [&mut a, &mut b], Command::Lrd, 0x0001_0000, &[0; 16], 0);
    assert_eq!(wkc, 2);
    let (_, wkc) = xfer(&mut [&mut a, &mut b], Command::Lwr, 0x0001_0000, &[0; 16], 0);
    assert_eq!(wkc, 2);
    // an LRW that maps nothing
    let (_, wkc) = xfer(&mut [&mut a, &mut b], Command::Lrw, 0x0002_0000, &[0; 16], 0);
    assert_eq!(wkc, 0);
}

#[test]
fn lrw_on_pdi_deactivated_sm_does_not_count() {
    use ::esc::{sm::pdi_control, Pdi};
    let mut a = esc_with_type(1);
    configure_pd(&mut a, 0x0001_0000, 0x0001_0008, 4);
    // the slave deactivates SM2 (still in PreOp)
    a.write(regs::sm(2) + 7, &[pdi_control::DEACTIVATE]).unwrap();
    let (_, wkc) = xfer1(&mut a, Command::Lrw, 0x0001_0000, &[1; 12], 0);
    assert_eq!(wkc, 1, "only the inputs count");
}

#[test]
fn malformed_frames_are_errors_without_panic() {
    let mut a = esc_with_type(1);
    let good = build(&[
        (Command::Aprd, phys(0, 0), &[0; 4]),
        (Command::Aprd, phys(0, 0), &[0; 4]),
    ]);
    // every truncation of a valid frame: no panic; short ones are errors
    for n in 0..good.len() {
        let mut f = good[..n].to_vec();
        let r = process_frame(&mut [&mut a], &mut f, Nanos::from_ns(0));
        // the datagram area ends at byte 16 + 2*16 = 48; shorter prefixes are errors
        if n < 48 {
            assert!(r.is_err(), "prefix {n}");
            assert_eq!(f, good[..n], "untouched");
        }
    }
    // wrong EtherType: error, untouched
    let mut f = good.clone();
    f[12] = 0x08;
    f[13] = 0x00;
    let before = f.clone();
    assert_eq!(
        process_frame(&mut [&mut a], &mut f, Nanos::from_ns(0)),
        Err(FrameError::NotEthercat(0x0800))
    );
    assert_eq!(f, before);
    // datagram length past the area
    let mut f = good.clone();
    f[16 + 6] = 0xF0;
    let before = f.clone();
    assert_eq!(
        process_frame(&mut [&mut a], &mut f, Nanos::from_ns(0)),
        Err(FrameError::MalformedDatagram)
    );
    assert_eq!(f, before);
    // "more follows" on the last datagram with nothing after it (unpadded)
    let mut f = good[..48].to_vec();
    f[16 + 16 + 7] |= 0x80;
    assert_eq!(
        process_frame(&mut [&mut a], &mut f, Nanos::from_ns(0)),
        Err(FrameError::MalformedDatagram)
    );
    // wrong frame type
    let mut f = good.clone();
    f[15] = (f[15] & 0x0F) | 0x40;
    assert_eq!(
        process_frame(&mut [&mut a], &mut f, Nanos::from_ns(0)),
        Err(FrameError::UnsupportedType(4))
    );
    // garbage of all lengths and patterns: never a panic
    for n in 0..80usize {
        for pat in [0x00u8, 0xFF, 0x88, 0xA4, 0x12] {
            let mut f: Vec<u8> = (0..n).map(|i| pat.wrapping_add(i as u8)).collect();
            if n > 14 {
                f[12] = 0x88;
                f[13] = 0xA4;
            }
            let _ = process_frame(&mut [&mut a], &mut f, Nanos::from_ns(0));
        }
    }
}

#[test]
fn datagram_iteration_stops_at_malformed() {
    let mut area = [0u8; 30];
    // first: 2 data bytes, more follows
    area[6] = 2;
    area[7] = 0x80;
    // second (at 14): claims 100 bytes
    area[14 + 6] = 100;
    let mut it = Datagrams::new(&mut area);
    let first = it.next().unwrap().unwrap();
    assert_eq!(first.data_len(), 2);
    assert_eq!(it.next().unwrap().unwrap_err(), FrameError::MalformedDatagram);
    assert!(it.next().is_none());
    assert!(Datagram::new_checked(&mut [0u8; 11]).is_err());
}

#[test]
fn vlan_tagged_frame_is_processed() {
    let mut a = esc_with_type(0x5C);
    let plain = build(&[(Command::Aprd, phys(0, regs::TYPE), &[0])]);
    let mut f = plain[..12].to_vec();
    f.extend_from_slice(&[0x81, 0x00, 0x00, 0x01]);
    f.extend_from_slice(&plain[12..]);
    process_frame(&mut [&mut a], &mut f, Nanos::from_ns(0)).unwrap();
    // data byte: 14 + 4 + 2 + 10
    assert_eq!(f[30], 0x5C);
}

#[test]
fn returned_frame_has_locally_administered_source_mac() {
    let mut a = esc_with_type(1);
    let mut f = build(&[(Command::Nop, 0, &[0])]);
    assert_eq!(f[6] & MAC_LOCAL_BIT, 0);
    process_frame(&mut [&mut a], &mut f, Nanos::from_ns(0)).unwrap();
    assert_eq!(f[6], MASTER_MAC[0] | MAC_LOCAL_BIT);
    assert_eq!(&f[7..12], &MASTER_MAC[1..]);
    // also through an empty line
    let mut f = build(&[(Command::Brd, 0, &[0])]);
    process_frame(&mut [], &mut f, Nanos::from_ns(0)).unwrap();
    assert_eq!(f[6] & MAC_LOCAL_BIT, MAC_LOCAL_BIT);
    assert_eq!(parse(&mut f)[0].wkc, 0);
}

#[test]
fn connect_line_opens_port1_except_last() {
    let (mut a, mut b) = (esc_with_type(1), esc_with_type(1));
    connect_line(&mut [&mut a, &mut b]);
    let dl = |e: &Esc| {
        let mut s = [0u8; 2];
        e.read_reg(regs::DL_STATUS, &mut s);
        u16::from_le_bytes(s)
    };
    // port 1: link bit 5, loop closed bit 10, communication bit 11
    assert_eq!(dl(&a) & (1 << 5 | 1 << 10 | 1 << 11), 1 << 5 | 1 << 11);
    assert_eq!(dl(&b) & (1 << 5 | 1 << 10 | 1 << 11), 1 << 10);
    // process_frame applies the line it is given
    let mut c = esc_with_type(1);
    let mut f = build(&[(Command::Nop, 0, &[0])]);
    process_frame(&mut [&mut b, &mut c], &mut f, Nanos::from_ns(0)).unwrap();
    assert_eq!(dl(&b) & (1 << 5 | 1 << 10 | 1 << 11), 1 << 5 | 1 << 11);
    assert_eq!(dl(&c) & (1 << 5 | 1 << 10 | 1 << 11), 1 << 10);
}

/// A frame built by `build`, unpadded, with the EtherCAT header's length
/// field changed by `delta` bytes (libethercat: +16).
fn as_sent(dgs: &[(Command, u32, &[u8])], delta: i32, pad_to: usize) -> Vec<u8> {
    let mut f = build(dgs);
    let area: usize = dgs
        .iter()
        .map(|(_, _, d)| DATAGRAM_HEADER_LEN + d.len() + WKC_LEN)
        .sum();
    f.truncate(ETHERNET_HEADER_LEN + ECAT_HEADER_LEN + area);
    let len = (area as i32 + delta) as u16 & 0x07FF;
    f[14..16].copy_from_slice(&(len | 0x1000).to_le_bytes());
    f.resize(f.len().max(pad_to), 0);
    f
}

/// Two slaves: BRD of the type register (WKC 2), APWR of the station address
/// of position 1, FPRD of it back; the replies (WKC, data) of one frame.
fn scan_frame(f: &mut [u8]) -> Result<Vec<(u16, Vec<u8>)>, FrameError> {
    let (mut a, mut b) = (esc_with_type(1), esc_with_type(1));
    process_frame(&mut [&mut a, &mut b], f, Nanos::from_ns(0))?;
    let first = parse(f).into_iter().map(|r| (r.wkc, r.data)).collect();
    // the station address written by the first frame answers a second one
    let mut g = build(&[(Command::Fprd, phys(0x1001, regs::STATION_ADDRESS), &[0; 2])]);
    process_frame(&mut [&mut a, &mut b], &mut g, Nanos::from_ns(0)).unwrap();
    let r = parse(&mut g).remove(0);
    assert_eq!((r.wkc, r.data), (1, std::vec![0x01, 0x10]), "FPWR applied");
    Ok(first)
}

/// [`scan_frame`] of `f` answered as the scan must be: the BRD by both
/// ESCs (type 1), the APWR by position 1 (`what`: the case).
fn assert_scanned(f: &mut [u8], what: &str) {
    let got = scan_frame(f).unwrap_or_else(|e| panic!("{what}: {e:?}"));
    assert_eq!(
        got,
        std::vec![(2, std::vec![1]), (1, std::vec![0x01, 0x10])],
        "{what}"
    );
}

fn scan_dgs() -> [(Command, u32, &'static [u8]); 2] {
    [
        (Command::Brd, phys(0, 0), &[0; 1]),
        (Command::Apwr, phys(pos(1), regs::STATION_ADDRESS), &[0x01, 0x10]),
    ]
}

#[test]
fn e002_header_length_larger_than_the_datagrams_is_processed_as_silicon_does() {
    // libethercat: header length 16 bytes more than its datagrams, unpadded
    for delta in [16, 1, 200] {
        let mut f = as_sent(&scan_dgs(), delta, 0);
        assert_scanned(&mut f, &std::format!("+{delta}"));
    }
}

#[test]
fn e002_header_length_smaller_than_the_datagrams_is_processed_as_silicon_does() {
    for delta in [-1, -16, -30] {
        let mut f = as_sent(&scan_dgs(), delta, 60);
        assert_scanned(&mut f, &std::format!("{delta}"));
    }
}

#[test]
fn e002_frame_shorter_than_60_bytes_is_processed() {
    let mut f = as_sent(&scan_dgs(), 0, 0);
    assert_eq!(f.len(), 16 + 13 + 14, "no padding");
    assert!(f.len() < 60);
    assert_scanned(&mut f, "no padding");
}

#[test]
fn e002_trailing_bytes_after_the_last_datagram_are_ignored_and_kept() {
    let mut f = as_sent(&scan_dgs(), 0, 0);
    let n = f.len();
    f.extend_from_slice(&[0xAA; 24]); // a trailer (e.g. a time stamp) or odd padding
    assert_scanned(&mut f, "with a trailer");
    assert_eq!(&f[n..], &[0xAA; 24], "the trailer comes back as it was");
}

#[test]
fn e002_datagram_past_the_end_of_the_frame_is_refused_untouched() {
    // strict where silicon is: the frame ends inside a datagram
    let full = as_sent(&scan_dgs(), 0, 0);
    for cut in [full.len() - 1, full.len() - 2, 16 + 11 + 5] {
        let mut f = full[..cut].to_vec();
        let before = f.clone();
        let mut a = esc_with_type(1);
        assert_eq!(
            process_frame(&mut [&mut a], &mut f, Nanos::from_ns(0)),
            Err(FrameError::MalformedDatagram),
            "cut at {cut}"
        );
        assert_eq!(f, before, "untouched");
    }
}

/// A libethercat-style frame as its scan sends it: BRD 0x0000 (type), header
/// length = datagrams + 16, no padding (veth), through the frame path `serve`
/// uses (`Simulation::exchange`): both drives answer.
#[test]
fn e002_libethercat_style_frame_through_the_simulated_line() {
    let mut sim = crate::sim::Simulation::new(2);
    let mut f = as_sent(&[(Command::Brd, phys(0, 0), &[0; 2])], 16, 0);
    assert!(f.len() < 60);
    sim.exchange(&mut f);
    let r = parse(&mut f).remove(0);
    assert_eq!(r.wkc, 2, "both drives answered");
}
