//! The position-record objects (J400 … J411) over the object dictionary as
//! a CoE server (or a PNU layer) reaches them: read, write, ranges, the
//! window on the selected record, per-axis and shared records,
//! persistence. Named after the spec items (features-profidrive.md).

use crate::objects::records::{
    Record, FIELDBUS, J400, J401, J402, J403, J404, J410, J411, JOG_NEGATIVE, JOG_POSITIVE,
    STANDARD_RECORDS_SAVED,
};
use crate::*;
use od::{CommState, Dictionary as _, SdoAbort};
use std::vec::Vec;

const OP: CommState = CommState::Op;

fn rd(d: &mut DriveObjects, index: u16, sub: u8) -> Result<Vec<u8>, SdoAbort> {
    let mut buf = [0u8; 64];
    let n = d.read(index, sub, &mut buf, OP)?;
    Ok(buf[..n].to_vec())
}

fn rd_u(d: &mut DriveObjects, index: u16, sub: u8) -> u32 {
    let v = rd(d, index, sub).unwrap();
    let mut b = [0u8; 4];
    b[..v.len()].copy_from_slice(&v);
    u32::from_le_bytes(b)
}

fn wr(d: &mut DriveObjects, index: u16, sub: u8, v: u32, n: usize) -> Result<(), SdoAbort> {
    d.write(index, sub, &v.to_le_bytes()[..n], OP)
}

/// J401 element `k` in the SDO Info numbering (the default template).
const fn el(k: u8) -> u8 {
    k + 1
}

/// P-141, P-142: J400 selects 0 … 267 (default 266), 268 is refused; the
/// objects are in the object list at the default access level.
#[test]
fn p141_record_selector_default_266_range_0_to_267() {
    let mut d = DriveObjects::new();
    for index in [J400, J401, J402, J403, J404, J400 + AXIS_B_MANUFACTURER] {
        assert!(d.object(index).is_some(), "{index:04X}h listed");
    }
    assert_eq!(rd_u(&mut d, J400, 0), u32::from(FIELDBUS));
    assert_eq!(wr(&mut d, J400, 0, 268, 2), Err(SdoAbort::VALUE_TOO_HIGH));
    assert_eq!(wr(&mut d, J400, 0, 267, 2), Ok(()));
    assert_eq!(wr(&mut d, J400, 0, 0, 2), Ok(()));
    assert_eq!(rd_u(&mut d, J400, 0), 0);
    // the memory is hidden at the default level and read-only
    assert!(d.object(J410).is_none() && d.object(J411).is_none());
    assert_eq!(wr(&mut d, J410, 0, 0, 1), Err(SdoAbort::NO_OBJECT));
}

/// P-143: J401 reads and writes the record J400 selects; moving the
/// selector keeps what was written; axis B's special records are its own,
/// the standard records are shared.
#[test]
fn p143_record_data_reads_and_writes_the_selected_record() {
    let mut d = DriveObjects::new();
    wr(&mut d, J400, 0, 10, 2).unwrap();
    let values = [(-123_456i32) as u32, 2_000_000, 500_000, 30_000_000, 40_000_000];
    for (k, v) in (0u8..).zip(values) {
        wr(&mut d, J401, el(k), v, 4).unwrap();
    }
    wr(&mut d, J401, el(6), 3, 1).unwrap();
    wr(&mut d, J400, 0, 11, 2).unwrap();
    assert_eq!(rd_u(&mut d, J401, el(0)), 0, "record 11 at its default");
    wr(&mut d, J400, 0, 10, 2).unwrap();
    for (k, v) in (0u8..).zip(values) {
        assert_eq!(rd_u(&mut d, J401, el(k)), v, "element {k}");
    }
    let r = d.record(0, 10).unwrap();
    assert_eq!(
        (
            r.target,
            r.profile_velocity,
            r.end_velocity,
            r.acceleration,
            r.deceleration,
            r.options
        ),
        (-123_456, 2_000_000, 500_000, 30_000_000, 40_000_000, 3)
    );
    assert_eq!(d.record(1, 10), Some(r), "standard records: one table");
    wr(&mut d, J400, 0, u32::from(FIELDBUS), 2).unwrap();
    assert_eq!(wr(&mut d, J401, el(6), 4, 1), Err(SdoAbort::VALUE_TOO_HIGH));
    // per-axis record 266
    wr(&mut d, J401, el(0), 777, 4).unwrap();
    assert_eq!(d.record(0, FIELDBUS).unwrap().target, 777);
    assert_eq!(d.record(1, FIELDBUS).unwrap().target, 0, "axis B's own");
    let b = J401 + AXIS_B_MANUFACTURER;
    assert_eq!(rd_u(&mut d, b, el(0)), 0);
    wr(&mut d, b, el(0), 999, 4).unwrap();
    assert_eq!(d.record(1, FIELDBUS).unwrap().target, 999);
    assert_eq!(d.record(0, FIELDBUS).unwrap().target, 777);
    // the "EtherCAT Rx" template: subindex = element
    d.set_template(Template::Rx);
    assert_eq!(rd_u(&mut d, J401, 0), 777);
}

