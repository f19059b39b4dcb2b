//! Configuration and robustness: axis B independent of axis A (C-134), polarity (C-110), invalid
//! cycle settings falling back (C-144), arbitrary object values, and the axis's memory footprint.

use super::*;

#[test]
fn c134_axis_b_is_independent_of_axis_a() {
    let mut rig = Rig::new();
    rig.enable(1);
    assert_eq!(rig.state(1), State::OperationEnabled);
    assert_eq!(rig.state(0), State::SwitchOnDisabled);
    assert_eq!(rig.get(1, E48, 0), 4);
    assert_eq!(rig.get(0, E48, 0), 1);
    let mut target = 0;
    for _ in 0..200 {
        target += REV_I / 1000;
        rig.set(1, 0x607A, 0, target);
        rig.cycle();
    }
    rig.run(400);
    assert!(
        (i64::from(rig.position(1)) - target).abs() < 20,
        "{} vs {target}",
        rig.position(1)
    );
    assert_eq!(rig.position(0), 0);
    assert!(!rig.commands[0].power_stage);
    assert!(rig.commands[1].power_stage);
    // a fault on B leaves A alone
    rig.enable(0);
    rig.drive.axes_mut()[1].raise_event(Event { number: 54, cause: 1 });
    rig.run_until(100, |r| r.state(1) == State::Fault);
    assert_eq!(rig.state(0), State::OperationEnabled);
    assert_eq!(rig.get(1, 0x603F, 0), 0x8611);
    assert_eq!(rig.get(0, 0x603F, 0), 0);
}

#[test]
fn c110_polarity_inverts_position_and_torque() {
    let mut rig = Rig::new();
    rig.set(0, 0x607E, 0, 0x80);
    rig.set(0, 0x6060, 0, 9);
    rig.motors[0].theta = TAU / 4.0; // +1/4 rev at the motor
    rig.run(2);
    assert!((rig.position(0) + (1 << 18)).abs() <= 1, "{}", rig.position(0));
    rig.enable(0);
    rig.set(0, 0x60FF, 0, REV_I);
    rig.run(200);
    assert!((i64::from(rig.velocity(0)) - REV_I).abs() < REV_I / 50);
    assert!(rig.motors[0].velocity_inc_per_s() < -0.9 * REV_I as f64);
}

#[test]
fn c144_invalid_cycle_settings_fall_back() {
    let mut rig = Rig::new();
    // 60C2h = 3 ms over A150 = 1 ms: N = 3, set-points every cycle are fine
    rig.set(0, 0x60C2, 1, 3);
    rig.enable(0);
    assert_eq!(
        rig.drive.objects().get(objects_a291(), 0).unwrap(),
        3000,
        "60C2h copied into A291 (C-114)"
    );
    for k in 1..=300 {
        rig.set(0, 0x607A, 0, k * 1000);
        rig.cycle();
    }
    rig.run(300);
    assert!((rig.position(0) - 300_000).abs() < 100, "{}", rig.position(0));
    // a period that is no multiple of A150 falls back to N = 1
    rig.set(0, 0x60C2, 1, 15);
    rig.set(0, 0x60C2, 2, -4);
    rig.run(5);
    assert_eq!(rig.state(0), State::OperationEnabled);
}

fn objects_a291() -> u16 {
    crate::parameter_index(0, 291)
}

/// Arbitrary values in every set-point and configuration object never
/// panic and never leave the statusword without a state pattern.
#[test]
fn arbitrary_object_values_do_not_panic() {
    let mut rig = Rig::new();
    rig.set(1, 0x6040, 0, 0x0F);
    // both limit switches evaluated (I101/I102 = 1, the inputs), a
    // following error a fault (I470 = 1)
    for axis in 0..2 {
        rig.set(axis, crate::params::I101, 0, 1);
        rig.set(axis, crate::params::I101 + 1, 0, 1);
        rig.set(axis, crate::params::I470, 0, 1);
    }
    let mut seed: u64 = 0x1234_5678_9ABC_DEF0;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let objects: &[(u16, u8)] = &[
        (0x6040, 0),
        (0x6060, 0),
        (0x607A, 0),
        (0x60FF, 0),
        (0x6071, 0),
        (0x60B1, 0),
        (0x60B2, 0),
        (0x6072, 0),
        (0x6081, 0),
        (0x6083, 0),
        (0x6084, 0),
        (0x6085, 0),
        (0x60A4, 1),
        (0x605A, 0),
        (0x605E, 0),
        (0x6065, 0),
        (0x607D, 1),
        (0x607D, 2),
        (0x607E, 0),
        (0x6098, 0),
        (0x6099, 1),
        (0x609A, 0),
        (0x60B8, 0),
        (0x60C1, 1),
        (0x60C2, 1),
        (0x60C2, 2),
        (0x6042, 0),
        (0x6087, 0),
        (0x60F2, 0),
    ];
    for _ in 0..3000 {
        let r = next();
        let (index, sub) = objects[(r % objects.len() as u64) as usize];
        let axis = (r >> 8) as usize % 2;
        // any value the type holds
        let _ = rig
            .drive
            .objects_mut()
            .set(Rig::index(axis, index), sub, (r >> 16) as i32 as i64);
        if r & 0x3000 == 0 {
            rig.io[axis].limit_positive ^= true;
        }
        if r & 0xC000 == 0 {
            rig.io[axis].limit_negative ^= true;
        }
        rig.cycle();
        for a in 0..2 {
            assert!(State::from_statusword(rig.sw(a)).is_some());
            assert!(rig.commands[a].torque_nm.is_finite());
        }
    }
}

#[test]
fn axis_memory_footprint() {
    extern crate std;
    std::println!("size_of::<Axis>() = {} bytes", core::mem::size_of::<Axis>());
    assert!(core::mem::size_of::<Axis>() < 4096);
}
