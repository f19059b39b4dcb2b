//! B43 "test winding" (spec §14, E-140): the three phases' resistances
//! compared.
//!
//! Started in Ready to switch on, it runs at once (the manual's table asks
//! no enable for it): the drive switches the power stage on with the brake
//! applied and runs the R measurement of B42 ([`CurrentTuning`]) three times,
//! each in a frame fixed along one phase's axis (U at 0°, V at 120°, W at
//! 240° electrical). With the voltage along phase x the current leaves
//! through x and returns through the other two in parallel, so the
//! resistance seen is (R_x + R_y‖R_z)/1.5 — R for a balanced winding. The
//! test passes when the three agree within [`TOLERANCE`] of their mean
//! (one phase 10 % high shows as +6.5 % along it, −3.4 % along the others);
//! an open phase leaves a frame without current (result 2).

use super::{result, CurrentTuning, Outcome};
use crate::axis::AxisCommand;

/// Largest deviation of a phase's resistance from the three's mean.
pub const TOLERANCE: f32 = 0.03;

/// The frames along U, V, W (2^32 a turn).
const FRAMES: [u32; 3] = [0, 0x5555_5555, 0xAAAA_AAAB];

/// Where the test stands.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WindingOutcome {
    /// Running, progress in %.
    Running(u8),
    /// Finished (passed or unbalanced: [`WindingTest::passed`]): the
    /// resistances seen along U, V, W, Ω.
    Done([f32; 3]),
    /// Failed with its [`result`] code.
    Failed(u8),
}

/// The B43 test of one axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindingTest {
    rated_a: f32,
    r_prior: f32,
    phase: usize,
    run: CurrentTuning,
    seen: [f32; 3],
    outcome: WindingOutcome,
}

impl WindingTest {
    /// A test at the rated current `rated_a` of a winding whose dictionary R
    /// is `r_prior_ohm`.
    pub fn new(rated_a: f32, r_prior_ohm: f32) -> Self {
        Self {
            rated_a,
            r_prior: r_prior_ohm,
            phase: 0,
            run: CurrentTuning::in_frame(rated_a, r_prior_ohm, 0),
            seen: [0.0; 3],
            outcome: WindingOutcome::Running(0),
        }
    }

    /// Where it stands.
    pub fn outcome(&self) -> WindingOutcome {
        self.outcome
    }

    /// Whether the three resistances agree within [`TOLERANCE`].
    pub fn passed(r: &[f32; 3]) -> bool {
        let mean = (r[0] + r[1] + r[2]) / 3.0;
        mean > 0.0 && r.iter().all(|&x| ((x - mean) / mean).abs() <= TOLERANCE)
    }

    /// One control cycle (see [`CurrentTuning::cycle`]).
    pub fn cycle(&mut self, e48: u8, actual: Option<&crate::axis::CurrentActual>) -> Option<AxisCommand> {
        if !matches!(self.outcome, WindingOutcome::Running(_)) {
            return None;
        }
        let cmd = self.run.cycle(e48, actual);
        match self.run.outcome() {
            Outcome::Running(p) => {
                self.outcome = WindingOutcome::Running(((self.phase as u32 * 100 + u32::from(p)) / 3) as u8);
                cmd
            }
            Outcome::Failed(code) => {
                self.outcome = WindingOutcome::Failed(code);
                None
            }
            Outcome::Done(id) => {
                if let Some(r) = self.seen.get_mut(self.phase) {
                    *r = id.r_ohm;
                }
                self.phase += 1;
                match FRAMES.get(self.phase) {
                    Some(&frame) => {
                        self.run = CurrentTuning::in_frame(self.rated_a, self.r_prior, frame);
                        // its first cycle: the power stage stays on
                        self.run.cycle(e48, None)
                    }
                    None => {
                        self.outcome = WindingOutcome::Done(self.seen);
                        None
                    }
                }
            }
        }
    }

    /// The result code of a finished test: 0 passed, 6 unbalanced.
    pub fn code(r: &[f32; 3]) -> u8 {
        if Self::passed(r) {
            result::OK
        } else {
            result::UNBALANCED
        }
    }
}
