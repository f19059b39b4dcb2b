//! The mode running on the axis and the state that belongs to that mode
//! alone ([`Running`]). Changing the mode (or stopping) drops the old mode's
//! state with the variant, so no mode reads what another left behind; what
//! all modes share (the set-point, the profile generator, the interpolators,
//! the monitors) stays in [`super::Axis`].

use cia402::Mode;
use nanos::Nanos;

/// The mode the motion core was set up for, with its own state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) enum Running {
    /// No mode runs: the drive function is off, a device-control stop runs,
    /// or the mode is not set up yet.
    #[default]
    Idle,
    /// csp (8) or ip (7) on the fine interpolator.
    CyclicPosition {
        /// ip (7) instead of csp (8).
        ip: bool,
        /// The master's set-points seen so far.
        master: MasterTrack,
    },
    /// csv (9) on the velocity interpolator.
    CyclicVelocity,
    /// cst (10).
    CyclicTorque,
    /// pp (1).
    ProfilePosition(PpState),
    /// pv (3).
    ProfileVelocity(VelocityCommand),
    /// pt (4): the output of the torque ramp, N·m.
    ProfileTorque {
        /// Torque ramp output, N·m.
        torque: f32,
    },
    /// vl (2).
    Velocity(VelocityCommand),
    /// Homing (6) on `motion::homing`.
    Homing,
    /// Jog (−1).
    Jog(VelocityCommand),
    /// No mode (0): holds the set-point.
    NoMode,
}

impl Running {
    /// The state a freshly activated `mode` starts with (pt: from `torque`,
    /// the last cascade torque).
    pub(super) fn start(mode: Mode, torque: f32) -> Running {
        match mode {
            Mode::CyclicPosition => Running::CyclicPosition {
                ip: false,
                master: MasterTrack::default(),
            },
            Mode::InterpolatedPosition => Running::CyclicPosition {
                ip: true,
                master: MasterTrack::default(),
            },
            Mode::CyclicVelocity => Running::CyclicVelocity,
            Mode::CyclicTorque => Running::CyclicTorque,
            Mode::ProfilePosition => Running::ProfilePosition(PpState::default()),
            Mode::ProfileVelocity => Running::ProfileVelocity(VelocityCommand::default()),
            Mode::ProfileTorque => Running::ProfileTorque { torque },
            Mode::Velocity => Running::Velocity(VelocityCommand::default()),
            Mode::Homing => Running::Homing,
            Mode::Jog => Running::Jog(VelocityCommand::default()),
            Mode::NoMode => Running::NoMode,
        }
    }

    /// The running mode, `None` when idle.
    pub(super) fn mode(&self) -> Option<Mode> {
        Some(match self {
            Running::Idle => return None,
            Running::CyclicPosition { ip: false, .. } => Mode::CyclicPosition,
            Running::CyclicPosition { ip: true, .. } => Mode::InterpolatedPosition,
            Running::CyclicVelocity => Mode::CyclicVelocity,
            Running::CyclicTorque => Mode::CyclicTorque,
            Running::ProfilePosition(_) => Mode::ProfilePosition,
            Running::ProfileVelocity(_) => Mode::ProfileVelocity,
            Running::ProfileTorque { .. } => Mode::ProfileTorque,
            Running::Velocity(_) => Mode::Velocity,
            Running::Homing => Mode::Homing,
            Running::Jog(_) => Mode::Jog,
            Running::NoMode => Mode::NoMode,
        })
    }

    /// Whether `mode` is the running mode (`mode() == Some(mode)`), the
    /// cyclic modes a master drives every cycle checked first by pattern.
    #[inline]
    pub(super) fn is(&self, mode: Mode) -> bool {
        match (self, mode) {
            (Running::CyclicPosition { ip: false, .. }, Mode::CyclicPosition)
            | (Running::CyclicPosition { ip: true, .. }, Mode::InterpolatedPosition)
            | (Running::CyclicVelocity, Mode::CyclicVelocity)
            | (Running::CyclicTorque, Mode::CyclicTorque) => true,
            _ => self.mode() == Some(mode),
        }
    }

    /// The velocity command of pv, vl and jog, if one of them runs.
    pub(super) fn velocity_command(&mut self) -> Option<&mut VelocityCommand> {
        match self {
            Running::ProfileVelocity(c) | Running::Velocity(c) | Running::Jog(c) => Some(c),
            _ => None,
        }
    }
}

/// csp/ip: the master's last cyclic position set-point, for the set-value
/// monitoring (C-148) and the endless axis' unwrapping (C-111).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) struct MasterTrack {
    /// Last set-point, increments (unwrapped).
    pub(super) setpoint: Option<i32>,
    /// The same set-point as sent, user units (endless axis only).
    pub(super) user: Option<i64>,
    /// Time since it arrived.
    pub(super) age: Nanos,
}

/// pp: the move being approached and its handshake.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct PpState {
    /// Set-point acknowledge, statusword bit 12.
    pub(super) ack: bool,
    /// The target being approached (an override change re-plans, C-030).
    pub(super) target: Option<i32>,
    /// The A340 override the move was planned with, %.
    pub(super) override_percent: u16,
    /// A halt (bit 8) in progress.
    pub(super) halting: bool,
}

impl Default for PpState {
    fn default() -> Self {
        Self {
            ack: false,
            target: None,
            override_percent: 100,
            halting: false,
        }
    }
}

/// pv, vl, jog: the velocity last commanded to the profile generator.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) struct VelocityCommand {
    /// Last commanded profile velocity, inc/s (`None`: none yet).
    pub(super) commanded: Option<f32>,
    /// A halt (bit 8) in progress (pv).
    pub(super) halting: bool,
}
