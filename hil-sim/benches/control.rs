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

const INC_PER_REV: f64 = 1_048_576.0;

/// The demo's profile: 10 revolutions out and back, cosine S-curves of
/// `t_move` cycles each, 150 cycles dwell between and after.
fn profile(k: usize, t_move: usize) -> f64 {
    let phase = |k: usize| (1.0 - (std::f64::consts::PI * k as f64 / t_move as f64).cos()) / 2.0;
    let x = if k < t_move {
        phase(k)
    } else if k < t_move + 150 {
        1.0
    } else if k < 2 * t_move + 150 {
        1.0 - phase(k - t_move - 150)
    } else {
        0.0
    };
    x * 10.0 * INC_PER_REV
}

fn main() {
    let mut drive = drive_ecat::runtime::Drive::new(SimFlash::new());
    let mut motors = [Motor::default_servo(), Motor::default_servo()];
    let mut pos = [0i32; 2];
    let mut now = Nanos::ZERO;
    let step = |drive: &mut drive_ecat::runtime::Drive<SimFlash>,
                motors: &mut [Motor; 2],
                pos: &mut [i32; 2],
                now: &mut Nanos| {
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
    // enable both axes in csp (mode 8 is the default), holding position 0
    for cw in [0x06, 0x07, 0x0F, 0x0F, 0x0F] {
        for axis in 0..2u16 {
            drive.objects_mut().set(0x6040 + 0x800 * axis, 0, cw).unwrap();
            drive.objects_mut().set(0x607A + 0x800 * axis, 0, 0).unwrap();
        }
        for _ in 0..5 {
            step(&mut drive, &mut motors, &mut pos, &mut now);
        }
    }
    for axis in 0..2u16 {
        let sw = drive.objects().get(0x6041 + 0x800 * axis, 0).unwrap();
        assert_eq!(sw & 0x6F, 0x27, "axis {axis} operation enabled");
    }
    let t_move = 1500;
    let total = 2 * t_move + 300;
    let (mut max, mut sq, mut spent) = (0.0f64, 0.0f64, std::time::Duration::ZERO);
    for k in 0..total {
        let target = profile(k, t_move).round() as i64;
        for axis in 0..2u16 {
            drive.objects_mut().set(0x607A + 0x800 * axis, 0, target).unwrap();
        }
        spent += step(&mut drive, &mut motors, &mut pos, &mut now);
        let ferr = drive.objects().get(0x60F4, 0).unwrap() as f64;
        max = max.max(ferr.abs());
        sq += ferr * ferr;
    }
    let per_cycle_ns = spent.as_nanos() as f64 / total as f64;
    println!("csp profile of the demo (10 rev out and back, 1.5 s each), control cycle 1 ms, default servo");
    println!("{:<44} {:>12}", "figure", "value");
    println!("{:<44} {:>12.0}", "following error max, inc", max);
    println!(
        "{:<44} {:>12.3}",
        "following error max, degrees",
        max / INC_PER_REV * 360.0
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
