//! ESC register addresses (ETG.1000.4 §6, ET1100/LAN9252 datasheets).
//!
//! Addresses are byte offsets in the ESC's 16-bit physical address space.
//! Multi-byte registers are little-endian.

/// Type (u8).
pub const TYPE: u16 = 0x0000;
/// Revision (u8).
pub const REVISION: u16 = 0x0001;
/// Build (u16).
pub const BUILD: u16 = 0x0002;
/// Number of FMMUs supported (u8).
pub const FMMU_COUNT: u16 = 0x0004;
/// Number of SyncManagers supported (u8).
pub const SM_COUNT: u16 = 0x0005;
/// Process RAM size in KiB (u8).
pub const RAM_SIZE: u16 = 0x0006;
/// Port descriptor (u8): 2 bits per port.
pub const PORT_DESCRIPTOR: u16 = 0x0007;
/// ESC features supported (u16).
pub const FEATURES: u16 = 0x0008;
/// Configured station address (u16), written by the master.
pub const STATION_ADDRESS: u16 = 0x0010;
/// Configured station alias (u16), loaded from SII word 4 at EEPROM load.
pub const STATION_ALIAS: u16 = 0x0012;
/// Register write enable (u8).
pub const WRITE_ENABLE: u16 = 0x0020;
/// Register write protection (u8).
pub const WRITE_PROTECTION: u16 = 0x0021;
/// ESC reset ECAT (u8).
pub const RESET_ECAT: u16 = 0x0040;
/// ESC reset PDI (u8).
pub const RESET_PDI: u16 = 0x0041;
/// ESC DL control (u32).
pub const DL_CONTROL: u16 = 0x0100;
/// Physical read/write offset (u16).
pub const RW_OFFSET: u16 = 0x0108;
/// ESC DL status (u16).
pub const DL_STATUS: u16 = 0x0110;
/// AL control (u16), written by the master: requested state and error acknowledge.
pub const AL_CONTROL: u16 = 0x0120;
/// AL status (u16), written by the slave (PDI): current state and error indication.
pub const AL_STATUS: u16 = 0x0130;
/// AL status code (u16), written by the slave (PDI).
pub const AL_STATUS_CODE: u16 = 0x0134;
/// RUN LED override (u8).
pub const RUN_LED_OVERRIDE: u16 = 0x0138;
/// ERR LED override (u8).
pub const ERR_LED_OVERRIDE: u16 = 0x0139;
/// PDI control (u8): PDI type (0x05 SPI, 0x80 on-chip bus, ...).
pub const PDI_CONTROL: u16 = 0x0140;
/// ESC configuration (u8).
pub const ESC_CONFIG: u16 = 0x0141;
/// PDI configuration (u8 / u16 / u32 depending on PDI).
pub const PDI_CONFIG: u16 = 0x0150;
/// ECAT event mask (u16).
pub const ECAT_EVENT_MASK: u16 = 0x0200;
/// AL event mask (u32), written by the PDI.
pub const AL_EVENT_MASK: u16 = 0x0204;
/// ECAT event request (u16).
pub const ECAT_EVENT_REQUEST: u16 = 0x0210;
/// AL event request (u32): events towards the PDI (see [`al_event`]).
pub const AL_EVENT_REQUEST: u16 = 0x0220;
/// RX error counters, 2 bytes per port (invalid frame, RX error).
pub const RX_ERROR_COUNTER: u16 = 0x0300;
/// Forwarded RX error counters, 1 byte per port.
pub const FWD_RX_ERROR_COUNTER: u16 = 0x0308;
/// ECAT processing unit error counter (u8).
pub const ECAT_PU_ERROR_COUNTER: u16 = 0x030C;
/// PDI error counter (u8).
pub const PDI_ERROR_COUNTER: u16 = 0x030D;
/// Lost link counters, 1 byte per port.
pub const LOST_LINK_COUNTER: u16 = 0x0310;
/// Watchdog divider (u16): number of 40 ns ticks in one watchdog increment (default 2498 → 100 µs).
pub const WATCHDOG_DIVIDER: u16 = 0x0400;
/// PDI watchdog time (u16) in watchdog increments.
pub const WATCHDOG_TIME_PDI: u16 = 0x0410;
/// Process-data (SM) watchdog time (u16) in watchdog increments.
pub const WATCHDOG_TIME_PD: u16 = 0x0420;
/// Process-data watchdog status (u16): bit 0 = 1 while not expired.
pub const WATCHDOG_STATUS_PD: u16 = 0x0440;
/// Process-data watchdog expiry counter (u8).
pub const WATCHDOG_COUNTER_PD: u16 = 0x0442;
/// PDI watchdog expiry counter (u8).
pub const WATCHDOG_COUNTER_PDI: u16 = 0x0443;
/// SII EEPROM configuration (u8): bit 0 = PDI access offered.
pub const SII_CONFIG: u16 = 0x0500;
/// SII EEPROM PDI access state (u8): bit 0 = PDI owns the EEPROM.
pub const SII_PDI_ACCESS: u16 = 0x0501;
/// SII EEPROM control/status (u16), see [`crate::sii::control`].
pub const SII_CONTROL: u16 = 0x0502;
/// SII EEPROM word address (u32).
pub const SII_ADDRESS: u16 = 0x0504;
/// SII EEPROM data (8 bytes read / 2 bytes write).
pub const SII_DATA: u16 = 0x0508;
/// MII management control/status (u16).
pub const MII_CONTROL: u16 = 0x0510;
/// First FMMU (16 bytes each, see [`crate::fmmu::Fmmu`]).
pub const FMMU_BASE: u16 = 0x0600;
/// Bytes per FMMU register block.
pub const FMMU_LEN: u16 = 16;
/// First SyncManager (8 bytes each, see [`crate::sm::SyncManager`]).
pub const SM_BASE: u16 = 0x0800;
/// Bytes per SyncManager register block.
pub const SM_LEN: u16 = 8;
/// Start of the process RAM.
pub const PROCESS_RAM: u16 = 0x1000;

