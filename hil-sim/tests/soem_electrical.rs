//! SOEM (through pysoem) against `hil-sim serve --plant electrical`: the
//! torque modes on the current loop and the PMSM plant (issue 34). Needs root
//! and `PYSOEM_PYTHON` (`.ci/run` sets it to target/pysoem-venv/bin/python);
//! skipped otherwise, like `soem.rs`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::scratch;
use common::soem_line::{pysoem_python, Line};

/// `script` with `args` through SOEM against one drive on the line `tag`
/// that `hil-sim serve --plant electrical` runs for `seconds` (with
/// `serve`'s further arguments); its failure fails the test. Skipped
/// without pysoem.
fn on_the_electrical_plant(tag: &str, seconds: u32, serve: &[&str], script: &str, args: &[&str]) {
    let Some(python) = common::or_skip(pysoem_python(), &format!("soem {script} test")) else {
        return;
    };
    let dir = scratch(&format!("soem-{}", script.trim_end_matches(".py")));
    let serve = [&["--plant", "electrical"], serve].concat();
    let line = Line::with_serve_args(tag, 1, seconds, &dir, &serve);
    line.run_passes(&python, script, args);
}

/// C-038, P-187 through SOEM on the electrical plant (`cst_electrical.py`):
/// 6071h steps of ±10 %, ±50 %, ±100 % of the rated torque in cst give a
/// 6077h (kt times the measured iq, averaged over the control cycle) within
/// 2 % of 6071h in every frame from the fourth after the step while the free
/// rotor is below half the speed limit (G472/G475 = 100 % of I10).
#[test]
fn c038_p187_soem_cst_steps_on_the_electrical_plant_give_6077h_within_2_percent() {
    let i10 = drive_ecat::DriveObjects::new()
        .get(drive_ecat::params::I10, 0)
        .expect("I10 declared");
    on_the_electrical_plant("e", 120, &[], "cst_electrical.py", &["--i10", &i10.to_string()]);
}

/// C-038 and E-089 through SOEM on the electrical plant
/// (`motor_protection.py`, issue 34): the motor data by SDO (6076h = kt ×
/// 6075h; zero pole pairs, zero rated current and a bandwidth above a fifth
/// of the PWM rate refused with 0609 0032h/0031h); 6073h lowered to 50 %
/// limits 6077h and the measured current 6078h in cst to ±500 ‰ (within 2 %,
/// statusword bit 11); 200 % of the rated current gives the i²t warning
/// (bit 7) at the first-order thermal model's t = −τ·ln(1 − (I_r/I)²) (within
/// 3 % + 20 ms, with the mean of the measured (I/I_r)²), the current held at
/// the rated current (bit 11), and U11 later the fault 4380h (603Fh and EMCY,
/// event 45).
#[test]
fn c038_e089_soem_max_current_and_motor_i2t_on_the_electrical_plant() {
    on_the_electrical_plant("m", 120, &[], "motor_protection.py", &[]);
}

/// E-089 and C-017 through SOEM on the electrical plant (`overcurrent.py`,
/// issue 34): `serve --plant-fault short` shorts leg a of axis A to the DC
/// link's negative rail through 1 Ω behind its current sensor; the enable
/// faults the axis once Switch on puts the power stage on (the first PWM
/// period with the gates on trips the over-current protection): statusword Fault, 603Fh and EMCY
/// 2310h (error register bit 1, event 33 cause 2), 6077h/6078h 0 after it;
/// a fault reset gives Switch on disabled and the next enable faults again.
#[test]
fn e089_c017_soem_over_current_trip_on_the_electrical_plant() {
    on_the_electrical_plant("o", 60, &["--plant-fault", "short"], "overcurrent.py", &[]);
}

