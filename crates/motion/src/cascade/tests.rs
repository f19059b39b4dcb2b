//! Tests of the control cascade.

use super::*;

const REV: f32 = INCREMENTS_PER_REVOLUTION as f32;
const DT_NS: u32 = 125_000;

/// Rigid body J·dω/dt = T − b·ω, integrated with 10 sub-steps per cycle.
struct Plant {
    j: f64,
    b: f64,
    /// Position, rad.
    theta: f64,
    /// Velocity, rad/s.
    omega: f64,
}

impl Plant {
    fn new() -> Self {
        Plant {
            j: 1e-4,
            b: 1e-4,
            theta: 0.0,
            omega: 0.0,
        }
    }
    fn step(&mut self, torque: f32, dt_ns: u32) {
        let h = f64::from(dt_ns) * 1e-9 / 10.0;
        for _ in 0..10 {
            let acc = (f64::from(torque) - self.b * self.omega) / self.j;
            self.omega += acc * h;
            self.theta += self.omega * h;
        }
    }
    fn position_inc(&self) -> i32 {
        let inc = self.theta / f64::from(RAD_PER_INCREMENT);
        (inc.round() as i64) as i32
    }
    fn velocity_inc_per_s(&self) -> f32 {
        (self.omega / f64::from(RAD_PER_INCREMENT)) as f32
    }
}

fn input(entry: ControlEntry, plant: &Plant) -> CascadeInput {
    CascadeInput {
        entry,
        position_setpoint_inc: 0,
        velocity_inc_per_s: 0.0,
        acceleration_feedforward_inc_per_s2: 0.0,
        torque_nm: 0.0,
        actual_position_inc: plant.position_inc(),
        actual_velocity_inc_per_s: None,
    }
}

#[test]
fn modes_enter_at_the_spec_entry_points() {
    assert_eq!(ControlEntry::for_mode(8), Some(ControlEntry::Position));
    assert_eq!(ControlEntry::for_mode(1), Some(ControlEntry::Position));
    assert_eq!(ControlEntry::for_mode(7), Some(ControlEntry::Position));
    assert_eq!(ControlEntry::for_mode(6), Some(ControlEntry::Position));
    assert_eq!(ControlEntry::for_mode(9), Some(ControlEntry::Velocity));
    assert_eq!(ControlEntry::for_mode(3), Some(ControlEntry::Velocity));
    assert_eq!(ControlEntry::for_mode(10), Some(ControlEntry::Torque));
    assert_eq!(ControlEntry::for_mode(4), Some(ControlEntry::Torque));
    assert_eq!(ControlEntry::for_mode(0), None);
    assert_eq!(ControlEntry::for_mode(5), None);
}

#[test]
fn config_validation_refuses_bad_values() {
    assert!(CascadeConfig::DEFAULT.validate().is_ok());
    let mut c = CascadeConfig::DEFAULT;
    c.torque_limit_negative_nm = -1.0;
    assert_eq!(c.validate(), Err(CascadeError::InvalidValue));
    let mut c = CascadeConfig::DEFAULT;
    c.velocity_gain_nm_per_rad_per_s = f32::NAN;
    assert_eq!(c.validate(), Err(CascadeError::InvalidValue));
    let mut c = CascadeConfig::DEFAULT;
    c.velocity_feedforward_percent = 120.0;
    assert_eq!(c.validate(), Err(CascadeError::FeedforwardWeight));
    assert!(Cascade::new(c, 0).is_err());
}

