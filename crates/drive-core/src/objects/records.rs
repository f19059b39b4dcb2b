//! Position records (PROFIdrive-style profile, spec `profidrive.md` §8.4,
//! P-141 … P-146; usable from any fieldbus): the record table, the record
//! selector and data, the start record number, the positioning override and
//! the set-up speed, in group J "Motion blocks" (3200h + line; axis B at
//! +8000h). The lines J400 … J411 are ours: the STÖBER manual names no J
//! parameter the drive has, and these do not claim to be its motion blocks.
//!
//! | line | index | object | per axis | saved |
//! |---|---|---|---|---|
//! | J400 | 3390h | record selector (PNU 1000): which record J401 shows | yes | no |
//! | J401 | 3391h | record data (PNU 1001) of the selected record | yes | (the record) |
//! | J402 | 3392h | start record number (PNU 1002): 0 … 254, 255 = record 266 | yes | no |
//! | J403 | 3393h | positioning override (PNU 1004), ‰ | yes | no |
//! | J404 | 3394h | set-up speed (PNU 1060) | yes | yes |
//! | J410 | 339Ah | memory of the standard records 0 … 255 and their options | no | see [`STANDARD_RECORDS_SAVED`] |
//! | J411 | 339Bh | memory of the special records 256 … 267, the axis' task state | yes | 256 … 260 |
//!
//! Records are in the CiA 402 user units of the axis (the factor group
//! 6091h/6092h, decimals A310/A311), like 607Ah, 6081h, 6082h, 6083h and
//! 6084h. A record is 20 bytes: target position (INT32), profile velocity,
//! end velocity, acceleration, deceleration (UNSIGNED32 each), little
//! endian; each record's options byte ([`OPT_RELATIVE`], [`OPT_IMMEDIATE`])
//! follows the records of its memory object. J410/J411 are the memory
//! only (level 3, read-only); J400/J401 are the way to a record.
//!
//! The 256 standard records are one table of the drive (both axes start
//! the same records): two tables do not fit the board's RAM budget next to
//! the rest (docs/conformance.md, decisions). The special records (homing
//! 256 … 258, jog 259/260, the fieldbus' own record 266) are per axis.

use super::shorthand::{e, j};
use super::{Object, Value};
use od::DataType::{OctetString, I32, U16, U32, U8};
use od::{Access, EntryInfo};

const RO: Access = Access::RO;
const RW: Access = Access::RW;

/// J400 record selector.
pub const J400: u16 = j(400);
/// J401 record data of the selected record.
pub const J401: u16 = j(401);
/// J402 start record number.
pub const J402: u16 = j(402);
/// J403 positioning override, ‰.
pub const J403: u16 = j(403);
/// J404 set-up speed.
pub const J404: u16 = j(404);
/// J410 memory of the standard records.
pub const J410: u16 = j(410);
/// J411 memory of the special records.
pub const J411: u16 = j(411);

/// J401\[5\]'s default (= \[3\]'s).
pub const ALL_ACCELERATIONS_DEFAULT: u32 = RPM_10000_PER_S as u32;
/// Records in the table: 0 … 267.
pub const RECORDS: u16 = 268;
/// Standard (stored) records 0 … 255.
pub const STANDARD: u16 = 256;
/// Homing records 256 … 258.
pub const HOMING_FIRST: u16 = 256;
/// Jog positive (TIPP0).
pub const JOG_POSITIVE: u16 = 259;
/// Jog negative (TIPP1).
pub const JOG_NEGATIVE: u16 = 260;
/// The fieldbus' own record (PROFINET record, P-146).
pub const FIELDBUS: u16 = 266;
/// Bytes of one record.
pub const RECORD_BYTES: usize = 20;
/// Option bit: the target is relative to the present position set-point.
pub const OPT_RELATIVE: u8 = 1;
/// Option bit: change immediately (else append to the running task).
pub const OPT_IMMEDIATE: u8 = 2;
/// Special records kept by the save service: 256 … 260.
const SPECIAL_SAVED: usize = 5;
/// Special records not kept: 261 … 267.
const SPECIAL_VOLATILE: usize = 7;
/// Special records per axis: 256 … 267.
const SPECIAL: usize = SPECIAL_SAVED + SPECIAL_VOLATILE;
/// Standard records per element of J410 (an element stays below the CoE
/// server's 4 KiB transfer buffer).
const HALF: usize = STANDARD as usize / 2;
/// Bytes of the record positioning state of an axis (J411's "Task state",
/// not saved; the axis' running tasks, `axis/record_state.rs`).
pub const TASK_STATE_BYTES: usize = 72;
/// Where it starts in J411's element values.
pub const TASK_STATE_AT: usize = SPECIAL * (RECORD_BYTES + 1);
/// Bytes of J410's values: the standard records, then their options.
pub const STANDARD_BYTES: usize = STANDARD as usize * (RECORD_BYTES + 1);

