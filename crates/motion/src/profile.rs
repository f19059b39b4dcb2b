//! Jerk-limited profile generator of the drive-generated modes (spec §6.5.5
//! pp, §6.5.7 pv; C-041 – C-049, C-055) and the halt / quick-stop ramps
//! (C-010).
//!
//! A plan is a short list of constant-jerk segments from the current state
//! (position, velocity, acceleration) to the goal, evaluated in closed form
//! at the time since the plan started, so no error accumulates. A position
//! move is: ramp to a cruise velocity (acceleration 6083h), cruise, ramp to
//! standstill (deceleration 6084h); each ramp has a trapezoidal acceleration
//! with slopes ± jerk (60A4h:01). The cruise velocity is the largest one
//! (≤ 6081h/607Fh) whose ramps fit into the distance; the rest of the
//! distance becomes cruise, so the plan ends on the target, which is then
//! taken exactly (whole increments). When the target is closer than the
//! stopping distance (a new target while moving), the plan stops first and
//! then moves back: no overshoot is ever planned when a move starts at
//! standstill.
//!
//! Inside, values are `f64` (increments, increments/s, …) relative to an
//! anchor position (`i32` increments + a fraction), so large positions keep
//! full resolution; at the API they are `f32`.

use libm::{floor, sqrt};
use nanos::Nanos;

/// Limits of one profile (units in increments).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileLimits {
    /// Profile velocity, increments/s: 6081h capped by 607Fh (pp); the cap
    /// of the target velocity (pv). Finite, > 0.
    pub velocity: f32,
    /// Acceleration 6083h, increments/s² (used while |v| grows). Finite, > 0.
    pub acceleration: f32,
    /// Deceleration 6084h, increments/s² (used while |v| shrinks). Finite, > 0.
    pub deceleration: f32,
    /// Jerk 60A4h:01, increments/s³; > 0, `f32::INFINITY` = no jerk limit.
    pub jerk: f32,
}

/// Why a profile command is refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProfileError {
    /// Velocity limit not finite or ≤ 0.
    Velocity,
    /// Acceleration not finite or ≤ 0.
    Acceleration,
    /// Deceleration not finite or ≤ 0.
    Deceleration,
    /// Jerk NaN or ≤ 0.
    Jerk,
    /// Target velocity not finite.
    TargetVelocity,
}

impl ProfileLimits {
    /// Checks every limit; see the field docs.
    pub fn validate(&self) -> Result<(), ProfileError> {
        fn ok(x: f32) -> bool {
            x.is_finite() && x > 0.0
        }
        if !ok(self.velocity) {
            return Err(ProfileError::Velocity);
        }
        if !ok(self.acceleration) {
            return Err(ProfileError::Acceleration);
        }
        if !ok(self.deceleration) {
            return Err(ProfileError::Deceleration);
        }
        if self.jerk.is_nan() || self.jerk <= 0.0 {
            return Err(ProfileError::Jerk);
        }
        Ok(())
    }
}

/// When a new target is taken (controlword bit 5, C-043, C-044).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SetMode {
    /// Bit 5 = 1 "change set immediately": the running move is re-planned.
    Immediate,
    /// Bit 5 = 0: taken only at standstill, refused while moving (the device
    /// has no set-point buffer).
    WhenStandstill,
}

/// A pp target (controlword bit 6 and 60F2h bits 1..0, C-045 – C-047).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PositionTarget {
    /// Absolute position, increments (bit 6 = 0, MC_MoveAbsolute).
    Absolute(i32),
    /// Distance from the last target position, increments (bit 6 = 1,
    /// 60F2h = 00, MC_MoveAdditive).
    Additive(i32),
    /// Distance from the actual position 6064h, increments (bit 6 = 1,
    /// 60F2h = 10, MC_MoveRelative).
    Relative {
        /// Distance, increments.
        distance: i32,
        /// Actual position 6064h, increments.
        actual: i32,
    },
}

