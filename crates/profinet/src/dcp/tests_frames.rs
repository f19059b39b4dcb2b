//! Frames exactly as profinet-py 0.6.6 (the CI controller) sends them, and our
//! answers read the way its parsers read them (`read_response`: blocks while
//! more than 6 bytes remain, BlockInfo stripped; `_parse_set_response`: the
//! third value byte of a Control/Response block is the BlockError).
//!
//! The vectors were printed by calling profinet-py's `send_discover`,
//! `send_request`, `get_param`, `set_param`, `set_ip`, `signal_device` and
//! `reset_to_factory` with a capturing socket (controller 02:00:00:00:00:01,
//! device 02:00:00:00:00:aa, xid 0x12345678). Note they are not padded to 60
//! bytes, an odd filter is not padded, and a Get's DCPDataLength (2) is
//! shorter than the block it wrote.

use std::vec::Vec;

use super::pdu::*;
use super::tests::{assert_name_event, assert_suite_event, server, suite, PLC};
use super::*;
use nanos::Nanos;

fn hex(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
        .collect()
}

const IDENTIFY_ALL: &str = "010ecf0000000200000000018892fefe05001234567800800004ffff0000";
const IDENTIFY_NAME: &str = "010ecf0000000200000000018892fefe0500123456780080000b0202000764726976652d31";
const GET_NAME: &str = "0200000000aa0200000000018892fefd0300123456780000000202020000";
const GET_IP: &str = "0200000000aa0200000000018892fefd0300123456780000000201020000";
const SET_NAME_PERM: &str =
    "0200000000aa0200000000018892fefd0400123456780000000e02020009000164726976652d3100";
const SET_NAME_TEMP: &str = "0200000000aa0200000000018892fefd0400123456780000000c020200080000617869732d61";
const SET_IP_PERM: &str =
    "0200000000aa0200000000018892fefd040012345678000000120102000e0001c0a80032ffffff00c0a80001";
const SET_IP_TEMP: &str =
    "0200000000aa0200000000018892fefd040012345678000000120102000e00000a000007ff00000000000000";
const SIGNAL: &str = "0200000000aa0200000000018892fefd040012345678000000080503000400000100";
const RESET_DEFAULT: &str = "0200000000aa0200000000018892fefd04001234567800000006050600020002";
const RESET_COMM: &str = "0200000000aa0200000000018892fefd04001234567800000006050600020004";

/// profinet-py's `read_response` on one frame: (option, suboption) → payload
/// after the BlockInfo, walking while DCPDataLength − consumed > 6.
fn pnpy_read_response(frame: &[u8]) -> Vec<((u8, u8), Vec<u8>)> {
    assert_eq!(&frame[..6], &PLC.0, "unicast to the controller");
    assert_eq!(&frame[12..14], &[0x88, 0x92]);
    let fid = u16::from_be_bytes([frame[14], frame[15]]);
    assert!(fid == 0xFEFF || fid == 0xFEFD);
    let dcp = &frame[16..];
    assert_eq!(dcp[1], 1, "service type response");
    let mut length = i32::from(u16::from_be_bytes([dcp[8], dcp[9]]));
    let mut blocks = &dcp[10..];
    let mut out = Vec::new();
    while length > 6 {
        let len = usize::from(u16::from_be_bytes([blocks[2], blocks[3]]));
        out.push(((blocks[0], blocks[1]), blocks[6..4 + len].to_vec()));
        let padded = len + (len % 2);
        blocks = &blocks[padded + 4..];
        length -= 4 + padded as i32;
    }
    out
}

/// profinet-py's `_parse_set_response`: the first Control/Response block's
/// BlockError.
fn pnpy_set_result(frame: &[u8]) -> u8 {
    let dcp = &frame[16..];
    assert_eq!(dcp[1], 1, "service type success");
    let mut remaining = i32::from(u16::from_be_bytes([dcp[8], dcp[9]]));
    let mut blocks = &dcp[10..];
    while remaining > 4 {
        let len = usize::from(u16::from_be_bytes([blocks[2], blocks[3]]));
        if (blocks[0], blocks[1]) == (5, 4) {
            assert!(len >= 3);
            return blocks[4 + 2];
        }
        let padded = len + (len % 2);
        blocks = &blocks[4 + padded..];
        remaining -= (4 + padded) as i32;
    }
    panic!("no Control/Response block");
}

