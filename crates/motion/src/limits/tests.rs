use super::*;

fn hw_config() -> LimitConfig {
    LimitConfig {
        positive_switch: true,
        negative_switch: true,
        ..LimitConfig::default()
    }
}

fn sw_config() -> LimitConfig {
    LimitConfig {
        software_min_inc: -10_000,
        software_max_inc: 10_000,
        window_inc: 100,
        ..LimitConfig::default()
    }
}

/// Low-active inputs: `true` = switch hit.
fn hw(actual: i32, pos_hit: bool, neg_hit: bool) -> LimitInput {
    LimitInput {
        actual_position_inc: actual,
        position_setpoint_inc: actual,
        positive_switch_signal: !pos_hit,
        negative_switch_signal: !neg_hit,
        referenced: true,
        referencing: false,
    }
}

fn at(actual: i32) -> LimitInput {
    hw(actual, false, false)
}

#[test]
fn c093_switches_without_source_are_ignored_and_low_active() {
    let mut l = Limits::new(LimitConfig::default(), 0);
    // Sources not set: both signals 0 mean nothing.
    let s = l.update(&hw(0, true, true));
    assert_eq!(s.event, None);
    assert!(!s.lock.any());
    // Sources set, signals high (NC contacts closed): no hit.
    let mut l = Limits::new(hw_config(), 0);
    let s = l.update(&hw(0, false, false));
    assert_eq!(s.event, None);
    assert!(!s.lock.any());
    // High-active configuration: a high signal is a hit.
    let mut l = Limits::new(
        LimitConfig {
            switch_polarity: SwitchPolarity::HighActive,
            ..hw_config()
        },
        0,
    );
    let mut input = at(0);
    input.positive_switch_signal = true;
    input.negative_switch_signal = false;
    assert_eq!(l.update(&input).event, Some(LimitCause::HardwarePositive.event()));
}

#[test]
fn c094_hardware_limit_positive_faults_on_the_edge() {
    let mut l = Limits::new(hw_config(), 0);
    assert_eq!(l.update(&at(900)).event, None);
    let s = l.update(&hw(1000, true, false));
    assert_eq!(s.event, Some(Event { number: 53, cause: 1 }));
    assert_eq!(
        s.stop,
        Some(StopRequest {
            ramp: StopRamp::FaultReaction,
            direction: Direction::Positive
        })
    );
    // Only once, while staying on the switch.
    let s = l.update(&hw(1050, true, false));
    assert_eq!(s.event, None);
    assert!(s.lock.positive && !s.lock.negative);
}

#[test]
fn c094_hardware_limit_negative_faults_on_the_edge() {
    let mut l = Limits::new(hw_config(), 0);
    l.update(&at(-900));
    let s = l.update(&hw(-1000, false, true));
    assert_eq!(s.event, Some(Event { number: 53, cause: 2 }));
    assert_eq!(s.denial, Some(DenialCause::HardwareNegative));
    assert_eq!(s.denial.unwrap().code(), 12);
}

#[test]
fn c095_hardware_limit_locks_direction_and_allows_moving_away() {
    let mut l = Limits::new(hw_config(), 0);
    l.update(&at(0));
    let s = l.update(&hw(1000, true, false));
    assert!(!s.lock.permits(Direction::Positive));
    assert!(s.lock.permits(Direction::Negative));
    assert_eq!(s.denial, Some(DenialCause::HardwarePositive));
    assert_eq!(s.denial.unwrap().code(), 11);
    assert_eq!(s.denial.unwrap().e80(), 20);
    assert_eq!(s.lock.filter_velocity(5000.0), 0.0);
    assert_eq!(s.lock.filter_velocity(-5000.0), -5000.0);
    assert_eq!(s.lock.filter_torque(1.0), 0.0);
    assert!(s.lock.refuses_move(1000, 2000));
    assert!(!s.lock.refuses_move(1000, 0));
    // Moving away, off the switch and behind the stored position: free,
    // and the fault can trigger again.
    let s = l.update(&at(990));
    assert!(!s.lock.any());
    assert_eq!(s.denial, None);
    let s = l.update(&hw(1000, true, false));
    assert_eq!(s.event, Some(LimitCause::HardwarePositive.event()));
}

#[test]
fn c096_both_switches_hit_is_cause_7_acknowledged_with_i52() {
    let mut l = Limits::new(hw_config(), 0);
    let s = l.update(&hw(0, true, true));
    assert_eq!(s.event, Some(Event { number: 53, cause: 7 }));
    assert!(s.lock.positive && s.lock.negative);
    assert_eq!(l.update(&hw(0, true, true)).event, None);
    // I52 only works once the signals are back.
    l.clear_switch_memory();
    assert!(l.update(&hw(0, true, true)).lock.positive);
    let s = l.update(&at(0));
    assert!(s.lock.positive, "latched until I52");
    assert!(l.clear_switch_memory());
    assert!(!l.update(&at(0)).lock.any());
}

