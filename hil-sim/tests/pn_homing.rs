//! The homing methods of the PROFIdrive profile (spec §8.5) through the
//! Example Function block against the simulated drive: each method in the
//! manual's numbering, translated to the core's, started with CW1 bit 11
//! inside positioning, on a linear axis with limit switches, a reference
//! switch, an index pulse per revolution and end stops. Each run asserts
//! the first direction of travel and the feature the reference lies on.

use hil_sim::fb::controller::PnController;
use hil_sim::fb::rig::FbRig;
use hil_sim::motor::{Motor, PositionInput, Switches};

const REV: i64 = 1 << 20;
/// The index pulse sits a quarter revolution into every revolution.
const INDEX: i64 = REV / 4;
/// Limit switches: actuated below −3 rev and from +3 rev on.
const LIMIT: i64 = 3 * REV;
/// End stops (block homing): ±3.5 rev.
const STOP: i64 = 3 * REV + REV / 2;

/// What the reference lies on.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Feature {
    /// The index pulse at this position (k · rev + a quarter).
    Index(i64),
    /// The edge of the limit switch in this direction.
    LimitEdge,
    /// The edge of the reference switch.
    ReferenceEdge,
    /// The end stop in this direction.
    Stop,
    /// Where the axis stood.
    Here,
}

struct Rig(FbRig);

impl Rig {
    /// The drive with axis A's motor on the test axis; `reference` is the
    /// reference switch; with `limits` the limit switches are fitted and
    /// wired (I101/I102 = 1), else the axis ends at its end stops only.
    fn new(reference: PositionInput, limits: bool) -> Rig {
        let mut sim = PnController::drive();
        let m: &mut Motor = sim.motor_mut(0).expect("axis A");
        *m.switches_mut() = if limits {
            Switches::linear_axis(-LIMIT, LIMIT, reference)
        } else {
            Switches {
                reference,
                ..Switches::default()
            }
        };
        m.params_mut().index_offset_inc = INDEX;
        m.params_mut().end_stops_inc = Some((-STOP, STOP));
        if limits {
            let objects = sim.drive_mut().objects_mut();
            for index in [drive_ecat::params::I101, drive_ecat::params::I101 + 1] {
                objects.set(index, 0, 1).expect("I101/I102");
            }
        }
        Rig(FbRig::connect(sim).expect("connect"))
    }

    fn enable(&mut self) {
        assert!(self.0.enable().expect("cycle"), "enabled: {:#06x}", self.0.o.zsw1);
    }

    /// Homes with `method`; returns the first direction of travel (+1 / −1,
    /// 0 without motion) and the reference in encoder increments.
    fn home(&mut self, method: i8) -> (i64, i64) {
        let r = &mut self.0;
        r.i.homing_method = method;
        r.i.start_homing = true;
        let start = r.encoder();
        let mut first = 0;
        let mut done = false;
        for _ in 0..40_000 {
            r.cycle().expect("cycle");
            let moved = r.encoder() - start;
            if first == 0 && moved.abs() > REV / 100 {
                first = moved.signum();
            }
            if r.ctl.fresh() && r.o.home_valid {
                done = true;
                break;
            }
            if r.o.fault {
                let o = r.ctl.sim().drive().objects();
                panic!(
                    "method {method}: fault {:#06x}, E82 {:?} E43 {:?} at {} inc",
                    r.o.zsw1,
                    o.get(drive_ecat::params::E82, 0),
                    o.get(drive_ecat::params::E43, 0),
                    r.encoder()
                );
            }
        }
        assert!(
            done,
            "method {method}: home_valid within 40 s ({:#06x})",
            r.o.zsw1
        );
        r.i.start_homing = false;
        for _ in 0..50 {
            r.cycle().expect("cycle");
        }
        // the reference reads 0 (home offset 0): encoder − actual position
        let actual = i64::from(r.o.position_actual_value) * REV / 1000;
        (first, r.encoder() - actual)
    }
}

/// `at` lies on `feature` (the limit or stop in direction `dir`), within
/// the position resolution of PNU 1100 (1/1000 rev) plus a creep step.
/// Index pulses: the first one after the switch, stop or start in the
/// method's direction of the final search (spec §8.5's table).
fn on_feature(at: i64, feature: Feature, dir: i64, start: i64, reference_edges: (i64, i64)) -> bool {
    let tol = REV / 1000 + 2000;
    let near = |x: i64| (at - x).abs() <= tol;
    match feature {
        Feature::Index(x) => near(x),
        Feature::LimitEdge => near(dir * LIMIT),
        Feature::ReferenceEdge => near(reference_edges.0) || near(reference_edges.1),
        Feature::Stop => near(dir * STOP),
        Feature::Here => near(start),
    }
}

