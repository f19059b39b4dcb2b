//! The scope on PROFINET (issue 35, [`crate::scope_record`]): group T
//! through record 0xB02E, the trace through records 4700h…, and what bad
//! input gets.

use super::scope_record::{PIECE_BYTES, SCOPE_RECORD};
use super::tests::{drive, run, TestFlash};
use super::tests_bmp::{change_req as change, exchange, read_req};
use super::tests_energy::record_at;
use super::PnDrive;
use drive_core::params::{T00, T01, T02, T03, T04, T05, T10, T11};
use drive_core::scope::{Signal, State};
use profinet::cm::PnioStatus;
use std::vec::Vec;

/// A drive with a scope of `words` words.
fn scoped(words: usize) -> PnDrive<TestFlash> {
    let mut d = drive();
    assert!(d.attach_scope(std::boxed::Box::leak(std::vec![0u32; words].into_boxed_slice())));
    assert!(
        !d.attach_scope(std::boxed::Box::leak(std::vec![0u32; 4].into_boxed_slice())),
        "once"
    );
    d
}

const U8: u8 = 0x05;
const U16: u8 = 0x06;
const U32: u8 = 0x07;

/// Position actual (6064h, 32 bits), the statusword (6041h, 16 bits).
const POSITION: u32 = 0x6064_0020;
const STATUSWORD: u32 = 0x6041_0010;

/// Configured and armed through 0xB02E alone (PNU = the object's index),
/// recorded by the control cycles, the complete trace read back through the
/// trace records: every value as the recorder holds it, the channels the
/// drive's 6064h and 6041h; T00 and T10 read back through 0xB02E; an
/// internal signal is a channel as well (T01 takes its code).
#[test]
fn issue35_scope_through_0xb02e_and_the_trace_records() {
    let mut d = scoped(4096);
    let (s, _) = record_at(&mut d, 2, false, SCOPE_RECORD, &[]);
    assert_eq!(s.code1, 0xB5, "no trace yet: state conflict");
    let r = exchange(
        &mut d,
        10,
        &change(
            1,
            &[
                (T01, 1, U32, &POSITION.to_be_bytes()),
                (T01, 2, U32, &STATUSWORD.to_be_bytes()),
                (T02, 0, U8, &[2, 0]),
                (T03, 0, U16, &2u16.to_be_bytes()),
                (T04, 0, U32, &300u32.to_be_bytes()),
                (T05, 0, U16, &0u16.to_be_bytes()),
            ],
        ),
    );
    assert_eq!(r, [1, 0x02, 0x01, 6], "configured");
    assert_eq!(
        exchange(&mut d, 12, &change(2, &[(T00, 0, U8, &[1, 0])])),
        [2, 0x02, 0x01, 1]
    );
    assert_eq!(d.scope().map(|s| s.state()), Some(State::Armed));
    run(&mut d, 0, 300, false);
    assert_eq!(
        d.scope().map(|s| s.state()),
        Some(State::Triggered),
        "triggered at once, 150 of 300"
    );
    let (s, _) = record_at(&mut d, 14, false, SCOPE_RECORD, &[]);
    assert_eq!(s.code1, 0xB5, "not complete: state conflict, never stale data");
    run(&mut d, 300, 601, false);
    assert_eq!(
        exchange(&mut d, 16, &read_req(3, &[(T00, 0)])),
        [3, 0x01, 0x01, 1, U8, 1, 3, 0]
    );
    assert_eq!(
        exchange(&mut d, 18, &read_req(4, &[(T10, 1)])),
        [4, 0x01, 0x01, 1, U32, 1, 0, 0, 0x01, 0x2C],
        "300 samples"
    );
    let bytes: usize = 300 * 2 * 4;
    let mut trace = Vec::new();
    for k in 0..bytes.div_ceil(PIECE_BYTES) {
        let (s, r) = record_at(&mut d, 20 + k as u32, false, SCOPE_RECORD + k as u16, &[]);
        assert_eq!(s, PnioStatus::OK, "piece {k}");
        assert_eq!(r.len(), PIECE_BYTES.min(bytes - k * PIECE_BYTES));
        trace.extend_from_slice(&r);
    }
    let scope = d.scope().unwrap();
    let position = d.objects().get(0x6064, 0).unwrap() as i32;
    let statusword = d.objects().get(0x6041, 0).unwrap() as i32;
    assert_ne!(statusword, 0);
    for (i, sample) in trace.chunks_exact(8).enumerate() {
        let v = |k: usize| i32::from_le_bytes(sample[4 * k..4 * k + 4].try_into().unwrap());
        assert_eq!(Some(v(0)), scope.value(i as u32, 0));
        assert_eq!(Some(v(1)), scope.value(i as u32, 1));
        assert_eq!((v(0), v(1)), (position, statusword), "at rest: 6064h, 6041h");
    }
    let pieces = bytes.div_ceil(PIECE_BYTES) as u16;
    assert!(pieces > 1, "read in more than one piece");
    let (s, _) = record_at(&mut d, 40, false, SCOPE_RECORD + pieces, &[]);
    assert_eq!(s.code1, 0xB7, "beyond the trace: invalid range");
}

