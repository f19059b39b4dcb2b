//! B42 "optimise current controller" (`drive_core::tuning`, issue 35) against
//! the electrical plant with motors the drive does not know: the identified R
//! and L beside the plant's, and what the gains from them do to the current
//! loop's step response (63 % rise time of an iq step of the rated current;
//! pole-zero cancellation aims at 1/ω_c = 159 µs at B64 = 1 kHz), with the
//! dictionary's default motor data (3.6 Ω, 12 mH) and with the identified:
//! after, every motor rises alike (1/ω_c and the loop's one-period delay,
//! ~210 µs) where before it ranged from an underdamped 115 µs to 624 µs (a
//! 45 mH motor's step meets the voltage circle: a little slower still).
//!
//! `cargo bench -p hil-sim --bench commission`
//!
//! No bus: the tuning and the plant are stepped as the drive's control cycle
//! and the simulator's shell step them (1 ms); `tests/tests/actions_motor.rs`
//! and `hil-sim/tests/soem/motor_actions.py` run the same through masters.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use drive_ecat::axis::{AxisCommand, CurrentControl, MotorData};
use drive_ecat::tuning::{CurrentTuning, Identified, Outcome};
use hil_sim::electrical::ElectricalAxis;
use hil_sim::motor::Motor;
use nanos::Nanos;

const CYCLE: Nanos = Nanos::from_ms(1);
const PWM: Nanos = Nanos::from_ns(62_500);

fn axis(r: f64, l: f64) -> (ElectricalAxis, Motor) {
    let mut el = ElectricalAxis::default_servo(0x35).unwrap();
    let mut m = el.plant().params().motor;
    (m.r_ohm, m.ld_h, m.lq_h) = (r, l, l);
    el.plant_mut().set_motor(m);
    (el, Motor::default_servo())
}

/// The tuning run to its end: what it identified and the simulated time.
fn identify(r: f64, l: f64) -> (Identified, f64) {
    let (mut el, mut motor) = axis(r, l);
    let d = MotorData::default();
    let mut t = CurrentTuning::new(d.rated_current_a, d.r_ohm, false);
    let mut actual = None;
    for k in 0..20_000 {
        let cmd = t.cycle(4, actual.as_ref());
        match t.outcome() {
            Outcome::Running(_) => {}
            Outcome::Done(id) => return (id, k as f64 * 1e-3),
            Outcome::Failed(code) => panic!("{r} Ω {l} H: failed with {code}"),
        }
        el.command(&cmd.unwrap_or(AxisCommand::OFF));
        el.run(&mut motor, CYCLE);
        actual = el.actual();
    }
    panic!("{r} Ω {l} H: no end");
}

/// The 63 % rise time of a rated-current iq step with the loop's gains from
/// `data`, µs (measured iq per PWM period, linear between samples).
fn rise_us(r: f64, l: f64, data: &MotorData) -> f64 {
    let (mut el, mut motor) = axis(r, l);
    el.set_motor_data(data).unwrap();
    let torque = f64::from(data.rated_torque_nm());
    let target = f64::from(data.rated_current_a) * 0.632;
    let mut last = 0.0;
    for k in 1..=64 {
        el.step(&mut motor, torque, true, false, PWM);
        let iq = el.last().iq_a;
        if iq >= target {
            let frac = (target - last) / (iq - last);
            return (k as f64 - 1.0 + frac) * 62.5;
        }
        last = iq;
    }
    f64::INFINITY
}

fn main() {
    println!("B42 optimise current controller on the electrical plant (dictionary: 3.6 Ω, 12 mH; B64 = 1 kHz, target rise 159 µs)");
    println!(
        "{:>8} {:>8} | {:>9} {:>7} {:>9} {:>7} {:>7} | {:>14} {:>14}",
        "R Ω", "L mH", "R id Ω", "err %", "L id mH", "err %", "time s", "rise µs before", "rise µs after"
    );
    for (r, l) in [
        (3.6, 0.012),
        (2.2, 0.0065),
        (6.0, 0.021),
        (1.0, 0.003),
        (12.0, 0.045),
    ] {
        let (id, t) = identify(r, l);
        let d = MotorData::default();
        let tuned = MotorData {
            r_ohm: id.r_ohm,
            ld_h: id.l_h,
            lq_h: id.l_h,
            ..d
        };
        let er = (f64::from(id.r_ohm) - r) / r * 100.0;
        let el = (f64::from(id.l_h) - l) / l * 100.0;
        println!(
            "{r:>8.2} {:>8.2} | {:>9.3} {er:>+7.2} {:>9.3} {el:>+7.2} {t:>7.2} | {:>14.0} {:>14.0}",
            l * 1e3,
            id.r_ohm,
            id.l_h * 1e3,
            rise_us(r, l, &d),
            rise_us(r, l, &tuned)
        );
    }
}
