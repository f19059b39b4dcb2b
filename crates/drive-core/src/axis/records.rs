//! Record positioning: position records (J400 … J411,
//! [`crate::objects::records`]) run as tasks in the profile-position mode
//! (pp, 6060h = 1) instead of the CiA 402 set-point handshake, when a
//! personality gives the axis a [`RecordCommand`] each cycle
//! ([`Axis::set_record_command`]); without one, pp is CiA 402 pp, unchanged.
//!
//! - **Start** (P-082, P-134): a rising edge of [`RecordCommand::start`]
//!   with `enable` and `proceed` runs the record J402 names (0 … 254; 255 =
//!   the fieldbus record 266) with its target, profile velocity, end
//!   velocity, acceleration and deceleration. Record 266 takes absolute /
//!   relative and append / change immediately from the command, the stored
//!   records from their options (P-091 … P-093). Relative targets count from
//!   the present position set-point, or, when appended, from the target of
//!   the task they follow.
//! - **Append** (P-135): the task waits for the running one; **change
//!   immediately** (P-136) replaces it at once. One task can wait; while
//!   one does, [`RecordStatus::acknowledge`] stays set and a start is
//!   refused. **End velocity** (P-137): a task whose record has an end
//!   velocity passes its target at that velocity when a task waits behind
//!   it, and the next one goes on from there without a stop.
//! - **Cancel** (P-078, P-138): `enable` = 0 drops the tasks and brakes with
//!   the running task's deceleration; target reached is not set.
//!   **Intermediate stop** (P-080): `proceed` = 0 (or the CiA halt, bit 8)
//!   brakes with the task's deceleration and holds in position control;
//!   `proceed` = 1 resumes the same task.
//! - **Target reached** (P-104, P-105) only once the last task is done and
//!   the axis is in the position window (I22/I87); **stopped** (P-109):
//!   nothing planned and standstill (I199).
//! - **Software limits** (P-152): a task whose target lies outside
//!   607Dh (referenced axis) is not started ([`StartRefusal`]).
//! - **Override** J403 (P-149, P-150): 0 … 2000 ‰ of the profile velocity
//!   (times A340), re-planned when it changes, never the accelerations; a
//!   change while the axis brakes (a stop, the ramp onto the target) waits
//!   for the next task. Not saved, 1000 after a restart (P-151).
//! - **Jog** (P-086 … P-088, P-176): a rising edge of `jog_positive` /
//!   `jog_negative` while no task runs moves with record 259 / 260
//!   (velocity, acceleration, deceleration) on the core's jog (I26 position
//!   control stops at the software limits); releasing it decelerates;
//!   changes of the record act while jogging. Homing is its own mode, so
//!   jog inputs do nothing while it runs.
//! - **Set-up mode** (P-140): `setup_mode` caps the velocities of tasks and
//!   jog at J404, at once.
//! - **Holding brake** (C-021): CiA 402 pp opens it with the first set-point
//!   (6040h bit 4), which record positioning leaves clear; a task start or
//!   a jog input counts as that set-point for the device control, so the
//!   first task after the enable (and after a fault's reset) opens it.
//! - **Jerk**: none (the profile's "jerk filter 0", P-147); 60A4h is CiA
//!   402 pp's.
//!
//! The records are in user units; they are turned into increments when a
//! task starts (jog: every cycle). Nothing here runs in a cycle without a
//! [`RecordCommand`].

use super::record_state::{command_bits, command_of, status_bits, status_of};
use super::*;
use crate::objects::records::{
    Record, FIELDBUS, J402, J403, J404, JOG_NEGATIVE, JOG_POSITIVE, OPT_IMMEDIATE, OPT_RELATIVE,
};

/// What a personality asks of the record positioning, each cycle before
/// [`Axis::cycle`] (PROFIdrive: the CW1 bits named).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RecordCommand {
    /// Tasks allowed (CW1 bit 4): 0 cancels the tasks (P-078).
    pub enable: bool,
    /// No intermediate stop (CW1 bit 5): 0 stops, 1 resumes (P-080).
    pub proceed: bool,
    /// A rising edge starts the record J402 names (CW1 bit 6, P-082).
    pub start: bool,
    /// Record 266: relative to the present position set-point (CW1 bit 12, P-091).
    pub relative: bool,
    /// Record 266: change immediately instead of append (CW1 bit 13, P-092).
    pub immediate: bool,
    /// Jog positive with record 259 while set (CW1 bit 8, P-086).
    pub jog_positive: bool,
    /// Jog negative with record 260 while set (CW1 bit 9, P-087).
    pub jog_negative: bool,
    /// Set-up mode (a digital input or flag): velocities capped at J404 (P-140).
    pub setup_mode: bool,
}

