//! A record move after a drive fault, its acknowledgement and the FB's
//! enable sequence again (P-227, P-221): the move follows its profile as
//! closely as the same move without a fault before it. The cause found
//! (profinet-py's 60F4h of ~203 000 inc after the fault): record tasks
//! never opened the holding brake (C-021: pp opens it on 6040h bit 4, which
//! record positioning leaves clear), only a homing run did; a fault closes
//! it, so every record move after it dragged the brake. The set-point
//! itself follows the actual position while the drive function is off.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use hil_sim::fb::controller::PnController;
use hil_sim::fb::rig::FbRig;
use hil_sim::fb::{FbOutputs, OPMODE_POS};
use hil_sim::pn::Command;

const REV: i64 = 1 << 20;

common::fb_rig!(Rig);

impl Rig {
    fn new() -> Rig {
        let mut r = Rig(FbRig::connect(PnController::drive()).expect("connect"));
        assert!(r.until(100, |o| o.identifier != 0), "a response telegram");
        r.i.operation_mode = OPMODE_POS;
        r.i.all_accelerations_positioning = 6000;
        r
    }

    fn axis_value(&self, index: u16) -> i64 {
        let d = self.ctl.sim().drive();
        let a = d.axes().first().expect("axis A");
        d.objects().get(a.cia402_index(index), 0).unwrap_or(i64::MIN)
    }

    fn cycle(&mut self) {
        self.0.cycle().expect("exchange");
    }

    fn until(&mut self, ms: u64, done: impl Fn(&FbOutputs) -> bool) -> bool {
        self.0.until(ms, done).expect("exchange")
    }

    fn wait(&mut self, ms: u64) {
        for _ in 0..ms {
            self.cycle();
        }
    }

    fn enable(&mut self) {
        let enabled = self.0.enable_within(1000).expect("exchange");
        assert!(enabled, "enabled: {:#06x}", self.o.zsw1);
    }

    /// Event 44 on axis A, fault_reset, the enable sequence again.
    fn fault_reset_enable(&mut self) {
        self.ctl.sim_mut().command(Command::Fault {
            axis: 0,
            event: 44,
            cause: 1,
        });
        assert!(self.until(200, |o| o.fault), "fault: {:#06x}", self.o.zsw1);
        self.i.jog_pos = false;
        self.i.jog_neg = false;
        self.wait(50);
        self.i.fault_reset = true;
        assert!(self.until(200, |o| !o.fault), "reset: {:#06x}", self.o.zsw1);
        self.i.fault_reset = false;
        self.enable();
    }

    /// A relative record move of `milli_rev` at `rpm`: the largest |60F4h|
    /// on the way, how far the axis went (6064h) and whether the holding
    /// brake acted in any cycle of the move.
    fn record_move(&mut self, milli_rev: i32, rpm: i32) -> Move {
        assert!(self.until(2000, |o| !o.pos_task_ack), "ready for a task");
        let start = self.axis_value(0x6064);
        self.i.relative = true;
        self.i.change_immediatly = false;
        self.i.target_position = milli_rev;
        self.i.profile_velocity = rpm;
        self.i.end_velocity = 0;
        self.i.start_pos = true;
        let mut m = Move::default();
        let mut taken = false;
        for _ in 0..20_000 {
            self.cycle();
            m.worst_following_error = m.worst_following_error.max(self.axis_value(0x60F4).abs());
            let motor = self.ctl.sim().motor_outputs(0).expect("a motor step");
            // the brake as it acted from the cycle after the start on
            m.braked |= taken && motor.brake_applied;
            if !taken && self.o.pos_task_ack {
                taken = true;
                self.i.start_pos = false;
            }
            if taken && self.ctl.fresh() && self.o.target_reached && !self.o.pos_task_ack {
                break;
            }
        }
        assert!(taken, "the task was acknowledged");
        self.wait(200);
        m.moved = self.axis_value(0x6064) - start;
        m
    }
}

#[derive(Debug, Default, Clone, Copy)]
struct Move {
    worst_following_error: i64,
    moved: i64,
    braked: bool,
}

impl Move {
    fn show(self, label: &str) -> Move {
        println!(
            "figure: {label}: max |60F4h| {} inc, moved {} inc ({:.4} rev), brake acted {}",
            self.worst_following_error,
            self.moved,
            self.moved as f64 / REV as f64,
            self.braked
        );
        self
    }
}

