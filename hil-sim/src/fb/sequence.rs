//! The Example Function block's sequence against the simulated drive (the
//! demo of issue 17, `hil-sim demo --fieldbus profinet`): in-process,
//! simulated time, deterministic. The Python twin (profinet-py against
//! `serve --fieldbus profinet`) runs the same steps:
//!
//! 1. enable (P-219): 0x0406 → 0x0407 → 0x040F, each on its ZSW1 state;
//! 2. home (P-222): method 33 (index pulse, positive; the motor's index
//!    pulse is at 0 within each revolution) until `home_valid`;
//! 3. positioning (P-221): three absolute targets appended
//!    (`change_immediatly` = 0), the first two with end velocities (a
//!    gap-free chain, §8.4), then one relative move; `target_reached`;
//! 4. speed (P-223, P-220): operation mode 0x08, 300 rpm then 0,
//!    `velo_reached` / `velo_zero`;
//! 5. jog (P-225): `jog_pos` 0.5 s, then `jog_neg` 0.5 s;
//! 6. PKW (P-226): PNU 964.0, PNU 1100.0, CANopen 6065h read / write /
//!    read back / restore, and an unknown PNU (refused);
//! 7. fault (P-227): a drive event raised through the simulator's control
//!    channel, `fault` (ZSW1 bit 3), `fault_reset` (CW1 bit 7 rising edge),
//!    the fault gone, the FB's enable sequence again.
//!
//! With [`Options::self_tune`] a self-tuning phase (B44 identify mechanics
//! through PKW, `sequence/self_tune.rs`) runs between 1 and 2, so that the
//! positioning moves run on the gains and feedforward B44 set; the
//! positioning moves' following error is in [`Report::moves`] either way.
//!
//! Where the drive does what the spec says it should not, the run goes on
//! and says so in [`Report::deviations`] ("P-xxx: …").

use super::controller::PnController;
use super::pkw::{Access, Outcome, PkwClient};
pub use super::report::{MoveFe, Observer, Phase, PhaseResult, Report, Sample, SelfTuneResult, TargetResult};
use super::{state_name, ExampleFb, FbInputs, FbOutputs, OPMODE_POS, OPMODE_VELO};
use crate::electrical::PlantModel;
use crate::pcap::Recording;
use crate::pn::Command;
use nanos::Nanos;

mod self_tune;

/// Increments per revolution.
pub const INC_PER_REV: i64 = 1 << 20;

/// The positioning chain: absolute targets (1/1000 rev), profile velocity
/// and end velocity (rpm), appended one after the other.
pub const CHAIN: [(i32, i32, i32); 3] = [(3000, 1000, 600), (6000, 600, 300), (8000, 300, 0)];
/// The relative move after the chain, 1/1000 rev.
pub const RELATIVE_MOVE: i32 = -2000;
/// The speed segment's set-point, rpm.
pub const SPEED_RPM: i32 = 300;
/// The jog velocity, rpm.
pub const JOG_RPM: i32 = 200;
/// How long each jog bit is held, ms.
pub const JOG_MS: u64 = 500;
/// The homing method (PROFIdrive numbering, §8.5): index pulse, positive.
pub const HOMING_METHOD: i8 = 33;
/// The CANopen object the PKW phase writes: 6065h following error window.
pub const PKW_OBJECT: (u16, u8) = (0x6065, 0);

/// 1/1000 rev (the PROFINET position unit) as increments, rounded to nearest.
pub fn milli_rev_to_inc(v: i64) -> i64 {
    (v * INC_PER_REV + v.signum() * 500) / 1000
}

/// One run of the sequence in progress.
struct Run<'a, O: Observer> {
    ctl: PnController,
    fb: ExampleFb,
    i: FbInputs,
    pkw: PkwClient,
    o: FbOutputs,
    last_cw1: Option<u16>,
    responses: u64,
    /// Input frames without a response telegram.
    skipped: u64,
    set_inc: i32,
    obs: &'a mut O,
    report: Report,
    phase_start: Nanos,
    /// The PLC program's own CW1 state command OFF (0x..06, ready to switch
    /// on) in place of the FB's while `drive_enable` is 0: the self-tuning
    /// phase starts B44 in ready to switch on (E-141).
    hold_ready: bool,
    /// The running move's |60F4h| max, Σ 60F4h², cycles.
    move_fe: Option<(i64, f64, u64)>,
    /// In the self-tuning phase: B44's own loop moves the axis, 60F4h is
    /// no following error of the cascade (not in the run's maximum).
    in_self_tune: bool,
    /// [`Options::bandwidth_hz`].
    bandwidth_hz: Option<u16>,
}