/// Why a start was not taken (P-152, P-153: the "optional message").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StartRefusal {
    /// The target lies outside the software limits 607Dh.
    SoftwareLimit,
    /// An absolute target on an axis without reference (C-050).
    NotReferenced,
    /// A limit switch or the permitted direction refuses the move.
    Direction,
    /// The record's velocity or an acceleration is 0, or no such record.
    InvalidRecord,
    /// A task already waits behind the running one.
    Busy,
}

/// What the record positioning reports ([`Axis::record_status`]), after
/// the cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RecordStatus {
    /// Task acknowledgement (ZSW1 bit 12, P-108): set from a taken start
    /// until the start input falls, and while a task waits; clear = a new
    /// task can be accepted.
    pub acknowledge: bool,
    /// The last task is done and the axis is in the position window (P-104,
    /// P-105); not after a cancel.
    pub target_reached: bool,
    /// Nothing planned and the axis stands still (P-109).
    pub stopped: bool,
    /// The record of the running task.
    pub record: Option<u16>,
    /// A task waits behind it.
    pub waiting: bool,
    /// A jog runs (or decelerates).
    pub jogging: bool,
    /// The last start that was not taken, until the next taken one.
    pub refused: Option<StartRefusal>,
}

/// A task: its record in increments.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Task {
    pub(super) record: u16,
    /// Target, increments (resolved).
    pub(super) target: i32,
    /// Limits without override and caps.
    pub(super) limits: ProfileLimits,
    /// End velocity, inc/s.
    pub(super) end_velocity: f32,
}

/// A record in increments (from its user units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct RecordInc {
    record: u16,
    position: i32,
    velocity: f32,
    end_velocity: f32,
    acceleration: f32,
    deceleration: f32,
    options: u8,
}

/// The records and objects one cycle of record positioning needs, read
/// before the motion step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) struct RecordInputs {
    start: Option<RecordInc>,
    jog: Option<RecordInc>,
    /// J403, ‰.
    override_per_mille: u16,
    /// J404, inc/s.
    setup_speed: f32,
}

/// A jog on a record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct RecordJog {
    pub(super) record: u16,
    /// +1 / −1; 0 once released (decelerating).
    pub(super) dir: f32,
    pub(super) command: VelocityCommand,
}

/// The record positioning state of an axis. It is kept in the RAM image
/// (J411's last element, `record_state.rs`) rather than in [`Axis`] or
/// beside the image: every byte more in the axis or in the dictionary's
/// fields moves fields the csp cycle uses past the load/store immediates
/// (~220 bytes in the axis were ~16 instructions per cycle, 240 bytes
/// behind the image ~9); inside the image it costs nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RecordTasks {
    pub(super) command: Option<RecordCommand>,
    pub(super) prev: RecordCommand,
    pub(super) current: Option<Task>,
    pub(super) next: Option<Task>,
    pub(super) jog: Option<RecordJog>,
    /// Intermediate stop in effect.
    pub(super) halted: bool,
    /// The override the running task is planned with (0: paused).
    pub(super) planned_override: u16,
    /// Set-up mode when it was planned.
    pub(super) planned_setup: bool,
    /// The start input's acknowledgement latch.
    pub(super) ack: bool,
    /// The last task ended (target reached once in the window).
    pub(super) finished: bool,
    /// The last sample decelerated (|v| shrinking).
    pub(super) braking: bool,
    pub(super) refused: Option<StartRefusal>,
    pub(super) status: RecordStatus,
}

const NO_COMMAND: RecordCommand = RecordCommand {
    enable: false,
    proceed: false,
    start: false,
    relative: false,
    immediate: false,
    jog_positive: false,
    jog_negative: false,
    setup_mode: false,
};

impl RecordTasks {
    /// No command, no task.
    pub(crate) const IDLE: RecordTasks = RecordTasks {
        command: None,
        prev: NO_COMMAND,
        current: None,
        next: None,
        jog: None,
        halted: false,
        planned_override: 0,
        planned_setup: false,
        ack: false,
        finished: false,
        braking: false,
        refused: None,
        status: RecordStatus {
            acknowledge: false,
            target_reached: false,
            stopped: false,
            record: None,
            waiting: false,
            jogging: false,
            refused: None,
        },
    };

