//! Homing mode (6) through a real master (spec cia402.md §6.4, §9;
//! features-cia402.md C-058 … C-087): every method code of 6098h on the
//! simulated motor with limit switches, a reference switch, the encoder's
//! index pulse and rigid end stops. Each test starts referencing with a 0→1
//! edge of controlword bit 4 in the standard RxPDO, checks the homing bits
//! 13/12/10 of Tab. 26 in every TxPDO and, at the end, that the reference
//! point the method defines (switch edge, index pulse, end stop) reads 607Ch
//! in 6064h; the plant's encoder is the independent ruler.

use drive_tests::axis::*;
use drive_tests::{init, line, sw, with_cyclic, with_master};
use drive_tests::{REV, REV_F};
use hil_sim::motor::{PositionInput, Switches};
use std::cell::RefCell;

/// I101 / I102 sources of the limit switches (1 = input), I28 / I29 homing
/// torque limit (0.1 %) and time (ms), I30 reference switch type: the
/// manual's parameters at 2000h + group·200h + line.
const I101: u16 = 0x3065;
const I102: u16 = 0x3066;
const I28: u16 = 0x301C;
const I29: u16 = 0x301D;
const I30: u16 = 0x301E;

/// One revolution, increments, as i64.
const R: i64 = REV as i64;
/// Where the encoder's index pulse sits within a revolution.
const INDEX_AT: i64 = 300_000;
/// 607Ch used by every test (non-zero, so a missing shift shows).
const HOME_OFFSET: i32 = 12_345;
/// Negative / positive hardware limit switch (actuated below / at or above).
const NEG_LS: i64 = -2 * R;
const POS_LS: i64 = 2 * R;
/// Tolerance of an index reference (exact hardware latch), increments.
const INDEX_TOL: i64 = 4;
/// Tolerance of a switch-edge reference: the simulator latches the switch
/// change where the motor crossed it (`AxisIo::switch_edges`), so the
/// reference is exact to a few increments, not one creep step (the creep,
/// 6099h:02 = 0.25 rev/s, moves 262 increments per 1 ms cycle).
const EDGE_TOL: i64 = 4;

/// First index pulse strictly above / below `x` (plant increments).
fn index_above(x: i64) -> i64 {
    let k = (x - INDEX_AT).div_euclid(R) + 1;
    k * R + INDEX_AT
}

fn index_below(x: i64) -> i64 {
    let k = (x - INDEX_AT - 1).div_euclid(R);
    k * R + INDEX_AT
}

/// A homing scenario on motor A.
#[derive(Clone, Copy)]
struct Case {
    /// 6098h.
    method: i8,
    /// Switches of the axis.
    switches: Switches,
    /// Motor position at power-on, increments.
    start: i64,
    /// I101/I102: the limit switches are evaluated.
    limits: bool,
    /// Rigid end stops of the plant.
    end_stops: Option<(i64, i64)>,
    /// The plant position that must read 607Ch afterwards.
    reference: i64,
    /// Allowed error of that reading, increments.
    tol: i64,
}

impl Case {
    fn new(method: i8, switches: Switches, reference: i64, tol: i64) -> Self {
        Self {
            method,
            switches,
            start: 0,
            limits: true,
            end_stops: None,
            reference,
            tol,
        }
    }

    fn from(mut self, start: i64) -> Self {
        self.start = start;
        self
    }
}

/// What a homing run saw.
#[derive(Debug)]
struct Run {
    /// The reference point's reading minus 607Ch, increments.
    error: i64,
    /// Lowest / highest plant position during the run.
    min: i64,
    max: i64,
    /// Homing took this long, ms.
    ms: u64,
}

/// Linear axis with limit switches at ±2 rev and `reference` as home switch.
fn axis(reference: PositionInput) -> Switches {
    Switches::linear_axis(NEG_LS, POS_LS, reference)
}

