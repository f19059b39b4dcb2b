//! Control cycle of the real drive runtime on the host, both axes, against
//! the simulated motors: following error of the cascade on the demo's csp
//! profile and compute time per control cycle per axis.
//!
//! `cargo bench -p hil-sim --bench control`
//!
//! No bus: the set-points are written into the dictionary as a decoded RxPDO
//! would, every 1 ms master cycle (= the control cycle); the drive runs
//! `Drive::control_cycle` and each motor takes one step.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]

use drive_ecat::axis::AxisIo;
use hil_sim::motor::Motor;
use hil_sim::sim::{SimFlash, CONTROL_CYCLE};
use nanos::Nanos;
use std::time::Instant;

mod common;
use common::{enable_csp, follow_profile, SimDrive};

fn main() {
    let mut drive = drive_ecat::runtime::Drive::new(SimFlash::new());
    let mut motors = [Motor::default_servo(), Motor::default_servo()];
    let mut pos = [0i32; 2];
    let mut now = Nanos::ZERO;
    let step = |drive: &mut SimDrive, motors: &mut [Motor; 2], pos: &mut [i32; 2], now: &mut Nanos| {
        *now += CONTROL_CYCLE;
        let io = [AxisIo::ready(pos[0]), AxisIo::ready(pos[1])];
        let t0 = Instant::now();
        let cmd = drive.control_cycle_with(*now, &io, [true, true]);
        let spent = t0.elapsed();
        for i in 0..2 {
            let torque = if cmd[i].power_stage {
                f64::from(cmd[i].torque_nm)
            } else {
                0.0
            };
            pos[i] = motors[i]
                .step(torque, !cmd[i].brake_release, CONTROL_CYCLE)
                .position_inc;
        }
        spent
    };
    enable_csp(&mut drive, |d| {
        step(d, &mut motors, &mut pos, &mut now);
    });
    for axis in 0..2u16 {
        let sw = drive.objects().get(0x6041 + 0x800 * axis, 0).unwrap();
        assert_eq!(sw & 0x6F, 0x27, "axis {axis} operation enabled");
    }
    let mut spent = std::time::Duration::ZERO;
    let (max, sq, total) = follow_profile(&mut drive, 1500, |d| {
        spent += step(d, &mut motors, &mut pos, &mut now);
    });
    let per_cycle_ns = spent.as_nanos() as f64 / total as f64;
    println!("csp profile of the demo (10 rev out and back, 1.5 s each), control cycle 1 ms, default servo");
    println!("{:<44} {:>12}", "figure", "value");
    println!("{:<44} {:>12.0}", "following error max, inc", max);
    println!(
        "{:<44} {:>12.3}",
        "following error max, degrees",
        max / common::INC_PER_REV * 360.0
    );
    println!(
        "{:<44} {:>12.1}",
        "following error rms, inc",
        (sq / total as f64).sqrt()
    );
    println!(
        "{:<44} {:>12.0}",
        "control cycle, both axes, ns (host)", per_cycle_ns
    );
    println!(
        "{:<44} {:>12.0}",
        "control cycle per axis, ns (host)",
        per_cycle_ns / 2.0
    );
}