#[test]
fn c035_position_step_settles_without_large_overshoot() {
    let mut plant = Plant::new();
    let mut cascade = Cascade::new(CascadeConfig::DEFAULT, plant.position_inc()).unwrap();
    let step = 10_000; // ≈ 3.4°
    let mut max_pos = i32::MIN;
    let mut settled_at = None;
    for k in 0..2400u32 {
        // 300 ms
        let mut inp = input(ControlEntry::Position, &plant);
        inp.position_setpoint_inc = step;
        let out = cascade.cycle(&inp, DT_NS);
        assert!(out.torque_nm.is_finite());
        plant.step(out.torque_nm, DT_NS);
        let p = plant.position_inc();
        max_pos = max_pos.max(p);
        if (p - step).abs() <= step / 100 {
            settled_at.get_or_insert(k);
        } else {
            settled_at = None;
        }
    }
    let overshoot = max_pos - step;
    assert!(overshoot <= step / 20, "overshoot {overshoot} inc above 5 %");
    let settled_at = settled_at.expect("never settled within 1 %");
    assert!(
        settled_at < 800,
        "settled only after {settled_at} cycles (100 ms bound)"
    );
    assert!((plant.position_inc() - step).abs() <= 5, "residual error");
}

#[test]
fn c035_bumpless_enable_gives_zero_torque_on_the_first_cycle() {
    let mut cascade = Cascade::new(CascadeConfig::DEFAULT, 0).unwrap();
    // Axis parked elsewhere: reset to its position, set-point = actual.
    cascade.reset(123_456);
    let out = cascade.cycle(
        &CascadeInput {
            entry: ControlEntry::Position,
            position_setpoint_inc: 123_456,
            velocity_inc_per_s: 0.0,
            acceleration_feedforward_inc_per_s2: 0.0,
            torque_nm: 0.0,
            actual_position_inc: 123_456,
            actual_velocity_inc_per_s: None,
        },
        DT_NS,
    );
    assert_eq!(out.torque_nm, 0.0);
    assert_eq!(out.following_error_inc, 0);
    assert!(!out.internal_limit);
}

/// P-157: inside the dead band the position controller's output is only
/// the feedforward; one increment beyond it Kv·error comes back.
#[test]
fn p157_no_position_correction_inside_the_dead_band() {
    let cfg = CascadeConfig {
        position_dead_band_inc: 100,
        ..CascadeConfig::DEFAULT
    };
    let command = |error: i32, ff: f32| {
        let mut cascade = Cascade::new(cfg, 0).unwrap();
        let out = cascade.cycle(
            &CascadeInput {
                entry: ControlEntry::Position,
                position_setpoint_inc: error,
                velocity_inc_per_s: ff,
                acceleration_feedforward_inc_per_s2: 0.0,
                torque_nm: 0.0,
                actual_position_inc: 0,
                actual_velocity_inc_per_s: Some(0.0),
            },
            DT_NS,
        );
        assert_eq!(out.following_error_inc, error, "reported unchanged");
        out.velocity_command_inc_per_s
    };
    assert_eq!(command(100, 0.0), 0.0);
    assert_eq!(command(-100, 0.0), 0.0);
    assert_eq!(command(60, 5000.0), 5000.0, "feedforward passes");
    assert_eq!(command(101, 0.0), 100.0 * 101.0);
    assert_eq!(command(-101, 0.0), -100.0 * 101.0);
    // off (the default): any error is corrected
    let mut cascade = Cascade::new(CascadeConfig::DEFAULT, 0).unwrap();
    let out = cascade.cycle(
        &CascadeInput {
            entry: ControlEntry::Position,
            position_setpoint_inc: 1,
            velocity_inc_per_s: 0.0,
            acceleration_feedforward_inc_per_s2: 0.0,
            torque_nm: 0.0,
            actual_position_inc: 0,
            actual_velocity_inc_per_s: Some(0.0),
        },
        DT_NS,
    );
    assert_eq!(out.velocity_command_inc_per_s, 100.0);
}

#[test]
fn c035_following_error_wraps_around_i32() {
    let mut cascade = Cascade::new(CascadeConfig::DEFAULT, i32::MAX - 10).unwrap();
    let out = cascade.cycle(
        &CascadeInput {
            entry: ControlEntry::Position,
            position_setpoint_inc: i32::MIN + 9, // 20 increments ahead
            velocity_inc_per_s: 0.0,
            acceleration_feedforward_inc_per_s2: 0.0,
            torque_nm: 0.0,
            actual_position_inc: i32::MAX - 10,
            actual_velocity_inc_per_s: Some(0.0),
        },
        DT_NS,
    );
    assert_eq!(out.following_error_inc, 20);
    assert!(out.torque_nm > 0.0);
}

