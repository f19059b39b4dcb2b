//! Host figures of the PROFIdrive profile's cyclic path (issue 17): ns per
//! control cycle with each receive telegram of the Example Function block
//! (0 positioning, 1 speed, 2 torque) against the cycle at rest.
//!
//! `cargo run --release -p drive-pn --example profile_bench`
//!
//! Two tables:
//! - the profile alone ([`drive_pn::profile::Profile`] on a fresh
//!   dictionary and axis A): `receive` (the telegram into the objects, the
//!   PKW step, CW1 last) and `respond` (ZSW1, the response telegram);
//! - the whole drive as `firmware-qemu-pn` measures it on QEMU
//!   ([`drive_pn::PnDrive`] with profinet-py's AR from the scripted
//!   controller of `profinet`'s `testing` feature): `control_cycle` of both
//!   axes with the telegram in the output data, and its cost above the
//!   cycle at rest (no telegram in the data).
//!
//! Each figure is the best mean of [`ROUNDS`] short rounds (the machine may
//! be shared: the best round is the one least disturbed).
//! A host benchmark, not device code: it may index and unwrap its own fixed
//! frames.
#![allow(clippy::indexing_slicing, clippy::expect_used, clippy::unwrap_used)]

use drive_core::axis::{Axis, AxisIo};
use drive_core::DriveObjects;
use drive_pn::profile::Profile;
use drive_pn::{settings, Hardware, PnDrive};
use nanos::Nanos;
use profidrive::telegram::{FbPositioning, FbSpeed, FbTorque, FB_RECEIVE_BYTES};
use profinet::testing;
use std::hint::black_box;
use std::time::Instant;

type Flash = drive_pn::PnParamFlash;

/// Rounds per figure (the best mean counts).
const ROUNDS: usize = 15;
/// Cycles per round of the profile alone.
const PROFILE_CYCLES: u32 = 20_000;
/// Cycles per round of the whole drive.
const DRIVE_CYCLES: u32 = 5_000;

/// `write`'s telegram (one of `profidrive::telegram`'s builders).
fn telegram(write: impl FnOnce(&mut [u8]) -> Option<usize>) -> [u8; FB_RECEIVE_BYTES] {
    let mut t = [0u8; FB_RECEIVE_BYTES];
    assert_eq!(write(&mut t), Some(FB_RECEIVE_BYTES));
    t
}

/// Receive telegram 0 (positioning): homing method 34, CW1 0x0406, target
/// 10000, profile velocity 5000, end velocity 0, all accelerations 10000,
/// jog velocity 1000, PKW idle, current limit 2000 mA.
fn telegram0() -> [u8; 36] {
    let mut t = FbPositioning::default();
    (t.homing_method, t.cw1, t.target, t.profile_velocity) = (34, 0x0406, 10_000, 5_000);
    (t.accelerations, t.jog_velocity, t.current_limit) = (10_000, 1_000, 2_000);
    telegram(|f| t.write(f))
}

/// Receive telegram 1 (speed) as `firmware-qemu-pn` sends it: CW1 0x0406,
/// 100 rpm, all ramps 10000, the rest 0.
fn telegram1() -> [u8; 36] {
    let mut t = FbSpeed::default();
    (t.cw1, t.velocity, t.accelerations) = (0x0406, 100, 10_000);
    telegram(|f| t.write(f))
}

/// Receive telegram 2 (torque): CW1 0x0406, 100 ‰ target torque, speed
/// limit 3000.
fn telegram2() -> [u8; 36] {
    let mut t = FbTorque::default();
    (t.cw1, t.torque, t.speed_limit) = (0x0406, 100, 3_000);
    telegram(|f| t.write(f))
}

/// The best of [`ROUNDS`] means of `f`'s ns per call over `n` calls.
fn best(n: u32, mut f: impl FnMut()) -> f64 {
    (0..ROUNDS)
        .map(|_| {
            let start = Instant::now();
            for _ in 0..n {
                f();
            }
            start.elapsed().as_nanos() as f64 / f64::from(n)
        })
        .fold(f64::INFINITY, f64::min)
}

/// The profile alone: ns per `receive` and per `respond` of `telegram`.
fn profile_alone(telegram: &[u8]) -> (f64, f64) {
    let mut objects = DriveObjects::new();
    let mut axis = Axis::new(0);
    let mut profile = Profile::new(&mut objects, &axis);
    assert!(profile.configured());
    let mut out = [0u8; 36];
    // one cycle first: the response telegram is chosen by the receive
    profile.receive(telegram, &mut objects, &mut axis);
    assert_eq!(profile.respond(&mut objects, &axis, &mut out), Some(36));
    let rx = best(PROFILE_CYCLES, || {
        profile.receive(black_box(telegram), &mut objects, &mut axis)
    });
    let tx = best(PROFILE_CYCLES, || {
        black_box(profile.respond(&mut objects, &axis, &mut out));
    });
    (rx, tx)
}

