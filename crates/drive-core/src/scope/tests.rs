//! The recorder on its own and through the dictionary (issue 35, the
//! scope: no spec item names it).

use super::*;
use crate::dictionary::DriveObjects;
use crate::params::{T00, T01, T02, T03, T04, T05, T06, T07, T08, T09, T10, T11};
use od::Dictionary;
use std::vec;
use std::vec::Vec;

type Rec = Recorder<Vec<u32>>;

fn signals(v: i32) -> [Signals; 2] {
    let s = Signals {
        speed_setpoint: v,
        speed_actual: 2 * v,
        following_error: -v,
        iq: 10 * v,
        id: 0,
        ud: 0,
    };
    [s, Signals::default()]
}

fn config(channels: &[u32]) -> Config {
    let mut c = Config::default();
    for (d, s) in c.channels.iter_mut().zip(channels) {
        *d = *s;
    }
    c.count = channels.len() as u8;
    c
}

/// Runs cycles with signal value `f(cycle)` until the recorder is complete
/// (or `max` cycles); returns the cycles run.
fn run(r: &mut Rec, od: &DriveObjects, max: u32, f: impl Fn(u32) -> i32) -> u32 {
    for t in 0..max {
        r.sample(od, || signals(f(t)));
        if r.state() == State::Complete {
            return t + 1;
        }
    }
    max
}

/// Issue 35, the scope: a rising edge on a signal channel lands at the
/// pre-trigger share's index; the samples before it are the pre-trigger
/// history in time order, those after it follow cycle by cycle.
#[test]
fn issue35_scope_edge_trigger_lands_at_the_pre_trigger_share() {
    let od = DriveObjects::new();
    let mut r = Rec::new(vec![0; 1000]);
    let mut c = config(&[Signal::SpeedSetpoint.code(0), Signal::Iq.code(0)]);
    c.length = 100;
    c.pre_percent = 25;
    c.source = 1;
    c.condition = 2;
    c.level = 500;
    r.configure(c).unwrap();
    r.arm().unwrap();
    assert_eq!(r.state(), State::Armed);
    // a ramp 0, 1, 2, …: crosses 500 at cycle 500
    let cycles = run(&mut r, &od, 10_000, |t| t as i32);
    assert_eq!(r.state(), State::Complete);
    assert_eq!(cycles, 500 + 75, "75 samples after the trigger sample");
    assert_eq!(r.frames(), 100);
    assert_eq!(r.trigger_index(), 25);
    for i in 0..100 {
        assert_eq!(r.value(i, 0), Some(475 + i as i32), "sample {i}");
        assert_eq!(r.value(i, 1), Some(10 * (475 + i as i32)));
    }
    assert_eq!(r.value(100, 0), None);
    assert_eq!(r.value(0, 2), None);
}

/// The divider takes every n-th cycle; a level trigger with no history
/// waits until the pre-trigger share is recorded.
#[test]
fn issue35_scope_divider_and_level_trigger_wait_for_the_pre_trigger_share() {
    let od = DriveObjects::new();
    let mut r = Rec::new(vec![0; 64]);
    let mut c = config(&[Signal::SpeedActual.code(0)]);
    c.length = 10;
    c.pre_percent = 50;
    c.divider = 3;
    c.source = 1;
    c.condition = 0; // ≥ 0: true from the first sample
    r.configure(c).unwrap();
    r.arm().unwrap();
    run(&mut r, &od, 1000, |t| t as i32);
    // samples at cycles 2, 5, 8, …; the trigger at the 6th (5 before it)
    assert_eq!(r.trigger_index(), 5);
    for i in 0..10 {
        assert_eq!(r.value(i, 0), Some(2 * (2 + 3 * i as i32)));
    }
}

/// A statusword bit triggers (6041h bit 10 "target reached" set by the
/// runtime); an object channel reads the dictionary through its prepared
/// access and follows a configuration change.
#[test]
fn issue35_scope_statusword_bit_and_object_channel() {
    let mut od = DriveObjects::new();
    let mut r = Rec::new(vec![0; 64]);
    // 6064h position actual value (TxPDO-mappable INTEGER32) and 6041h
    let mut c = config(&[0x6064_0020, 0x6041_0010]);
    c.length = 8;
    c.pre_percent = 50;
    c.source = 0x10 + 10;
    c.condition = 2;
    r.configure(c).unwrap();
    r.arm().unwrap();
    for t in 0..40 {
        od.set(0x6064, 0, 1000 + t).unwrap();
        od.set(0x6041, 0, if t >= 20 { 0x0400 } else { 0 }).unwrap();
        if t == 10 {
            // a configuration change stales the prepared access
            od.set(0x6048, 1, 77).unwrap();
        }
        r.sample(&od, || signals(0));
    }
    assert_eq!(r.state(), State::Complete);
    assert_eq!(r.trigger_index(), 4);
    for i in 0..8 {
        assert_eq!(r.value(i, 0), Some(1016 + i as i32));
    }
    assert_eq!(r.value(3, 1), Some(0));
    assert_eq!(r.value(4, 1), Some(0x0400));
}