#[test]
fn c037_velocity_follows_a_ramp_with_bounded_error() {
    let mut plant = Plant::new();
    let mut cascade = Cascade::new(CascadeConfig::DEFAULT, 0).unwrap();
    let acc = 100.0 * REV; // 100 rev/s²
    let mut worst = 0.0f32;
    for k in 0..3200u32 {
        // ramp to 20 rev/s in 200 ms, then hold for 200 ms
        let t = (k + 1) as f32 * DT_NS as f32 * 1e-9;
        let v_set = (acc * t).min(20.0 * REV);
        let mut inp = input(ControlEntry::Velocity, &plant);
        inp.velocity_inc_per_s = v_set;
        let out = cascade.cycle(&inp, DT_NS);
        plant.step(out.torque_nm, DT_NS);
        assert!(!out.torque_limited, "ramp needs far less than the torque limit");
        if k > 160 {
            worst = worst.max((v_set - plant.velocity_inc_per_s()).abs());
        }
    }
    assert!(worst < 0.2 * REV, "velocity error {} rev/s", worst / REV);
    let end = (20.0 * REV - plant.velocity_inc_per_s()).abs();
    assert!(end < 0.01 * REV, "final velocity error {} rev/s", end / REV);
}

#[test]
fn c035_velocity_feedforward_weight_i25_reduces_lag() {
    // C-118/C-120: with I25 = 100 % a constant-velocity track has a
    // smaller following error than with I25 = 0 %.
    let lag = |percent: f32| {
        let mut plant = Plant::new();
        let mut cfg = CascadeConfig::DEFAULT;
        cfg.velocity_feedforward_percent = percent;
        let mut cascade = Cascade::new(cfg, 0).unwrap();
        let v = 5.0 * REV;
        let mut last = 0;
        for k in 0..1600u32 {
            let t = (k + 1) as f64 * f64::from(DT_NS) * 1e-9;
            let mut inp = input(ControlEntry::Position, &plant);
            inp.position_setpoint_inc = (f64::from(v) * t).round() as i32;
            inp.velocity_inc_per_s = v;
            let out = cascade.cycle(&inp, DT_NS);
            plant.step(out.torque_nm, DT_NS);
            last = out.following_error_inc;
        }
        last.abs()
    };
    let with = lag(100.0);
    let without = lag(0.0);
    assert!(with * 10 < without, "I25 100 %: {with} inc, 0 %: {without} inc");
}

#[test]
fn c039_torque_clamps_at_the_limits_and_reports_internal_limit() {
    let mut cfg = CascadeConfig::DEFAULT;
    cfg.torque_limit_positive_nm = 1.0;
    cfg.torque_limit_negative_nm = 0.5;
    let mut plant = Plant::new();
    let mut cascade = Cascade::new(cfg, 0).unwrap();
    // A step of 1/20 revolution forward, then back: the velocity command
    // (Kv·e ≈ 5 rev/s) asks for more torque than either limit allows.
    let step = INCREMENTS_PER_REVOLUTION as i32 / 20;
    for (target, limit) in [(step, 1.0f32), (0, -0.5f32)] {
        let start = plant.position_inc();
        let mut saw_limit = false;
        let mut overshoot = 0;
        for _ in 0..2400 {
            let mut inp = input(ControlEntry::Position, &plant);
            inp.position_setpoint_inc = target;
            let out = cascade.cycle(&inp, DT_NS);
            assert!(
                out.torque_nm <= 1.0 && out.torque_nm >= -0.5,
                "torque {}",
                out.torque_nm
            );
            assert_eq!(out.internal_limit, out.torque_limited || out.velocity_limited);
            saw_limit |= out.torque_limited && out.internal_limit && out.torque_nm == limit;
            plant.step(out.torque_nm, DT_NS);
            let beyond = if target > start {
                plant.position_inc() - target
            } else {
                target - plant.position_inc()
            };
            overshoot = overshoot.max(beyond);
        }
        assert!(saw_limit, "the torque never clamped at {limit} N·m");
        // Anti-windup: the saturated start does not wind the integral up
        // into a large overshoot.
        assert!(overshoot < step / 10, "overshoot {overshoot} inc");
        assert!((plant.position_inc() - target).abs() < 20);
        assert!(cascade.integral_nm().abs() < 0.05);
    }
}

