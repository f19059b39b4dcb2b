#![allow(clippy::unwrap_used, clippy::panic, clippy::indexing_slicing)]
use super::*;
use crate::axis::DAxisMeans;

/// A winding u = R·i + L·di/dt behind a loop that applies each PWM
/// period's voltage less a constant error (the dead time's remainder) and
/// reports the means of the voltage it meant and the current at the periods'
/// centres, as the seam says; the rotor stands. Exact per period
/// (exponential), 16 PWM periods per 1 ms control cycle.
struct Winding {
    r: f64,
    l: f64,
    offset_v: f64,
    i: f64,
    report: Option<CurrentActual>,
}

impl Winding {
    fn run(&mut self, cmd: Option<AxisCommand>) {
        let Some(c) = cmd else {
            self.report = None;
            return;
        };
        let u = f64::from(c.injection.map_or(0.0, |j| j.ud_v));
        let ts = 1.0 / 16_000.0;
        let (mut su, mut si) = (0.0, 0.0);
        for _ in 0..16 {
            let ue = u - self.offset_v;
            let inf = ue / self.r;
            let k = (-ts * self.r / self.l).exp();
            let mid = inf + (self.i - inf) * (-0.5 * ts * self.r / self.l).exp();
            self.i = inf + (self.i - inf) * k;
            su += u;
            si += mid;
        }
        self.report = Some(CurrentActual {
            d_axis: Some(DAxisMeans {
                voltage_v: (su / 16.0) as f32,
                current_a: (si / 16.0) as f32,
                interval_s: 1e-3,
            }),
            ..CurrentActual::measured(0.0, 0.0)
        });
    }
}

fn run(r: f64, l: f64, offset_v: f64) -> (Outcome, u32) {
    let mut w = Winding {
        r,
        l,
        offset_v,
        i: 0.0,
        report: None,
    };
    let mut t = CurrentTuning::new(2.0, 3.6, false);
    assert_eq!(t.cycle(2, None), None, "waits for the enable");
    for n in 0..20_000 {
        let cmd = t.cycle(4, w.report.as_ref());
        if !matches!(t.outcome(), Outcome::Running(_)) {
            return (t.outcome(), n);
        }
        w.run(cmd);
    }
    panic!("no end");
}

/// E-140 (B42): R and L of windings the tuning does not know (the prior R is
/// 3.6 Ω) come out within 1 % of the model's, with a constant voltage error.
#[test]
fn e140_b42_identifies_r_and_l_of_an_unknown_winding() {
    for (r, l, off) in [
        (3.6, 0.012, 0.0),
        (1.2, 0.003, 0.8),
        (9.0, 0.040, -1.5),
        (0.5, 0.0008, 0.3),
    ] {
        let (o, cycles) = run(r, l, off);
        let Outcome::Done(id) = o else {
            panic!("{r} Ω {l} H: {o:?}");
        };
        let er = (f64::from(id.r_ohm) - r) / r;
        let el = (f64::from(id.l_h) - l) / l;
        assert!(
            er.abs() < 0.01 && el.abs() < 0.01,
            "{r} Ω {l} H: {id:?} ({er:+.4}, {el:+.4}) in {cycles} cycles"
        );
    }
}

/// E-141: the enable removed mid-run aborts it (result 1) and gives the axis
/// its own command back; a disable before the enable ends it as well.
#[test]
fn e141_b42_aborted_when_the_enable_goes() {
    let mut t = CurrentTuning::new(2.0, 3.6, true);
    assert!(t
        .cycle(4, None)
        .is_some_and(|c| c.injection.is_some() && !c.brake_release));
    assert_eq!(t.cycle(2, None), None);
    assert_eq!(t.outcome(), Outcome::Failed(result::ABORTED));
    assert_eq!(t.cycle(4, None), None, "ended: the axis' own command");
    let mut t = CurrentTuning::new(2.0, 3.6, false);
    assert_eq!(t.cycle(1, None), None);
    assert_eq!(t.outcome(), Outcome::Failed(result::ABORTED));
}