fn bit(b: bool) -> u8 {
    u8::from(b)
}

/// The FB outputs whose changes are printed.
fn flags(o: &FbOutputs) -> [(&'static str, bool); 11] {
    [
        ("control_by_plc", o.control_by_plc),
        ("drive_is_enabled", o.drive_is_enabled),
        ("fault", o.fault),
        ("warning", o.warning),
        ("home_valid", o.home_valid),
        ("target_reached", o.target_reached),
        ("following_error", o.following_error),
        ("pos_task_ack", o.pos_task_ack),
        ("velo_zero", o.velo_zero),
        ("velo_reached", o.velo_reached),
        ("velo_exceeded", o.velo_exceeded),
    ]
}

impl<O: Observer> Run<'_, O> {
    fn axis_value(&self, index: u16) -> i64 {
        let d = self.ctl.sim().drive();
        d.axes()
            .first()
            .and_then(|a| d.objects().get(a.cia402_index(index), 0).ok())
            .unwrap_or(0)
    }

    fn line(&mut self, text: &str) {
        self.obs.line(self.ctl.now(), text);
    }

    fn deviation(&mut self, text: String) {
        if !self.report.deviations.contains(&text) {
            self.line(&format!("deviation: {text}"));
            self.report.deviations.push(text);
        }
    }

    /// One controller cycle; prints what changed.
    fn cycle(&mut self) -> Result<(), String> {
        self.pkw.inputs(&mut self.i);
        let mut telegram = self.fb.receive_telegram(&self.i);
        let mut cw1 = self.fb.cw1(&self.i);
        if self.hold_ready && !self.i.drive_enable {
            cw1 = cw1 & !0x000F | super::CMD_OFF;
            if let Some(w) = telegram.get_mut(2..4) {
                w.copy_from_slice(&cw1.to_be_bytes());
            }
        }
        if self.last_cw1 != Some(cw1) {
            let was = self.last_cw1.map_or("-".to_string(), |c| format!("{c:#06x}"));
            self.line(&format!("CW1 {was} -> {cw1:#06x}"));
            self.last_cw1 = Some(cw1);
        }
        let response = self.ctl.exchange(&telegram)?.map(<[u8]>::to_vec);
        for (t, e) in self.ctl.take_events() {
            self.obs.line(t, &e);
        }
        self.report.cycles += 1;
        if let (Some(r), true) = (response, self.ctl.fresh()) {
            self.take_response(&r)?;
        }
        let ferr = self.axis_value(0x60F4);
        if !self.in_self_tune {
            self.report.max_following_error_inc = self.report.max_following_error_inc.max(ferr.abs());
        }
        if let Some((max, sq, n)) = self.move_fe.as_mut() {
            *max = (*max).max(ferr.abs());
            *sq += (ferr as f64).powi(2);
            *n += 1;
        }
        let s = Sample {
            t: self.ctl.now(),
            zsw1: self.o.zsw1,
            set_inc: self.set_inc,
            pos_inc: self.axis_value(0x6064) as i32,
            vel_inc_s: self.axis_value(0x606C) as i32,
            torque_permille: self.axis_value(0x6077) as i16,
            ferr_inc: ferr as i32,
        };
        self.obs.sample(&s);
        Ok(())
    }

    /// Takes a response telegram into the FB's outputs and the PKW client.
    fn take_response(&mut self, r: &[u8]) -> Result<(), String> {
        let old = self.o;
        let Ok(new) = self.fb.response(r, self.i.drive_enable).copied() else {
            // no response telegram yet (the input data before the drive's
            // first one): nothing to take
            self.skipped += 1;
            if self.skipped > 100 {
                return Err(format!("no response telegram in 100 input frames: {r:02x?}"));
            }
            return Ok(());
        };
        self.pkw.outputs(&new);
        self.o = new;
        self.responses += 1;
        self.print_changes(&old, &new);
        if self.responses > 3 && !new.control_by_plc {
            self.deviation("P-103: ZSW1 bit 9 does not mirror CW1 bit 10".into());
        }
        Ok(())
    }

    fn print_changes(&mut self, old: &FbOutputs, new: &FbOutputs) {
        let mut parts = Vec::new();
        if old.zsw1 & 0x4F != new.zsw1 & 0x4F || old.identifier == 0 {
            parts.push(format!(
                "state {} -> {}",
                state_name(old.zsw1),
                state_name(new.zsw1)
            ));
        }
        if old.operation_mode_actual != new.operation_mode_actual {
            parts.push(format!(
                "operation_mode_actual {:#04x} -> {:#04x}",
                old.operation_mode_actual, new.operation_mode_actual
            ));
        }
        for ((name, a), (_, b)) in flags(old).iter().zip(flags(new).iter()) {
            if a != b {
                parts.push(format!("{name} {}->{}", bit(*a), bit(*b)));
            }
        }
        if old.pkw_access_status != new.pkw_access_status {
            parts.push(format!(
                "pkw_access_status {:#04x} -> {:#04x}",
                old.pkw_access_status, new.pkw_access_status
            ));
        }
        if !parts.is_empty() {
            let text = format!("ZSW1 {:#06x}: {}", new.zsw1, parts.join(", "));
            self.line(&text);
        }
    }

    /// Cycles until `done` or `max_ms`; `Ok(false)` on the time limit.
    fn until(&mut self, max_ms: u64, done: impl Fn(&FbOutputs) -> bool) -> Result<bool, String> {
        for _ in 0..max_ms {
            self.cycle()?;
            if self.ctl.fresh() && done(&self.o) {
                return Ok(true);
            }
        }
        Ok(false)
    }

    fn wait_ms(&mut self, ms: u64) -> Result<(), String> {
        for _ in 0..ms {
            self.cycle()?;
        }
        Ok(())
    }

    fn begin(&mut self, phase: Phase) {
        self.phase_start = self.ctl.now();
        self.obs.phase(self.phase_start, phase);
        self.line(&format!("--- {} ---", phase.name()));
    }

    fn end(&mut self, phase: Phase, summary: String) {
        let r = PhaseResult {
            phase,
            start: self.phase_start,
            end: self.ctl.now(),
            summary,
        };
        self.report.phases.push(r);
    }

    fn enable(&mut self) -> Result<(), String> {
        self.begin(Phase::Enable);
        if !self.until(100, |o| o.identifier != 0)? {
            return Err("no response telegram within 100 ms of the Connect".into());
        }
        self.i.drive_enable = true;
        let mut states = vec![self.o.zsw1 & 0x47];
        let done = {
            let mut ok = false;
            for _ in 0..500 {
                self.cycle()?;
                let s = self.o.zsw1 & 0x47;
                if states.last() != Some(&s) {
                    states.push(s);
                }
                if self.o.drive_is_enabled {
                    ok = true;
                    break;
                }
            }
            ok
        };
        if states != [0x40, 0x01, 0x03, 0x07] {
            self.deviation(format!(
                "P-219: the enable sequence went through ZSW1 states {states:02x?}, not SOI, RTSO, SO, OP"
            ));
        }
        self.report.enable_states = states;
        self.report.enabled = done;
        let summary = if done {
            "drive_is_enabled".to_string()
        } else {
            self.deviation("P-219: drive_is_enabled did not come within 500 ms".into());
            "not enabled".to_string()
        };
        self.end(Phase::Enable, summary);
        Ok(())
    }

    fn home(&mut self) -> Result<(), String> {
        self.begin(Phase::Home);
        self.i.homing_method = HOMING_METHOD;
        self.i.start_homing = true;
        self.line(&format!(
            "start_homing, method {HOMING_METHOD} (index pulse, positive)"
        ));
        // home_valid is 0 during the run (P-107): wait for the run first
        self.until(20, |o| !o.home_valid)?;
        let ok = self.until(20_000, |o| o.home_valid)?;
        self.i.start_homing = false;
        self.wait_ms(20)?;
        let pos = self.axis_value(0x6064);
        self.report.home_valid = ok && self.o.home_valid;
        self.report.home_position_inc = pos;
        let summary = if ok {
            format!("home_valid, position {pos} inc")
        } else {
            self.deviation("P-222: home_valid did not come within 20 s".into());
            "no home_valid".into()
        };
        self.set_inc = pos as i32;
        self.end(Phase::Home, summary);
        Ok(())
    }

    /// Starts one record-266 task with the values in the inputs: waits
    /// until the drive can take a task (ZSW1 bit 12 clear), raises
    /// `start_pos` until it is acknowledged (bit 12 set), drops it.
    fn start_task(&mut self) -> Result<bool, String> {
        if !self.until(10_000, |o| !o.pos_task_ack)? {
            return Ok(false);
        }
        self.i.start_pos = true;
        let taken = self.until(100, |o| o.pos_task_ack)?;
        self.i.start_pos = false;
        self.cycle()?;
        Ok(taken)
    }

    /// Waits for target reached, then 200 ms to settle; returns 6064h.
    fn settle(&mut self, label: String, commanded_inc: i64) -> Result<(), String> {
        let ok = self.until(20_000, |o| o.target_reached)?;
        if !ok {
            self.deviation(format!("P-221: target_reached did not come for {label}"));
        }
        self.wait_ms(200)?;
        let reached_inc = self.axis_value(0x6064);
        self.line(&format!(
            "{label}: commanded {commanded_inc} inc, at {reached_inc} inc ({:+} inc); position_actual_value {}",
            reached_inc - commanded_inc,
            self.o.position_actual_value
        ));
        self.report.targets.push(TargetResult {
            label,
            commanded_inc,
            reached_inc,
        });
        Ok(())
    }

    /// Ends the running move's following-error record as `label`.
    fn end_move(&mut self, label: &str) {
        if let Some((max_inc, sq, cycles)) = self.move_fe.take() {
            let rms_inc = (sq / cycles.max(1) as f64).sqrt();
            self.line(&format!(
                "{label}: following error max {max_inc} inc, rms {rms_inc:.1} inc"
            ));
            self.report.moves.push(MoveFe {
                label: label.to_string(),
                max_inc,
                rms_inc,
                cycles,
            });
        }
    }

    fn positioning(&mut self) -> Result<(), String> {
        self.begin(Phase::Positioning);
        self.i.operation_mode = OPMODE_POS;
        self.i.change_immediatly = false;
        self.i.relative = false;
        let mut passing = Vec::new();
        self.move_fe = Some((0, 0.0, 0));
        for (k, (target, velocity, end)) in CHAIN.iter().copied().enumerate() {
            self.i.target_position = target;
            self.i.profile_velocity = velocity;
            self.i.end_velocity = end;
            if !self.start_task()? {
                self.deviation(format!(
                    "P-221: task T{} was not acknowledged (ZSW1 bit 12)",
                    k + 1
                ));
            }
            self.line(&format!(
                "T{} appended: target {target} (1/1000 rev), {velocity} rpm, end velocity {end} rpm",
                k + 1
            ));
            if end != 0 {
                passing.push((k, target, end));
            }
        }
        self.set_inc = milli_rev_to_inc(i64::from(CHAIN[2].0)) as i32;
        // watch the intermediate targets pass, and no early target reached
        let last = milli_rev_to_inc(i64::from(CHAIN[2].0));
        let mut next = 0;
        for _ in 0..20_000 {
            self.cycle()?;
            let pos = self.axis_value(0x6064);
            if let Some((k, target, end)) = passing.get(next).copied() {
                if pos >= milli_rev_to_inc(i64::from(target)) {
                    let rpm = self.axis_value(0x606C) * 60 / INC_PER_REV;
                    self.line(&format!(
                        "passing T{} at {rpm} rpm (end velocity {end} rpm)",
                        k + 1
                    ));
                    self.report.passing_rpm.push((rpm as i32, end));
                    if rpm * 2 < i64::from(end) {
                        self.deviation(format!(
                            "P-221: T{} passed at {rpm} rpm, its end velocity is {end} rpm (§8.4 gap-free)",
                            k + 1
                        ));
                    }
                    next += 1;
                }
            }
            if self.o.target_reached && (pos - last).abs() > INC_PER_REV / 10 {
                self.report.early_target_reached = true;
                self.deviation("P-105: target_reached before the last appended task ended".into());
            }
            if self.o.target_reached && next >= passing.len() {
                break;
            }
        }
        self.settle("T3 (end of chain)".into(), last)?;
        self.end_move("chain T1…T3");
        // the relative move, relative to the position set-point
        self.i.relative = true;
        self.i.target_position = RELATIVE_MOVE;
        self.i.profile_velocity = 500;
        self.i.end_velocity = 0;
        self.move_fe = Some((0, 0.0, 0));
        if !self.start_task()? {
            self.deviation("P-221: the relative task was not acknowledged".into());
        }
        self.i.relative = false;
        let commanded = last + milli_rev_to_inc(i64::from(RELATIVE_MOVE));
        self.set_inc = commanded as i32;
        self.line(&format!("relative move {RELATIVE_MOVE} (1/1000 rev) started"));
        self.settle(format!("relative {RELATIVE_MOVE}"), commanded)?;
        self.end_move(&format!("relative {RELATIVE_MOVE}"));
        let worst = self
            .report
            .targets
            .iter()
            .map(|t| t.error_inc().abs())
            .max()
            .unwrap_or(0);
        let summary = format!(
            "{} targets, worst end position error {worst} inc",
            self.report.targets.len()
        );
        self.end(Phase::Positioning, summary);
        Ok(())
    }

    fn speed(&mut self) -> Result<(), String> {
        self.begin(Phase::Speed);
        self.i.operation_mode = OPMODE_VELO;
        self.i.target_velocity = SPEED_RPM;
        if !self.until(100, |o| o.operation_mode_actual == OPMODE_VELO)? {
            self.deviation("P-220: operation_mode_actual did not become 0x08 with telegram E1".into());
        }
        self.report.speed_mode_actual = self.o.operation_mode_actual;
        let reached = self.until(2_000, |o| o.velo_reached && o.velocity_actual_value > 0)?;
        self.report.velo_reached = reached.then_some(self.o.velocity_actual_value);
        if !reached {
            self.deviation(format!(
                "P-223/P-102: velo_reached (ZSW1 bit 8) did not come at {SPEED_RPM} rpm, actual {} rpm \
                 (known: docs/conformance.md P-223)",
                self.o.velocity_actual_value
            ));
        }
        if !self.o.velo_exceeded {
            self.deviation(format!(
                "P-223/P-106: velo_exceeded (ZSW1 bit 10) not set at {} rpm for the set-point {SPEED_RPM} rpm",
                self.o.velocity_actual_value
            ));
        }
        self.wait_ms(300)?;
        let at_speed = self.o.velocity_actual_value;
        self.report.speed_rpm = at_speed;
        self.i.target_velocity = 0;
        let zero = self.until(5_000, |o| o.velo_zero)?;
        self.report.velo_zero = zero;
        if !zero {
            self.deviation("P-223: velo_zero did not come after the set-point 0".into());
        }
        self.end(
            Phase::Speed,
            format!(
                "{at_speed} rpm at set-point {SPEED_RPM}, then velo_zero {}",
                bit(zero)
            ),
        );
        Ok(())
    }

    fn jog(&mut self) -> Result<(), String> {
        self.begin(Phase::Jog);
        self.i.operation_mode = OPMODE_POS;
        self.i.jogging_velocity = JOG_RPM;
        self.until(100, |o| o.operation_mode_actual == OPMODE_POS)?;
        for (k, positive) in [true, false].into_iter().enumerate() {
            let from = self.axis_value(0x6064);
            self.i.jog_pos = positive;
            self.i.jog_neg = !positive;
            self.wait_ms(JOG_MS)?;
            self.i.jog_pos = false;
            self.i.jog_neg = false;
            if !self.until(3_000, |o| o.velo_zero)? {
                self.deviation("P-225: the axis did not stop after the jog bit fell".into());
            }
            let moved = self.axis_value(0x6064) - from;
            self.report.jog_inc[k] = moved;
            let name = if positive { "jog_pos" } else { "jog_neg" };
            self.line(&format!("{name}: moved {moved} inc"));
            if (moved > 0) != positive || moved == 0 {
                self.deviation(format!("P-225: {name} moved {moved} inc"));
            }
        }
        self.set_inc = self.axis_value(0x6064) as i32;
        let [p, n] = self.report.jog_inc;
        self.end(Phase::Jog, format!("jog_pos {p:+} inc, jog_neg {n:+} inc"));
        Ok(())
    }

    fn pkw_access(&mut self, label: &str, access: Access) -> Result<Outcome, String> {
        self.pkw.start(access);
        for _ in 0..200 {
            self.cycle()?;
            if let Some(r) = self.pkw.take_result() {
                let text = match r {
                    Outcome::Done(v) => format!("PKW {label}: {v} ({v:#x})"),
                    Outcome::Refused(e) => format!("PKW {label}: refused, error {e:#x}"),
                };
                self.line(&text);
                self.report.pkw.push((label.to_string(), r));
                return Ok(r);
            }
        }
        Err(format!("PKW {label}: no answer within 200 ms"))
    }

    fn pkw_phase(&mut self) -> Result<(), String> {
        self.begin(Phase::Pkw);
        let before = self.report.pkw.len();
        let m = self.pkw_access("read 964.0", Access::Read { index: 964, sub: 0 })?;
        if m == Outcome::Done(u32::from(profinet::model::VENDOR_ID)) {
            self.deviation(format!(
                "P-202: PNU 964.0 reads the drive's PROFINET vendor ID {:#06x}, the spec's manufacturer is 277 \
                 (known: docs/conformance.md P-202)",
                profinet::model::VENDOR_ID
            ));
        } else if m != Outcome::Done(277) {
            self.deviation(format!("P-202: PNU 964.0 read {m:?}, the manufacturer is 277"));
        }
        let p = self.pkw_access("read 1100.0", Access::Read { index: 1100, sub: 0 })?;
        let cyclic = self.o.position_actual_value;
        if p != Outcome::Done(cyclic as u32) {
            self.deviation(format!(
                "P-226: PNU 1100.0 read {p:?} through PKW, the telegram carries {cyclic} (1/1000 rev)"
            ));
        }
        let (index, sub) = PKW_OBJECT;
        let old = self.pkw_access("read 6065h.0", Access::Read { index, sub })?;
        let value = 20_000;
        self.pkw_access("write 6065h.0", Access::Write { index, sub, value })?;
        let back = self.pkw_access("read 6065h.0", Access::Read { index, sub })?;
        if back != Outcome::Done(value) {
            self.deviation(format!("P-226: 6065h.0 read back {back:?} after writing {value}"));
        }
        if let Outcome::Done(v) = old {
            self.pkw_access("write 6065h.0 (restore)", Access::Write { index, sub, value: v })?;
        }
        let bad = self.pkw_access("read 999.0 (no such PNU)", Access::Read { index: 999, sub: 0 })?;
        if !matches!(bad, Outcome::Refused(_)) {
            self.deviation(format!("P-226: an unknown PNU read {bad:?}"));
        }
        let n = self.report.pkw.len() - before;
        self.end(Phase::Pkw, format!("{n} accesses"));
        Ok(())
    }

    fn fault(&mut self) -> Result<(), String> {
        self.begin(Phase::Fault);
        let said = self.ctl.sim_mut().command(Command::Fault {
            axis: 0,
            event: 44,
            cause: 1,
        });
        self.line(&format!("control channel: {said}"));
        let seen = self.until(500, |o| o.fault)?;
        self.report.fault_seen = seen;
        self.report.disabled_by_fault = seen && !self.o.drive_is_enabled;
        if !seen {
            self.deviation("P-215: no fault (ZSW1 bit 3) after a drive event".into());
        } else if self.o.drive_is_enabled {
            self.deviation("P-215: the drive stays enabled with a fault".into());
        }
        self.wait_ms(50)?;
        self.i.fault_reset = true;
        self.line("fault_reset (CW1 bit 7 rising)");
        let cleared = self.until(200, |o| !o.fault)?;
        self.i.fault_reset = false;
        self.report.fault_cleared = cleared;
        if !cleared {
            self.deviation("P-227: fault_reset did not clear the fault".into());
        }
        let again = self.until(1_000, |o| o.drive_is_enabled)?;
        self.report.re_enabled = again;
        if !again {
            self.deviation("P-227: the drive did not enable again after the acknowledgement".into());
        }
        self.end(
            Phase::Fault,
            format!(
                "fault {}, cleared {}, enabled again {}",
                bit(seen),
                bit(cleared),
                bit(again)
            ),
        );
        Ok(())
    }
}

