//! Simulated motor and load: a torque-driven rotor with encoder, index pulse,
//! limit/reference switches and touch-probe inputs.
//!
//! # Model
//!
//! One rigid rotor (motor plus load reflected to the shaft), inertia `J`:
//!
//! ```text
//! J·dω/dt = T_motor + T_gravity(θ) − b·ω − T_coulomb·sign(ω) − T_brake·sign(ω)
//! ```
//!
//! - `T_motor` is the commanded torque (N·m), clamped to ±`max_torque_nm`,
//!   with a **one-cycle actuation delay**: the command given to
//!   [`Motor::step`] number k acts during step k+1 (step k uses the command of
//!   step k−1; the very first step uses 0 N·m, brake as given in
//!   [`MotorParams::initial_brake_engaged`]). The brake command is delayed the
//!   same way.
//! - Viscous friction `b` is integrated implicitly, so it is stable for any
//!   step length.
//! - Coulomb friction and the brake follow a stick–slip (Karnopp) rule: while
//!   the rotor is at rest (or slower than the stiction band) and
//!   `|T_motor + T_gravity|` is within the static torque (breakaway friction
//!   plus the brake's holding torque if engaged), the rotor sticks at exactly
//!   zero velocity. A moving rotor whose velocity would change sign inside a
//!   sub-step stops at zero (and sticks if the static torque holds it), so
//!   there is no chatter around zero velocity. A slipping brake brakes with its
//!   holding torque.
//! - Gravity ([`GravityLoad`]): none, a constant torque (vertical axis through
//!   a screw, belt or rack: the weight acts as a constant torque), or an
//!   unbalanced arm `T = −m·g·r·cos(θ − θ_h)` (θ_h = where the arm is
//!   horizontal on the positive side).
//! - Optional rigid end stops (for torque-limit homing, spec §9 methods −1…−4):
//!   the rotor stops dead at them.
//!
//! Internal sub-steps of at most [`MotorParams::max_substep`] (default
//! 10 µs) make 62.5 µs … 8 ms control cycles equally accurate. Velocity uses
//! semi-implicit Euler; position the trapezoid rule (exact for constant
//! acceleration). Position is an `i64` encoder count plus an `f64` fraction of
//! an increment, so long runs neither drift nor lose resolution.
//!
//! # Encoder and inputs
//!
//! 2^20 increments per revolution ([`INC_PER_REV`]). The encoder count is the
//! floor of the continuous position; [`MotorOutputs::position_inc`] wraps it to
//! `i32` (optional seeded noise, off by default). The index (zero) pulse fires
//! at every position `≡ index_offset_inc (mod 2^20)`, in both directions.
//! Limit, reference and touch-probe inputs are position-defined
//! ([`PositionInput`]); every level change and index pulse is reported with
//! its exact crossing time, linearly interpolated inside the sub-step.
//!
//! No heap, no `std`, no randomness unless seeded: the same inputs give the
//! same outputs bit for bit.
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]
#![deny(missing_docs)]

mod inputs;
#[cfg(test)]
mod tests;

pub use inputs::{
    CapacityError, Edge, EdgeList, Input, InputLevels, PositionInput, Switches, MAX_EDGES_PER_STEP, MAX_MARKS,
};

use core::f64::consts::{FRAC_PI_2, PI, TAU};
use inputs::Crossing;
use nanos::Nanos;

/// Encoder increments per revolution (2^20), fixed.
pub const INC_PER_REV: i64 = 1 << 20;

/// Increments per radian.
pub const INC_PER_RAD: f64 = INC_PER_REV as f64 / TAU;

/// Gravity (or other position-dependent) load torque acting on the rotor.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum GravityLoad {
    /// No gravity load (horizontal axis or balanced load).
    #[default]
    None,
    /// Constant torque, N·m, signed: negative pulls towards negative positions.
    /// Models a vertical axis through a screw, belt or rack.
    Constant {
        /// Load torque on the shaft, N·m.
        torque_nm: f64,
    },
    /// Unbalanced arm (pendulum): `T = −amplitude_nm · cos(θ − θ_h)`, with
    /// `amplitude_nm = m·g·r` and θ_h the angle where the arm is horizontal,
    /// pointing so that positive rotation lifts it. The arm hangs (stable) at
    /// θ_h − 90° and stands upright (unstable) at θ_h + 90°.
    Arm {
        /// `m·g·r`, N·m.
        amplitude_nm: f64,
        /// Encoder position where the arm is horizontal, increments (taken
        /// modulo one revolution).
        horizontal_inc: i64,
    },
}

