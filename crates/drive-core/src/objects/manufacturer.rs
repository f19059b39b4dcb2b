//! Manufacturer parameters at 2000h + group·200h + line (spec §2.6, E-009);
//! per-axis parameters also at +8000h (E-010), derived in [`super::OBJECTS`].
//!
//! Simple parameters use sub 0 in both templates (E-011); arrays and records
//! are declared by their elements (subindex = element number, template
//! "EtherCAT Rx", E-012) and get the "EtherCAT Rx SDO Info" view (element +
//! 1, E-013) derived. The parameters are those of spec §20 that are reachable
//! over CoE (lines < 512) and the ones the stack needs; where the spec gives
//! no type or range, the note says what was assumed. Levels: the access level
//! (A10\[2\]) needed to see a parameter (E-016).

use super::shorthand::{a, e, e_, i_};
use super::{comm, repeat, Object, Value};
use crate::{DEVICE_NAME, HARDWARE_VERSION, SOFTWARE_VERSION};
use od::DataType::{Bool, OctetString, VisibleString, I32, U16, U32, U8};
use od::{Access, DataType, EntryInfo, ObjectCode::*};

const RO: Access = Access::RO;
const RW: Access = Access::RW;
const RW_PREOP: Access = Access::RW_PREOP;

/// A66: the sources of the 16 bits of A67, one per element (C-143).
const A66_ELEMENTS: [EntryInfo; 16] = repeat(
    e(0, "", U32, RW).saved(),
    0,
    &numbered!("Source bit "; "0" "1" "2" "3" "4" "5" "6" "7" "8" "9" "10" "11" "12" "13" "14" "15"),
);

/// A279 PROFINET units (spec §11, P-208…P-213): each unit as a code
/// (time base 0x1000 = per minute, dimension × 0x100: 0 revolution, 1
/// degree, 2 metre, plus the number of decimals 0…9), the gear and the feed
/// constant with its unit (0xFFFF: unitless). Defaults: 1/1000 rev, rpm,
/// rpm/s, 1 : 1, feed 1 unitless (P-207).
const A279_ELEMENTS: &[EntryInfo] = &[
    e(0, "Position unit", U16, RW)
        .range(0, 0x1209)
        .default_value(0x0003)
        .saved(),
    e(1, "Velocity unit", U16, RW)
        .range(0, 0x1209)
        .default_value(0x1000)
        .saved(),
    e(2, "Acceleration unit", U16, RW)
        .range(0, 0x1209)
        .default_value(0x1000)
        .saved(),
    e(3, "Gear motor revolutions", U32, RW)
        .range(1, u32::MAX as i64)
        .default_value(1)
        .saved(),
    e(4, "Gear output revolutions", U32, RW)
        .range(1, u32::MAX as i64)
        .default_value(1)
        .saved(),
    e(5, "Feed constant", U32, RW)
        .range(1, u32::MAX as i64)
        .default_value(1)
        .saved(),
    e(6, "Feed unit", U16, RW).default_value(0xFFFF).saved(),
];

/// An action parameter (A00, A09, A37, A287): [0] start, [1] progress, [2] result.
const ACTION: &[EntryInfo] = &[
    e(0, "Start", U8, RW).range(0, 1),
    e(1, "Progress", U8, RO).unit("%"),
    e(2, "Result", U8, RO),
];

/// A287 DC-Sync optimisation: the action elements, then the measurement's
/// results (spec §11.8: proposed A292 range, end of frame → SYNC0, frame
/// duration, SYNC0 → Rx), µs.
const A287_ELEMENTS: &[EntryInfo] = &[
    e(0, "Start", U8, RW).range(0, 1),
    e(1, "Progress", U8, RO).unit("%"),
    e(2, "Result", U8, RO),
    e(3, "A292 minimum", I32, RO).unit("µs"),
    e(4, "A292 maximum", I32, RO).unit("µs"),
    e(5, "End of frame to SYNC0", I32, RO).unit("µs"),
    e(6, "Frame duration", I32, RO).unit("µs"),
    e(7, "SYNC0 to Rx", I32, RO).unit("µs"),
];

