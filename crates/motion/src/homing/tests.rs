use super::*;
extern crate std;
use std::vec::Vec;

/// The error status once the axis stands still.
fn stopped_error(error: HomingError) -> HomingStatus {
    HomingStatus::Error {
        error,
        standstill: true,
    }
}

const REV: i64 = 1 << 20;
const DT: u32 = 250_000; // 250 µs
const FAST: f32 = 4.0 * (1 << 20) as f32; // 4 rev/s
const SLOW: f32 = 0.25 * (1 << 20) as f32; // 0.25 rev/s
const ACC: f32 = 100.0 * (1 << 20) as f32; // 100 rev/s²

/// A switch active for `lo ≤ x < hi` (raw increments).
#[derive(Debug, Clone, Copy)]
struct Band {
    lo: i64,
    hi: i64,
}

impl Band {
    const NONE: Band = Band { lo: 0, hi: 0 };
    fn below(x: i64) -> Band {
        Band { lo: i64::MIN, hi: x }
    }
    fn from(x: i64) -> Band {
        Band { lo: x, hi: i64::MAX }
    }
    fn active(&self, x: i64) -> bool {
        self.lo <= x && x < self.hi
    }
    /// First position on the way `p0 → p1` whose state differs from
    /// the state at `p0`.
    fn edge(&self, p0: i64, p1: i64) -> Option<i64> {
        if self.active(p0) == self.active(p1) {
            return None;
        }
        let bounds = [self.lo, self.hi];
        if p1 > p0 {
            bounds.iter().copied().filter(|&b| p0 < b && b <= p1).min()
        } else {
            bounds
                .iter()
                .copied()
                .filter(|&b| p1 < b && b <= p0)
                .max()
                .map(|b| b - 1)
        }
    }
    /// The leaving edge approached in `dir`: first position outside.
    fn leave(&self, dir: i64) -> i64 {
        if dir > 0 {
            self.hi
        } else {
            self.lo - 1
        }
    }
}

/// An ideal axis: follows the set-point exactly, except at mechanical
/// stops; switches and an index pulse every revolution at `index_at`.
#[derive(Debug, Clone)]
struct Axis {
    raw: i64,
    /// Drive position = raw + offset (wrapping).
    offset: i32,
    neg: Band,
    pos: Band,
    rs: Band,
    index_at: i64,
    stops: (i64, i64),
    // Observations of the last move.
    edges: [Option<i64>; 3],
    index: Option<i64>,
    torque: bool,
    standstill: bool,
}

impl Axis {
    fn new(raw: i64) -> Self {
        Self {
            raw,
            offset: 0,
            neg: Band::below(-10 * REV + 1), // −LS active ≤ −10 rev
            pos: Band::from(10 * REV),       // +LS active ≥ +10 rev
            rs: Band::NONE,
            index_at: 12_345,
            stops: (-20 * REV, 20 * REV),
            edges: [None; 3],
            index: None,
            torque: false,
            standstill: true,
        }
    }
    fn drive(&self, raw: i64) -> i32 {
        (raw as i32).wrapping_add(self.offset)
    }
    fn input(&self, start: bool, halt: bool) -> HomingInput {
        let sw = |b: &Band, e: Option<i64>| SwitchInput {
            active: b.active(self.raw),
            edge: e.map(|e| self.drive(e)),
        };
        HomingInput {
            actual_position: self.drive(self.raw),
            negative_limit: sw(&self.neg, self.edges[0]),
            positive_limit: sw(&self.pos, self.edges[1]),
            reference_switch: sw(&self.rs, self.edges[2]),
            index: self.index.map(|q| self.drive(q)),
            torque_limit: self.torque,
            standstill: self.standstill,
            start,
            halt,
        }
    }
    /// First index pulse crossed on `p0 → p1` (p0 excluded).
    fn index_between(&self, p0: i64, p1: i64) -> Option<i64> {
        if p1 > p0 {
            let q = p0 + (self.index_at - p0 - 1).rem_euclid(REV) + 1;
            (q <= p1).then_some(q)
        } else if p1 < p0 {
            let q = p0 - (p0 - self.index_at - 1).rem_euclid(REV) - 1;
            (q >= p1).then_some(q)
        } else {
            None
        }
    }
    /// First index pulse at least `min` beyond `from` in `dir`, `from`
    /// itself excluded (never crossed).
    fn first_index(&self, from: i64, dir: i64, min: i64) -> i64 {
        let mut q = self.index_between(from, from + dir * 2 * REV).unwrap_or(i64::MAX);
        while (q - from) * dir < min {
            q += dir * REV;
        }
        q
    }
    fn follow(&mut self, out: &HomingOutput) {
        let sp = i64::from(out.position.wrapping_sub(self.offset));
        let p0 = self.raw;
        let p1 = sp.max(self.stops.0).min(self.stops.1);
        self.edges = [self.neg.edge(p0, p1), self.pos.edge(p0, p1), self.rs.edge(p0, p1)];
        self.index = self.index_between(p0, p1);
        self.torque = (sp - p1).abs() >= 50;
        self.standstill = p0 == p1 && out.velocity == 0.0;
        self.raw = p1;
    }
}

fn config(method: i8) -> HomingConfig {
    HomingConfig {
        method,
        fast_speed: FAST,
        slow_speed: SLOW,
        acceleration: ACC,
        jerk: 1.0e11,
        home_offset: 7_000_000,
        move_to_home: false,
        index_search_offset: 0,
        torque_hold: Nanos::from_ms(5),
        max_search_distance: 0,
        limit_as_reference: false,
    }
}