    /// Drops tasks and jog (mode change, stop, disable); keeps the command.
    pub(super) fn reset(&mut self) {
        *self = RecordTasks {
            command: self.command,
            prev: match self.command {
                Some(c) => c,
                None => NO_COMMAND,
            },
            ..RecordTasks::IDLE
        };
    }
}

/// Bit 12 of the packed record command: its start or a jog input is set
/// (shifted down by 8 it is 6040h bit 4, [`Axis::record_brake_trigger`]).
const RECORD_MOTION: u16 = CW_MODE_BIT4 << 8;

impl Axis {
    /// Sets the record command for the next cycles (`None`: pp is CiA 402
    /// pp). A personality calls this every cycle before
    /// [`cycle`](Self::cycle).
    pub fn set_record_command(&mut self, command: Option<RecordCommand>) {
        self.record_command = command.map_or(0, |c| {
            let motion = c.start || c.jog_positive || c.jog_negative;
            0x100 | u16::from(command_bits(&c)) | (u16::from(motion) * RECORD_MOTION)
        });
    }

    /// Sets the speed limit of the torque modes (both directions, inc/s,
    /// magnitude) in place of G472/G475 of the parameters; `None` goes back
    /// to them. A personality whose fieldbus carries the limit (PROFINET's
    /// 2416h.02, P-130) calls this before [`cycle`](Self::cycle); a
    /// non-finite or negative limit counts as 0 (the axis does not move).
    pub fn set_torque_mode_speed_limit(&mut self, limit_inc_per_s: Option<f32>) {
        let limit = match limit_inc_per_s {
            Some(v) if v.is_finite() && v > 0.0 => v,
            Some(_) => 0.0,
            None => f32::NAN,
        };
        if limit.to_bits() != self.torque_mode_speed_limit.to_bits() {
            self.torque_mode_speed_limit = limit;
            // the cascade takes it at the next configuration
            self.configured = None;
        }
    }

    /// Sets a torque limit in ‰ of the rated torque below 6072h (both
    /// directions; the lower of the two applies); `None` removes it. A
    /// personality whose fieldbus carries a current limit (PROFINET's
    /// 2415h.02 in speed control, P-133) calls this before
    /// [`cycle`](Self::cycle).
    pub fn set_torque_limit_per_mille(&mut self, limit: Option<u16>) {
        let limit = limit.unwrap_or(u16::MAX);
        if limit != self.torque_limit_per_mille {
            self.torque_limit_per_mille = limit;
            self.configured = None;
        }
    }

    /// 6040h bit 4 for the device control's brake release (C-021) while a
    /// record command is set: CiA 402 pp opens the holding brake with its
    /// first set-point (bit 4), record positioning leaves bit 4 clear and
    /// starts tasks and jogs with the command, so its start and jog inputs
    /// count as that set-point (0 without a command: pp unchanged).
    /// (Packed by [`set_record_command`](Self::set_record_command) as bit
    /// 12 of the command, [`RECORD_MOTION`]: one shift and mask per cycle,
    /// nothing to test on the EtherCAT path.)
    #[inline(always)]
    pub(super) fn record_brake_trigger(&self) -> u16 {
        (self.record_command >> 8) & CW_MODE_BIT4
    }

    /// The record command set by [`set_record_command`](Self::set_record_command).
    fn record_command(&self) -> Option<RecordCommand> {
        (self.record_command & 0x100 != 0).then(|| command_of(self.record_command as u8))
    }

    /// The record positioning's status after the last cycle (outside pp or
    /// without a command: no task, stopped at standstill).
    pub fn record_status(&self) -> RecordStatus {
        if matches!(self.running, Running::ProfilePosition(_)) && self.record_command != 0 {
            status_of(self.record_status)
        } else {
            RecordStatus {
                stopped: self.profile.is_standstill()
                    && is_standstill(self.velocity, self.params.velocity_window_inc_per_s),
                ..RecordStatus::default()
            }
        }
    }

