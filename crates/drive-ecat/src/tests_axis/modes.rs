//! The operating modes: csp along a master trajectory (with and without acceleration
//! feed-forward), csv, cst and its default speed limit, pp moves and jog (C-035 … C-048, C-088).

use super::*;

/// A master trajectory at 1 ms: 100 ms at 20 rev/s² to 2 rev/s, 300 ms
/// at 2 rev/s, 100 ms braking; increments at cycle `k`.
fn trajectory(k: i64) -> i64 {
    let a = 20.0 * REV_I as f64; // inc/s²
    let t = k as f64 * 1e-3;
    let x = if t < 0.1 {
        0.5 * a * t * t
    } else if t < 0.4 {
        0.5 * a * 0.01 + 0.1 * a * (t - 0.1)
    } else if t < 0.5 {
        let u = t - 0.4;
        0.5 * a * 0.01 + 0.1 * a * 0.3 + 2.0 * REV_I as f64 * u - 0.5 * a * u * u
    } else {
        0.5 * a * 0.01 + 0.1 * a * 0.3 + 0.5 * a * 0.01
    };
    x as i64
}

/// Axis A (enabled in csp) sent the 500 cycles of [`trajectory`], `each`
/// after every cycle; the largest following error 60F4h seen, inc.
fn follow_trajectory(rig: &mut Rig, mut each: impl FnMut(&Rig)) -> i64 {
    let mut max_fe = 0i64;
    for k in 1..=500 {
        rig.set(0, 0x607A, 0, trajectory(k));
        rig.cycle();
        max_fe = max_fe.max(rig.get(0, 0x60F4, 0).abs());
        each(rig);
    }
    max_fe
}

#[test]
fn c035_csp_follows_target_position() {
    let mut rig = Rig::new();
    rig.enable(0);
    // bit 12: the drive follows the set position
    let max_fe = follow_trajectory(&mut rig, |r| assert_ne!(r.sw(0) & SW_MODE_BIT12, 0));
    // ≈ 1° at most on 20 rev/s² without acceleration feedforward
    assert!(max_fe < REV_I / 360, "max following error {max_fe} inc");
    let target = trajectory(500);
    assert!((target - 4 * REV_I / 5).abs() <= 1, "0.8 rev: {target}");
    rig.run(200);
    let pos = i64::from(rig.position(0));
    assert!((pos - target).abs() < 100, "stopped at {pos}, target {target}");
    assert!(rig.velocity(0).abs() < 5000);
    assert!((i64::from(rig.motors[0].position_inc()) - target).abs() < 100);
    assert_eq!(rig.sw(0) & SW_MODE_BIT13, 0, "no following error bit");
}

#[test]
fn c035_csp_with_acceleration_feedforward_tracks_closely() {
    let mut rig = Rig::new();
    rig.drive.axes_mut()[0].params_mut().cascade.inertia_kg_m2 = 1e-4;
    // I425 = 4: quadratic, internal feedforward (acceleration from ∇²),
    // written as a master does (issue 40)
    rig.set(0, crate::params::I425, 0, 4);
    rig.enable(0);
    let max_fe = follow_trajectory(&mut rig, |_| {});
    // a third of the error without it
    assert!(max_fe < REV_I / 1000, "max following error {max_fe} inc");
}

#[test]
fn c037_csv_velocity_reached() {
    let mut rig = Rig::new();
    rig.set(0, 0x6060, 0, 9);
    rig.enable(0);
    assert_eq!(rig.get(0, 0x6061, 0), 9);
    let v = 5 * REV_I;
    rig.set(0, 0x60FF, 0, v);
    rig.run(300);
    let actual = i64::from(rig.velocity(0));
    assert!((actual - v).abs() < v / 100, "velocity {actual}, set {v}");
    assert!((rig.motors[0].velocity_inc_per_s() - v as f64).abs() < v as f64 / 100.0);
    assert_ne!(rig.sw(0) & SW_MODE_BIT12, 0);
}

#[test]
fn c038_cst_torque_produced() {
    let mut rig = Rig::new();
    // G472/G475: let the axis run up to 40 % of I10 (20 rev/s) in the torque modes
    rig.set(0, crate::params::G472, 0, 400);
    rig.set(0, crate::params::G475, 0, 400);
    rig.set(0, 0x6060, 0, 10);
    rig.enable(0);
    rig.set(0, 0x6071, 0, 100); // 10 % of 1.3 N·m
    rig.run(5);
    assert!(
        (rig.commands[0].torque_nm - 0.13).abs() < 1e-4,
        "{}",
        rig.commands[0].torque_nm
    );
    assert_eq!(rig.get(0, 0x6077, 0), 100);
    assert_eq!(rig.get(0, 0x6076, 0), 1300, "rated torque in mN·m");
    rig.run(20);
    // 0.13 N·m on 1e-4 kg·m²: about 1300 rad/s² → positive velocity
    assert!(rig.velocity(0) > REV_I as i32, "velocity {}", rig.velocity(0));
    assert_ne!(rig.sw(0) & SW_MODE_BIT12, 0);
}