/// P-144: J401[5] "all accelerations": a write sets acceleration and
/// deceleration, a read returns the acceleration.
#[test]
fn p144_all_accelerations_write_sets_both_read_gives_acceleration() {
    let mut d = DriveObjects::new();
    wr(&mut d, J401, el(3), 1_000, 4).unwrap();
    wr(&mut d, J401, el(4), 2_000, 4).unwrap();
    assert_eq!(rd_u(&mut d, J401, el(5)), 1_000, "read = acceleration");
    wr(&mut d, J401, el(5), 5_000, 4).unwrap();
    assert_eq!(rd_u(&mut d, J401, el(3)), 5_000);
    assert_eq!(rd_u(&mut d, J401, el(4)), 5_000);
    let r = d.record(0, FIELDBUS).unwrap();
    assert_eq!((r.acceleration, r.deceleration), (5_000, 5_000));
    // a value a cyclic mapping leaves in [5] applies when the record is used
    d.set(J401, el(5), 7_000).unwrap();
    let r = d.take_record(0, FIELDBUS).unwrap();
    assert_eq!((r.acceleration, r.deceleration), (7_000, 7_000));
    assert_eq!(rd_u(&mut d, J401, el(4)), 7_000);
}

/// P-145, P-177: defaults 0 / 1000 rpm / 0 / 10 000 rpm/s / 10 000 rpm/s;
/// jog records 100 rpm and 1000 rpm/s (default user unit: increments, 2^20
/// per revolution).
#[test]
fn p145_p177_record_defaults() {
    let mut d = DriveObjects::new();
    let rpm = |v: u32| f64::from(v) * 60.0 / f64::from(1u32 << 20);
    for n in [0, 200, 255, 256, 266, 267] {
        let r = d.record(0, n).unwrap();
        assert_eq!(r.target, 0, "record {n}: {r:?}");
        assert!((rpm(r.profile_velocity) - 1000.0).abs() < 0.01, "record {n}");
        assert_eq!(r.end_velocity, 0);
        assert!((rpm(r.acceleration) - 10_000.0).abs() < 0.01);
        assert_eq!(r.acceleration, r.deceleration);
    }
    for n in [JOG_POSITIVE, JOG_NEGATIVE] {
        let r = d.record(1, n).unwrap();
        assert!((rpm(r.profile_velocity) - 100.0).abs() < 0.01);
        assert!((rpm(r.acceleration) - 1000.0).abs() < 0.01);
    }
    assert_eq!(d.record(0, 268), None);
    // the window shows record 266's defaults
    assert_eq!(
        rd_u(&mut d, J401, el(1)),
        d.record(0, FIELDBUS).unwrap().profile_velocity
    );
    assert!(
        (rpm(rd_u(&mut d, J404, 0)) - 3276.0).abs() < 0.01,
        "P-183 set-up speed"
    );
}

/// P-146: J402 default 255 (= record 266), 0 … 255.
#[test]
fn p146_start_record_number_default_255() {
    let mut d = DriveObjects::new();
    assert_eq!(rd_u(&mut d, J402, 0), 255);
    assert_eq!(wr(&mut d, J402, 0, 254, 1), Ok(()));
    assert_eq!(rd_u(&mut d, J402, 0), 254);
}