/// Elements `1..=N` of `entries` renumbered from 0 (a mirror of a standard
/// object as a manufacturer array, e.g. A264 = 1C32h:01…).
const fn elements_of<const N: usize>(entries: &[EntryInfo]) -> [EntryInfo; N] {
    let mut out = [e(0, "", U8, RO); N];
    let mut i = 0;
    while i < N {
        // i + 1 < entries.len() or compile error (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            out[i] = entries[i + 1].at(i as u8);
        }
        i += 1;
    }
    out
}

const MAPPING_RX_VIEW: [EntryInfo; 24] = repeat(e(0, "", U32, RW_PREOP).saved(), 0, &comm::APP_OBJECT);
const MAPPING_RX_VIEW_RO: [EntryInfo; 24] = repeat(e(0, "", U32, RO), 0, &comm::APP_OBJECT);
const ASSIGN_RX_VIEW: [EntryInfo; 4] = repeat(
    e(0, "", U16, RW_PREOP).saved(),
    0,
    &[
        "Assigned PDO 1",
        "Assigned PDO 2",
        "Assigned PDO 3",
        "Assigned PDO 4",
    ],
);

/// A parameter mirroring a standard array entry by entry, sub 0 included
/// (A225 ≡ 1600h: A225[e] = 1600h:e+1, A225:00 = 1600h:00 in the SDO Info
/// template).
macro_rules! mirror {
    ($index:expr, $name:expr, $target:expr, $entries:expr, $rx:expr, $note:expr) => {{
        // the "EtherCAT Rx" view is the SDO Info view's elements renumbered
        // from 0 (packing shares their records)
        const _: () = assert!(
            super::is_rx_view($rx, &$entries, super::RxView::ElementsNoDefaults),
            "the Rx view of a mirror is its SDO Info elements from subindex 0, without defaults"
        );
        Object::new(
            $index,
            $name,
            Array,
            &$entries,
            Value::Mirror {
                index: $target,
                sub0: true,
            },
        )
        .rx_view(super::RxView::ElementsNoDefaults)
        .level(2)
        .note($note)
    }};
}

/// The longest name of station, bytes (IEC 61158-6-10: 240).
pub const PN_NAME_LEN: u16 = 240;

/// A280's length: the longest stored telegram configuration (the profile's
/// `profidrive::telegram::MAX_SERIAL_BYTES`, a test ties the two).
pub const PN_TELEGRAMS_LEN: u16 = 255;

const fn string(s: &str) -> DataType {
    VisibleString(s.len() as u16)
}

