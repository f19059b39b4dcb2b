//! What the demo sequence ([`super::sequence`]) reports: its phases, the
//! samples for a plot, the observer that hears it go, and the outcome of
//! each phase ([`Report`]).

use super::pkw::Outcome;
use nanos::Nanos;

/// The phases, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Connect and enable.
    Enable,
    /// Homing.
    Home,
    /// The positioning chain and the relative move.
    Positioning,
    /// The speed-mode segment.
    Speed,
    /// Jog both ways.
    Jog,
    /// PKW accesses.
    Pkw,
    /// The provoked fault and its acknowledgement.
    Fault,
    /// B44 identify mechanics through PKW (only with
    /// [`super::sequence::Options::self_tune`]: between enable and home).
    SelfTune,
}

impl Phase {
    /// Every phase, in order.
    pub const ALL: [Phase; 7] = [
        Phase::Enable,
        Phase::Home,
        Phase::Positioning,
        Phase::Speed,
        Phase::Jog,
        Phase::Pkw,
        Phase::Fault,
    ];

    /// A short name ("enable", "home", …).
    pub fn name(self) -> &'static str {
        match self {
            Phase::Enable => "enable",
            Phase::Home => "home",
            Phase::Positioning => "positioning",
            Phase::Speed => "speed",
            Phase::Jog => "jog",
            Phase::Pkw => "PKW",
            Phase::Fault => "fault",
            Phase::SelfTune => "self-tune",
        }
    }

    /// The phases of a run, in order: [`Self::ALL`], with `self_tune` the
    /// self-tuning after the enable.
    pub fn of_run(self_tune: bool) -> Vec<Phase> {
        let mut v = Phase::ALL.to_vec();
        if self_tune {
            v.insert(1, Phase::SelfTune);
        }
        v
    }
}

/// One cycle's values for a plot (axis A; the drive's own objects).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Simulated time.
    pub t: Nanos,
    /// ZSW1 of the last response.
    pub zsw1: u16,
    /// The commanded target position, increments.
    pub set_inc: i32,
    /// 6064h, increments.
    pub pos_inc: i32,
    /// 606Ch, increments/s.
    pub vel_inc_s: i32,
    /// 6077h, ‰ of rated torque.
    pub torque_permille: i16,
    /// 60F4h, increments.
    pub ferr_inc: i32,
}

/// What the run tells as it goes.
pub trait Observer {
    /// A line (a state change, an FB output change, a step).
    fn line(&mut self, t: Nanos, text: &str);
    /// A phase starts.
    fn phase(&mut self, t: Nanos, phase: Phase) {
        let _ = (t, phase);
    }
    /// One controller cycle's values.
    fn sample(&mut self, s: &Sample) {
        let _ = s;
    }
}

/// A target of the positioning phase and where the axis ended.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetResult {
    /// What it was ("T3 absolute", "relative −2000").
    pub label: String,
    /// Commanded, increments.
    pub commanded_inc: i64,
    /// 6064h once target reached was reported and the axis settled.
    pub reached_inc: i64,
}

impl TargetResult {
    /// Reached − commanded, increments.
    pub fn error_inc(&self) -> i64 {
        self.reached_inc - self.commanded_inc
    }
}

/// The following error (|60F4h|) of one positioning move, from the start
/// of its task until it settled at its target.
#[derive(Debug, Clone, PartialEq)]
pub struct MoveFe {
    /// Which move ("chain T1…T3", "relative −2000").
    pub label: String,
    /// max |60F4h|, increments.
    pub max_inc: i64,
    /// rms of 60F4h, increments.
    pub rms_inc: f64,
    /// Controller cycles the move took (with its 200 ms settling).
    pub cycles: u64,
}

/// What B44 (identify mechanics) found through PKW, as read back: the raw
/// dictionary values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SelfTuneResult {
    /// A69 at the end (state in bits 12–15, 2 = done).
    pub a69: u32,
    /// B44\[0\]: the result code (0 = written).
    pub code: u32,
    /// B45 J, 10⁻⁷ kg·m².
    pub inertia: u32,
    /// B46 Fc, µN·m.
    pub coulomb: u32,
    /// B47 B, nN·m·s/rad.
    pub viscous: u32,
    /// C31 Kp (µN·m·s/rad), C32 Ti (µs), I20 Kv (0.1/s) as set by B44.
    pub gains: [u32; 3],
    /// Simulated time from Execute to done, ms.
    pub ms: u64,
}

/// How long a phase took and what it found.
#[derive(Debug, Clone, PartialEq)]
pub struct PhaseResult {
    /// The phase.
    pub phase: Phase,
    /// Its start and end, simulated time.
    pub start: Nanos,
    /// End.
    pub end: Nanos,
    /// One line: what it found.
    pub summary: String,
}

/// The run's outcome, phase by phase.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Report {
    /// Every phase run.
    pub phases: Vec<PhaseResult>,
    /// Spec deviations seen ("P-xxx: …"), each once.
    pub deviations: Vec<String>,
    /// The ZSW1 states the enable sequence went through (mask 0x47).
    pub enable_states: Vec<u16>,
    /// `drive_is_enabled` after the enable sequence.
    pub enabled: bool,
    /// `home_valid` after homing.
    pub home_valid: bool,
    /// 6064h after homing, increments.
    pub home_position_inc: i64,
    /// The velocity (rpm) at which the axis passed each intermediate
    /// target of the chain, with the end velocity asked for.
    pub passing_rpm: Vec<(i32, i32)>,
    /// The targets that end a move, with where the axis ended.
    pub targets: Vec<TargetResult>,
    /// `target_reached` came before the chain's last task ended (P-105).
    pub early_target_reached: bool,
    /// `operation_mode_actual` in the speed segment.
    pub speed_mode_actual: u8,
    /// `velo_reached` at 300 rpm, and the velocity then (rpm).
    pub velo_reached: Option<i32>,
    /// `velocity_actual_value` after 300 ms at the set-point, rpm.
    pub speed_rpm: i32,
    /// `velo_zero` after the set-point 0.
    pub velo_zero: bool,
    /// 6064h change of the positive and the negative jog, increments.
    pub jog_inc: [i64; 2],
    /// The PKW accesses: what, and how they ended.
    pub pkw: Vec<(String, Outcome)>,
    /// `fault` seen after the provoked event.
    pub fault_seen: bool,
    /// `drive_is_enabled` went with the fault.
    pub disabled_by_fault: bool,
    /// `fault` gone after `fault_reset`.
    pub fault_cleared: bool,
    /// `drive_is_enabled` again after the acknowledgement.
    pub re_enabled: bool,
    /// The positioning moves' following error: the chain, the relative move.
    pub moves: Vec<MoveFe>,
    /// B44 through PKW, when the run self-tuned.
    pub self_tune: Option<SelfTuneResult>,
    /// max |60F4h| over the run, increments.
    pub max_following_error_inc: i64,
    /// Controller cycles run.
    pub cycles: u64,
    /// Output frames sent, input frames taken.
    pub frames: (u64, u64),
}