/// Parameters of the motor, load and encoder. SI units are named in the field
/// names. See [`MotorParams::default_servo`] for plausible values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorParams {
    /// Total inertia on the shaft (rotor + reflected load), kg·m². Values below
    /// 1e-9 are treated as 1e-9.
    pub inertia_kg_m2: f64,
    /// Viscous friction, N·m·s/rad.
    pub viscous_friction_nm_s_per_rad: f64,
    /// Coulomb (sliding) friction, N·m.
    pub coulomb_friction_nm: f64,
    /// Static (breakaway) friction, N·m; the larger of this and the Coulomb
    /// friction must be exceeded to start moving.
    pub static_friction_nm: f64,
    /// Stiction band, rad/s: below this speed a rotor whose driving torque is
    /// within the static torque is stopped.
    pub stiction_velocity_rad_s: f64,
    /// Gravity load.
    pub gravity: GravityLoad,
    /// Rated torque, N·m: the reference of the 0.1 % torque values (6071h,
    /// 6077h, 6072h).
    pub rated_torque_nm: f64,
    /// Peak torque, N·m: commands are clamped to ±this.
    pub max_torque_nm: f64,
    /// Holding torque of the holding brake, N·m (also its sliding torque).
    pub brake_holding_torque_nm: f64,
    /// Brake state before the first command has taken effect.
    pub initial_brake_engaged: bool,
    /// A fault: the brake stays closed whatever is commanded (a stuck
    /// armature, no brake supply); it brakes with its holding torque.
    pub brake_stuck: bool,
    /// Index pulse position within a revolution, increments (taken modulo 2^20).
    pub index_offset_inc: i64,
    /// Encoder count at start, increments (absolute, unwrapped).
    pub initial_position_inc: i64,
    /// Rigid end stops `(lowest, highest)`, increments, or `None`.
    pub end_stops_inc: Option<(i64, i64)>,
    /// Longest internal integration sub-step (values below 100 ns are
    /// treated as 100 ns).
    pub max_substep: Nanos,
    /// Encoder noise amplitude, increments: the reported position gets a
    /// uniform offset in `±encoder_noise_inc`. 0 = off (default).
    pub encoder_noise_inc: u32,
    /// Seed of the noise generator (xorshift64*).
    pub noise_seed: u64,
}

impl MotorParams {
    /// A small servo motor, about 400 W class, with a light load and a holding
    /// brake, on a horizontal axis:
    ///
    /// | value | |
    /// |---|---|
    /// | inertia | 1e-4 kg·m² (rotor ≈ 0.4e-4 plus load) |
    /// | rated / peak torque | 1.3 N·m / 3.9 N·m (3 ×) |
    /// | viscous friction | 2e-5 N·m·s/rad (≈ 6 mN·m at 3000 rpm) |
    /// | Coulomb / breakaway friction | 0.02 / 0.03 N·m |
    /// | stiction band | 1e-3 rad/s (≈ 0.01 rpm) |
    /// | brake holding torque | 2.0 N·m |
    /// | index pulse | at 0 within the revolution |
    /// | sub-step | 10 µs |
    pub const fn default_servo() -> Self {
        Self {
            inertia_kg_m2: 1.0e-4,
            viscous_friction_nm_s_per_rad: 2.0e-5,
            coulomb_friction_nm: 0.02,
            static_friction_nm: 0.03,
            stiction_velocity_rad_s: 1.0e-3,
            gravity: GravityLoad::None,
            rated_torque_nm: 1.3,
            max_torque_nm: 3.9,
            brake_holding_torque_nm: 2.0,
            initial_brake_engaged: false,
            brake_stuck: false,
            index_offset_inc: 0,
            initial_position_inc: 0,
            end_stops_inc: None,
            max_substep: Nanos::from_us(10),
            encoder_noise_inc: 0,
            noise_seed: 0x5eed_0000_0000_0001,
        }
    }

    /// A frictionless, brakeless rotor of inertia `inertia_kg_m2` (for tests and
    /// open-loop checks); rated and peak torque as [`Self::default_servo`].
    pub const fn frictionless(inertia_kg_m2: f64) -> Self {
        let mut p = Self::default_servo();
        p.set_flywheel(inertia_kg_m2);
        p.stiction_velocity_rad_s = 0.0;
        p
    }