struct Sim {
    h: Homing,
    cfg: HomingConfig,
    axis: Axis,
    /// Distinct statusword patterns (bits 13/12/10) in order.
    bits: Vec<u16>,
    events: Vec<(ReferenceEvent, HomingOutput)>,
    last: Option<HomingOutput>,
    max_speed: f32,
    max_acc: f32,
    /// Raw range visited.
    min_raw: i64,
    max_raw: i64,
    cycles: u32,
}

impl Sim {
    fn new(cfg: HomingConfig, axis: Axis) -> Self {
        let h = Homing::new(axis.drive(axis.raw));
        let raw = axis.raw;
        Self {
            h,
            cfg,
            axis,
            bits: Vec::new(),
            events: Vec::new(),
            last: None,
            max_speed: 0.0,
            max_acc: 0.0,
            min_raw: raw,
            max_raw: raw,
            cycles: 0,
        }
    }

    fn cycle(&mut self, start: bool, halt: bool) -> HomingOutput {
        let input = self.axis.input(start, halt);
        let out = self.h.step(&self.cfg, &input, DT);
        let b = out.status.statusword_bits();
        assert_eq!(b & !SW_HOMING_MASK, 0);
        if self.bits.last() != Some(&b) {
            self.bits.push(b);
        }
        if let Some(e) = out.reference {
            self.axis.offset = self.axis.offset.wrapping_add(e.shift);
            self.events.push((e, out));
        }
        self.max_speed = self.max_speed.max(out.velocity.abs());
        self.max_acc = self.max_acc.max(out.acceleration.abs());
        self.axis.follow(&out);
        self.min_raw = self.min_raw.min(self.axis.raw);
        self.max_raw = self.max_raw.max(self.axis.raw);
        self.last = Some(out);
        self.cycles += 1;
        out
    }

    /// Bit 4 low for a cycle, then high until completed or failed at
    /// standstill.
    fn home(&mut self) -> HomingOutput {
        self.cycle(false, false);
        self.run_until(true, false, |o| {
            matches!(
                o.status,
                HomingStatus::Completed | HomingStatus::Error { standstill: true, .. }
            )
        })
    }

    fn run_until(&mut self, start: bool, halt: bool, done: fn(&HomingOutput) -> bool) -> HomingOutput {
        for _ in 0..400_000 {
            let out = self.cycle(start, halt);
            if done(&out) {
                return out;
            }
        }
        panic!("no end: {:?}", self.last);
    }

    /// Drive position of the raw reference point after the event.
    fn reference_drive(&self, raw: i64) -> i32 {
        self.axis.drive(raw)
    }
}

const RUN: u16 = 0;
const NOT_STARTED: u16 = SW_TARGET_REACHED;
const ATTAINED: u16 = SW_HOMING_ATTAINED;
const COMPLETED: u16 = SW_HOMING_ATTAINED | SW_TARGET_REACHED;
const ERR_MOVING: u16 = SW_HOMING_ERROR;
const ERR_STILL: u16 = SW_HOMING_ERROR | SW_HOMING_ATTAINED;

/// Homes and checks: completed, one reference event, the raw point
/// `expected` reads 607Ch, status 001 → 000 → 010 → 011, speeds and
/// accelerations within 6099h/609Ah, creeping at the event.
fn check_homes(cfg: HomingConfig, axis: Axis, expected: i64) -> Sim {
    let mut sim = Sim::new(cfg, axis);
    let out = sim.home();
    assert_eq!(out.status, HomingStatus::Completed, "{:?}", sim.last);
    assert_eq!(sim.events.len(), 1);
    let (e, at) = sim.events[0];
    assert_eq!(sim.reference_drive(expected), cfg.home_offset, "reference point");
    assert_eq!(e.reference_position.wrapping_add(e.shift), cfg.home_offset);
    assert_eq!(
        sim.bits,
        [NOT_STARTED, RUN, ATTAINED, COMPLETED],
        "status sequence"
    );
    assert!(sim.max_speed <= FAST * 1.000_01, "{}", sim.max_speed);
    assert!(sim.max_acc <= ACC * 1.000_01, "{}", sim.max_acc);
    assert!(
        at.velocity.abs() <= SLOW * 1.000_01,
        "creep at the event: {}",
        at.velocity
    );
    assert!(sim.h.is_referenced());
    assert!(!sim.h.is_referencing());
    // Holds still, completed.
    let hold = sim.cycle(true, false);
    assert_eq!(hold.status, HomingStatus::Completed);
    assert_eq!(hold.velocity, 0.0);
    assert_eq!(hold.position, sim.axis.drive(sim.axis.raw));
    sim
}

fn rs_neg() -> Band {
    Band::below(3 * REV + 777) // negative-side home switch
}
fn rs_pos() -> Band {
    Band::from(-2 * REV - 555) // positive-side home switch
}
fn rs_mid() -> Band {
    Band {
        lo: 2 * REV + 300_001,
        hi: 4 * REV - 99_999,
    }
}
fn with_rs(raw: i64, rs: Band) -> Axis {
    Axis { rs, ..Axis::new(raw) }
}

// ---- the 20 method codes ----

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

// ---- §9.3 limit switches, errors ----

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

// ---- halt, interruption, restart ----

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

// ---- reference event, move to home, index offset, I30 ----

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
