//! B42/B49 "optimise current controller" (spec §14, E-140): the winding's
//! resistance R and d-axis inductance L measured at standstill through the
//! current seam, and from them the current controllers' gains.
//!
//! The action runs per control cycle once the master enabled the axis after
//! starting it (E48 = 4, E-141's "next step"): instead of the cascade's torque
//! the axis commands a d-axis voltage open loop ([`Injection`]); a d current
//! makes no torque, the rotor stays where it is. The loop reports per cycle
//! the mean d voltage it applied and the mean d current it measured over the
//! same interval ([`DAxisMeans`](crate::axis::DAxisMeans)). The steps:
//!
//! 1. **probe**: a small voltage (a tenth of the rated current through the
//!    dictionary's R), four times larger each time until the current reaches
//!    5 % of the test current (else: no current, an open winding); its
//!    steady current gives a first R;
//! 2. **levels**: five stages at half and full test current (the rated
//!    current 6075h), U = R·I from the probe: ½, 1, ½, 1, ½. Each stage lasts
//!    until its current settles (blocks of [`BLOCK`] cycles whose means
//!    differ by less than 0.1 % of the test current);
//! 3. **R** is the slope between the levels' steady means,
//!    R = (Ū₁ − Ū½)/(Ī₁ − Ī½): a constant voltage error (the inverter's dead
//!    time left over after its compensation) drops out;
//! 4. **L** from each of the four steps: the winding equation
//!    u = R·i + L·di/dt integrated over the stage, relative to the stage's
//!    own steady state (U, I), gives
//!    L = (∫(u − U)dt − R·∫(i − I)dt) / (I − I_before): exact for any step
//!    shape, insensitive to where in a cycle the step falls (the loop's
//!    reported voltage carries it) and to a constant voltage error.
//!    L is the mean of the four.
//!
//! The caller writes R to B53 and L to B52 and B62 (Lq = Ld: measured at
//! standstill in the d axis only, a surface-magnet motor's assumption); the
//! current loop takes its gains from them by pole-zero cancellation,
//! Kp = ω_c·L, Ki = ω_c·R (ω_c = 2π·B64).

use crate::axis::{AxisCommand, CurrentActual, Injection};

/// Result codes of the action (B42\[0\], B49 likewise; 0 = identified).
pub mod result {
    /// R and L identified and written.
    pub const OK: u8 = 0;
    /// The enable went away (disable, quick stop, fault) before the end.
    pub const ABORTED: u8 = 1;
    /// No current at the highest probe voltage: an open winding or phase.
    pub const NO_CURRENT: u8 = 2;
    /// A stage's current did not settle in [`super::MAX_STAGE_CYCLES`].
    pub const NOT_SETTLED: u8 = 3;
    /// R or L came out non-positive or beyond the objects' ranges.
    pub const IMPLAUSIBLE: u8 = 4;
    /// The current loop reports no d-axis measurement.
    pub const NO_MEASUREMENT: u8 = 5;
    /// B43: the three phases' resistances differ by more than the
    /// tolerance ([`super::winding::TOLERANCE`]).
    pub const UNBALANCED: u8 = 6;
    /// B41: the rotor did not come to rest (the same code as
    /// [`NOT_SETTLED`]: the measurement did not settle).
    pub const NOT_AT_REST: u8 = NOT_SETTLED;
    /// B300: the shaft turned against the applied brake (beyond
    /// [`super::brake::TOLERANCE_INC`]); 7 and 8 are B40's.
    pub const SLIPPED: u8 = 9;
    /// B301: a grind phase did not turn the shaft (the peak torque cannot
    /// move it against the applied brake, [`super::grind::MIN_SHARE`]).
    pub const STALLED: u8 = 10;
    /// B301: a released phase did not turn the shaft with a quarter of the
    /// rated torque: the brake stays closed when commanded open.
    pub const NOT_RELEASED: u8 = 11;
    /// B44: the test move would pass a software limit (607Dh), or a limit
    /// switch is active: refused before it moves.
    pub const LIMIT: u8 = 12;
    /// B44: the axis left the stated travel of the test move.
    pub const OUT_OF_TRAVEL: u8 = 13;
}

/// Cycles per settle block.
pub const BLOCK: u16 = 8;
/// Longest stage, control cycles (4 s at 1 ms).
pub const MAX_STAGE_CYCLES: u16 = 4000;
/// Highest probe voltage, V.
const PROBE_MAX_V: f32 = 60.0;
/// The level stages: multiples of the test current.
const LEVELS: [f32; 5] = [0.5, 1.0, 0.5, 1.0, 0.5];
/// Settled: successive block means closer than this share of the test current.
const SETTLE_SHARE: f32 = 1.0e-3;

/// What was identified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Identified {
    /// Phase resistance (star equivalent), Ω.
    pub r_ohm: f32,
    /// d-axis inductance, H.
    pub l_h: f32,
}

/// Where the action stands.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Outcome {
    /// Running, progress in %.
    Running(u8),
    /// Finished: the figures.
    Done(Identified),
    /// Failed with its [`result`] code.
    Failed(u8),
}

