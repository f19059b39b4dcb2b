//! CiA 402 objects of axis A, 6000h–65FFh (`od-cia402.md` Tab. 34 and X-01).
//! Axis B is the same table at +800h ([`super::OBJECTS`] derives it).
//!
//! Types and access are the CiA 402 standard's (the source gives none);
//! PDO mappability is the source's. Units are the standard's: positions in
//! increments (2^20 per revolution with the default feed constant),
//! velocities in inc/s, accelerations in inc/s², torques and currents in
//! 0.1 % of the rated value. Set-points and commands are [`Value::Ram`],
//! actual values [`Value::Live`] (fed by the CiA 402 and motion code),
//! configuration is saved.

use super::shorthand::e;
use super::{count_entry, repeat, Object, Value};
use od::DataType::{I16, I32, I8, U16, U32, U8};
use od::{Access, DataType, EntryInfo, ObjectCode::*};

const RO: Access = Access::RO;
const RW: Access = Access::RW;
const WO: Access = Access::WO;
/// A read-write, RxPDO- and TxPDO-mappable entry.
const fn rt(sub: u8, name: &'static str, t: DataType) -> EntryInfo {
    e(sub, name, t, RW).rx().tx()
}
/// A read-only, TxPDO-mappable entry.
const fn ro_tx(sub: u8, name: &'static str, t: DataType) -> EntryInfo {
    e(sub, name, t, RO).tx()
}

const POS: &str = "inc";
const VEL: &str = "inc/s";
const ACC: &str = "inc/s²";
const TRQ: &str = "0.1 %";
const REV_INC: i64 = 1 << 20;

/// Supported homing methods.
pub const HOMING_METHODS: [i8; 20] = [
    1, 2, 3, 5, 7, 11, 17, 18, 19, 21, 23, 27, 33, 34, 35, 37, -1, -2, -3, -4,
];
/// The same as `i64`, for the enumeration check of 6098h.
pub const HOMING_METHODS_I64: [i64; 20] = {
    let mut out = [0i64; 20];
    let mut i = 0;
    while i < 20 {
        // i < 20 (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            out[i] = HOMING_METHODS[i] as i64;
        }
        i += 1;
    }
    out
};
const HOMING_NAMES: [&str; 20] =
    numbered!("Supported homing method "; 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20);
const SUPPORTED_HOMING: [EntryInfo; 21] = {
    let els = repeat(e(1, "", I8, RO), 1, &HOMING_NAMES);
    let mut out = [count_entry(20); 21];
    let mut i = 0;
    while i < 20 {
        // i < 20 (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            out[i + 1] = els[i].default_value(HOMING_METHODS_I64[i]);
        }
        i += 1;
    }
    out
};

/// 6502h: pp, vl, pv, tq, hm, ip, csp, csv, cst (bits 0–3, 5–9); jog (−1) is
/// not reported.
pub const SUPPORTED_DRIVE_MODES: u32 = 0x0000_03EF;

/// A vl ramp (6048h/6049h/604Ah): delta speed / delta time.
const fn ramp(name: &'static str, index: u16, note: &'static str) -> Object {
    const RAMP: &[EntryInfo] = &[
        count_entry(2),
        rt(1, "Delta speed", U32).default_value(3000).unit("rpm").saved(),
        rt(2, "Delta time", U16).default_value(1).unit("s").saved(),
    ];
    Object::new(index, name, Record, RAMP, Value::Ram).note(note)
}

/// An ARRAY of two saved, PDO-mappable values.
macro_rules! pair {
    ($index:expr, $name:expr, $t:expr, $n1:expr, $d1:expr, $n2:expr, $d2:expr, $unit:expr, $note:expr) => {
        Object::new(
            $index,
            $name,
            Array,
            entries![
                count_entry(2),
                rt(1, $n1, $t).default_value($d1).unit($unit).saved(),
                rt(2, $n2, $t).default_value($d2).unit($unit).saved(),
            ],
            Value::Ram,
        )
        .note($note)
    };
}

