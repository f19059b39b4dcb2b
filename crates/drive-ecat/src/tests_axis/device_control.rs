//! Device control: the enable sequence and what refuses or ends it (A60, A44), quick stop, the
//! following-error fault, missing set-points, mode changes at standstill and the hardware limit
//! switches (C-003, C-010, C-011, C-018, C-027, C-036, C-094, C-095, C-117).

use super::*;

#[test]
fn c018_enable_sequence_reaches_operation_enabled() {
    let mut rig = Rig::new();
    rig.run(2);
    // T1 on its own, statusword 0x0040 pattern, E48 = 1
    assert_eq!(rig.sw(0) & 0x4F, 0x40);
    assert_eq!(rig.get(0, E48, 0), 1);
    assert!(!rig.commands[0].power_stage);
    rig.enable(0);
    assert_eq!(rig.state(0), State::OperationEnabled);
    assert_eq!(rig.sw(0) & 0x6F, 0x0027);
    // voltage enabled (bit 4) and remote (bit 9)
    assert_ne!(rig.sw(0) & (1 << 4), 0);
    assert_ne!(rig.sw(0) & (1 << 9), 0);
    assert_eq!(rig.get(0, E48, 0), 4);
    assert_eq!(rig.get(0, 0x6061, 0), 8, "csp is the default mode (C-026)");
    assert!(rig.commands[0].power_stage);
    // csp: the brake opens on the active cyclic command (C-021)
    assert!(rig.commands[0].brake_release);
    // holding still: no drift
    rig.run(100);
    assert!(rig.position(0).abs() < 50, "drifted to {}", rig.position(0));
}

#[test]
fn c003_enable_refused_without_additional_enable() {
    let mut rig = Rig::new();
    rig.io[0].additional_enable = false;
    rig.run(2);
    rig.controlword(0, 0x06);
    rig.run(3);
    assert_eq!(rig.state(0), State::SwitchOnDisabled);
    rig.io[0].additional_enable = true;
    rig.run(2);
    assert_eq!(rig.state(0), State::ReadyToSwitchOn);
}

/// A44 (issue 40, spec cia402.md transitions 9 and 11): losing A60 in
/// Operation enabled switches the power stage off with A44 = 0 (the
/// default) and quick-stops with A44 = 1, set in the dictionary.
#[test]
fn c003_a44_decides_what_losing_a60_does() {
    for (a44, want) in [(0, State::SwitchOnDisabled), (1, State::QuickStopActive)] {
        let mut rig = Rig::new();
        rig.set(0, crate::params::A44, 0, a44);
        rig.enable(0);
        rig.io[0].additional_enable = false;
        rig.run(2);
        assert_eq!(rig.state(0), want, "A44 = {a44}");
    }
}

#[test]
fn c010_c011_quick_stop_to_standstill_then_switch_on_disabled() {
    let mut rig = Rig::new();
    rig.set(0, 0x6060, 0, 9);
    rig.set(0, 0x6085, 0, 50 * REV_I); // 50 rev/s²
    rig.enable(0);
    rig.set(0, 0x60FF, 0, 5 * REV_I);
    rig.run(300);
    assert!(rig.velocity(0) > 4 * REV_I as i32);
    rig.controlword(0, 0x0B); // bit 2 = 0: quick stop
    rig.run(2);
    assert_eq!(rig.state(0), State::QuickStopActive);
    assert_eq!(rig.sw(0) & 0x6F, 0x0007);
    assert_eq!(rig.get(0, E48, 0), 7);
    // 5 rev/s at 50 rev/s²: 100 ms
    let n = rig.run_until(400, |r| r.state(0) == State::SwitchOnDisabled);
    assert!((80..200).contains(&n), "quick stop took {n} cycles");
    assert!(rig.motors[0].velocity_inc_per_s().abs() < 0.1 * REV_I as f64);
    assert!(!rig.commands[0].power_stage);
    // no return to Operation enabled (no T16)
    rig.controlword(0, 0x0F);
    rig.run(3);
    assert_eq!(rig.state(0), State::SwitchOnDisabled);
}

