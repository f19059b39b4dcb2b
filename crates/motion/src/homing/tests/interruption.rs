//! Halt, interruption and restart (C-058, C-059, C-062).

use super::*;

#[test]
fn c058_halt_interrupts_and_a_new_edge_restarts() {
    let rs = rs_neg();
    let mut sim = Sim::new(config(5), with_rs(8 * REV, rs));
    sim.cycle(false, false);
    for _ in 0..2000 {
        assert_eq!(sim.cycle(true, false).status, HomingStatus::InProgress);
    }
    let moving_at = sim.axis.raw;
    assert!(moving_at < 8 * REV);
    // Halt: braking (000) then interrupted (001), no reference.
    let out = sim.cycle(true, true);
    assert_eq!(out.status, HomingStatus::InProgress);
    let out = sim.run_until(true, true, |o| o.status == HomingStatus::Interrupted);
    assert_eq!(out.velocity, 0.0);
    assert!(sim.events.is_empty());
    assert!(moving_at - sim.axis.raw < REV / 10, "braked with 609Ah");
    // Halt released, bit 4 still 1: stays interrupted.
    for _ in 0..50 {
        assert_eq!(sim.cycle(true, false).status, HomingStatus::Interrupted);
    }
    // New edge: homes from where it stands.
    let out = sim.home();
    assert_eq!(out.status, HomingStatus::Completed);
    assert_eq!(
        sim.reference_drive(Axis::new(0).first_index(rs.leave(1), 1, 0)),
        7_000_000
    );
    assert_eq!(
        sim.bits,
        [NOT_STARTED, RUN, NOT_STARTED, RUN, ATTAINED, COMPLETED]
    );
}

#[test]
fn c058_bit4_falling_interrupts() {
    let mut sim = Sim::new(config(2), Axis::new(0));
    sim.cycle(false, false);
    for _ in 0..1000 {
        sim.cycle(true, false);
    }
    let out = sim.run_until(false, false, |o| o.status == HomingStatus::Interrupted);
    assert_eq!(out.status.statusword_bits(), NOT_STARTED);
    assert!(sim.events.is_empty());
    assert!(!sim.h.is_referencing());
}

#[test]
fn c059_restart_after_error() {
    // No RS: error; then the RS is connected and a new edge homes.
    let mut sim = Sim::new(config(19), Axis::new(0));
    let out = sim.home();
    assert!(matches!(
        out.status,
        HomingStatus::Error {
            error: HomingError::SwitchNotFound,
            ..
        }
    ));
    let rs = rs_pos();
    sim.axis.rs = rs;
    let out = sim.home();
    assert_eq!(out.status, HomingStatus::Completed);
    assert_eq!(sim.reference_drive(rs.leave(-1)), 7_000_000);
    assert_eq!(
        sim.bits,
        [NOT_STARTED, RUN, ERR_MOVING, ERR_STILL, RUN, ATTAINED, COMPLETED]
    );
}

#[test]
fn c062_halt_after_the_reference_skips_the_move_to_home() {
    let cfg = HomingConfig {
        move_to_home: true,
        ..config(18)
    };
    let mut sim = Sim::new(cfg, Axis::new(0));
    sim.cycle(false, false);
    sim.run_until(true, false, |o| o.status == HomingStatus::Attained);
    let out = sim.run_until(true, true, |o| o.status == HomingStatus::Completed);
    assert_eq!(sim.events.len(), 1);
    assert_ne!(
        out.position, cfg.home_offset,
        "stopped beyond the reference point"
    );
    assert!(sim.h.is_referenced());
}