/// P-149, P-151: J403 0 … 2000 ‰, default 1000, not saved (a restart or
/// a load brings 1000 back).
#[test]
fn p151_override_default_1000_not_saved() {
    let mut d = DriveObjects::new();
    assert_eq!(rd_u(&mut d, J403, 0), 1000);
    assert_eq!(wr(&mut d, J403, 0, 2001, 2), Err(SdoAbort::VALUE_TOO_HIGH));
    wr(&mut d, J403, 0, 2000, 2).unwrap();
    let mut image = [0u8; PERSISTENT_IMAGE_BYTES];
    d.persistent_image(&mut image).unwrap();
    let mut fresh = DriveObjects::new();
    fresh.load_persistent(&image).unwrap();
    assert_eq!(rd_u(&mut fresh, J403, 0), 1000);
}

/// Persistence: the save service keeps the homing and jog records (256 …
/// 260) and the standard records as [`STANDARD_RECORDS_SAVED`] says, never
/// record 266; 1011h "load" brings every record's default back.
#[test]
fn records_saved_and_restored() {
    let mut d = DriveObjects::new();
    let mut r = Record::JOG_DEFAULT;
    r.profile_velocity = 12_345;
    d.set_record(1, JOG_POSITIVE, &r);
    let mut s = Record::STANDARD_DEFAULT;
    s.target = 42;
    d.set_record(0, 5, &s);
    d.set_record(0, FIELDBUS, &s);
    let mut image = [0u8; PERSISTENT_IMAGE_BYTES];
    d.persistent_image(&mut image).unwrap();
    let mut fresh = DriveObjects::new();
    fresh.load_persistent(&image).unwrap();
    assert_eq!(fresh.record(1, JOG_POSITIVE).unwrap().profile_velocity, 12_345);
    assert_eq!(fresh.record(0, JOG_POSITIVE), Some(Record::JOG_DEFAULT));
    assert_eq!(fresh.record(0, FIELDBUS).unwrap().target, 0, "266 not kept");
    let kept = if STANDARD_RECORDS_SAVED { 42 } else { 0 };
    assert_eq!(fresh.record(0, 5).unwrap().target, kept);
    // 1011h:01 "load": every record at its default, the window too
    wr(&mut d, J400, 0, 5, 2).unwrap();
    d.write(0x1011, 1, &LOAD_SIGNATURE.to_le_bytes(), CommState::PreOp)
        .unwrap();
    assert_eq!(d.record(0, 5), Some(Record::STANDARD_DEFAULT));
    assert_eq!(d.record(1, JOG_POSITIVE), Some(Record::JOG_DEFAULT));
    assert_eq!(rd_u(&mut d, J401, el(0)), 0);
}

/// P-142: the record map: 0 … 255 standard (one table of the drive),
/// 256 … 258 homing, 259/260 jog (own defaults), 266 the fieldbus record,
/// 256 … 267 per axis; nothing beyond 267.
#[test]
fn p142_record_map() {
    let mut d = DriveObjects::new();
    let mut r = Record::STANDARD_DEFAULT;
    for n in 0..=267u16 {
        r.target = i32::from(n) + 1;
        assert!(d.set_record(0, n, &r), "record {n}");
    }
    assert!(!d.set_record(0, 268, &r));
    for n in 0..=267u16 {
        let shared = n < 256;
        let b = d.record(1, n).unwrap().target;
        assert_eq!(b == i32::from(n) + 1, shared, "record {n} on axis B");
        assert_eq!(d.record(0, n).unwrap().target, i32::from(n) + 1);
    }
    let fresh = DriveObjects::new();
    assert_eq!(fresh.record(0, 258), Some(Record::STANDARD_DEFAULT));
    assert_eq!(fresh.record(0, JOG_POSITIVE), Some(Record::JOG_DEFAULT));
    assert_eq!(fresh.record(0, JOG_NEGATIVE), Some(Record::JOG_DEFAULT));
    // J400 reaches every record of the map through J401
    wr(&mut d, J400, 0, 267, 2).unwrap();
    assert_eq!(rd_u(&mut d, J401, el(0)), 268);
}
