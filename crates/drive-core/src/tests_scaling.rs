//! Fieldbus scaling A213 (E-059, E-143, E-086, C-142): the object, its
//! elements and the decimal places A310/A311, the parameter channel's
//! representation, and the scaled entries against the declaration and the
//! axis. Through a master: `tests/tests/fieldbus_scaling.rs`.

use crate::axis::{Snapshot, Window};
use crate::objects::scaling::{scaled, Quantity, SCALED};
use crate::objects::{find, records::J401, Value, OBJECTS};
use crate::params::{A213, A310, A311};
use crate::*;
use od::{Access, CommState, DataType, Dictionary as _, ObjectCode, SdoAbort};
use std::vec::Vec;

const PREOP: CommState = CommState::PreOp;
const SAFEOP: CommState = CommState::SafeOp;
const OP: CommState = CommState::Op;

fn write(d: &mut DriveObjects, index: u16, sub: u8, bytes: &[u8], state: CommState) -> Result<(), SdoAbort> {
    d.write(index, sub, bytes, state)
}

/// A write through the parameter channel (as CoE and UDP see the dictionary).
fn ch_write(d: &mut DriveObjects, index: u16, sub: u8, value: i64) -> Result<(), SdoAbort> {
    let t = find(index).unwrap().1.info.entry(sub).unwrap().data_type;
    let mut b = [0u8; 8];
    let n = t.encode(value, &mut b).unwrap();
    d.parameter_channel(&mut NoLive).write(index, sub, &b[..n], OP)
}

/// A read through the parameter channel.
fn ch_read(d: &mut DriveObjects, index: u16, sub: u8) -> i64 {
    let t = find(index).unwrap().1.info.entry(sub).unwrap().data_type;
    let mut b = [0u8; 8];
    let n = d
        .parameter_channel(&mut NoLive)
        .read(index, sub, &mut b, OP)
        .unwrap();
    t.decode(&b[..n]).unwrap()
}

/// A dictionary with A213 = (`process_data`, `channel`) and the decimal
/// places (A310, A311) of axis A, written over the bus in Pre-Op.
fn with_scaling(process_data: u8, channel: u8, decimals: (u8, u8)) -> DriveObjects {
    let mut d = DriveObjects::new();
    write(&mut d, A213, 1, &[process_data], PREOP).unwrap();
    write(&mut d, A213, 2, &[channel], PREOP).unwrap();
    write(&mut d, A310, 0, &[decimals.0], PREOP).unwrap();
    write(&mut d, A311, 0, &[decimals.1], PREOP).unwrap();
    d
}

#[test]
fn e143_a213_is_an_array_of_two_native_elements_saved_with_the_parameters() {
    let mut d = DriveObjects::new();
    let o = d.object(A213).expect("A213 visible");
    assert_eq!((o.index, o.code), (0x20D5, ObjectCode::Array));
    assert_eq!(o.entry(0).unwrap().default, 2, "two elements");
    for (sub, writable_in_op) in [(1, false), (2, true)] {
        let e = o.entry(sub).unwrap();
        assert_eq!(e.data_type, DataType::U8);
        assert_eq!(
            (e.min, e.max, e.default),
            (Some(0), Some(1), 1),
            "A213[{}]",
            sub - 1
        );
        assert!(e.persistent, "saved");
        assert!(e.access.writable_in(0));
        assert_eq!(e.access.writable_in(2), writable_in_op, "A213[{}] in Op", sub - 1);
    }
    for line in [A310, A311] {
        let e = d.object(line).unwrap().entry(0).unwrap();
        assert_eq!(
            (e.data_type, e.min, e.max, e.default),
            (DataType::U8, Some(0), Some(9), 0)
        );
        assert!(e.persistent);
        assert_eq!(e.access, Access::RW_PREOP, "{line:04X}h in Pre-Op only");
        // axis B's own decimals
        assert!(d.object(line + AXIS_B_MANUFACTURER).is_some());
    }
    // native by default, both elements
    let mut b = [0u8; 4];
    for sub in [1, 2] {
        assert_eq!(d.read(A213, sub, &mut b, PREOP), Ok(1));
        assert_eq!(b[0], 1);
    }

    // saved and loaded with the parameter set; 1011h brings the defaults back
    let mut d = with_scaling(0, 0, (3, 4));
    let mut image = std::vec![0u8; dictionary::PERSISTENT_IMAGE_BYTES];
    let n = d.persistent_image(&mut image).unwrap();
    let mut fresh = DriveObjects::new();
    fresh.load_persistent(&image[..n]).unwrap();
    for (index, sub, v) in [(A213, 1, 0), (A213, 2, 0), (A310, 0, 3), (A311, 0, 4)] {
        assert_eq!(fresh.get(index, sub), Ok(v), "{index:04X}h:{sub} after a load");
    }
    write(
        &mut d,
        0x1011,
        1,
        &dictionary::LOAD_SIGNATURE.to_le_bytes(),
        PREOP,
    )
    .unwrap();
    for (index, sub, v) in [(A213, 1, 1), (A213, 2, 1), (A310, 0, 0), (A311, 0, 0)] {
        assert_eq!(d.get(index, sub), Ok(v), "{index:04X}h:{sub} after 1011h");
    }
}