/// Address of FMMU `n`'s register block.
pub const fn fmmu(n: u8) -> u16 {
    FMMU_BASE + FMMU_LEN * n as u16
}

/// Address of SyncManager `n`'s register block.
pub const fn sm(n: u8) -> u16 {
    SM_BASE + SM_LEN * n as u16
}

/// Bits of the AL event request (0x0220) and AL event mask (0x0204).
pub mod al_event {
    /// AL control register written by the master.
    pub const AL_CONTROL: u32 = 1 << 0;
    /// DC latch event.
    pub const DC_LATCH: u32 = 1 << 1;
    /// SYNC0 (when mapped to the AL event request).
    pub const SYNC0: u32 = 1 << 2;
    /// SYNC1 (when mapped to the AL event request).
    pub const SYNC1: u32 = 1 << 3;
    /// SyncManager activation register (0x0806 + 8n) changed.
    pub const SM_ACTIVATION: u32 = 1 << 4;
    /// EEPROM emulation command pending.
    pub const EEPROM_EMULATION: u32 = 1 << 5;
    /// Watchdog process data expired.
    pub const WATCHDOG_PD: u32 = 1 << 6;
    /// SyncManager `n` interrupt (buffer written/read by ECAT).
    pub const fn sm(n: u8) -> u32 {
        1 << (8 + n as u32)
    }
}

/// Bits of the DL status register (0x0110, u16).
pub mod dl_status {
    /// PDI operational: EEPROM loaded with a correct checksum.
    pub const PDI_OPERATIONAL: u16 = 1 << 0;
    /// PDI watchdog status: 1 = reloaded, 0 = expired.
    pub const PDI_WATCHDOG: u16 = 1 << 1;
    /// Enhanced link detection active.
    pub const ENHANCED_LINK_DETECTION: u16 = 1 << 2;
    /// Physical link on port `n` (0..3).
    pub const fn link(n: u8) -> u16 {
        1 << (4 + n as u16)
    }
    /// Loop closed on port `n` (0..3): the port forwards back, nothing behind it.
    pub const fn loop_closed(n: u8) -> u16 {
        1 << (8 + 2 * n as u16)
    }
    /// Stable communication on port `n` (0..3).
    pub const fn communication(n: u8) -> u16 {
        1 << (9 + 2 * n as u16)
    }
}

