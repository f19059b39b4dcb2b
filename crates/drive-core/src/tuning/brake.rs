//! B300 "test brake" (spec §14, E-140): the holding brake against a test
//! torque.
//!
//! Started in Ready to switch on, it runs once the master enabled the axis
//! (E48 = 4, E-141). The brake stays applied while the drive commands the
//! test torque, the rated torque 6076h (the brake must hold the motor's
//! rated torque; the manual's own test-torque parameters are not in the
//! seeds), first forward for [`HOLD_CYCLES`] control cycles, then backward
//! as long, each after a ramp of [`RAMP_CYCLES`]. The encoder watches the
//! shaft: a brake that holds lets it move by the play of the brake alone; one
//! whose holding torque is below the test torque lets the shaft turn, and
//! the test fails with [`result::SLIPPED`] once the shaft moved more than
//! [`TOLERANCE_INC`] (1/360 rev) from where it stood (the power stage then
//! drops the torque at once). The result and the largest movement seen land
//! in B300.

use super::result;
use crate::axis::AxisCommand;

/// Cycles of the torque's ramp to the test torque (each direction).
pub const RAMP_CYCLES: u32 = 100;
/// Cycles the test torque is held (each direction).
pub const HOLD_CYCLES: u32 = 500;
/// Largest movement of a holding brake's shaft, increments (1/360 rev).
pub const TOLERANCE_INC: u32 = (1 << 20) / 360;

/// Where the test stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BrakeOutcome {
    /// Running, progress in %.
    Running(u8),
    /// Finished: the brake held; the largest movement seen, increments.
    Held(u32),
    /// Failed with its [`result`] code and the largest movement seen.
    Failed(u8, u32),
}

/// The B300 test of one axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BrakeTest {
    /// The test torque, N·m.
    torque_nm: f32,
    /// The position at the enable, increments.
    start_inc: Option<i32>,
    /// Cycles since the enable.
    cycles: u32,
    /// The largest |position − start| seen, increments.
    moved_inc: u32,
    outcome: BrakeOutcome,
}

/// Cycles of the whole test (both directions).
const TOTAL_CYCLES: u32 = 2 * (RAMP_CYCLES + HOLD_CYCLES);

impl BrakeTest {
    /// A test with `torque_nm` (the rated torque 6076h).
    pub fn new(torque_nm: f32) -> Self {
        let torque_nm = if torque_nm.is_finite() && torque_nm > 0.0 {
            torque_nm
        } else {
            0.0
        };
        Self {
            torque_nm,
            start_inc: None,
            cycles: 0,
            moved_inc: 0,
            outcome: BrakeOutcome::Running(0),
        }
    }

    /// Where it stands.
    pub fn outcome(&self) -> BrakeOutcome {
        self.outcome
    }

    /// The torque of cycle `k` since the enable: a ramp up, the hold, the
    /// same backwards.
    fn torque_at(&self, k: u32) -> f32 {
        let half = RAMP_CYCLES + HOLD_CYCLES;
        let (sign, k) = if k < half { (1.0, k) } else { (-1.0, k - half) };
        let share = if k < RAMP_CYCLES {
            k as f32 / RAMP_CYCLES as f32
        } else {
            1.0
        };
        sign * share * self.torque_nm
    }

    /// One control cycle: the axis' state `e48` after its cycle and the
    /// encoder position (increments); the command that replaces the axis'
    /// (`None`: its own): the power stage on, the brake applied, the test
    /// torque.
    pub fn cycle(&mut self, e48: u8, position_inc: i32) -> Option<AxisCommand> {
        if !matches!(self.outcome, BrakeOutcome::Running(_)) {
            return None;
        }
        if e48 != 4 {
            if self.start_inc.is_some() || !(e48 == 2 || e48 == 3) {
                self.outcome = BrakeOutcome::Failed(result::ABORTED, self.moved_inc);
            }
            return None;
        }
        let start = *self.start_inc.get_or_insert(position_inc);
        let moved = position_inc.wrapping_sub(start).unsigned_abs();
        self.moved_inc = self.moved_inc.max(moved);
        if moved > TOLERANCE_INC {
            self.outcome = BrakeOutcome::Failed(result::SLIPPED, self.moved_inc);
            return None;
        }
        if self.cycles >= TOTAL_CYCLES {
            self.outcome = BrakeOutcome::Held(self.moved_inc);
            return None;
        }
        let torque_nm = self.torque_at(self.cycles);
        self.cycles += 1;
        self.outcome = BrakeOutcome::Running((self.cycles * 100 / (TOTAL_CYCLES + 1)) as u8);
        Some(AxisCommand {
            torque_nm,
            power_stage: true,
            brake_release: false,
            injection: None,
        })
    }
}
