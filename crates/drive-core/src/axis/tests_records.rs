//! Record positioning, jog records, override and set-up mode through the
//! axis API ([`Axis::set_record_command`], [`Axis::record_status`]) in
//! simulated time against a rigid-body motor (J = 1e-4 kg·m², one cycle of
//! actuation delay), axis A in pp (6060h = 1).

use super::*;
use crate::objects::records::{
    Record, FIELDBUS, J400, J401, J402, J403, J404, JOG_POSITIVE, OPT_IMMEDIATE, OPT_RELATIVE,
};
use crate::params::I46;

const DT_NS: u64 = 1_000_000;
const REV_I: i32 = 1 << 20;
const REV_F: f32 = REV_I as f32;

/// Rigid body in increments: J·dω/dt = τ(t − 1 cycle) − b·ω.
struct Motor {
    position: f64,
    velocity: f64,
    pending: f64,
}

impl Motor {
    fn step(&mut self, cmd: &AxisCommand) {
        let torque = self.pending;
        self.pending = if cmd.power_stage {
            f64::from(cmd.torque_nm)
        } else {
            0.0
        };
        let (j, b) = (1e-4, 1e-4);
        let to_inc = f64::from(REV_I) / core::f64::consts::TAU;
        const SUB: u32 = 20;
        let h = DT_NS as f64 * 1e-9 / f64::from(SUB);
        for _ in 0..SUB {
            let omega = self.velocity / to_inc;
            let a = (torque - b * omega) / j;
            self.velocity += a * to_inc * h;
            self.position += self.velocity * h;
        }
    }
}

struct Rig {
    od: DriveObjects,
    axis: Axis,
    motor: Motor,
    now: Nanos,
    cmd: RecordCommand,
    /// Position set-point velocity (607Ah…: from 6064h differences is too
    /// noisy; the axis' own set-point), inc/s, per cycle.
    sp_velocity: f32,
    /// The last cycle's brake command: released.
    brake_release: bool,
}

impl Rig {
    /// Axis A enabled in pp with a record command (tasks allowed, no stop).
    fn new() -> Self {
        let mut r = Rig {
            od: DriveObjects::new(),
            axis: Axis::new(0),
            motor: Motor {
                position: 0.0,
                velocity: 0.0,
                pending: 0.0,
            },
            now: Nanos::ZERO,
            cmd: RecordCommand {
                enable: true,
                proceed: true,
                ..RecordCommand::default()
            },
            sp_velocity: 0.0,
            brake_release: false,
        };
        r.axis.params_mut().absolute_needs_reference = false;
        r.od.set(0x6060, 0, 1).unwrap();
        for cw in [0x06, 0x07, 0x0F] {
            r.od.set(0x6040, 0, cw).unwrap();
            r.run(5);
        }
        assert_eq!(r.axis.state(), State::OperationEnabled);
        assert_eq!(r.axis.mode(), Mode::ProfilePosition);
        r
    }

    fn cycle(&mut self) -> RecordStatus {
        self.axis.set_record_command(Some(self.cmd));
        let io = AxisIo::ready(self.motor.position.round() as i32);
        let report = self.axis.cycle(&mut self.od, &io, self.now, false);
        self.motor.step(&report.command);
        self.brake_release = report.command.brake_release;
        self.now = self.now.saturating_add(Nanos::from_ns(DT_NS));
        self.sp_velocity = self.axis.sp_vel;
        self.axis.record_status()
    }

    fn run(&mut self, n: usize) -> RecordStatus {
        let mut s = RecordStatus::default();
        for _ in 0..n {
            s = self.cycle();
        }
        s
    }

    /// Runs until `f` holds (at most `max` cycles); the cycle count.
    fn run_until(&mut self, max: usize, mut f: impl FnMut(&Rig, &RecordStatus) -> bool) -> Option<usize> {
        (1..=max).find(|_| {
            let s = self.cycle();
            f(self, &s)
        })
    }

    fn position(&self) -> i32 {
        self.od.get(0x6064, 0).unwrap() as i32
    }

    fn setpoint(&self) -> i32 {
        self.axis.sp_pos
    }

    fn sw(&self) -> u16 {
        self.od.get(0x6041, 0).unwrap() as u16
    }