/// Runs `case` through the master; asserts Tab. 26 on the way (000 while
/// running, never 1xx, never a fault), 011 at the end, and returns the
/// reading error of the reference point.
fn home(case: Case) -> Run {
    let sim = line(1);
    {
        let mut s = sim.borrow_mut();
        let d = &mut s.drives_mut()[0];
        let m = &mut d.motors[0];
        *m.switches_mut() = case.switches;
        m.params_mut().index_offset_inc = INDEX_AT;
        m.params_mut().end_stops_inc = case.end_stops;
        m.set_position_inc(case.start);
    }
    let run = RefCell::new(None);
    with_cyclic(&sim, async |m, sd| {
        // the settings as a master sets them (issue 40): I101/I102 = 1 the
        // limit switches from the inputs; torque methods: 40 % of the rated
        // torque for 50 ms is the stop (I28/I29)
        let ls = u8::from(case.limits);
        sd.sdo_write(I101, 0, ls).await.unwrap();
        sd.sdo_write(I102, 0, ls).await.unwrap();
        sd.sdo_write(I28, 0, 400u16).await.unwrap();
        sd.sdo_write(I29, 0, 50u16).await.unwrap();
        sd.sdo_write(0x6098, 0, case.method).await.unwrap();
        sd.sdo_write(0x607C, 0, HOME_OFFSET).await.unwrap();
        let tx = m.enable_in(6).await;
        assert_eq!(tx.mode_display, 6);
        // 001 before the start (not started)
        assert!(
            tx.bit(10) && !tx.bit(12) && !tx.bit(13),
            "method {}: not started = 001: {:#06x}",
            case.method,
            tx.statusword
        );
        m.set_controlword(CW_ENABLED | CW_BIT4);
        let t0 = m.now().as_ns();
        let (mut min, mut max) = (case.start, case.start);
        let mut done = false;
        for k in 0..20_000 {
            let tx = m.cycle().await;
            let p = sim.borrow().drives()[0].motors[0].position_inc_i64();
            min = min.min(p);
            max = max.max(p);
            assert_eq!(
                tx.state(),
                sw::OE,
                "method {}: no fault while referencing (C-083): {:#06x} at {p}",
                case.method,
                tx.statusword
            );
            assert!(
                !tx.bit(13),
                "method {}: no homing error: {:#06x} at {p}",
                case.method,
                tx.statusword
            );
            if tx.bit(12) && tx.bit(10) {
                done = true;
                break;
            }
            // 000 running, or 010 reference set and still moving (one cycle of bus delay at the start)
            if k > 1 {
                assert!(
                    !tx.bit(10),
                    "method {}: 000/010 while running: {:#06x}",
                    case.method,
                    tx.statusword
                );
            }
        }
        assert!(
            done,
            "method {}: homing done (011): {:#06x}",
            case.method, m.tx.statusword
        );
        let ms = (m.now().as_ns() - t0) / 1_000_000;
        m.set_controlword(CW_ENABLED);
        let tx = m.run(20).await;
        assert!(
            tx.bit(12) && tx.bit(10) && !tx.bit(13),
            "method {}: 011 stays after bit 4 = 0: {:#06x}",
            case.method,
            tx.statusword
        );
        let enc = sim.borrow().drives()[0].motors[0].position_inc_i64();
        let reads = i64::from(tx.position) - (enc - case.reference);
        let error = reads - i64::from(HOME_OFFSET);
        println!(
            "method {:3}: {ms:5} ms, travel {:+.3} … {:+.3} rev, reference {:+.4} rev reads {reads} (607Ch {HOME_OFFSET}, error {error} inc)",
            case.method,
            min as f64 / REV_F,
            max as f64 / REV_F,
            case.reference as f64 / REV_F,
        );
        *run.borrow_mut() = Some(Run { error, min, max, ms });
    });
    let r = run.into_inner().expect("run");
    assert!(
        r.error.abs() <= case.tol,
        "method {}: the reference point reads 607Ch ± {}: error {}",
        case.method,
        case.tol,
        r.error
    );
    r
}

// ---------------------------------------------------------------------------
// Limit-switch methods (A, C, E, G)
// ---------------------------------------------------------------------------

#[test]
fn c064_c083_method_1_negative_limit_switch_and_index() {
    let r = home(Case::new(
        1,
        axis(PositionInput::never()),
        index_above(NEG_LS),
        INDEX_TOL,
    ));
    assert!(r.min < NEG_LS, "went onto −LS: {}", r.min);
}

#[test]
fn c066_method_17_negative_limit_switch_edge() {
    let r = home(Case::new(17, axis(PositionInput::never()), NEG_LS, EDGE_TOL));
    assert!(
        r.min < NEG_LS && r.max <= R / 100,
        "searched negative only: {r:?}"
    );
}

