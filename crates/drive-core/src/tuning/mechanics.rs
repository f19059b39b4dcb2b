//! B44 "identify mechanics" (issue 35; A75 selector 1111b, ours): the total
//! inertia J, the Coulomb friction Fc and the viscous friction B of the axis
//! from a bounded test move, and from them the cascade's feedforward and
//! gains.
//!
//! Started in Ready to switch on, it runs once the master enabled the axis
//! (E48 = 4, E-141), brake released. The drive moves the axis itself, under
//! a position and speed loop of its own (the cascade's command is replaced):
//!
//! 1. **kick**: a torque step of [`KICK_SHARE`] of the rated torque until the
//!    speed reaches [`KICK_SPEED_REV_S`]: a first inertia J₀ = T·t/v (high
//!    by the friction's share, which only makes the test's loop a little
//!    stiffer) for the gains of the test's own loop (speed PI with
//!    Kp = J₀·ω_t, Ti = 4/ω_t, position P ω_t/4, ω_t = 2π·15 Hz at most
//!    0.15/cycle) and for the speeds' scale (the kinetic energy ½·J₀·v²
//!    at most [`MAX_ENERGY_J`]), then a ramp back to rest;
//! 2. **legs**: for each speed of [`SPEEDS_REV_S`] a leg forward and one
//!    back: a ramp at [`ACCELERATION_REV_S2`], a constant speed for
//!    [`HOLD_S`], a ramp to rest, a rest. Forward legs leave the start
//!    position by at most s·T + s²/a (10.3 rev at the top speed), the
//!    backward ones return; the move never leaves [−[`BACK_INC`],
//!    +[`TRAVEL_INC`]] around the start (else result 11);
//! 3. **return** to the start position, and rest.
//!
//! The model is the rigid body T = J·a + Fc·sign(v) + B·v + c (c a constant
//! load such as gravity on a vertical axis, reported, not fed forward),
//! with T the commanded torque:
//!
//! - **friction**: on each constant speed, after [`SETTLE_S`], the mean
//!   torque T̄ and the mean speed v̄ = Δx/Δt (from positions, exact). Per
//!   direction a straight line T̄ = a± + B±·v̄ through the four speeds; then
//!   Fc = (a₊ − a₋)/2, c = (a₊ + a₋)/2, B = (B₊ + B₋)/2;
//! - **inertia**: over each ramp, from its start at rest or constant speed
//!   to [`SETTLE_S`] into the next constant speed, the integral of the model,
//!   ∫T dt = J·(v_b − v_a) + Fc·∫sign(v)dt + B·(x_b − x_a) + c·(t_b − t_a),
//!   with v_a, v_b the mean speeds of the [`VELOCITY_CYCLES`] cycles before
//!   each end (both in steady motion): no acceleration is differentiated
//!   from positions. J = Σ Δv·(∫T − friction terms) / Σ Δv² over the 16
//!   ramps (accelerations and decelerations: an error of the friction
//!   cancels).
//!
//! The gains for the speed-loop bandwidth f_v of B48 (ω_v = 2π·f_v):
//! speed controller Kp = J·ω_v (the loop's crossover at ω_v), Ti = 4/ω_v
//! (the PI's zero a quarter below it), position controller Kv = ω_v/4 (the
//! outer loop a quarter of the inner's bandwidth). The dictionary's gains
//! C31/C32/I20 are those of the 250 µs reference cycle (the axis scales
//! them to A150: Kp × r, Ti / r, Kv × √r, r = 250 µs / A150 ≤ 1): the
//! caller writes Kp/r, Ti·r, Kv/√r, so that the gains at A150 are these. The cascade's feedforward from B45…B47
//! ([`motion::cascade`]): J·a (a from the set-points' speed in csp/ip with
//! linear interpolation), Fc·s(v_ref) + B·v_ref with s smoothed over
//! ±0.02 rev/s.