/// One control cycle's set-point from the generator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileSample {
    /// Position set-point, increments.
    pub position: i32,
    /// Velocity set-point, increments/s.
    pub velocity: f32,
    /// Acceleration set-point, increments/s².
    pub acceleration: f32,
    /// No motion planned: the generator stands still (target taken, stop
    /// finished).
    pub done: bool,
}

/// Most segments a plan has: stop (3) + ramp (3) + cruise (1) + ramp (3).
const MAX_SEGS: usize = 10;

/// A constant-jerk segment, in plan coordinates.
#[derive(Debug, Clone, Copy)]
struct Seg {
    /// Start time from the plan start, s.
    t0: f64,
    /// Duration, s (> 0).
    dt: f64,
    /// Jerk, increments/s³ (finite).
    j: f64,
    /// Position, velocity and acceleration at the segment start
    /// (increments, /s, /s²); the acceleration may jump between segments
    /// when the jerk is unlimited.
    x: f64,
    v: f64,
    a: f64,
}

/// What happens when a plan ends.
#[derive(Debug, Clone, Copy, PartialEq)]
enum End {
    /// Stand still on this target, increments.
    Position(i32),
    /// Go on at this velocity, increments/s.
    Velocity(f64),
    /// Stand still where the ramp ended.
    Stop,
    /// Stand still, then plan a move to this target with these limits.
    StopThenMove(i32, ProfileLimits),
    /// Pass this target (increments) at this end velocity (increments/s,
    /// plan coordinates, > 0) and go on at it: a gap-free sequence.
    Pass(i32, f64),
}

#[derive(Debug, Clone, Copy)]
struct Plan {
    segs: [Seg; MAX_SEGS],
    len: usize,
    /// +1 or −1: plan coordinates × dir = position change.
    dir: f64,
    /// Plan coordinates stay ≤ this (the target of a direct move).
    x_max: f64,
    /// Total duration, s.
    total: f64,
    /// State at the end of the segments so far, plan coordinates.
    x_end: f64,
    v_end: f64,
    a_end: f64,
    end: End,
}

impl Plan {
    const EMPTY: Plan = Plan {
        segs: [Seg {
            t0: 0.0,
            dt: 0.0,
            j: 0.0,
            x: 0.0,
            v: 0.0,
            a: 0.0,
        }; MAX_SEGS],
        len: 0,
        dir: 1.0,
        x_max: f64::INFINITY,
        total: 0.0,
        x_end: 0.0,
        v_end: 0.0,
        a_end: 0.0,
        end: End::Stop,
    };

    fn new(dir: f64, v0: f64, a0: f64) -> Self {
        Self {
            dir,
            v_end: v0,
            a_end: a0,
            ..Self::EMPTY
        }
    }

    /// Appends a segment of `dt` s with jerk `j` starting at acceleration `a`.
    fn push(&mut self, dt: f64, j: f64, a: f64) {
        if !(dt > 0.0 && dt.is_finite()) {
            return;
        }
        let j = if j.is_finite() { j } else { 0.0 };
        let seg = Seg {
            t0: self.total,
            dt,
            j,
            x: self.x_end,
            v: self.v_end,
            a,
        };
        if let Some(slot) = self.segs.get_mut(self.len) {
            *slot = seg;
            self.len += 1;
            self.total += dt;
            self.x_end += self.v_end * dt + a * dt * dt * 0.5 + j * dt * dt * dt / 6.0;
            self.v_end += a * dt + j * dt * dt * 0.5;
            self.a_end = a + j * dt;
        }
    }

