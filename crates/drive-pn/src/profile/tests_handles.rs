//! Issue 36: the telegrams compiled into per-slot handles
//! ([`profidrive::telegram::compiled`], [`super::access::Handle`]) answer as
//! the address path. Two profiles over two equal drives take the same
//! frames, one through its handles, one with them forgotten before every
//! receive and response (the address path): the same response bytes, the
//! same objects, axis, own values and warnings after every frame, for
//! telegrams 0, 1 and 2, frames the telegram refuses or does not know, a
//! unit change (A279) and a telegram configured over PKW between frames.

use super::tests::frame;
use super::Profile;
use drive_core::axis::Axis;
use drive_core::params::A279;
use drive_core::DriveObjects;
use profidrive::telegram::{Dir, FbPositioning, FbSpeed, FbTorque};
use profidrive::Addr;
use std::format;
use std::string::String;
use std::vec::Vec;

/// One drive with its profile.
struct Side {
    od: DriveObjects,
    axis: Axis,
    profile: Profile,
}

impl Side {
    fn new(axis: u8) -> Side {
        let mut od = DriveObjects::new();
        let axis = Axis::new(axis);
        let profile = Profile::new(&mut od, &axis);
        Side { od, axis, profile }
    }

    /// One frame as `PnDrive` takes it: prepared in the bus task, then
    /// the control cycle's receive and response. `handles`: through the
    /// compiled handles, else the address path.
    fn frame(&mut self, frame: &[u8], handles: bool, between: Option<(u16, u8, i64)>) -> Vec<u8> {
        self.profile.prepare(Some(frame), &mut self.od, &mut self.axis);
        // a write between the bus task's preparation and the control
        // cycle (a record in the bus task)
        if let Some((index, sub, v)) = between {
            self.set(index, sub, v);
        }
        if handles {
            let t = self.profile.telegrams().expect("configured");
            assert!(self.profile.handles.is_for(t), "the handles are current");
        } else {
            self.profile.handles.clear();
        }
        self.profile.receive(frame, &mut self.od, &mut self.axis);
        if !handles {
            self.profile.handles.clear();
        }
        let mut out = std::vec![0u8; 36];
        let n = self.profile.respond(&mut self.od, &self.axis, &mut out);
        out.truncate(n.unwrap_or(0));
        out
    }

    /// `index` (axis A's CiA 402 index: this axis') written.
    fn set(&mut self, index: u16, sub: u8, v: i64) {
        let index = if index >= 0x6000 {
            self.axis.cia402_index(index)
        } else {
            index
        };
        self.od.set(index, sub, v).unwrap();
    }

    /// What the two paths must leave alike.
    fn state(&self) -> String {
        format!(
            "{:?} {:?} {} {} {:?} {:?}",
            self.profile.own(),
            self.profile.units(),
            self.profile.warnings(),
            self.profile.homing(),
            self.axis,
            self.od.config_generation(),
        )
    }
}

fn pkw(code: u8, pnu: u16, sub: u8, value: u32) -> [u8; 8] {
    let i = pnu.to_be_bytes();
    let v = value.to_be_bytes();
    [code, i[0], i[1], sub, v[0], v[1], v[2], v[3]]
}

/// Telegram 0: homing method, CW1, target, profile and end velocity, both
/// accelerations, jog velocity, PKW, current limit.
fn t0(cw1: u16, target: i32, v: i32, end: i32, acc: u32, jog: i32, p: [u8; 8]) -> [u8; 36] {
    let t = FbPositioning {
        homing_method: 34,
        cw1,
        target,
        profile_velocity: v,
        end_velocity: end,
        accelerations: acc,
        jog_velocity: jog,
        pkw: p,
        current_limit: 1500,
    };
    frame(|f| t.write(f))
}

/// Telegram 1 (as [`super::tests::speed`]) with jog velocity 300.
fn t1(cw1: u16, rpm: i32, ramps: u32, p: [u8; 8]) -> [u8; 36] {
    let t = FbSpeed {
        cw1,
        velocity: rpm,
        accelerations: ramps,
        jog_velocity: 300,
        pkw: p,
        current_limit: 0,
    };
    frame(|f| t.write(f))
}

/// Telegram 2: CW1, target torque, PKW, speed limit.
fn t2(cw1: u16, torque: i16, p: [u8; 8]) -> [u8; 36] {
    let t = FbTorque {
        cw1,
        torque,
        pkw: p,
        speed_limit: 2000,
    };
    frame(|f| t.write(f))
}

/// Telegram 3 as configured below: CW1, target velocity.
fn t3(cw1: u16, rpm: i32) -> [u8; 36] {
    let mut t = [0u8; 36];
    t[0] = 0xE3;
    t[1..3].copy_from_slice(&cw1.to_be_bytes());
    t[3..7].copy_from_slice(&rpm.to_be_bytes());
    t
}

/// CANopen-style entry of the telegram editor: index << 16 | sub << 8.
fn entry(index: u16, sub: u8) -> u32 {
    u32::from(index) << 16 | u32::from(sub) << 8
}