fn answer(s: &mut DcpServer, now: Nanos, req: &str) -> (Vec<u8>, Nanos, Events) {
    let mut out = [0u8; 1514];
    let o = s.handle_frame(now, &hex(req), &mut out);
    let r = o.reply.expect("answered");
    (out[..r.len].to_vec(), r.send_at, o.events)
}

#[test]
fn p008_profinet_py_identify_all_finds_the_drive() {
    let mut s = server("drive-1");
    let t = Nanos::from_secs(1);
    let (f, at, _) = answer(&mut s, t, IDENTIFY_ALL);
    // Factor 0x80 (1.28 s): h = 0x02AA mod 128 = 42 → 420 ms.
    assert_eq!(at, t + Nanos::from_ms(420));
    assert_eq!(&f[16..22], &[0x05, 0x01, 0x12, 0x34, 0x56, 0x78]);
    let blocks = pnpy_read_response(&f);
    let get = |k| blocks.iter().find(|(p, _)| *p == k).map(|(_, v)| v.clone());
    assert_eq!(get((2, 2)).unwrap(), b"drive-1");
    assert_eq!(get((2, 1)).unwrap(), crate::model::STATION_TYPE.as_bytes());
    assert_eq!(get((2, 3)).unwrap(), [0xFE, 0xFE, 0x00, 0x01]);
    assert_eq!(get((2, 4)).unwrap(), [0x01, 0x00]);
    assert_eq!(
        get((1, 2)).unwrap(),
        [192, 168, 0, 86, 255, 255, 255, 0, 192, 168, 0, 86]
    );
    assert_eq!(blocks.len(), 7, "every block read, none lost to the > 6 rule");
}

#[test]
fn p008_profinet_py_identify_by_name() {
    let mut s = server("drive-1");
    let (f, _, _) = answer(&mut s, Nanos::ZERO, IDENTIFY_NAME);
    assert!(pnpy_read_response(&f)
        .iter()
        .any(|(k, v)| *k == (2, 2) && v == b"drive-1"));
    let mut other = server("drive-2");
    let mut out = [0u8; 1514];
    assert!(other
        .handle_frame(Nanos::ZERO, &hex(IDENTIFY_NAME), &mut out)
        .reply
        .is_none());
}

#[test]
fn profinet_py_get_name_and_ip() {
    let mut s = server("drive-1");
    let (f, _, _) = answer(&mut s, Nanos::ZERO, GET_NAME);
    assert_eq!(pnpy_read_response(&f), [((2, 2), b"drive-1".to_vec())]);
    let (f, _, _) = answer(&mut s, Nanos::ZERO, GET_IP);
    let ip = [192, 168, 0, 86, 255, 255, 255, 0, 192, 168, 0, 86];
    assert_eq!(pnpy_read_response(&f), [((1, 2), ip.to_vec())]);
}

#[test]
fn p007_profinet_py_set_name_permanent_and_temporary() {
    let mut s = server("");
    let (f, _, ev) = answer(&mut s, Nanos::ZERO, SET_NAME_PERM);
    assert_eq!(pnpy_set_result(&f), 0);
    let name: NameOfStation = "drive-1".parse().unwrap();
    assert_name_event(&ev, name, true);
    let (f, _, ev) = answer(&mut s, Nanos::ZERO, SET_NAME_TEMP);
    assert_eq!(pnpy_set_result(&f), 0);
    let name: NameOfStation = "axis-a".parse().unwrap();
    assert_name_event(&ev, name, false);
    assert_eq!(s.name_of_station().as_str(), "axis-a");
}