use super::result;
use crate::axis::{sqrt, AxisCommand};
use motion::cascade::RAD_PER_INCREMENT;
use motion::float::clamp;

/// The speeds of the legs, rev/s.
pub const SPEEDS_REV_S: [f32; 4] = [3.0, 6.0, 12.0, 24.0];
/// The ramps' acceleration, rev/s².
pub const ACCELERATION_REV_S2: f32 = 300.0;
/// The time at each constant speed, s.
pub const HOLD_S: f32 = 0.35;
/// The settle time before a constant speed (or rest) is measured, s.
pub const SETTLE_S: f32 = 0.12;
/// The rest between legs, s.
pub const REST_S: f32 = 0.15;
/// The kick's torque, share of the rated torque.
pub const KICK_SHARE: f32 = 0.3;
/// The kick ends at this speed, rev/s.
pub const KICK_SPEED_REV_S: f32 = 5.0;
/// Cycles of the mean speed at a window's ends.
pub const VELOCITY_CYCLES: usize = 10;
/// The stated travel forward of the start position, increments (12 rev).
pub const TRAVEL_INC: i32 = 12 << 20;
/// The stated travel backward of the start position, increments (1 rev).
pub const BACK_INC: i32 = 1 << 20;
/// The largest kinetic energy of the test move, J: the speeds are scaled
/// down for a large inertia (J₀ from the kick) so that ½·J·v² stays below
/// it, what a DC link without a brake chopper takes back (the simulated
/// 470 µF at 565 V rise by ~9 V). (Longer constant speeds at the lower
/// speeds would narrow B's error; on the electrical plant a second-long
/// hold at a tenth of an ampere tripped the current loop's plausibility
/// check, `foc::CurrentDeviation`, so the holds stay at [`HOLD_S`].)
pub const MAX_ENERGY_J: f32 = 2.5;
/// The test loop's bandwidth, Hz (at most 0.15 / cycle).
const LOOP_HZ: f32 = 15.0;
/// The return's top speed, rev/s.
const RETURN_REV_S: f32 = 2.0;
/// The rest at the start position after the return, s.
const RETURN_REST_S: f32 = 0.5;

const TAU: f32 = core::f32::consts::TAU;
/// Stages before the legs: kick, stop, rest.
const FIRST_LEG_STAGE: u16 = 3;
/// Stages per leg.
const LEG_STAGES: u16 = 4;
/// Legs.
const LEGS: u16 = 2 * SPEEDS_REV_S.len() as u16;
/// The return stage.
const RETURN_STAGE: u16 = FIRST_LEG_STAGE + LEGS * LEG_STAGES;

/// What was identified (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mechanics {
    /// Total inertia, kg·m².
    pub inertia_kg_m2: f32,
    /// Coulomb friction, N·m.
    pub coulomb_nm: f32,
    /// Viscous friction, N·m·s/rad.
    pub viscous_nm_s_per_rad: f32,
    /// Constant load torque, N·m.
    pub load_nm: f32,
}

/// The controller gains for a speed-loop bandwidth (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gains {
    /// Speed controller Kp, N·m per rad/s.
    pub kp_nm_s_per_rad: f32,
    /// Speed controller Ti, s.
    pub ti_s: f32,
    /// Position controller Kv, 1/s.
    pub kv_per_s: f32,
}

impl Mechanics {
    /// The gains for the speed-loop bandwidth `bandwidth_hz`.
    pub fn gains(&self, bandwidth_hz: f32) -> Gains {
        let w = TAU * bandwidth_hz.max(0.1);
        Gains {
            kp_nm_s_per_rad: self.inertia_kg_m2 * w,
            ti_s: 4.0 / w,
            kv_per_s: w / 4.0,
        }
    }
}

/// Where the action stands.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MechanicsOutcome {
    /// Running, progress in %, and the largest excursion so far (increments).
    Running(u8, u32),
    /// Finished: the figures and the largest excursion.
    Done(Mechanics, u32),
    /// Failed with its [`result`] code and the largest excursion.
    Failed(u8, u32),
}

