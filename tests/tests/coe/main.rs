//! The CoE SDO server and the drive's object dictionary through a real master:
//! every entry read and written over the mailbox (ethercrab moves the frames,
//! `CoeClient` builds them from the spec's byte layouts), the abort codes of
//! spec §6.5 for every kind of bad input, SDO Information (§7), segmented
//! transfers and complete access.
//!
//! Here: the access level, the abort codes and the dictionary helpers the modules share; the
//! tests, by spec area, in the modules.

use drive_ecat::objects::{enumeration, Object, Value, OBJECTS};
use drive_ecat::{revision, DriveObjects, Template};
use drive_tests::objects as device_objects;
use drive_tests::{init, line, variant, with_master, with_sdo, CoeClient, UploadKind, MAILBOX_LEN};
use ecat::{CommState, DataType, Dictionary, SdoAbort};
use hil_sim::sim::Simulation;
use std::cell::RefCell;

mod entries;
mod sdo_info;
mod transfers;

/// A10[2], the CoE access level of a fresh drive.
const LEVEL: u8 = 2;
/// Largest value a normal upload carries: mailbox data − CoE header − 8.
const NORMAL_MAX: usize = MAILBOX_LEN - 6 - 2 - 8;

const NO_OBJECT: u32 = SdoAbort::NO_OBJECT.0;
const NO_SUBINDEX: u32 = SdoAbort::NO_SUBINDEX.0;
const WRITE_ONLY: u32 = SdoAbort::WRITE_ONLY.0;
const READ_ONLY: u32 = SdoAbort::READ_ONLY.0;
const DEVICE_STATE: u32 = SdoAbort::DEVICE_STATE.0;
const LENGTH_TOO_LOW: u32 = SdoAbort::LENGTH_TOO_LOW.0;
const LENGTH_TOO_HIGH: u32 = SdoAbort::LENGTH_TOO_HIGH.0;
const VALUE_TOO_LOW: u32 = SdoAbort::VALUE_TOO_LOW.0;
const VALUE_TOO_HIGH: u32 = SdoAbort::VALUE_TOO_HIGH.0;
const INVALID_VALUE: u32 = SdoAbort::INVALID_VALUE.0;
const PDO_LENGTH: u32 = SdoAbort::PDO_LENGTH.0;
const TRANSFER: u32 = SdoAbort::TRANSFER.0;
const TOGGLE_BIT: u32 = SdoAbort::TOGGLE_BIT.0;
const UNSUPPORTED_ACCESS: u32 = SdoAbort::UNSUPPORTED_ACCESS.0;
const PARAMETER_INCOMPATIBLE: u32 = SdoAbort::PARAMETER_INCOMPATIBLE.0;

/// Access bits of [`od::Access`] by state: 0 PreOp, 1 SafeOp, 2 Op.
const PREOP: u8 = 0;
const SAFEOP: u8 = 1;

fn visible(o: &Object) -> bool {
    o.level <= LEVEL
}

/// PDO mapping and assignment objects and their A225… mirrors: their entries
/// follow the CiA 301 sequence (sub 0 = 0 first), tested in `pdo.rs` and below.
fn pdo_object(index: u16) -> bool {
    matches!(
        index,
        0x1600..=0x1603 | 0x1A00..=0x1A03 | 0x1C12 | 0x1C13 | 0x20E1..=0x20EC | 0x20FC | 0x20FD
    )
}

/// Mapping objects (and their mirrors), whose sub 0 is checked against the
/// PDO length first (0604 0042h).
fn mapping_object(index: u16) -> bool {
    matches!(index, 0x1600..=0x1603 | 0x1A00..=0x1A03 | 0x20E1..=0x20EC)
}

fn encode(t: DataType, v: i64) -> Vec<u8> {
    v.to_le_bytes()[..t.bytes()].to_vec()
}

fn objects(sim: &RefCell<Simulation>) -> DriveObjects {
    sim.borrow().drives()[0].drive.objects().clone()
}

/// What a bus write may change and the runtime does not: every integer entry
/// of the RAM image outside the live objects, the persistent image (strings
/// included), the template and the pending requests.
fn settled(sim: &RefCell<Simulation>) -> (Vec<i64>, Vec<u8>, Template, drive_ecat::Requests) {
    let o = objects(sim);
    let values = device_objects()
        .filter(|obj| obj.value == Value::Ram)
        .flat_map(|obj| obj.info.entries.iter().map(move |e| (obj.info.index, e)))
        .filter(|(_, e)| e.data_type.is_integer())
        .map(|(i, e)| o.get(i, e.sub).unwrap())
        .collect();
    let mut image = vec![0u8; drive_ecat::PERSISTENT_IMAGE_BYTES];
    o.persistent_image(&mut image).unwrap();
    (values, image, o.template(), o.requests())
}

/// The value the drive's dictionary holds for `index`:`sub`, read locally.
fn local_read(sim: &RefCell<Simulation>, index: u16, sub: u8) -> Vec<u8> {
    // the longest entry: A280's 255 bytes
    let mut buf = [0u8; 512];
    let n = sim.borrow_mut().drives_mut()[0]
        .drive
        .read_object(index, sub, &mut buf, CommState::PreOp)
        .unwrap();
    buf[..n].to_vec()
}
