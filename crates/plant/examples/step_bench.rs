//! Current-step figures of `foc` against the plant (issue 34): iq 0 → rated,
//! locked and free rotor, and at full speed (id excursion with and without
//! decoupling), at ω_c = 2π·1 kHz and 16 kHz PWM, and at 8 kHz with 1 kHz
//! (the loop's delay doubled: the overshoot of a delayed first order) and
//! with 500 Hz (ω_c·T as at 16 kHz). Goal (issue 34): rise ≈ 2.2/ω_c or
//! shorter, overshoot ≤ 15 %, |id| ≤ 5 % of rated (0.1 A) at full speed
//! decoupled.
//!
//! `cargo run --release -p plant --example step_bench`

use core::f64::consts::TAU;
use foc::{LoopParams, MotorData};
use plant::closed_loop::current_step;
use plant::{PlantParams, Shaft};

fn main() {
    let motor = MotorData::default_servo();
    let rated = motor.rated_current_a;
    let full_speed = 3000.0 / 60.0 * TAU;
    println!(
        "current step iq 0 -> {rated} A (rated), default servo (R {} ohm, L {} mH, p {})",
        motor.r_ohm,
        motor.ld_h * 1e3,
        motor.pole_pairs
    );
    println!(
        "{:>6} {:>8} {:>22} {:>10} {:>12} {:>10} {:>12}",
        "PWM", "f_c", "shaft", "rise us", "2.2/wc us", "overshoot", "|id| max A"
    );
    for (pwm, fc) in [(16_000.0f32, 1_000.0f32), (8_000.0, 1_000.0), (8_000.0, 500.0)] {
        let mut params = LoopParams::default_16k();
        params.pwm_hz = pwm;
        params.omega_c_rad_s = core::f32::consts::TAU * fc;
        let mut plant = PlantParams::default_servo();
        plant.inverter.pwm_hz = f64::from(pwm);
        plant.inverter.pwm_period_counts = (144.0e6 / 2.0 / f64::from(pwm)) as u16;
        let cases: [(&str, Shaft, bool); 4] = [
            ("locked", Shaft::Locked, true),
            ("free", Shaft::Free, true),
            (
                "3000 rpm, decoupled",
                Shaft::Driven {
                    speed_rad_s: full_speed,
                },
                true,
            ),
            (
                "3000 rpm, no decoupling",
                Shaft::Driven {
                    speed_rad_s: full_speed,
                },
                false,
            ),
        ];
        for (name, shaft, dec) in cases {
            params.decoupling = dec;
            match current_step(plant, motor, params, shaft, rated, 400, 400) {
                Ok(f) => println!(
                    "{:>4}k {:>6.0}Hz {:>22} {:>10.1} {:>12.1} {:>9.1}% {:>12.4}",
                    pwm / 1000.0,
                    params.omega_c_rad_s / core::f32::consts::TAU,
                    name,
                    f.rise_s * 1e6,
                    2.2 / f64::from(params.omega_c_rad_s) * 1e6,
                    f.overshoot * 100.0,
                    f.id_max_abs_a
                ),
                Err(e) => println!("{name}: parameters refused: {e:?}"),
            }
        }
    }
}