#[test]
fn c039_anti_windup_limits_overshoot_after_long_saturation() {
    // csv step to 20 rev/s with only 0.2 N·m: ≈ 60 ms at the torque
    // limit. Without anti-windup the integral would grow to tens of N·m
    // and the velocity would overshoot by several rev/s.
    let mut cfg = CascadeConfig::DEFAULT;
    cfg.torque_limit_positive_nm = 0.2;
    cfg.torque_limit_negative_nm = 0.2;
    let mut plant = Plant::new();
    let mut cascade = Cascade::new(cfg, 0).unwrap();
    let v_set = 20.0 * REV;
    let mut limited_cycles = 0;
    let mut peak = 0.0f32;
    for _ in 0..4000 {
        let mut inp = input(ControlEntry::Velocity, &plant);
        inp.velocity_inc_per_s = v_set;
        let out = cascade.cycle(&inp, DT_NS);
        if out.torque_limited {
            limited_cycles += 1;
            assert!(out.internal_limit);
        }
        assert!(cascade.integral_nm().abs() <= 0.2);
        plant.step(out.torque_nm, DT_NS);
        peak = peak.max(plant.velocity_inc_per_s());
    }
    assert!(limited_cycles > 400, "saturated for {limited_cycles} cycles");
    assert!(peak < 21.0 * REV, "peak {} rev/s", peak / REV);
    assert!((plant.velocity_inc_per_s() - v_set).abs() < 0.05 * REV);
}

#[test]
fn c039_cst_with_zero_velocity_limit_does_not_move() {
    let mut plant = Plant::new();
    let mut cascade = Cascade::new(CascadeConfig::DEFAULT, 0).unwrap();
    let mut limited = false;
    for _ in 0..4000 {
        let mut inp = input(ControlEntry::Torque, &plant);
        inp.torque_nm = 0.5;
        let out = cascade.cycle(&inp, DT_NS);
        limited |= out.speed_limited && out.internal_limit;
        plant.step(out.torque_nm, DT_NS);
    }
    assert!(limited);
    // Less than 1/100 revolution in 0.5 s with 0.5 N·m commanded (free
    // run would be ≈ 300 revolutions).
    assert!(plant.position_inc().abs() < INCREMENTS_PER_REVOLUTION as i32 / 100);
    assert!(plant.velocity_inc_per_s().abs() < 0.01 * REV);
}

#[test]
fn c039_cst_speed_limiter_caps_velocity() {
    let mut cfg = CascadeConfig::DEFAULT;
    cfg.torque_mode_velocity_limit_positive_inc_per_s = 5.0 * REV;
    cfg.torque_mode_velocity_limit_negative_inc_per_s = 2.0 * REV;
    let mut plant = Plant::new();
    let mut cascade = Cascade::new(cfg, 0).unwrap();
    let mut max_v = 0.0f32;
    let mut out = None;
    for _ in 0..4000 {
        let mut inp = input(ControlEntry::Torque, &plant);
        inp.torque_nm = 0.5;
        let o = cascade.cycle(&inp, DT_NS);
        plant.step(o.torque_nm, DT_NS);
        max_v = max_v.max(plant.velocity_inc_per_s());
        out = Some(o);
    }
    let v = plant.velocity_inc_per_s();
    assert!(max_v < 5.1 * REV, "peak {} rev/s", max_v / REV);
    assert!(v > 4.5 * REV, "speed {} rev/s", v / REV);
    assert!(out.unwrap().speed_limited && out.unwrap().internal_limit);
    // Negative direction: capped at the (different) negative limit.
    for _ in 0..8000 {
        let mut inp = input(ControlEntry::Torque, &plant);
        inp.torque_nm = -0.5;
        let o = cascade.cycle(&inp, DT_NS);
        plant.step(o.torque_nm, DT_NS);
    }
    let v = plant.velocity_inc_per_s();
    assert!(v < -1.8 * REV && v > -2.05 * REV, "speed {} rev/s", v / REV);
}