#[test]
fn c068_method_2_positive_limit_switch_and_index() {
    let r = home(Case::new(
        2,
        axis(PositionInput::never()),
        index_below(POS_LS),
        INDEX_TOL,
    ));
    assert!(r.max >= POS_LS, "went onto +LS: {}", r.max);
}

#[test]
fn c070_method_18_positive_limit_switch_edge() {
    let r = home(Case::new(18, axis(PositionInput::never()), POS_LS, EDGE_TOL));
    assert!(
        r.max >= POS_LS && r.min >= -R / 100,
        "searched positive only: {r:?}"
    );
}

// ---------------------------------------------------------------------------
// Home switch on one side (B, D, F, H), both start alternatives
// ---------------------------------------------------------------------------

/// Home switch actuated below −0.7 rev (negative side).
const RS_NEG: i64 = -7 * R / 10;
/// Home switch actuated from +0.7 rev on (positive side).
const RS_POS: i64 = 7 * R / 10;

#[test]
fn c065_method_5_negative_home_switch_and_index_both_starts() {
    let sw = axis(PositionInput::below(RS_NEG));
    let off = home(Case::new(5, sw, index_above(RS_NEG), INDEX_TOL));
    assert!(off.min < RS_NEG, "searched negative onto the switch: {off:?}");
    // started on the switch: creeps off positive, same index pulse
    let on = home(Case::new(5, sw, index_above(RS_NEG), INDEX_TOL).from(RS_NEG - R / 2));
    assert!(on.min >= RS_NEG - R / 2 - R / 100, "no negative search: {on:?}");
}

#[test]
fn c067_method_21_negative_home_switch_edge_both_starts() {
    let sw = axis(PositionInput::below(RS_NEG));
    home(Case::new(21, sw, RS_NEG, EDGE_TOL));
    let on = home(Case::new(21, sw, RS_NEG, EDGE_TOL).from(RS_NEG - R / 2));
    assert!(on.min >= RS_NEG - R / 2 - R / 100, "no negative search: {on:?}");
}

#[test]
fn c069_method_3_positive_home_switch_and_index_both_starts() {
    let sw = axis(PositionInput::above(RS_POS));
    let off = home(Case::new(3, sw, index_below(RS_POS), INDEX_TOL));
    assert!(off.max >= RS_POS, "searched positive onto the switch: {off:?}");
    let on = home(Case::new(3, sw, index_below(RS_POS), INDEX_TOL).from(RS_POS + R / 2));
    assert!(on.max <= RS_POS + R / 2 + R / 100, "no positive search: {on:?}");
}

#[test]
fn c071_method_19_positive_home_switch_edge_both_starts() {
    let sw = axis(PositionInput::above(RS_POS));
    home(Case::new(19, sw, RS_POS, EDGE_TOL));
    let on = home(Case::new(19, sw, RS_POS, EDGE_TOL).from(RS_POS + R / 2));
    assert!(on.max <= RS_POS + R / 2 + R / 100, "no positive search: {on:?}");
}

// ---------------------------------------------------------------------------
// Centred home switch (I, J, K, L), three start alternatives each
// ---------------------------------------------------------------------------

/// Cam from +0.5 to +0.9 rev (initial-positive methods) and its mirror.
const CAM_LO: i64 = R / 2;
const CAM_HI: i64 = 9 * R / 10;

fn cam_pos() -> Switches {
    axis(PositionInput::window(CAM_LO, CAM_HI))
}

fn cam_neg() -> Switches {
    axis(PositionInput::window(-CAM_HI, -CAM_LO))
}

#[test]
fn c072_c083_method_7_centred_switch_and_index_three_starts() {
    let reference = index_below(CAM_LO);
    // below the cam: positive search onto the lower edge
    home(Case::new(7, cam_pos(), reference, INDEX_TOL));
    // on the cam: creeps off negative at once
    let on = home(Case::new(7, cam_pos(), reference, INDEX_TOL).from((CAM_LO + CAM_HI) / 2));
    assert!(on.max < CAM_HI, "stayed below the upper edge: {on:?}");
    // above the cam: +LS reverses the search without a fault (C-083)
    let above = home(Case::new(7, cam_pos(), reference, INDEX_TOL).from(CAM_HI + R / 2));
    assert!(above.max >= POS_LS, "reversed at +LS: {above:?}");
}