/// Wrong size, out of range, no such element, wrong state: each its abort
/// code, and the dictionary as before.
#[test]
fn e143_bad_writes_to_a213_a310_a311_are_refused_and_change_nothing() {
    let b_a310 = A310 + AXIS_B_MANUFACTURER;
    let cases: [(u16, u8, &[u8], CommState, SdoAbort); 12] = [
        (A213, 1, &[0, 0], PREOP, SdoAbort::LENGTH_TOO_HIGH),
        (A213, 2, &[1, 0, 0, 0], OP, SdoAbort::LENGTH_TOO_HIGH),
        (A213, 1, &[2], PREOP, SdoAbort::VALUE_TOO_HIGH),
        (A213, 2, &[0xFF], OP, SdoAbort::VALUE_TOO_HIGH),
        (A213, 3, &[0], PREOP, SdoAbort::NO_SUBINDEX),
        (A213, 0, &[3], PREOP, SdoAbort::READ_ONLY),
        (A213, 1, &[0], SAFEOP, SdoAbort::DEVICE_STATE),
        (A213, 1, &[0], OP, SdoAbort::DEVICE_STATE),
        (A310, 0, &[10], PREOP, SdoAbort::VALUE_TOO_HIGH),
        (A310, 0, &[2], OP, SdoAbort::DEVICE_STATE),
        (A311, 0, &[2], SAFEOP, SdoAbort::DEVICE_STATE),
        (b_a310, 0, &[1, 0], PREOP, SdoAbort::LENGTH_TOO_HIGH),
    ];
    for (index, sub, data, state, abort) in cases {
        for channel in [false, true] {
            let mut d = DriveObjects::new();
            let before = d.clone();
            let generation = d.config_generation();
            let r = if channel {
                d.parameter_channel(&mut NoLive).write(index, sub, data, state)
            } else {
                d.write(index, sub, data, state)
            };
            assert_eq!(r, Err(abort), "{index:04X}h:{sub} {data:?} in {state:?}");
            assert!(d == before, "{index:04X}h:{sub}: nothing changed");
            assert_eq!(d.config_generation(), generation);
        }
    }
    // the parameter channel's element may change in any state
    let mut d = DriveObjects::new();
    assert_eq!(write(&mut d, A213, 2, &[0], OP), Ok(()));
    assert_eq!(d.get(A213, 2), Ok(0));
}