    /// The load made a bare flywheel of inertia `inertia_kg_m2`: no viscous,
    /// Coulomb or static friction and no holding brake; the other data stay
    /// (`serve --flywheel`, the chopper's fault-matrix rows).
    pub const fn set_flywheel(&mut self, inertia_kg_m2: f64) {
        self.inertia_kg_m2 = inertia_kg_m2;
        self.viscous_friction_nm_s_per_rad = 0.0;
        self.coulomb_friction_nm = 0.0;
        self.static_friction_nm = 0.0;
        self.brake_holding_torque_nm = 0.0;
    }

    /// Torque in N·m from a value in 0.1 % of the rated torque (CiA 402 6071h
    /// target torque).
    pub fn torque_from_permille(&self, permille: i16) -> f64 {
        f64::from(permille) * 1.0e-3 * self.rated_torque_nm
    }

    /// Torque in 0.1 % of the rated torque (CiA 402 6077h actual torque),
    /// rounded to nearest and saturated to `i16`; 0 for a rated torque of 0.
    pub fn torque_to_permille(&self, torque_nm: f64) -> i16 {
        if self.rated_torque_nm.is_nan() || self.rated_torque_nm <= 0.0 {
            return 0;
        }
        let x = torque_nm / self.rated_torque_nm * 1.0e3;
        // `as` saturates and maps NaN to 0.
        round_half_away(x) as i16
    }

    fn clamp_torque(&self, torque_nm: f64) -> f64 {
        if torque_nm.is_nan() {
            return 0.0;
        }
        let max = if self.max_torque_nm > 0.0 {
            self.max_torque_nm
        } else {
            0.0
        };
        torque_nm.clamp(-max, max)
    }
}

impl Default for MotorParams {
    fn default() -> Self {
        Self::default_servo()
    }
}

/// An index (zero) pulse seen during a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IndexEvent {
    /// Encoder position of the pulse, increments, wrapped to `i32`.
    pub position_inc: i32,
    /// Time of the pulse after the start of the step.
    pub time_offset: Nanos,
    /// Crossed while moving in the positive direction.
    pub positive: bool,
}

/// What the drive reads back after one [`Motor::step`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorOutputs {
    /// Encoder position at the end of the step, increments (2^20 per
    /// revolution), quantised (floor), wrapping on `i32`, plus noise if enabled.
    pub position_inc: i32,
    /// Velocity at the end of the step, increments per second (not quantised).
    pub velocity_inc_per_s: f64,
    /// Torque that acted during this step (the previous command, clamped), N·m.
    pub torque_applied_nm: f64,
    /// Brake state that acted during this step.
    pub brake_applied: bool,
    /// The first index pulse of this step.
    pub index: Option<IndexEvent>,
    /// Number of index pulses in this step (usually 0 or 1).
    pub index_count: u32,
    /// Electrical levels of the inputs at the end of the step.
    pub inputs: InputLevels,
    /// Level changes of the inputs during the step, earliest first.
    pub edges: EdgeList,
    /// Simulated time at the start of the step, since creation.
    pub step_start: Nanos,
    /// The rotor rests against an end stop at the end of the step.
    pub at_end_stop: bool,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Actuation {
    torque_nm: f64,
    brake: bool,
}

/// The simulated motor, load, encoder and position-defined inputs of one axis.
#[derive(Debug, Clone)]
pub struct Motor {
    params: MotorParams,
    switches: Switches,
    /// Encoder count (floor of the continuous position), increments.
    pos_int: i64,
    /// Fraction of an increment, `[0, 1)`.
    pos_frac: f64,
    /// Angular velocity, rad/s.
    vel_rad_s: f64,
    /// Held by static friction / brake (velocity exactly 0).
    stuck: bool,
    at_end_stop: bool,
    /// The command that acts during the next step.
    pending: Actuation,
    /// Simulated time.
    time: Nanos,
    rng: u64,
}

impl Motor {
    /// A motor at rest at `params.initial_position_inc`.
    pub fn new(params: MotorParams, switches: Switches) -> Self {
        let mut m = Self {
            params,
            switches,
            pos_int: 0,
            pos_frac: 0.0,
            vel_rad_s: 0.0,
            stuck: true,
            at_end_stop: false,
            pending: Actuation {
                torque_nm: 0.0,
                brake: params.initial_brake_engaged,
            },
            time: Nanos::ZERO,
            rng: 0,
        };
        m.set_position_inc(params.initial_position_inc);
        m.rng = if params.noise_seed == 0 {
            0x9e37_79b9_7f4a_7c15
        } else {
            params.noise_seed
        };
        m
    }

