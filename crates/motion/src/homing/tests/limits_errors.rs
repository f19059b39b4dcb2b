//! §9.3 limit switches and errors: reversal at a limit in the travel direction, limits against
//! the travel, missing switches and invalid speeds (C-063, C-083, C-084).

use super::*;

#[test]
fn c083_limit_switch_in_travel_direction_reverses() {
    // Method 27 (initial −) from between −LS and RS: −LS reverses the
    // axis, the RS is then found from below and left at its top.
    let rs = rs_mid();
    let sim = check_homes(config(27), with_rs(-8 * REV, rs), rs.leave(1));
    assert!(sim.min_raw <= -10 * REV);
}

#[test]
fn c084_limit_switch_against_travel_is_an_error() {
    // Wiring swapped: the "+LS" is on the negative side; method 1 runs
    // negative into it.
    let a = Axis {
        pos: Band::below(-3 * REV),
        neg: Band::NONE,
        ..Axis::new(0)
    };
    let mut sim = Sim::new(config(1), a);
    let out = sim.home();
    assert_eq!(out.status, stopped_error(HomingError::LimitAgainstTravel));
    assert_eq!(sim.bits, [NOT_STARTED, RUN, ERR_MOVING, ERR_STILL]);
    assert!(sim.events.is_empty());
    assert!(!sim.h.is_referenced());
    // Braked with 609Ah: stopping distance of 4 rev/s at 100 rev/s².
    let overrun = -3 * REV - sim.min_raw;
    assert!(overrun > 0 && overrun < REV / 10, "{overrun}");
}

#[test]
fn c083_missing_home_switch_is_an_error_after_one_reversal() {
    let mut sim = Sim::new(config(23), Axis::new(0));
    let out = sim.home();
    assert_eq!(out.status, stopped_error(HomingError::SwitchNotFound));
    assert!(sim.max_raw >= 10 * REV && sim.min_raw <= -10 * REV);
    assert!(sim.events.is_empty());
    assert_eq!(out.status.statusword_bits(), ERR_STILL);
}

#[test]
fn c083_limit_while_creeping_or_searching_index_is_an_error() {
    // Method 34 with +LS half a revolution ahead, index farther.
    let a = Axis {
        pos: Band::from(REV / 2),
        index_at: REV - 10,
        ..Axis::new(0)
    };
    let mut sim = Sim::new(config(34), a);
    let out = sim.home();
    assert_eq!(out.status, stopped_error(HomingError::UnexpectedLimit));
}

#[test]
fn c084_both_limits_active_is_an_error() {
    let a = Axis {
        neg: Band::below(REV),
        pos: Band::from(-REV),
        ..Axis::new(0)
    };
    let mut sim = Sim::new(config(17), a);
    let out = sim.home();
    assert_eq!(out.status, stopped_error(HomingError::BothLimits));
    assert_eq!(sim.axis.raw, 0);
    assert_eq!(sim.bits, [NOT_STARTED, ERR_STILL]);
}

#[test]
fn c083_switch_not_found_within_travel_limit() {
    let cfg = HomingConfig {
        max_search_distance: 3 << 20,
        ..config(21)
    };
    let a = Axis {
        neg: Band::NONE,
        pos: Band::NONE,
        ..Axis::new(0)
    };
    let mut sim = Sim::new(cfg, a);
    let out = sim.home();
    assert_eq!(out.status, stopped_error(HomingError::TravelExceeded));
    let travelled = -sim.min_raw;
    assert!(
        travelled > 3 * REV && travelled < 3 * REV + REV / 10,
        "{travelled}"
    );
}

#[test]
fn c063_invalid_speeds_are_an_error() {
    for cfg in [
        HomingConfig {
            fast_speed: 0.0,
            ..config(1)
        },
        HomingConfig {
            slow_speed: -1.0,
            ..config(33)
        },
        HomingConfig {
            acceleration: f32::NAN,
            ..config(-1)
        },
    ] {
        let mut sim = Sim::new(cfg, Axis::new(0));
        let out = sim.home();
        assert_eq!(out.status, stopped_error(HomingError::InvalidParameters));
        assert_eq!(sim.axis.raw, 0);
    }
    // 33 needs only the slow speed.
    let cfg = HomingConfig {
        fast_speed: 0.0,
        ..config(33)
    };
    let a = Axis::new(0);
    let q = a.first_index(0, -1, 0);
    let mut sim = Sim::new(cfg, a);
    assert_eq!(sim.home().status, HomingStatus::Completed);
    assert_eq!(sim.reference_drive(q), cfg.home_offset);
}
