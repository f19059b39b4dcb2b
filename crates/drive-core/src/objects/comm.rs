//! Communication area 1000h–1FFFh (ETG.1000.6, ETG.1020) and the modular
//! device objects F0xxh (ETG.5000.1), as listed in `od-ethercat.md` parts 1–3.

use super::shorthand::e;
use super::{count_entry, repeat, Object, Value};
use crate::pdo_maps::{RX_A, RX_B, TX_A, TX_B};
use crate::{DEVICE_NAME, DEVICE_TYPE, HARDWARE_VERSION, MAPPING_ENTRIES, SERIAL, SOFTWARE_BUILD};
use crate::{PRODUCT_CODE, SOFTWARE_VERSION, VENDOR_ID};
use od::DataType::{Bool, OctetString, VisibleString, U16, U32, U8};
use od::PdoEntry;
use od::{Access, EntryInfo, ObjectCode::*};

const RO: Access = Access::RO;
const RW: Access = Access::RW;
const RW_PREOP: Access = Access::RW_PREOP;

/// Entries of a diagnosis message (10F3h:06…): ETG.1020 header (diag code
/// UINT32, flags UINT16, text ID UINT16, time stamp UINT64) + up to 12 bytes
/// of parameters (the size is not specified; assumption).
pub const DIAG_MESSAGE_BYTES: u16 = 28;
/// Diagnosis messages kept in 10F3h (spec §16).
pub const DIAG_MESSAGES: u8 = 20;

/// Names of mapping entries 1…24.
pub const APP_OBJECT: [&str; 24] =
    numbered!("Application object "; 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24);
const PDO_ASSIGN: [&str; 4] = numbered!("Assigned PDO "; 1 2 3 4);
const DIAG_MESSAGE: [&str; 20] =
    numbered!("Diagnosis message "; 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20);

/// Sub 0 + 24 entries of a PDO mapping object with `pdo` as default mapping.
const fn mapping(sub0: &'static str, pdo: &[PdoEntry], access: Access, saved: bool) -> [EntryInfo; 25] {
    let mut out = [e(0, sub0, U8, access); 25];
    out[0] = out[0]
        .range(0, MAPPING_ENTRIES as i64)
        .default_value(pdo.len() as i64);
    let entries = repeat(e(1, "", U32, access), 1, &APP_OBJECT);
    let mut i = 0;
    while i < 24 {
        // i < 24 (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            out[i + 1] = entries[i];
            if i < pdo.len() {
                out[i + 1] = out[i + 1].default_value(pdo[i].mapping_value() as i64);
            }
        }
        i += 1;
    }
    if saved {
        let mut k = 0;
        while k < 25 {
            #[allow(clippy::indexing_slicing)]
            {
                out[k] = out[k].saved();
            }
            k += 1;
        }
    }
    out
}

const RX_SUB0: &str = "Number of mapped application objects in RxPDO";
const TX_SUB0: &str = "Number of mapped application objects in TxPDO";
pub(crate) const MAP_1600: [EntryInfo; 25] = mapping(RX_SUB0, &RX_A, RW_PREOP, true);
pub(crate) const MAP_1601: [EntryInfo; 25] = mapping(RX_SUB0, &RX_B, RW_PREOP, true);
pub(crate) const MAP_1602: [EntryInfo; 25] = mapping(RX_SUB0, &[], RW_PREOP, true);
pub(crate) const MAP_1A00: [EntryInfo; 25] = mapping(TX_SUB0, &TX_A, RW_PREOP, true);
pub(crate) const MAP_1A01: [EntryInfo; 25] = mapping(TX_SUB0, &TX_B, RW_PREOP, true);
pub(crate) const MAP_1A02: [EntryInfo; 25] = mapping(TX_SUB0, &[], RW_PREOP, true);
/// Channel 4 is reserved for FSoE and configured by the firmware (E-052):
/// read-only on the bus, empty until the safety module sets it.
pub(crate) const MAP_1603: [EntryInfo; 25] = mapping(RX_SUB0, &[], RO, false);
pub(crate) const MAP_1A03: [EntryInfo; 25] = mapping(TX_SUB0, &[], RO, false);

/// Sub 0 + 4 entries of a PDO assignment object (sub 0 = number of assigned
/// PDOs, see docs/conformance.md "Decisions").
const fn assign(first: u16) -> [EntryInfo; 5] {
    let mut out = [e(0, "Number of assigned PDOs", U8, RW_PREOP)
        .range(0, 4)
        .default_value(1)
        .saved(); 5];
    let entries = repeat(e(1, "", U16, RW_PREOP).saved(), 1, &PDO_ASSIGN);
    let mut i = 0;
    while i < 4 {
        // i < 4 (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            out[i + 1] = entries[i];
        }
        i += 1;
    }
    out[1] = out[1].default_value(first as i64);
    out
}
pub(crate) const ASSIGN_1C12: [EntryInfo; 5] = assign(0x1600);
pub(crate) const ASSIGN_1C13: [EntryInfo; 5] = assign(0x1A00);

