//! The drive product: the SC6-class double-axis drive as seen on the bus.
//!
//! - [`DEVICE`]: the device description (identity, SyncManagers, FMMUs, PDO maps,
//!   DC op modes), the one source the SII image, the stack's checks and later
//!   the ESI XML and object dictionary derive from.
//! - [`objects`]: the object dictionary, declared once (communication area,
//!   manufacturer parameters, CiA 402 objects of both axes) with its RAM image
//!   layout, computed at compile time.
//! - [`DriveObjects`]: the values and the CoE access rules; implements
//!   [`od::Dictionary`] for the CoE server. Live values come from the runtime
//!   ([`DriveObjects::set`], [`LiveValues`]); saving and restoring go through
//!   [`DriveObjects::persistent_image`], [`DriveObjects::load_persistent`] and
//!   [`Requests`].
//! - [`doc`]: the object-dictionary reference (`docs/object-dictionary.md`)
//!   generated from the declaration.
#![no_std]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]
#![deny(missing_docs)]

use ecat::desc::coe_details;
use ecat::{DataType, DcOpMode, Device, FmmuUsage, Identity, MailboxSm, Pdo, PdoEntry, ProcessSm};

pub mod axis;
pub mod dictionary;
pub mod doc;
pub mod ecat_app;
pub mod emcy;
pub mod objects;
pub mod params;
pub mod pdo_image;
pub mod runtime;

pub use dictionary::{
    revision, DriveObjects, ImageError, LiveValues, NoLive, Requests, Slot, Template, WithLive,
    LOAD_SIGNATURE, PERSISTENT_IMAGE_BYTES, SAVE_SIGNATURE,
};
use esc::sii::mailbox_protocol;

/// The firmware slots crate (A/B images, boot decision), re-exported for the
/// firmware, the simulator and the tests.
pub use boot;

/// STOBER's EtherCAT vendor ID (E-005).
pub const VENDOR_ID: u32 = 0xB9;
/// Product code = nominal power in 0.1 kW (E-005). The SC6A062's nominal power
/// is not in the seeds or the spec; assumed 1.5 kW (2 × 0.75 kW) until checked
/// against the SC6 manual.
pub const PRODUCT_CODE: u32 = 15;
/// Revision number 1018h:03 with the default template "EtherCAT Rx SDO
/// Info", also in the SII (E-005, E-008): software build number << 1 | 1
/// (bit 0 = template, see [`revision`]); build 0 for now.
pub const SOFTWARE_BUILD: u32 = 1;
/// Hardware version 1009h (E52\[1\]).
pub const HARDWARE_VERSION: &str = "HW 1";
/// Software version 100Ah (E52\[3\]).
pub const SOFTWARE_VERSION: &str = env!("CARGO_PKG_VERSION");
/// Serial number placeholder; the real value is E52\[2\], from the device's
/// production data (E-005).
pub const SERIAL: u32 = 0;
/// Device type 1000h: profile 402, servo drive (E-004).
pub const DEVICE_TYPE: u32 = 0x0002_0192;
/// Device name (1008h, E50).
pub const DEVICE_NAME: &str = "SC6";
/// Entries per PDO mapping object (spec §5.1).
pub const MAPPING_ENTRIES: u8 = 24;
/// Offset of axis B's CiA 402 objects (E-015).
pub const AXIS_B_CIA402: u16 = 0x0800;
/// Offset of axis B's manufacturer objects (E-010).
pub const AXIS_B_MANUFACTURER: u16 = 0x8000;

/// CoE index of manufacturer parameter `group` (A = 0 … Z = 25), `line`, axis A
/// window (spec §2.6, E-009).
pub const fn parameter_index(group: u16, line: u16) -> u16 {
    0x2000 + group * 0x200 + line
}

/// Axis-A RxPDO entries (spec §5.4, 23 bytes): the default of 1600h.
pub(crate) const RX_A: [PdoEntry; 8] = [
    PdoEntry::new(0x6040, 0, DataType::U16, "Controlword"),
    PdoEntry::new(0x6060, 0, DataType::I8, "Modes of operation"),
    PdoEntry::new(0x607A, 0, DataType::I32, "Target position"),
    PdoEntry::new(0x60FF, 0, DataType::I32, "Target velocity"),
    PdoEntry::new(0x60B1, 0, DataType::I32, "Velocity offset"),
    PdoEntry::new(0x60B2, 0, DataType::I16, "Torque offset"),
    PdoEntry::new(0x6071, 0, DataType::I16, "Target torque"),
    PdoEntry::new(0x60FE, 1, DataType::U32, "Digital outputs"),
];