/// An open winding (no current at any probe voltage): result 2; a loop that
/// reports no d axis: result 5.
#[test]
fn e140_b42_open_winding_and_no_measurement_fail_with_their_codes() {
    let (o, _) = run(1.0e9, 0.01, 0.0);
    assert_eq!(o, Outcome::Failed(result::NO_CURRENT));
    let mut t = CurrentTuning::new(2.0, 3.6, false);
    for _ in 0..6 {
        let _ = t.cycle(4, None);
    }
    assert_eq!(t.outcome(), Outcome::Failed(result::NO_MEASUREMENT));
}

/// A rotor that turns its d axis towards the injected frame: torque
/// K·sin(frame − θe), Coulomb friction with stick, inertia J; 4 pole pairs,
/// its d axis along phase a at `offset_inc`. Stepped in 0.1 ms.
fn align_run(offset_inc: i32, start_el: f64) -> (align::AlignOutcome, u32) {
    use align::{AlignOutcome, Alignment};
    let (k, tc, j, p) = (5.2f64, 0.02f64, 1e-4f64, 4.0f64);
    let (mut th, mut w) = (start_el / p, 0.0f64); // mechanical, from the offset
    let pos = |th: f64| offset_inc.wrapping_add((th / core::f64::consts::TAU * 1_048_576.0).round() as i32);
    let mut a = Alignment::new(7.2, 4);
    let mut cmd = a.cycle(4, pos(th));
    for n in 0..40_000 {
        let frame = cmd.and_then(|c| c.injection).and_then(|i| i.angle);
        for _ in 0..10 {
            let drive = frame.map_or(0.0, |f| {
                let fe = f64::from(f) / 4_294_967_296.0 * core::f64::consts::TAU;
                k * (fe - p * th).sin()
            });
            let torque = if w == 0.0 && drive.abs() <= tc {
                0.0
            } else {
                drive - tc * if w != 0.0 { w.signum() } else { drive.signum() }
            };
            let w1 = w + torque / j * 1e-4;
            th += 0.5 * (w + w1) * 1e-4;
            w = if w != 0.0 && w * w1 < 0.0 { 0.0 } else { w1 };
        }
        cmd = a.cycle(4, pos(th));
        if !matches!(a.outcome(), AlignOutcome::Running(_)) {
            return (a.outcome(), n);
        }
    }
    panic!("no end");
}

/// E-140 (B41): the alignment finds a rotor's commutation offset from any
/// start (up to 170° electrical away) within 0.2° electrical, friction
/// notwithstanding (its two approaches straddle the offset).
#[test]
fn e140_b41_alignment_finds_the_offset_of_a_rotor_with_friction() {
    let per_el = 262_144i64;
    for (offset, start) in [
        (50_066, 0.0),
        (1_000_000, 0.0),
        (50_066, 2.9),
        (1_000_000, 2.9),
        (7, -2.0),
    ] {
        let (o, n) = align_run(offset, start);
        let align::AlignOutcome::Done {
            offset_inc,
            spread_inc,
        } = o
        else {
            panic!("{offset}: {o:?}");
        };
        let err = (i64::from(offset_inc) - i64::from(offset)).rem_euclid(per_el);
        let err = err.min(per_el - err) as f64 / per_el as f64 * 360.0;
        assert!(
            err < 0.2,
            "{offset} from {start}: B05 {offset_inc}, {err}° el off, spread {spread_inc}, {n} cycles"
        );
        assert!(spread_inc > 0, "friction parts the approaches");
    }
}

/// E-141 (B41): the enable removed mid-run aborts the calibration.
#[test]
fn e141_b41_aborted_when_the_enable_goes() {
    let mut a = align::Alignment::new(7.2, 4);
    assert!(a.cycle(2, 0).is_none(), "waits for the enable");
    assert!(a
        .cycle(4, 0)
        .is_some_and(|c| c.brake_release && c.injection.is_some_and(|i| i.angle == Some(0))));
    assert!(a.cycle(2, 0).is_none());
    assert_eq!(a.outcome(), align::AlignOutcome::Failed(result::ABORTED));
}