/// A213 = (0, 1): the process data (and the values kept) carry the decimal
/// places, the parameter channel shows the native unit.
#[test]
fn e143_native_parameter_channel_over_integer_process_data() {
    let mut d = with_scaling(0, 1, (2, 3));
    // 1234.56 inc/s kept as 123456 → 1235 on the channel
    d.set(0x6081, 0, 123_456).unwrap();
    assert_eq!(ch_read(&mut d, 0x6081, 0), 1235);
    let mut b = [0u8; 4];
    d.read(0x6081, 0, &mut b, OP).unwrap();
    assert_eq!(
        u32::from_le_bytes(b),
        123_456,
        "the dictionary keeps the process data's value"
    );
    // signed, rounded half away from zero
    d.set(0x60FF, 0, -12_345).unwrap();
    assert_eq!(ch_read(&mut d, 0x60FF, 0), -123);
    d.set(0x60FF, 0, -12_350).unwrap();
    assert_eq!(ch_read(&mut d, 0x60FF, 0), -124);
    // accelerations take A311 = 3
    d.set(0x6083, 0, 104_857_600).unwrap();
    assert_eq!(ch_read(&mut d, 0x6083, 0), 104_858);
    // a write in the native unit is kept with the decimals
    ch_write(&mut d, 0x6081, 0, 1234).unwrap();
    assert_eq!(d.get(0x6081, 0), Ok(123_400));
    ch_write(&mut d, 0x60A4, 1, 7).unwrap();
    assert_eq!(d.get(0x60A4, 1), Ok(7000));
    // writing back what a read returns keeps the decimals
    d.set(0x6081, 0, 123_456).unwrap();
    ch_write(&mut d, 0x6081, 0, 1235).unwrap();
    assert_eq!(d.get(0x6081, 0), Ok(123_456));
    // beyond the type once converted: refused, nothing changed
    let before = d.clone();
    assert_eq!(
        ch_write(&mut d, 0x6081, 0, 50_000_000),
        Err(SdoAbort::VALUE_TOO_HIGH)
    );
    assert_eq!(
        ch_write(&mut d, 0x60FF, 0, -30_000_000),
        Err(SdoAbort::VALUE_TOO_LOW)
    );
    assert_eq!(
        ch_write(&mut d, 0x6085, 0, 4_294_968),
        Err(SdoAbort::VALUE_TOO_HIGH)
    );
    assert!(d == before);
    // axis B with its own A310; the record window J401 and J404 too
    write(&mut d, A310 + AXIS_B_MANUFACTURER, 0, &[1], PREOP).unwrap();
    d.set(0x6881, 0, 1234).unwrap();
    d.set(0x6081, 0, 1234).unwrap();
    assert_eq!(ch_read(&mut d, 0x6881, 0), 123);
    assert_eq!(ch_read(&mut d, 0x6081, 0), 12);
    ch_write(&mut d, J401, 2, 1000).unwrap();
    assert_eq!(d.get(J401, 2), Ok(100_000), "J401[1] kept with two decimals");
    assert_eq!(ch_read(&mut d, J401, 2), 1000);
    // entries with a fixed unit are never converted
    d.set(0x607A, 0, 123_456).unwrap();
    assert_eq!(ch_read(&mut d, 0x607A, 0), 123_456);
    ch_write(&mut d, 0x6071, 0, 321).unwrap();
    assert_eq!(d.get(0x6071, 0), Ok(321));
    // both integer: the channel shows what the process data carry
    ch_write(&mut d, A213, 2, 0).unwrap();
    assert_eq!(ch_read(&mut d, 0x6081, 0), 1234);
}

/// A213 = (1, 0): the values kept are native, the parameter channel shows
/// them with the decimal places (saturated at the type's bounds).
#[test]
fn e143_integer_parameter_channel_over_native_process_data() {
    let mut d = with_scaling(1, 0, (2, 1));
    assert_eq!(ch_read(&mut d, 0x6081, 0), 10 * (1 << 20) * 100);
    // 50 rev/s × 100 does not fit UINT32
    assert_eq!(ch_read(&mut d, 0x607F, 0), i64::from(u32::MAX));
    ch_write(&mut d, 0x607F, 0, i64::from(u32::MAX)).unwrap();
    assert_eq!(
        d.get(0x607F, 0),
        Ok(50 << 20),
        "the saturated value written back keeps it"
    );
    ch_write(&mut d, 0x6081, 0, 12_345).unwrap();
    assert_eq!(d.get(0x6081, 0), Ok(123));
    ch_write(&mut d, 0x6081, 0, 12_350).unwrap();
    assert_eq!(d.get(0x6081, 0), Ok(124));
    d.set(0x60FF, 0, -5).unwrap();
    assert_eq!(ch_read(&mut d, 0x60FF, 0), -500);
    assert_eq!(ch_read(&mut d, 0x6084, 0), 100 * (1 << 20) * 10, "A311 = 1");
    // the live value 606Ch as well
    d.set(0x606C, 0, 77).unwrap();
    assert_eq!(ch_read(&mut d, 0x606C, 0), 7700);
}

