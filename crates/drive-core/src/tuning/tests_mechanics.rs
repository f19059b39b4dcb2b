//! B44 (issue 35) against a rigid-body plant whose parameters the test
//! does not tell the identification: inertia, Coulomb and viscous friction,
//! breakaway (static) friction, a constant load; the command of a cycle acts
//! until the next (one cycle of actuation delay), integrated in 10 µs steps.
#![allow(clippy::unwrap_used, clippy::panic, clippy::indexing_slicing)]
use super::mechanics::{MechanicsOutcome, MechanicsTest, BACK_INC, TRAVEL_INC};
use super::result;

/// A rigid rotor with friction.
struct Rotor {
    j: f64,
    coulomb: f64,
    viscous: f64,
    stiction: f64,
    load: f64,
    x: f64,
    v: f64,
}

impl Rotor {
    fn new(j: f64, coulomb: f64, viscous: f64, load: f64) -> Self {
        Self {
            j,
            coulomb,
            viscous,
            stiction: 1.5 * coulomb,
            load,
            x: 0.0,
            v: 0.0,
        }
    }

    /// One 1 ms cycle with torque `t`; the encoder position after it.
    fn step(&mut self, t: f64) -> i32 {
        let h = 1e-5;
        for _ in 0..100 {
            let drive = t - self.load;
            if self.v.abs() < 1e-4 && drive.abs() <= self.stiction {
                self.v = 0.0;
                continue;
            }
            let s = if self.v.abs() < 1e-4 {
                drive.signum()
            } else {
                self.v.signum()
            };
            let a = (drive - self.coulomb * s - self.viscous * self.v) / self.j;
            self.v += a * h;
            self.x += self.v * h;
        }
        (self.x / core::f64::consts::TAU * f64::from(1u32 << 20)).round() as i32
    }
}

/// The test run on `rotor` from `start_inc` to its end; the outcome, the
/// commands seen and the lowest and highest position relative to the start.
fn run(rotor: &mut Rotor, start_inc: i32) -> (MechanicsOutcome, usize, (i32, i32)) {
    let mut t = MechanicsTest::new(1e-3, 1.3, 3.9);
    rotor.x = f64::from(start_inc) / f64::from(1u32 << 20) * core::f64::consts::TAU;
    let mut pos = rotor.step(0.0);
    let (mut lo, mut hi) = (0i32, 0i32);
    // waiting for the enable
    assert!(t.cycle(2, pos).is_none());
    let mut n = 0;
    while let Some(c) = t.cycle(4, pos) {
        assert!(c.power_stage && c.brake_release && c.injection.is_none());
        assert!(c.torque_nm.abs() <= 3.9);
        pos = rotor.step(f64::from(c.torque_nm));
        lo = lo.min(pos.wrapping_sub(start_inc));
        hi = hi.max(pos.wrapping_sub(start_inc));
        n += 1;
        assert!(n < 60_000, "no end");
    }
    (t.outcome(), n, (lo, hi))
}

/// Issue 35: the identified inertia within 5 %, the Coulomb and viscous
/// friction within 10 % of plants the identification does not know (the
/// servo, 5× its inertia with 3× its friction, one with a constant load);
/// the move stays in the stated travel and ends where it started.
#[test]
fn e140_b44_identifies_inertia_and_friction_of_unknown_plants() {
    for (j, fc, b, load) in [
        (1.0e-4, 0.02, 2.0e-5, 0.0),
        (5.0e-4, 0.06, 6.0e-5, 0.0),
        (2.0e-4, 0.04, 1.0e-4, 0.05),
    ] {
        let mut rotor = Rotor::new(j, fc, b, load);
        let (outcome, n, (lo, hi)) = run(&mut rotor, 1000);
        let MechanicsOutcome::Done(m, excursion) = outcome else {
            panic!("J {j}: {outcome:?}");
        };
        let err = |x: f32, y: f64| (f64::from(x) - y) / y;
        std::println!(
            "J {j}: J {:+.2} %, Fc {:+.2} %, B {:+.2} %, load {:.4} N·m, {n} cycles, excursion {excursion}",
            err(m.inertia_kg_m2, j) * 100.0,
            err(m.coulomb_nm, fc) * 100.0,
            err(m.viscous_nm_s_per_rad, b) * 100.0,
            m.load_nm
        );
        assert!(err(m.inertia_kg_m2, j).abs() < 0.05, "J {m:?}");
        assert!(err(m.coulomb_nm, fc).abs() < 0.10, "Fc {m:?}");
        assert!(err(m.viscous_nm_s_per_rad, b).abs() < 0.10, "B {m:?}");
        assert!(
            (f64::from(m.load_nm) - load).abs() < 0.1 * fc.max(load),
            "load {m:?}"
        );
        assert!(lo >= -BACK_INC && hi <= TRAVEL_INC, "travel {lo} … {hi}");
        assert_eq!(excursion, hi.unsigned_abs().max(lo.unsigned_abs()));
        let back = pos_err(&rotor, 1000);
        assert!(back < (1 << 20) / 100, "back at the start: {back}");
    }
}