    /// [`Rig::new`] with the fieldbus record ([`Rig::record`]) started.
    fn started(target_rev: f32, v: f32, ve: f32, acc: f32, options: u8) -> Self {
        let mut r = Rig::new();
        r.record(FIELDBUS, target_rev, v, ve, acc, options);
        r.start(FIELDBUS);
        r
    }

    /// Record `n` with target (rev), profile velocity (rev/s), end velocity
    /// (rev/s), acceleration = deceleration (rev/s²), options.
    fn record(&mut self, n: u16, target_rev: f32, v: f32, ve: f32, acc: f32, options: u8) {
        let r = Record {
            target: (target_rev * REV_F) as i32,
            profile_velocity: (v * REV_F) as u32,
            end_velocity: (ve * REV_F) as u32,
            acceleration: (acc * REV_F) as u32,
            deceleration: (acc * REV_F) as u32,
            options,
        };
        assert!(self.od.set_record(0, n, &r));
    }

    /// A start edge for record `n` (J402; 266 as 255).
    fn start(&mut self, n: u16) -> RecordStatus {
        let number = if n == FIELDBUS { 255 } else { i64::from(n) };
        self.od.set(J402, 0, number).unwrap();
        self.cmd.start = true;
        let s = self.cycle();
        self.cmd.start = false;
        s
    }
}

fn rev(inc: i32) -> f32 {
    inc as f32 / REV_F
}

/// P-134, P-146, P-104: a start runs record 266 (J402 = 255) to its target
/// at its profile velocity; target reached and stopped at the end.
#[test]
fn p134_p146_start_runs_record_266_to_its_target() {
    let mut r = Rig::new();
    r.record(FIELDBUS, 3.0, 5.0, 0.0, 50.0, 0);
    let s = r.start(FIELDBUS);
    assert!(s.acknowledge, "task taken");
    assert_eq!(s.record, Some(FIELDBUS));
    let mut vmax = 0.0f32;
    let done = r.run_until(3000, |r, s| {
        vmax = vmax.max(r.sp_velocity);
        s.target_reached
    });
    assert!(done.is_some(), "target reached");
    assert!(
        (vmax / REV_F - 5.0).abs() < 0.01,
        "profile velocity {}",
        vmax / REV_F
    );
    assert_eq!(r.setpoint(), 3 * REV_I);
    let s = r.run(20);
    assert!(s.stopped && s.target_reached && s.record.is_none());
    assert!(r.sw() & SW_TARGET_REACHED != 0, "6041h bit 10 too");
    assert!((rev(r.position()) - 3.0).abs() < 0.01);
}

/// P-146: J402 0…254 start that stored record; another record's values do
/// not leak in.
#[test]
fn p146_start_number_selects_the_stored_record() {
    let mut r = Rig::new();
    r.record(7, -2.0, 4.0, 0.0, 40.0, 0);
    r.record(FIELDBUS, 9.0, 4.0, 0.0, 40.0, 0);
    r.start(7);
    assert!(r.run_until(3000, |_, s| s.target_reached).is_some());
    assert_eq!(r.setpoint(), -2 * REV_I);
}

/// P-135, P-105, P-108: an appended task waits for the running one (the
/// acknowledgement stays set while it waits, a third start is refused);
/// target reached only after the last task.
#[test]
fn p135_p105_append_runs_after_the_running_task_reached_only_at_the_end() {
    let mut r = Rig::started(2.0, 5.0, 0.0, 50.0, 0);
    r.run(50);
    r.record(FIELDBUS, 4.0, 5.0, 0.0, 50.0, 0);
    let s = r.start(FIELDBUS);
    assert!(s.waiting && s.acknowledge);
    let s = r.run(3);
    assert!(s.acknowledge, "P-108: no new job while one waits");
    let s = r.start(FIELDBUS);
    assert_eq!(s.refused, Some(StartRefusal::Busy));
    let mut reached_early = false;
    let mut max = i32::MIN;
    let done = r.run_until(4000, |r, s| {
        max = max.max(r.setpoint());
        if s.target_reached && r.setpoint() != 4 * REV_I {
            reached_early = true;
        }
        s.target_reached
    });
    assert!(done.is_some());
    assert!(!reached_early, "P-105: bit 10 only after the last task");
    assert_eq!(max, 4 * REV_I, "no overshoot");
    let s = r.run(2);
    assert!(!s.acknowledge, "P-108: a new job can be accepted");
}

