//! The reference event, the move to home, the index offset and I30 (C-061, C-062, C-085 …
//! C-087).

use super::*;

#[test]
fn c062_move_to_home_offset_after_the_stop() {
    let cfg = HomingConfig {
        move_to_home: true,
        home_offset: -123_456,
        ..config(1)
    };
    let a = Axis::new(0);
    let q = a.first_index(a.neg.leave(1), 1, 0);
    let mut sim = check_homes(cfg, a, q);
    // Stopped beyond, then came back: it stands on 607Ch, on the
    // reference point.
    assert_eq!(sim.axis.raw, q);
    let out = sim.cycle(true, false);
    assert_eq!(out.position, -123_456);
    assert_eq!(sim.axis.input(true, false).actual_position, -123_456);
}

#[test]
fn c061_reference_event_shifts_by_home_offset_across_wrap() {
    // Drive coordinates near i32::MAX: the run crosses the wrap.
    let cfg = HomingConfig {
        home_offset: i32::MIN + 5,
        ..config(17)
    };
    let a = Axis {
        offset: i32::MAX - 3 * (1 << 20),
        ..Axis::new(0)
    };
    let edge = a.neg.leave(1);
    let sim = check_homes(cfg, a, edge);
    let (e, _) = sim.events[0];
    assert_eq!(
        e.reference_position,
        (edge as i32).wrapping_add(i32::MAX - 3 * (1 << 20))
    );
}

#[test]
fn c087_index_search_starts_after_i53() {
    let a = Axis::new(0);
    let edge = a.neg.leave(1);
    let first = a.first_index(edge, 1, 0);
    let off = (first - edge + 1) as u32;
    let cfg = HomingConfig {
        index_search_offset: off,
        ..config(1)
    };
    let q = a.first_index(edge, 1, i64::from(off));
    assert_eq!(q, first + REV, "the first pulse is skipped");
    check_homes(cfg, a, q);
}

#[test]
fn c086_limit_switch_as_reference_switch() {
    // I30 = 2, method 19: the +LS is the home switch; no fault.
    let cfg = HomingConfig {
        limit_as_reference: true,
        ..config(19)
    };
    let a = Axis::new(0);
    let edge = a.pos.leave(-1);
    check_homes(cfg, a, edge);
    // Method 21 (negative side) likewise with −LS.
    let cfg = HomingConfig {
        limit_as_reference: true,
        ..config(21)
    };
    check_homes(cfg, Axis::new(0), Axis::new(0).neg.leave(1));
}

#[test]
fn c085_referencing_flag_while_moving() {
    let mut sim = Sim::new(config(2), Axis::new(0));
    assert!(!sim.h.is_referencing());
    sim.cycle(false, false);
    sim.cycle(true, false);
    assert!(sim.h.is_referencing());
    sim.run_until(true, false, |o| o.status == HomingStatus::Attained);
    assert!(sim.h.is_referencing());
    sim.run_until(true, false, |o| o.status == HomingStatus::Completed);
    assert!(!sim.h.is_referencing());
}

#[test]
fn c061_latched_edge_beats_actual_position() {
    // Without latches the edge is the actual position of the cycle that
    // sees it: within one creep step of the exact edge.
    let rs = rs_mid();
    let mut sim = Sim::new(config(23), with_rs(0, rs));
    sim.cycle(false, false);
    loop {
        let mut input = sim.axis.input(true, false);
        input.reference_switch.edge = None;
        let out = sim.h.step(&sim.cfg, &input, DT);
        if let Some(e) = out.reference {
            sim.axis.offset = sim.axis.offset.wrapping_add(e.shift);
        }
        sim.axis.follow(&out);
        if out.status == HomingStatus::Completed {
            break;
        }
    }
    let exact = sim.reference_drive(rs.leave(-1));
    let err = i64::from(exact.wrapping_sub(7_000_000)).abs();
    let step = (f64::from(SLOW) * 250e-6).ceil() as i64;
    assert!(err <= step, "{err}");
}