/// A window's sums (a ramp's or a constant speed's).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Window {
    /// Open.
    open: bool,
    /// Position at the start, rad.
    x0: f32,
    /// Mean speed before the start, rad/s.
    v0: f32,
    /// ∫T dt, N·m·s; ∫sign(v) dt, s; ∫dt, s.
    torque: f32,
    sign: f32,
    time: f32,
}

/// One direction's constant speeds: the sums of the straight line T̄ = a +
/// B·v̄ through them (count, Σv̄, ΣT̄, Σv̄², Σv̄·T̄).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct LineSums {
    n: f32,
    v: f32,
    t: f32,
    vv: f32,
    vt: f32,
}

impl LineSums {
    fn add(&mut self, v: f32, t: f32) {
        self.n += 1.0;
        self.v += v;
        self.t += t;
        self.vv += v * v;
        self.vt += v * t;
    }

    /// (a, B) of the least-squares line; `None` below two points.
    fn line(&self) -> Option<(f32, f32)> {
        if self.n < 2.0 {
            return None;
        }
        let (mv, mt) = (self.v / self.n, self.t / self.n);
        let b = (self.vt - self.n * mv * mt) / (self.vv - self.n * mv * mv);
        Some((mt - b * mv, b))
    }
}

/// The ramps' sums for J (the windows themselves are not kept): Σ Δv·∫T,
/// Σ Δv·∫sign, Σ Δv·Δx, Σ Δv·t, Σ Δv², over the closed ramp windows.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct RampSums {
    torque: f32,
    sign: f32,
    dx: f32,
    time: f32,
    dv2: f32,
}

/// The B44 test of one axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MechanicsTest {
    dt_s: f32,
    kick_nm: f32,
    max_nm: f32,
    /// The start position, increments.
    start_inc: Option<i32>,
    /// The last position relative to the start, increments.
    last_inc: i32,
    /// The last positions relative to the start (ring), increments.
    history: [i32; VELOCITY_CYCLES],
    cycles_total: u32,
    stage: u16,
    stage_cycles: u32,
    /// The first inertia (kick), kg·m².
    j0: f32,
    /// The speeds' scale (≤ 1, [`MAX_ENERGY_J`]).
    speed_scale: f32,
    /// The test loop: speed PI integral, N·m; references.
    integral_nm: f32,
    x_ref: f32,
    v_ref: f32,
    a_ref: f32,
    /// The return reached the start position.
    returned: bool,
    ramp: Window,
    plateau: Window,
    ramps: RampSums,
    /// (mean speed rad/s, mean torque N·m) per leg's constant speed.
    plateaus: [LineSums; 2],
    result: Option<Mechanics>,
    excursion_inc: u32,
    outcome: MechanicsOutcome,
}

impl MechanicsTest {
    /// A test at a control cycle of `dt_s` for a motor of rated torque
    /// `rated_nm`, commands within ±`max_nm`.
    pub fn new(dt_s: f32, rated_nm: f32, max_nm: f32) -> Self {
        let pos = |x: f32, fallback: f32| if x > 0.0 && x.is_finite() { x } else { fallback };
        let max_nm = pos(max_nm, 1.0);
        Self {
            dt_s: pos(dt_s, 1.0e-3).min(0.01),
            kick_nm: (KICK_SHARE * pos(rated_nm, 1.0)).min(max_nm),
            max_nm,
            start_inc: None,
            last_inc: 0,
            history: [0; VELOCITY_CYCLES],
            cycles_total: 0,
            stage: 0,
            stage_cycles: 0,
            j0: 0.0,
            speed_scale: 1.0,
            integral_nm: 0.0,
            x_ref: 0.0,
            v_ref: 0.0,
            a_ref: 0.0,
            returned: false,
            ramp: Window::default(),
            plateau: Window::default(),
            ramps: RampSums::default(),
            plateaus: [LineSums::default(); 2],
            result: None,
            excursion_inc: 0,
            outcome: MechanicsOutcome::Running(0, 0),
        }
    }

