//! The 20 method codes (C-064 … C-082), the supported methods (C-060), the statusword
//! combinations (C-059) and the start on a rising edge of bit 4 (C-058).

use super::*;

#[test]
fn c064_homing_method_1_negative_limit_index() {
    let a = Axis::new(3 * REV);
    let edge = a.neg.leave(1);
    let q = a.first_index(edge, 1, 0);
    let sim = check_homes(config(1), a, q);
    assert!(sim.min_raw <= -10 * REV, "reached −LS");
    // Started on −LS: creeps off it, same index.
    let a = Axis::new(-10 * REV - 1000);
    check_homes(config(1), a, q);
}

#[test]
fn c068_homing_method_2_positive_limit_index() {
    let a = Axis::new(-REV);
    let q = a.first_index(a.pos.leave(-1), -1, 0);
    let sim = check_homes(config(2), a, q);
    assert!(sim.max_raw >= 10 * REV);
    check_homes(config(2), Axis::new(10 * REV + 5), q);
}

#[test]
fn c069_homing_method_3_positive_home_switch_index() {
    let rs = rs_pos();
    let q = Axis::new(0).first_index(rs.leave(-1), -1, 0);
    // Alt 1: off the switch, + until the RS, reverse.
    check_homes(config(3), with_rs(-6 * REV, rs), q);
    // Alt 2: on the switch, − at slow speed off it.
    let sim = check_homes(config(3), with_rs(5 * REV, rs), q);
    assert!(sim.max_raw <= 5 * REV, "never moved positive");
    assert!(sim.max_speed <= SLOW * 1.000_01);
}

#[test]
fn c065_homing_method_5_negative_home_switch_index() {
    let rs = rs_neg();
    let q = Axis::new(0).first_index(rs.leave(1), 1, 0);
    check_homes(config(5), with_rs(7 * REV, rs), q);
    let sim = check_homes(config(5), with_rs(-3 * REV, rs), q);
    assert!(sim.min_raw >= -3 * REV);
}

#[test]
fn c072_homing_method_7_centred_switch_index_initial_positive() {
    let rs = rs_mid();
    let q = Axis::new(0).first_index(rs.leave(-1), -1, 0);
    // Alt 1: between −LS and RS.
    let sim = check_homes(config(7), with_rs(-5 * REV, rs), q);
    assert!(sim.max_raw < 10 * REV);
    // Alt 2: on the RS.
    check_homes(config(7), with_rs(3 * REV, rs), q);
    // Alt 3: between RS and +LS: reversal at +LS (C-083).
    let sim = check_homes(config(7), with_rs(6 * REV, rs), q);
    assert!(sim.max_raw >= 10 * REV, "reached +LS");
}

#[test]
fn c074_homing_method_11_centred_switch_index_initial_negative() {
    let rs = rs_mid();
    let q = Axis::new(0).first_index(rs.leave(1), 1, 0);
    let sim = check_homes(config(11), with_rs(8 * REV, rs), q);
    assert!(sim.min_raw > -10 * REV);
    check_homes(config(11), with_rs(3 * REV, rs), q);
    let sim = check_homes(config(11), with_rs(-4 * REV, rs), q);
    assert!(sim.min_raw <= -10 * REV, "reached −LS");
}

#[test]
fn c066_homing_method_17_negative_limit() {
    let a = Axis::new(2 * REV);
    let edge = a.neg.leave(1);
    check_homes(config(17), a, edge);
    check_homes(config(17), Axis::new(-10 * REV - 77), edge);
}

#[test]
fn c070_homing_method_18_positive_limit() {
    let a = Axis::new(2 * REV);
    let edge = a.pos.leave(-1);
    check_homes(config(18), a, edge);
    check_homes(config(18), Axis::new(10 * REV + 99), edge);
}

#[test]
fn c071_homing_method_19_positive_home_switch() {
    let rs = rs_pos();
    check_homes(config(19), with_rs(-7 * REV, rs), rs.leave(-1));
    check_homes(config(19), with_rs(REV, rs), rs.leave(-1));
}