    /// Appends a ramp from the current end (velocity, acceleration) to
    /// velocity `v1` at zero acceleration, |a| ≤ `amax` (or the start
    /// acceleration if that is larger: it is first brought down), |jerk| ≤
    /// `jerk` (may be infinite: the acceleration then jumps).
    fn ramp(&mut self, v1: f64, amax: f64, jerk: f64) {
        let v0 = self.v_end;
        let a0 = self.a_end;
        // Velocity reached by bringing the acceleration to zero at once.
        let vz = v0 + a0 * a0.abs() / (2.0 * jerk);
        // s = +1: the velocity has to grow (in mirrored coordinates).
        let s = if v1 >= vz { 1.0 } else { -1.0 };
        let a0s = s * a0;
        let dv = s * (v1 - v0);
        let two_j_dv = if dv == 0.0 { 0.0 } else { 2.0 * jerk * dv };
        let ap_sq = (two_j_dv + a0s * a0s) * 0.5;
        // Peak acceleration: triangle, or trapezoid clipped at amax.
        let ap = if ap_sq > 0.0 { sqrt(ap_sq) } else { 0.0 }.min(amax);
        let t1 = (ap - a0s).abs() / jerk;
        let j1 = if ap >= a0s { s * jerk } else { -s * jerk };
        let dv1 = (ap + a0s) * 0.5 * t1;
        let t3 = ap / jerk;
        let dv3 = ap * t3 * 0.5;
        let t2 = if ap > 0.0 {
            ((dv - dv1 - dv3) / ap).max(0.0)
        } else {
            0.0
        };
        self.push(t1, j1, a0);
        self.push(t2, 0.0, s * ap);
        self.push(t3, -s * jerk, s * ap);
        // The segments end on v1 at zero acceleration up to rounding; close
        // the ramp exactly there (with unlimited jerk the acceleration jumps).
        self.v_end = v1;
        self.a_end = 0.0;
    }

    /// Velocity ramp that splits at standstill when the sign changes
    /// (brake with `dec`, then speed up with `acc`); otherwise `acc` when |v|
    /// grows, `dec` when it shrinks.
    fn ramp_to(&mut self, v1: f64, acc: f64, dec: f64, jerk: f64) {
        let v0 = self.v_end;
        if v0 * v1 < 0.0 {
            self.ramp(0.0, dec, jerk);
            self.ramp(v1, acc, jerk);
        } else if v1.abs() >= v0.abs() {
            self.ramp(v1, acc, jerk);
        } else {
            self.ramp(v1, dec, jerk);
        }
    }

    /// State (x, v, a) at time `t` s, plan coordinates; `t` ≥ total gives
    /// the end.
    fn eval(&self, t: f64) -> (f64, f64, f64) {
        for seg in self.segs.iter().take(self.len) {
            if t < seg.t0 + seg.dt {
                let tau = (t - seg.t0).max(0.0);
                let x = seg.x + seg.v * tau + seg.a * tau * tau * 0.5 + seg.j * tau * tau * tau / 6.0;
                let v = seg.v + seg.a * tau + seg.j * tau * tau * 0.5;
                let a = seg.a + seg.j * tau;
                return (x.min(self.x_max), v, a);
            }
        }
        (self.x_end.min(self.x_max), self.v_end, self.a_end)
    }
}

/// Limits as `f64` (increments, /s, /s², /s³).
#[derive(Debug, Clone, Copy)]
struct Lim {
    v: f64,
    acc: f64,
    dec: f64,
    jerk: f64,
}

impl From<ProfileLimits> for Lim {
    fn from(l: ProfileLimits) -> Self {
        Self {
            v: f64::from(l.velocity),
            acc: f64::from(l.acceleration),
            dec: f64::from(l.deceleration),
            jerk: f64::from(l.jerk),
        }
    }
}

/// Ramp to `vc`, cruise `cruise_s` s, ramp to standstill; plan coordinates
/// (direction +1), starting at (0, `v0`, `a0`).
fn direct_plan(v0: f64, a0: f64, vc: f64, cruise_s: f64, l: &Lim) -> Plan {
    direct_plan_to(v0, a0, vc, cruise_s, 0.0, l)
}

/// [`direct_plan`] ending at velocity `ve` (≥ 0) instead of standstill.
fn direct_plan_to(v0: f64, a0: f64, vc: f64, cruise_s: f64, ve: f64, l: &Lim) -> Plan {
    let mut p = Plan::new(1.0, v0, a0);
    p.ramp_to(vc, l.acc, l.dec, l.jerk);
    p.push(cruise_s, 0.0, 0.0);
    if ve > 0.0 {
        p.ramp_to(ve, l.acc, l.dec, l.jerk);
    } else {
        p.ramp(0.0, l.dec, l.jerk);
    }
    p
}