/// Distributed-clock registers (0x0900–0x09FF).
pub mod dc {
    /// Receive time port 0 (u32), latched by a write to it.
    pub const RECEIVE_TIME_PORT0: u16 = 0x0900;
    /// Receive time port 1 (u32).
    pub const RECEIVE_TIME_PORT1: u16 = 0x0904;
    /// Receive time port 2 (u32).
    pub const RECEIVE_TIME_PORT2: u16 = 0x0908;
    /// Receive time port 3 (u32).
    pub const RECEIVE_TIME_PORT3: u16 = 0x090C;
    /// System time (u64); an ARMW/FRMW write feeds the drift control loop.
    pub const SYSTEM_TIME: u16 = 0x0910;
    /// Receive time of the processing unit (u64).
    pub const RECEIVE_TIME_PU: u16 = 0x0918;
    /// System time offset (u64).
    pub const SYSTEM_TIME_OFFSET: u16 = 0x0920;
    /// System time delay (u32).
    pub const SYSTEM_TIME_DELAY: u16 = 0x0928;
    /// System time difference (u32): sign bit 31, magnitude in ns.
    pub const SYSTEM_TIME_DIFFERENCE: u16 = 0x092C;
    /// Speed counter start (u16).
    pub const SPEED_COUNTER_START: u16 = 0x0930;
    /// Speed counter difference (i16).
    pub const SPEED_COUNTER_DIFF: u16 = 0x0932;
    /// System time difference filter depth (u8).
    pub const FILTER_DEPTH_TIME: u16 = 0x0934;
    /// Speed counter filter depth (u8).
    pub const FILTER_DEPTH_SPEED: u16 = 0x0935;
    /// Cyclic unit control (u8): bit 0 = SYNC/latch unit 0 controlled by PDI.
    pub const CYCLIC_UNIT_CONTROL: u16 = 0x0980;
    /// Activation (u8): bit 0 cyclic operation, bit 1 SYNC0, bit 2 SYNC1.
    pub const ACTIVATION: u16 = 0x0981;
    /// Pulse length of SYNC signals (u16) in units of 10 ns.
    pub const PULSE_LENGTH: u16 = 0x0982;
    /// Activation status (u8).
    pub const ACTIVATION_STATUS: u16 = 0x0984;
    /// SYNC0 status (u8): bit 0 set on a SYNC0 pulse, cleared by reading.
    pub const SYNC0_STATUS: u16 = 0x098E;
    /// SYNC1 status (u8).
    pub const SYNC1_STATUS: u16 = 0x098F;
    /// Start time of cyclic operation (u64), system time in ns.
    pub const START_TIME: u16 = 0x0990;
    /// Next SYNC1 pulse (u64).
    pub const NEXT_SYNC1: u16 = 0x0998;
    /// SYNC0 cycle time (u32) in ns.
    pub const SYNC0_CYCLE: u16 = 0x09A0;
    /// SYNC1 cycle time (u32) in ns.
    pub const SYNC1_CYCLE: u16 = 0x09A4;
    /// Latch0 control (u8).
    pub const LATCH0_CONTROL: u16 = 0x09A8;
    /// Latch1 control (u8).
    pub const LATCH1_CONTROL: u16 = 0x09A9;
    /// Latch0 status (u8).
    pub const LATCH0_STATUS: u16 = 0x09AE;
    /// Latch1 status (u8).
    pub const LATCH1_STATUS: u16 = 0x09AF;
    /// Latch0 positive-edge time (u64).
    pub const LATCH0_POS: u16 = 0x09B0;
    /// Latch0 negative-edge time (u64).
    pub const LATCH0_NEG: u16 = 0x09B8;
    /// Latch1 positive-edge time (u64).
    pub const LATCH1_POS: u16 = 0x09C0;
    /// Latch1 negative-edge time (u64).
    pub const LATCH1_NEG: u16 = 0x09C8;
    /// Time of the last SM event of the ECAT side (u32).
    pub const ECAT_BUFFER_CHANGE: u16 = 0x09F0;
    /// Time of the last PDI buffer start event (u32).
    pub const PDI_BUFFER_START: u16 = 0x09F8;
    /// Time of the last PDI buffer change event (u32).
    pub const PDI_BUFFER_CHANGE: u16 = 0x09FC;
}
