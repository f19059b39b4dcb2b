//! The electrical axis against closed form: the torque a command gives.

use super::*;

/// Closed form of the motor: T = 1.5·p·ψ·iq.
fn torque_of_iq(iq: f64) -> f64 {
    let m = MotorData::default_servo();
    1.5 * f64::from(m.pole_pairs) * f64::from(m.psi_vs) * iq
}

/// Runs `cycles` control cycles of 1 ms with `torque_nm` and the brake as
/// given; returns the axis, the motor and the measured iq of the last PWM period
/// (its ADC noise, ~7 mA, is far inside 2 % of the currents checked).
fn run(torque_nm: f64, brake: bool, cycles: u32) -> (ElectricalAxis, Motor, f64) {
    run_at(torque_nm, brake, cycles, 16_000.0)
}

/// [`run`] with the inverter and the loop at `pwm_hz`.
fn run_at(torque_nm: f64, brake: bool, cycles: u32, pwm_hz: f32) -> (ElectricalAxis, Motor, f64) {
    let mut el = ElectricalAxis::default_servo_at(7, pwm_hz).unwrap();
    let mut motor = Motor::default_servo();
    for _ in 0..cycles {
        el.step(&mut motor, torque_nm, true, brake, Nanos::from_ms(1));
    }
    let iq = f64::from(el.foc().measured().current.q);
    (el, motor, iq)
}

/// C-038 (cst follows 6071h): with the rotor held by the brake, 1.3 N·m (rated)
/// commanded gives, once the current loop has settled (20 ms ≫ 1/ω_c), the
/// torque T = 1.5·p·ψ·iq from the measured iq and in the motor within 2 %, and id ≈ 0.
#[test]
fn c038_a_torque_command_gives_its_torque_through_the_current_loop_locked() {
    locked_at(16_000.0);
}

/// 1.3 N·m against the brake at `pwm_hz` for 20 cycles of 1 ms: the
/// measured iq's torque and the motor's within 2 %, id ≈ 0.
fn locked_at(pwm_hz: f32) -> ElectricalAxis {
    let (el, motor, iq) = run_at(1.3, true, 20, pwm_hz);
    assert_eq!(motor.velocity_rad_s(), 0.0, "the brake (2 N·m) holds 1.3 N·m");
    let measured = torque_of_iq(iq);
    assert!(
        (measured - 1.3).abs() <= 0.02 * 1.3,
        "measured-iq torque {measured} N·m"
    );
    let true_t = el.plant().torque_nm();
    assert!((true_t - 1.3).abs() <= 0.02 * 1.3, "motor torque {true_t} N·m");
    assert!(el.plant().id().abs() < 0.05 * 2.0, "id {} A", el.plant().id());
    el
}

/// C-038 at the 8 kHz option (`serve --pwm-khz 8`, the board's `pwm-8k`):
/// eight PWM periods per 1 ms cycle; the locked rotor's torque and the
/// measured iq's as at 16 kHz, within 2 %.
#[test]
fn c038_a_torque_command_gives_its_torque_through_the_8_khz_current_loop() {
    let el = locked_at(8_000.0);
    assert_eq!(el.stats().periods, 20 * 8, "8 PWM periods per 1 ms cycle");
}

/// C-038 with the rotor free: 1.0 N·m accelerates the default servo
/// (J = 1e-4 kg·m², Coulomb 0.02 N·m) against its back-EMF; after 30 ms the
/// torque is within 2 % of the command, and the speed is the closed form
/// ω(t) = (T − Tc)/J · t less the current loop's lag (≈ 1/ω_c = 0.16 ms of
/// acceleration) and the viscous friction, within 2 %.
#[test]
fn c038_a_torque_command_gives_its_torque_through_the_current_loop_free() {
    let (el, motor, iq) = run(1.0, false, 30);
    let measured = torque_of_iq(iq);
    assert!(
        (measured - 1.0).abs() <= 0.02,
        "measured-iq torque {measured} N·m"
    );
    let true_t = el.plant().torque_nm();
    assert!((true_t - 1.0).abs() <= 0.02, "motor torque {true_t} N·m");
    let w = motor.velocity_rad_s();
    let closed = (1.0 - 0.02) / 1.0e-4 * 0.030;
    assert!(w > 100.0, "the rotor turns: {w} rad/s");
    assert!(
        (w - closed).abs() <= 0.02 * closed,
        "speed {w} rad/s, closed form {closed} rad/s"
    );
    assert!(
        el.stats().id_true_max_abs < 0.05 * 2.0,
        "id max {} A",
        el.stats().id_true_max_abs
    );
}

