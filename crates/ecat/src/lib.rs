//! EtherCAT slave stack, sans-IO.
//!
//! - [`desc`]: the device description a product declares once (`static`): identity,
//!   SyncManagers, FMMUs, PDO maps, DC op modes.
//! - [`sii`]: the SII EEPROM image generated from it, and a checked category reader.
//! - [`esm`]: the EtherCAT state machine rules and SyncManager checks (spec §3–4).
//! - [`led`]: the RUN/ERR/link indicators (ETG.1300) as pure functions of state and time.
//! - [`mailbox`]: the mailbox header and error replies; [`coe`]: the CoE server
//!   ([`CoeServer`]: SDO expedited/normal/segmented transfers, complete access,
//!   abort, timeout) over [`od::Dictionary`]; [`sdo_info`]: the SDO Information
//!   service; [`foe`]: the FoE server ([`FoeServer`]: file download in Bootstrap
//!   for the firmware update, packet numbers, busy, errors, timeout) over the
//!   application's [`FoeHandler`]; [`eoe`]: Ethernet over EtherCAT ([`eoe::EoeServer`]:
//!   fragment reassembly and fragmentation, set IP parameter, EMCY FFF0h) towards the
//!   application's [`eoe::EthernetPort`].
//! - [`app`]: what the stack asks of the application beyond its dictionary
//!   ([`Application`]: its cycle, the RxPDO monitoring, the check of a DC
//!   configuration); the stack knows no manufacturer object.
//! - [`Slave`]: all of it composed; the application calls
//!   [`Slave::poll`]`(pdi, app, now)`
//!   (or [`Slave::poll_with_eoe`] with the FoE handler and the Ethernet port) with the ESC behind an [`esc::Pdi`].
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

pub mod app;
pub mod coe;
pub mod desc;
pub mod diag;
pub mod emcy;
pub mod eoe;
pub mod eoe_queue;
pub mod esm;
pub mod foe;
pub mod led;
pub mod mailbox;
pub mod sdo_info;
pub mod sii;
mod slave;

pub use app::{Application, DcRequest, PdoTimeout};
pub use coe::{CoeConfig, CoeServer, CommState, Dictionary, SdoAbort};
pub use desc::{DataType, DcOpMode, Device, FmmuUsage, Identity, MailboxSm, Pdo, PdoEntry, ProcessSm};
pub use foe::{FoeError, FoeHandler, FoeServer};
pub use sii::{build_sii, SiiError};
pub use slave::{Slave, StateChange};

#[cfg(test)]
mod tests;