/// Idle costs nothing and records nothing; a stop drops an armed trace.
#[test]
fn issue35_scope_idle_records_nothing() {
    let od = DriveObjects::new();
    let mut r = Rec::new(vec![7; 16]);
    r.configure(config(&[Signal::Iq.code(0)])).unwrap();
    for t in 0..100 {
        r.sample(&od, || signals(t));
    }
    assert_eq!(r.state(), State::Idle);
    assert!(r.storage.iter().all(|&w| w == 7));
    r.arm().unwrap();
    r.sample(&od, || signals(1));
    r.stop();
    assert_eq!(r.state(), State::Idle);
    assert_eq!(r.value(0, 0), None);
}

fn read(od: &mut DriveObjects, r: &mut Rec, index: u16, sub: u8) -> Result<Vec<u8>, SdoAbort> {
    let mut buf = vec![0u8; BLOCK_BYTES];
    let n = od.with_live(r).read(index, sub, &mut buf, CommState::Op)?;
    Ok(buf[..n].to_vec())
}

fn write(od: &mut DriveObjects, r: &mut Rec, index: u16, sub: u8, v: &[u8]) -> Result<(), SdoAbort> {
    od.with_live(r).write(index, sub, v, CommState::Op)
}

fn u32_at(b: &[u8], k: usize) -> u32 {
    u32::from_le_bytes(b[4 * k..4 * k + 4].try_into().unwrap())
}

/// Through the objects: bad input refused with its abort code and nothing
/// changed; the trace is read only when complete (0800 0022h before and
/// while recording, never the old trace as new), in blocks of 4096 bytes,
/// 0800 0024h beyond its end; normal mode arms again after the last block.
#[test]
fn issue35_scope_objects_refuse_bad_input_and_incomplete_reads() {
    let mut od = DriveObjects::new();
    let mut r = Rec::new(vec![0; 3000]);
    let (od, r) = (&mut od, &mut r);
    // not mappable: 6040h is, 6060h is not mapped here? use an unmappable
    // parameter (A00) and an unknown entry
    let bad = [
        (0x2000_0108u32, 0x0604_0041),
        (0x5FFF_0020, 0x0604_0041),
        (0x6064_0010, 0x0604_0043),
    ];
    for (code, abort) in bad {
        assert_eq!(
            write(od, r, T01, 1, &code.to_le_bytes()),
            Err(SdoAbort(abort)),
            "{code:08X}"
        );
    }
    // an internal signal that does not exist (n = 7) and axis C
    for code in [0x0000_0720u32, 0x0000_2120] {
        assert_eq!(
            write(od, r, T01, 1, &code.to_le_bytes()),
            Err(SdoAbort::NOT_MAPPABLE)
        );
    }
    assert_eq!(read(od, r, T01, 1).unwrap(), [0; 4], "nothing changed");
    assert_eq!(write(od, r, T02, 0, &[9]), Err(SdoAbort::VALUE_TOO_HIGH));
    assert_eq!(write(od, r, T03, 0, &[0, 0]), Err(SdoAbort::VALUE_TOO_LOW));
    assert_eq!(
        write(od, r, T03, 0, &1001u16.to_le_bytes()),
        Err(SdoAbort::VALUE_TOO_HIGH)
    );
    assert_eq!(write(od, r, T05, 0, &[0x30, 0]), Err(SdoAbort::INVALID_VALUE));
    assert_eq!(write(od, r, T06, 0, &[5]), Err(SdoAbort::VALUE_TOO_HIGH));
    assert_eq!(write(od, r, T08, 0, &[101]), Err(SdoAbort::VALUE_TOO_HIGH));
    // no channels: arming refused
    assert_eq!(write(od, r, T00, 0, &[1]), Err(SdoAbort::INVALID_VALUE));
    assert_eq!(read(od, r, T11, 1), Err(SdoAbort::DEVICE_STATE));
    // two channels, the buffer holds 1500 samples each: 1501 refused
    write(od, r, T01, 1, &Signal::SpeedSetpoint.code(0).to_le_bytes()).unwrap();
    write(od, r, T01, 2, &0x6064_0020u32.to_le_bytes()).unwrap();
    write(od, r, T02, 0, &[2]).unwrap();
    assert_eq!(
        write(od, r, T04, 0, &1501u32.to_le_bytes()),
        Err(SdoAbort::VALUE_TOO_HIGH)
    );
    write(od, r, T04, 0, &1200u32.to_le_bytes()).unwrap();
    // three channels of 1200 no longer fit
    assert_eq!(write(od, r, T02, 0, &[3]), Err(SdoAbort::VALUE_TOO_HIGH));
    write(od, r, T09, 0, &[1]).unwrap();
    write(od, r, T07, 0, &(-5i32).to_le_bytes()).unwrap();
    write(od, r, T00, 0, &[1]).unwrap();
    assert_eq!(read(od, r, T00, 0).unwrap(), [1]);
    // armed: no configuration change, no data
    assert_eq!(write(od, r, T04, 0, &[10, 0, 0, 0]), Err(SdoAbort::DEVICE_STATE));
    assert_eq!(read(od, r, T11, 1), Err(SdoAbort::DEVICE_STATE));
    assert_eq!(read(od, r, T10, 1).unwrap(), [0; 4]);
    for t in 0..1200 {
        od.set(0x6064, 0, i64::from(t) * 3).unwrap();
        r.sample(od, || signals(t));
    }
    assert_eq!(read(od, r, T00, 0).unwrap(), [3]);
    assert_eq!(u32_at(&read(od, r, T10, 1).unwrap(), 0), 1200);
    assert_eq!(u32_at(&read(od, r, T10, 3).unwrap(), 0), 1);
    assert_eq!(u32_at(&read(od, r, T10, 4).unwrap(), 0), 3000);
    // 1200 × 2 × 4 = 9600 bytes: blocks of 4096, 4096, 1408
    let mut all = Vec::new();
    for k in 1..=3 {
        all.extend(read(od, r, T11, k).unwrap());
    }
    assert_eq!(all.len(), 9600);
    for i in 0..1200 {
        assert_eq!(u32_at(&all, 2 * i) as i32, i as i32);
        assert_eq!(u32_at(&all, 2 * i + 1) as i32, 3 * i as i32);
    }
    // normal mode: the last block read armed the next trace
    assert_eq!(read(od, r, T00, 0).unwrap(), [1]);
    assert_eq!(read(od, r, T11, 1), Err(SdoAbort::DEVICE_STATE));
    // single mode, complete: beyond the end 0800 0024h; state writes 2/3 refused
    write(od, r, T00, 0, &[0]).unwrap();
    write(od, r, T09, 0, &[0]).unwrap();
    write(od, r, T04, 0, &[4, 0, 0, 0]).unwrap();
    write(od, r, T00, 0, &[1]).unwrap();
    for t in 0..4 {
        r.sample(od, || signals(t));
    }
    assert_eq!(read(od, r, T11, 1).unwrap().len(), 32);
    assert_eq!(read(od, r, T11, 2), Err(SdoAbort::NO_DATA));
    assert_eq!(read(od, r, T00, 0).unwrap(), [3], "single mode stays complete");
    assert_eq!(write(od, r, T00, 0, &[2]), Err(SdoAbort::INVALID_VALUE));
    // a drive without a recorder answers 0800 0022h
    let mut buf = [0u8; 8];
    assert_eq!(
        Dictionary::read(od, T02, 0, &mut buf, CommState::Op),
        Err(SdoAbort::DEVICE_STATE)
    );
}