#[test]
fn c038_cst_below_the_speed_limit_passes_the_torque_through() {
    let mut cfg = CascadeConfig::DEFAULT;
    cfg.torque_mode_velocity_limit_positive_inc_per_s = 50.0 * REV;
    cfg.torque_mode_velocity_limit_negative_inc_per_s = 50.0 * REV;
    cfg.torque_limit_positive_nm = 1.0;
    let mut cascade = Cascade::new(cfg, 0).unwrap();
    let mut inp = CascadeInput {
        entry: ControlEntry::Torque,
        position_setpoint_inc: 0,
        velocity_inc_per_s: 0.0,
        acceleration_feedforward_inc_per_s2: 0.0,
        torque_nm: 0.3,
        actual_position_inc: 0,
        actual_velocity_inc_per_s: Some(0.0),
    };
    let out = cascade.cycle(&inp, DT_NS);
    assert_eq!(out.torque_nm, 0.3);
    assert!(!out.internal_limit);
    inp.torque_nm = 2.0;
    let out = cascade.cycle(&inp, DT_NS);
    assert_eq!(out.torque_nm, 1.0);
    assert!(out.torque_limited && out.internal_limit);
}

#[test]
fn differentiating_filter_estimates_velocity() {
    let mut cascade = Cascade::new(CascadeConfig::DEFAULT, 0).unwrap();
    let v = 10.0 * REV;
    let mut est = 0.0;
    for k in 1..=200u32 {
        let p = (f64::from(v) * f64::from(k) * 125e-6).round() as i64 as i32;
        let inp = CascadeInput {
            entry: ControlEntry::Velocity,
            position_setpoint_inc: 0,
            velocity_inc_per_s: v,
            acceleration_feedforward_inc_per_s2: 0.0,
            torque_nm: 0.0,
            actual_position_inc: p,
            actual_velocity_inc_per_s: None,
        };
        est = cascade.cycle(&inp, DT_NS).actual_velocity_inc_per_s;
    }
    assert!((est - v).abs() < 0.001 * v, "estimate {est}");
}

/// E-140 B44 (issue 35), what its results feed: the friction feedforward Fc·s(v_ref) + B·v_ref, s smoothed
/// over ±[`FRICTION_BAND_INC_PER_S`] (0 at standstill: no chatter), and the
/// acceleration derived from the change of the velocity feedforward (from
/// the third cycle after a reset) when the generator gives none.
#[test]
fn e140_b44_friction_feedforward_and_derived_acceleration() {
    let cfg = CascadeConfig {
        coulomb_friction_nm: 0.02,
        viscous_friction_nm_per_rad_per_s: 2e-5,
        ..CascadeConfig::DEFAULT
    };
    assert_eq!(friction_feedforward(&cfg, 0.0), 0.0);
    let half = friction_feedforward(&cfg, 0.5 * FRICTION_BAND_INC_PER_S);
    assert!((half - 0.01).abs() < 1e-4, "{half}");
    let v = 10.0 * REV;
    let full = friction_feedforward(&cfg, -v);
    let expect = -0.02 - 2e-5 * v * RAD_PER_INCREMENT;
    assert!((full - expect).abs() < 1e-6, "{full} {expect}");
    assert_eq!(friction_feedforward(&cfg, f32::NAN), 0.0);

    // with the inertia and derive_acceleration: a constant velocity
    // feedforward gives no acceleration torque, a ramp of 1000 rev/s² gives
    // J·a (Kp = 0, Ti = 0: the feedforward alone)
    let cfg = CascadeConfig {
        inertia_kg_m2: 1e-4,
        derive_acceleration: true,
        velocity_gain_nm_per_rad_per_s: 0.0,
        velocity_integral_time_ns: 0,
        ..CascadeConfig::DEFAULT
    };
    let mut c = Cascade::new(cfg, 0).unwrap();
    let dt = 1_000_000;
    let mut torque = [0.0f32; 6];
    for (k, t) in torque.iter_mut().enumerate() {
        let v = if k < 3 { 0.0 } else { (k - 2) as f32 * REV };
        let input = CascadeInput {
            entry: ControlEntry::Velocity,
            position_setpoint_inc: 0,
            velocity_inc_per_s: v,
            acceleration_feedforward_inc_per_s2: 0.0,
            torque_nm: 0.0,
            actual_position_inc: 0,
            actual_velocity_inc_per_s: Some(0.0),
        };
        *t = c.cycle(&input, dt).torque_nm;
    }
    let ja = 1e-4 * 1000.0 * core::f32::consts::TAU;
    assert_eq!(&torque[..3], &[0.0; 3]);
    for t in &torque[3..] {
        assert!((t - ja).abs() < 1e-4, "{torque:?}");
    }
    // after a reset the first two cycles take no difference (the enable's jump)
    c.reset(0);
    let input = CascadeInput {
        entry: ControlEntry::Velocity,
        position_setpoint_inc: 0,
        velocity_inc_per_s: 100.0 * REV,
        acceleration_feedforward_inc_per_s2: 0.0,
        torque_nm: 0.0,
        actual_position_inc: 0,
        actual_velocity_inc_per_s: Some(0.0),
    };
    assert_eq!(c.cycle(&input, dt).torque_nm, 0.0);
    assert_eq!(c.cycle(&input, dt).torque_nm, 0.0);
}