/// Whether the save service keeps the 256 standard records. Off until the
/// parameter stores have room for them: the saved set is ~1.3 KiB without
/// and ~6.7 KiB with them, and the stores the images and the simulator use
/// have 2 KiB (`firmware_tasks::ParamFlash`) and 4 KiB (hil-sim) slots. Turning it on
/// changes the layout hash (a saved set from before loads as defaults).
pub const STANDARD_RECORDS_SAVED: bool = false;

/// 1000 rpm in the default user units (increments, 2^20 per revolution), /s.
const RPM_1000: i64 = 17_476_267;
/// 10 000 rpm/s, increments/s².
const RPM_10000_PER_S: i64 = 174_762_667;
/// 100 rpm, increments/s.
const RPM_100: i64 = 1_747_627;
/// 1000 rpm/s, increments/s².
const RPM_1000_PER_S: i64 = 17_476_267;
/// 3276 rpm, increments/s (the set-up speed's default).
const RPM_3276: i64 = 57_252_250;

/// A record's values, user units.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Record {
    /// Target position, user position units.
    pub target: i32,
    /// Profile velocity, user velocity units.
    pub profile_velocity: u32,
    /// End velocity (the velocity at the target when a task follows), user
    /// velocity units.
    pub end_velocity: u32,
    /// Acceleration, user acceleration units.
    pub acceleration: u32,
    /// Deceleration, user acceleration units.
    pub deceleration: u32,
    /// Options ([`OPT_RELATIVE`], [`OPT_IMMEDIATE`]); a start uses those
    /// of the standard records (record 266 takes them from the command).
    pub options: u8,
}

impl Record {
    /// The default of a standard record (P-145): target 0, 1000 rpm, end
    /// velocity 0, 10 000 rpm/s both ways.
    pub const STANDARD_DEFAULT: Record = Record {
        target: 0,
        profile_velocity: RPM_1000 as u32,
        end_velocity: 0,
        acceleration: RPM_10000_PER_S as u32,
        deceleration: RPM_10000_PER_S as u32,
        options: 0,
    };

    /// The default of a jog record 259/260 (P-177): 100 rpm, 1000 rpm/s.
    pub const JOG_DEFAULT: Record = Record {
        target: 0,
        profile_velocity: RPM_100 as u32,
        end_velocity: 0,
        acceleration: RPM_1000_PER_S as u32,
        deceleration: RPM_1000_PER_S as u32,
        options: 0,
    };

    /// The default of record `n`.
    pub const fn default_of(n: u16) -> Record {
        match n {
            JOG_POSITIVE | JOG_NEGATIVE => Self::JOG_DEFAULT,
            _ => Self::STANDARD_DEFAULT,
        }
    }

    /// The 20 bytes of the record (options not included).
    pub const fn to_bytes(&self) -> [u8; RECORD_BYTES] {
        let mut out = [0u8; RECORD_BYTES];
        let words = [
            self.target as u32,
            self.profile_velocity,
            self.end_velocity,
            self.acceleration,
            self.deceleration,
        ];
        let mut w = 0;
        while w < 5 {
            // w < 5, 4·w + k < 20 (compile-time evaluation as well)
            #[allow(clippy::indexing_slicing)]
            {
                let b = words[w].to_le_bytes();
                let mut k = 0;
                while k < 4 {
                    out[4 * w + k] = b[k];
                    k += 1;
                }
            }
            w += 1;
        }
        out
    }

    /// The record of `bytes` (20) with `options`.
    pub fn from_bytes(bytes: &[u8], options: u8) -> Option<Record> {
        let word = |k: usize| -> Option<u32> {
            let b = bytes.get(4 * k..4 * k + 4)?;
            Some(u32::from_le_bytes([
                *b.first()?,
                *b.get(1)?,
                *b.get(2)?,
                *b.get(3)?,
            ]))
        };
        Some(Record {
            target: word(0)? as i32,
            profile_velocity: word(1)?,
            end_velocity: word(2)?,
            acceleration: word(3)?,
            deceleration: word(4)?,
            options,
        })
    }
}

/// Where record `n` lives: (memory object, axis-A numbering; byte offset
/// of the record in the object's element values (after sub 0); byte
/// offset of its options there). `None` for `n` ≥ 268.
pub const fn place(n: u16) -> Option<(u16, usize, usize)> {
    if n < STANDARD {
        let k = n as usize;
        Some((J410, k * RECORD_BYTES, STANDARD as usize * RECORD_BYTES + k))
    } else if n < RECORDS {
        let k = (n - STANDARD) as usize;
        Some((J411, k * RECORD_BYTES, SPECIAL * RECORD_BYTES + k))
    } else {
        None
    }
}