/// Within this much of the commanded 3 rev (a creep of the profile's
/// rounding, well inside the target window of 1 degree = 2 913 inc).
const END_TOLERANCE: i64 = 2913;
/// The same 3 rev move at 600 rpm, 6000 rpm/s without a fault before it
/// follows within ~2 000 inc (profinet-py's P-221 figures); a dragging
/// brake or a set-point from before the fault gives 10 to 100 times more.
const FOLLOWING_LIMIT: i64 = 10_000;

fn check(m: Move, label: &str) {
    assert!(!m.braked, "{label}: the holding brake acted during the move");
    assert!(
        (m.moved - 3 * REV).abs() <= END_TOLERANCE,
        "{label}: moved {} inc, not 3 rev",
        m.moved
    );
    assert!(
        m.worst_following_error <= FOLLOWING_LIMIT,
        "{label}: following error up to {} inc",
        m.worst_following_error
    );
}

/// P-221: the first record move after enabling releases the holding brake
/// (CiA 402 pp releases it with the first set-point, 6040h bit 4; record
/// tasks start with CW1 bit 6 and leave bit 4 clear).
#[test]
fn p221_the_first_record_move_releases_the_brake() {
    let mut r = Rig::new();
    r.enable();
    check(r.record_move(3000, 600).show("first move"), "first move");
}

/// P-227 + P-221: after a fault at rest, fault_reset and the enable
/// sequence, the move is as good as before the fault.
#[test]
fn p227_a_record_move_after_fault_reset_and_enable_follows() {
    let mut r = Rig::new();
    r.enable();
    check(
        r.record_move(3000, 600).show("before the fault"),
        "before the fault",
    );
    r.fault_reset_enable();
    check(
        r.record_move(3000, 600).show("after the fault"),
        "after the fault",
    );
}

/// P-227 + P-225: the fault comes while the axis jogs (the motor coasts
/// out with the power stage off); after the reset and enable the move
/// starts from where the axis came to rest.
#[test]
fn p227_a_record_move_after_a_fault_while_jogging_follows() {
    let mut r = Rig::new();
    r.enable();
    r.i.jog_pos = true;
    r.i.jogging_velocity = 300;
    r.wait(300);
    assert!(
        r.o.velocity_actual_value > 100,
        "jogging: {} rpm",
        r.o.velocity_actual_value
    );
    r.fault_reset_enable();
    r.wait(500);
    check(
        r.record_move(3000, 600).show("after a fault while jogging"),
        "after jog + fault",
    );
}

/// A motor without holding brake coasts out after a fault while jogging
/// (the fault reaction ends at standstill, so the reset and the enable
/// come after it); the set-point starts from where the axis came to rest:
/// no jump at the enable, the move follows.
#[test]
fn p227_after_coasting_out_the_setpoint_starts_from_the_actual_position() {
    let mut r = Rig::new();
    let m = r.ctl.sim_mut().motor_mut(0).expect("axis A");
    m.params_mut().brake_holding_torque_nm = 0.0;
    r.enable();
    r.i.jog_pos = true;
    r.i.jogging_velocity = 600;
    r.wait(300);
    r.ctl.sim_mut().command(Command::Fault {
        axis: 0,
        event: 44,
        cause: 1,
    });
    assert!(r.until(200, |o| o.fault));
    r.i.jog_pos = false;
    // the fault reaction ends at standstill; the first reset edge after it
    // clears the fault
    let mut cleared = false;
    for _ in 0..100 {
        r.i.fault_reset = !r.i.fault_reset;
        if r.until(20, |o| !o.fault) {
            cleared = true;
            break;
        }
    }
    assert!(cleared, "reset: {:#06x}", r.o.zsw1);
    r.i.fault_reset = false;
    r.enable();
    println!("figure: enabled again at {} rpm", r.o.velocity_actual_value);
    let mut worst = 0;
    for _ in 0..300 {
        r.cycle();
        worst = worst.max(r.axis_value(0x60F4).abs());
    }
    println!("figure: after the enable: max |60F4h| {worst} inc");
    assert!(
        worst <= FOLLOWING_LIMIT,
        "following error up to {worst} inc after the enable"
    );
    let m = r.record_move(3000, 600).show("after coasting out");
    // the brake flag acts in the model without holding torque: not checked
    check(Move { braked: false, ..m }, "after coasting out");
}
