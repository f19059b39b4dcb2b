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
use ecat::{DcOpMode, Device, FmmuUsage, Identity, MailboxSm, Pdo, PdoEntry, ProcessSm};
use pdo_maps::{RX_A, RX_B, TX_A, TX_B};

pub mod axis;
pub mod dictionary;
pub mod doc;
pub mod ecat_app;
pub mod emcy;
pub mod faults;
pub mod objects;
pub mod params;
pub mod pdo_image;
pub mod pdo_maps;
pub mod runtime;

pub use dictionary::{
    revision, DriveObjects, ImageError, LiveValues, NoLive, Requests, Slot, Template, WithLive,
    LOAD_SIGNATURE, PERSISTENT_IMAGE_BYTES, SAVE_SIGNATURE,
};
use esc::sii::mailbox_protocol;
pub use pdo_maps::{PdoLayout, IP_RX, IP_TX, VL_RX, VL_TX};

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