/// The CiA 402 objects of axis A, sorted by index.
pub const AXIS_A: [Object; 70] = [
    Object::var(0x603F, Value::Live, entries![ro_tx(0, "Error code", U16)]).note("A514"),
    Object::var(0x6040, Value::Ram, entries![rt(0, "Controlword", U16)]).note("A515"),
    Object::var(0x6041, Value::Live, entries![ro_tx(0, "Statusword", U16)]).note("A516"),
    Object::var(
        0x6042,
        Value::Ram,
        entries![rt(0, "vl target velocity", I16).unit("rpm")],
    )
    .note("A517"),
    Object::var(
        0x6043,
        Value::Live,
        entries![ro_tx(0, "vl velocity demand", I16).unit("rpm")],
    )
    .note("A518"),
    Object::var(
        0x6044,
        Value::Live,
        entries![ro_tx(0, "vl velocity actual value", I16).unit("rpm")],
    )
    .note("A519"),
    pair!(
        0x6046,
        "vl velocity min max amount",
        U32,
        "vl velocity min amount",
        0,
        "vl velocity max amount",
        3000,
        "rpm",
        "A521; max default: placeholder until the motion core"
    ),
    ramp("vl velocity acceleration", 0x6048, "A523"),
    ramp("vl velocity deceleration", 0x6049, "A524"),
    ramp("vl velocity quick stop", 0x604A, "A525"),
    pair!(
        0x604B,
        "vl set-point factor",
        I16,
        "vl set-point factor numerator",
        1,
        "vl set-point factor denominator",
        1,
        "",
        "A526"
    ),
    pair!(
        0x604C,
        "vl dimension factor",
        I32,
        "vl dimension factor numerator",
        1,
        "vl dimension factor denominator",
        1,
        "",
        "A527"
    ),
    Object::var(
        0x605A,
        Value::Ram,
        entries![e(0, "Quick stop option code", I16, RW)
            .rx()
            .default_value(2)
            .saved()],
    )
    .note("A536; CiA 402 values 0–8"),
    Object::var(
        0x605E,
        Value::Ram,
        entries![e(0, "Fault reaction option code", I16, RW)
            .rx()
            .default_value(2)
            .saved()],
    )
    .note("A540; CiA 402 values 0–4"),
    Object::var(
        0x6060,
        Value::Ram,
        entries![rt(0, "Modes of operation", I8).default_value(8).saved()],
    )
    .note("A541; -1, 0, 1, 2, 3, 4, 6, 7, 8, 9, 10"),
    Object::var(
        0x6061,
        Value::Live,
        entries![ro_tx(0, "Modes of operation display", I8)],
    )
    .note("A542"),
    Object::var(
        0x6064,
        Value::Live,
        entries![ro_tx(0, "Position actual value", I32).unit(POS)],
    )
    .note("A545"),
    Object::var(
        0x6065,
        Value::Ram,
        entries![rt(0, "Following error window", U32)
            .default_value(0xFFFF_FFFF)
            .unit(POS)
            .saved()],
    )
    .note("A546; FFFFFFFFh = monitoring off (CiA 402)"),
    Object::var(
        0x6066,
        Value::Ram,
        entries![rt(0, "Following error time out", U16)
            .default_value(10)
            .unit("ms")
            .saved()],
    )
    .note("A547"),
    Object::var(
        0x606C,
        Value::Live,
        entries![ro_tx(0, "Velocity actual value", I32).unit(VEL)],
    )
    .note("A553"),
    Object::var(
        0x6071,
        Value::Ram,
        entries![rt(0, "Target torque", I16).unit(TRQ)],
    )
    .note("A558"),
    Object::var(
        0x6072,
        Value::Ram,
        entries![rt(0, "Max torque", U16).default_value(3000).unit(TRQ).saved()],
    )
    .note("A559; default: placeholder until the motion core"),
    Object::var(
        0x6073,
        Value::Ram,
        entries![rt(0, "Max current", U16).default_value(3000).unit("0.1 %").saved()],
    )
    .note("issue 34 (not in the source's list, CiA 402): the motor's peak current in ‰ of 6075h; the current limit is the lowest of it, 2415h.02 (P-133) and the i²t limit (U10); default 300 % (6 A of 2 A)"),
    Object::var(
        0x6075,
        Value::Ram,
        entries![e(0, "Motor rated current", U32, RW)
            .range(1, 1_000_000)
            .default_value(2000)
            .unit("mA")
            .saved()],
    )
    .note("issue 34 (CiA 402): the motor's rated current (dq amplitude, the phase current's peak): 6073h and 6078h (PNU 1102) are ‰ of it, the i²t model's 100 %; 0 refused; default 2 A"),
    Object::var(
        0x6076,
        Value::Live,
        entries![ro_tx(0, "Rated torque", U32).unit("mNm")],
    )
    .note("A563; ro (the source lists it TxPDO only): kt (B17) × rated current (6075h), from the motor data"),
    Object::var(
        0x6077,
        Value::Live,
        entries![ro_tx(0, "Torque actual value", I16).unit(TRQ)],
    )
    .note("A564"),
    Object::var(
        0x6078,
        Value::Live,
        entries![ro_tx(0, "Current actual value", I16).unit(TRQ)],
    )
    .note("A565"),
    Object::var(
        0x6079,
        Value::Live,
        entries![ro_tx(0, "DC link circuit voltage", U32).unit("mV")],
    )
    .note("A566"),
    Object::var(
        0x607A,
        Value::Ram,
        entries![rt(0, "Target position", I32).unit(POS)],
    )
    .note("A567"),
    pair!(
        0x607B,
        "Position range limit",
        I32,
        "Min position range limit",
        0,
        "Max position range limit",
        0,
        POS,
        "A568; [0] no function, [1] revolution length (endless axis)"
    ),
    Object::var(
        0x607C,
        Value::Ram,
        entries![rt(0, "Home offset", I32).unit(POS).saved()],
    )
    .note("A569"),
    pair!(
        0x607D,
        "Software position limit",
        I32,
        "Min position limit",
        0,
        "Max position limit",
        0,
        POS,
        "A570; min = max disables the limits"
    ),
    Object::var(
        0x607E,
        Value::Ram,
        entries![e(0, "Polarity", U8, RW).rx().saved()],
    )
    .note("A571; only bit 7 has a function"),
    Object::var(
        0x607F,
        Value::Ram,
        entries![rt(0, "Max profile velocity", U32)
            .default_value(50 * REV_INC)
            .unit(VEL)
            .saved()],
    )
    .note("A572; default 50 rev/s: placeholder until the motion core"),
    Object::var(
        0x6080,
        Value::Ram,
        entries![e(0, "Max motor speed", U32, RW)
            .range(1, 100_000)
            .default_value(6000)
            .unit("rpm")
            .saved()],
    )
    .note("issue 34 (CiA 402; the manual's B83 \"v-max motor\", declared once here): the motor's highest speed; the cascade's speed limit is the lower of it and I10; default 6000 rpm"),
    Object::var(
        0x6081,
        Value::Ram,
        entries![rt(0, "Profile velocity", U32)
            .default_value(10 * REV_INC)
            .unit(VEL)
            .saved()],
    )
    .note("A574"),
    Object::var(
        0x6083,
        Value::Ram,
        entries![rt(0, "Profile acceleration", U32)
            .default_value(100 * REV_INC)
            .unit(ACC)
            .saved()],
    )
    .note("A576"),
    Object::var(
        0x6084,
        Value::Ram,
        entries![rt(0, "Profile deceleration", U32)
            .default_value(100 * REV_INC)
            .unit(ACC)
            .saved()],
    )
    .note("A577"),
    Object::var(
        0x6085,
        Value::Ram,
        entries![rt(0, "Quick stop deceleration", U32)
            .default_value(1000 * REV_INC)
            .unit(ACC)
            .saved()],
    )
    .note("A578"),
    Object::var(
        0x6087,
        Value::Ram,
        entries![rt(0, "Torque slope", U32)
            .default_value(10_000)
            .unit("0.1 %/s")
            .saved()],
    )
    .note("A561"),
    Object::new(
        0x6091,
        "Gear ratio",
        Array,
        entries![
            count_entry(2),
            rt(1, "Motor revolutions", U32)
                .range(1, u32::MAX as i64)
                .default_value(1)
                .saved(),
            rt(2, "Shaft revolutions", U32)
                .range(1, u32::MAX as i64)
                .default_value(1)
                .saved(),
        ],
        Value::Ram,
    )
    .note("A584"),
    Object::new(
        0x6092,
        "Feed constant",
        Array,
        entries![
            count_entry(2),
            rt(1, "Feed", U32)
                .range(1, u32::MAX as i64)
                .default_value(REV_INC)
                .unit(POS)
                .saved(),
            rt(2, "Shaft revolutions", U32)
                .range(1, u32::MAX as i64)
                .default_value(1)
                .saved(),
        ],
        Value::Ram,
    )
    .note("A585"),
    Object::var(
        0x6098,
        Value::Ram,
        entries![e(0, "Homing method", I8, RW).default_value(35).saved()],
    )
    .note("A586; one of 60E3h"),
    pair!(
        0x6099,
        "Homing speeds",
        U32,
        "Speed during search for switch",
        2 * REV_INC,
        "Speed during search for zero",
        REV_INC / 4,
        VEL,
        "A587"
    ),
    Object::var(
        0x609A,
        Value::Ram,
        entries![rt(0, "Homing acceleration", U32)
            .default_value(100 * REV_INC)
            .unit(ACC)
            .saved()],
    )
    .note("A588: acceleration and deceleration"),
    Object::var(
        0x60A3,
        Value::Ram,
        entries![e(0, "Profile jerk use", U8, RW).default_value(1).saved()],
    )
    .note("A589"),
    Object::new(
        0x60A4,
        "Profile jerk",
        Array,
        entries![
            count_entry(1),
            rt(1, "Profile jerk 1", U32)
                .default_value(1000 * REV_INC)
                .unit("inc/s³")
                .saved(),
        ],
        Value::Ram,
    )
    .note("A590"),
    Object::var(
        0x60B1,
        Value::Ram,
        entries![rt(0, "Velocity offset", I32).unit(VEL)],
    )
    .note("A592"),
    Object::var(
        0x60B2,
        Value::Ram,
        entries![rt(0, "Torque offset", I16).unit(TRQ)],
    )
    .note("A593"),
    Object::var(0x60B8, Value::Ram, entries![rt(0, "Touch probe function", U16)]).note("A594"),
    Object::var(0x60B9, Value::Live, entries![ro_tx(0, "Touch probe status", U16)]).note("A595"),
    Object::var(
        0x60BA,
        Value::Live,
        entries![ro_tx(0, "Touch probe position 1 positive value", I32).unit(POS)],
    )
    .note("A596"),
    Object::var(
        0x60BB,
        Value::Live,
        entries![ro_tx(0, "Touch probe position 1 negative value", I32).unit(POS)],
    )
    .note("A597"),
    Object::var(
        0x60BC,
        Value::Live,
        entries![ro_tx(0, "Touch probe position 2 positive value", I32).unit(POS)],
    )
    .note("A598"),
    Object::var(
        0x60BD,
        Value::Live,
        entries![ro_tx(0, "Touch probe position 2 negative value", I32).unit(POS)],
    )
    .note("A599"),
    Object::var(
        0x60C0,
        Value::Ram,
        entries![e(0, "Interpolation sub mode select", I16, RW).rx().saved()],
    )
    .note("A600; 0 = linear"),
    Object::new(
        0x60C1,
        "Interpolation data record",
        Array,
        entries![count_entry(1), rt(1, "1st set-point", I32).unit(POS),],
        Value::Ram,
    )
    .note("A601"),
    Object::new(
        0x60C2,
        "Interpolation time period",
        Record,
        entries![
            count_entry(2),
            e(1, "Interpolation time period value", U8, RW)
                .rx()
                .default_value(1)
                .saved(),
            e(2, "Interpolation time index", I8, RW)
                .rx()
                .range(-128, 63)
                .default_value(-3)
                .saved(),
        ],
        Value::Ram,
    )
    .note("A602: period = value · 10^index s"),
    Object::new(
        0x60C4,
        "Interpolation data configuration",
        Record,
        entries![
            // the source prints 5 but lists subs 1–6; the standard's 6 is used
            count_entry(6),
            e(1, "Maximum buffer size", U32, RO).default_value(1),
            e(2, "Actual buffer size", U32, RW).default_value(1),
            e(3, "Buffer organisation", U8, RW),
            e(4, "Buffer position", U16, RW),
            e(5, "Size of data record", U8, WO),
            e(6, "Buffer clear", U8, WO),
        ],
        Value::Ram,
    )
    .note("A603; no function"),
    Object::var(
        0x60C5,
        Value::Ram,
        entries![rt(0, "Max acceleration", U32)
            .default_value(1000 * REV_INC)
            .unit(ACC)
            .saved()],
    )
    .note("A604"),
    Object::var(
        0x60C6,
        Value::Ram,
        entries![rt(0, "Max deceleration", U32)
            .default_value(1000 * REV_INC)
            .unit(ACC)
            .saved()],
    )
    .note("A605"),
    Object::new(
        0x60D0,
        "Touch probe source",
        Array,
        entries![
            count_entry(2),
            e(1, "Touch probe 1 source", I16, RW).default_value(1).saved(),
            e(2, "Touch probe 2 source", I16, RW).default_value(2).saved(),
        ],
        Value::Ram,
    )
    .note("I110, I126"),
    Object::new(
        0x60E3,
        "Supported homing methods",
        Array,
        &SUPPORTED_HOMING,
        Value::Const,
    )
    .note("A619"),
    Object::new(
        0x60E4,
        "Additional position actual value",
        Array,
        entries![
            count_entry(1),
            ro_tx(1, "1st additional position actual value", I32).unit(POS),
        ],
        Value::Live,
    )
    .note("A620"),
    Object::var(
        0x60F2,
        Value::Ram,
        entries![e(0, "Positioning option code", U16, RW).rx().saved()],
    )
    .note("A621"),
    Object::var(
        0x60F4,
        Value::Live,
        entries![ro_tx(0, "Following error actual value", I32).unit(POS)],
    )
    .note("A632"),
    Object::var(0x60FD, Value::Live, entries![ro_tx(0, "Digital inputs", U32)]).note("A636"),
    Object::new(
        0x60FE,
        "Digital outputs",
        Array,
        entries![
            count_entry(2),
            e(1, "Physical outputs", U32, RW).rx(),
            e(2, "Bit mask", U32, RW).rx(),
        ],
        Value::Ram,
    )
    .note("A637; not in Tab. 34 (X-01): the CiA 402 standard array"),
    Object::var(
        0x60FF,
        Value::Ram,
        entries![rt(0, "Target velocity", I32).unit(VEL)],
    )
    .note("A638"),
    Object::var(
        0x6502,
        Value::Const,
        entries![e(0, "Supported drive modes", U32, RO).default_value(SUPPORTED_DRIVE_MODES as i64)],
    ),
];