/// Axis-A TxPDO entries (spec §5.4, 29 bytes): the default of 1A00h.
pub(crate) const TX_A: [PdoEntry; 10] = [
    PdoEntry::new(0x6041, 0, DataType::U16, "Statusword"),
    PdoEntry::new(0x6061, 0, DataType::I8, "Modes of operation display"),
    PdoEntry::new(0x6064, 0, DataType::I32, "Position actual value"),
    PdoEntry::new(0x606C, 0, DataType::I32, "Velocity actual value"),
    PdoEntry::new(0x6077, 0, DataType::I16, "Torque actual value"),
    PdoEntry::new(0x60F4, 0, DataType::I32, "Following error actual value"),
    PdoEntry::new(0x60FD, 0, DataType::U32, "Digital inputs"),
    PdoEntry::new(0x60E4, 1, DataType::I32, "Additional position actual value"),
    PdoEntry::new(parameter_index(4, 201), 0, DataType::U16, "E201 Status word 2"),
    PdoEntry::new(
        parameter_index(0, 67),
        0,
        DataType::U16,
        "A67 Status word user-defined",
    ),
];

/// The mode-specific maps of cia402.md §6.5.1 and §6.5.6: ip and vl cannot use
/// the standard maps. A master (startup list) or the commissioning side writes
/// them into 1600h/1A00h in Pre-Op ([`DriveObjects::apply_map`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PdoLayout {
    /// RxPDO 23 bytes, TxPDO 29 bytes (spec §5.4).
    Standard,
    /// Interpolated position (ip, 7): 6040h, 6060h, 60C1h:01 / 6041h, 6061h, 6064h; 7 bytes each.
    Ip,
    /// Velocity mode (vl, 2): 6040h, 6060h, 6042h / 6041h, 6061h, 6044h; 5 bytes each.
    Vl,
}

/// ip RxPDO (7 bytes).
pub const IP_RX: [PdoEntry; 3] = [
    PdoEntry::new(0x6040, 0, DataType::U16, "Controlword"),
    PdoEntry::new(0x6060, 0, DataType::I8, "Modes of operation"),
    PdoEntry::new(0x60C1, 1, DataType::I32, "Interpolation data record 1"),
];
/// ip TxPDO (7 bytes).
pub const IP_TX: [PdoEntry; 3] = [
    PdoEntry::new(0x6041, 0, DataType::U16, "Statusword"),
    PdoEntry::new(0x6061, 0, DataType::I8, "Modes of operation display"),
    PdoEntry::new(0x6064, 0, DataType::I32, "Position actual value"),
];
/// vl RxPDO (5 bytes).
pub const VL_RX: [PdoEntry; 3] = [
    PdoEntry::new(0x6040, 0, DataType::U16, "Controlword"),
    PdoEntry::new(0x6060, 0, DataType::I8, "Modes of operation"),
    PdoEntry::new(0x6042, 0, DataType::I16, "vl target velocity"),
];
/// vl TxPDO (5 bytes).
pub const VL_TX: [PdoEntry; 3] = [
    PdoEntry::new(0x6041, 0, DataType::U16, "Statusword"),
    PdoEntry::new(0x6061, 0, DataType::I8, "Modes of operation display"),
    PdoEntry::new(0x6044, 0, DataType::I16, "vl velocity actual value"),
];

impl PdoLayout {
    /// The RxPDO and TxPDO entries of axis A.
    pub const fn entries(self) -> (&'static [PdoEntry], &'static [PdoEntry]) {
        match self {
            PdoLayout::Standard => (&RX_A, &TX_A),
            PdoLayout::Ip => (&IP_RX, &IP_TX),
            PdoLayout::Vl => (&VL_RX, &VL_TX),
        }
    }
}