/// P-136, P-092: change immediately drops the running task for the new one
/// (record 266 with the command's bit).
#[test]
fn p136_p092_change_immediately_replaces_the_running_task() {
    let mut r = Rig::started(10.0, 5.0, 0.0, 50.0, 0);
    r.run(300);
    assert!(r.setpoint() > REV_I);
    r.record(FIELDBUS, 1.0, 5.0, 0.0, 50.0, 0);
    r.cmd.immediate = true;
    r.start(FIELDBUS);
    let mut max = 0;
    assert!(r
        .run_until(4000, |r, s| {
            max = max.max(r.setpoint());
            s.target_reached
        })
        .is_some());
    assert_eq!(r.setpoint(), REV_I);
    assert!(max < 5 * REV_I, "never went on to 10 rev: {}", rev(max));
}

/// P-137: a task with an end velocity passes its target at that velocity
/// into the appended one (no stop in between).
#[test]
fn p137_end_velocity_chains_two_tasks_without_a_stop() {
    let mut r = Rig::started(3.0, 5.0, 2.0, 50.0, 0);
    r.run(20);
    r.record(FIELDBUS, 6.0, 2.0, 0.0, 50.0, 0);
    r.start(FIELDBUS);
    let mut vmin_after_start = f32::INFINITY;
    let mut at_first = None;
    assert!(r
        .run_until(6000, |r, s| {
            if r.setpoint() > REV_I && r.setpoint() < 6 * REV_I - REV_I / 4 {
                vmin_after_start = vmin_after_start.min(r.sp_velocity);
            }
            if at_first.is_none() && r.setpoint() >= 3 * REV_I {
                at_first = Some(r.sp_velocity);
            }
            s.target_reached
        })
        .is_some());
    let v = at_first.unwrap() / REV_F;
    assert!((v - 2.0).abs() < 0.05, "velocity at the first target {v} rev/s");
    assert!(
        vmin_after_start / REV_F > 1.95,
        "no stop: {}",
        vmin_after_start / REV_F
    );
    assert_eq!(r.setpoint(), 6 * REV_I);
}

/// P-078, P-138: enable = 0 cancels: braked with the task's deceleration
/// (stopping distance v²/2d), the task is dropped, target reached not set.
#[test]
fn p078_p138_cancel_brakes_with_the_task_deceleration() {
    let mut r = Rig::started(20.0, 5.0, 0.0, 25.0, 0);
    r.run(600);
    assert!((r.sp_velocity / REV_F - 5.0).abs() < 0.01);
    let from = r.setpoint();
    r.cmd.enable = false;
    let mut reached = false;
    let s = r.run_until(2000, |_, s| {
        reached |= s.target_reached;
        s.stopped
    });
    assert!(s.is_some());
    assert!(!reached, "target reached is not set");
    let s = r.run(5);
    assert!(s.record.is_none() && !s.target_reached);
    let dist = rev(r.setpoint() - from);
    assert!((dist - 0.5).abs() < 0.02, "5²/(2·25) = 0.5 rev, got {dist}");
    // the dropped task does not come back
    r.cmd.enable = true;
    let s = r.run(100);
    assert!(s.stopped && s.record.is_none());
}

/// P-080: proceed = 0 stops in position control and holds; 1 resumes the
/// same task to its target.
#[test]
fn p080_intermediate_stop_holds_and_resumes_the_same_task() {
    let mut r = Rig::started(6.0, 5.0, 0.0, 50.0, 0);
    r.run(400);
    r.cmd.proceed = false;
    assert!(r.run_until(1000, |_, s| s.stopped).is_some());
    let held = r.setpoint();
    let s = r.run(200);
    assert_eq!(r.setpoint(), held, "holds");
    assert!(held < 6 * REV_I && s.record == Some(FIELDBUS) && !s.target_reached);
    r.cmd.proceed = true;
    assert!(r.run_until(3000, |_, s| s.target_reached).is_some());
    assert_eq!(r.setpoint(), 6 * REV_I);
}