/// The objects take no RAM image bytes and are not saved.
#[test]
fn issue35_scope_objects_have_no_ram_image() {
    for index in [T00, T01, T02, T03, T04, T05, T06, T07, T08, T09, T10, T11] {
        let (_, o) = crate::objects::find(index).unwrap();
        assert_eq!(o.value, crate::objects::Value::Provided);
        assert_eq!(o.ram_bytes(), 0, "{index:04X}");
    }
}

/// Issue 36 (no long first cycle): the context that arms a trace prepares
/// its object channels' accesses, so the control cycle's first sample finds
/// them prepared; the trace is the same as one whose first sample prepares
/// them itself, and a second `prepare` is a no-op until the next arming.
#[test]
fn issue36_scope_channels_prepared_where_the_trace_is_armed() {
    let trace = |prepare_first: bool| {
        let mut od = DriveObjects::new();
        let mut r = Rec::new(vec![0; 1000]);
        let mut c = config(&[0x6064_0020, Signal::Iq.code(0), 0x6041_0010]);
        c.length = 10;
        r.configure(c).unwrap();
        r.arm().unwrap();
        let prepared = |r: &Rec| {
            r.chans
                .iter()
                .filter(|ch| {
                    matches!(
                        ch,
                        Channel::Entry {
                            prepared: Some(_),
                            ..
                        }
                    )
                })
                .count()
        };
        assert_eq!(prepared(&r), 0, "arming decodes, it does not prepare");
        if prepare_first {
            r.prepare(&od);
            assert_eq!(prepared(&r), 2, "both object channels prepared, the signal not");
            assert!(!r.unprepared);
        }
        for t in 0..10 {
            od.set(0x6064, 0, 1000 + t).unwrap();
            r.sample(&od, || signals(t as i32));
        }
        assert_eq!(r.state(), State::Complete);
        (0..10)
            .map(|i| (r.value(i, 0), r.value(i, 1), r.value(i, 2)))
            .collect::<Vec<_>>()
    };
    let (lazy, early) = (trace(false), trace(true));
    assert_eq!(lazy, early);
    assert_eq!(early[0], (Some(1000), Some(0), Some(0)));
    assert_eq!(early[9].0, Some(1009));
}
