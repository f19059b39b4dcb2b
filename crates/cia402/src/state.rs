//! Device states and the statusword 6041h (spec §5.1, §5.3).

/// Statusword bit 0: ready to switch on.
pub const SW_READY_TO_SWITCH_ON: u16 = 1 << 0;
/// Statusword bit 1: switched on.
pub const SW_SWITCHED_ON: u16 = 1 << 1;
/// Statusword bit 2: operation enabled.
pub const SW_OPERATION_ENABLED: u16 = 1 << 2;
/// Statusword bit 3: fault.
pub const SW_FAULT: u16 = 1 << 3;
/// Statusword bit 4: voltage enabled (DC-link supply present).
pub const SW_VOLTAGE_ENABLED: u16 = 1 << 4;
/// Statusword bit 5: quick stop (active **low**: 0 while Quick stop active).
pub const SW_QUICK_STOP: u16 = 1 << 5;
/// Statusword bit 6: switch on disabled.
pub const SW_SWITCH_ON_DISABLED: u16 = 1 << 6;
/// Statusword bit 7: warning.
pub const SW_WARNING: u16 = 1 << 7;
/// Statusword bit 9: remote (the controlword is processed).
pub const SW_REMOTE: u16 = 1 << 9;
/// Statusword bit 10: target reached (mode-specific).
pub const SW_TARGET_REACHED: u16 = 1 << 10;
/// Statusword bit 11: internal limit active.
pub const SW_INTERNAL_LIMIT: u16 = 1 << 11;
/// Statusword bit 12: mode-specific.
pub const SW_MODE_BIT12: u16 = 1 << 12;
/// Statusword bit 13: mode-specific.
pub const SW_MODE_BIT13: u16 = 1 << 13;
/// Statusword bits 8, 14, 15: manufacturer-specific, passed through from the inputs.
pub const SW_MANUFACTURER_MASK: u16 = (1 << 8) | (1 << 14) | (1 << 15);

/// A state of the CiA 402 device-control state machine (spec §5.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum State {
    /// Initialisation and self-test; power stage locked.
    NotReadyToSwitchOn,
    /// Power stage locked; entered after init and on every switch-on-disabled cause.
    SwitchOnDisabled,
    /// Power stage locked, activation enabled.
    ReadyToSwitchOn,
    /// Power stage on, no torque, set values ignored.
    SwitchedOn,
    /// Drive function enabled, set values processed.
    OperationEnabled,
    /// Quick stop running (or, option codes 5..8, holding after it).
    QuickStopActive,
    /// The fault reaction is running.
    FaultReactionActive,
    /// Fault; power stage locked.
    Fault,
}

impl State {
    /// All states, in the order of [`State::code`].
    pub const ALL: [State; 8] = [
        State::NotReadyToSwitchOn,
        State::SwitchOnDisabled,
        State::ReadyToSwitchOn,
        State::SwitchedOn,
        State::OperationEnabled,
        State::QuickStopActive,
        State::FaultReactionActive,
        State::Fault,
    ];

    /// Mask and value of the state pattern in the statusword (spec §5.3).
    pub const fn pattern(self) -> (u16, u16) {
        match self {
            State::NotReadyToSwitchOn => (0x004F, 0x0000),
            State::SwitchOnDisabled => (0x004F, 0x0040),
            State::ReadyToSwitchOn => (0x006F, 0x0021),
            State::SwitchedOn => (0x006F, 0x0023),
            State::OperationEnabled => (0x006F, 0x0027),
            State::QuickStopActive => (0x006F, 0x0007),
            State::FaultReactionActive => (0x004F, 0x000F),
            State::Fault => (0x004F, 0x0008),
        }
    }

    /// Bits 0, 1, 2, 3, 5 and 6 of the statusword in this state. Bit 5 is set only where
    /// the pattern defines it as 1 (Ready to switch on, Switched on, Operation enabled).
    pub const fn state_bits(self) -> u16 {
        self.pattern().1
    }

    /// The state a statusword shows, if it matches one of the patterns.
    pub fn from_statusword(sw: u16) -> Option<State> {
        State::ALL.into_iter().find(|s| {
            let (mask, value) = s.pattern();
            sw & mask == value
        })
    }

    /// A small numeric code for the state (0 = Not ready … 7 = Fault, in the order of
    /// [`State::ALL`]), for the device-state display E48.
    pub const fn code(self) -> u8 {
        match self {
            State::NotReadyToSwitchOn => 0,
            State::SwitchOnDisabled => 1,
            State::ReadyToSwitchOn => 2,
            State::SwitchedOn => 3,
            State::OperationEnabled => 4,
            State::QuickStopActive => 5,
            State::FaultReactionActive => 6,
            State::Fault => 7,
        }
    }

    /// The state's name as the spec writes it ("Switch on disabled").
    pub const fn name(self) -> &'static str {
        match self {
            State::NotReadyToSwitchOn => "Not ready to switch on",
            State::SwitchOnDisabled => "Switch on disabled",
            State::ReadyToSwitchOn => "Ready to switch on",
            State::SwitchedOn => "Switched on",
            State::OperationEnabled => "Operation enabled",
            State::QuickStopActive => "Quick stop active",
            State::FaultReactionActive => "Fault reaction active",
            State::Fault => "Fault",
        }
    }

    /// `true` in the two fault states.
    pub const fn is_fault(self) -> bool {
        matches!(self, State::FaultReactionActive | State::Fault)
    }
}