/// Seed of the electrical plant's ADC noise in the sequence's drive.
pub const PLANT_SEED: u64 = 0x5EED_0F00;

/// How to run the sequence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// The axes' motor model.
    pub plant: PlantModel,
    /// B44 identify mechanics through PKW between enable and home
    /// (`demo --fieldbus profinet --self-tune`).
    pub self_tune: bool,
    /// The plant's inertia and its friction (Coulomb, breakaway, viscous)
    /// times these, both axes: mechanics the drive does not know. (1, 1):
    /// the simulated servo the drive's defaults are set for.
    pub mechanics: (f64, f64),
    /// With `self_tune`: B48, the speed-loop bandwidth B44 chooses the
    /// gains for, written through PKW before A75 (Hz); `None` leaves the
    /// drive's (30 Hz by default).
    pub bandwidth_hz: Option<u16>,
}

impl From<PlantModel> for Options {
    /// The demo's run: no self-tuning, the simulated servo.
    fn from(plant: PlantModel) -> Self {
        Options {
            plant,
            self_tune: false,
            mechanics: (1.0, 1.0),
            bandwidth_hz: None,
        }
    }
}

/// Runs the whole sequence against a fresh simulated drive whose axes run
/// `plant`; `obs` hears every change; with `pcap` every frame is recorded
/// (returned at the end for the caller to flush). Errors only when the
/// exchange itself fails; what the drive does wrong is a deviation in the
/// report.
pub fn run(
    obs: &mut impl Observer,
    pcap: Option<Recording>,
    plant: PlantModel,
) -> Result<(Report, Option<Recording>), String> {
    run_with(obs, pcap, plant.into())
}