/// Global and axis-A manufacturer parameters, sorted by index.
pub const PARAMS: [Object; 81] = [
    param_array!(a(0), "Save values", Record, Value::Ram, from ACTION)
        .note("A00; [0] = 1 requests saving (E-018); progress/result set by the store"),
    param_array!(a(9), "Restart", Record, Value::Ram, from ACTION)
        .level(1)
        .note("A09; [0] = 1 requests a restart"),
    param_array!(
        a(10),
        "Access level",
        Array,
        Value::Ram,
        [
            e(0, "Operating unit", U8, RW)
                .range(0, 3)
                .default_value(2)
                .saved(),
            e(1, "DS6", U8, RW).range(0, 3).default_value(2).saved(),
            e(2, "CANopen and EtherCAT", U8, RW)
                .range(0, 3)
                .default_value(2)
                .saved(),
            e(3, "PROFINET", U8, RW).range(0, 3).default_value(2).saved(),
        ]
    )
    .note("A10; [2] applies to CoE (E-017); element meanings of [1]/[3] assumed"),
    Object::var(
        a(29),
        Value::Ram,
        entries![e(0, "Quick stop on fault", U8, RW).range(0, 1).saved()],
    )
    .axis()
    .level(1)
    .note("A29; drive-based fault reaction: 0 inactive, 1 active"),
    param_array!(a(37), "Reset memorised values", Record, Value::Ram, from ACTION)
        .level(1)
        .note("A37; action"),
    param_array!(a(66), "Sources user status word", Array, Value::Ram, from &A66_ELEMENTS)
        .axis()
        .note("A66; element = index << 16 | subindex << 8 | bit of the source (0 = bit stays 0); ours, the spec gives no encoding"),
    Object::var(
        a(67),
        Value::Live,
        entries![e(0, "Status word user-defined", U16, RO).tx()],
    )
    .axis()
    .note("A67; bits from the sources in A66"),
    Object::var(
        a(69),
        Value::Live,
        entries![e(0, "Status word for actions", U16, RO).tx()],
    )
    .axis()
    .level(1)
    .note("A69; layout not in the spec (§22)"),
    Object::var(
        a(75),
        Value::Ram,
        entries![e(0, "Control byte for actions", U8, RW).rx()],
    )
    .axis()
    .level(1)
    .note("A75; bit 0 execute, bits 1–4 action selector (assumed, §14)"),
    Object::var(
        a(149),
        Value::Ram,
        entries![e(0, "Cycle sequence", U8, RW).range(0, 1).saved()],
    )
    .level(2)
    .note("A149; 0 Rx→app→Tx, 1 Rx→Tx→app"),
    Object::var(
        a(150),
        Value::Ram,
        entries![e(0, "Cycle time", U16, RW).default_value(1000).unit("µs").saved()],
    )
    .level(1)
    .note("A150; 250, 500, 1000, 2000, 4000, 8000 µs (type assumed UINT16 in µs)"),
    Object::var(
        a(166),
        Value::Ram,
        entries![e(0, "IP address reference", U8, RW)
            .range(0, 2)
            .default_value(2)
            .saved()],
    )
    .level(2)
    .note("A166; 2 = DHCP + DS6 (other codes assumed)"),
    Object::var(a(175), Value::Ram, entries![e(0, "Gateway", U32, RW).saved()])
        .level(2)
        .note("A175; IPv4 address as DWORD (assumed)"),
    param_array!(
        a(199),
        "SNTP settings",
        Record,
        Value::Ram,
        [
            e(0, "Active", U8, RW).range(0, 1).saved(),
            e(1, "Server 1", U32, RW).saved(),
            e(2, "Server 2", U32, RW).saved(),
        ]
    )
    .level(2)
    .note("A199; elements assumed (spec §10: two servers)"),
    param_array!(
        a(213),
        "Fieldbus scaling",
        Array,
        Value::Ram,
        [
            e(0, "Process data", U8, RW_PREOP)
                .range(0, 1)
                .default_value(1)
                .saved(),
            e(1, "Parameter channel", U8, RW)
                .range(0, 1)
                .default_value(1)
                .saved(),
        ]
    )
    .level(2)
    .note("A213 (E-143): 1 = native (default), 0 = integer with the decimal places A310/A311; [0] the process data and what the objects hold, [1] the SDO and UDP parameter channel (element roles assumed); see Fieldbus scaling below"),
    mirror!(
        0x20E1,
        "RxPDO 1 mapping",
        0x1600,
        comm::MAP_1600,
        &MAPPING_RX_VIEW,
        "A225 = 1600h"
    ),
    mirror!(
        0x20E2,
        "RxPDO 2 mapping",
        0x1601,
        comm::MAP_1601,
        &MAPPING_RX_VIEW,
        "A226 = 1601h"
    ),
    mirror!(
        0x20E3,
        "RxPDO 3 mapping",
        0x1602,
        comm::MAP_1602,
        &MAPPING_RX_VIEW,
        "A227 = 1602h"
    ),
    mirror!(
        0x20E4,
        "RxPDO 4 mapping",
        0x1603,
        comm::MAP_1603,
        &MAPPING_RX_VIEW_RO,
        "A228 = 1603h (FSoE)"
    ),
    mirror!(
        0x20E9,
        "TxPDO 1 mapping",
        0x1A00,
        comm::MAP_1A00,
        &MAPPING_RX_VIEW,
        "A233 = 1A00h"
    ),
    mirror!(
        0x20EA,
        "TxPDO 2 mapping",
        0x1A01,
        comm::MAP_1A01,
        &MAPPING_RX_VIEW,
        "A234 = 1A01h"
    ),
    mirror!(
        0x20EB,
        "TxPDO 3 mapping",
        0x1A02,
        comm::MAP_1A02,
        &MAPPING_RX_VIEW,
        "A235 = 1A02h"
    ),
    mirror!(
        0x20EC,
        "TxPDO 4 mapping",
        0x1A03,
        comm::MAP_1A03,
        &MAPPING_RX_VIEW_RO,
        "A236 = 1A03h (FSoE)"
    ),
    Object::var(
        a(250),
        Value::Alias({
            const LIST: &[(u16, u8)] = &[(0x10F3, 4)];
            &LIST
        }),
        entries![e(0, "New diagnosis messages available", Bool, RO).tx()],
    )
    .note("A250 = 10F3h:04"),
    mirror!(
        0x20FC,
        "PDO assignment SM2",
        0x1C12,
        comm::ASSIGN_1C12,
        &ASSIGN_RX_VIEW,
        "A252 = 1C12h"
    ),
    mirror!(
        0x20FD,
        "PDO assignment SM3",
        0x1C13,
        comm::ASSIGN_1C13,
        &ASSIGN_RX_VIEW,
        "A253 = 1C13h"
    ),
    Object::var(
        a(254),
        Value::Live,
        entries![e(0, "EtherCAT station alias", U16, RO)],
    )
    .level(1)
    .note("A254; from the SII at Init→PreOp"),
    Object::var(
        a(255),
        Value::Live,
        entries![e(0, "EtherCAT device state", U8, RO)],
    )
    .note("A255; 1/2/4/8 = Init/PreOp/SafeOp/Op, +16 with error"),
    Object::var(a(256), Value::Live, entries![e(0, "EtherCAT address", U16, RO)])
        .level(1)
        .note("A256; station address"),
    param_array!(
        a(257),
        "EtherCAT diagnosis",
        Array,
        Value::Live,
        [
            e(0, "Error and links", VisibleString(16), RO),
            e(1, "Link-lost counters", VisibleString(16), RO),
            e(2, "Data-error counters", VisibleString(16), RO),
            e(3, "AL status", VisibleString(16), RO),
        ]
    )
    .note("A257; texts (spec §13.5)"),
    Object::var(
        a(258),
        Value::Ram,
        entries![e(0, "PDO timeout", U16, RW).unit("ms").saved()],
    )
    .level(1)
    .note("A258; 0/65535 off, 65532–65534 special (spec §13.1)"),
    param_array!(
        a(259),
        "EtherCAT SM watchdog",
        Record,
        Value::Live,
        [
            e(0, "Tolerated failure time", U16, RO).unit("ms"),
            e(1, "State", U8, RO),
            e(2, "Times triggered", U16, RO),
        ]
    )
    .level(1)
    .note("A259"),
    param_array!(
        a(261),
        "Sync diagnostics",
        Record,
        Value::Live,
        [
            e(0, "Error code", U8, RO),
            e(1, "Data to SYNC0", I32, RO).unit("µs"),
            e(2, "Error counter", U32, RO),
            e(3, "Reserved", U32, RO),
        ]
    )
    .level(2)
    .note("A261; element types assumed"),
    param_array!(
        a(264),
        "Output SyncManager parameter",
        Record,
        Value::Mirror {
            index: 0x1C32,
            sub0: false
        },
        from & elements_of::<10>(&comm::SM_OUTPUT)
    )
    .level(2)
    .note("A264 = 1C32h:01…20h"),
    param_array!(
        a(265),
        "Input SyncManager parameter",
        Record,
        Value::Mirror {
            index: 0x1C33,
            sub0: false
        },
        from & elements_of::<10>(&comm::SM_INPUT)
    )
    .level(2)
    .note("A265 = 1C33h:01…20h"),
    param_array!(
        a(268),
        "SDO Info object selection",
        Record,
        Value::Ram,
        [
            e(0, "Index area", U8, RW).range(0, 2).default_value(2).saved(),
            e(1, "Manufacturer groups", U32, RW)
                .default_value(0x03FF_FFFF)
                .saved(),
        ]
    )
    .level(2)
    .note("A268; encoding ours (0 standard area, 1 manufacturer area, 2 all; bit g of [1] lists group A + g, E-083); selects the SDO Info OD lists only"),
    Object::var(
        a(269),
        Value::Ram,
        entries![e(0, "UDP parameter writes", U8, RW).range(0, 1).saved()],
    )
    .level(1)
    .note("A269 (line ours); 0 = the UDP parameter service only reads (default), 1 = it writes too; the service never writes A269 itself, so only CoE (the master) or the panel opens it (docs/eoe.md)"),
    // A270…A278: the PROFINET personality's operating parameters (spec
    // §2.4, P-007…P-019; lines ours). The EtherCAT personality declares and
    // stores them like every parameter and reads none of them.
    Object::var(
        a(270),
        Value::Ram,
        entries![e(0, "PROFINET active", Bool, RW).default_value(1).saved()],
    )
    .note("A270; 1 = active (default: a drive running the PROFINET personality answers out of the box); off takes effect at once, on after save and restart (P-012, P-013)"),
    Object::var(
        a(271),
        Value::Ram,
        entries![e(0, "Name of station", VisibleString(PN_NAME_LEN), RW).saved()],
    )
    .note("A271; up to 240 characters (IEC 61158-6-10), empty = none; read at start (P-007); DCP Set writes it"),
    Object::var(a(272), Value::Ram, entries![e(0, "PROFINET IP address", U32, RW).saved()])
        .note("A272; static IPv4 address, first octet in the most significant byte; 0 = none; used while DCP assigns none (P-010), overwritten by DCP (P-009)"),
    Object::var(a(273), Value::Ram, entries![e(0, "PROFINET subnet mask", U32, RW).saved()])
        .note("A273; as A272"),
    Object::var(a(274), Value::Ram, entries![e(0, "PROFINET gateway", U32, RW).saved()])
        .note("A274; as A272; 0 = no gateway"),
    Object::var(
        a(275),
        Value::Ram,
        entries![e(0, "PROFIenergy active", Bool, RW).saved()],
    )
    .note("A275; 1 = active (P-015); the PROFIenergy services themselves are not built (P-016)"),
    Object::var(
        a(276),
        Value::Ram,
        entries![e(0, "PROFINET protocol", U8, RW).range(0, 0).saved()],
    )
    .note("A276; 0 = standard protocol, the only one (P-014)"),
    Object::var(
        a(277),
        Value::Ram,
        entries![e(0, "Parameterisation interface", U8, RW).range(0, 2).saved()],
    )
    .note("A277; 0 automatic, 1 on-board Ethernet (service port), 2 PROFINET (P-017)"),
    Object::var(
        a(278),
        Value::Ram,
        entries![e(0, "Vendor service port", U16, RW)
            .range(1, 65535)
            .default_value(8802)
            .saved()],
    )
    .note("A278; UDP/TCP port of the vendor service protocol on the PROFINET IP while A277 = 2 (P-018); the service itself is not built"),
    param_array!(a(279), "PROFINET units", Record, Value::Ram, from A279_ELEMENTS)
        .note("A279; the PROFINET personality's unit choices (P-208…P-213); a setting whose conversion does not fit 32-bit fractions raises event 70 cause 4 (the manual's 22-4) and the previous units stay"),
    Object::var(
        a(280),
        Value::Ram,
        entries![e(0, "PROFINET telegrams", OctetString(PN_TELEGRAMS_LEN), RO).saved()],
    )
    .note("A280; the PROFIdrive profile's telegram configuration in its stored form (P-069; version 0 = the Example Function block's telegrams); written by the profile when an edited telegram is applied, saved with the parameters"),
    param_array!(a(287), "DC-Sync optimization", Record, Value::Ram, from A287_ELEMENTS)
        .level(2)
        .note("A287; action, results not stored (spec §22); [3]..[7] measurement results (our choice, spec §11.8 leaves their place open)"),
    Object::var(
        a(290),
        Value::Ram,
        entries![e(0, "PLL control", U8, RW).range(0, 1).default_value(1).saved()],
    )
    .level(2)
    .note("A290; 1 = active"),
    Object::var(
        a(291),
        Value::Ram,
        entries![e(0, "PLC cycle time", U32, RW)
            .default_value(1000)
            .unit("µs")
            .saved()],
    )
    .level(2)
    .note("A291; 60C2h copied into it when the interpolation period or A150 changes and at start (C-114)"),
    Object::var(
        a(292),
        Value::Ram,
        entries![e(0, "PLL phase offset", I32, RW)
            .range(-8000, 8000)
            .unit("µs")
            .saved()],
    )
    .level(2)
    .note("A292; unit µs assumed, at most one A150 cycle"),
    Object::var(a(293), Value::Ram, entries![e(0, "PLL gain", U16, RW).saved()])
        .level(3)
        .note("A293; meaning unclear (spec §11.6), service level"),
    Object::var(
        a(296),
        Value::Live,
        entries![e(0, "Measured sync cycle time", U32, RO).unit("µs")],
    )
    .level(2)
    .note("A296"),
    Object::var(a(298), Value::Live, entries![e(0, "PLL status word", U16, RO)])
        .level(2)
        .note("A298; bits spec §11.6"),
    Object::var(
        a(310),
        Value::Ram,
        entries![e(0, "Decimal places velocity", U8, RW_PREOP)
            .range(0, 9)
            .saved()],
    )
    .axis()
    .level(2)
    .note("A310: decimal places of the velocity objects under A213 = 0 (C-142)"),
    Object::var(
        a(311),
        Value::Ram,
        entries![e(0, "Decimal places acceleration", U8, RW_PREOP)
            .range(0, 9)
            .saved()],
    )
    .axis()
    .level(2)
    .note("A311: decimal places of the acceleration, deceleration and jerk objects under A213 = 0 (C-142)"),
    Object::var(
        a(340),
        Value::Ram,
        entries![e(0, "Velocity override", U16, RW)
            .range(0, 200)
            .default_value(100)
            .unit("%")
            .rx()],
    )
    .axis()
    .note("A340; pp, vl, pv (C-030); range 0–200 % assumed"),
    Object::var(e_(43), Value::Live, entries![e(0, "Event cause", U8, RO)]).note("E43; EMCY byte 5"),
    Object::var(
        e_(47),
        Value::Live,
        entries![e(0, "Cause of switch on disabled", U8, RO)],
    )
    .axis()
    .note("E47; first cause: 0 none, 1 STO, 2 supply, 3 additional enable A60, 4 controlword (encoding ours, C-015)"),
    Object::var(e_(48), Value::Live, entries![e(0, "Device state", U8, RO)])
        .axis()
        .note("E48; 2 ready to switch on, 4 enabled, 7 quick stop"),
    Object::var(
        e_(49),
        Value::Live,
        entries![e(0, "Causes of switch on disabled", U8, RO)],
    )
    .axis()
    .note("E49; all causes: bit 0 STO, 1 supply, 2 A60, 3 controlword (encoding ours, C-015)"),
    Object::var(
        e_(50),
        Value::Alias({
            const LIST: &[(u16, u8)] = &[(0x1008, 0)];
            &LIST
        }),
        entries![e(0, "Device name", string(DEVICE_NAME), RO)],
    )
    .note("E50 = 1008h"),
    param_array!(
        e_(52),
        "Device identification",
        Record,
        Value::Alias({
            const LIST: &[(u16, u8)] = &[(0, 0), (0, 0), (0x1009, 0), (0x1018, 4), (0x100A, 0)];
            &LIST
        }),
        [
            e(0, "Identification", U32, RO),
            e(1, "Hardware version", string(HARDWARE_VERSION), RO),
            e(2, "Serial number", U32, RO),
            e(3, "Software version", string(SOFTWARE_VERSION), RO),
        ]
    )
    .note("E52; [1] = 1009h, [2] = 1018h:04, [3] = 100Ah; [0] not described (0)"),
    Object::var(e_(54), Value::Live, entries![e(0, "Firmware update slot", U8, RO)])
        .level(1)
        .note("E54 (number ours, issue 33): the slot an FoE download goes to, 1 = A, 2 = B (send firmware-slot-a/-b.sc6f); 0 = no firmware slots"),
    param_array!(
        e_(59),
        "Projected fieldbus identification",
        Array,
        Value::Live,
        [
            e(0, "Element 0", U16, RO),
            e(1, "Element 1", U16, RO),
            e(2, "Fieldbus", U16, RO),
        ]
    )
    .level(1)
    .note("E59; [2] compared with E52[3] (Event 52 cause 15); type assumed"),
    Object::var(
        e_(72),
        Value::Ram,
        entries![e(0, "User configuration identification", VisibleString(16), RW).saved()],
    )
    .level(1)
    .note("E72; ESI module name, STR16"),
    Object::var(e_(80), Value::Live, entries![e(0, "Operating condition", U8, RO).tx()])
        .axis()
        .note("E80; 0 none, 15 illegal direction, 20 limit switch (C-107); other codes not modelled"),
    Object::var(e_(82), Value::Live, entries![e(0, "Event type", U8, RO)]).note("E82; EMCY byte 4"),
    Object::var(
        e_(191),
        Value::Live,
        entries![e(0, "Real-time task utilisation", U8, RO).unit("%")],
    )
    .level(2)
    .note("E191"),
    param_array!(
        e_(200),
        "Status words",
        Array,
        Value::Live,
        [
            e(0, "Status word 1", U16, RO),
            e(1, "Status word 1 (element 1)", U16, RO),
        ]
    )
    .axis()
    .note("E200; content not in the sources, declared for the addressing example E-014"),
    Object::var(
        e_(201),
        Value::Live,
        entries![e(0, "Status word 2", U16, RO).tx()],
    )
    .axis()
    .note("E201; content not described"),
    Object::var(
        i_(2),
        Value::Ram,
        entries![e(0, "Position encoder", U8, RW).range(0, 0).saved()],
    )
    .axis()
    .level(1)
    .note("I02; 0 = motor encoder, the only encoder of this hardware model (C-113)"),
    Object::var(
        i_(21),
        Value::Ram,
        entries![e(0, "Position error limit", U32, RW)
            .default_value(u32::MAX as i64)
            .unit("inc")
            .saved()],
    )
    .axis()
    .level(1)
    .note("I21; beyond it event 54 cause 2 (a fault) at once; 4294967295 = off; PROFINET PNU 1273 (P-160)"),
    Object::var(
        i_(22),
        Value::Ram,
        entries![e(0, "Target window", U32, RW).default_value(2912).unit("inc").saved()],
    )
    .axis()
    .level(1)
    .note("I22; position window of target reached and in position (CiA 402 6067h's role; default 1° in increments); PROFINET PNU 1271 (P-158)"),
    Object::var(
        i_(23),
        Value::Ram,
        entries![e(0, "Position dead band", U32, RW).unit("inc").saved()],
    )
    .axis()
    .level(1)
    .note("I23; no position correction while |following error| is within it (backlash); 0 = off; PROFINET PNU 1270.2 (P-157)"),
    Object::var(
        i_(46),
        Value::Ram,
        entries![e(0, "Reference retaining", U8, RW).range(0, 5).saved()],
    )
    .axis()
    .level(1)
    .note("I46; 5 = direct absolute (C-112); 0–4 = not referenced after power-on"),
    Object::var(
        i_(101),
        Value::Ram,
        entries![e(0, "Source positive limit switch", U8, RW).range(0, 2).saved()],
    )
    .axis()
    .level(1)
    .note("I101; 0 off, 1 input, 2 parameter I210 bit 0 (C-104)"),
    Object::var(
        i_(102),
        Value::Ram,
        entries![e(0, "Source negative limit switch", U8, RW).range(0, 2).saved()],
    )
    .axis()
    .level(1)
    .note("I102; 0 off, 1 input, 2 parameter I210 bit 1 (C-104)"),
    Object::var(
        i_(103),
        Value::Ram,
        entries![e(0, "Source reference switch", U8, RW)
            .range(0, 2)
            .default_value(1)
            .saved()],
    )
    .axis()
    .level(1)
    .note("I103; 0 off, 1 input, 2 parameter I210 bit 2"),
    Object::var(
        i_(210),
        Value::Ram,
        entries![e(0, "Application control word", U16, RW).rx()],
    )
    .axis()
    .note("I210; bit 0 +LS, bit 1 −LS, bit 2 reference switch (1 = actuated; bit layout ours)"),
];