/// SyncManager parameter 1C32h/1C33h (ETG.1020; subs as S Tab. 12, mirrored
/// in A264/A265). `sync_max`: highest synchronisation type accepted.
const fn sm_parameter(sync_max: i64) -> [EntryInfo; 11] {
    [
        count_entry(0x20),
        e(0x01, "Synchronization type", U16, RW_PREOP).range(0, sync_max),
        e(0x02, "Cycle time", U32, RW_PREOP)
            .default_value(1_000_000)
            .unit("ns"),
        e(0x03, "Shift time", U32, RO).unit("ns"),
        // bit 0 free run, bit 1 SM-synchronous, bits 2–4 = 001b DC SYNC0
        e(0x04, "Synchronization types supported", U16, RO).default_value(0x0007),
        e(0x05, "Minimum cycle time", U32, RO)
            .default_value(250_000)
            .unit("ns"),
        e(0x06, "Calc and copy time", U32, RO).unit("ns"),
        e(0x09, "Delay time", U32, RO).unit("ns"),
        e(0x0B, "SM-event missed counter", U16, RO),
        e(0x0C, "Cycle time too small counter", U16, RO),
        e(0x20, "Sync error", Bool, RO),
    ]
}
pub(crate) const SM_OUTPUT: [EntryInfo; 11] = sm_parameter(3);
// inputs may also follow the SM2 event (22h, ETG.1020)
pub(crate) const SM_INPUT: [EntryInfo; 11] = sm_parameter(0x22);

/// Diagnosis history 10F3h (ETG.1020, spec §16): sub 0 = 5 + 20 messages.
const fn diagnosis() -> [EntryInfo; 26] {
    let mut out = [count_entry(5 + DIAG_MESSAGES as usize); 26];
    out[1] = e(1, "Maximum messages", U8, RO).default_value(DIAG_MESSAGES as i64);
    out[2] = e(2, "Newest message", U8, RO);
    out[3] = e(3, "Newest acknowledged message", U8, RW);
    out[4] = e(4, "New messages available", Bool, RO).tx();
    out[5] = e(5, "Flags", U16, RW);
    let msgs = repeat(e(6, "", OctetString(DIAG_MESSAGE_BYTES), RO), 6, &DIAG_MESSAGE);
    let mut i = 0;
    while i < 20 {
        // i < 20 (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            out[6 + i] = msgs[i];
        }
        i += 1;
    }
    out
}
const DIAGNOSIS: [EntryInfo; 26] = diagnosis();

const fn string(s: &str) -> od::DataType {
    VisibleString(s.len() as u16)
}

