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
            torque_nm: 0.0,
            current_a: 0.0,
            trip: None,
            d_axis: Some(DAxisMeans {
                voltage_v: (su / 16.0) as f32,
                current_a: (si / 16.0) as f32,
                interval_s: 1e-3,
            }),
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
