//! The established application relation (AR): plain data the cyclic (rt) and
//! alarm code are configured from. Self-contained: it names no rt/alarm type.
//!
//! Directions follow PROFINET's controller view: an **input** CR carries data
//! device → controller (the drive's "OUT modules", [`Direction::FromDrive`]),
//! an **output** CR controller → device ("IN modules", [`Direction::ToDrive`]).

use heapless::Vec;
use nanos::Nanos;

use crate::ip::Endpoint;
use crate::model::{DataModule, Direction};
use crate::rpc::Uuid;
use crate::wire::MacAddr;

/// Submodules an AR can hold (4 DAP subslots + data slots).
pub const MAX_SUBMODULES: usize = 16;
/// The last data slot the drive offers (the model's [`crate::model::DATA_SLOTS`],
/// each one data module at subslot 1).
pub const MAX_DATA_SLOTS: u16 = *crate::model::DATA_SLOTS.end();
/// Longest CMInitiatorStationName.
pub const MAX_STATION_NAME: usize = 240;

/// ARType values the device accepts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArType {
    /// IOCARSingle (0x0001): cyclic data, alarms, records.
    IoCarSingle,
    /// IOSAR (0x0006): supervisor / device access, records only.
    IoSar,
}

impl ArType {
    /// The ARType value.
    pub const fn to_u16(self) -> u16 {
        match self {
            ArType::IoCarSingle => 0x0001,
            ArType::IoSar => 0x0006,
        }
    }
}

/// Where the AR is in its start-up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArState {
    /// Connect answered; parameters may be written until PrmEnd.
    Parameterising,
    /// PrmEnd answered; the device's ApplicationReady is due or in flight.
    ApplicationReadyPending,
    /// ApplicationReady confirmed by the controller: data exchange.
    Data,
}

/// Which way an IOCR's frames go.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IocrType {
    /// Input CR (IOCRType 1): the device provides, the controller consumes.
    Input,
    /// Output CR (IOCRType 2): the controller provides, the device consumes.
    Output,
}

/// One IODataObject or IOCS entry of an IOCR.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IoObject {
    /// Slot.
    pub slot: u16,
    /// Subslot.
    pub subslot: u16,
    /// Byte offset of the data (or of the IOCS octet) in the C_SDU.
    pub frame_offset: u16,
    /// IO data bytes before the IOPS octet (0 for IOCS entries and for
    /// submodules without data in this direction).
    pub data_len: u16,
}

/// The parameters of one IOCR, as accepted (FrameID as assigned).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Iocr {
    /// Input or output.
    pub iocr_type: IocrType,
    /// IOCRReference (the controller's name for it).
    pub reference: u16,
    /// RTClass of IOCRProperties: 1 (legacy startup) or 2 (advanced startup;
    /// the frames are RT_CLASS_1 frames either way, only the FrameID range
    /// differs).
    pub rt_class: u8,
    /// FrameID of its frames (assigned by the device when the request left it
    /// to the device with 0xFFFF).
    pub frame_id: u16,
    /// Length of the C_SDU (IO data, IOPS and IOCS octets), 40…1440.
    pub data_length: u16,
    /// SendClockFactor (× 31.25 µs = send clock).
    pub send_clock_factor: u16,
    /// ReductionRatio (send clock × ratio = cycle).
    pub reduction_ratio: u16,
    /// Phase (1…ReductionRatio).
    pub phase: u16,
    /// Sequence (frame order within the phase; informative).
    pub sequence: u16,
    /// FrameSendOffset in ns (0xFFFF_FFFF = "as soon as possible").
    pub frame_send_offset: u32,
    /// WatchdogFactor (cycles without a frame before the consumer gives up).
    pub watchdog_factor: u16,
    /// DataHoldFactor (cycles the consumer holds the last data).
    pub data_hold_factor: u16,
    /// IOCRTagHeader: the 802.1Q TCI (priority 6, VLAN 0 for RT_CLASS_1).
    pub vlan_tci: u16,
    /// IOCRMulticastMACAdd (unused for unicast CRs).
    pub multicast_mac: MacAddr,
    /// The IODataObjects (data + IOPS of this CR's provider).
    pub data: Vec<IoObject, MAX_SUBMODULES>,
    /// The IOCS entries (the consumer states for the other direction).
    pub iocs: Vec<IoObject, MAX_SUBMODULES>,
}

impl Iocr {
    /// The cycle: SendClockFactor × ReductionRatio × 31.25 µs.
    pub fn cycle(&self) -> Nanos {
        Nanos::from_ns(u64::from(self.send_clock_factor) * u64::from(self.reduction_ratio) * 31_250)
    }

    /// The consumer's watchdog time (WatchdogFactor cycles).
    pub fn watchdog(&self) -> Nanos {
        Nanos::from_ns(
            self.cycle()
                .as_ns()
                .saturating_mul(u64::from(self.watchdog_factor)),
        )
    }

    /// The data hold time (DataHoldFactor cycles).
    pub fn data_hold(&self) -> Nanos {
        Nanos::from_ns(
            self.cycle()
                .as_ns()
                .saturating_mul(u64::from(self.data_hold_factor)),
        )
    }
}

