//! The motor models side by side on the demo's csp profile, both axes: the
//! rigid rotor (torque in, one cycle later) and the electrical axis (the
//! 16 kHz current loop on the PMSM plant, `hil_sim::electrical`). Prints the
//! following error of each and the host time each model costs per simulated
//! second, which decides whether `demo`/`serve` can run the electrical model by
//! default (serve runs up to 128 drives of 2 axes in real time on one core).
//!
//! `cargo bench -p hil-sim --bench plant`
//!
//! No bus: the set-points are written into the dictionary as a decoded RxPDO
//! would, every 1 ms (= the control cycle).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]

use drive_ecat::axis::AxisIo;
use hil_sim::electrical::{ElectricalAxis, PlantModel};
use hil_sim::motor::Motor;
use hil_sim::sim::{SimFlash, CONTROL_CYCLE};
use nanos::Nanos;
use std::time::{Duration, Instant};

mod common;
use common::{enable_csp, follow_profile, SimDrive};

struct Figures {
    ferr_max: f64,
    ferr_rms: f64,
    /// Host time of the two motor models per simulated second.
    plant_per_s: Duration,
    iq_max: f64,
    id_max: f64,
}

fn run(model: PlantModel) -> Figures {
    let mut drive = drive_ecat::runtime::Drive::new(SimFlash::new());
    let mut motors = [Motor::default_servo(), Motor::default_servo()];
    let mut el: Vec<ElectricalAxis> = match model {
        PlantModel::Rigid => Vec::new(),
        PlantModel::Electrical => (0..2)
            .map(|k| ElectricalAxis::default_servo(k).unwrap())
            .collect(),
    };
    let mut pos = [0i32; 2];
    let mut now = Nanos::ZERO;
    let mut spent = Duration::ZERO;
    let mut step = |drive: &mut SimDrive, pos: &mut [i32; 2], now: &mut Nanos| {
        *now += CONTROL_CYCLE;
        let io = [AxisIo::ready(pos[0]), AxisIo::ready(pos[1])];
        let cmd = drive.control_cycle_with(*now, &io, [true, true]);
        let t0 = Instant::now();
        for i in 0..2 {
            let c = cmd[i];
            let torque = if c.power_stage {
                f64::from(c.torque_nm)
            } else {
                0.0
            };
            let out = match el.get_mut(i) {
                Some(e) => e.step(
                    &mut motors[i],
                    torque,
                    c.power_stage,
                    !c.brake_release,
                    CONTROL_CYCLE,
                ),
                None => motors[i].step(torque, !c.brake_release, CONTROL_CYCLE),
            };
            pos[i] = out.position_inc;
        }
        spent += t0.elapsed();
    };
    enable_csp(&mut drive, |d| {
        step(d, &mut pos, &mut now);
    });
    let (max, sq, total) = follow_profile(&mut drive, 1500, |d| step(d, &mut pos, &mut now));
    let seconds = now.as_ns() as f64 * 1e-9;
    let (iq_max, id_max) = el
        .first()
        .map(|e| (e.stats().iq_max_abs, e.stats().id_true_max_abs))
        .unwrap_or((f64::NAN, f64::NAN));
    Figures {
        ferr_max: max,
        ferr_rms: (sq / total as f64).sqrt(),
        plant_per_s: spent.div_f64(seconds),
        iq_max,
        id_max,
    }
}

/// Host time of one axis at rest with the gates off for a simulated second
/// (most of a served line's drives), ms.
fn idle_ms(model: PlantModel) -> f64 {
    let mut motor = Motor::default_servo();
    let mut el = ElectricalAxis::default_servo(0).unwrap();
    let t0 = Instant::now();
    for _ in 0..1000 {
        let _ = match model {
            PlantModel::Rigid => motor.step(0.0, true, CONTROL_CYCLE),
            PlantModel::Electrical => el.step(&mut motor, 0.0, false, true, CONTROL_CYCLE),
        };
    }
    t0.elapsed().as_secs_f64() * 1e3
}

fn main() {
    let rigid = run(PlantModel::Rigid);
    let el = run(PlantModel::Electrical);
    println!("csp profile of the demo (10 rev out and back, 1.5 s each), control cycle 1 ms, both axes");
    println!("{:<52} {:>12} {:>12}", "figure", "rigid", "electrical");
    let row = |name: &str, a: f64, b: f64, prec: usize| {
        println!("{name:<52} {a:>12.prec$} {b:>12.prec$}");
    };
    row("following error max, inc", rigid.ferr_max, el.ferr_max, 0);
    row("following error rms, inc", rigid.ferr_rms, el.ferr_rms, 1);
    row("axis A max |iq|, A", rigid.iq_max, el.iq_max, 3);
    row("axis A max |id| in the motor, A", rigid.id_max, el.id_max, 4);
    let per_axis_ms = |f: &Figures| f.plant_per_s.as_secs_f64() * 1e3 / 2.0;
    row(
        "motor model per axis, ms host per simulated s",
        per_axis_ms(&rigid),
        per_axis_ms(&el),
        3,
    );
    row(
        "idle axis (gates off, at rest), ms host per simulated s",
        idle_ms(PlantModel::Rigid),
        idle_ms(PlantModel::Electrical),
        3,
    );
    // a drive has two axes; serve's line runs in one thread
    row(
        "moving drives one core keeps in real time (models)",
        500.0 / per_axis_ms(&rigid),
        500.0 / per_axis_ms(&el),
        0,
    );
}