#[test]
fn c097_passable_switch_clears_only_behind_the_stored_position() {
    // Cam 100 … 120, seen at 100, physically left at 101 on the way back.
    let mut l = Limits::new(hw_config(), 0);
    l.update(&at(99));
    let s = l.update(&hw(100, true, false));
    assert_eq!(s.event, Some(LimitCause::HardwarePositive.event()));
    assert_eq!(l.switch_memory().0, Some(100));
    // Overtravel across the cam: signal gone, still locked, no new fault.
    let s = l.update(&hw(110, true, false));
    assert!(s.lock.positive && s.event.is_none());
    let s = l.update(&at(125));
    assert!(s.lock.positive, "beyond the cam the memory keeps the lock");
    // Back through the cam: no new event.
    let s = l.update(&hw(115, true, false));
    assert_eq!(s.event, None);
    // Signal inactive at 101, but not yet behind 100.
    let s = l.update(&at(101));
    assert!(s.lock.positive);
    let s = l.update(&at(100));
    assert!(!s.lock.positive, "cleared at the stored position");
    assert_eq!(l.switch_memory().0, None);
}

#[test]
fn c098_switch_memory_cleared_by_i52_referencing_and_restart() {
    let mut l = Limits::new(hw_config(), 0);
    l.update(&at(0));
    l.update(&hw(100, true, false));
    l.update(&at(150));
    // I52 refused while the signal is active …
    l.update(&hw(150, true, false));
    assert!(!l.clear_switch_memory());
    // … accepted once it is inactive, even beyond the stored position.
    l.update(&at(150));
    assert!(l.clear_switch_memory());
    assert!(!l.update(&at(150)).lock.any());
    // Referencing clears it and ignores the switches.
    l.update(&hw(160, true, false));
    let mut input = hw(170, true, false);
    input.referencing = true;
    let s = l.update(&input);
    assert!(!s.lock.any() && s.event.is_none());
    assert_eq!(l.switch_memory(), (None, None));
    // Deleting the reference clears it too.
    l.update(&at(0));
    l.update(&hw(100, false, true));
    assert!(l.switch_memory().1.is_some());
    l.reference_changed(100);
    assert_eq!(l.switch_memory(), (None, None));
    // Restart: a new instance has no memory.
    assert_eq!(Limits::new(hw_config(), 0).switch_memory(), (None, None));
}

#[test]
fn c099_software_limits_only_when_referenced_and_limited() {
    let mut l = Limits::new(sw_config(), 0);
    let mut input = at(20_000);
    input.referenced = false;
    let s = l.update(&input);
    assert!(s.event.is_none() && !s.lock.any());
    input.referenced = true;
    input.referencing = true;
    let s = l.update(&input);
    assert!(s.event.is_none() && !s.lock.any());
    let mut l = Limits::new(
        LimitConfig {
            endless_axis: true,
            ..sw_config()
        },
        0,
    );
    let s = l.update(&at(20_000));
    assert!(s.event.is_none() && !s.lock.any());
}

#[test]
fn c100_software_limits_disabled_when_min_equals_max() {
    let mut l = Limits::new(
        LimitConfig {
            software_min_inc: 5000,
            software_max_inc: 5000,
            ..sw_config()
        },
        0,
    );
    for p in [-1_000_000, 0, 5000, 1_000_000] {
        let s = l.update(&at(p));
        assert!(s.event.is_none() && !s.lock.any(), "at {p}");
    }
}

#[test]
fn c101_software_limit_positive_fault_beyond_window() {
    let mut l = Limits::new(sw_config(), 0);
    let s = l.update(&at(10_050));
    assert!(s.event.is_none(), "within I22 beyond the limit: no fault");
    assert!(s.lock.positive);
    let s = l.update(&at(10_101));
    assert_eq!(s.event, Some(Event { number: 53, cause: 3 }));
    assert_eq!(s.stop.unwrap().ramp, StopRamp::FaultReaction);
    assert_eq!(l.update(&at(10_200)).event, None, "only once");
}

#[test]
fn c101_software_limit_negative_fault_beyond_window() {
    let mut l = Limits::new(sw_config(), 0);
    assert!(l.update(&at(-10_100)).event.is_none());
    let s = l.update(&at(-10_101));
    assert_eq!(s.event, Some(Event { number: 53, cause: 4 }));
    assert_eq!(s.denial, Some(DenialCause::SoftwareNegative));
}

