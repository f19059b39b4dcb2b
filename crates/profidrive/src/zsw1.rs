//! Status word 1 (PNU 968, spec §6, P-095…P-109) from a fieldbus-neutral
//! status.
//!
//! The state sits in bits 0, 1, 2 and 6 (mask 0x47, P-096): switching on
//! inhibited 0x40, ready to switch on 0x01, switched on 0x03, operation
//! 0x07. There is no S5 (P-126): a quick stop or fault reaction in
//! progress shows as switching on inhibited (the controller enable is
//! gone), a fault as switching on inhibited with bit 3.

/// The drive state as the core knows it (the CiA 402 states).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum State {
    /// Self-test (no exchange yet): no state bit.
    NotReady,
    /// Switch on disabled / switching on inhibited (S1).
    SwitchOnDisabled,
    /// Ready to switch on (S2).
    ReadyToSwitchOn,
    /// Switched on (S3).
    SwitchedOn,
    /// Operation enabled (S4).
    OperationEnabled,
    /// Quick stop active (the ramp running or held).
    QuickStopActive,
    /// Fault reaction active.
    FaultReactionActive,
    /// Fault.
    Fault,
}

/// What ZSW1 is made of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Status {
    /// The device state.
    pub state: State,
    /// A warning is present, or a limit switch locks the set-point (bit 7).
    pub warning: bool,
    /// A coast stop (OFF2) is active: bit 4 = 0.
    pub coast_stop: bool,
    /// A quick stop (OFF3) is active: bit 5 = 0.
    pub quick_stop: bool,
    /// Bit 8: positioning: following error within its window (P-101);
    /// speed: actual speed within the message window (P-102).
    pub within_tolerance: bool,
    /// Bit 9: the mirror of CW1 bit 10 (P-103).
    pub control_requested: bool,
    /// Bit 10: positioning: task done and inside the target window, after
    /// the last appended task (P-104, P-105); speed: actual ≥ threshold,
    /// signed (P-106).
    pub reached: bool,
    /// Bit 11: home position valid, 0 during a homing run (P-107).
    pub homed: bool,
    /// Bit 12: traversing task acknowledgement; 0 = a new job can be
    /// accepted (P-108).
    pub task_ack: bool,
    /// Bit 13: drive stopped (P-109).
    pub stopped: bool,
}

impl Status {
    /// A drive in `state` with no other flag set (no warning, stop, message or
    /// acknowledgement): a start for a caller that sets the few it needs.
    pub const fn of(state: State) -> Self {
        Self {
            state,
            warning: false,
            coast_stop: false,
            quick_stop: false,
            within_tolerance: false,
            control_requested: false,
            reached: false,
            homed: false,
            task_ack: false,
            stopped: false,
        }
    }
}

/// The state mask (P-096).
pub const STATE_MASK: u16 = 0x0047;
/// Switching on inhibited.
pub const SOI: u16 = 0x0040;
/// Ready to switch on.
pub const RTSO: u16 = 0x0001;
/// Switched on.
pub const SO: u16 = 0x0003;
/// Operation.
pub const OP: u16 = 0x0007;
/// Bit 3: fault present.
pub const FAULT: u16 = 1 << 3;

/// ZSW1 of `s`.
pub fn encode(s: &Status) -> u16 {
    let state = match s.state {
        State::NotReady => 0,
        State::SwitchOnDisabled | State::QuickStopActive => SOI,
        State::FaultReactionActive | State::Fault => SOI | FAULT,
        State::ReadyToSwitchOn => RTSO,
        State::SwitchedOn => SO,
        State::OperationEnabled => OP,
    };
    let bit = |on: bool, n: u16| if on { 1u16 << n } else { 0 };
    state
        | bit(!s.coast_stop, 4)
        | bit(!s.quick_stop && s.state != State::QuickStopActive, 5)
        | bit(s.warning, 7)
        | bit(s.within_tolerance, 8)
        | bit(s.control_requested, 9)
        | bit(s.reached, 10)
        | bit(s.homed, 11)
        | bit(s.task_ack, 12)
        | bit(s.stopped, 13)
}