/// C-037 with identified mechanics (`compensate_velocity_lag`, issue 35):
/// the speed controller compares with the measured speed advanced by its
/// lag under the given acceleration, τ·a through a first-order lag of τ
/// (half a cycle plus the velocity filter). At a measured speed equal to
/// the command the proportional part is −Kp·τ·a once the acceleration has
/// held; when it ends the allowance decays over the following cycles (the
/// measurement catching up) instead of vanishing at once; a derived
/// acceleration (csp: none given) gets none.
#[test]
fn c037_velocity_lag_allowance_follows_the_given_acceleration_and_decays() {
    let cfg = CascadeConfig {
        velocity_integral_time_ns: 0,
        compensate_velocity_lag: true,
        ..CascadeConfig::DEFAULT
    };
    let mut c = Cascade::new(cfg, 0).unwrap();
    let v = 0.0;
    let at = |a: f32| CascadeInput {
        entry: ControlEntry::Velocity,
        position_setpoint_inc: 0,
        velocity_inc_per_s: v,
        acceleration_feedforward_inc_per_s2: a,
        torque_nm: 0.0,
        actual_position_inc: 0,
        actual_velocity_inc_per_s: Some(v),
    };
    let a = 50.0 * REV;
    let mut held = 0.0;
    for _ in 0..200 {
        held = c.cycle(&at(a), DT_NS).torque_nm;
    }
    let tau = 0.5 * DT_NS as f32 * 1e-9 + cfg.velocity_filter_time_ns as f32 * 1e-9;
    let want = -cfg.velocity_gain_nm_per_rad_per_s * tau * a * RAD_PER_INCREMENT;
    assert!((held - want).abs() <= 0.02 * want.abs(), "{held} vs {want}");
    let mut after = [0.0f32; 40];
    for t in after.iter_mut() {
        *t = c.cycle(&at(0.0), DT_NS).torque_nm;
    }
    assert!(
        want < 0.0 && after[0] <= 0.5 * want,
        "decays, not gone at once: {after:?}"
    );
    assert!(after.windows(2).all(|w| w[1] >= w[0]), "monotonic: {after:?}");
    assert!(after[39].abs() < 0.01 * want.abs(), "caught up: {after:?}");
    // no given acceleration: no allowance (the csp path)
    let mut fresh = Cascade::new(cfg, 0).unwrap();
    assert_eq!(fresh.cycle(&at(0.0), DT_NS).torque_nm, 0.0);
}