    /// Reads what this cycle's record positioning needs: the start record
    /// on a start edge, the jog record, J403 and J404.
    fn record_inputs(
        &self,
        od: &mut DriveObjects,
        rt: &RecordTasks,
        cmd: &RecordCommand,
        o: &Snapshot,
    ) -> RecordInputs {
        let axis = self.window.axis;
        let prev = rt.prev;
        let param = |od: &DriveObjects, index: u16| od.get(self.window.manufacturer(index), 0).unwrap_or(0);
        let start = if cmd.start && !prev.start {
            let n = match param(od, J402) {
                n @ 0..=254 => n as u16,
                _ => FIELDBUS,
            };
            od.take_record(axis, n).map(|r| self.record_increments(n, &r, o))
        } else {
            None
        };
        let jog_record = match rt.jog {
            Some(j) => Some(j.record),
            None if cmd.jog_positive && !prev.jog_positive => Some(JOG_POSITIVE),
            None if cmd.jog_negative && !prev.jog_negative => Some(JOG_NEGATIVE),
            None => None,
        };
        let jog = jog_record.and_then(|n| od.take_record(axis, n).map(|r| self.record_increments(n, &r, o)));
        let setup = param(od, J404);
        RecordInputs {
            start,
            jog,
            override_per_mille: u16::try_from(param(od, J403)).unwrap_or(1000).min(2000),
            setup_speed: self.velocity_increments(u32::try_from(setup).unwrap_or(u32::MAX), o),
        }
    }

    fn velocity_increments(&self, v: u32, o: &Snapshot) -> f32 {
        let k = self.scaling.user_per_increment().abs() * o.decimal_factors().0;
        (f64::from(v) / k) as f32
    }

    fn record_increments(&self, n: u16, r: &Record, o: &Snapshot) -> RecordInc {
        let (_, fa) = o.decimal_factors();
        let k = self.scaling.user_per_increment().abs();
        let acc = |v: u32| (f64::from(v) / (k * fa)) as f32;
        RecordInc {
            record: n,
            position: sat_i32(
                self.scaling
                    .to_increments(i64::from(r.target))
                    .unwrap_or(i64::from(r.target)),
            ),
            velocity: self.velocity_increments(r.profile_velocity, o),
            end_velocity: self.velocity_increments(r.end_velocity, o),
            acceleration: acc(r.acceleration),
            deceleration: acc(r.deceleration),
            options: r.options,
        }
    }

    /// The velocity cap of this cycle: 607Fh, and J404 in set-up mode.
    fn record_velocity_cap(&self, inputs: &RecordInputs, o: &Snapshot, cmd: &RecordCommand) -> f32 {
        let cap = o.max_profile_velocity as f32;
        if cmd.setup_mode {
            cap.min(inputs.setup_speed)
        } else {
            cap
        }
    }

    /// `t`'s limits with the override `per_mille` (× A340) and the caps.
    fn task_limits(
        &self,
        inputs: &RecordInputs,
        t: &Task,
        o: &Snapshot,
        cmd: &RecordCommand,
        per_mille: u16,
    ) -> ProfileLimits {
        let v = t.limits.velocity * f32::from(per_mille) * 0.001 * override_factor(o);
        ProfileLimits {
            velocity: v.min(self.record_velocity_cap(inputs, o, cmd)),
            ..t.limits
        }
    }

    /// Plans the running task from the present state: passing its target
    /// at its end velocity when a task waits, else stopping on it; the
    /// override 0 pauses it.
    fn plan_task(&mut self, rt: &mut RecordTasks, inputs: &RecordInputs, o: &Snapshot, cmd: &RecordCommand) {
        let Some(t) = rt.current else {
            return;
        };
        let per_mille = inputs.override_per_mille;
        rt.planned_override = per_mille;
        rt.planned_setup = cmd.setup_mode;
        if per_mille == 0 || override_factor(o) == 0.0 {
            rt.planned_override = 0;
            let _ = self.profile.stop(t.limits.deceleration, t.limits.jerk);
            return;
        }
        let limits = self.task_limits(inputs, &t, o, cmd, per_mille);
        let ok = if rt.next.is_some() && t.end_velocity > 0.0 {
            self.profile
                .move_through(t.target, t.end_velocity.min(limits.velocity), limits)
                .is_ok()
        } else {
            self.profile
                .move_to(PositionTarget::Absolute(t.target), limits, SetMode::Immediate)
                .is_ok()
        };
        if !ok {
            rt.current = None;
        }
    }

