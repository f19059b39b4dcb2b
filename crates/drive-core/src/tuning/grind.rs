//! B301 "grind brake" (spec §14, E-140): the holding brake's pads ground in
//! by the motor turning slowly against the closed brake, the brake released
//! and closed again under motion.
//!
//! Started in Ready to switch on, it runs once the master enabled the axis
//! (E48 = 4, E-141). The manual names the action but not its sequence (its
//! own grinding parameters are not in the seeds); ours, at the 1 ms control
//! cycle, about three revolutions at 60 rpm:
//!
//! [`ROUNDS`] rounds of
//! 1. **grind** for [`GRIND_CYCLES`] (0.5 s): the brake applied, the motor
//!    turns the shaft at [`SPEED_INC`] increments a cycle (60 rpm) against
//!    it with up to the peak torque (6076h × 6072h);
//! 2. **released** for [`RELEASE_CYCLES`] (0.25 s): the brake released,
//!    the same speed with at most a quarter of the rated torque
//!    ([`FREE_SHARE`]: a free shaft needs its friction only; a brake that
//!    holds the rated torque stops it),
//!
//! then [`STOP_CYCLES`] (0.1 s) with the brake applied and no torque: the
//! shaft stops on the brake, and the axis' own control takes over.
//!
//! The speed is held by a PI rule on the speed error e (a share of the
//! grinding speed, from the encoder's count per cycle), in N·m:
//! τ = τ_i + P·e, τ_i += I·e each cycle, both within 0 … the phase's limit
//! (the shaft only turns forward), τ_i from 0 at each phase's start;
//! P = half the released limit, I = a hundredth of the peak torque: for the
//! default servo (1e-4 kg·m²) a loop of some 250 rad/s, damping 0.5; the
//! torque reaches a 2 N·m brake's breakaway some 50 ms into a grind phase.
//! The mean torque over each grind phase's second half (the shaft sliding
//! at the grinding speed: the brake's sliding torque plus friction), the
//! largest of them, is B301\[3\].
//!
//! A phase must turn the shaft by a quarter of what its speed gives
//! ([`MIN_SHARE`]), else the action fails at the phase's end:
//! - a grind phase short of it: [`result::STALLED`] (10): the peak torque
//!   cannot turn the shaft against the brake (a brake holding more than the
//!   drive's peak torque, a blocked shaft);
//! - a released phase short of it: [`result::NOT_RELEASED`] (11): the brake
//!   stays closed when commanded open (a stuck brake, no brake supply).
//!
//! The commanded torque changes by at most a twentieth of the peak torque
//! a cycle; the brake opens for a released phase only once the torque is
//! within its limit (the shaft stands on the brake meanwhile), and after a
//! failed phase the torque winds down to 0 on the applied brake before the
//! failure shows and the axis' own control takes over.
//!
//! The enable going away before the end aborts it ([`result::ABORTED`]).
//! The result, the smallest travel of a grind and of a released phase and
//! the largest grinding torque land in B301.

use super::result;
use crate::axis::AxisCommand;

/// The grinding speed, increments per control cycle (60 rpm at 1 ms).
pub const SPEED_INC: i32 = (1 << 20) / 1000;
/// Rounds of grinding and release.
pub const ROUNDS: u32 = 4;
/// Cycles of a grind phase (brake applied).
pub const GRIND_CYCLES: u32 = 500;
/// Cycles of a released phase.
pub const RELEASE_CYCLES: u32 = 250;
/// Cycles at the end with the brake applied and no torque.
pub const STOP_CYCLES: u32 = 100;
/// A phase must turn the shaft by this share of its speed × its cycles.
pub const MIN_SHARE: f32 = 0.25;
/// The torque limit of a released phase as a share of the rated torque.
pub const FREE_SHARE: f32 = 0.25;
/// The speed rule's P, N·m at 100 % speed error, as a share of the
/// released phase's torque limit.
const P_SHARE: f32 = 0.5;
/// The speed rule's I, N·m per cycle at 100 % speed error, as a share of the
/// peak torque.
const I_SHARE: f32 = 0.01;
/// Cycles over which the commanded torque may change by the peak torque:
/// its changes are slewed (a step of several amperes to nothing would leave
/// a current-deviation window, `foc::CurrentDeviation`, with the step's
/// error and hardly any reference: event 69).
const SLEW_CYCLES: f32 = 20.0;
/// Cycles of one round.
const ROUND_CYCLES: u32 = GRIND_CYCLES + RELEASE_CYCLES;
/// Cycles of the whole action.
const TOTAL_CYCLES: u32 = ROUNDS * ROUND_CYCLES + STOP_CYCLES;