/// One method: the reference switch `reference` with its edges at
/// `edges`, the expected first direction and the feature (with the
/// direction of the limit or stop it names).
fn check(method: i8, reference: PositionInput, edges: (i64, i64), first: i64, feature: Feature, side: i64) {
    let limits = method > 0;
    let mut r = Rig::new(reference, limits);
    r.enable();
    let start = r.0.encoder();
    let (dir, at) = r.home(method);
    println!(
        "PROFIdrive method {method:>3}: first move {dir:+}, reference at {at} inc ({:.4} rev), {feature:?}",
        at as f64 / REV as f64
    );
    if first != 0 {
        assert_eq!(dir, first, "method {method}: first direction");
    }
    assert!(
        on_feature(at, feature, side, start, edges),
        "method {method}: reference {at} inc is not on {feature:?} (side {side})"
    );
    assert_eq!(r.0.o.operation_mode_actual, 0x10, "back in positioning");
}

/// The reference switch on the positive side (actuated from +1 rev on).
const REF_POS: PositionInput = PositionInput::above(REV);
/// The reference switch on the negative side (actuated below −1 rev).
const REF_NEG: PositionInput = PositionInput::below(-REV);
const NONE: PositionInput = PositionInput::never();
const NO_EDGES: (i64, i64) = (0, 0);

#[test]
fn p166_methods_1_and_2_limit_switch_then_index() {
    check(1, NONE, NO_EDGES, -1, Feature::Index(-LIMIT + INDEX), -1);
    check(2, NONE, NO_EDGES, 1, Feature::Index(LIMIT - REV + INDEX), 1);
}

#[test]
fn p168_methods_7_and_11_reference_switch_then_index() {
    check(7, REF_POS, (REV, REV), 1, Feature::Index(INDEX), 1);
    check(11, REF_NEG, (-REV, -REV), -1, Feature::Index(-REV + INDEX), -1);
}

#[test]
fn p165_methods_17_and_18_limit_switch_edge() {
    check(17, NONE, NO_EDGES, -1, Feature::LimitEdge, -1);
    check(18, NONE, NO_EDGES, 1, Feature::LimitEdge, 1);
}

#[test]
fn p167_methods_23_and_27_reference_switch_edge() {
    check(23, REF_POS, (REV, REV), 1, Feature::ReferenceEdge, 1);
    check(27, REF_NEG, (-REV, -REV), -1, Feature::ReferenceEdge, -1);
}

/// A centred reference switch on the far side (−1.5 … −1 rev): method 23
/// searches positive, reverses at the limit switch and finds it on the way
/// back; 27 mirrored (P-167).
#[test]
fn p167_methods_23_and_27_reverse_at_the_limit_switch() {
    let low = -REV - REV / 2;
    check(
        23,
        PositionInput::window(low, -REV),
        (low, -REV),
        1,
        Feature::ReferenceEdge,
        -1,
    );
    let high = REV + REV / 2;
    check(
        27,
        PositionInput::window(REV, high),
        (REV, high),
        -1,
        Feature::ReferenceEdge,
        1,
    );
}

#[test]
fn p170_methods_32_and_33_index_pulse() {
    check(32, NONE, NO_EDGES, -1, Feature::Index(-REV + INDEX), -1);
    check(33, NONE, NO_EDGES, 1, Feature::Index(INDEX), 1);
}

#[test]
fn p171_method_34_the_current_position() {
    check(34, NONE, NO_EDGES, 0, Feature::Here, 0);
}

/// Block homing without limit switches, against the end stops: the core's
/// torque-stop methods stand in for the manual's i²t criterion
/// (docs/conformance.md, P-163/P-164).
#[test]
fn p163_p164_block_methods_run_to_the_end_stop() {
    check(-17, NONE, NO_EDGES, -1, Feature::Stop, -1);
    check(-18, NONE, NO_EDGES, 1, Feature::Stop, 1);
    check(
        -1,
        NONE,
        NO_EDGES,
        -1,
        Feature::Index(-STOP + REV / 2 + INDEX),
        -1,
    );
    check(-2, NONE, NO_EDGES, 1, Feature::Index(STOP - REV / 2 + INDEX), 1);
}