/// E-140 (B300): the test torque ramps to the rated torque forward, then
/// backward, with the brake applied and the power stage on; a shaft that
/// stays put passes, one that moves beyond 1/360 rev fails at once (9), and
/// the enable going away mid-test aborts it (1).
#[test]
fn e140_b300_test_brake_torque_profile_slip_and_abort() {
    use super::brake::{BrakeOutcome, BrakeTest, HOLD_CYCLES, RAMP_CYCLES, TOLERANCE_INC};
    // waiting for the enable: nothing commanded, still running
    let mut t = BrakeTest::new(1.3);
    assert_eq!(t.cycle(2, 0), None);
    assert_eq!(t.outcome(), BrakeOutcome::Running(0));
    let (mut lo, mut hi) = (0.0f32, 0.0f32);
    let mut n = 0;
    while let Some(c) = t.cycle(4, 1000) {
        assert!(c.power_stage && !c.brake_release && c.injection.is_none());
        lo = lo.min(c.torque_nm);
        hi = hi.max(c.torque_nm);
        n += 1;
    }
    assert_eq!(n, 2 * (RAMP_CYCLES + HOLD_CYCLES));
    assert_eq!((lo, hi), (-1.3, 1.3));
    assert_eq!(t.outcome(), BrakeOutcome::Held(0));
    // a slipping shaft
    let mut t = BrakeTest::new(1.3);
    let mut pos = 0;
    while t.cycle(4, pos).is_some() {
        pos += 50;
    }
    match t.outcome() {
        BrakeOutcome::Failed(code, moved) => {
            assert_eq!(code, super::result::SLIPPED);
            assert!(moved > TOLERANCE_INC && moved <= TOLERANCE_INC + 50, "{moved}");
        }
        o => panic!("{o:?}"),
    }
    // the enable goes away
    let mut t = BrakeTest::new(1.3);
    assert!(t.cycle(4, 0).is_some());
    assert_eq!(t.cycle(2, 0), None);
    assert_eq!(t.outcome(), BrakeOutcome::Failed(super::result::ABORTED, 0));
}

/// A shaft of 1e-4 kg·m² with 0.02 N·m friction behind a brake of
/// `holding_nm` (its sliding torque too) that closes when commanded, or
/// always if `stuck`; stick–slip at 10 µs steps, the command acting in the
/// cycle after it. Runs B301 to its end: the outcome, the cycles, the brake
/// commands over the cycles.
fn grind_run(holding_nm: f64, stuck: bool) -> (grind::GrindOutcome, u32, std::vec::Vec<bool>) {
    let (j, friction, h) = (1.0e-4, 0.02, 1.0e-5);
    let (mut theta, mut omega) = (0.0f64, 0.0f64);
    let mut g = grind::GrindBrake::new(1.3, 3.9);
    assert_eq!(g.cycle(2, 0), None, "waits for the enable");
    let mut releases = std::vec::Vec::new();
    let inc = |theta: f64| (theta / core::f64::consts::TAU * f64::from(1u32 << 20)).floor() as i32;
    let mut n = 0;
    while let Some(c) = g.cycle(4, inc(theta)) {
        assert!(c.power_stage && c.injection.is_none());
        releases.push(c.brake_release);
        let brake = if stuck || !c.brake_release {
            holding_nm
        } else {
            0.0
        };
        let stat = friction + brake;
        let t = f64::from(c.torque_nm);
        for _ in 0..100 {
            if omega == 0.0 && t.abs() <= stat {
                continue;
            }
            let dir = if omega != 0.0 { omega.signum() } else { t.signum() };
            let w = omega + h * (t - stat * dir) / j;
            omega = if w * dir < 0.0 { 0.0 } else { w };
            theta += omega * h;
        }
        n += 1;
        assert!(n < 10_000, "ends");
    }
    (g.outcome(), n, releases)
}