#[test]
fn c039_cst_default_speed_limit_keeps_the_axis_still() {
    let mut rig = Rig::new();
    rig.set(0, 0x6060, 0, 10);
    rig.enable(0);
    rig.set(0, 0x6071, 0, 500);
    rig.run(200);
    assert!(
        rig.velocity(0).abs() < REV_I as i32 / 10,
        "velocity {}",
        rig.velocity(0)
    );
    // the speed limiter is an internal limit (bit 11)
    assert_ne!(rig.sw(0) & SW_INTERNAL_LIMIT, 0);
    // a raised G472 lets the same torque move the axis, up to G472 · I10
    // (the refusal of a value beyond 100 % is checked through SOEM)
    rig.set(0, crate::params::G472, 0, 100); // 10 % of 50 rev/s
    rig.run(400);
    let limit = 5 * REV_I as i32;
    assert!(
        (rig.velocity(0) - limit).abs() < limit / 50,
        "velocity {} at the limit {limit}",
        rig.velocity(0)
    );
    assert_ne!(rig.sw(0) & SW_INTERNAL_LIMIT, 0);
}

#[test]
fn c041_c048_pp_move_sets_target_reached() {
    let mut rig = Rig::new();
    rig.enable(0);
    // C-050: an absolute move is refused before referencing
    rig.set(0, 0x6060, 0, 1);
    rig.set(0, 0x607A, 0, 5 * REV_I);
    rig.run(3);
    assert_eq!(rig.get(0, 0x6061, 0), 1);
    rig.controlword(0, 0x1F);
    rig.run(20);
    assert_eq!(rig.sw(0) & SW_MODE_BIT12, 0, "no acknowledge unreferenced");
    assert!(rig.position(0).abs() < 100);

    rig.controlword(0, 0x0F);
    home_here(&mut rig, 0, 0);
    rig.set(0, 0x6060, 0, 1);
    rig.run(3);
    // a steady bit 4 starts nothing; the edge does (C-041)
    rig.controlword(0, 0x1F);
    rig.run(2);
    assert_ne!(rig.sw(0) & SW_MODE_BIT12, 0, "set-point acknowledge (C-042)");
    assert_eq!(rig.sw(0) & SW_TARGET_REACHED, 0);
    rig.controlword(0, 0x0F);
    rig.run(1);
    assert_eq!(rig.sw(0) & SW_MODE_BIT12, 0, "acknowledge follows bit 4");
    let n = rig.run_until(3000, |r| r.sw(0) & SW_TARGET_REACHED != 0);
    // 5 rev at 10 rev/s with 100 rev/s² ramps: ≈ 0.6 s
    assert!((500..1000).contains(&n), "took {n} cycles");
    let pos = i64::from(rig.position(0));
    assert!((pos - 5 * REV_I).abs() <= i64::from(INCREMENTS_PER_REVOLUTION / 360));
    assert_eq!(rig.sw(0) & SW_MODE_BIT13, 0);
}

#[test]
fn c046_pp_relative_move_is_additive() {
    let mut rig = Rig::new();
    rig.enable(0);
    rig.set(0, 0x6060, 0, 1);
    rig.run(3);
    // relative moves need no reference
    rig.set(0, 0x607A, 0, REV_I);
    rig.controlword(0, 0x5F);
    rig.run(2);
    rig.controlword(0, 0x4F);
    rig.run_until(2000, |r| r.sw(0) & SW_TARGET_REACHED != 0);
    rig.controlword(0, 0x5F);
    rig.run(2);
    rig.controlword(0, 0x4F);
    rig.run(2);
    rig.run_until(2000, |r| r.sw(0) & SW_TARGET_REACHED != 0);
    assert!((i64::from(rig.position(0)) - 2 * REV_I).abs() < 3000);
}

#[test]
fn c088_jog_positive_and_stop() {
    let mut rig = Rig::new();
    rig.set(0, 0x6060, 0, -1);
    rig.enable(0);
    rig.controlword(0, 0x1F);
    rig.run(300);
    let v = rig.velocity(0);
    assert!((i64::from(v) - REV_I).abs() < REV_I / 20, "jog velocity {v}");
    rig.controlword(0, 0x0F);
    rig.run(300);
    assert!(rig.velocity(0).abs() < REV_I as i32 / 100);
}
