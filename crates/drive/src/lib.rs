//! The drive on EtherCAT (SC6A062, double axis): the fieldbus-neutral core
//! ([`drive_core`], re-exported whole) behind the EtherCAT slave stack.
//!
//! - [`DEVICE`]: the device description (identity, SyncManagers, FMMUs, PDO
//!   maps, DC op modes), the one source the SII image, the stack's checks
//!   and the ESI XML derive from.
//! - [`runtime`]: [`runtime::Drive`], the core's axes and dictionary behind an
//!   [`ecat::Slave`]: process data, ESM hooks, DC-Sync PLL, save, FoE, EoE,
//!   diagnosis.
//! - [`ecat_app`]: the drive as the slave stack's [`ecat::Application`]
//!   (A150, A258, DC checks, event 52); [`emcy`]: its emergencies.
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

pub use drive_core::*;

use drive_core::pdo_maps::{RX_A, RX_B, TX_A, TX_B};
use ecat::desc::coe_details;
use ecat::{DcOpMode, Device, FmmuUsage, Identity, MailboxSm, Pdo, PdoEntry, ProcessSm};
use esc::sii::mailbox_protocol;

pub mod ecat_app;
pub mod emcy;
pub mod runtime;

/// The firmware slots crate (A/B images, boot decision), re-exported for the
/// firmware, the simulator and the tests.
pub use boot;

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
mod tests_axis;