/// Plans a move over `d` (increments) from (`v`, `a`) that passes `target`
/// at the end velocity `ve` (increments/s, > 0, capped at the velocity
/// limit) in the direction of the move. `None`: the end velocity cannot be
/// reached within the distance (the caller plans an ordinary move).
fn plan_pass(d: f64, v: f64, a: f64, target: i32, ve: f64, limits: ProfileLimits) -> Option<Plan> {
    let l = Lim::from(limits);
    let dir = if d >= 0.0 { 1.0 } else { -1.0 };
    let dn = d.abs();
    let (vn, an) = (dir * v, dir * a);
    let ve = ve.min(l.v);
    if ve.is_nan() || ve <= 0.0 || dn == 0.0 || vn < 0.0 {
        return None;
    }
    let dist = |vc: f64| direct_plan_to(vn, an, vc, 0.0, ve, &l).x_end;
    if dist(ve) > dn + 0.5 {
        return None;
    }
    let mut plan = if dist(l.v) <= dn {
        direct_plan_to(vn, an, l.v, (dn - dist(l.v)) / l.v, ve, &l)
    } else {
        let lo = bisect(&dist, ve, l.v, dn);
        direct_plan_to(vn, an, lo, ((dn - dist(lo)) / lo).max(0.0), ve, &l)
    };
    plan.dir = dir;
    plan.x_max = dn;
    plan.end = End::Pass(target, ve);
    Some(plan)
}

/// Bisection steps for the cruise velocity (2^-40 of the velocity limit).
const BISECTION_STEPS: u32 = 40;