#[test]
fn c067_homing_method_21_negative_home_switch() {
    let rs = rs_neg();
    check_homes(config(21), with_rs(9 * REV, rs), rs.leave(1));
    check_homes(config(21), with_rs(0, rs), rs.leave(1));
}

#[test]
fn c073_homing_method_23_centred_switch_initial_positive() {
    let rs = rs_mid();
    for start in [-9 * REV, 3 * REV, 7 * REV] {
        check_homes(config(23), with_rs(start, rs), rs.leave(-1));
    }
}

#[test]
fn c073_narrow_switch_overrun_while_reversing_is_found_on_the_way_back() {
    // RS narrower than the stopping distance from 6099h:01 (≈ 84 000
    // inc): the axis leaves it on the far side while still braking in
    // the search direction; that edge does not count.
    let rs = Band {
        lo: 3 * REV,
        hi: 3 * REV + 20_000,
    };
    let sim = check_homes(config(23), with_rs(0, rs), rs.leave(-1));
    assert!(sim.max_raw > rs.hi + 40_000, "passed through the switch");
    let q = Axis::new(0).first_index(rs.leave(-1), -1, 0);
    check_homes(config(7), with_rs(0, rs), q);
}

#[test]
fn c075_homing_method_27_centred_switch_initial_negative() {
    let rs = rs_mid();
    for start in [9 * REV, 3 * REV, -7 * REV] {
        check_homes(config(27), with_rs(start, rs), rs.leave(1));
    }
}

#[test]
fn c076_homing_method_33_index_negative() {
    let a = Axis::new(REV / 3);
    let q = a.first_index(a.raw, -1, 0);
    assert!(q < a.raw && a.raw - q < REV);
    let sim = check_homes(config(33), a, q);
    assert!(sim.max_speed <= SLOW * 1.000_01, "slow speed only");
}

#[test]
fn c077_homing_method_34_index_positive() {
    let a = Axis::new(-REV / 3);
    let q = a.first_index(a.raw, 1, 0);
    assert!(q > a.raw && q - a.raw < REV);
    let sim = check_homes(config(34), a, q);
    assert!(sim.max_speed <= SLOW * 1.000_01);
}

#[test]
fn c078_homing_method_37_and_35_current_position() {
    for m in [37, 35] {
        let mut sim = Sim::new(config(m), Axis::new(4_444_444));
        let out = sim.home();
        assert_eq!(out.status, HomingStatus::Completed);
        assert_eq!(sim.bits, [NOT_STARTED, COMPLETED]);
        assert_eq!(sim.events.len(), 1);
        assert_eq!(sim.axis.raw, 4_444_444, "no motion");
        assert_eq!(sim.reference_drive(4_444_444), 7_000_000);
        assert_eq!(out.position, 7_000_000);
    }
}

fn stops() -> (i64, i64) {
    (-6 * REV - 4321, 5 * REV + 1234)
}

#[test]
fn c079_homing_method_minus1_torque_positive() {
    let a = Axis {
        stops: stops(),
        ..Axis::new(0)
    };
    let sim = check_homes(config(-1), a, stops().1);
    assert_eq!(sim.axis.raw, stops().1);
}

#[test]
fn c080_homing_method_minus3_torque_positive_index() {
    let a = Axis {
        stops: stops(),
        ..Axis::new(0)
    };
    let q = a.first_index(stops().1, -1, 1);
    check_homes(config(-3), a, q);
}

#[test]
fn c081_homing_method_minus2_torque_negative() {
    let a = Axis {
        stops: stops(),
        ..Axis::new(0)
    };
    check_homes(config(-2), a, stops().0);
}

#[test]
fn c082_homing_method_minus4_torque_negative_index() {
    let a = Axis {
        stops: stops(),
        ..Axis::new(0)
    };
    let q = a.first_index(stops().0, 1, 1);
    check_homes(config(-4), a, q);
}