/// C-038 and E-089 through SOEM on the electrical plant (`stage_i2t.py`,
/// issue 34): the current limit is the lowest of 6073h and the power
/// stage's: 6073h lowered to 25 % by SDO limits 6078h to ±250 ‰ (bit 11);
/// raised to 500 % the stage's maximum (8 A = 4000 ‰ of 6075h) limits; the
/// stage's i²t (4 A rated, τ = 5 s) warns (bit 7) at 80 % and limits to its
/// rated current (2000 ‰) at 100 %, each at the first-order model's
/// t = −τ·ln(1 − x/u) (within 3 % + 36 ms, u the mean measured
/// (i/I_rated)²), without a fault.
#[test]
fn c038_e089_soem_current_limit_and_power_stage_i2t_on_the_electrical_plant() {
    on_the_electrical_plant("i", 60, &[], "stage_i2t.py", &[]);
}

/// E-140, E-141 through SOEM on the electrical plant (`motor_actions.py`,
/// issue 35): A75/A69 in the process data; B42 refused while the axis is
/// switch-on disabled (nothing changes); B42 and B49 started in Ready to
/// switch on, run after the enable, identify the plant's R and L (2.2 Ω,
/// 6.5 mH: `serve --plant-r/--plant-l`, the drive's B53/B52 say 3.6 Ω,
/// 12 mH) within 5 % into B53 and B52/B62; B41 finds the plant's
/// commutation offset (0.3 rad: `--plant-offset`) within 0.5° electrical
/// into B05; B43 (no enable) measures the three phases within 3 % of R;
/// B40 passes the plant as wired (the pole pairs seen = B10); B300 (test
/// brake) holds the rated torque both ways within 1/360 rev; B301 (grind
/// brake) turns the shaft at 60 rpm against the applied brake and released,
/// each phase at least 0.8 of what that speed gives, its grinding torque
/// the plant's brake (2 N·m, unknown to the drive) plus friction.
#[test]
fn e140_e141_soem_motor_actions_identify_the_plants_r_l_and_commutation_offset() {
    let (r, l, offset) = ("2.2", "0.0065", "0.3");
    on_the_electrical_plant(
        "a",
        120,
        &["--plant-r", r, "--plant-l", l, "--plant-offset", offset],
        "motor_actions.py",
        &["--r", r, "--l", l, "--offset", offset],
    );
}

/// E-090 and E-089 through SOEM on the electrical plant (`chopper.py`, issue
/// 34): the DC-link window refused where it is written (A38 at the
/// over-voltage trip and A35 above A38 − 20 V: 0609 0031h; A38 too close to
/// A35: 0609 0032h; A40 read only), then a 0.01 kg·m² flywheel (`serve
/// --flywheel`) braked from 40 rev/s at −200 % in cst without a brake
/// resistor (A21 = 0): the link (6079h) climbs from 565 V to the 800 V trip
/// by the energy balance (within 5 %), 603Fh and EMCY 3110h (event 36).
#[test]
fn e090_e089_soem_braking_a_flywheel_without_brake_resistor_trips_over_voltage() {
    on_the_electrical_plant("v", 120, &["--flywheel", "0.01"], "chopper.py", &[]);
}

/// E-140, E-141 through SOEM on the electrical plant (`mechanics.py`, issue
/// 35): B44 "identify mechanics" (A75 selector 1111b, ours) refused while
/// the axis is switch-on disabled (nothing changes) and, before it moves,
/// when its travel would pass the software limits 607Dh (B44[0] = 12); then
/// started in Ready to switch on and run after the enable it identifies the
/// simulated servo's inertia within 5 % and its Coulomb and viscous friction
/// within 10 % (1e-4 kg·m², 0.02 N·m, 2e-5 N·m·s/rad: the drive's B45…B47
/// are 0) and writes the speed controller's gain for B48.
#[test]
fn e140_e141_soem_b44_identify_mechanics_refused_beyond_the_limits_then_identifies_the_plant() {
    on_the_electrical_plant(
        "b4",
        120,
        &[],
        "mechanics.py",
        &["--j", "1e-4", "--fc", "0.02", "--b", "2e-5"],
    );
}