/// E-086: the master's CoE-Online view edits a value in the unit the ESI
/// and SDO Info declare. With A213[1] = 1 (native) the edit means that
/// unit whatever the process data carry; with A213[1] = 0 the same number
/// is taken with the decimal places, 100 times smaller here.
#[test]
fn e086_an_edit_in_the_declared_unit_lands_as_such_only_with_native() {
    let axis = |d: &DriveObjects| {
        let s = Snapshot::read(d, Window { axis: 0 });
        s.to_increments(&s.scaling()).profile_velocity
    };
    let mut native = with_scaling(0, 1, (2, 0));
    ch_write(&mut native, 0x6081, 0, 5000).unwrap();
    assert_eq!(axis(&native), 5000, "5000 inc/s as edited");
    assert_eq!(ch_read(&mut native, 0x6081, 0), 5000, "and shown so");
    let mut integer = with_scaling(0, 0, (2, 0));
    ch_write(&mut integer, 0x6081, 0, 5000).unwrap();
    assert_eq!(axis(&integer), 50, "5000 in 0.01 inc/s");
}

/// Every entry the declaration gives a velocity, acceleration or jerk unit
/// is scaled with the matching decimal places, on both axes; every scaled
/// entry is a 32-bit integer in RAM.
#[test]
fn c142_e143_the_scaled_entries_are_those_the_declaration_names() {
    let mut by_unit = Vec::new();
    for o in OBJECTS.iter().filter(|o| o.info.index < 0x6800) {
        for e in o.info.entries {
            let q = match e.unit {
                "inc/s" => Some(Quantity::Velocity),
                "inc/s²" | "inc/s³" => Some(Quantity::Acceleration),
                _ => None,
            };
            if let Some(q) = q {
                by_unit.push((o.info.index, e.sub, q));
                assert_eq!(
                    scaled(o.info.index, e.sub),
                    Some((0, q)),
                    "{:04X}h:{}",
                    o.info.index,
                    e.sub
                );
            }
        }
    }
    assert!(by_unit.len() >= 14, "{by_unit:?}");
    for (index, sub, q) in SCALED {
        let (_, o) = find(index).unwrap();
        let e = o.info.entry(sub).unwrap();
        assert!(
            matches!(e.data_type, DataType::U32 | DataType::I32),
            "{index:04X}h:{sub}"
        );
        assert!(matches!(o.value, Value::Ram | Value::Live));
        let b = if index >= 0x6000 {
            index + AXIS_B_CIA402
        } else {
            index + AXIS_B_MANUFACTURER
        };
        assert_eq!(find(b).unwrap().1.info.entry(sub).unwrap().name, e.name);
        assert_eq!(scaled(b, sub), Some((1, q)), "axis B {b:04X}h:{sub}");
    }
    assert!(
        SCALED.windows(2).all(|w| (w[0].0, w[0].1) < (w[1].0, w[1].1)),
        "sorted, no entry twice"
    );
    assert_eq!(scaled(0x607A, 0), None);
    assert_eq!(scaled(A310, 0), None);
}

/// The axis converts exactly the scaled entries: with A213[0] = 0 and every
/// scaled entry it reads at its native value × 10^decimals, its increments
/// are those of the native dictionary, on both axes.
#[test]
fn c142_e143_the_axis_converts_exactly_the_scaled_entries() {
    for axis in [0u8, 1] {
        let w = Window { axis };
        let b = if axis == 0 { 0 } else { AXIS_B_MANUFACTURER };
        let mut native = DriveObjects::new();
        let mut integer = DriveObjects::new();
        write(&mut integer, A213, 1, &[0], PREOP).unwrap();
        write(&mut integer, A310 + b, 0, &[1], PREOP).unwrap();
        write(&mut integer, A311 + b, 0, &[2], PREOP).unwrap();
        for (k, (index, sub, q)) in SCALED.into_iter().enumerate() {
            let index = if index >= 0x6000 {
                w.cia402(index)
            } else {
                index + b
            };
            let v = 1000 + 37 * k as i64;
            native.set(index, sub, v).unwrap();
            let f = match q {
                Quantity::Velocity => 10,
                Quantity::Acceleration => 100,
            };
            integer.set(index, sub, v * f).unwrap();
        }
        let inc = |d: &DriveObjects| {
            let s = Snapshot::read(d, w);
            Snapshot {
                decimals: (0, 0),
                ..s.to_increments(&s.scaling())
            }
        };
        assert_eq!(inc(&integer), inc(&native), "axis {axis}");
    }
}