/// One stage's sums and steady means.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Stage {
    /// ∫u·dt, ∫i·dt, ∫dt over the stage's reports.
    su: f32,
    si: f32,
    t: f32,
    /// The running block's sums of u and i and its cycles.
    bu: f32,
    bi: f32,
    bn: u16,
    /// The last complete block's means.
    last: Option<(f32, f32)>,
    /// Cycles in the stage.
    cycles: u16,
}

impl Stage {
    /// Adds a report; returns the steady (u, i) once two blocks agree.
    fn add(&mut self, u: f32, i: f32, dt: f32, tolerance_a: f32) -> Option<(f32, f32)> {
        self.su += u * dt;
        self.si += i * dt;
        self.t += dt;
        self.cycles = self.cycles.saturating_add(1);
        self.bu += u;
        self.bi += i;
        self.bn += 1;
        if self.bn < BLOCK {
            return None;
        }
        let n = f32::from(self.bn);
        let now = (self.bu / n, self.bi / n);
        (self.bu, self.bi, self.bn) = (0.0, 0.0, 0);
        let before = self.last.replace(now);
        // at least two blocks after the first (the step's own transient)
        match before {
            Some((_, i0)) if self.cycles >= 3 * BLOCK && abs(now.1 - i0) < tolerance_a => Some(now),
            _ => None,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Started; waiting for the master's enable.
    WaitEnable,
    /// The probe at this voltage.
    Probe(f32),
    /// Level stage k (index into [`LEVELS`]).
    Level(usize),
    /// Ended.
    End,
}

/// The B42/B49 measurement of one axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurrentTuning {
    phase: Phase,
    /// B49: the brake stays applied.
    standstill: bool,
    /// The test current, A.
    test_a: f32,
    /// The dictionary's R before the run (the probe's scale), Ω.
    r_prior: f32,
    /// R from the probe, Ω.
    r_probe: f32,
    /// The voltage commanded last, V (the next report belongs to it).
    ud: f32,
    stage: Stage,
    /// Steady (u, i) of each level stage.
    steady: [(f32, f32); LEVELS.len()],
    /// Per level stage: ∫(u − U)dt and ∫(i − I)dt, and the steady current before it.
    steps: [(f32, f32, f32); LEVELS.len()],
    /// The steady current of the stage before (probe or level).
    before_a: f32,
    /// Enabled cycles without a d-axis report.
    unmeasured: u8,
    /// The frame's fixed electrical angle (B43: along one phase), or the
    /// rotor's (`None`).
    frame: Option<u32>,
    /// Waits for the master's enable (B42/B49); else runs in Ready to switch
    /// on (B43: the drive switches the power stage on itself).
    needs_enable: bool,
    outcome: Outcome,
}

impl CurrentTuning {
    /// A run for a motor of rated current `rated_a` whose dictionary R is
    /// `r_prior_ohm`; `standstill` (B49) keeps the brake applied.
    pub fn new(rated_a: f32, r_prior_ohm: f32, standstill: bool) -> Self {
        let pos = |x: f32, fallback: f32| if x > 0.0 && x.is_finite() { x } else { fallback };
        Self {
            phase: Phase::WaitEnable,
            standstill,
            test_a: pos(rated_a, 1.0),
            r_prior: pos(r_prior_ohm, 1.0),
            r_probe: 0.0,
            ud: 0.0,
            stage: Stage::default(),
            steady: [(0.0, 0.0); LEVELS.len()],
            steps: [(0.0, 0.0, 0.0); LEVELS.len()],
            before_a: 0.0,
            unmeasured: 0,
            frame: None,
            needs_enable: true,
            outcome: Outcome::Running(0),
        }
    }

    /// The measurement in a frame at the fixed electrical angle `frame`
    /// (2^32 a turn), brake applied, run in Ready to switch on without an
    /// enable (B43, [`winding`]): its R is the resistance seen along that
    /// frame.
    pub fn in_frame(rated_a: f32, r_prior_ohm: f32, frame: u32) -> Self {
        Self {
            frame: Some(frame),
            needs_enable: false,
            ..Self::new(rated_a, r_prior_ohm, true)
        }
    }

    /// Where it stands.
    pub fn outcome(&self) -> Outcome {
        self.outcome
    }