    /// [`MotorParams::default_servo`] with no switches fitted.
    pub fn default_servo() -> Self {
        Self::new(MotorParams::default_servo(), Switches::default())
    }

    /// The parameters.
    pub fn params(&self) -> &MotorParams {
        &self.params
    }

    /// Changes parameters (takes effect in the next step; position, velocity
    /// and the pending command are kept).
    pub fn params_mut(&mut self) -> &mut MotorParams {
        &mut self.params
    }

    /// The position-defined inputs.
    pub fn switches(&self) -> &Switches {
        &self.switches
    }

    /// Changes the position-defined inputs (no edges are reported for the
    /// change itself).
    pub fn switches_mut(&mut self) -> &mut Switches {
        &mut self.switches
    }

    /// Puts the rotor at encoder count `position_inc` (absolute), fraction 0,
    /// keeping its velocity. No edges are reported.
    pub fn set_position_inc(&mut self, position_inc: i64) {
        self.pos_int = position_inc;
        self.pos_frac = 0.0;
        self.apply_end_stops();
    }

    /// Sets the angular velocity, rad/s (a non-zero value releases stiction).
    pub fn set_velocity_rad_s(&mut self, velocity_rad_s: f64) {
        self.vel_rad_s = if velocity_rad_s.is_finite() {
            velocity_rad_s
        } else {
            0.0
        };
        self.stuck = self.vel_rad_s == 0.0;
    }

    /// Encoder count, increments, absolute (not wrapped, no noise).
    pub fn position_inc_i64(&self) -> i64 {
        self.pos_int
    }

    /// Continuous position, increments (absolute; loses sub-increment
    /// resolution beyond about 2^40 increments).
    pub fn position_inc_f64(&self) -> f64 {
        self.pos_int as f64 + self.pos_frac
    }

    /// Angular velocity, rad/s.
    pub fn velocity_rad_s(&self) -> f64 {
        self.vel_rad_s
    }

    /// Simulated time since creation (sum of all `dt`).
    pub fn time(&self) -> Nanos {
        self.time
    }

    /// Electrical input levels now.
    pub fn inputs(&self) -> InputLevels {
        self.switches.levels_at(self.pos_int)
    }

    /// Advances the simulation by `dt` (one control cycle).
    ///
    /// `torque_cmd_nm` and `brake_engaged` take effect one cycle later: during
    /// this step the command of the previous call acts. Returns the state at
    /// the end of the step and the events during it.
    pub fn step(&mut self, torque_cmd_nm: f64, brake_engaged: bool, dt: Nanos) -> MotorOutputs {
        let dt_ns = dt.as_ns();
        let act = self.pending;
        self.pending = Actuation {
            torque_nm: self.params.clamp_torque(torque_cmd_nm),
            brake: brake_engaged,
        };

        let mut edges = EdgeList::new();
        let mut index = None;
        let mut index_count = 0u32;

        let max_sub = self.params.max_substep.as_ns().max(100);
        let n = dt_ns.div_ceil(max_sub).max(1);
        let mut t_prev = 0u64;
        for i in 1..=n {
            let t_next = match dt_ns.checked_mul(i) {
                Some(p) => p / n,
                None => (u128::from(dt_ns) * u128::from(i) / u128::from(n)) as u64,
            };
            let h_ns = t_next - t_prev;
            let (p0_int, p0_frac) = (self.pos_int, self.pos_frac);
            let held = self.substep(act, h_ns as f64 * 1.0e-9);
            if self.pos_int != p0_int {
                let c = Crossing {
                    p0_int,
                    p0_frac,
                    p1_int: self.pos_int,
                    delta: (self.pos_int - p0_int) as f64 + (self.pos_frac - p0_frac),
                    t0_ns: t_prev,
                    h_ns,
                };
                let count = self.detect_index(&c, &mut index);
                index_count = index_count.saturating_add(count);
                self.switches.detect(&c, &mut edges);
            }
            t_prev = t_next;
            if held {
                // the rotor holds: so does every later sub-step of this step
                // (the same torque at the same position), changing nothing
                break;
            }
        }
        edges.sort_by_time();

        let step_start = self.time;
        self.time = self.time.saturating_add(dt);
        let noise = self.noise();
        MotorOutputs {
            position_inc: self.pos_int.wrapping_add(noise) as i32,
            velocity_inc_per_s: self.vel_rad_s * INC_PER_RAD,
            torque_applied_nm: act.torque_nm,
            brake_applied: act.brake,
            index,
            index_count,
            inputs: self.inputs(),
            edges,
            step_start,
            at_end_stop: self.at_end_stop,
        }
    }

