//! Application layer: AL control (0x0120), AL status (0x0130), AL status code (0x0134).

/// EtherCAT state machine states as encoded in AL control/status bits 0..3.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum AlState {
    /// Init (1).
    Init,
    /// Pre-Operational (2).
    PreOp,
    /// Bootstrap (3).
    Bootstrap,
    /// Safe-Operational (4).
    SafeOp,
    /// Operational (8).
    Op,
}

impl AlState {
    /// The 4-bit state code.
    pub const fn code(self) -> u8 {
        match self {
            AlState::Init => 1,
            AlState::PreOp => 2,
            AlState::Bootstrap => 3,
            AlState::SafeOp => 4,
            AlState::Op => 8,
        }
    }

    /// The state for a 4-bit code, or `None` for an unknown code.
    pub const fn from_code(code: u8) -> Option<Self> {
        match code {
            1 => Some(AlState::Init),
            2 => Some(AlState::PreOp),
            3 => Some(AlState::Bootstrap),
            4 => Some(AlState::SafeOp),
            8 => Some(AlState::Op),
            _ => None,
        }
    }
}

/// The AL control register as written by the master.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AlControl {
    /// Requested state code (bits 0..3), possibly unknown.
    pub requested: u8,
    /// Error indication acknowledge (bit 4).
    pub ack: bool,
    /// Device identification request (bit 5).
    pub id_request: bool,
}

impl AlControl {
    /// Decodes the 16-bit register value.
    pub const fn from_raw(raw: u16) -> Self {
        Self {
            requested: (raw & 0x0F) as u8,
            ack: raw & 0x10 != 0,
            id_request: raw & 0x20 != 0,
        }
    }

    /// Encodes the register value.
    pub const fn raw(self) -> u16 {
        (self.requested as u16 & 0x0F)
            | if self.ack { 0x10 } else { 0 }
            | if self.id_request { 0x20 } else { 0 }
    }
}

/// The AL status register as written by the slave.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AlStatus {
    /// Current state.
    pub state: AlState,
    /// Error indication (bit 4): the AL status code says why.
    pub error: bool,
    /// Device identification loaded (bit 5).
    pub id_loaded: bool,
}

impl AlStatus {
    /// A status without error.
    pub const fn new(state: AlState) -> Self {
        Self {
            state,
            error: false,
            id_loaded: false,
        }
    }

    /// Encodes the register value.
    pub const fn raw(self) -> u16 {
        self.state.code() as u16 | if self.error { 0x10 } else { 0 } | if self.id_loaded { 0x20 } else { 0 }
    }

    /// Decodes a register value; `None` when the state bits are not a known state.
    pub const fn from_raw(raw: u16) -> Option<Self> {
        match AlState::from_code((raw & 0x0F) as u8) {
            Some(state) => Some(Self {
                state,
                error: raw & 0x10 != 0,
                id_loaded: raw & 0x20 != 0,
            }),
            None => None,
        }
    }
}

/// AL status code (0x0134), ETG.1000.6 Table 11; the subset the drive uses is in
/// `../shared/spec/ethercat.md` §4.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct AlStatusCode(pub u16);

impl AlStatusCode {
    /// 0000h No error.
    pub const NO_ERROR: Self = Self(0x0000);
    /// 0001h Unspecified error.
    pub const UNSPECIFIED: Self = Self(0x0001);
    /// 0002h No memory.
    pub const NO_MEMORY: Self = Self(0x0002);
    /// 0011h Invalid requested state change.
    pub const INVALID_STATE_CHANGE: Self = Self(0x0011);
    /// 0012h Unknown requested state.
    pub const UNKNOWN_STATE: Self = Self(0x0012);
    /// 0013h Bootstrap not supported.
    pub const BOOTSTRAP_NOT_SUPPORTED: Self = Self(0x0013);
    /// 0014h No valid firmware.
    pub const NO_VALID_FIRMWARE: Self = Self(0x0014);
    /// 0015h Invalid mailbox configuration (bootstrap).
    pub const INVALID_MAILBOX_CONFIG_BOOT: Self = Self(0x0015);
    /// 0016h Invalid mailbox configuration.
    pub const INVALID_MAILBOX_CONFIG: Self = Self(0x0016);
    /// 0017h Invalid sync manager configuration.
    pub const INVALID_SM_CONFIG: Self = Self(0x0017);
    /// 0018h No valid inputs available.
    pub const NO_VALID_INPUTS: Self = Self(0x0018);
    /// 0019h No valid outputs.
    pub const NO_VALID_OUTPUTS: Self = Self(0x0019);
    /// 001Ah Synchronization error.
    pub const SYNC_ERROR: Self = Self(0x001A);
    /// 001Bh Sync manager watchdog.
    pub const SM_WATCHDOG: Self = Self(0x001B);
    /// 001Dh Invalid output configuration (SM2).
    pub const INVALID_OUTPUT_CONFIG: Self = Self(0x001D);
    /// 001Eh Invalid input configuration (SM3).
    pub const INVALID_INPUT_CONFIG: Self = Self(0x001E);
    /// 001Fh Invalid watchdog configuration.
    pub const INVALID_WATCHDOG_CONFIG: Self = Self(0x001F);
    /// 0029h Freerun needs 3-buffer mode.
    pub const FREERUN_NEEDS_3BUFFER: Self = Self(0x0029);
    /// 002Bh No valid inputs and outputs.
    pub const NO_VALID_IO: Self = Self(0x002B);
    /// 002Dh No sync error (SYNC0 not received).
    pub const NO_SYNC: Self = Self(0x002D);
    /// 0030h Invalid DC SYNC configuration.
    pub const INVALID_DC_SYNC_CONFIG: Self = Self(0x0030);
    /// 0032h PLL error.
    pub const PLL_ERROR: Self = Self(0x0032);
    /// 0033h DC sync IO error.
    pub const DC_SYNC_IO_ERROR: Self = Self(0x0033);
    /// 0034h DC sync timeout error.
    pub const DC_SYNC_TIMEOUT: Self = Self(0x0034);
    /// 0035h DC invalid sync cycle time.
    pub const DC_INVALID_CYCLE_TIME: Self = Self(0x0035);
    /// 0036h DC SYNC0 cycle time.
    pub const DC_SYNC0_CYCLE_TIME: Self = Self(0x0036);
    /// 0051h EEPROM error.
    pub const EEPROM_ERROR: Self = Self(0x0051);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn e041_state_codes_round_trip() {
        for s in [
            AlState::Init,
            AlState::PreOp,
            AlState::Bootstrap,
            AlState::SafeOp,
            AlState::Op,
        ] {
            assert_eq!(AlState::from_code(s.code()), Some(s));
        }
        assert_eq!(AlState::from_code(0), None);
        assert_eq!(AlState::from_code(5), None);
        // error variants as shown in A255: state | 0x10
        let st = AlStatus {
            state: AlState::PreOp,
            error: true,
            id_loaded: false,
        };
        assert_eq!(st.raw(), 18);
    }

    #[test]
    fn al_control_decodes_ack() {
        let c = AlControl::from_raw(0x0012);
        assert_eq!(c.requested, 2);
        assert!(c.ack);
        assert_eq!(c.raw(), 0x0012);
    }
}