#[test]
fn c073_method_23_centred_switch_edge_three_starts() {
    home(Case::new(23, cam_pos(), CAM_LO, EDGE_TOL));
    home(Case::new(23, cam_pos(), CAM_LO, EDGE_TOL).from((CAM_LO + CAM_HI) / 2));
    let above = home(Case::new(23, cam_pos(), CAM_LO, EDGE_TOL).from(CAM_HI + R / 2));
    assert!(above.max >= POS_LS, "reversed at +LS: {above:?}");
}

#[test]
fn c074_c083_method_11_centred_switch_and_index_three_starts() {
    let reference = index_above(-CAM_LO);
    home(Case::new(11, cam_neg(), reference, INDEX_TOL));
    let on = home(Case::new(11, cam_neg(), reference, INDEX_TOL).from(-(CAM_LO + CAM_HI) / 2));
    assert!(on.min > -CAM_HI, "stayed above the lower edge: {on:?}");
    let below = home(Case::new(11, cam_neg(), reference, INDEX_TOL).from(-CAM_HI - R / 2));
    assert!(below.min < NEG_LS, "reversed at −LS: {below:?}");
}

#[test]
fn c075_method_27_centred_switch_edge_three_starts() {
    home(Case::new(27, cam_neg(), -CAM_LO, EDGE_TOL));
    home(Case::new(27, cam_neg(), -CAM_LO, EDGE_TOL).from(-(CAM_LO + CAM_HI) / 2));
    let below = home(Case::new(27, cam_neg(), -CAM_LO, EDGE_TOL).from(-CAM_HI - R / 2));
    assert!(below.min < NEG_LS, "reversed at −LS: {below:?}");
}

// ---------------------------------------------------------------------------
// Index pulse only (M, N), here (O)
// ---------------------------------------------------------------------------

#[test]
fn c076_method_33_next_index_pulse_negative() {
    let start = R / 10;
    let r = home(Case::new(33, axis(PositionInput::never()), index_below(start), INDEX_TOL).from(start));
    assert!(r.max <= start + R / 100, "negative only: {r:?}");
}

#[test]
fn c077_method_34_next_index_pulse_positive() {
    let start = R / 2;
    let r = home(Case::new(34, axis(PositionInput::never()), index_above(start), INDEX_TOL).from(start));
    assert!(r.min >= start - R / 100, "positive only: {r:?}");
}

#[test]
fn c078_methods_35_and_37_reference_here_without_motion() {
    let start = 3 * R / 10;
    for method in [35, 37] {
        let r = home(Case::new(method, axis(PositionInput::never()), start, 2).from(start));
        assert!(r.max - r.min < 50, "method {method}: no motion: {r:?}");
        assert!(r.ms < 10, "method {method}: at once: {r:?}");
    }
}

// ---------------------------------------------------------------------------
// Torque methods (P, Q, R, S) against rigid end stops
// ---------------------------------------------------------------------------

const STOP_LO: i64 = -R - R / 3;
const STOP_HI: i64 = R + R / 3;

fn torque_case(method: i8, reference: i64, tol: i64) -> Case {
    Case {
        limits: false,
        end_stops: Some((STOP_LO, STOP_HI)),
        ..Case::new(method, Switches::default(), reference, tol)
    }
}

#[test]
fn c079_method_minus_1_positive_torque_stop() {
    let r = home(torque_case(-1, STOP_HI, 50));
    assert!(r.max >= STOP_HI - 50, "drove into the stop: {r:?}");
}

#[test]
fn c081_method_minus_2_negative_torque_stop() {
    let r = home(torque_case(-2, STOP_LO, 50));
    assert!(r.min <= STOP_LO + 50, "drove into the stop: {r:?}");
}

#[test]
fn c080_method_minus_3_positive_torque_stop_then_index() {
    let r = home(torque_case(-3, index_below(STOP_HI), INDEX_TOL));
    assert!(r.max >= STOP_HI - 50, "drove into the stop: {r:?}");
}

#[test]
fn c082_method_minus_4_negative_torque_stop_then_index() {
    let r = home(torque_case(-4, index_above(STOP_LO), INDEX_TOL));
    assert!(r.min <= STOP_LO + 50, "drove into the stop: {r:?}");
}

// ---------------------------------------------------------------------------
// I30 = 2, halt, every code of 60E3h
// ---------------------------------------------------------------------------