    /// Where it stands.
    pub fn outcome(&self) -> MechanicsOutcome {
        self.outcome
    }

    /// Whether a start at `position` (in the units of the limits) with the
    /// software limits `min`/`max` (active when min < max) and `travel`
    /// (forward) / `back` in the same units keeps the test move inside them.
    pub fn travel_allowed(position: i64, min: i64, max: i64, travel: i64, back: i64) -> bool {
        min >= max
            || (position.checked_add(travel).is_some_and(|p| p <= max)
                && position.checked_sub(back).is_some_and(|p| p >= min))
    }

    /// One control cycle: the axis' state `e48` after its cycle and the
    /// encoder position (increments); the command that replaces the axis'
    /// (`None`: its own).
    pub fn cycle(&mut self, e48: u8, position_inc: i32) -> Option<AxisCommand> {
        if !matches!(self.outcome, MechanicsOutcome::Running(..)) {
            return None;
        }
        if e48 != 4 {
            if self.start_inc.is_some() || !(e48 == 2 || e48 == 3) {
                return self.fail(result::ABORTED);
            }
            return None;
        }
        let start = *self.start_inc.get_or_insert(position_inc);
        let x_inc = position_inc.wrapping_sub(start);
        if !(-BACK_INC..=TRAVEL_INC).contains(&x_inc) {
            return self.fail(result::OUT_OF_TRAVEL);
        }
        self.excursion_inc = self.excursion_inc.max(x_inc.unsigned_abs());
        let dt = self.dt_s;
        let x = x_inc as f32 * RAD_PER_INCREMENT;
        let v = x_inc.wrapping_sub(self.last_inc) as f32 * RAD_PER_INCREMENT / dt;
        let sign = sign_of(x_inc.wrapping_sub(self.last_inc));
        let slot = (self.cycles_total as usize) % VELOCITY_CYCLES;
        let before = self.history.get(slot).copied().unwrap_or(x_inc);
        if let Some(h) = self.history.get_mut(slot) {
            *h = x_inc;
        }
        let v_mean = if self.cycles_total as usize >= VELOCITY_CYCLES {
            x_inc.wrapping_sub(before) as f32 * RAD_PER_INCREMENT / (VELOCITY_CYCLES as f32 * dt)
        } else {
            0.0
        };
        self.last_inc = x_inc;
        self.cycles_total = self.cycles_total.saturating_add(1);

        // the windows: the interval just ended belongs to the open ones
        for w in [&mut self.ramp, &mut self.plateau] {
            if w.open {
                w.sign += sign * dt;
            }
        }
        let torque = match self.step(x, v, v_mean) {
            Ok(t) => t,
            Err(code) => return self.fail(code),
        };
        if self.stage > RETURN_STAGE {
            self.outcome = match self.result {
                Some(m) => MechanicsOutcome::Done(m, self.excursion_inc),
                None => MechanicsOutcome::Failed(result::IMPLAUSIBLE, self.excursion_inc),
            };
            return None;
        }
        for w in [&mut self.ramp, &mut self.plateau] {
            if w.open {
                w.torque += torque * dt;
                w.time += dt;
            }
        }
        let progress = (u32::from(self.stage) * 100 / (u32::from(RETURN_STAGE) + 2)).min(99) as u8;
        self.outcome = MechanicsOutcome::Running(progress, self.excursion_inc);
        Some(AxisCommand {
            torque_nm: torque,
            power_stage: true,
            brake_release: true,
            injection: None,
        })
    }