/// The largest cruise velocity between `lo` and `hi` whose distance `dist` stays
/// within `dn` (`dist` rising; `dist(lo) ≤ dn < dist(hi)`).
fn bisect(dist: &impl Fn(f64) -> f64, mut lo: f64, mut hi: f64, dn: f64) -> f64 {
    for _ in 0..BISECTION_STEPS {
        let mid = 0.5 * (lo + hi);
        if dist(mid) <= dn {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Plans a position move from (`v`, `a`) (increments/s, /s²) over the
/// distance `d` (increments) to `target`. `None`: nothing to do.
fn plan_move(d: f64, v: f64, a: f64, target: i32, limits: ProfileLimits) -> Option<Plan> {
    let l = Lim::from(limits);
    let dir = if d >= 0.0 { 1.0 } else { -1.0 };
    let dn = d.abs();
    let vn = dir * v;
    let an = dir * a;
    if dn == 0.0 && vn == 0.0 && an == 0.0 {
        return None;
    }
    let dist = |vc: f64| direct_plan(vn, an, vc, 0.0, &l).x_end;
    let f0 = dist(0.0);
    let mut plan = if f0 > dn + 0.5 {
        // Closer than the stopping distance (or moving away): stop, then
        // move back.
        let mut p = Plan::new(1.0, vn, an);
        p.ramp(0.0, l.dec, l.jerk);
        p.dir = dir;
        p.end = End::StopThenMove(target, limits);
        return Some(p);
    } else if dist(l.v) <= dn {
        direct_plan(vn, an, l.v, (dn - dist(l.v)) / l.v, &l)
    } else if f0 >= dn {
        direct_plan(vn, an, 0.0, 0.0, &l)
    } else {
        // f(lo) ≤ dn < f(hi); the rest of the distance is cruised at lo.
        let lo = bisect(&dist, 0.0, l.v, dn);
        let cruise = if lo > 0.0 {
            ((dn - dist(lo)) / lo).max(0.0)
        } else {
            0.0
        };
        direct_plan(vn, an, lo, cruise, &l)
    };
    plan.dir = dir;
    plan.x_max = dn;
    plan.end = End::Position(target);
    Some(plan)
}

#[derive(Debug, Clone, Copy)]
enum Mode {
    /// Standing still at the anchor.
    Idle,
    /// Following the generator's plan from the anchor.
    Plan,
    /// Constant velocity (increments/s), re-anchored every step.
    Cruise(f64),
}

/// Splits `base + off` into a new base and a fraction in [0, 1).
fn split(base: i32, off: f64) -> (i32, f64) {
    let n = floor(off);
    // `as i64` saturates (NaN → 0); truncation to i32 is the wrap-around.
    (base.wrapping_add(n as i64 as i32), off - n)
}

/// `base + off` rounded to whole increments (half up), wrapping.
fn round_pos(base: i32, off: f64) -> i32 {
    base.wrapping_add(floor(off + 0.5) as i64 as i32)
}

/// Jerk-limited profile generator for pp and pv, with halt and quick stop.
///
/// One generator per axis; [`step`](Self::step) once per control cycle with
/// the cycle time. Commands take effect from the current set-point state
/// (position, velocity, acceleration), so a new target or a stop mid-move is
/// smooth (jerk-limited).
#[derive(Debug, Clone)]
pub struct ProfileGenerator {
    /// Anchor: position = base + frac (increments, frac in [0, 1)).
    base: i32,
    frac: f64,
    mode: Mode,
    /// The plan of [`Mode::Plan`].
    plan: Plan,
    /// Time since the plan started.
    elapsed: Nanos,
    /// Last target position (MC_MoveAdditive reference), increments.
    target: i32,
    /// A passing move ([`Self::move_through`]) reached its target and the
    /// generator goes on at the end velocity.
    passed: bool,
}

impl ProfileGenerator {
    /// A generator standing still at `position` (increments).
    pub const fn new(position: i32) -> Self {
        Self {
            base: position,
            frac: 0.0,
            mode: Mode::Idle,
            plan: Plan::EMPTY,
            elapsed: Nanos::ZERO,
            target: position,
            passed: false,
        }
    }

    /// Standstill at `position` (increments), e.g. the actual position when
    /// the mode becomes active; the last target becomes `position`.
    pub fn reset(&mut self, position: i32) {
        // every field as `new` leaves it but the plan: it is read only in
        // `Mode::Plan`, which `start_plan` enters with a plan of its own (so
        // does an ended plan, left behind in `Mode::Idle`). Not a whole new
        // generator: its plan is ~540 bytes, two copies per call, and a
        // disabled axis resets every control cycle (issue 36: ~1,000
        // instructions per axis and cycle on QEMU)
        self.start_plan(position, 0.0, None);
        self.target = position;
    }

    /// Takes over a moving axis at `position` (increments) and `velocity`
    /// (increments/s, acceleration 0), e.g. on a switch from csp to pp; the
    /// generator keeps that velocity until commanded. A non-finite velocity
    /// counts as 0.
    pub fn take_over(&mut self, position: i32, velocity: f32) {
        self.reset(position);
        let v = f64::from(velocity);
        if v.is_finite() && v != 0.0 {
            self.mode = Mode::Cruise(v);
        }
    }

    /// No motion planned (standstill, I199 = 1).
    pub const fn is_standstill(&self) -> bool {
        matches!(self.mode, Mode::Idle)
    }

    /// Last target position taken, increments.
    pub const fn target(&self) -> i32 {
        self.target
    }

    /// Current set-point state without advancing: (base, frac, velocity, acceleration).
    fn current(&self) -> (i32, f64, f64, f64) {
        match self.mode {
            Mode::Idle => (self.base, self.frac, 0.0, 0.0),
            Mode::Cruise(v) => (self.base, self.frac, v, 0.0),
            Mode::Plan => {
                let p = &self.plan;
                let (x, v, a) = p.eval(self.elapsed_s());
                let (b, f) = split(self.base, self.frac + p.dir * x);
                (b, f, p.dir * v, p.dir * a)
            }
        }
    }

    fn elapsed_s(&self) -> f64 {
        self.elapsed.as_secs_f64()
    }

    fn start_plan(&mut self, base: i32, frac: f64, plan: Option<Plan>) {
        self.passed = false;
        self.base = base;
        self.frac = frac;
        self.elapsed = Nanos::ZERO;
        self.mode = match plan {
            Some(p) => {
                self.plan = p;
                Mode::Plan
            }
            None => Mode::Idle,
        };
    }

    /// pp: takes a new target (controlword bit 4 edge) with these limits.
    ///
    /// With [`SetMode::WhenStandstill`] (bit 5 = 0) the target is refused
    /// while a motion is planned; `Ok(true)` = taken (set-point acknowledge,
    /// statusword bit 12), `Ok(false)` = refused. A taken target re-plans
    /// from the current state; when it is closer than the stopping distance
    /// the axis stops and comes back.
    pub fn move_to(
        &mut self,
        target: PositionTarget,
        limits: ProfileLimits,
        mode: SetMode,
    ) -> Result<bool, ProfileError> {
        limits.validate()?;
        if mode == SetMode::WhenStandstill && !self.is_standstill() {
            return Ok(false);
        }
        let target = match target {
            PositionTarget::Absolute(p) => p,
            PositionTarget::Additive(d) => self.target.wrapping_add(d),
            PositionTarget::Relative { distance, actual } => actual.wrapping_add(distance),
        };
        self.target = target;
        let (base, frac, v, a) = self.current();
        let d = f64::from(target.wrapping_sub(base)) - frac;
        match plan_move(d, v, a, target, limits) {
            Some(plan) => self.start_plan(base, frac, Some(plan)),
            None => self.start_plan(target, 0.0, None),
        }
        Ok(true)
    }

    /// A move to `target` (always re-planned from the current state, as
    /// [`SetMode::Immediate`]) that passes the target at `end_velocity`
    /// (increments/s, magnitude, in the direction of the move; 6082h, the
    /// end velocity of a position record) and goes on at that velocity until
    /// the next command: the first move of a gap-free sequence.
    /// [`passed`](Self::passed) turns true once the target is passed. An end
    /// velocity of 0, or one that cannot be reached within the distance,
    /// gives an ordinary move that stops on the target.
    pub fn move_through(
        &mut self,
        target: i32,
        end_velocity: f32,
        limits: ProfileLimits,
    ) -> Result<(), ProfileError> {
        limits.validate()?;
        let (base, frac, v, a) = self.current();
        let d = f64::from(target.wrapping_sub(base)) - frac;
        let ve = f64::from(end_velocity).abs();
        match plan_pass(d, v, a, target, ve, limits) {
            Some(plan) => {
                self.target = target;
                self.start_plan(base, frac, Some(plan));
            }
            None => {
                self.move_to(PositionTarget::Absolute(target), limits, SetMode::Immediate)?;
            }
        }
        Ok(())
    }

    /// A passing move ([`move_through`](Self::move_through)) has passed its
    /// target; the generator goes on at the end velocity. Cleared by the
    /// next command.
    pub const fn passed(&self) -> bool {
        self.passed
    }

    /// pv: ramps to `target_velocity` (increments/s, capped at ±
    /// `limits.velocity`) with the acceleration, deceleration and jerk of
    /// `limits`, then holds it.
    pub fn run_velocity(&mut self, target_velocity: f32, limits: ProfileLimits) -> Result<(), ProfileError> {
        limits.validate()?;
        if !target_velocity.is_finite() {
            return Err(ProfileError::TargetVelocity);
        }
        let l = Lim::from(limits);
        let vt = f64::from(target_velocity).max(-l.v).min(l.v);
        let (base, frac, v, a) = self.current();
        let mut p = Plan::new(1.0, v, a);
        p.ramp_to(vt, l.acc, l.dec, l.jerk);
        p.end = End::Velocity(vt);
        self.start_plan(base, frac, Some(p));
        if p.len == 0 {
            self.mode = if vt == 0.0 { Mode::Idle } else { Mode::Cruise(vt) };
            if vt == 0.0 {
                self.frac = 0.0;
                self.base = round_pos(base, frac);
            }
        }
        Ok(())
    }

    /// Halt or quick stop: ramps to standstill with `deceleration`
    /// (increments/s², e.g. 6084h for halt, 6085h for quick stop) and `jerk`
    /// (increments/s³, `f32::INFINITY` = no jerk limit). The last target is
    /// kept (reference of additive moves).
    pub fn stop(&mut self, deceleration: f32, jerk: f32) -> Result<(), ProfileError> {
        if !(deceleration.is_finite() && deceleration > 0.0) {
            return Err(ProfileError::Deceleration);
        }
        if jerk.is_nan() || jerk <= 0.0 {
            return Err(ProfileError::Jerk);
        }
        let (base, frac, v, a) = self.current();
        if v == 0.0 && a == 0.0 {
            self.start_plan(round_pos(base, frac), 0.0, None);
            return Ok(());
        }
        let mut p = Plan::new(1.0, v, a);
        p.ramp(0.0, f64::from(deceleration), f64::from(jerk));
        p.end = End::Stop;
        self.start_plan(base, frac, Some(p));
        Ok(())
    }

    /// Advances by one control cycle of `dt_ns` ns and returns the set-point.
    pub fn step(&mut self, dt_ns: u32) -> ProfileSample {
        let dt_s = f64::from(dt_ns) * 1e-9;
        match self.mode {
            Mode::Idle => ProfileSample {
                position: round_pos(self.base, self.frac),
                velocity: 0.0,
                acceleration: 0.0,
                done: true,
            },
            Mode::Cruise(v) => {
                (self.base, self.frac) = split(self.base, self.frac + v * dt_s);
                ProfileSample {
                    position: round_pos(self.base, self.frac),
                    velocity: v as f32,
                    acceleration: 0.0,
                    done: false,
                }
            }
            Mode::Plan => {
                self.elapsed = self.elapsed.saturating_add(Nanos::from_ns(u64::from(dt_ns)));
                let t = self.elapsed_s();
                let p = &self.plan;
                if t >= p.total {
                    let p = *p;
                    return self.finish(&p, t - p.total);
                }
                let (x, v, a) = p.eval(t);
                ProfileSample {
                    position: round_pos(self.base, self.frac + p.dir * x),
                    velocity: (p.dir * v) as f32,
                    acceleration: (p.dir * a) as f32,
                    done: false,
                }
            }
        }
    }

    /// The plan `p` ended `over_s` s ago.
    fn finish(&mut self, p: &Plan, over_s: f64) -> ProfileSample {
        let idle = |s: &mut Self, position: i32| {
            s.start_plan(position, 0.0, None);
            ProfileSample {
                position,
                velocity: 0.0,
                acceleration: 0.0,
                done: true,
            }
        };
        match p.end {
            End::Position(target) => idle(self, target),
            End::Stop => {
                let at = round_pos(self.base, self.frac + p.dir * p.x_end);
                idle(self, at)
            }
            End::StopThenMove(target, limits) => {
                let at = round_pos(self.base, self.frac + p.dir * p.x_end);
                self.start_plan(at, 0.0, None);
                let d = f64::from(target.wrapping_sub(at));
                if let Some(plan) = plan_move(d, 0.0, 0.0, target, limits) {
                    self.start_plan(at, 0.0, Some(plan));
                } else {
                    self.start_plan(target, 0.0, None);
                }
                ProfileSample {
                    position: at,
                    velocity: 0.0,
                    acceleration: 0.0,
                    done: self.is_standstill(),
                }
            }
            End::Pass(target, ve) => {
                let v = p.dir * ve;
                let (b, f) = split(target, v * over_s);
                self.base = b;
                self.frac = f;
                self.elapsed = Nanos::ZERO;
                self.mode = Mode::Cruise(v);
                self.passed = true;
                ProfileSample {
                    position: round_pos(b, f),
                    velocity: v as f32,
                    acceleration: 0.0,
                    done: false,
                }
            }
            End::Velocity(v) => {
                let (b, f) = split(self.base, self.frac + p.dir * p.x_end + v * over_s);
                self.base = b;
                self.frac = f;
                self.elapsed = Nanos::ZERO;
                if v == 0.0 {
                    let at = round_pos(b, f);
                    return idle(self, at);
                }
                self.mode = Mode::Cruise(v);
                ProfileSample {
                    position: round_pos(b, f),
                    velocity: v as f32,
                    acceleration: 0.0,
                    done: false,
                }
            }
        }
    }
}

#[cfg(test)]
mod tests;