/// Bad input changes nothing: a channel that is not mappable, a length
/// beyond the buffer, T11 through the parameter access (a 4 KiB element),
/// a write to a trace record, a configuration while armed.
#[test]
fn issue35_scope_on_profinet_refuses_bad_input() {
    let mut d = scoped(1024);
    // 1018h (identity) is not mappable; 9999 samples of 2 channels exceed 1024 words
    let r = exchange(
        &mut d,
        10,
        &change(1, &[(T01, 1, U32, &0x1018_0120u32.to_be_bytes())]),
    );
    assert_eq!(r.get(1), Some(&0x82), "refused: {r:02x?}");
    let r = exchange(&mut d, 12, &change(2, &[(T04, 0, U32, &9999u32.to_be_bytes())]));
    assert_eq!(r.get(1), Some(&0x82), "refused: {r:02x?}");
    let c = d.scope().unwrap().config();
    assert_eq!((c.channels[0], c.length), (0, 0), "nothing changed");
    let r = exchange(&mut d, 14, &read_req(3, &[(T11, 1)]));
    assert_eq!(r.get(1), Some(&0x81), "T11 is the records' job: {r:02x?}");
    assert_eq!(
        record_at(&mut d, 16, true, SCOPE_RECORD, &[0; 8]).0.code1,
        0xB6,
        "the trace is read-only"
    );
    // armed: the configuration is refused until stopped
    exchange(
        &mut d,
        18,
        &change(
            4,
            &[
                (T01, 1, U32, &POSITION.to_be_bytes()),
                (T02, 0, U8, &[1, 0]),
                (T04, 0, U32, &100u32.to_be_bytes()),
            ],
        ),
    );
    assert_eq!(
        exchange(&mut d, 20, &change(5, &[(T00, 0, U8, &[1, 0])])),
        [5, 0x02, 0x01, 1]
    );
    let r = exchange(&mut d, 22, &change(6, &[(T04, 0, U32, &50u32.to_be_bytes())]));
    assert_eq!(r.get(1), Some(&0x82), "armed: {r:02x?}");
    assert_eq!(d.scope().unwrap().config().length, 100);
    // stopped: an internal signal as channel 2
    assert_eq!(
        exchange(&mut d, 24, &change(7, &[(T00, 0, U8, &[0, 0])])),
        [7, 0x02, 0x01, 1]
    );
    let speed = Signal::SpeedActual.code(0);
    assert_eq!(
        exchange(&mut d, 26, &change(8, &[(T01, 2, U32, &speed.to_be_bytes())])),
        [8, 0x02, 0x01, 1]
    );
    assert_eq!(d.scope().unwrap().config().channels[1], speed);
}

/// Without a buffer the drive has no scope: group T answers "not in this
/// state" and the trace records do not exist.
#[test]
fn issue35_scope_on_profinet_without_a_buffer() {
    let mut d = drive();
    let r = exchange(&mut d, 10, &change(1, &[(T00, 0, U8, &[1, 0])]));
    assert_eq!(r.get(1), Some(&0x82), "{r:02x?}");
    assert_eq!(record_at(&mut d, 12, false, SCOPE_RECORD, &[]).0.code1, 0xB0);
}