/// The gates off (power stage off): no current, no torque, the rotor coasts.
#[test]
fn without_the_power_stage_no_current_flows() {
    let mut el = ElectricalAxis::default_servo(7).unwrap();
    let mut motor = Motor::default_servo();
    for _ in 0..5 {
        el.step(&mut motor, 1.0, false, false, Nanos::from_ms(1));
    }
    assert_eq!(el.plant().iq(), 0.0);
    assert_eq!(motor.velocity_rad_s(), 0.0);
    assert_eq!(el.stats().enabled_periods, 0);
}

/// An idle axis (gates off, no current) steps only the motor, and enabling it
/// again gives the commanded torque as an axis enabled all along does.
#[test]
fn an_idle_axis_comes_back_with_its_torque() {
    let mut el = ElectricalAxis::default_servo(7).unwrap();
    let mut motor = Motor::default_servo();
    // spin up, switch off, coast idle, switch on again
    for _ in 0..10 {
        el.step(&mut motor, 1.0, true, false, Nanos::from_ms(1));
    }
    for _ in 0..5 {
        el.step(&mut motor, 0.0, false, false, Nanos::from_ms(1));
    }
    assert!(
        motor.velocity_rad_s() > 50.0,
        "coasting at {} rad/s",
        motor.velocity_rad_s()
    );
    assert!(el.plant().iq().abs() < IDLE_A, "idle: iq {}", el.plant().iq());
    for _ in 0..10 {
        el.step(&mut motor, 0.5, true, false, Nanos::from_ms(1));
    }
    let t = el.plant().torque_nm();
    assert!(
        (t - 0.5).abs() <= 0.02 * 0.5,
        "torque {t} N·m after enabling while turning"
    );
}

/// C-038, P-187 at the drive core's current seam ([`CurrentControl`]): the
/// commands of 10 %, 50 % and 100 % of the rated torque (1.3 N·m), rotor held
/// by the brake (2 N·m), give after 20 ms (≫ 1/ω_c) an `actual()` whose torque
/// (the measured iq's mean over the cycle) is within 2 % of the command and
/// equals kt·iq with kt = 1.5·p·ψ (closed form), and the motor's own
/// instantaneous torque within 2 % of the rated torque; before
/// the first cycle under the command `actual()` shows no current.
#[test]
fn c038_p187_the_seam_reports_the_measured_torque_at_10_50_100_percent() {
    for share in [0.1, 0.5, 1.0] {
        let t = 1.3 * share;
        let mut el = ElectricalAxis::default_servo(11).unwrap();
        let mut motor = Motor::default_servo();
        el.command(&AxisCommand {
            torque_nm: t as f32,
            power_stage: true,
            brake_release: false,
            injection: None,
        });
        let before = el.actual().unwrap();
        assert!(before.current_a.abs() < 0.02, "{share}: {before:?}");
        for _ in 0..20 {
            el.run(&mut motor, Nanos::from_ms(1));
        }
        let a = el.actual().unwrap();
        assert_eq!(motor.velocity_rad_s(), 0.0, "{share}: the brake holds");
        let closed = torque_of_iq(f64::from(a.current_a));
        assert!(
            (f64::from(a.torque_nm) - closed).abs() < 1e-4,
            "{share}: {a:?} vs kt·iq {closed}"
        );
        assert!(
            (f64::from(a.torque_nm) - t).abs() <= 0.02 * t,
            "{share}: {a:?}, command {t}"
        );
        // the motor's instantaneous torque: the loop regulates the noisy
        // sample (σ ≈ 7 mA = 0.35 % of the rated current), so 2 % of rated
        let motor_t = el.plant().torque_nm();
        assert!(
            (motor_t - t).abs() <= 0.02 * 1.3,
            "{share}: motor torque {motor_t}"
        );
    }
}