#[test]
fn p009_profinet_py_set_ip_overwrites_the_static_ip() {
    let mut s = server("drive-1");
    let (f, _, ev) = answer(&mut s, Nanos::ZERO, SET_IP_PERM);
    assert_eq!(pnpy_set_result(&f), 0);
    let new = suite([192, 168, 0, 50], [255, 255, 255, 0], [192, 168, 0, 1]);
    assert_suite_event(&ev, new, true);
    assert_eq!(s.ip_suite(), new);
    let (f, _, ev) = answer(&mut s, Nanos::ZERO, SET_IP_TEMP);
    assert_eq!(pnpy_set_result(&f), 0);
    let tmp = suite([10, 0, 0, 7], [255, 0, 0, 0], [0, 0, 0, 0]);
    assert_suite_event(&ev, tmp, false);
}

#[test]
fn p011_profinet_py_signal_flashes_the_led() {
    let mut s = server("drive-1");
    let t = Nanos::from_secs(7);
    let (f, _, ev) = answer(&mut s, t, SIGNAL);
    assert_eq!(pnpy_set_result(&f), 0);
    assert_eq!(
        &ev[..],
        [Event::Signal {
            until: t + Nanos::from_secs(3)
        }]
    );
    assert!(s.signal().is_lit(t + Nanos::from_ms(100)));
}

#[test]
fn profinet_py_reset_to_factory() {
    // Its default qualifier 0x0002 is mode 1, application data.
    let mut s = server("drive-1");
    let (f, _, ev) = answer(&mut s, Nanos::ZERO, RESET_DEFAULT);
    assert_eq!(pnpy_set_result(&f), 0);
    assert_eq!(&ev[..], [Event::ResetToFactory(ResetMode::ApplicationData)]);
    assert_eq!(s.name_of_station().as_str(), "drive-1");
    let (f, _, ev) = answer(&mut s, Nanos::ZERO, RESET_COMM);
    assert_eq!(pnpy_set_result(&f), 0);
    assert_eq!(ev[0], Event::ResetToFactory(ResetMode::Communication));
    assert!(s.name_of_station().is_empty() && s.ip_suite().is_unset());
}

#[test]
fn profinet_py_requests_parse_with_our_views() {
    for req in [
        IDENTIFY_ALL,
        IDENTIFY_NAME,
        SET_NAME_PERM,
        SET_IP_PERM,
        SIGNAL,
        RESET_COMM,
    ] {
        let f = hex(req);
        let p = Packet::new_checked(&f[16..]).unwrap();
        assert_eq!(p.xid(), 0x1234_5678);
        assert!(Blocks::new(p.data()).all(|b| b.is_ok()), "{req}");
    }
}

/// Prints our answers to the profinet-py requests as hex, one per line, for
/// the tshark and profinet-py checks (`cargo test -p profinet dump_answers --
/// --ignored --nocapture`).
#[test]
#[ignore]
fn dump_answers() {
    for req in [
        IDENTIFY_ALL,
        IDENTIFY_NAME,
        GET_NAME,
        GET_IP,
        SET_NAME_PERM,
        SET_IP_PERM,
        SIGNAL,
        RESET_COMM,
    ] {
        let mut s = server("drive-1");
        let (f, _, _) = answer(&mut s, Nanos::ZERO, req);
        std::println!("{req}");
        let h: Vec<std::string::String> = f.iter().map(|b| std::format!("{b:02x}")).collect();
        std::println!("{}", h.concat());
    }
    let mut out = [0u8; 1514];
    let mut s = server("drive-1");
    let get_all = "0200000000aa0200000000018892fefd03001234567800000002ffff";
    let n = s
        .handle_frame(Nanos::ZERO, &hex(get_all), &mut out)
        .reply
        .unwrap()
        .len;
    std::println!("{get_all}");
    let h: Vec<std::string::String> = out[..n].iter().map(|b| std::format!("{b:02x}")).collect();
    std::println!("{}", h.concat());
    let _ = BlockType::All;
}