    /// [`Self::step`] with `torque_nm` and `brake_engaged` acting during this
    /// step already (no actuation delay): for a caller that models the delay
    /// itself (the electrical axis, [`crate::electrical`], one PWM period per call).
    pub fn step_applied(&mut self, torque_nm: f64, brake_engaged: bool, dt: Nanos) -> MotorOutputs {
        self.pending = Actuation {
            torque_nm: self.params.clamp_torque(torque_nm),
            brake: brake_engaged,
        };
        self.step(torque_nm, brake_engaged, dt)
    }

    /// [`Self::step`] with the torque in 0.1 % of the rated torque (6071h).
    pub fn step_permille(
        &mut self,
        torque_cmd_permille: i16,
        brake_engaged: bool,
        dt: Nanos,
    ) -> MotorOutputs {
        let t = self.params.torque_from_permille(torque_cmd_permille);
        self.step(t, brake_engaged, dt)
    }

    /// Load torque from gravity at the current position, N·m.
    pub fn gravity_torque_nm(&self) -> f64 {
        match self.params.gravity {
            GravityLoad::None => 0.0,
            GravityLoad::Constant { torque_nm } => torque_nm,
            GravityLoad::Arm {
                amplitude_nm,
                horizontal_inc,
            } => {
                let rel = self.pos_int.wrapping_sub(horizontal_inc).rem_euclid(INC_PER_REV);
                let theta = (rel as f64 + self.pos_frac) / INC_PER_RAD;
                -amplitude_nm * cos(theta)
            }
        }
    }

    /// One integration sub-step of `h` seconds under `act`; `true` when the
    /// rotor holds (at rest, the driving torque within the static friction
    /// and brake): the sub-step then only sets it at rest, whatever `h`.
    fn substep(&mut self, act: Actuation, h: f64) -> bool {
        let p = &self.params;
        let j = p.inertia_kg_m2.max(1.0e-9);
        let b = p.viscous_friction_nm_s_per_rad.max(0.0);
        let brake = if act.brake || p.brake_stuck {
            p.brake_holding_torque_nm.max(0.0)
        } else {
            0.0
        };
        let kinetic = p.coulomb_friction_nm.max(0.0) + brake;
        let stat = p.static_friction_nm.max(p.coulomb_friction_nm).max(0.0) + brake;
        let band = p.stiction_velocity_rad_s.max(0.0);
        let drive = act.torque_nm + self.gravity_torque_nm();
        let damp = 1.0 + h * b / j;
        let v0 = self.vel_rad_s;
        let holds = abs(drive) <= stat;

        if self.stuck || v0 == 0.0 || (abs(v0) < band && holds) {
            if holds {
                self.vel_rad_s = 0.0;
                self.stuck = true;
                return true;
            }
            // Break away: sliding friction opposes the driving torque.
            self.stuck = false;
            let net = drive - sign(drive) * kinetic;
            let v1 = (v0 + h * net / j) / damp;
            self.advance(v0, v1, h);
            return false;
        }

        let friction = -sign(v0) * kinetic;
        let v1 = (v0 + h * (drive + friction) / j) / damp;
        if v0 * v1 <= 0.0 && holds {
            // The rotor reaches zero speed inside the sub-step and sticks.
            let denom = v0 - v1;
            let tau = if denom != 0.0 { v0 / denom } else { 0.0 };
            self.advance(v0, 0.0, h * tau.clamp(0.0, 1.0));
            self.vel_rad_s = 0.0;
            self.stuck = true;
        } else {
            self.advance(v0, v1, h);
        }
        false
    }