#[test]
fn c086_limit_switch_as_reference_switch() {
    // I30 = 2: method 19 takes +LS as its home switch; no limit-switch fault
    let sim_case = Case::new(19, axis(PositionInput::never()), POS_LS, EDGE_TOL);
    let sim = line_with_switches(sim_case.switches);
    with_cyclic(&sim, async |m, sd| {
        // by SDO (issue 40): limit switches from the inputs, I30 = 2
        sd.sdo_write(I101, 0, 1u8).await.unwrap();
        sd.sdo_write(I102, 0, 1u8).await.unwrap();
        sd.sdo_write(I30, 0, 2u8).await.unwrap();
        sd.sdo_write(0x6098, 0, 19i8).await.unwrap();
        sd.sdo_write(0x607C, 0, HOME_OFFSET).await.unwrap();
        m.enable_in(6).await;
        m.set_controlword(CW_ENABLED | CW_BIT4);
        let done = m
            .run_until(10_000, |t| {
                t.state() != sw::OE || (t.bit(12) && t.bit(10)) || t.bit(13)
            })
            .await;
        assert!(done.is_some(), "finished: {:#06x}", m.tx.statusword);
        assert_eq!(
            m.tx.state(),
            sw::OE,
            "no limit-switch fault: {:#06x}",
            m.tx.statusword
        );
        assert!(
            m.tx.bit(12) && !m.tx.bit(13),
            "referenced on +LS: {:#06x}",
            m.tx.statusword
        );
        m.set_controlword(CW_ENABLED);
        let tx = m.run(20).await;
        let enc = sim.borrow().drives()[0].motors[0].position_inc_i64();
        let reads = i64::from(tx.position) - (enc - POS_LS);
        println!("I30 = 2, method 19 on +LS: the edge reads {reads}");
        assert!(
            (reads - i64::from(HOME_OFFSET)).abs() <= EDGE_TOL,
            "edge reads 607Ch: {reads}"
        );
    });
}

#[test]
fn c059_halt_interrupts_homing_then_restart_completes() {
    let sim = line_with_switches(axis(PositionInput::above(RS_POS)));
    with_cyclic(&sim, async |m, sd| {
        sd.sdo_write(0x6098, 0, 19i8).await.unwrap();
        m.enable_in(6).await;
        m.set_controlword(CW_ENABLED | CW_BIT4);
        m.run_until(2000, |t| t.velocity > REV).await.expect("searching");
        // halt (bit 8): the axis brakes, 000 while braking, then 001 interrupted at standstill
        m.set_controlword(CW_ENABLED | CW_BIT4 | CW_HALT);
        let stopped = m.run_until(2000, |t| t.bit(10) && !t.bit(12) && !t.bit(13)).await;
        assert!(stopped.is_some(), "interrupted = 001: {:#06x}", m.tx.statusword);
        m.run(30).await;
        assert!(
            m.tx.velocity.abs() < REV / 50,
            "at standstill: {} inc/s",
            m.tx.velocity
        );
        let at = m.tx.position;
        m.run(50).await;
        assert!((m.tx.position - at).abs() < REV / 100, "stays halted");
        // a new edge of bit 4 without halt restarts and completes
        m.set_controlword(CW_ENABLED);
        m.run(2).await;
        m.set_controlword(CW_ENABLED | CW_BIT4);
        let done = m.run_until(10_000, |t| t.bit(12) && t.bit(10)).await;
        assert!(done.is_some(), "restarted and done: {:#06x}", m.tx.statusword);
    });
}

#[test]
fn c060_every_method_of_60e3_is_accepted_by_6098() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).unwrap();
        let n: u8 = sd.sdo_read(0x60E3, 0).await.unwrap();
        assert_eq!(n, 0x14, "60E3h:00");
        let mut listed = Vec::new();
        for sub in 1..=n {
            let code: i8 = sd.sdo_read(0x60E3, sub).await.unwrap();
            sd.sdo_write(0x6098, 0, code)
                .await
                .expect("6098h accepts a listed method");
            let back: i8 = sd.sdo_read(0x6098, 0).await.unwrap();
            assert_eq!(back, code);
            listed.push(code);
        }
        listed.sort_unstable();
        assert_eq!(
            listed,
            [-4, -3, -2, -1, 1, 2, 3, 5, 7, 11, 17, 18, 19, 21, 23, 27, 33, 34, 35, 37]
        );
        for bad in [4i8, 6, 36, 38, -5] {
            assert!(sd.sdo_write(0x6098, 0, bad).await.is_err(), "6098h refuses {bad}");
        }
    });
}