/// P-091: relative (record 266 with the command's bit) counts from the
/// present position set-point.
#[test]
fn p091_relative_counts_from_the_position_setpoint() {
    let mut r = Rig::started(2.0, 5.0, 0.0, 50.0, 0);
    assert!(r.run_until(3000, |_, s| s.target_reached).is_some());
    r.record(FIELDBUS, -0.5, 5.0, 0.0, 50.0, 0);
    r.cmd.relative = true;
    r.run(2);
    r.start(FIELDBUS);
    assert!(r.run_until(3000, |_, s| s.target_reached).is_some());
    assert_eq!(r.setpoint(), 2 * REV_I - REV_I / 2);
}

/// P-093: a stored record uses its own options, not the command's bits.
#[test]
fn p093_stored_records_use_their_own_options() {
    let mut r = Rig::new();
    r.record(3, 1.0, 5.0, 0.0, 50.0, OPT_RELATIVE);
    r.cmd.relative = false;
    for k in 1..=2 {
        r.start(3);
        assert!(r.run_until(3000, |_, s| s.target_reached).is_some());
        assert_eq!(r.setpoint(), k * REV_I, "relative by its option");
    }
    // absolute record, the command asks relative: absolute
    r.record(4, 0.5, 5.0, 0.0, 50.0, OPT_IMMEDIATE);
    r.cmd.relative = true;
    r.start(4);
    assert!(r.run_until(3000, |_, s| s.target_reached).is_some());
    assert_eq!(r.setpoint(), REV_I / 2);
}

/// P-152: a target beyond the software limits (referenced axis) is not
/// started, with the refusal; one inside is.
#[test]
fn p152_software_limits_block_the_start() {
    let mut r = Rig::new();
    r.od.set(I46, 0, 5).unwrap();
    r.od.set(0x607D, 1, i64::from(-5 * REV_I)).unwrap();
    r.od.set(0x607D, 2, i64::from(5 * REV_I)).unwrap();
    r.run(2);
    assert!(r.axis.is_referenced());
    r.record(FIELDBUS, 6.0, 5.0, 0.0, 50.0, 0);
    let s = r.start(FIELDBUS);
    assert_eq!(s.refused, Some(StartRefusal::SoftwareLimit));
    assert!(!s.acknowledge && s.record.is_none());
    let s = r.run(100);
    assert!(s.stopped);
    assert_eq!(r.setpoint(), 0, "no motion");
    r.record(FIELDBUS, 4.0, 5.0, 0.0, 50.0, 0);
    let s = r.start(FIELDBUS);
    assert_eq!(s.refused, None);
    assert!(r.run_until(3000, |_, s| s.target_reached).is_some());
}

/// P-149, P-150: J403 scales the velocity of the running task at once (500
/// ‰ halves it) without touching the accelerations; 0 pauses, 1000 goes on.
#[test]
fn p149_p150_override_scales_the_running_velocity() {
    let mut r = Rig::started(30.0, 4.0, 0.0, 40.0, 0);
    r.run(300);
    assert!((r.sp_velocity / REV_F - 4.0).abs() < 0.01);
    r.od.set(J403, 0, 500).unwrap();
    // 2 rev/s less at 40 rev/s²: 50 ms
    r.run(45);
    assert!(
        r.sp_velocity / REV_F > 2.05,
        "decelerates with the record's deceleration"
    );
    r.run(20);
    assert!(
        (r.sp_velocity / REV_F - 2.0).abs() < 0.01,
        "{}",
        r.sp_velocity / REV_F
    );
    r.od.set(J403, 0, 0).unwrap();
    assert!(r.run_until(500, |_, s| s.stopped).is_some(), "0 pauses");
    let s = r.run(10);
    assert!(s.record.is_some() && !s.target_reached);
    r.od.set(J403, 0, 2000).unwrap();
    r.run(400);
    assert!((r.sp_velocity / REV_F - 8.0).abs() < 0.01, "2000 ‰ doubles");
}

/// P-150: no effect while braking: an override change during a cancel's
/// ramp leaves its stopping distance alone.
#[test]
fn p150_override_has_no_effect_while_braking() {
    let mut r = Rig::started(20.0, 5.0, 0.0, 25.0, 0);
    r.run(600);
    let from = r.setpoint();
    r.cmd.proceed = false;
    r.run(20);
    r.od.set(J403, 0, 2000).unwrap();
    assert!(r.run_until(2000, |_, s| s.stopped).is_some());
    assert!((rev(r.setpoint() - from) - 0.5).abs() < 0.02);
}