    /// A start edge: the task of `r`, or why not.
    fn start_task(
        &mut self,
        rt: &mut RecordTasks,
        inputs: &RecordInputs,
        r: &RecordInc,
        o: &Snapshot,
        cmd: &RecordCommand,
    ) -> Result<(), StartRefusal> {
        let options = if r.record == FIELDBUS {
            (u8::from(cmd.relative) * OPT_RELATIVE) | (u8::from(cmd.immediate) * OPT_IMMEDIATE)
        } else {
            r.options
        };
        let running = rt.current.is_some();
        let immediate = options & OPT_IMMEDIATE != 0 || !running;
        if !immediate && rt.next.is_some() {
            return Err(StartRefusal::Busy);
        }
        let relative = options & OPT_RELATIVE != 0;
        let base = match (immediate, rt.current) {
            (false, Some(t)) => t.target,
            _ => self.sp_pos,
        };
        let target = if relative {
            if self
                .limits
                .relative_move_exceeds_computing_limit(i64::from(r.position))
            {
                return Err(StartRefusal::SoftwareLimit);
            }
            base.wrapping_add(r.position)
        } else {
            if self.params.absolute_needs_reference && !self.is_referenced() {
                return Err(StartRefusal::NotReferenced);
            }
            r.position
        };
        if self.limits.clamp_target(target, self.is_referenced()) != target {
            return Err(StartRefusal::SoftwareLimit);
        }
        if self.lock.refuses_move(base, target) {
            return Err(StartRefusal::Direction);
        }
        let task = Task {
            record: r.record,
            target,
            limits: ProfileLimits {
                velocity: r.velocity,
                acceleration: r.acceleration,
                deceleration: r.deceleration,
                jerk: f32::INFINITY,
            },
            end_velocity: r.end_velocity,
        };
        if task.limits.validate().is_err() {
            return Err(StartRefusal::InvalidRecord);
        }
        rt.finished = false;
        self.in_position.reset();
        if immediate {
            rt.current = Some(task);
            rt.next = None;
            if !rt.halted {
                self.plan_task(rt, inputs, o, cmd);
            }
        } else {
            rt.next = Some(task);
            // the running task now passes its target at its end velocity
            if !rt.halted && !rt.braking {
                self.plan_task(rt, inputs, o, cmd);
            }
        }
        Ok(())
    }

    /// One cycle of record positioning in pp (`halt`: the CiA halt, bit 8).
    #[allow(clippy::too_many_arguments)]
    #[inline(never)]
    pub(super) fn record_position(
        &mut self,
        od: &mut DriveObjects,
        o: &Snapshot,
        halt: bool,
        actual: i32,
        i199: bool,
        now_ns: Nanos,
        dt_ns: u32,
    ) -> Demand {
        let axis = self.window.axis;
        let mut rt = od.record_tasks(axis);
        rt.command = self.record_command();
        if self.record_fresh {
            // pp (re)activated: no task survives a mode change or a stop; an
            // input already set is no edge
            self.record_fresh = false;
            rt.reset();
        }
        let cmd = rt.command.unwrap_or_default();
        let inputs = self.record_inputs(od, &rt, &cmd, o);
        let prev = rt.prev;
        rt.prev = cmd;

        // cancel: tasks dropped, braked with the running task's deceleration
        if !cmd.enable {
            if let Some(t) = rt.current.or(rt.next) {
                let _ = self.profile.stop(t.limits.deceleration, t.limits.jerk);
            }
            rt.current = None;
            rt.next = None;
            rt.finished = false;
        }
        // intermediate stop and resume of the same task
        let stop = !cmd.proceed || halt;
        if stop && !rt.halted {
            rt.halted = true;
            if let Some(t) = rt.current {
                let _ = self.profile.stop(t.limits.deceleration, t.limits.jerk);
            }
        } else if !stop && rt.halted {
            rt.halted = false;
            self.plan_task(&mut rt, &inputs, o, &cmd);
        }
        if !cmd.start {
            rt.ack = false;
        }
        if let Some(r) = inputs.start {
            let idle = rt.jog.is_none();
            if cmd.enable && cmd.proceed && !halt && idle {
                match self.start_task(&mut rt, &inputs, &r, o, &cmd) {
                    Ok(()) => {
                        rt.ack = true;
                        rt.refused = None;
                    }
                    Err(why) => rt.refused = Some(why),
                }
            }
        }
        // override and set-up mode: re-planned unless the axis brakes (P-150)
        let running = rt.current.is_some() && !rt.halted;
        let changed = inputs.override_per_mille != rt.planned_override || cmd.setup_mode != rt.planned_setup;
        if running && changed && !rt.braking {
            self.plan_task(&mut rt, &inputs, o, &cmd);
        }

        let d = if rt.current.is_none() && rt.next.is_none() {
            self.record_jog(&mut rt, &cmd, &prev, &inputs, o, dt_ns)
        } else {
            None
        };
        let d = match d {
            Some(d) => d,
            None => {
                let s = self.profile.step(dt_ns);
                self.record_progress(&mut rt, &inputs, &s, o, &cmd);
                Demand {
                    position: s.position,
                    velocity: s.velocity,
                    acceleration: s.acceleration,
                    ..Demand::hold(s.position)
                }
            }
        };
        rt.braking = d.velocity * d.acceleration < 0.0;

        let target = self.profile.target();
        let reached = rt.finished
            && rt.current.is_none()
            && self
                .in_position
                .update(target, actual, self.profile.is_standstill(), now_ns);
        let acknowledge = rt.ack || rt.next.is_some();
        rt.status = RecordStatus {
            acknowledge,
            target_reached: reached,
            stopped: self.profile.is_standstill() && i199,
            record: rt.current.map(|t| t.record),
            waiting: rt.next.is_some(),
            jogging: rt.jog.is_some(),
            refused: rt.refused,
        };
        od.set_record_tasks(axis, &rt);
        self.record_status = status_bits(&rt.status);
        let mut bits = 0;
        if reached {
            bits |= SW_TARGET_REACHED;
        }
        if acknowledge {
            bits |= SW_MODE_BIT12;
        }
        Demand { bits, ..d }
    }

