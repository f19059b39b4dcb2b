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
    let mut p = Plan::new(1.0, v0, a0);
    p.ramp_to(vc, l.acc, l.dec, l.jerk);
    p.push(cruise_s, 0.0, 0.0);
    p.ramp(0.0, l.dec, l.jerk);
    p
}

/// Bisection steps for the cruise velocity (2^-40 of the velocity limit).
const BISECTION_STEPS: u32 = 40;

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
        let (mut lo, mut hi) = (0.0, l.v);
        for _ in 0..BISECTION_STEPS {
            let mid = 0.5 * (lo + hi);
            if dist(mid) <= dn {
                lo = mid;
            } else {
                hi = mid;
            }
        }
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
    /// Time since the plan started, ns.
    elapsed_ns: u64,
    /// Last target position (MC_MoveAdditive reference), increments.
    target: i32,
}

impl ProfileGenerator {
    /// A generator standing still at `position` (increments).
    pub const fn new(position: i32) -> Self {
        Self {
            base: position,
            frac: 0.0,
            mode: Mode::Idle,
            plan: Plan::EMPTY,
            elapsed_ns: 0,
            target: position,
        }
    }

    /// Standstill at `position` (increments), e.g. the actual position when
    /// the mode becomes active; the last target becomes `position`.
    pub fn reset(&mut self, position: i32) {
        *self = Self::new(position);
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
        self.elapsed_ns as f64 * 1e-9
    }

