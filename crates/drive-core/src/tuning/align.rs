//! B41 "calibrate motor" (spec §14, E-140): the commutation offset B05 by
//! alignment.
//!
//! Once the master enabled the axis (E48 = 4), the drive releases the brake
//! and drives the rated current (6075h, as the voltage R·I with B53) into the
//! winding as a d current in a frame at a fixed electrical angle
//! ([`Injection::angle`]): the free rotor turns until its d axis points along
//! that current vector (the torque 1.5·p·ψ·I·sin(error) pulls it there). The
//! frame is turned slowly (a ramp of [`RAMP_CYCLES`]) so the rotor follows
//! without swinging (at the first stop the current ramps up instead): 0,
//! +90°, 0 → the position A at rest;
//! −90°, 0 → position B. Friction stops the rotor short of alignment by
//! Tc/(kt·I) on the side it came from, so A and B lie on both sides of the
//! true offset: their mean is the offset (the position at which the d axis
//! points along phase a), |A − B| the friction's share (B41\[1\]).

use super::result;
use crate::axis::{AxisCommand, Injection};

/// Cycles of a quarter-turn ramp of the frame.
pub const RAMP_CYCLES: u32 = 250;
/// Cycles at rest: the position moved less than [`REST_INC`] over this many.
const REST_CYCLES: u32 = 50;
/// Rest: the position's span over [`REST_CYCLES`], increments.
const REST_INC: i32 = 16;
/// Longest wait for rest after a ramp, cycles.
const MAX_SETTLE_CYCLES: u32 = 5000;
/// The frame's lag behind the rotor's motion, in cycles of that motion.
const DAMPING: u32 = 2;
/// The frames' stops, electrical angle (2^32 a turn): 0, +90°, 0, −90°, 0.
const STOPS: [u32; 5] = [0, 1 << 30, 0, 3 << 30, 0];

/// Where the calibration stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AlignOutcome {
    /// Running, progress in %.
    Running(u8),
    /// Finished: the offset (increments, 0..2^20) and the spread |A − B|.
    Done {
        /// The commutation offset, increments.
        offset_inc: u32,
        /// The two alignments' difference, increments.
        spread_inc: u32,
    },
    /// Failed with its [`result`] code.
    Failed(u8),
}

/// The B41 calibration of one axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Alignment {
    /// Started (enabled once).
    enabled: bool,
    /// The stop ramped to or held (index into [`STOPS`]).
    stop: usize,
    /// Cycles since the stop's ramp began.
    cycles: u32,
    /// The rest window: its start position, lowest and highest, cycles in it.
    window: (i32, i32, i32, u32),
    /// Position A (after stop 2).
    a: Option<i32>,
    /// The voltage, mV.
    ud_v: i32,
    /// Pole pairs (B10).
    pole_pairs: u32,
    /// The position of the last cycle, increments.
    last_inc: i32,
    /// The frame's damping shift of this cycle (electrical, 2^32 a turn).
    damping: u32,
    outcome: AlignOutcome,
}

impl Alignment {
    /// A calibration with the voltage `ud_v` (R·I of the motor data) for a
    /// motor of `pole_pairs` (B10).
    pub fn new(ud_v: f32, pole_pairs: u8) -> Self {
        let mv = if ud_v.is_finite() && ud_v > 0.0 {
            (ud_v * 1e3) as i32
        } else {
            1000
        };
        Self {
            enabled: false,
            stop: 0,
            cycles: 0,
            window: (0, 0, 0, 0),
            a: None,
            ud_v: mv,
            pole_pairs: u32::from(pole_pairs.max(1)),
            last_inc: 0,
            damping: 0,
            outcome: AlignOutcome::Running(0),
        }
    }

    /// Where it stands.
    pub fn outcome(&self) -> AlignOutcome {
        self.outcome
    }