/// An object written on both drives (axis A's CiA 402 index, subindex,
/// value).
type Write = Option<(u16, u8, i64)>;

/// A frame, the object written on both drives before it and the one
/// written between the preparation and the control cycle.
type Step = ([u8; 36], Write, Write);

/// The frames, in order, with what happens to both drives before each.
fn script() -> Vec<Step> {
    let none = [0u8; 8];
    let mut s = Vec::new();
    // telegram 0: records changed, unchanged, a value the record refuses
    for (cw1, target, v, end, acc, jog) in [
        (0x0406, 5000, 1000, 0, 10_000, 100),
        (0x0407, 5000, 1000, 0, 10_000, 100),
        (0x040F, 5000, 1000, 0, 10_000, 100),
        (0x045F, -20_000, 700, 100, 300, -50),
        (0x041F, -20_000, 700, 100, 300, -50),
        (0x040F, 1, -5, 0, u32::MAX, 0),
        (0x0C0F, 1, 10, 0, 1, 0),
    ] {
        s.push((t0(cw1, target, v, end, acc, jog, none), None, None));
    }
    // a PKW read and write inside telegram 0 (PNU 1001.0, the target)
    s.push((t0(0x040F, 77, 10, 0, 100, 0, pkw(0x41, 1001, 0, 0)), None, None));
    s.push((t0(0x040F, 77, 10, 0, 100, 0, none), None, None));
    s.push((t0(0x040F, 77, 10, 0, 100, 0, pkw(0x42, 1040, 0, 250)), None, None));
    // telegram 1, then 2, then 0 again (the mode changes)
    for (cw1, rpm, ramps) in [(0x0406, 100, 10_000), (0x0407, 100, 10_000), (0x047F, -300, 2500)] {
        s.push((t1(cw1, rpm, ramps, none), None, None));
    }
    // a ramp changed behind the telegram, before the frame and between
    // its preparation and the control cycle, then the same value again
    s.push((t1(0x047F, -300, 2500, none), Some((0x6048, 1, 7)), None));
    s.push((t1(0x047F, -300, 2500, none), None, Some((0x6049, 1, 9))));
    s.push((t1(0x047F, -300, 2500, none), None, Some((0x6048, 2, 3))));
    s.push((t1(0x047F, -300, 2500, none), None, None));
    // a ramp the objects refuse (beyond 6048h:01's range), then taken
    s.push((t1(0x047F, -300, u32::MAX, none), None, None));
    s.push((t1(0x047F, -300, u32::MAX, none), None, None));
    s.push((t1(0x047F, -300, 2500, none), None, None));
    for (cw1, torque) in [(0x0406, 0), (0x040F, 100), (0x040F, -100)] {
        s.push((t2(cw1, torque, none), None, None));
    }
    // A279: the position in 1/10 degree, then the velocity
    s.push((
        t0(0x040F, 3600, 10, 0, 100, 20, none),
        Some((A279, 1, 0x0101)),
        None,
    ));
    s.push((t0(0x040F, 3601, 10, 0, 100, 20, none), None, None));
    s.push((t1(0x047F, 50, 2500, none), Some((A279, 2, 0x1001)), None));
    s.push((t1(0x047F, 51, 2500, none), None, None));
    // an unknown identifier, then telegram 3 configured over PKW and used
    let mut unknown = t0(0x040F, 1, 1, 0, 1, 0, none);
    unknown[0] = 0xE7;
    s.push((unknown, None, None));
    let editor = [
        (2020, 0, 7),
        (2021, 0, entry(968, 0)),
        (2021, 1, entry(1101, 0)),
        (2021, 2, entry(0x6077, 0)),
        (2022, 0, 1),
        (2020, 0, 3),
        (2021, 0, entry(967, 0)),
        (2021, 1, entry(1010, 0)),
        (2022, 0, 1),
    ];
    for (pnu, sub, value) in editor {
        s.push((t2(0x0406, 0, pkw(0x42, pnu, sub, value)), None, None));
        s.push((t2(0x0406, 0, none), None, None));
    }
    for (cw1, rpm) in [(0x0406, 10), (0x0407, 20), (0x047F, 30)] {
        s.push((t3(cw1, rpm), None, None));
    }
    s.push((t1(0x0406, 5, 1000, none), None, None));
    s.push((t3(0x0406, 10), None, None));
    s
}