    /// Moves by the trapezoid `(v0 + v1)/2 · h` and sets the velocity to `v1`.
    fn advance(&mut self, v0: f64, v1: f64, h: f64) {
        self.vel_rad_s = v1;
        let dx = 0.5 * (v0 + v1) * h * INC_PER_RAD;
        if dx.is_finite() {
            let x = self.pos_frac + dx;
            let whole = floor(x);
            // `as` saturates; whole is far inside i64 for any sane speed.
            self.pos_int = self.pos_int.saturating_add(whole as i64);
            let mut frac = x - whole;
            if frac >= 1.0 {
                frac -= 1.0;
                self.pos_int = self.pos_int.saturating_add(1);
            }
            self.pos_frac = if frac > 0.0 { frac } else { 0.0 };
        } else {
            self.vel_rad_s = 0.0;
            self.stuck = true;
        }
        self.apply_end_stops();
    }

    fn apply_end_stops(&mut self) {
        self.at_end_stop = false;
        let Some((lo, hi)) = self.params.end_stops_inc else {
            return;
        };
        if self.pos_int >= hi {
            if self.pos_int > hi || self.pos_frac > 0.0 || self.vel_rad_s > 0.0 {
                self.pos_int = hi;
                self.pos_frac = 0.0;
                self.vel_rad_s = self.vel_rad_s.min(0.0);
            }
            self.at_end_stop = self.pos_int == hi && self.pos_frac == 0.0;
        } else if self.pos_int < lo {
            self.pos_int = lo;
            self.pos_frac = 0.0;
            self.vel_rad_s = self.vel_rad_s.max(0.0);
            self.at_end_stop = true;
        } else if self.pos_int == lo && self.pos_frac == 0.0 {
            self.at_end_stop = true;
        }
    }

    /// Index pulses crossed in sub-step `c`; records the first of the step.
    fn detect_index(&self, c: &Crossing, first: &mut Option<IndexEvent>) -> u32 {
        let off = self.params.index_offset_inc.rem_euclid(INC_PER_REV);
        let rev = |p: i64| p.wrapping_sub(off).div_euclid(INC_PER_REV);
        let (r0, r1) = (rev(c.p0_int), rev(c.p1_int));
        if r0 == r1 {
            return 0;
        }
        let positive = r1 > r0;
        let mark_rev = if positive { r0 + 1 } else { r0 };
        let mark = mark_rev.wrapping_mul(INC_PER_REV).wrapping_add(off);
        if first.is_none() {
            *first = Some(IndexEvent {
                position_inc: mark as i32,
                time_offset: Nanos::from_ns(c.time_of(mark)),
                positive,
            });
        }
        u32::try_from(r1.abs_diff(r0)).unwrap_or(u32::MAX)
    }

    /// Encoder noise of this step (xorshift64*), increments.
    fn noise(&mut self) -> i64 {
        let a = self.params.encoder_noise_inc;
        if a == 0 {
            return 0;
        }
        let mut x = self.rng;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.rng = x;
        let r = x.wrapping_mul(0x2545_f491_4f6c_dd1d);
        let span = 2 * u64::from(a) + 1;
        (r % span) as i64 - i64::from(a)
    }
}

fn abs(x: f64) -> f64 {
    if x < 0.0 {
        -x
    } else {
        x
    }
}

fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Floor for finite values of moderate size (`|x| < 2^62`), without `std`.
fn floor(x: f64) -> f64 {
    let t = x as i64 as f64;
    if t > x {
        t - 1.0
    } else {
        t
    }
}

fn round_half_away(x: f64) -> f64 {
    if x >= 0.0 {
        floor(x + 0.5)
    } else {
        -floor(-x + 0.5)
    }
}

/// Cosine without `std` for `x` in `[0, 2π)` (any finite `x` works, less
/// precisely far from it): reduction to `[0, π/2]` and a Taylor polynomial to
/// x^14, error below 1e-9.
pub(crate) fn cos(x: f64) -> f64 {
    // Reduce to [-π, π].
    let mut y = x - TAU * floor(x / TAU);
    if y > PI {
        y -= TAU;
    }
    let y = abs(y);
    let (y, s) = if y > FRAC_PI_2 { (PI - y, -1.0) } else { (y, 1.0) };
    let y2 = y * y;
    // Horner form of 1 − y²/2! + y⁴/4! − … − y¹⁴/14!.
    let mut c = -1.0 / 87_178_291_200.0;
    c = c * y2 + 1.0 / 479_001_600.0;
    c = c * y2 - 1.0 / 3_628_800.0;
    c = c * y2 + 1.0 / 40_320.0;
    c = c * y2 - 1.0 / 720.0;
    c = c * y2 + 1.0 / 24.0;
    c = c * y2 - 0.5;
    c = c * y2 + 1.0;
    s * c
}