    /// The stage machine: the torque of this cycle.
    fn step(&mut self, x: f32, v: f32, v_mean: f32) -> Result<f32, u8> {
        let dt = self.dt_s;
        let cycles = |s: f32| (s / dt) as u32;
        let a = ACCELERATION_REV_S2 * TAU;
        self.stage_cycles = self.stage_cycles.saturating_add(1);
        self.a_ref = 0.0;
        match self.stage {
            0 => {
                // kick
                // the command of a cycle acts until the next: after m
                // cycles the last interval's mean speed is a·(m − 1.5)·dt
                let n = self.stage_cycles as f32 - 1.5;
                if v >= KICK_SPEED_REV_S * TAU || self.stage_cycles > cycles(0.2) {
                    if v < 0.05 * KICK_SPEED_REV_S * TAU {
                        return Err(result::NOT_SETTLED);
                    }
                    self.j0 = self.kick_nm * n * dt / v;
                    let top = SPEEDS_REV_S.iter().fold(0.0f32, |m, &s| m.max(s)) * TAU;
                    let allowed = sqrt(2.0 * MAX_ENERGY_J / self.j0);
                    self.speed_scale = clamp(allowed / top, 0.05, 1.0);
                    (self.x_ref, self.v_ref, self.integral_nm) = (x, v, 0.0);
                    self.next_stage();
                } else {
                    return Ok(self.kick_nm);
                }
            }
            1 => {
                if self.ramp_to(0.0, a) {
                    self.next_stage();
                }
            }
            2 => {
                if self.stage_cycles >= cycles(REST_S) {
                    self.next_stage();
                }
            }
            RETURN_STAGE => {
                // back to the start: approach x = 0 within the deceleration
                let d = -self.x_ref;
                let reach = sqrt(2.0 * a * d.abs()).min(RETURN_REV_S * TAU);
                let step = reach * dt;
                if self.returned || d.abs() <= step {
                    (self.x_ref, self.v_ref) = (0.0, 0.0);
                    if !self.returned {
                        self.returned = true;
                        self.stage_cycles = 0;
                    } else if self.stage_cycles > cycles(RETURN_REST_S) {
                        self.next_stage();
                        return Ok(0.0);
                    }
                } else if self.stage_cycles > cycles(20.0) {
                    return Err(result::OUT_OF_TRAVEL);
                } else {
                    self.v_ref = reach * d.signum();
                }
            }
            s if s < RETURN_STAGE => {
                let k = s.saturating_sub(FIRST_LEG_STAGE);
                let leg = k / LEG_STAGES;
                let part = k % LEG_STAGES;
                let dir = if leg % 2 == 0 { 1.0 } else { -1.0 };
                let speed = SPEEDS_REV_S.get(usize::from(leg / 2)).copied().unwrap_or(0.0)
                    * TAU
                    * dir
                    * self.speed_scale;
                match part {
                    0 | 2 => {
                        if self.stage_cycles == 1 {
                            self.ramp = Window {
                                open: true,
                                x0: x,
                                v0: v_mean,
                                ..Window::default()
                            };
                        }
                        let target = if part == 0 { speed } else { 0.0 };
                        if self.ramp_to(target, a) {
                            self.next_stage();
                        }
                    }
                    _ => {
                        // constant speed (1) or rest (3): the ramp's window
                        // closes after the settle time, the speed's is
                        // measured from there to the end
                        let hold = if part == 1 { HOLD_S } else { REST_S };
                        // a deceleration's window closes where the shaft
                        // stops (from there a breakaway friction holds what
                        // the model does not know), at the latest then
                        let stopped = part == 3 && v * w_dir(self.ramp.x0, x) <= 0.0;
                        if self.ramp.open && (stopped || self.stage_cycles == cycles(SETTLE_S)) {
                            let w = self.ramp;
                            self.ramp.open = false;
                            let v_end = if part == 3 { v } else { v_mean };
                            let dv = v_end - w.v0;
                            let r = &mut self.ramps;
                            r.torque += dv * w.torque;
                            r.sign += dv * w.sign;
                            r.dx += dv * (x - w.x0);
                            r.time += dv * w.time;
                            r.dv2 += dv * dv;
                            if part == 1 {
                                self.plateau = Window {
                                    open: true,
                                    x0: x,
                                    ..Window::default()
                                };
                            }
                        }
                        if self.stage_cycles >= cycles(hold) {
                            if part == 1 {
                                let w = self.plateau;
                                self.plateau.open = false;
                                if w.time <= 0.0 {
                                    return Err(result::NOT_SETTLED);
                                }
                                let (v_mean, t_mean) = ((x - w.x0) / w.time, w.torque / w.time);
                                if let Some(p) = self.plateaus.get_mut(usize::from(leg % 2)) {
                                    p.add(v_mean, t_mean);
                                }
                            }
                            self.next_stage();
                            if self.stage == RETURN_STAGE {
                                self.result = self.identify();
                                self.plateau = Window::default();
                            }
                        }
                    }
                }
            }
            _ => return Ok(0.0),
        }
        Ok(self.control(x, v))
    }

