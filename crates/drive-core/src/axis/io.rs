//! The axis' hardware seam: what the board or simulator hands to a control
//! cycle ([`AxisIo`]: encoder, latched edges, switches, enables, the measured
//! current) and what it gets back ([`AxisCommand`], [`AxisReport`]).

use super::*;

/// An encoder zero (index) pulse latched by the hardware in this cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IndexLatch {
    /// Encoder position at the pulse, increments (motor coordinates, like
    /// [`AxisIo::position_inc`]).
    pub position_inc: i32,
    /// Time of the pulse (same clock as `now_ns`).
    pub time_ns: Nanos,
}

/// An edge of a touch-probe input seen in this cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ProbeEdge {
    /// The physical input: 1 or 2 (60D0h:01/:02 select which probe it feeds).
    pub input: u8,
    /// `true` = rising (0 → 1), `false` = falling.
    pub rising: bool,
    /// Time stamp of the edge (same clock as `now_ns`).
    pub time_ns: Nanos,
    /// Encoder position latched by the hardware at the edge, increments
    /// (motor coordinates); `None`: interpolated between the last and this
    /// cycle's positions at `time_ns`.
    pub position_inc: Option<i32>,
}

/// A limit or reference switch input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SwitchId {
    /// Positive hardware limit switch (I441).
    PositiveLimit,
    /// Negative hardware limit switch (I442).
    NegativeLimit,
    /// Reference (home) switch.
    Reference,
}

/// A change of a limit or reference switch latched by the hardware in this
/// cycle (time-stamped input, spec §12): homing takes its reference from the
/// latched position instead of the position of the cycle that sees the new
/// level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SwitchEdge {
    /// Which switch changed.
    pub switch: SwitchId,
    /// Encoder position at the change, increments (motor coordinates).
    pub position_inc: i32,
}

/// What the hardware (board driver or simulated motor) reports for one axis
/// at the start of a control cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisIo {
    /// Encoder position, increments (2^20 per revolution, wrapping), motor
    /// coordinates.
    pub position_inc: i32,
    /// Encoder zero pulse seen since the last cycle.
    pub index: Option<IndexLatch>,
    /// Positive hardware limit switch hit (I441 after the wiring's polarity:
    /// a broken NC wire reads as hit). Evaluated only with
    /// [`LimitConfig::positive_switch`] (I101) set.
    pub limit_positive: bool,
    /// Negative hardware limit switch hit (I442), see `limit_positive`.
    pub limit_negative: bool,
    /// Reference (home) switch active (I103).
    pub reference: bool,
    /// Touch-probe input edges since the last cycle (up to 4).
    pub probe_edges: [Option<ProbeEdge>; 4],
    /// Limit/reference switch changes latched since the last cycle (up to
    /// 4; none: homing uses the position of the cycle that sees the level).
    pub switch_edges: [Option<SwitchEdge>; 4],
    /// Additional enable A60 active.
    pub additional_enable: bool,
    /// Supply and DC link present.
    pub supply_ok: bool,
    /// Safe torque off active.
    pub sto_active: bool,
    /// The motor encoder delivers a valid position (the feedback driver's
    /// own check: signal, communication, plausibility). While `false`,
    /// `position_inc` is not used and the axis faults (event 37).
    pub encoder_ok: bool,
    /// The current loop's latest measurement ([`CurrentControl::actual`]):
    /// 6077h and 6078h show it. `None`: no measurement, they show the demand.
    pub current: Option<CurrentActual>,
}

impl AxisIo {
    /// A ready axis at `position_inc`: enable A60 on, supply present, STO
    /// off, encoder valid, no switches or edges, no current measurement (what
    /// the simulator passes by default).
    pub const fn ready(position_inc: i32) -> Self {
        Self {
            position_inc,
            index: None,
            limit_positive: false,
            limit_negative: false,
            reference: false,
            probe_edges: [None; 4],
            switch_edges: [None; 4],
            additional_enable: true,
            supply_ok: true,
            sto_active: false,
            encoder_ok: true,
            current: None,
        }
    }
}

/// What the axis commands to the power stage for the next cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisCommand {
    /// Torque set-point for the current controller, N·m (motor coordinates).
    pub torque_nm: f32,
    /// Power stage on.
    pub power_stage: bool,
    /// Release (open) the holding brake.
    pub brake_release: bool,
    /// A motor action's measurement voltage instead of the torque's current
    /// (`None` in normal operation; [`Injection`]).
    pub injection: Option<Injection>,
}

impl AxisCommand {
    /// Power stage off, brake engaged, no torque.
    pub const OFF: AxisCommand = AxisCommand {
        torque_nm: 0.0,
        power_stage: false,
        brake_release: false,
        injection: None,
    };
}

/// One cycle's result of [`Axis::cycle`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisReport {
    /// The command for the power stage.
    pub command: AxisCommand,
    /// The device-control transition taken, if any.
    pub transition: Option<Transition>,
    /// The fault change of the cycle: the fault on T13, cleared on T15 (a
    /// fieldbus personality sends its message for it).
    pub fault: Option<crate::faults::FaultChange>,
}