fn pos_err(rotor: &Rotor, start: i32) -> u32 {
    let p = (rotor.x / core::f64::consts::TAU * f64::from(1u32 << 20)).round() as i32;
    p.wrapping_sub(start).unsigned_abs()
}

/// E-141: nothing is commanded before the enable; the enable going away
/// mid-move aborts it (1) and hands the axis back at once.
#[test]
fn e141_b44_waits_for_the_enable_and_aborts_on_disable() {
    let mut t = MechanicsTest::new(1e-3, 1.3, 3.9);
    for _ in 0..10 {
        assert!(t.cycle(2, 0).is_none());
    }
    assert_eq!(t.outcome(), MechanicsOutcome::Running(0, 0));
    let mut rotor = Rotor::new(1e-4, 0.02, 2e-5, 0.0);
    let mut pos = 0;
    for _ in 0..300 {
        let c = t.cycle(4, pos).unwrap();
        pos = rotor.step(f64::from(c.torque_nm));
    }
    assert!(pos > 1000, "it moves");
    assert!(t.cycle(5, pos).is_none(), "quick stop");
    assert!(matches!(
        t.outcome(),
        MechanicsOutcome::Failed(result::ABORTED, _)
    ));
    assert!(t.cycle(4, pos).is_none(), "ended");
    // a fault before the enable ends it too
    let mut t = MechanicsTest::new(1e-3, 1.3, 3.9);
    assert!(t.cycle(8, 0).is_none());
    assert!(matches!(
        t.outcome(),
        MechanicsOutcome::Failed(result::ABORTED, 0)
    ));
}

/// A shaft that runs away (a load that pulls harder than the test) leaves
/// the stated travel: the test ends (11) and hands the axis back; a blocked
/// one does not reach the kick's speed (3).
#[test]
fn e140_b44_leaving_the_travel_or_a_blocked_shaft_fails() {
    let mut t = MechanicsTest::new(1e-3, 1.3, 0.5);
    let mut pos = 0i32;
    let mut n = 0;
    while t.cycle(4, pos).is_some() {
        pos = pos.saturating_add(20_000);
        n += 1;
    }
    assert!(
        matches!(t.outcome(), MechanicsOutcome::Failed(result::OUT_OF_TRAVEL, _)),
        "{:?}",
        t.outcome()
    );
    assert!(n * 20_000 <= TRAVEL_INC + 20_000);
    let mut t = MechanicsTest::new(1e-3, 1.3, 3.9);
    while t.cycle(4, 0).is_some() {}
    assert!(matches!(
        t.outcome(),
        MechanicsOutcome::Failed(result::NOT_SETTLED, 0)
    ));
}

/// The software-limit check of the start: inside, at the edges, beyond, and
/// limits that are off (min ≥ max).
#[test]
fn e140_b44_travel_against_software_limits() {
    let (t, b) = (i64::from(TRAVEL_INC), i64::from(BACK_INC));
    assert!(MechanicsTest::travel_allowed(0, -b, t, t, b));
    assert!(!MechanicsTest::travel_allowed(1, -b, t, t, b));
    assert!(!MechanicsTest::travel_allowed(-1, -b, t, t, b));
    assert!(MechanicsTest::travel_allowed(i64::MAX, 0, 0, t, b), "off");
    assert!(!MechanicsTest::travel_allowed(i64::MAX, i64::MIN, i64::MAX, t, b));
}

mod through_actions {
    use super::Rotor;
    use crate::actions::{state, Actions, A69, A75};
    use crate::axis::AxisIo;
    use crate::params::{B44, B45, B46, B47, B48, C31, C32, E48, I20};
    use crate::tuning::result;
    use crate::DriveObjects;

    fn objects() -> DriveObjects {
        let mut od = DriveObjects::new();
        let n = od.get(0x1600, 0).unwrap() as u8;
        let _ = od.set(0x1600, 0, 0);
        od.set(0x1600, n + 1, i64::from(u32::from(A75) << 16 | 8))
            .unwrap();
        od.set(0x1600, 0, i64::from(n + 1)).unwrap();
        od.set(E48, 0, 2).unwrap();
        od
    }

    fn start(od: &mut DriveObjects, a: &mut Actions) {
        od.set(A75, 0, 0b1111 << 1 | 1).unwrap();
        a.serve(od);
    }

    const TUNING: [u16; 7] = [B45, B46, B47, C31, C32, I20, B48];

    fn tuning(od: &DriveObjects) -> [i64; 7] {
        TUNING.map(|i| od.get(i, 0).unwrap())
    }