/// The current loop's periods of `el` at the reference `torque_nm`, gates
/// on, the rotor free; the first period whose step left a latched trip.
fn periods(el: &mut ElectricalAxis, motor: &mut Motor, torque_nm: f64, n: u32) -> Option<u32> {
    let period = Nanos::from_ns(62_500);
    (0..n).find(|_| {
        el.step(motor, torque_nm, true, false, period);
        el.foc().trip().is_some()
    })
}

/// E-089 against a false event 69 (seen through SOEM: `stage_i2t.py` on a
/// loaded machine, its square wave's flips from the speed limit): the
/// current deviation is judged per window of 256 PWM periods, so a torque
/// step of 8 A from (nearly) nothing late in a window left its healthy
/// transient (the error ≈ Δ for a period or two, then e^(−ω_c·t)) against
/// a window of almost no reference. A step of 5.2 N·m (8 A) at each 4th
/// period of a window, with the rotor at standstill, at 100 rad/s and at
/// 312 rad/s (the torque modes' speed limit of `serve`), and a pulse of
/// 8 A lasting one control cycle of 250 µs, trip nothing over two windows;
/// the same step with motor phase c open still trips `MotorConnection`
/// within two windows (the open phase's witness is kept).
#[test]
fn e089_a_torque_step_late_in_a_window_is_no_motor_connection_fault() {
    let w = foc::axis::I2T_DECIMATION;
    for open in [false, true] {
        for speed in [0.0, 100.0, 312.0] {
            for offset in (0..w).step_by(4) {
                let mut el = ElectricalAxis::default_servo(7).unwrap();
                let mut motor = Motor::default_servo();
                let mut k = 0;
                while motor.velocity_rad_s() < speed {
                    assert_eq!(periods(&mut el, &mut motor, 5.2, 1), None, "speeding up");
                    k += 1;
                }
                // two windows of (nearly) no torque, then the step `offset`
                // periods into a window
                let hold = 2 * w + (w - k % w) + offset;
                assert_eq!(
                    periods(&mut el, &mut motor, 0.03, hold),
                    None,
                    "{speed} rad/s, holding"
                );
                if open {
                    el.plant_mut().set_faults(plant::FaultOptions {
                        open_phase: Some(plant::Phase::C),
                        ..plant::FaultOptions::NONE
                    });
                }
                let tripped = periods(&mut el, &mut motor, -5.2, 2 * w);
                if open {
                    assert!(
                        tripped.is_some(),
                        "open phase c, {speed} rad/s, step at {offset}: not seen"
                    );
                    assert_eq!(el.foc().trip(), Some(foc::Trip::MotorConnection));
                } else {
                    assert_eq!(
                        tripped, None,
                        "{speed} rad/s, step at period {offset} of a window"
                    );
                }
            }
        }
    }
    // a pulse: 8 A for one control cycle of 250 µs (4 periods), at standstill
    for offset in (0..w).step_by(4) {
        let mut el = ElectricalAxis::default_servo(7).unwrap();
        let mut motor = Motor::default_servo();
        assert_eq!(periods(&mut el, &mut motor, 0.0, w + offset), None);
        assert_eq!(periods(&mut el, &mut motor, 5.2, 4), None);
        assert_eq!(
            periods(&mut el, &mut motor, 0.0, 2 * w),
            None,
            "pulse at period {offset}"
        );
    }
}