/// P-086, P-176: a rising jog-positive edge moves at record 259's velocity;
/// a change of the record acts while jogging; releasing decelerates to a
/// stop.
#[test]
fn p086_p176_jog_positive_with_record_259() {
    let mut r = Rig::new();
    r.record(JOG_POSITIVE, 0.0, 2.0, 0.0, 20.0, 0);
    r.cmd.jog_positive = true;
    let s = r.run(300);
    assert!(s.jogging);
    assert!((r.sp_velocity / REV_F - 2.0).abs() < 0.01);
    // P-176: through the window, as a bus would
    r.od.set(J400, 0, i64::from(JOG_POSITIVE)).unwrap();
    use od::Dictionary;
    let v = ((3.0 * REV_F) as u32).to_le_bytes();
    r.od.write(J401, 2, &v, od::CommState::Op).unwrap();
    r.run(200);
    assert!(
        (r.sp_velocity / REV_F - 3.0).abs() < 0.01,
        "{}",
        r.sp_velocity / REV_F
    );
    r.cmd.jog_positive = false;
    assert!(r.run_until(1000, |_, s| s.stopped && !s.jogging).is_some());
    assert!(r.position() > 0);
}

/// P-087, P-177: jog negative with record 260's defaults (100 rpm).
#[test]
fn p087_p177_jog_negative_with_the_default_record_260() {
    let mut r = Rig::new();
    r.cmd.jog_negative = true;
    r.run(500);
    let rpm = -r.sp_velocity / REV_F * 60.0;
    assert!((rpm - 100.0).abs() < 0.1, "{rpm} rpm");
    r.cmd.jog_negative = false;
    assert!(r.run_until(1000, |_, s| s.stopped).is_some());
    assert!(r.setpoint() < 0);
}

/// P-088: jog inputs do nothing while homing runs (its own mode), and a jog
/// input held into pp is no edge.
#[test]
fn p088_jog_ignored_during_homing() {
    let mut r = Rig::new();
    r.od.set(0x6060, 0, 6).unwrap();
    r.od.set(0x6098, 0, 37).unwrap();
    r.run(3);
    r.cmd.jog_positive = true;
    r.run(200);
    assert_eq!(r.setpoint(), 0);
    r.od.set(0x6060, 0, 1).unwrap();
    let s = r.run(200);
    assert!(!s.jogging);
    assert_eq!(r.setpoint(), 0);
}

/// P-140, P-183: set-up mode caps task velocities at J404.
#[test]
fn p140_setup_mode_caps_the_velocity() {
    let mut r = Rig::new();
    r.od.set(J404, 0, i64::from(REV_I)).unwrap();
    r.cmd.setup_mode = true;
    r.record(FIELDBUS, 5.0, 5.0, 0.0, 50.0, 0);
    r.start(FIELDBUS);
    r.run(500);
    assert!(
        (r.sp_velocity / REV_F - 1.0).abs() < 0.01,
        "{}",
        r.sp_velocity / REV_F
    );
    r.cmd.setup_mode = false;
    r.run(300);
    assert!((r.sp_velocity / REV_F - 5.0).abs() < 0.01);
}

/// Without a record command pp stays CiA 402 pp: a bit-4 edge moves to
/// 607Ah; a start input means nothing.
#[test]
fn pp_without_a_record_command_is_cia402_pp() {
    let mut r = Rig::new();
    r.axis.set_record_command(None);
    r.od.set(0x607A, 0, i64::from(REV_I)).unwrap();
    for cw in [0x0F, 0x1F] {
        r.od.set(0x6040, 0, cw).unwrap();
        let io = AxisIo::ready(r.motor.position.round() as i32);
        let rep = r.axis.cycle(&mut r.od, &io, r.now, false);
        r.motor.step(&rep.command);
        r.now = r.now.saturating_add(Nanos::from_ns(DT_NS));
    }
    for _ in 0..2000 {
        let io = AxisIo::ready(r.motor.position.round() as i32);
        let rep = r.axis.cycle(&mut r.od, &io, r.now, false);
        r.motor.step(&rep.command);
        r.now = r.now.saturating_add(Nanos::from_ns(DT_NS));
    }
    assert_eq!(r.axis.sp_pos, REV_I);
    assert_eq!(
        r.axis.record_status(),
        RecordStatus {
            stopped: true,
            ..Default::default()
        }
    );
}