/// Issue 36, P-067, P-071…P-074, P-208 (A279), Q-08: the handle path and
/// the address path leave the same bytes, objects and state after every
/// frame, on both axes; the handles are compiled again after the telegram
/// configured over PKW.
#[test]
fn issue36_p067_the_handles_answer_as_the_address_path() {
    for axis in [0, 1] {
        let (mut a, mut b) = (Side::new(axis), Side::new(axis));
        for (k, (frame, before, between)) in script().into_iter().enumerate() {
            if let Some((index, sub, v)) = before {
                a.set(index, sub, v);
                b.set(index, sub, v);
            }
            let (ra, rb) = (a.frame(&frame, true, between), b.frame(&frame, false, between));
            assert_eq!(ra, rb, "axis {axis} frame {k}: the response");
            assert!(a.od == b.od, "axis {axis} frame {k}: the objects");
            assert_eq!(a.state(), b.state(), "axis {axis} frame {k}");
        }
        // the script reached what it is for
        assert_eq!(a.profile.telegrams().unwrap().active_receive(), Some(3));
        assert!(a.profile.warnings() > 0, "the unknown identifier counted");
        let n = a.od.record_selector(axis);
        // 360.1 degrees in increments: A279's unit was in force
        let target = i64::from(a.od.record(axis, n).unwrap().target);
        assert!(
            (target - (3601 << 20) / 3600).abs() <= 1,
            "A279: 1/10 degree, {target}"
        );
    }
}

/// Issue 36: a handle holds no axis: the handles compiled with axis A
/// reach axis B's objects when the profile drives axis B.
#[test]
fn issue36_handles_follow_the_axis() {
    let mut s = Side::new(0);
    let frame = t2(0x0406, 123, [0; 8]);
    s.frame(&frame, true, None);
    assert_eq!(s.od.get(0x6071, 0), Ok(123));
    let mut b = Axis::new(1);
    let frame = t2(0x0406, -9, [0; 8]);
    assert!(s.profile.handles.is_for(s.profile.telegrams().unwrap()));
    s.profile.receive(&frame, &mut s.od, &mut b);
    assert_eq!(s.od.get(b.cia402_index(0x6071), 0), Ok(-9));
    assert_eq!(s.od.get(0x6071, 0), Ok(123), "axis A's stays");
    // the response's 6077h (actual torque) is axis B's
    s.od.set(0x6077, 0, 11).unwrap();
    s.od.set(b.cia402_index(0x6077), 0, 22).unwrap();
    let layout = s.profile.telegrams().unwrap().layout(Dir::Response, 2).unwrap();
    let at = layout
        .slots()
        .iter()
        .find(|x| x.addr == Addr::new(0x6077, 0))
        .unwrap()
        .offset;
    let mut out = [0u8; 36];
    s.profile.respond(&mut s.od, &b, &mut out);
    let at = usize::from(at);
    assert_eq!(i16::from_be_bytes([out[at], out[at + 1]]), 22, "6077h of axis B");
}

/// Issue 36, P-208…P-213 (A279): a remembered conversion answers as the
/// conversion computed, for every unit and values around the 32-bit limits,
/// after a unit change, and when the units change without a configuration
/// change (A279 stored before the profile was made: its first look at A279
/// changes the units at the same generation).
#[test]
fn issue36_p208_remembered_conversions_answer_as_computed() {
    use super::access::DriveAccess;
    use super::pnu::Unit;
    use drive_core::NoLive;
    let mut od = DriveObjects::new();
    od.set(A279, 1, 0x0101).unwrap();
    let mut axis = Axis::new(0);
    let mut profile = Profile::new(&mut od, &axis);
    let values = [
        0i64,
        1,
        -1,
        5000,
        -20_000,
        1 << 20,
        i64::from(i32::MAX),
        i64::from(i32::MIN),
        i64::from(u32::MAX),
    ];
    let units = [
        Unit::Position,
        Unit::Velocity,
        Unit::Acceleration,
        Unit::Rpm,
        Unit::RpmPerSecond,
    ];
    let check = |profile: &mut Profile, od: &mut DriveObjects, axis: &Axis| {
        let p = profile;
        let mut access = drive_access!(p, od, axis, &mut NoLive);
        for round in 0..2 {
            for unit in units {
                for &bus in &values {
                    let computed = access.convert(unit, bus);
                    assert_eq!(access.object_of(unit, bus), computed, "{unit:?} {bus} {round}");
                }
            }
        }
    };
    // the default units until the profile looks at A279
    check(&mut profile, &mut od, &axis);
    let one = |profile: &mut Profile, od: &mut DriveObjects, axis: &Axis| {
        let p = profile;
        let mut access = drive_access!(p, od, axis, &mut NoLive);
        (
            access.object_of(Unit::Position, 3600),
            access.convert(Unit::Position, 3600),
        )
    };
    let (before, _) = one(&mut profile, &mut od, &axis);
    let g = od.config_generation();
    profile.prepare(None, &mut od, &mut axis);
    assert_eq!(od.config_generation(), g, "no configuration change");
    assert_ne!(profile.units(), &motion::units::UnitProfile::default_profile());
    let (remembered, computed) = one(&mut profile, &mut od, &axis);
    assert_eq!(remembered, computed, "the units changed: forgotten");
    assert_ne!(remembered, before, "1/10 degree");
    check(&mut profile, &mut od, &axis);
    for (sub, code) in [(2, 0x1001), (1, 0x0203), (3, 0x1002)] {
        od.set(A279, sub, code).unwrap();
        profile.prepare(None, &mut od, &mut axis);
        check(&mut profile, &mut od, &axis);
    }
}