    /// One control cycle: the axis' state `e48` after its cycle, the encoder
    /// position (increments, 2^20 a revolution); the command that replaces
    /// the axis' (`None`: its own).
    pub fn cycle(&mut self, e48: u8, position_inc: i32) -> Option<AxisCommand> {
        if !matches!(self.outcome, AlignOutcome::Running(_)) {
            return None;
        }
        if e48 != 4 {
            if self.enabled || !(e48 == 2 || e48 == 3) {
                self.outcome = AlignOutcome::Failed(result::ABORTED);
            }
            return None;
        }
        if !self.enabled {
            self.enabled = true;
            self.window = (position_inc, 0, 0, 0);
            self.last_inc = position_inc;
            return Some(self.command());
        }
        self.cycles += 1;
        // damping: the frame lags the rotor's motion by DAMPING cycles of it
        // (the torque K·sin(frame − θ) then brakes the swing: ζ ≈
        // DAMPING·T·ω_n/2, 0.46 for the simulated servo at 1 ms)
        let moved = position_inc.wrapping_sub(self.last_inc) as u32;
        self.last_inc = position_inc;
        self.damping = moved
            .wrapping_mul(self.pole_pairs << 12)
            .wrapping_mul(DAMPING)
            .wrapping_neg();
        if self.cycles > RAMP_CYCLES {
            let (start, lo, hi, n) = self.window;
            let d = position_inc.wrapping_sub(start);
            let (lo, hi) = (lo.min(d), hi.max(d));
            if hi - lo > REST_INC {
                self.window = (position_inc, 0, 0, 0);
            } else if n + 1 >= REST_CYCLES {
                self.at_rest(position_inc);
                if !matches!(self.outcome, AlignOutcome::Running(_)) {
                    return None;
                }
            } else {
                self.window = (start, lo, hi, n + 1);
            }
            if self.cycles > RAMP_CYCLES + MAX_SETTLE_CYCLES {
                self.outcome = AlignOutcome::Failed(result::NOT_SETTLED);
                return None;
            }
        }
        self.outcome = AlignOutcome::Running((20 * self.stop) as u8);
        Some(self.command())
    }

    /// At rest at the stop held: the next stop, or the end.
    fn at_rest(&mut self, position_inc: i32) {
        match self.stop {
            2 => self.a = Some(position_inc),
            4 => {
                let a = self.a.unwrap_or(position_inc);
                let diff = position_inc.wrapping_sub(a);
                let mean = a.wrapping_add(diff / 2);
                self.outcome = AlignOutcome::Done {
                    offset_inc: (mean as u32) & ((1 << 20) - 1),
                    spread_inc: diff.unsigned_abs(),
                };
                return;
            }
            _ => {}
        }
        self.stop += 1;
        self.cycles = 0;
        self.window = (position_inc, 0, 0, 0);
    }

    /// The frame's angle now: ramped from the last stop to this one.
    fn angle(&self) -> u32 {
        let to = STOPS.get(self.stop).copied().unwrap_or(0);
        let from = match self.stop {
            0 => to,
            k => STOPS.get(k - 1).copied().unwrap_or(0),
        };
        let step = to.wrapping_sub(from) as i32;
        let share = self.cycles.min(RAMP_CYCLES) as i64;
        let delta = (i64::from(step) * share / i64::from(RAMP_CYCLES)) as i32;
        from.wrapping_add(delta as u32)
    }

    fn command(&self) -> AxisCommand {
        // the first stop's current rises over a ramp: the rotor, wherever it
        // starts, breaks away at a small current and follows without a swing
        let share = if self.stop == 0 {
            self.cycles.min(RAMP_CYCLES) as f32 / RAMP_CYCLES as f32
        } else {
            1.0
        };
        AxisCommand {
            torque_nm: 0.0,
            power_stage: true,
            brake_release: true,
            injection: Some(Injection {
                ud_v: self.ud_v as f32 * 1e-3 * share,
                angle: Some(self.angle().wrapping_add(self.damping)),
            }),
        }
    }
}