/// E-140 (B301): the sequence — after the enable 4 rounds of 500 cycles
/// grinding (brake applied) and 250 released, then 100 cycles stopped on the
/// brake — on a shaft whose 2 N·m brake the 3.9 N·m peak turns: done, each
/// grind phase turning the shaft most of 60 rpm × 0.5 s (2^19 inc), the
/// grinding torque settling at the brake's sliding torque; a brake that
/// holds 5 N·m stalls it (10) after the first grind phase, one that never
/// releases fails the first released phase (11).
#[test]
fn e140_b301_grind_brake_sequence_and_its_failures() {
    use grind::{GrindOutcome, GRIND_CYCLES, RELEASE_CYCLES, ROUNDS, SPEED_INC, STOP_CYCLES};
    let (o, n, releases) = grind_run(2.0, false);
    assert_eq!(n, ROUNDS * (GRIND_CYCLES + RELEASE_CYCLES) + STOP_CYCLES);
    // the brake pattern: closed 500, open 250, ×4, closed 100
    let edges = releases.windows(2).filter(|w| w[0] != w[1]).count();
    assert_eq!(edges as u32, 2 * ROUNDS, "{ROUNDS} releases: {edges} edges");
    // the brake opens once the torque is down to the released limit
    let open = releases.iter().filter(|r| **r).count() as u32;
    assert!(
        (ROUNDS * (RELEASE_CYCLES - 12)..=ROUNDS * RELEASE_CYCLES).contains(&open),
        "{open}"
    );
    assert!(!releases[0] && releases[GRIND_CYCLES as usize + 12] && !releases[n as usize - 1]);
    assert!(!releases[GRIND_CYCLES as usize], "the torque first");
    let GrindOutcome::Done(f) = o else { panic!("{o:?}") };
    let full = |cycles: u32| (SPEED_INC as u32 * cycles) as f32;
    std::println!("B301 healthy: {f:?}");
    assert!(f.grind_travel_inc as f32 > 0.8 * full(GRIND_CYCLES), "{f:?}");
    assert!(
        f.grind_travel_inc as f32 <= 1.1 * full(GRIND_CYCLES),
        "slow: {f:?}"
    );
    assert!(f.release_travel_inc as f32 > 0.8 * full(RELEASE_CYCLES), "{f:?}");
    assert!((2.0..2.1).contains(&f.grind_torque_nm), "{f:?}");
    // a brake beyond the peak torque: the first grind phase stalls
    let (o, n, _) = grind_run(5.0, false);
    let GrindOutcome::Failed(code, f) = o else {
        panic!("{o:?}")
    };
    // then 20 cycles (21: rounding) winding 3.9 N·m down on the brake
    assert_eq!(code, result::STALLED, "{f:?}");
    assert!((GRIND_CYCLES + 20..=GRIND_CYCLES + 21).contains(&n), "{n}");
    assert_eq!(f.grind_travel_inc, 0);
    assert!((f.grind_torque_nm - 3.9).abs() < 1e-3, "the peak: {f:?}");
    // a stuck brake: ground, but not released
    let (o, n, _) = grind_run(2.0, true);
    let GrindOutcome::Failed(code, f) = o else {
        panic!("{o:?}")
    };
    assert_eq!(code, result::NOT_RELEASED, "{f:?}");
    let wound = n - (GRIND_CYCLES + RELEASE_CYCLES);
    assert!(wound <= 2, "at most 0.33 N·m to wind down: {wound}");
    assert!(f.release_travel_inc < SPEED_INC as u32 * 10, "{f:?}");
}

/// E-141 (B301): the enable going away mid-sequence aborts it (1): no
/// command after that.
#[test]
fn e141_b301_aborted_when_the_enable_goes() {
    let mut g = grind::GrindBrake::new(1.3, 3.9);
    assert!(g
        .cycle(4, 0)
        .is_some_and(|c| !c.brake_release && c.torque_nm > 0.0));
    assert!(g.cycle(4, 10).is_some());
    assert_eq!(g.cycle(5, 20), None);
    assert!(matches!(
        g.outcome(),
        grind::GrindOutcome::Failed(result::ABORTED, _)
    ));
    assert_eq!(g.cycle(4, 20), None);
}