    /// The test's loop: position P + speed PI + J₀·a, within ±max.
    fn control(&mut self, x: f32, v: f32) -> f32 {
        let dt = self.dt_s;
        let w = (TAU * LOOP_HZ).min(0.15 / dt);
        self.x_ref += self.v_ref * dt;
        let kp = self.j0 * w;
        let v_cmd = self.v_ref + 0.25 * w * (self.x_ref - x);
        let e = v_cmd - v;
        let p = kp * e;
        self.integral_nm = (self.integral_nm + p * dt * w * 0.25)
            .max(-self.max_nm)
            .min(self.max_nm);
        let t = p + self.integral_nm + self.j0 * self.a_ref;
        if t.is_finite() {
            clamp(t, -self.max_nm, self.max_nm)
        } else {
            0.0
        }
    }

    /// Moves `v_ref` toward `target` by `a`·dt; whether it arrived.
    fn ramp_to(&mut self, target: f32, a: f32) -> bool {
        let step = a * self.dt_s;
        if (target - self.v_ref).abs() <= step {
            self.v_ref = target;
            true
        } else {
            let dir = if target > self.v_ref { 1.0 } else { -1.0 };
            self.v_ref += step * dir;
            self.a_ref = a * dir;
            false
        }
    }

    fn next_stage(&mut self) {
        self.stage = self.stage.saturating_add(1);
        self.stage_cycles = 0;
    }

    /// The figures from the windows (see the module docs).
    fn identify(&self) -> Option<Mechanics> {
        let [forward, backward] = self.plateaus;
        let (ap, bp) = forward.line()?;
        let (an, bn) = backward.line()?;
        let coulomb = 0.5 * (ap - an);
        let load = 0.5 * (ap + an);
        let viscous = 0.5 * (bp + bn);
        let r = self.ramps;
        let j = (r.torque - coulomb * r.sign - viscous * r.dx - load * r.time) / r.dv2;
        let ok = |x: f32| x.is_finite();
        (ok(j) && j > 0.0 && ok(coulomb) && ok(viscous) && ok(load)).then_some(Mechanics {
            inertia_kg_m2: j,
            coulomb_nm: coulomb.max(0.0),
            viscous_nm_s_per_rad: viscous.max(0.0),
            load_nm: load,
        })
    }

    fn fail(&mut self, code: u8) -> Option<AxisCommand> {
        self.outcome = MechanicsOutcome::Failed(code, self.excursion_inc);
        None
    }
}

/// The direction of a movement from `x0` to `x` (rad): ±1.
fn w_dir(x0: f32, x: f32) -> f32 {
    if x >= x0 {
        1.0
    } else {
        -1.0
    }
}

fn sign_of(d: i32) -> f32 {
    match d {
        d if d > 0 => 1.0,
        d if d < 0 => -1.0,
        _ => 0.0,
    }
}
