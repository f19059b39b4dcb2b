//! The fieldbus-neutral drive (SC6-class, two axes; or the SI6-class
//! single-axis device, [`Variant`]): what every fieldbus personality shares.
//! No fieldbus crate is a dependency.
//!
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

pub mod actions;
pub mod axis;
pub mod dictionary;
// the reference reads the notes, which bare-metal builds do not keep
#[cfg(not(target_os = "none"))]
pub mod doc;
pub mod faults;
pub mod objects;
pub mod params;
pub mod pdo_image;
pub mod pdo_maps;
pub mod scope;
pub mod stage;
pub mod tuning;
pub mod user_units;
pub mod variant;

pub use dictionary::{
    revision, scope_mappable, DriveObjects, ImageError, LiveValues, NoLive, Prepared, Requests, Slot,
    Template, WithLive, LOAD_SIGNATURE, PERSISTENT_IMAGE_BYTES, SAVE_SIGNATURE,
};
pub use pdo_maps::{module_ident, PdoLayout, AXIS_B_MODULE, IP_RX, IP_TX, USER_MODULE, VL_RX, VL_TX};
pub use variant::Variant;

/// STOBER's EtherCAT vendor ID (E-005).
pub const VENDOR_ID: u32 = 0xB9;
/// Product code = nominal power in 0.1 kW (E-005). The SC6A062's nominal power
/// is not in the seeds or the spec; assumed 1.5 kW (2 × 0.75 kW) until checked
/// against the SC6 manual.
pub const PRODUCT_CODE: u32 = 15;
/// Product code of the single-axis device (SI6A061, [`Variant::Single`]):
/// its nominal power is not in the seeds either; assumed 0.75 kW (one axis
/// of the SC6A062's assumed 2 × 0.75 kW), 7.5 rounded to 8 (docs/conformance.md,
/// decisions).
pub const PRODUCT_CODE_SINGLE: u32 = 8;
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
/// Device name of the single-axis device (1008h, E50; [`Variant::Single`]).
pub const DEVICE_NAME_SINGLE: &str = "SI6";
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

#[cfg(test)]
extern crate std;
#[cfg(test)]
mod tests_od;
#[cfg(test)]
mod tests_records_od;
#[cfg(test)]
mod tests_scaling;
#[cfg(test)]
mod tests_sdo;
#[cfg(test)]
mod tests_spec_walk;
#[cfg(test)]
mod tests_stage;
#[cfg(test)]
mod tests_variant;
