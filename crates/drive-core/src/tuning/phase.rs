//! B40 "test phase" (spec §14, E-140): the motor's wiring against its
//! encoder.
//!
//! After the master's enable (E48 = 4), in frames at fixed electrical angles
//! (the commutation offset plays no part):
//!
//! 1. **each phase carries current** (the brake applied): half the rated
//!    current's voltage
//!    (B53·6075h/2) along U, V and W in turn; the current along each must
//!    reach a quarter of what the voltage should drive (an open phase leaves
//!    the frame along it without current: result 2);
//! 2. **alignment** (the brake released from here on): the rated current's
//!    voltage at 0°, ramped up, the rotor
//!    comes to rest (position P0);
//! 3. **one electrical turn forward**: the frame turned through 360° in
//!    [`TURN_CYCLES`], then held until the rotor rests (P1). The encoder must
//!    have counted up (else result 7: phase order and encoder direction do
//!    not match — phases V and W swapped, or the encoder counting the other
//!    way), and by 2^20/p increments for the pole pairs B10 (else result 8;
//!    the pole pairs seen are 2^20/(P1 − P0), rounded).
//!
//! The frame lags the rotor's motion a little (as in [`super::align`]),
//! which damps its swing.

use super::result;
use crate::axis::{AxisCommand, CurrentActual, Injection};

/// Cycles per phase in step 1.
const PHASE_CYCLES: u32 = 60;
/// The last cycles of a phase's step averaged.
const PHASE_MEAN: u32 = 20;
/// Cycles of the alignment's current ramp and of the rest after it.
const ALIGN_CYCLES: u32 = 500;
/// Cycles of the electrical turn.
pub const TURN_CYCLES: u32 = 1000;
/// Cycles of rest after the turn.
const REST_CYCLES: u32 = 400;
/// The frame's lag behind the rotor's motion, in cycles of that motion.
const DAMPING: u32 = 2;
/// The frames along U, V, W (2^32 a turn).
const FRAMES: [u32; 3] = [0, 0x5555_5555, 0xAAAA_AAAB];

/// Result codes of B40 beyond [`result`]'s.
pub mod code {
    /// The encoder counted down for a forward field: phase order and encoder
    /// direction do not match.
    pub const DIRECTION: u8 = 7;
    /// The encoder's increments per electrical turn do not match B10.
    pub const POLE_PAIRS: u8 = 8;
}

/// Where the test stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PhaseOutcome {
    /// Running, progress in %.
    Running(u8),
    /// Passed: the increments per electrical turn and the pole pairs seen.
    Done {
        /// Encoder increments over one electrical turn of the field.
        per_turn_inc: i32,
        /// 2^20 / that, rounded.
        pole_pairs: u8,
    },
    /// Failed with its code ([`result`], [`code`]); for 7 and 8 the
    /// increments seen over the turn.
    Failed(u8, i32),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Step {
    WaitEnable,
    Phase(usize),
    Align,
    Turn,
    Rest,
}

/// The B40 test of one axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseTest {
    step: Step,
    cycles: u32,
    /// The voltage of the rated current, V.
    ud_v: f32,
    /// The rated current, A.
    rated_a: f32,
    pole_pairs: u8,
    /// Sum of the d current over a phase step's last cycles.
    id_sum: f32,
    start_inc: i32,
    last_inc: i32,
    damping: u32,
    outcome: PhaseOutcome,
}

impl PhaseTest {
    /// A test at the rated current `rated_a` with the dictionary's R and pole
    /// pairs.
    pub fn new(rated_a: f32, r_ohm: f32, pole_pairs: u8) -> Self {
        let ok = |x: f32, d: f32| if x.is_finite() && x > 0.0 { x } else { d };
        let rated_a = ok(rated_a, 1.0);
        Self {
            step: Step::WaitEnable,
            cycles: 0,
            ud_v: rated_a * ok(r_ohm, 1.0),
            rated_a,
            pole_pairs: pole_pairs.max(1),
            id_sum: 0.0,
            start_inc: 0,
            last_inc: 0,
            damping: 0,
            outcome: PhaseOutcome::Running(0),
        }
    }

    /// Where it stands.
    pub fn outcome(&self) -> PhaseOutcome {
        self.outcome
    }