#[test]
fn c102_software_limit_blocks_positive_direction() {
    let mut l = Limits::new(sw_config(), 0);
    assert!(!l.update(&at(10_000)).lock.any(), "at the limit: not yet beyond");
    let s = l.update(&at(10_001));
    assert!(!s.lock.permits(Direction::Positive));
    assert!(s.lock.permits(Direction::Negative));
    assert_eq!(s.denial, Some(DenialCause::SoftwarePositive));
    assert_eq!(s.denial.unwrap().code(), 2);
    assert!(s.lock.refuses_move(10_001, 10_002));
    assert!(!s.lock.refuses_move(10_001, 0));
}

#[test]
fn c103_software_lock_releases_with_hysteresis() {
    let mut l = Limits::new(sw_config(), 0);
    assert!(l.update(&at(10_001)).lock.positive);
    assert!(l.update(&at(9_950)).lock.positive, "inside, but not by I22");
    assert!(l.update(&at(9_900)).lock.positive, "exactly limit − I22");
    assert!(!l.update(&at(9_899)).lock.positive);
    assert!(l.update(&at(-10_001)).lock.negative);
    assert!(l.update(&at(-9_900)).lock.negative);
    assert!(!l.update(&at(-9_899)).lock.negative);
}

#[test]
fn c091_jog_velocity_control_quick_stops_at_software_limit() {
    let mut l = Limits::new(
        LimitConfig {
            soft_limit_reaction: SoftLimitReaction::QuickStop,
            ..sw_config()
        },
        0,
    );
    let s = l.update(&at(10_001));
    assert_eq!(
        s.stop,
        Some(StopRequest {
            ramp: StopRamp::QuickStop,
            direction: Direction::Positive
        })
    );
    assert_eq!(s.event, None);
    assert!(s.lock.positive);
    // Stops a little past the limit: no fault even beyond I22.
    let s = l.update(&at(10_500));
    assert_eq!(s.event, None);
    assert_eq!(s.stop, None);
    assert!(s.lock.positive);
}

#[test]
fn c092_jog_position_control_target_clamped_to_limits() {
    let l = Limits::new(sw_config(), 0);
    assert_eq!(l.clamp_target(50_000, true), 10_000);
    assert_eq!(l.clamp_target(-50_000, true), -10_000);
    assert_eq!(l.clamp_target(500, true), 500);
    assert_eq!(l.clamp_target(50_000, false), 50_000);
}

#[test]
fn c105_endless_axis_permitted_direction() {
    let mut l = Limits::new(
        LimitConfig {
            endless_axis: true,
            permitted_direction: PermittedDirection::PositiveOnly,
            ..sw_config()
        },
        0,
    );
    let s = l.update(&at(1_000_000));
    assert!(s.lock.negative && !s.lock.positive);
    assert_eq!(s.denial, Some(DenialCause::IllegalDirection));
    assert_eq!(s.denial.unwrap().e80(), 15);
    assert_eq!(s.event, None);
}

#[test]
fn c106_computing_limit_trips_beyond_31_bits() {
    let mut l = Limits::new(LimitConfig::default(), 0);
    // Chained moves summing to i32::MAX: fine.
    let mut p: i32 = 0;
    for _ in 0..2047 {
        p = p.wrapping_add(1 << 20);
        let mut input = at(p);
        input.position_setpoint_inc = p;
        assert_eq!(l.update(&input).event, None);
    }
    p = p.wrapping_add((1 << 20) - 1);
    let mut input = at(p);
    input.position_setpoint_inc = p;
    assert_eq!(l.update(&input).event, None);
    assert_eq!(l.unwrapped_setpoint_inc(), i64::from(i32::MAX));
    assert!(l.relative_move_exceeds_computing_limit(1));
    assert!(!l.relative_move_exceeds_computing_limit(-1));
    // One more increment wraps the i32 set-point: event 53 cause 5.
    p = p.wrapping_add(1);
    input.position_setpoint_inc = p;
    let s = l.update(&input);
    assert_eq!(s.event, Some(Event { number: 53, cause: 5 }));
    assert_eq!(s.stop.unwrap().ramp, StopRamp::FaultReaction);
    assert!(s.lock.positive && !s.lock.negative);
    assert_eq!(l.update(&input).event, None, "only once");
    // Back inside: the lock goes.
    p = p.wrapping_sub(10);
    input.position_setpoint_inc = p;
    assert!(!l.update(&input).lock.any());
    // Endless axes wrap by design.
    let mut e = Limits::new(
        LimitConfig {
            endless_axis: true,
            ..LimitConfig::default()
        },
        i32::MAX,
    );
    let mut input = at(i32::MIN);
    input.position_setpoint_inc = i32::MIN;
    assert_eq!(e.update(&input).event, None);
    assert!(!e.relative_move_exceeds_computing_limit(i64::MAX));
}