/// The same entries for axis B: CiA 402 objects +800h, manufacturer +8000h.
const fn axis_b<const N: usize>(a: [PdoEntry; N]) -> [PdoEntry; N] {
    let mut b = a;
    let mut i = 0;
    while i < N {
        // N is the array's length: compile-time evaluation, no run-time index.
        #[allow(clippy::indexing_slicing)]
        let e = &mut b[i];
        e.index += if e.index >= 0x6000 {
            AXIS_B_CIA402
        } else {
            AXIS_B_MANUFACTURER
        };
        i += 1;
    }
    b
}

/// Axis-B RxPDO entries: the default of 1601h.
pub(crate) const RX_B: [PdoEntry; 8] = axis_b(RX_A);
/// Axis-B TxPDO entries: the default of 1A01h.
pub(crate) const TX_B: [PdoEntry; 10] = axis_b(TX_A);

static RX_A_ENTRIES: [PdoEntry; 8] = RX_A;
static RX_B_ENTRIES: [PdoEntry; 8] = RX_B;
static TX_A_ENTRIES: [PdoEntry; 10] = TX_A;
static TX_B_ENTRIES: [PdoEntry; 10] = TX_B;

static RX_PDOS: [Pdo; 2] = [
    Pdo {
        index: 0x1600,
        name: "RxPDO axis A",
        entries: &RX_A_ENTRIES,
    },
    Pdo {
        index: 0x1601,
        name: "RxPDO axis B",
        entries: &RX_B_ENTRIES,
    },
];

static TX_PDOS: [Pdo; 2] = [
    Pdo {
        index: 0x1A00,
        name: "TxPDO axis A",
        entries: &TX_A_ENTRIES,
    },
    Pdo {
        index: 0x1A01,
        name: "TxPDO axis B",
        entries: &TX_B_ENTRIES,
    },
];

static DC_MODES: [DcOpMode; 3] = [
    // first = the default the master's configuration tool offers (E-108)
    DcOpMode {
        name: "DC",
        description: "DC enabled (SYNC0)",
        assign_activate: 0x0300,
        cycle_time_ns: 0,
        shift_ns: 0,
        sync0_cycle_factor: 1,
    },
    DcOpMode {
        name: "FreeRun",
        description: "Free run",
        assign_activate: 0,
        cycle_time_ns: 0,
        shift_ns: 0,
        sync0_cycle_factor: 0,
    },
    DcOpMode {
        name: "SM-Synchron",
        description: "SM-synchronous",
        assign_activate: 0,
        cycle_time_ns: 0,
        shift_ns: 0,
        sync0_cycle_factor: 0,
    },
];

/// The drive as seen on the bus (SC6A062, double axis).
pub static DEVICE: Device = Device {
    identity: Identity {
        vendor_id: VENDOR_ID,
        product_code: PRODUCT_CODE,
        revision: SOFTWARE_BUILD,
        serial: SERIAL,
    },
    device_type: DEVICE_TYPE,
    name: DEVICE_NAME,
    order_code: "SC6A062",
    group: "Drives",
    mailbox_out: MailboxSm {
        start: 0x1000,
        length: 256,
        control: 0x26,
    },
    mailbox_in: MailboxSm {
        start: 0x1100,
        length: 256,
        control: 0x22,
    },
    outputs: ProcessSm {
        start: 0x1200,
        control: 0x64,
    },
    inputs: ProcessSm {
        start: 0x1A00,
        control: 0x20,
    },
    // ethercrab needs an outputs and an inputs FMMU
    fmmus: &[
        FmmuUsage::Outputs,
        FmmuUsage::Inputs,
        FmmuUsage::MailboxStatus,
        FmmuUsage::Unused,
    ],
    // FoE: the firmware download in Bootstrap (issue 8, `runtime::Drive` with
    // `boot::BootSlots`)
    mailbox_protocols: mailbox_protocol::COE | mailbox_protocol::EOE | mailbox_protocol::FOE,
    coe_details: coe_details::SDO
        | coe_details::SDO_INFO
        | coe_details::PDO_ASSIGN
        | coe_details::PDO_CONFIG
        | coe_details::SDO_COMPLETE_ACCESS,
    ports: 2,
    process_ram_end: 0x3000,
    dc_modes: &DC_MODES,
    rx_pdos: &RX_PDOS,
    tx_pdos: &TX_PDOS,
    rx_assign: &[0x1600],
    tx_assign: &[0x1A00],
};

#[cfg(test)]
extern crate std;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_od;