    /// One control cycle: the axis' state, the encoder and the loop's last
    /// report; the command that replaces the axis' (`None`: its own).
    pub fn cycle(
        &mut self,
        e48: u8,
        position_inc: i32,
        actual: Option<&CurrentActual>,
    ) -> Option<AxisCommand> {
        if !matches!(self.outcome, PhaseOutcome::Running(_)) {
            return None;
        }
        if e48 != 4 {
            if self.step != Step::WaitEnable || !(e48 == 2 || e48 == 3) {
                self.outcome = PhaseOutcome::Failed(result::ABORTED, 0);
            }
            return None;
        }
        let moved = position_inc.wrapping_sub(self.last_inc) as u32;
        self.last_inc = position_inc;
        self.damping = moved
            .wrapping_mul(u32::from(self.pole_pairs) << 12)
            .wrapping_mul(DAMPING)
            .wrapping_neg();
        self.cycles += 1;
        match self.step {
            Step::WaitEnable => {
                self.step = Step::Phase(0);
                self.cycles = 0;
                self.damping = 0;
            }
            Step::Phase(k) => {
                if self.cycles > PHASE_CYCLES - PHASE_MEAN {
                    self.id_sum += actual.and_then(|a| a.d_axis).map_or(0.0, |d| d.current_a);
                }
                if self.cycles >= PHASE_CYCLES {
                    let mean = self.id_sum / PHASE_MEAN as f32;
                    if mean < 0.25 * 0.5 * self.rated_a {
                        self.outcome = PhaseOutcome::Failed(result::NO_CURRENT, 0);
                        return None;
                    }
                    self.id_sum = 0.0;
                    self.cycles = 0;
                    self.step = if k + 1 < FRAMES.len() {
                        Step::Phase(k + 1)
                    } else {
                        Step::Align
                    };
                }
            }
            Step::Align => {
                if self.cycles >= 2 * ALIGN_CYCLES {
                    self.start_inc = position_inc;
                    self.cycles = 0;
                    self.step = Step::Turn;
                }
            }
            Step::Turn => {
                if self.cycles >= TURN_CYCLES {
                    self.cycles = 0;
                    self.step = Step::Rest;
                }
            }
            Step::Rest => {
                if self.cycles >= REST_CYCLES {
                    self.outcome = self.verdict(position_inc.wrapping_sub(self.start_inc));
                    return None;
                }
            }
        }
        self.outcome = PhaseOutcome::Running(self.progress());
        Some(self.command())
    }

    fn verdict(&self, per_turn: i32) -> PhaseOutcome {
        if per_turn <= 0 {
            return PhaseOutcome::Failed(code::DIRECTION, per_turn);
        }
        let p = ((1i64 << 20) + i64::from(per_turn) / 2) / i64::from(per_turn);
        match u8::try_from(p) {
            Ok(p) if p == self.pole_pairs => PhaseOutcome::Done {
                per_turn_inc: per_turn,
                pole_pairs: p,
            },
            _ => PhaseOutcome::Failed(code::POLE_PAIRS, per_turn),
        }
    }

    fn progress(&self) -> u8 {
        match self.step {
            Step::WaitEnable => 0,
            Step::Phase(k) => 5 + 10 * k as u8,
            Step::Align => 35,
            Step::Turn => 50 + (40 * self.cycles / TURN_CYCLES) as u8,
            Step::Rest => 90,
        }
    }

    fn command(&self) -> AxisCommand {
        let (ud, angle) = match self.step {
            Step::Phase(k) => (0.5 * self.ud_v, FRAMES.get(k).copied().unwrap_or(0)),
            Step::Align => {
                let share = self.cycles.min(ALIGN_CYCLES) as f32 / ALIGN_CYCLES as f32;
                (self.ud_v * share, self.damping)
            }
            Step::Turn => {
                let turned = (u64::from(self.cycles) << 32) / u64::from(TURN_CYCLES);
                (self.ud_v, (turned as u32).wrapping_add(self.damping))
            }
            Step::Rest | Step::WaitEnable => (self.ud_v, self.damping),
        };
        AxisCommand {
            torque_nm: 0.0,
            power_stage: true,
            // the phases' currents with the brake applied: the rotor stays
            brake_release: !matches!(self.step, Step::Phase(_)),
            injection: Some(Injection {
                ud_v: ud,
                angle: Some(angle),
            }),
        }
    }
}