    /// E-141: B44 started in Operation enabled (E48 = 4) is refused with
    /// A69's refused state and changes nothing: no measurement, no object.
    #[test]
    fn e141_b44_in_the_wrong_state_is_refused_and_changes_nothing() {
        for e48 in [0, 1, 3, 4, 7] {
            let mut od = objects();
            od.set(E48, 0, e48).unwrap();
            let before = tuning(&od);
            let mut a = Actions::new();
            start(&mut od, &mut a);
            assert_eq!(a.status(0) >> 12, state::REFUSED, "E48 = {e48}");
            assert_eq!(a.status(0) >> 8 & 0xF, 0b1111);
            assert!(a.control(0, 4, &AxisIo::ready(0)).is_none(), "nothing runs");
            assert_eq!(tuning(&od), before);
            assert_eq!(od.get(B44, 1).unwrap(), 0);
        }
    }

    /// Issue 35, bad input: a test move that would pass a software limit
    /// (607Dh) or start on an active limit switch (60FDh) is refused before
    /// it moves, B44[0] = 12.
    #[test]
    fn e140_b44_refused_before_it_moves_beyond_a_limit() {
        let travel = i64::from(super::TRAVEL_INC);
        for (min, max, inputs, refused) in [
            (-2_000_000, travel + 10, 0, false),
            (-2_000_000, travel - 10, 0, true),
            (-10, travel + 10, 0, true),
            (0, 0, 0, false),
            (0, 0, 0b10, true),
            (0, 0, 0b01, true),
        ] {
            let mut od = objects();
            od.set(0x607D, 1, min).unwrap();
            od.set(0x607D, 2, max).unwrap();
            od.set(0x60FD, 0, inputs).unwrap();
            let before = tuning(&od);
            let mut a = Actions::new();
            start(&mut od, &mut a);
            let st = a.status(0) >> 12;
            if refused {
                assert_eq!(st, state::REFUSED, "{min} {max} {inputs}");
                assert_eq!(od.get(B44, 1).unwrap(), i64::from(result::LIMIT));
                assert!(a.control(0, 4, &AxisIo::ready(0)).is_none(), "nothing moves");
                assert_eq!(tuning(&od), before);
            } else {
                assert_eq!(st, state::RUNNING, "{min} {max} {inputs}");
                assert!(a
                    .control(0, 4, &AxisIo::ready(0))
                    .is_some_and(|c| c.torque_nm > 0.0));
            }
        }
    }

    /// E-140 (B44) through the action unit on a plant it does not know: the
    /// figures land in B45…B47, the gains for B48's bandwidth in C31/C32/I20
    /// (for the 250 µs reference cycle at A150 = 1 ms: Kp = J·ω/r, Ti = 4/ω·r,
    /// Kv = ω/4/√r, r = 1/4), A69 shows the end; Execute low returns to idle.
    #[test]
    fn e140_b44_through_a75_writes_the_figures_and_the_gains() {
        let mut od = objects();
        od.set(B48, 0, 25).unwrap();
        let mut a = Actions::new();
        start(&mut od, &mut a);
        assert_eq!(a.status(0) >> 12, state::RUNNING);
        let mut rotor = Rotor::new(3.0e-4, 0.03, 4.0e-5, 0.0);
        let mut pos = rotor.step(0.0);
        let mut n = 0;
        while let Some(c) = a.control(0, 4, &AxisIo::ready(pos)) {
            pos = rotor.step(f64::from(c.torque_nm));
            if n % 100 == 0 {
                a.serve(&mut od);
                assert_eq!(a.status(0) >> 12, state::RUNNING);
            }
            n += 1;
            assert!(n < 20_000);
        }
        a.serve(&mut od);
        assert_eq!(a.status(0), 100 | 0b1111 << 8 | state::DONE << 12);
        assert_eq!(od.get(A69, 0).unwrap(), i64::from(a.status(0)));
        assert_eq!(od.get(B44, 1).unwrap(), 0);
        let j = od.get(B45, 0).unwrap() as f64 * 1e-7;
        assert!((j / 3.0e-4 - 1.0).abs() < 0.05, "{j}");
        assert!((od.get(B46, 0).unwrap() as f64 * 1e-6 / 0.03 - 1.0).abs() < 0.1);
        assert!((od.get(B47, 0).unwrap() as f64 * 1e-9 / 4.0e-5 - 1.0).abs() < 0.1);
        let w = core::f64::consts::TAU * 25.0;
        let kp = od.get(C31, 0).unwrap() as f64 * 1e-6;
        assert!((kp / (j * w * 4.0) - 1.0).abs() < 1e-3, "{kp}");
        let ti = od.get(C32, 0).unwrap() as f64 * 1e-6;
        assert!((ti / (4.0 / w / 4.0) - 1.0).abs() < 1e-3, "{ti}");
        let kv = od.get(I20, 0).unwrap() as f64 * 0.1;
        assert!((kv / (w / 4.0 * 2.0) - 1.0).abs() < 2e-3, "{kv}");
        assert!(od.get(B44, 2).unwrap() > 5 << 20, "the excursion");
        od.set(A75, 0, 0b1111 << 1).unwrap();
        a.serve(&mut od);
        assert_eq!(a.status(0), 0);
    }
}