/// The alarm CR (RTA over Ethernet, EtherType 0x8892).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AlarmCr {
    /// AlarmCRProperties (bit 0 priority: 1 = user priority, bit 1 transport: 0 = layer 2).
    pub properties: u32,
    /// RTATimeoutFactor (× 100 ms = retransmission timeout).
    pub rta_timeout_factor: u16,
    /// RTARetries (3…15).
    pub rta_retries: u16,
    /// The controller's LocalAlarmReference: the destination endpoint of our alarms.
    pub controller_ref: u16,
    /// Our alarm reference (the controller sends to it).
    pub device_ref: u16,
    /// MaxAlarmDataLength agreed (200…1432).
    pub max_alarm_data_length: u16,
    /// AlarmCRTagHeaderHigh (TCI of high-priority alarm frames).
    pub tag_header_high: u16,
    /// AlarmCRTagHeaderLow (TCI of low-priority alarm frames).
    pub tag_header_low: u16,
}

impl AlarmCr {
    /// The RTA retransmission timeout.
    pub fn timeout(&self) -> Nanos {
        Nanos::from_ms(u64::from(self.rta_timeout_factor) * 100)
    }
}

/// What an expected submodule carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SubmoduleData {
    /// No IO data (DAP, interface, ports): IOPS in the input CR only.
    NoIo,
    /// Input data of this many bytes (device → controller).
    Input(u16),
    /// Output data of this many bytes (controller → device).
    Output(u16),
    /// Both, input and output byte counts.
    InputOutput(u16, u16),
}

/// How an expected submodule compares with the real one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fit {
    /// As expected.
    Proper,
    /// Wrong module ident (the module is listed in the ModuleDiffBlock; its IO
    /// data is exchanged with IOPS "bad").
    WrongModule,
    /// No module at this slot.
    NoModule,
    /// Wrong submodule ident or data description.
    WrongSubmodule,
    /// No submodule at this subslot.
    NoSubmodule,
}

/// One expected submodule of the AR with its comparison result.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Submodule {
    /// API (always 0).
    pub api: u32,
    /// Slot.
    pub slot: u16,
    /// Subslot.
    pub subslot: u16,
    /// Expected module ident.
    pub module_ident: u32,
    /// Expected submodule ident.
    pub submodule_ident: u32,
    /// Its IO data as the controller configured it (P-028: the lengths the
    /// drive reports as "configured by the controller").
    pub data: SubmoduleData,
    /// The comparison with the real module.
    pub fit: Fit,
    /// The catalogue module plugged (data slots whose ident is in the catalogue).
    pub module: Option<DataModule>,
}

impl Submodule {
    /// The bytes of the drive's telegram this submodule carries and which way
    /// (None for DAP subslots and misfits).
    pub fn telegram(&self) -> Option<(Direction, usize)> {
        let m = self.module.filter(|_| self.fit == Fit::Proper)?;
        Some((m.direction, m.bytes()))
    }
}

/// An established AR.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Ar {
    /// AR UUID.
    pub ar_uuid: Uuid,
    /// ARType.
    pub ar_type: ArType,
    /// SessionKey (echoed in every control block).
    pub session_key: u16,
    /// CMInitiatorMacAdd: the controller's MAC (destination of our RT frames).
    pub controller_mac: MacAddr,
    /// CMInitiatorObjectUUID (object of our CControl call).
    pub controller_object: Uuid,
    /// The controller's RPC endpoint (its IP; port 34964 for CControl).
    pub controller_rpc: Endpoint,
    /// CMInitiatorStationName.
    pub controller_station: Vec<u8, MAX_STATION_NAME>,
    /// ARProperties as requested.
    pub properties: u32,
    /// CMInitiatorActivityTimeoutFactor (× 100 ms).
    pub activity_timeout_factor: u16,
    /// The input CR (IOCARSingle).
    pub input_cr: Option<Iocr>,
    /// The output CR (IOCARSingle).
    pub output_cr: Option<Iocr>,
    /// The alarm CR (IOCARSingle).
    pub alarm_cr: Option<AlarmCr>,
    /// The expected submodules, in request order, with their fit.
    pub submodules: Vec<Submodule, MAX_SUBMODULES>,
    /// Start-up state.
    pub state: ArState,
}

/// ARProperties bit 30, StartupMode: 0 legacy, 1 advanced.
pub const AR_PROPERTIES_STARTUP_MODE: u32 = 1 << 30;

impl Ar {
    /// The submodule at `slot`/`subslot`.
    pub fn submodule(&self, slot: u16, subslot: u16) -> Option<&Submodule> {
        self.submodules
            .iter()
            .find(|s| s.slot == slot && s.subslot == subslot)
    }

    /// True if the controller asked for advanced startup (ARProperties
    /// bit 30, StartupMode): its IOCRs are RTClass 2 and the Connect
    /// response carries an ARServerBlockRes.
    pub fn advanced_startup(&self) -> bool {
        self.properties & AR_PROPERTIES_STARTUP_MODE != 0
    }

    /// True if any expected submodule differs from the real one.
    pub fn has_diff(&self) -> bool {
        self.submodules.iter().any(|s| s.fit != Fit::Proper)
    }
}