/// [`run`] with [`Options`]: self-tuning, the plant's mechanics.
pub fn run_with(
    obs: &mut impl Observer,
    pcap: Option<Recording>,
    options: Options,
) -> Result<(Report, Option<Recording>), String> {
    let mut drive = PnController::drive();
    drive
        .set_plant(options.plant, PLANT_SEED)
        .map_err(|e| format!("the electrical plant's parameters: {e:?}"))?;
    let (jf, ff) = options.mechanics;
    for axis in 0..2 {
        if let Some(m) = drive.motor_mut(axis) {
            let p = m.params_mut();
            p.inertia_kg_m2 *= jf;
            p.coulomb_friction_nm *= ff;
            p.static_friction_nm *= ff;
            p.viscous_friction_nm_s_per_rad *= ff;
        }
    }
    let ctl = PnController::connect(drive, Nanos::from_ms(10), pcap)?;
    let mut run = Run {
        ctl,
        fb: ExampleFb::new(),
        i: FbInputs::default(),
        pkw: PkwClient::new(),
        o: FbOutputs::default(),
        last_cw1: None,
        responses: 0,
        skipped: 0,
        set_inc: 0,
        obs,
        report: Report::default(),
        phase_start: Nanos::ZERO,
        hold_ready: false,
        move_fe: None,
        in_self_tune: false,
        bandwidth_hz: options.bandwidth_hz,
    };
    for (t, e) in run.ctl.take_events() {
        run.obs.line(t, &e);
    }
    run.enable()?;
    if options.self_tune {
        run.self_tune()?;
    }
    run.home()?;
    run.positioning()?;
    run.speed()?;
    run.jog()?;
    run.pkw_phase()?;
    run.fault()?;
    run.i.drive_enable = false;
    run.line("drive_enable 0");
    run.until(200, |o| !o.drive_is_enabled)?;
    run.wait_ms(20)?;
    run.report.frames = run.ctl.frames();
    let pcap = run.ctl.take_recording();
    Ok((run.report, pcap))
}