#[test]
fn c036_following_error_fault_goes_to_fault_and_queues_emcy() {
    let mut rig = Rig::new();
    // I470 = 1: a following error is a fault
    rig.set(0, crate::params::I470, 0, 1);
    rig.set(0, 0x6065, 0, 1000);
    rig.set(0, 0x6066, 0, 2);
    rig.enable(0);
    assert_eq!(rig.drive.slave().emergencies_pending(), 0);
    // block the motor and ask for a revolution
    rig.set(0, 0x607A, 0, REV_I / 10);
    rig.run_until(200, |r| r.state(0) == State::Fault);
    assert_eq!(rig.sw(0) & 0x4F, 0x08);
    assert_eq!(rig.get(0, E48, 0), 5);
    assert_eq!(rig.drive.slave().emergencies_pending(), 1);
    assert_eq!(rig.get(0, 0x603F, 0), 0x8611);
    assert_ne!(rig.drive.objects().get(0x1001, 0).unwrap(), 0);
    assert!(!rig.commands[0].power_stage);
    // T15: fault reset edge → Switch on disabled, "fault cleared" EMCY
    rig.controlword(0, 0x80);
    rig.run(2);
    assert_eq!(rig.state(0), State::SwitchOnDisabled);
    assert_eq!(rig.drive.slave().emergencies_pending(), 2);
    assert_eq!(rig.get(0, 0x603F, 0), 0);
    assert_eq!(rig.drive.objects().get(0x1001, 0).unwrap(), 0);
}

#[test]
fn c117_missing_setpoints_extrapolate_then_fault() {
    let mut rig = Rig::new();
    rig.enable(0);
    let step = REV_I / 1000;
    for k in 1..=50 {
        rig.set(0, 0x607A, 0, k * step);
        rig.cycle();
    }
    // the master stops sending: extrapolation with the last increment (C-116)
    rig.new_setpoint = Some([false, true]);
    let p0 = rig.position(0);
    rig.run(5);
    assert!(rig.position(0) - p0 > 3 * step as i32, "keeps moving");
    assert_ne!(rig.state(0), State::Fault);
    // beyond I423 (10 ms): event 78 cause 3 → Fault
    rig.run_until(20, |r| r.state(0).is_fault());
    rig.run_until(500, |r| r.state(0) == State::Fault);
    assert_eq!(rig.get(0, 0x603F, 0), 0x8612);
}

#[test]
fn c027_mode_change_between_classes_waits_for_standstill() {
    let mut rig = Rig::new();
    rig.set(0, 0x6060, 0, 9);
    rig.enable(0);
    rig.set(0, 0x60FF, 0, 2 * REV_I);
    rig.run(100);
    rig.set(0, 0x6060, 0, 3); // pv: drive-based
    rig.run(5);
    assert_eq!(rig.get(0, 0x6061, 0), 9, "moving: csv stays");
    rig.set(0, 0x60FF, 0, 0);
    rig.run_until(300, |r| r.get(0, 0x6061, 0) == 3);
    // pv then runs on its own profile
    rig.set(0, 0x60FF, 0, REV_I);
    rig.run_until(500, |r| r.sw(0) & SW_TARGET_REACHED != 0);
    rig.run(200);
    assert!(
        (i64::from(rig.velocity(0)) - REV_I).abs() < REV_I / 50,
        "{}",
        rig.velocity(0)
    );
}

#[test]
fn c094_c095_hardware_limit_switch_faults_and_locks_the_direction() {
    let mut rig = Rig::new();
    // I101 = 1: +LS from its input
    rig.set(0, crate::params::I101, 0, 1);
    rig.set(0, 0x6060, 0, 9);
    rig.enable(0);
    rig.set(0, 0x60FF, 0, REV_I);
    rig.run(100);
    rig.io[0].limit_positive = true;
    rig.run_until(200, |r| r.state(0) == State::Fault);
    assert_eq!(rig.get(0, 0x603F, 0), 0x8500, "event 53");
    assert_eq!(rig.drive.slave().emergencies_pending(), 1);
    // acknowledge, enable again: positive motion refused, negative allowed
    rig.controlword(0, 0x80);
    rig.run(2);
    rig.enable(0);
    rig.run(100);
    assert!(
        rig.velocity(0).abs() < REV_I as i32 / 100,
        "locked: {}",
        rig.velocity(0)
    );
    assert_ne!(
        rig.sw(0) & SW_INTERNAL_LIMIT,
        0,
        "direction lock shows as internal limit"
    );
    rig.set(0, 0x60FF, 0, -REV_I);
    rig.run(200);
    assert!(rig.velocity(0) < -(REV_I as i32) / 2);
    assert_eq!(rig.state(0), State::OperationEnabled);
}