    /// After the generator's step: the running task done (on its target,
    /// or passed at its end velocity) → the waiting task starts from there.
    fn record_progress(
        &mut self,
        rt: &mut RecordTasks,
        inputs: &RecordInputs,
        s: &motion::ProfileSample,
        o: &Snapshot,
        cmd: &RecordCommand,
    ) {
        let Some(t) = rt.current else {
            return;
        };
        let paused = rt.halted || rt.planned_override == 0;
        let done = self.profile.passed() || (!paused && s.done && s.position == t.target);
        if !done {
            return;
        }
        rt.current = rt.next.take();
        if rt.current.is_some() {
            self.plan_task(rt, inputs, o, cmd);
        } else {
            rt.finished = true;
        }
    }

    /// Jog on records 259/260 while no task runs; `None`: no jog.
    fn record_jog(
        &mut self,
        rt: &mut RecordTasks,
        cmd: &RecordCommand,
        prev: &RecordCommand,
        inputs: &RecordInputs,
        o: &Snapshot,
        dt_ns: u32,
    ) -> Option<Demand> {
        if rt.jog.is_none() {
            let dir = match (
                cmd.jog_positive && !prev.jog_positive,
                cmd.jog_negative && !prev.jog_negative,
            ) {
                (true, false) if !cmd.jog_negative => 1.0,
                (false, true) if !cmd.jog_positive => -1.0,
                _ => return None,
            };
            let r = inputs.jog?;
            rt.finished = false;
            rt.jog = Some(RecordJog {
                record: r.record,
                dir,
                command: VelocityCommand::default(),
            });
        }
        let mut jog = rt.jog?;
        let held = if jog.dir > 0.0 {
            cmd.jog_positive
        } else {
            cmd.jog_negative
        };
        if !held {
            jog.dir = 0.0;
        }
        let r = inputs.jog?;
        let limits = ProfileLimits {
            velocity: r.velocity.min(self.record_velocity_cap(inputs, o, cmd)),
            acceleration: r.acceleration,
            deceleration: r.deceleration,
            jerk: f32::INFINITY,
        };
        if limits.validate().is_err() {
            jog.dir = 0.0;
        }
        // a changed record velocity re-commands the jog (P-176): the core
        // jog re-plans whenever the commanded velocity changes
        let stop_limits = ProfileLimits {
            deceleration: if limits.deceleration > 0.0 {
                limits.deceleration
            } else {
                o.quick_stop_deceleration as f32
            },
            ..limits
        };
        let d = self.jog_with(&mut jog.command, jog.dir, stop_limits, dt_ns);
        rt.jog = if jog.dir == 0.0 && self.profile.is_standstill() {
            None
        } else {
            Some(jog)
        };
        Some(d)
    }
}
