//! The drive on EtherCAT (SC6A062, double axis; or SI6A061, single axis):
//! the fieldbus-neutral core ([`drive_core`], re-exported whole) behind the
//! EtherCAT slave stack.
//!
//! - [`DEVICE`]: the device description (identity, SyncManagers, FMMUs, PDO
//!   maps, DC op modes), the one source the SII image, the stack's checks
//!   and the ESI XML derive from; [`DEVICE_SINGLE`] the single-axis
//!   device's ([`device`] of a [`Variant`]).
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

const RX_PDO_A: Pdo = Pdo {
    index: 0x1600,
    name: "RxPDO axis A",
    entries: &RX_A_ENTRIES,
};

const TX_PDO_A: Pdo = Pdo {
    index: 0x1A00,
    name: "TxPDO axis A",
    entries: &TX_A_ENTRIES,
};

static RX_PDOS: [Pdo; 2] = [
    RX_PDO_A,
    Pdo {
        index: 0x1601,
        name: "RxPDO axis B",
        entries: &RX_B_ENTRIES,
    },
];

static TX_PDOS: [Pdo; 2] = [
    TX_PDO_A,
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

/// The single-axis device's PDOs: axis A's only.
static RX_PDOS_SINGLE: [Pdo; 1] = [RX_PDO_A];
static TX_PDOS_SINGLE: [Pdo; 1] = [TX_PDO_A];

/// The drive as seen on the bus (SC6A062, double axis).
pub static DEVICE: Device = DOUBLE;

/// The single-axis device as seen on the bus (SI6A061,
/// [`Variant::Single`]): the double-axis description with its own identity
/// (product code [`PRODUCT_CODE_SINGLE`], name, order code) and axis A's
/// PDOs only (no 1601h/1A01h: channel 2 is a free channel there, empty).
pub static DEVICE_SINGLE: Device = Device {
    identity: Identity {
        product_code: Variant::Single.product_code(),
        ..DOUBLE.identity
    },
    name: Variant::Single.device_name(),
    order_code: "SI6A061",
    rx_pdos: &RX_PDOS_SINGLE,
    tx_pdos: &TX_PDOS_SINGLE,
    ..DOUBLE
};

/// The description of `variant`: [`DEVICE`] or [`DEVICE_SINGLE`].
pub fn device(variant: Variant) -> &'static Device {
    match variant {
        Variant::Double => &DEVICE,
        Variant::Single => &DEVICE_SINGLE,
    }
}

const DOUBLE: Device = Device {
    identity: Identity {
        vendor_id: VENDOR_ID,
        product_code: Variant::Double.product_code(),
        revision: SOFTWARE_BUILD,
        serial: SERIAL,
    },
    device_type: DEVICE_TYPE,
    name: Variant::Double.device_name(),
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
#[cfg(test)]
mod tests_single;