/// The board data of the scripted controller's device.
fn hardware() -> Hardware {
    Hardware::from(testing::device_config())
}

/// The drive commissioned as the scripted controller expects it, restarted,
/// with profinet-py's AR connected.
fn drive() -> PnDrive<Flash> {
    let mut d = PnDrive::new(Flash::new(), hardware());
    let c = testing::device_config();
    settings::write_name(d.objects_mut(), &c.name);
    settings::write_ip(d.objects_mut(), c.ip);
    assert!(d.save());
    let mut d = PnDrive::new(d.into_flash(), hardware());
    d.receive(
        Nanos::ZERO,
        &testing::connect_frame(),
        &mut |_: &[u8]| {},
        &mut |_| {},
    );
    assert!(d.device().cm().ar().is_some(), "connected");
    d
}

/// ns per `control_cycle` of the whole drive with `telegram` (`None`: the
/// output data as the scripted controller fills it, no telegram).
fn drive_cycle(telegram: Option<&[u8]>) -> f64 {
    let mut d = drive();
    let ar = d.device().cm().ar().cloned().unwrap();
    let cr = ar.output_cr.clone().unwrap();
    let cycle = cr.cycle();
    let mut frame = testing::output_frame(&ar, 0, 0x11).to_vec();
    let n = frame.len();
    if let Some(t) = telegram {
        let csdu = n - 4 - usize::from(cr.data_length);
        for o in cr.data.iter().filter(|o| o.slot == 2) {
            let at = csdu + usize::from(o.frame_offset);
            let len = usize::from(o.data_len).min(t.len());
            frame[at..at + len].copy_from_slice(&t[..len]);
        }
    }
    let io = [AxisIo::ready(0); 2];
    let mut k = 0u64;
    let mut step = |d: &mut PnDrive<Flash>, timed: &mut f64| {
        k += 1;
        let now = cycle.saturating_mul(k);
        let counter = (k as u16).wrapping_mul(256);
        frame[n - 4..n - 2].copy_from_slice(&counter.to_be_bytes());
        d.receive(now, &frame, &mut |_: &[u8]| {}, &mut |_| {});
        let _ = d.poll(now, &mut |_: &[u8]| {}, &mut |_| {});
        let start = Instant::now();
        black_box(d.control_cycle(now, &io));
        *timed += start.elapsed().as_nanos() as f64;
    };
    // settle: the enable sequence, the first response
    let mut ignored = 0.0;
    for _ in 0..1000 {
        step(&mut d, &mut ignored);
    }
    assert!(d.device().output_data(2).is_some(), "outputs valid");
    (0..ROUNDS)
        .map(|_| {
            let mut timed = 0.0;
            for _ in 0..DRIVE_CYCLES {
                step(&mut d, &mut timed);
            }
            timed / f64::from(DRIVE_CYCLES)
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let telegrams: [(&str, [u8; 36]); 3] = [
        ("0 (positioning)", telegram0()),
        ("1 (speed)", telegram1()),
        ("2 (torque)", telegram2()),
    ];
    println!("PROFIdrive profile alone (Profile on axis A, ns per call):");
    println!(
        "  {:<18} {:>10} {:>10} {:>10}",
        "receive telegram", "receive", "respond", "together"
    );
    for (name, t) in &telegrams {
        let (rx, tx) = profile_alone(t);
        println!("  {name:<18} {rx:>10.0} {tx:>10.0} {:>10.0}", rx + tx);
    }
    println!("PnDrive control cycle (2 axes, profile included, ns per cycle):");
    println!(
        "  {:<18} {:>10} {:>14}",
        "receive telegram", "cycle", "above at rest"
    );
    let rest = drive_cycle(None);
    println!("  {:<18} {rest:>10.0} {:>14}", "none (at rest)", "-");
    for (name, t) in &telegrams {
        let c = drive_cycle(Some(t));
        println!("  {name:<18} {c:>10.0} {:>14.0}", c - rest);
    }
    println!(
        "figure: PROFIdrive profile on the host: {:.0} ns per control cycle with receive telegram 1 above the cycle at rest",
        drive_cycle(Some(&telegram1())) - rest
    );
}