/// What B301 saw, for its object.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GrindFigures {
    /// The smallest travel of a finished grind phase, increments.
    pub grind_travel_inc: u32,
    /// The smallest travel of a finished released phase, increments.
    pub release_travel_inc: u32,
    /// The largest of the grind phases' mean torques over their second
    /// half, N·m.
    pub grind_torque_nm: f32,
}

/// Where the action stands.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GrindOutcome {
    /// Running, progress in %.
    Running(u8),
    /// Finished: the brake ground in.
    Done(GrindFigures),
    /// Failed with its [`result`] code.
    Failed(u8, GrindFigures),
}

/// The B301 action of one axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrindBrake {
    /// The peak torque (grinding limit), N·m.
    peak_nm: f32,
    /// The torque limit with the brake released, N·m.
    free_nm: f32,
    /// The position of the last cycle, increments.
    last_inc: Option<i32>,
    /// Cycles since the enable.
    cycles: u32,
    /// The speed rule's integral part, N·m.
    integral_nm: f32,
    /// The torque commanded last, N·m.
    torque_nm: f32,
    /// A phase failed with this code: the torque winds down, then the end.
    failing: Option<u8>,
    /// The sum of the torques over the grind phase's second half, N·m.
    sum_nm: f32,
    /// The running phase's travel, increments.
    travel_inc: i64,
    figures: GrindFigures,
    outcome: GrindOutcome,
}

/// What cycle `k` since the enable is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Part {
    Grind,
    Released,
    Stop,
}

fn part(k: u32) -> Part {
    if k >= ROUNDS * ROUND_CYCLES {
        Part::Stop
    } else if k % ROUND_CYCLES < GRIND_CYCLES {
        Part::Grind
    } else {
        Part::Released
    }
}

/// `x` if finite and positive, else 0.
fn positive(x: f32) -> f32 {
    if x.is_finite() && x > 0.0 {
        x
    } else {
        0.0
    }
}

impl GrindBrake {
    /// The action with the rated torque 6076h and the peak torque (6076h ×
    /// 6072h), N·m.
    pub fn new(rated_nm: f32, peak_nm: f32) -> Self {
        Self {
            peak_nm: positive(peak_nm),
            free_nm: positive(rated_nm) * FREE_SHARE,
            last_inc: None,
            cycles: 0,
            integral_nm: 0.0,
            torque_nm: 0.0,
            failing: None,
            sum_nm: 0.0,
            travel_inc: 0,
            figures: GrindFigures {
                grind_travel_inc: u32::MAX,
                release_travel_inc: u32::MAX,
                grind_torque_nm: 0.0,
            },
            outcome: GrindOutcome::Running(0),
        }
    }

    /// Where it stands.
    pub fn outcome(&self) -> GrindOutcome {
        self.outcome
    }

    /// The figures so far (travels not yet seen read 0).
    fn figures(&self) -> GrindFigures {
        let f = self.figures;
        let seen = |x: u32| if x == u32::MAX { 0 } else { x };
        GrindFigures {
            grind_travel_inc: seen(f.grind_travel_inc),
            release_travel_inc: seen(f.release_travel_inc),
            ..f
        }
    }