/// The communication objects, sorted by index.
pub const COMM: [Object; 22] = [
    Object::var(
        0x1000,
        Value::Const,
        entries![e(0, "Device type", U32, RO).default_value(DEVICE_TYPE as i64)],
    )
    .note("E-004: profile 402, servo drive"),
    Object::var(0x1001, Value::Live, entries![e(0, "Error register", U8, RO)])
        .note("E-007: live, from the EMCY/diagnosis module"),
    Object::var(
        0x1008,
        Value::Text(&DEVICE_NAME),
        entries![e(0, "Manufacturer device name", string(DEVICE_NAME), RO)],
    )
    .note("E50"),
    Object::var(
        0x1009,
        Value::Text(&HARDWARE_VERSION),
        entries![e(
            0,
            "Manufacturer hardware version",
            string(HARDWARE_VERSION),
            RO
        )],
    )
    .note("E52[1]"),
    Object::var(
        0x100A,
        Value::Text(&SOFTWARE_VERSION),
        entries![e(
            0,
            "Manufacturer software version",
            string(SOFTWARE_VERSION),
            RO
        )],
    )
    .note("E52[3]"),
    Object::new(
        0x1010,
        "Store parameters",
        Array,
        entries![
            count_entry(1),
            // reads 1: the device saves on command (CiA 301)
            e(1, "Save all parameters", U32, RW).default_value(1),
        ],
        Value::Command,
    )
    .note("write 65766173h (\"save\") to request saving; other values 0800 0020h"),
    Object::new(
        0x1011,
        "Restore default parameters",
        Array,
        entries![
            count_entry(1),
            e(1, "Restore all default parameters", U32, RW_PREOP).default_value(1),
        ],
        Value::Command,
    )
    .note("write 64616F6Ch (\"load\") in PreOp: defaults in RAM at once; other values 0800 0020h"),
    Object::new(
        0x1018,
        "Identity object",
        Record,
        entries![
            count_entry(4),
            e(1, "Vendor ID", U32, RO).default_value(VENDOR_ID as i64),
            e(2, "Product code", U32, RO)
                .default_value(PRODUCT_CODE as i64)
                .unit("0.1 kW"),
            e(3, "Revision number", U32, RO).default_value(SOFTWARE_BUILD as i64),
            e(4, "Serial number", U32, RO).default_value(SERIAL as i64),
        ],
        Value::Identity,
    )
    .note("E-005; :03 = build << 1 | template (1 = SDO Info), E-008; :04 = E52[2]"),
    Object::new(0x10F3, "Diagnosis history", Record, &DIAGNOSIS, Value::Live)
        .note("live, from the diagnosis module; :04 = A250"),
    Object::new(
        0x1600,
        "1st RxPDO mapping parameter",
        Record,
        &MAP_1600,
        Value::Ram,
    )
    .note("channel 1, axis A; A225"),
    Object::new(
        0x1601,
        "2nd RxPDO mapping parameter",
        Record,
        &MAP_1601,
        Value::Ram,
    )
    .note("channel 2, axis B; A226"),
    Object::new(
        0x1602,
        "3rd RxPDO mapping parameter",
        Record,
        &MAP_1602,
        Value::Ram,
    )
    .note("channel 3, free; A227"),
    Object::new(
        0x1603,
        "4th RxPDO mapping parameter",
        Record,
        &MAP_1603,
        Value::Ram,
    )
    .note("channel 4, FSoE, set by the firmware; A228"),
    Object::new(
        0x1A00,
        "1st TxPDO mapping parameter",
        Record,
        &MAP_1A00,
        Value::Ram,
    )
    .note("channel 1, axis A; A233"),
    Object::new(
        0x1A01,
        "2nd TxPDO mapping parameter",
        Record,
        &MAP_1A01,
        Value::Ram,
    )
    .note("channel 2, axis B; A234"),
    Object::new(
        0x1A02,
        "3rd TxPDO mapping parameter",
        Record,
        &MAP_1A02,
        Value::Ram,
    )
    .note("channel 3, free; A235"),
    Object::new(
        0x1A03,
        "4th TxPDO mapping parameter",
        Record,
        &MAP_1A03,
        Value::Ram,
    )
    .note("channel 4, FSoE, set by the firmware; A236"),
    Object::new(
        0x1C00,
        "Sync manager communication type",
        Array,
        entries![
            count_entry(4),
            e(1, "Communication type SM0", U8, RO).default_value(1),
            e(2, "Communication type SM1", U8, RO).default_value(2),
            e(3, "Communication type SM2", U8, RO).default_value(3),
            e(4, "Communication type SM3", U8, RO).default_value(4),
        ],
        Value::Const,
    )
    .note("E-055"),
    Object::new(
        0x1C12,
        "Sync manager 2 PDO assignment",
        Array,
        &ASSIGN_1C12,
        Value::Ram,
    )
    .note("RxPDOs 1600h–1603h; A252"),
    Object::new(
        0x1C13,
        "Sync manager 3 PDO assignment",
        Array,
        &ASSIGN_1C13,
        Value::Ram,
    )
    .note("TxPDOs 1A00h–1A03h; A253"),
    Object::new(
        0x1C32,
        "Output SyncManager parameter",
        Record,
        &SM_OUTPUT,
        Value::Live,
    )
    .note("A264; counters and times live, from the sync module"),
    Object::new(
        0x1C33,
        "Input SyncManager parameter",
        Record,
        &SM_INPUT,
        Value::Live,
    )
    .note("A265; counters and times live, from the sync module"),
];

/// F050h's defaults: the modules of the standard PDO layout on axes A and B
/// (E-148).
const STANDARD_MODULE_A: i64 = crate::module_ident(crate::PdoLayout::Standard, 0) as i64;
const STANDARD_MODULE_B: i64 = crate::module_ident(crate::PdoLayout::Standard, 1) as i64;

/// The modular-device objects (ETG.5000.1, S Tab. 14).
pub const MDP: [Object; 1] = [Object::new(
    0xF050,
    "Detected module ident list",
    Record,
    entries![
        count_entry(2),
        // (the defaults: the standard layout's module, what both axes carry at start)
        e(1, "Module ident axis A", U32, RO).default_value(STANDARD_MODULE_A),
        e(2, "Module ident axis B", U32, RO).default_value(STANDARD_MODULE_B),
    ],
    Value::Live,
)
.note("ident of the ESI module of each axis's PDO configuration (E-148)")];