/// The initial byte at `at` (offset in the values of memory object `index`,
/// axis-A numbering) of the record memory: the records' defaults, options 0.
pub const fn initial_byte(index: u16, at: usize) -> Option<u8> {
    let (first, records) = match index {
        J410 => (0, STANDARD as usize),
        J411 => (STANDARD, RECORDS as usize - STANDARD as usize),
        _ => return None,
    };
    let k = at / RECORD_BYTES;
    if k >= records {
        return Some(0);
    }
    let bytes = Record::default_of(first + k as u16).to_bytes();
    // at % 20 < 20 (compile-time evaluation)
    #[allow(clippy::indexing_slicing)]
    Some(bytes[at % RECORD_BYTES])
}

/// J401 elements (subindex = element; the SDO Info view adds 1): the
/// selected record's data (P-143, P-144; defaults P-145 = record 266's).
const DATA_ELEMENTS: &[EntryInfo] = &[
    e(0, "Target position", I32, RW).rx(),
    e(1, "Profile velocity", U32, RW).default_value(RPM_1000).rx(),
    e(2, "End velocity", U32, RW).rx(),
    e(3, "Acceleration", U32, RW).default_value(RPM_10000_PER_S).rx(),
    e(4, "Deceleration", U32, RW).default_value(RPM_10000_PER_S).rx(),
    e(5, "All accelerations", U32, RW)
        .default_value(RPM_10000_PER_S)
        .rx(),
    e(6, "Options", U8, RW).range(0, 3),
];

/// J410: the standard records (two halves) and their options.
const STANDARD_ELEMENTS: [EntryInfo; 3] = {
    let els = [
        e(0, "Records 0-127", OctetString((HALF * RECORD_BYTES) as u16), RO),
        e(
            1,
            "Records 128-255",
            OctetString((HALF * RECORD_BYTES) as u16),
            RO,
        ),
        e(2, "Options 0-255", OctetString(STANDARD), RO),
    ];
    if STANDARD_RECORDS_SAVED {
        [els[0].saved(), els[1].saved(), els[2].saved()]
    } else {
        els
    }
};

/// J411: records 256 … 260 (kept), 261 … 267 (not kept), their options,
/// the task state of the axis' record positioning (not kept).
const SPECIAL_ELEMENTS: &[EntryInfo] = &[
    e(
        0,
        "Records 256-260",
        OctetString((SPECIAL_SAVED * RECORD_BYTES) as u16),
        RO,
    )
    .saved(),
    e(
        1,
        "Records 261-267",
        OctetString((SPECIAL_VOLATILE * RECORD_BYTES) as u16),
        RO,
    ),
    e(2, "Options 256-267", OctetString(SPECIAL as u16), RO),
    e(3, "Task state", OctetString(TASK_STATE_BYTES as u16), RO),
];
const _: () = assert!(SPECIAL == (RECORDS - STANDARD) as usize);
const _: () = assert!(HALF * RECORD_BYTES < 4096);

/// The record objects, sorted by index.
pub const PARAMS: [Object; 7] = [
    Object::var(
        J400,
        Value::Ram,
        entries![e(0, "Record selector", U16, RW)
            .range(0, RECORDS as i64 - 1)
            .default_value(FIELDBUS as i64)],
    )
    .axis()
    .note("J400 (ours; PNU 1000): the record J401 reads and writes, 0…267 (P-141, P-142)"),
    param_array!(J401, "Record data", Record, Value::Ram, from DATA_ELEMENTS)
        .axis()
        .note("J401 (ours; PNU 1001): the selected record in user units; [5] write sets [3] and [4], read gives [3] (P-144); [6] options: bit 0 relative, bit 1 change immediately (used by the standard records)"),
    Object::var(
        J402,
        Value::Ram,
        entries![e(0, "Start record number", U8, RW)
            .default_value(255)
            .rx()],
    )
    .axis()
    .note("J402 (ours; PNU 1002): the record a start runs, 0…254; 255 = record 266 (P-146)"),
    Object::var(
        J403,
        Value::Ram,
        entries![e(0, "Positioning override", U16, RW)
            .range(0, 2000)
            .default_value(1000)
            .unit("‰")
            .rx()],
    )
    .axis()
    .note("J403 (ours; PNU 1004): scales the velocity of record tasks, not saved, 1000 after a restart (P-149 … P-151)"),
    Object::var(
        J404,
        Value::Ram,
        entries![e(0, "Set-up speed", U32, RW)
            .default_value(RPM_3276)
            .saved()],
    )
    .axis()
    .note("J404 (ours; PNU 1060): the velocity limit of record tasks and jog while set-up mode is on, user velocity units (P-140, P-183)"),
    param_array!(J410, "Standard records", Array, Value::Ram, from &STANDARD_ELEMENTS)
        .level(3)
        .note("J410 (ours): memory of records 0…255 (20 bytes each) and their options (1 byte each); through J400/J401"),
    param_array!(J411, "Special records", Array, Value::Ram, from SPECIAL_ELEMENTS)
        .axis()
        .level(3)
        .note("J411 (ours): memory of records 256…267 of the axis (20 bytes each); through J400/J401"),
];