    /// Ends the phase before cycle `k`: its travel checked; `true` if the
    /// action failed.
    fn end_phase(&mut self, ended: Part, cycles: u32) -> bool {
        let travel = self.travel_inc.max(0).min(i64::from(u32::MAX)) as u32;
        self.travel_inc = 0;
        self.integral_nm = 0.0;
        if ended == Part::Grind {
            let mean = self.sum_nm / (GRIND_CYCLES - GRIND_CYCLES / 2) as f32;
            self.figures.grind_torque_nm = self.figures.grind_torque_nm.max(mean);
            self.sum_nm = 0.0;
        }
        let min = MIN_SHARE * SPEED_INC as f32 * cycles as f32;
        let (slot, code) = match ended {
            Part::Grind => (&mut self.figures.grind_travel_inc, result::STALLED),
            Part::Released => (&mut self.figures.release_travel_inc, result::NOT_RELEASED),
            Part::Stop => return false,
        };
        *slot = (*slot).min(travel);
        if (travel as f32) < min {
            self.failing = Some(code);
            return true;
        }
        false
    }

    /// One control cycle: the axis' state `e48` after its cycle and the
    /// encoder position (increments); the command that replaces the axis'
    /// (`None`: its own): the power stage on, the brake as the sequence
    /// says, the torque of the speed rule.
    pub fn cycle(&mut self, e48: u8, position_inc: i32) -> Option<AxisCommand> {
        if !matches!(self.outcome, GrindOutcome::Running(_)) {
            return None;
        }
        if e48 != 4 {
            if self.last_inc.is_some() || !(e48 == 2 || e48 == 3) {
                self.outcome = GrindOutcome::Failed(result::ABORTED, self.figures());
            }
            return None;
        }
        let delta = position_inc.wrapping_sub(self.last_inc.unwrap_or(position_inc));
        self.last_inc = Some(position_inc);
        self.travel_inc = self.travel_inc.saturating_add(i64::from(delta));
        let step = self.peak_nm / SLEW_CYCLES;
        if let Some(code) = self.failing {
            return self.wind_down(code, step);
        }
        let k = self.cycles;
        // the phase that ended with the last cycle
        if k > 0 && part(k) != part(k - 1) {
            let (ended, len) = match part(k - 1) {
                Part::Grind => (Part::Grind, GRIND_CYCLES),
                Part::Released => (Part::Released, RELEASE_CYCLES),
                Part::Stop => (Part::Stop, STOP_CYCLES),
            };
            if self.end_phase(ended, len) {
                return self.failing.and_then(|code| self.wind_down(code, step));
            }
        }
        if k >= TOTAL_CYCLES {
            self.outcome = GrindOutcome::Done(self.figures());
            return None;
        }
        let now = part(k);
        let (limit, release) = match now {
            Part::Grind => (self.peak_nm, false),
            Part::Released => (self.free_nm, true),
            Part::Stop => (0.0, false),
        };
        // the speed error as a share of the grinding speed
        let e = (SPEED_INC as f32 - delta as f32) / SPEED_INC as f32;
        let integral = self.integral_nm + self.peak_nm * I_SHARE * e;
        self.integral_nm = integral.max(0.0).min(limit);
        let target = (self.integral_nm + self.free_nm * P_SHARE * e)
            .max(0.0)
            .min(limit);
        let torque = target.max(self.torque_nm - step).min(self.torque_nm + step);
        self.torque_nm = torque;
        // the brake opens once the torque is within the released limit
        let release = release && torque <= self.free_nm;
        if now == Part::Grind && k % ROUND_CYCLES >= GRIND_CYCLES / 2 {
            self.sum_nm += torque;
        }
        self.cycles = k + 1;
        self.outcome = GrindOutcome::Running((self.cycles * 100 / (TOTAL_CYCLES + 1)) as u8);
        Some(AxisCommand {
            torque_nm: torque,
            power_stage: true,
            brake_release: release,
            injection: None,
        })
    }

    /// A cycle of the wind-down after a failed phase: the brake applied, the
    /// torque towards 0 by `step`; at 0 the failure (`code`) shows.
    fn wind_down(&mut self, code: u8, step: f32) -> Option<AxisCommand> {
        if self.torque_nm <= 0.0 {
            self.failing = None;
            self.outcome = GrindOutcome::Failed(code, self.figures());
            return None;
        }
        self.torque_nm = (self.torque_nm - step).max(0.0);
        Some(AxisCommand {
            torque_nm: self.torque_nm,
            power_stage: true,
            brake_release: false,
            injection: None,
        })
    }
}
