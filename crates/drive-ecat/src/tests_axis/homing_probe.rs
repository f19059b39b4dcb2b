//! Homing and the touch probe: the home offset, the latched switch edge of method 19, and the
//! probe's latch in the user units of the moment (C-061, C-071, C-109, C-122).

use super::*;

#[test]
fn c061_homing_sets_the_home_offset() {
    let mut rig = Rig::new();
    rig.motors[0].theta = 1.0; // somewhere
    rig.set(0, 0x6060, 0, 6);
    rig.enable(0);
    let before = rig.position(0);
    assert!((i64::from(before) - REV_I / 6).abs() < REV_I / 100, "{before}");
    home_here(&mut rig, 0, 1234);
    assert!(
        (rig.position(0) - 1234).abs() < 20,
        "position {}",
        rig.position(0)
    );
    assert!(rig.drive.axes()[0].is_referenced());
}

#[test]
fn c122_touch_probe_latches_the_rising_edge() {
    let mut rig = Rig::probe1_armed();
    assert_eq!(rig.get(0, 0x60B9, 0), 0x01);
    rig.motors[0].theta = TAU; // one revolution
    rig.probe1_rising(Some(777));
    rig.cycle();
    assert_eq!(rig.get(0, 0x60BA, 0), 777);
    assert_eq!(rig.get(0, 0x60B9, 0), 0x03);
    // a second edge is ignored in first-event mode (C-124)
    rig.probe1_rising(None);
    rig.cycle();
    assert_eq!(rig.get(0, 0x60BA, 0), 777);
}

/// C-109 with C-122: a latched probe value is shown in the user units of
/// the moment, so a new feed constant (6092h) converts it again although
/// the probe latched nothing new.
#[test]
fn c109_c122_probe_value_follows_a_new_feed_constant() {
    let mut rig = Rig::probe1_armed();
    rig.probe1_rising(Some(1000));
    rig.cycle();
    rig.io[0].probe_edges[0] = None;
    assert_eq!(rig.get(0, 0x60BA, 0), 1000);
    rig.run(3);
    assert_eq!(rig.get(0, 0x60BA, 0), 1000);
    // half a user unit per increment
    rig.set(0, 0x6092, 1, REV_I / 2);
    rig.run(1);
    assert_eq!(rig.get(0, 0x60BA, 0), 500);
}

/// Method 19 on a reference switch from X on (motor increments), with or
/// without the hardware's latched edge; returns the error of the edge's
/// reading against 607Ch.
fn method_19_edge_error(latched: bool) -> i64 {
    const X: i32 = 300_000;
    let mut rig = Rig::new();
    rig.set(0, 0x6098, 0, 19);
    rig.set(0, 0x607C, 0, 0);
    rig.set(0, 0x6060, 0, 6);
    rig.enable(0);
    rig.controlword(0, 0x1F);
    let mut last = rig.motors[0].position_inc();
    let mut done = false;
    for _ in 0..10_000 {
        let now = rig.motors[0].position_inc();
        rig.io[0].reference = now >= X;
        rig.io[0].switch_edges = [None; 4];
        if latched && (last >= X) != (now >= X) {
            rig.io[0].switch_edges[0] = Some(SwitchEdge {
                switch: SwitchId::Reference,
                position_inc: X,
            });
        }
        last = now;
        rig.cycle();
        if rig.sw(0) & 0x1400 == 0x1400 {
            done = true;
            break;
        }
    }
    assert!(done, "homing done: {:#06x}", rig.sw(0));
    rig.controlword(0, 0x0F);
    rig.run(50);
    // the switch edge X (motor increments) reads, in 6064h:
    i64::from(rig.position(0)) - i64::from(rig.motors[0].position_inc() - X)
}

#[test]
fn c071_homing_takes_the_latched_switch_edge() {
    let level = method_19_edge_error(false);
    let latched = method_19_edge_error(true);
    // creep 6099h:02 = 0.25 rev/s: one cycle is 262 increments
    assert!(
        level.abs() <= 2 * 262,
        "level only: within two creep steps: {level}"
    );
    assert!(latched.abs() <= 2, "latched edge: exact: {latched}");
    assert!(latched.abs() < level.abs(), "{latched} vs {level}");
}
