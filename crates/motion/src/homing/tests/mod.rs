//! Homing tests on an ideal axis (switch bands, an index pulse every revolution, mechanical
//! stops) that follows the set-point exactly.
//!
//! Here: the axis, the simulation and `check_homes`; the tests, by topic, in the submodules.

use super::*;
extern crate std;
use std::vec::Vec;

mod interruption;
mod limits_errors;
mod methods;
mod reference;

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