    fn start_plan(&mut self, base: i32, frac: f64, plan: Option<Plan>) {
        self.base = base;
        self.frac = frac;
        self.elapsed_ns = 0;
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
                self.elapsed_ns = self.elapsed_ns.saturating_add(u64::from(dt_ns));
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
            End::Velocity(v) => {
                let (b, f) = split(self.base, self.frac + p.dir * p.x_end + v * over_s);
                self.base = b;
                self.frac = f;
                self.elapsed_ns = 0;
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
mod tests {
    use super::*;

    const DT: u32 = 250_000; // 250 µs

    /// 3000 rpm, 1e9 inc/s² acceleration, 5e8 deceleration, 1e11 jerk.
    fn limits() -> ProfileLimits {
        ProfileLimits {
            velocity: 52_428_800.0,
            acceleration: 1.0e9,
            deceleration: 5.0e8,
            jerk: 1.0e11,
        }
    }

    /// Steps until done (at most `max` steps) and returns the samples'
    /// count; checks each sample with `check(prev, sample)`.
    fn run(
        g: &mut ProfileGenerator,
        dt: u32,
        max: usize,
        mut check: impl FnMut(&ProfileSample, &ProfileSample),
    ) -> (usize, ProfileSample) {
        let mut prev = ProfileSample {
            position: g.current().0,
            velocity: g.current().2 as f32,
            acceleration: g.current().3 as f32,
            done: false,
        };
        for i in 0..max {
            let s = g.step(dt);
            assert!(s.velocity.is_finite() && s.acceleration.is_finite());
            check(&prev, &s);
            prev = s;
            if s.done {
                return (i + 1, s);
            }
        }
        panic!("not done after {max} steps");
    }

    /// Checks v, a (speed-up vs. slow-down) and jerk against the limits.
    fn limit_checker(l: ProfileLimits, dt: u32) -> impl FnMut(&ProfileSample, &ProfileSample) {
        let dt_s = f64::from(dt) * 1e-9;
        move |p, s| {
            let tol = 1.0 + 1e-6;
            let v = f64::from(s.velocity);
            let a = f64::from(s.acceleration);
            assert!(v.abs() <= f64::from(l.velocity) * tol, "v {v}");
            let amax = if a * v > 0.0 {
                l.acceleration
            } else {
                l.acceleration.max(l.deceleration)
            };
            assert!(a.abs() <= f64::from(amax) * tol + 1.0, "a {a} at v {v}");
            if a * v < -1.0 && v.abs() > 1.0 && f64::from(p.velocity) * v > 0.0 {
                assert!(a.abs() <= f64::from(l.deceleration) * tol + 1.0, "dec {a}");
            }
            let jerk = (a - f64::from(p.acceleration)).abs() / dt_s;
            assert!(jerk <= f64::from(l.jerk) * (1.0 + 1e-3), "jerk {jerk}");
            // Position and velocity agree: Δx ≈ mean velocity · dt.
            let dx = f64::from(s.position.wrapping_sub(p.position));
            let vm = 0.5 * (v + f64::from(p.velocity));
            assert!(
                (dx - vm * dt_s).abs() <= 1.0 + f64::from(l.jerk) * dt_s * dt_s * dt_s,
                "dx {dx} vs {}",
                vm * dt_s
            );
        }
    }

    #[test]
    fn c049_pp_profile_reaches_target_exactly() {
        let starts = [0, -12_345, i32::MAX - 1_000_000, i32::MIN + 3];
        let distances = [
            1,
            2,
            7,
            1000,
            1 << 20,
            10 << 20,
            1 << 30,
            -1,
            -(3 << 20),
            -(1 << 30),
        ];
        for &start in &starts {
            for &d in &distances {
                let mut g = ProfileGenerator::new(start);
                let target = start.wrapping_add(d);
                assert_eq!(
                    g.move_to(PositionTarget::Absolute(target), limits(), SetMode::Immediate),
                    Ok(true)
                );
                let sign = d.signum();
                let (_, last) = run(&mut g, DT, 200_000, |p, s| {
                    // Never beyond the target, never backwards.
                    let rest = i64::from(target.wrapping_sub(s.position));
                    assert!(rest * i64::from(sign) >= 0, "overshoot {rest} (d {d})");
                    let step = i64::from(s.position.wrapping_sub(p.position));
                    assert!(step * i64::from(sign) >= 0, "backwards {step}");
                });
                assert_eq!(last.position, target, "start {start} d {d}");
                assert_eq!(last.velocity, 0.0);
                assert!(g.is_standstill());
                assert_eq!(g.step(DT).position, target);
            }
        }
    }

    #[test]
    fn c049_pp_profile_respects_v_a_j_limits() {
        for (d, l) in [
            (10 << 20, limits()),
            (1 << 30, limits()),
            (-(1 << 22), limits()),
            (
                5000,
                ProfileLimits {
                    velocity: 1.0e6,
                    acceleration: 2.0e7,
                    deceleration: 4.0e7,
                    jerk: 1.0e9,
                },
            ),
        ] {
            let mut g = ProfileGenerator::new(100);
            g.move_to(
                PositionTarget::Relative {
                    distance: d,
                    actual: 100,
                },
                l,
                SetMode::Immediate,
            )
            .unwrap();
            let dt = 100_000;
            let mut vmax = 0.0f32;
            let mut check = limit_checker(l, dt);
            let (_, last) = run(&mut g, dt, 1_000_000, |p, s| {
                vmax = vmax.max(s.velocity.abs());
                check(p, s);
            });
            assert_eq!(last.position, 100i32.wrapping_add(d));
            if d.abs() >= 1 << 30 {
                // Long moves reach the velocity limit.
                assert!(vmax >= l.velocity * 0.999, "vmax {vmax}");
            }
        }
    }

    #[test]
    fn c049_pp_move_time_close_to_minimum() {
        // 1e7 inc with v = 1e7 inc/s, a = d = 1e8 inc/s², j = 1e10 inc/s³:
        // the plan reaches v and cruises (time-optimal for these limits).
        let l = ProfileLimits {
            velocity: 1.0e7,
            acceleration: 1.0e8,
            deceleration: 1.0e8,
            jerk: 1.0e10,
        };
        let mut g = ProfileGenerator::new(0);
        g.move_to(PositionTarget::Absolute(10_000_000), l, SetMode::Immediate)
            .unwrap();
        // Ramp: 0.01 s jerk + 0.09 s const + 0.01 s jerk = 0.11 s, distance
        // 0.55e6 each; cruise 8.9e6 / 1e7 = 0.89 s: total 1.11 s.
        let (steps, _) = run(&mut g, 1_000_000, 10_000, |_, _| {});
        assert!((1110..=1112).contains(&steps), "{steps}");
    }

    #[test]
    fn c044_change_set_immediately_replans_mid_move() {
        let l = limits();
        for (first, second) in [
            (10 << 20, 20 << 20),
            (10 << 20, 3 << 20),
            (10 << 20, -(5 << 20)),
            (1 << 20, 0),
        ] {
            let mut g = ProfileGenerator::new(0);
            g.move_to(PositionTarget::Absolute(first), l, SetMode::Immediate)
                .unwrap();
            let mut check = limit_checker(l, DT);
            for _ in 0..100 {
                let s = g.step(DT);
                assert!(!s.done);
            }
            assert_eq!(
                g.move_to(PositionTarget::Absolute(second), l, SetMode::Immediate),
                Ok(true)
            );
            assert_eq!(g.target(), second);
            let (_, last) = run(&mut g, DT, 400_000, &mut check);
            assert_eq!(last.position, second, "{first} → {second}");
        }
    }

    #[test]
    fn c044_same_target_again_while_decelerating_does_not_reverse() {
        let l = limits();
        let mut g = ProfileGenerator::new(0);
        g.move_to(PositionTarget::Absolute(1 << 20), l, SetMode::Immediate)
            .unwrap();
        let mut n = 0;
        loop {
            let s = g.step(DT);
            n += 1;
            if n % 7 == 0 {
                g.move_to(PositionTarget::Absolute(1 << 20), l, SetMode::Immediate)
                    .unwrap();
            }
            assert!(s.position <= 1 << 20);
            if s.done {
                assert_eq!(s.position, 1 << 20);
                break;
            }
            assert!(n < 100_000);
        }
    }

    #[test]
    fn c043_new_target_refused_while_moving_without_bit5() {
        let l = limits();
        let mut g = ProfileGenerator::new(0);
        assert_eq!(
            g.move_to(PositionTarget::Absolute(1 << 20), l, SetMode::WhenStandstill),
            Ok(true)
        );
        g.step(DT);
        assert_eq!(
            g.move_to(PositionTarget::Absolute(5 << 20), l, SetMode::WhenStandstill),
            Ok(false)
        );
        assert_eq!(g.target(), 1 << 20);
        let (_, last) = run(&mut g, DT, 100_000, |_, _| {});
        assert_eq!(last.position, 1 << 20);
        assert_eq!(
            g.move_to(PositionTarget::Absolute(5 << 20), l, SetMode::WhenStandstill),
            Ok(true)
        );
        let (_, last) = run(&mut g, DT, 100_000, |_, _| {});
        assert_eq!(last.position, 5 << 20);
    }

    #[test]
    fn c041_zero_distance_move_is_done_at_once() {
        let mut g = ProfileGenerator::new(42);
        g.move_to(PositionTarget::Absolute(42), limits(), SetMode::Immediate)
            .unwrap();
        assert!(g.is_standstill());
        let s = g.step(DT);
        assert!(s.done);
        assert_eq!(s.position, 42);
    }

    #[test]
    fn c046_additive_moves_from_last_target() {
        let l = limits();
        let mut g = ProfileGenerator::new(1000);
        g.move_to(PositionTarget::Absolute(2000), l, SetMode::Immediate)
            .unwrap();
        // Interrupted after a few cycles: the next additive move still counts
        // from the last target 2000.
        g.step(DT);
        g.move_to(PositionTarget::Additive(500), l, SetMode::Immediate)
            .unwrap();
        assert_eq!(g.target(), 2500);
        let (_, last) = run(&mut g, DT, 100_000, |_, _| {});
        assert_eq!(last.position, 2500);
        for _ in 0..10 {
            g.move_to(PositionTarget::Additive(-3), l, SetMode::WhenStandstill)
                .unwrap();
            run(&mut g, DT, 100_000, |_, _| {});
        }
        assert_eq!(g.step(DT).position, 2470);
    }

    #[test]
    fn c047_relative_moves_from_actual_position() {
        let l = limits();
        let mut g = ProfileGenerator::new(1000);
        g.move_to(
            PositionTarget::Relative {
                distance: -700,
                actual: 995,
            },
            l,
            SetMode::Immediate,
        )
        .unwrap();
        assert_eq!(g.target(), 295);
        let (_, last) = run(&mut g, DT, 100_000, |_, _| {});
        assert_eq!(last.position, 295);
    }

    #[test]
    fn c055_pv_reaches_target_velocity_within_limits() {
        let l = limits();
        let mut g = ProfileGenerator::new(i32::MAX - 10);
        let mut check = limit_checker(l, DT);
        let mut prev = g.step(DT);
        for (vt, want) in [
            (1.0e7f32, 1.0e7f32),
            (-5.0e6, -5.0e6),
            (1.0e9, l.velocity), // capped at the limit
            (0.0, 0.0),
        ] {
            g.run_velocity(vt, l).unwrap();
            let mut reached = 0;
            for _ in 0..40_000 {
                let s = g.step(DT);
                check(&prev, &s);
                prev = s;
                if s.velocity == want {
                    reached += 1;
                    if reached > 10 {
                        break;
                    }
                }
            }
            assert_eq!(prev.velocity, want);
            assert_eq!(prev.acceleration, 0.0);
        }
        assert!(g.is_standstill());
        assert!(g.step(DT).done);
    }

    #[test]
    fn c055_pv_cruise_position_keeps_exact_pace() {
        // 1000.5 inc/s for 2000 s of 1 ms steps: 2 001 000 increments.
        let l = ProfileLimits {
            velocity: 1.0e6,
            acceleration: 1.0e12,
            deceleration: 1.0e12,
            jerk: f32::INFINITY,
        };
        let mut g = ProfileGenerator::new(0);
        g.take_over(0, 1000.5);
        g.run_velocity(1000.5, l).unwrap();
        let mut last = 0;
        for _ in 0..2_000_000 {
            last = g.step(1_000_000).position;
        }
        assert_eq!(last, 2_001_000);
    }

    #[test]
    fn c010_quick_stop_brakes_on_its_own_deceleration() {
        let l = limits();
        let mut g = ProfileGenerator::new(0);
        g.move_to(PositionTarget::Absolute(1 << 30), l, SetMode::Immediate)
            .unwrap();
        let mut s = g.step(DT);
        for _ in 0..8000 {
            s = g.step(DT);
        }
        let v0 = f64::from(s.velocity);
        assert!((v0 - f64::from(l.velocity)).abs() < 1.0, "cruising {v0}");
        // Quick stop 6085h = 2e9 inc/s², no jerk limit.
        let qs = 2.0e9f32;
        g.stop(qs, f32::INFINITY).unwrap();
        let mut steps = 0;
        let start = s.position;
        let (n, last) = run(&mut g, DT, 100_000, |p, s| {
            steps += 1;
            assert!(f64::from(s.acceleration).abs() <= f64::from(qs) * 1.000_001);
            assert!(s.position >= p.position);
        });
        // t = v/d = 26.2 ms = 105 cycles; distance v²/2d.
        let t = v0 / f64::from(qs);
        assert!((n as f64 - t / 250e-6).abs() <= 2.0, "{n}");
        let dist = v0 * v0 / (2.0 * f64::from(qs));
        assert!((f64::from(last.position - start) - dist).abs() < v0 * 250e-6 + 1.0);
        assert!(g.is_standstill());
        assert_eq!(g.target(), 1 << 30);
    }

    #[test]
    fn c010_halt_with_jerk_limited_ramp() {
        let l = limits();
        let mut g = ProfileGenerator::new(0);
        g.run_velocity(-3.0e7, l).unwrap();
        for _ in 0..2000 {
            g.step(DT);
        }
        // Stop while still accelerating or at speed, with 6084h and jerk.
        g.stop(l.deceleration, l.jerk).unwrap();
        let mut check = limit_checker(l, DT);
        let (_, last) = run(&mut g, DT, 100_000, |p, s| {
            check(p, s);
            assert!(s.position <= p.position);
        });
        assert_eq!(last.velocity, 0.0);
        // Stop at standstill is a no-op.
        g.stop(1.0, 1.0).unwrap();
        assert!(g.step(DT).done);
    }

    #[test]
    fn c049_invalid_limits_refused() {
        let mut g = ProfileGenerator::new(0);
        let t = PositionTarget::Absolute(1);
        let base = limits();
        for (l, e) in [
            (
                ProfileLimits {
                    velocity: 0.0,
                    ..base
                },
                ProfileError::Velocity,
            ),
            (
                ProfileLimits {
                    velocity: -1.0,
                    ..base
                },
                ProfileError::Velocity,
            ),
            (
                ProfileLimits {
                    velocity: f32::INFINITY,
                    ..base
                },
                ProfileError::Velocity,
            ),
            (
                ProfileLimits {
                    acceleration: 0.0,
                    ..base
                },
                ProfileError::Acceleration,
            ),
            (
                ProfileLimits {
                    acceleration: f32::NAN,
                    ..base
                },
                ProfileError::Acceleration,
            ),
            (
                ProfileLimits {
                    deceleration: -5.0,
                    ..base
                },
                ProfileError::Deceleration,
            ),
            (ProfileLimits { jerk: 0.0, ..base }, ProfileError::Jerk),
            (
                ProfileLimits {
                    jerk: f32::NAN,
                    ..base
                },
                ProfileError::Jerk,
            ),
        ] {
            assert_eq!(g.move_to(t, l, SetMode::Immediate), Err(e));
            assert_eq!(g.run_velocity(1.0, l), Err(e));
        }
        assert_eq!(g.run_velocity(f32::NAN, base), Err(ProfileError::TargetVelocity));
        assert_eq!(g.stop(0.0, 1.0), Err(ProfileError::Deceleration));
        assert_eq!(g.stop(1.0, -1.0), Err(ProfileError::Jerk));
        assert!(g.is_standstill());
    }

    #[test]
    fn c049_random_commands_always_end_exactly() {
        // A small LCG drives random targets, limits and interruptions.
        let mut seed = 0x1234_5678_9abc_def0u64;
        let mut rnd = move || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (seed >> 33) as u32
        };
        let mut g = ProfileGenerator::new(0);
        for _ in 0..300 {
            let l = ProfileLimits {
                velocity: 1.0e3 + (rnd() % 50_000_000) as f32,
                acceleration: 1.0e4 + (rnd() % 1_000_000_000) as f32,
                deceleration: 1.0e4 + (rnd() % 1_000_000_000) as f32,
                jerk: if rnd() % 5 == 0 {
                    f32::INFINITY
                } else {
                    1.0e6 + (rnd() % 2_000_000_000) as f32 * 50.0
                },
            };
            let target = rnd().wrapping_mul(rnd()) as i32 >> (rnd() % 24);
            g.move_to(PositionTarget::Absolute(target), l, SetMode::Immediate)
                .unwrap();
            let interrupt = rnd() % 3 == 0;
            let n = rnd() % 2000;
            let mut done = false;
            for _ in 0..n {
                let s = g.step(DT);
                assert!(s.velocity.is_finite() && s.acceleration.is_finite());
                if s.done {
                    assert_eq!(s.position, target);
                    done = true;
                    break;
                }
            }
            if interrupt && !done {
                if rnd() % 2 == 0 {
                    g.stop(l.deceleration, l.jerk).unwrap();
                } else {
                    g.run_velocity((rnd() % 1000) as f32 - 500.0, l).unwrap();
                }
                for _ in 0..50 {
                    g.step(DT);
                }
            }
        }
        // Finally: a move from wherever it is ends exactly.
        let l = limits();
        g.move_to(PositionTarget::Absolute(-77), l, SetMode::Immediate)
            .unwrap();
        let (_, last) = run(&mut g, DT, 10_000_000, |_, _| {});
        assert_eq!(last.position, -77);
    }
}