/// C-021 with P-082, P-086: in pp the brake opens with the first set-point
/// (6040h bit 4); record positioning leaves bit 4 clear and starts tasks
/// with the record command, so a task start or a jog opens it. It closes
/// with a fault and opens again at the first start after the reset and the
/// enable sequence (before, only a homing run did: every record move after
/// a fault dragged the engaged brake, 60F4h ~100 times larger).
#[test]
fn c021_p082_p086_a_record_start_or_jog_opens_the_brake() {
    let mut r = Rig::new();
    r.run(5);
    assert!(!r.brake_release, "enabled, no motion command yet: engaged");
    r.record(FIELDBUS, 1.0, 5.0, 0.0, 50.0, 0);
    r.start(FIELDBUS);
    assert!(r.brake_release, "the task start opens it");
    assert!(r.run_until(3000, |_, s| s.target_reached).is_some());
    assert!(r.brake_release, "open until the drive function goes off");
    // a fault closes it
    r.axis.raise_event(motion::Event { number: 44, cause: 1 });
    r.run(50);
    assert!(r.axis.state().is_fault());
    assert!(!r.brake_release, "fault: engaged");
    for cw in [0x80, 0x06, 0x07, 0x0F] {
        r.od.set(0x6040, 0, cw).unwrap();
        r.run(5);
    }
    assert_eq!(r.axis.state(), State::OperationEnabled);
    assert!(!r.brake_release, "enabled again, no motion command: engaged");
    r.record(FIELDBUS, 2.0, 5.0, 0.0, 50.0, 0);
    r.start(FIELDBUS);
    assert!(r.brake_release, "the first start after the reset opens it");
    assert!(r.run_until(3000, |_, s| s.target_reached).is_some());
    assert!((rev(r.position()) - 2.0).abs() < 0.01);
    // the jog records open it as well
    r.od.set(0x6040, 0, 0x07).unwrap();
    r.run(5);
    r.od.set(0x6040, 0, 0x0F).unwrap();
    r.run(5);
    assert!(!r.brake_release, "switched on and enabled again: engaged");
    r.record(JOG_POSITIVE, 0.0, 2.0, 0.0, 20.0, 0);
    r.cmd.jog_positive = true;
    r.run(1);
    assert!(r.brake_release, "a jog opens it");
    r.cmd.jog_positive = false;
    r.run(300);
}

/// P-104, P-105: at the end of an appended chain (the demo's: 3 rev at
/// 1000 rpm ending at 600 rpm, 6 rev at 600 ending at 300, 8 rev at 300,
/// 10 000 rpm/s) target reached comes once the last task is done in the
/// window and does not fall again while the axis stays in the window.
#[test]
fn p104_p105_target_reached_holds_at_the_end_of_an_appended_chain() {
    let mut r = Rig::new();
    let rps = |rpm: f32| rpm / 60.0;
    let acc = rps(10_000.0);
    let chain = [(3.0, 1000.0, 600.0), (6.0, 600.0, 300.0), (8.0, 300.0, 0.0)];
    for (k, (target, v, ve)) in chain.into_iter().enumerate() {
        r.record(FIELDBUS, target, rps(v), rps(ve), acc, 0);
        let s = r.start(FIELDBUS);
        assert!(s.acknowledge, "task {k} taken");
        // the start input falls; a waiting task keeps the acknowledge
        r.run_until(1000, |_, s| !s.acknowledge || k > 0)
            .expect("start released");
        if k > 0 {
            r.run_until(3000, |_, s| !s.waiting).expect("the next task runs");
        }
    }
    let window = r.od.get(crate::params::I22, 0).unwrap();
    let first = r
        .run_until(10_000, |_, s| s.target_reached)
        .expect("target reached");
    let mut trace = std::vec::Vec::new();
    for k in 0..500 {
        let s = r.cycle();
        let error = 8 * REV_I - r.position();
        trace.push((k, s.target_reached, error));
        if i64::from(error.unsigned_abs()) <= window {
            assert!(
                s.target_reached,
                "target reached fell {k} ms after it came at {first} ms, {error} inc from the target \
                 (window {window}): {:?}",
                &trace[trace.len().saturating_sub(8)..]
            );
        }
    }
}