    /// One control cycle: the axis' device state `e48` after its cycle and
    /// the loop's report of the last cycle; returns the command that replaces
    /// the axis' (`None`: the axis' own, while waiting for the enable and
    /// after the end).
    pub fn cycle(&mut self, e48: u8, actual: Option<&CurrentActual>) -> Option<AxisCommand> {
        if self.phase == Phase::End {
            return None;
        }
        let run_state = if self.needs_enable { 4 } else { 2 };
        if e48 != run_state {
            if self.phase != Phase::WaitEnable || !self.needs_enable {
                return self.fail(result::ABORTED);
            }
            // still waiting; a disable or a fault before the enable ends it too
            if e48 != 2 && e48 != 3 {
                return self.fail(result::ABORTED);
            }
            return None;
        }
        if self.phase == Phase::WaitEnable {
            self.phase = Phase::Probe(0.1 * self.test_a * self.r_prior);
            return Some(self.command_for());
        }
        // the report of the cycle the last command ran in
        let Some(d) = actual.and_then(|a| a.d_axis) else {
            self.unmeasured = self.unmeasured.saturating_add(1);
            if self.unmeasured > 3 {
                return self.fail(result::NO_MEASUREMENT);
            }
            return Some(self.command_for());
        };
        let tolerance = SETTLE_SHARE * self.test_a;
        if let Some(steady) = self.stage.add(d.voltage_v, d.current_a, d.interval_s, tolerance) {
            if let Some(code) = self.next(steady) {
                return self.fail(code);
            }
        } else if self.stage.cycles >= MAX_STAGE_CYCLES {
            return self.fail(result::NOT_SETTLED);
        }
        if self.phase == Phase::End {
            return None;
        }
        self.outcome = Outcome::Running(self.progress());
        Some(self.command_for())
    }

    /// The stage settled at `(u, i)`: the next stage, or the end; a failure's code.
    fn next(&mut self, (u, i): (f32, f32)) -> Option<u8> {
        let s = self.stage;
        self.stage = Stage::default();
        match self.phase {
            Phase::Probe(v) => {
                if abs(i) < 0.05 * self.test_a {
                    if v * 4.0 > PROBE_MAX_V {
                        return Some(result::NO_CURRENT);
                    }
                    self.phase = Phase::Probe(v * 4.0);
                    return None;
                }
                self.r_probe = u / i;
                if !self.r_probe.is_finite() || self.r_probe <= 0.0 {
                    return Some(result::IMPLAUSIBLE);
                }
                self.before_a = i;
                self.phase = Phase::Level(0);
            }
            Phase::Level(k) => {
                if let (Some(st), Some(sp)) = (self.steady.get_mut(k), self.steps.get_mut(k)) {
                    *st = (u, i);
                    *sp = (s.su - u * s.t, s.si - i * s.t, self.before_a);
                }
                self.before_a = i;
                if k + 1 < LEVELS.len() {
                    self.phase = Phase::Level(k + 1);
                } else {
                    self.phase = Phase::End;
                    return match self.identify() {
                        Some(id) => {
                            self.outcome = Outcome::Done(id);
                            None
                        }
                        None => Some(result::IMPLAUSIBLE),
                    };
                }
            }
            Phase::WaitEnable | Phase::End => {}
        }
        None
    }

    /// R from the levels' slope, L from the four steps.
    fn identify(&self) -> Option<Identified> {
        let (mut u_hi, mut i_hi, mut u_lo, mut i_lo, mut n_hi, mut n_lo) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for (&(u, i), &level) in self.steady.iter().zip(LEVELS.iter()) {
            if level > 0.75 {
                (u_hi, i_hi, n_hi) = (u_hi + u, i_hi + i, n_hi + 1.0);
            } else {
                (u_lo, i_lo, n_lo) = (u_lo + u, i_lo + i, n_lo + 1.0);
            }
        }
        let di = i_hi / n_hi - i_lo / n_lo;
        let r = (u_hi / n_hi - u_lo / n_lo) / di;
        let mut l_sum = 0.0;
        let mut count = 0.0;
        // the steps: every level stage after the first
        for (&(su, si, before), &(_, i)) in self.steps.iter().zip(self.steady.iter()).skip(1) {
            let step = i - before;
            if abs(step) > 0.1 * self.test_a {
                l_sum += (su - r * si) / step;
                count += 1.0;
            }
        }
        let l = l_sum / count;
        let ok = |x: f32| x.is_finite() && x > 0.0;
        (ok(r) && ok(l)).then_some(Identified { r_ohm: r, l_h: l })
    }

    fn progress(&self) -> u8 {
        match self.phase {
            Phase::WaitEnable => 0,
            Phase::Probe(_) => 5,
            Phase::Level(k) => 20 + 16 * k as u8,
            Phase::End => 100,
        }
    }

    fn command_for(&mut self) -> AxisCommand {
        self.ud = match self.phase {
            Phase::Probe(v) => v,
            Phase::Level(k) => LEVELS.get(k).copied().unwrap_or(0.0) * self.test_a * self.r_probe,
            Phase::WaitEnable | Phase::End => 0.0,
        };
        AxisCommand {
            torque_nm: 0.0,
            power_stage: true,
            brake_release: !self.standstill,
            injection: Some(Injection {
                ud_v: self.ud,
                angle: self.frame,
            }),
        }
    }

    fn fail(&mut self, code: u8) -> Option<AxisCommand> {
        self.phase = Phase::End;
        self.outcome = Outcome::Failed(code);
        None
    }
}

fn abs(x: f32) -> f32 {
    if x < 0.0 {
        -x
    } else {
        x
    }
}

pub mod align;
pub mod brake;
pub mod grind;
pub mod mechanics;
pub mod phase;
pub mod winding;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_mechanics;