#[test]
fn c079_torque_must_hold_for_i29() {
    // Short torque peaks (shorter than I29) are no stop.
    let mut sim = Sim::new(
        config(-1),
        Axis {
            stops: stops(),
            ..Axis::new(0)
        },
    );
    sim.cycle(false, false);
    let mut blips = 0;
    while sim.axis.raw < stops().1 {
        assert!(
            sim.events.is_empty(),
            "blip taken as the stop at {}",
            sim.axis.raw
        );
        sim.axis.torque = true; // one cycle (250 µs) < I29 (5 ms)
        blips += 1;
        for _ in 0..10 {
            sim.cycle(true, false);
        }
    }
    assert!(blips > 100);
    let out = sim.run_until(true, false, |o| o.status == HomingStatus::Completed);
    assert_eq!(sim.events.len(), 1);
    assert_eq!(sim.reference_drive(stops().1), 7_000_000);
    assert_eq!(out.status, HomingStatus::Completed);
}

#[test]
fn c060_supported_methods_are_the_20_codes() {
    assert_eq!(SUPPORTED_METHODS.len(), 20);
    let mut letters = Vec::new();
    for code in i8::MIN..=i8::MAX {
        let m = HomingMethod::from_code(code);
        assert_eq!(m.is_some(), SUPPORTED_METHODS.contains(&code), "{code}");
        if let Some(m) = m {
            assert_eq!(m.code(), code);
            letters.push(m.letter());
        }
    }
    letters.sort_unstable();
    letters.dedup();
    assert_eq!(letters.len(), 19, "A … S, 35 and 37 share O");
    for code in [0, 4, 6, 36, 38, -5] {
        let mut sim = Sim::new(config(code), Axis::new(0));
        let out = sim.home();
        assert_eq!(out.status, stopped_error(HomingError::InvalidMethod));
        assert_eq!(out.status.statusword_bits(), ERR_STILL);
        assert!(sim.events.is_empty());
    }
    assert_eq!(
        HomingMethod::NegativeLimitIndex.first_direction(),
        Some(Direction::Negative)
    );
    assert_eq!(
        HomingMethod::HomeIndexPositive.first_direction(),
        Some(Direction::Positive)
    );
    assert_eq!(HomingMethod::CurrentPosition.first_direction(), None);
    assert!(HomingMethod::TorqueNegativeIndex.uses_index());
    assert!(!HomingMethod::HomePositive.uses_index());
}

#[test]
fn c059_statusword_combinations() {
    use HomingStatus::*;
    let e = HomingError::BothLimits;
    assert_eq!(InProgress.statusword_bits(), 0b000 << 10);
    assert_eq!(Interrupted.statusword_bits(), 1 << 10);
    assert_eq!(Attained.statusword_bits(), 1 << 12);
    assert_eq!(Completed.statusword_bits(), (1 << 12) | (1 << 10));
    assert_eq!(
        Error {
            error: e,
            standstill: false
        }
        .statusword_bits(),
        1 << 13
    );
    assert_eq!(
        Error {
            error: e,
            standstill: true
        }
        .statusword_bits(),
        (1 << 13) | (1 << 12)
    );
}

#[test]
fn c058_start_needs_a_rising_edge_of_bit4() {
    let mut sim = Sim::new(config(34), Axis::new(0));
    // Bit 4 held high from activation: nothing starts.
    for _ in 0..100 {
        let out = sim.cycle(true, false);
        assert_eq!(out.status, HomingStatus::Interrupted);
    }
    assert_eq!(sim.axis.raw, 0);
    sim.cycle(false, false);
    let out = sim.cycle(true, false);
    assert_eq!(out.status, HomingStatus::InProgress);
    let out = sim.run_until(true, false, |o| o.status == HomingStatus::Completed);
    assert_eq!(out.status.statusword_bits(), COMPLETED);
}
