//! The PNU catalogue (spec `profidrive.md` §10): each PROFIdrive parameter
//! number as a view of the drive core's one object declaration, not a
//! second store. A PNU names the core object it stands for and the unit
//! class its value is converted with (PROFINET units, [`motion::units`],
//! against the object's CiA 402 user units, P-214); the few that are the
//! profile's own state (CW1, ZSW1, the operating mode, the last error, the
//! identification, save) say so.
//!
//! PNUs (< 0x1000) and CANopen indices (≥ 0x1000) share one 16-bit index
//! space (P-057); every CANopen object of the drive is reachable besides
//! (P-045), in its CiA 402 units. Two CANopen indices of the Metronix drive
//! that the Example Function block maps, 2415h.02 (current limit, mA) and
//! 2416h.02 (speed limit in torque mode), are not objects of this drive:
//! the catalogue serves them as the profile's own values (docs/conformance.md).

use od::DataType;
use profidrive::{Addr, PdError};

/// How a PNU's value converts between the bus and the core object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    /// As it is.
    None,
    /// A position: PROFINET position unit ⇄ the object's user units.
    Position,
    /// A velocity: PROFINET velocity unit ⇄ user units/s.
    Velocity,
    /// An acceleration: PROFINET acceleration unit ⇄ user units/s².
    Acceleration,
    /// A velocity: PROFINET velocity unit ⇄ rpm (the vl objects 6042h…).
    Rpm,
    /// An acceleration: PROFINET acceleration unit ⇄ a vl ramp (rpm per
    /// 1 s in 6048h/6049h).
    RpmPerSecond,
}

/// Which field of a position record a PNU names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RecordField {
    /// Target position.
    Target,
    /// Profile velocity.
    ProfileVelocity,
    /// End velocity.
    EndVelocity,
    /// Acceleration.
    Acceleration,
    /// Deceleration.
    Deceleration,
    /// Write: acceleration and deceleration; read: acceleration.
    BothAccelerations,
}

/// Which jog record(s) a jog PNU names (P-173…P-175).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Jog {
    /// Both (1040: write both, read the positive one).
    Both,
    /// Record 259 (TIPP0).
    Positive,
    /// Record 260 (TIPP1).
    Negative,
}

/// Where a PNU's value lives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// A core object of the axis (axis-A numbering; the axis' own index is
    /// taken for axis B).
    Object {
        /// CiA 402 or manufacturer index, axis A.
        index: u16,
        /// Subindex.
        sub: u8,
    },
    /// The selected position record (PNU 1000 → J400) field (PNU 1001.x).
    SelectedRecord(RecordField),
    /// A jog record's field (profile velocity or one of the accelerations).
    JogRecord(Jog, RecordField),
    /// Both vl ramps 6048h and 6049h (1011.2).
    VlBothRamps,
    /// CW1 as last received (967).
    Cw1,
    /// ZSW1 (968).
    Zsw1,
    /// The operating mode (1500): 0x04 / 0x08 / 0x10 ⇄ 6060h/6061h.
    OperatingMode,
    /// The homing method in PROFIdrive numbering (1050), copied into 6098h
    /// at the homing start.
    HomingMethod,
    /// The digital inputs in the manual's bit map (1141).
    DigitalInputs,
    /// The last error, main × 16 + sub (1600, P-217).
    LastError,
    /// PNU 964.sub (identification).
    Identification,
    /// Save (971, P-199…P-201).
    Save,
    /// The profile's own RAM value (2415h.02, 2416h.02).
    Own,
    /// The telegram editor (2020…2022, ours: [`super::telegram_config`]).
    TelegramEditor,
    /// The position profile type (1003): 0 = jerk filter 0, what record
    /// tasks do (P-147); 1, the automatic jerk filter, is not built.
    ProfileType,
}

/// One PNU.sub.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pnu {
    /// The address.
    pub addr: Addr,
    /// The manual's name (host builds only: the docs and the catalogue's
    /// tests; a bare-metal build keeps the names out of flash).
    #[cfg(not(target_os = "none"))]
    pub name: &'static str,
    /// The type on the bus.
    pub data_type: DataType,
    /// Readable.
    pub readable: bool,
    /// Writable.
    pub writable: bool,
    /// The unit class.
    pub unit: Unit,
    /// Where the value is.
    pub source: Source,
}

use DataType::{I32, I8, U16, U32, U8};

/// One catalogue entry (the name only in host builds).
#[cfg_attr(target_os = "none", allow(unused_variables))]
const fn p(pnu: u16, sub: u8, name: &'static str, t: DataType, w: bool, unit: Unit, source: Source) -> Pnu {
    Pnu {
        addr: Addr::new(pnu, sub),
        #[cfg(not(target_os = "none"))]
        name,
        data_type: t,
        readable: true,
        writable: w,
        unit,
        source,
    }
}

const fn obj(index: u16, sub: u8) -> Source {
    Source::Object { index, sub }
}

const RO: bool = false;
const RW: bool = true;

/// The J lines of the record objects (drive-core `objects::records`).
const J400: u16 = drive_core::objects::records::J400;
const J402: u16 = drive_core::objects::records::J402;
const J403: u16 = drive_core::objects::records::J403;
const J404: u16 = drive_core::objects::records::J404;

/// The catalogue, sorted by PNU and subindex.
pub const CATALOGUE: &[Pnu] = &[
    p(
        964,
        0,
        "Manufacturer",
        U16,
        RO,
        Unit::None,
        Source::Identification,
    ),
    p(964, 1, "Device Type", U16, RO, Unit::None, Source::Identification),
    p(964, 2, "Version", U16, RO, Unit::None, Source::Identification),
    p(
        964,
        3,
        "Creation date: year",
        U16,
        RO,
        Unit::None,
        Source::Identification,
    ),
    p(
        964,
        4,
        "Creation date: day/month",
        U16,
        RO,
        Unit::None,
        Source::Identification,
    ),
    p(967, 0, "Control word 1", U16, RW, Unit::None, Source::Cw1),
    p(968, 0, "Status word 1", U16, RO, Unit::None, Source::Zsw1),
    p(
        971,
        0,
        "Transfer into non-volatile memory",
        U16,
        RW,
        Unit::None,
        Source::Save,
    ),
    p(1000, 0, "Position Set Number", U16, RW, Unit::None, obj(J400, 0)),
    p(
        1001,
        0,
        "Target Position",
        I32,
        RW,
        Unit::Position,
        Source::SelectedRecord(RecordField::Target),
    ),
    p(
        1001,
        1,
        "Profile Velocity",
        I32,
        RW,
        Unit::Velocity,
        Source::SelectedRecord(RecordField::ProfileVelocity),
    ),
    p(
        1001,
        2,
        "End Velocity",
        I32,
        RW,
        Unit::Velocity,
        Source::SelectedRecord(RecordField::EndVelocity),
    ),
    p(
        1001,
        3,
        "Acceleration Positioning",
        U32,
        RW,
        Unit::Acceleration,
        Source::SelectedRecord(RecordField::Acceleration),
    ),
    p(
        1001,
        4,
        "Deceleration Positioning",
        U32,
        RW,
        Unit::Acceleration,
        Source::SelectedRecord(RecordField::Deceleration),
    ),
    p(
        1001,
        5,
        "All Accelerations Positioning",
        U32,
        RW,
        Unit::Acceleration,
        Source::SelectedRecord(RecordField::BothAccelerations),
    ),
    p(1002, 0, "Start Set Number", U8, RW, Unit::None, obj(J402, 0)),
    p(
        1003,
        0,
        "Position Profile Type",
        U16,
        RW,
        Unit::None,
        Source::ProfileType,
    ),
    p(1004, 0, "Override Factor", U16, RW, Unit::None, obj(J403, 0)),
    p(
        1005,
        0,
        "Lower software position limit",
        I32,
        RW,
        Unit::Position,
        obj(0x607D, 1),
    ),
    p(
        1005,
        1,
        "Upper software position limit",
        I32,
        RW,
        Unit::Position,
        obj(0x607D, 2),
    ),
    p(1010, 0, "Target Velocity", I32, RW, Unit::Rpm, obj(0x6042, 0)),
    p(
        1011,
        0,
        "Acceleration Velocity Control",
        U32,
        RW,
        Unit::RpmPerSecond,
        obj(0x6048, 1),
    ),
    p(
        1011,
        1,
        "Deceleration Velocity Control",
        U32,
        RW,
        Unit::RpmPerSecond,
        obj(0x6049, 1),
    ),
    p(
        1011,
        2,
        "All Accelerations Velocity Control",
        U32,
        RW,
        Unit::RpmPerSecond,
        Source::VlBothRamps,
    ),
    p(
        1040,
        0,
        "Symmetrical Jogging Velocity",
        I32,
        RW,
        Unit::Velocity,
        Source::JogRecord(Jog::Both, RecordField::ProfileVelocity),
    ),
    p(
        1040,
        1,
        "Symmetrical Jogging Accelerations",
        U32,
        RW,
        Unit::Acceleration,
        Source::JogRecord(Jog::Both, RecordField::BothAccelerations),
    ),
    p(
        1041,
        0,
        "Jogging Velocity Positive",
        I32,
        RW,
        Unit::Velocity,
        Source::JogRecord(Jog::Positive, RecordField::ProfileVelocity),
    ),
    p(
        1041,
        1,
        "Jogging Acceleration Positive",
        U32,
        RW,
        Unit::Acceleration,
        Source::JogRecord(Jog::Positive, RecordField::Acceleration),
    ),
    p(
        1041,
        2,
        "Jogging Deceleration Positive",
        U32,
        RW,
        Unit::Acceleration,
        Source::JogRecord(Jog::Positive, RecordField::Deceleration),
    ),
    p(
        1041,
        3,
        "Symmetrical Jogging Accelerations Positive",
        U32,
        RW,
        Unit::Acceleration,
        Source::JogRecord(Jog::Positive, RecordField::BothAccelerations),
    ),
    p(
        1042,
        0,
        "Jogging Velocity Negative",
        I32,
        RW,
        Unit::Velocity,
        Source::JogRecord(Jog::Negative, RecordField::ProfileVelocity),
    ),
    p(
        1042,
        1,
        "Jogging Acceleration Negative",
        U32,
        RW,
        Unit::Acceleration,
        Source::JogRecord(Jog::Negative, RecordField::Acceleration),
    ),
    p(
        1042,
        2,
        "Jogging Deceleration Negative",
        U32,
        RW,
        Unit::Acceleration,
        Source::JogRecord(Jog::Negative, RecordField::Deceleration),
    ),
    p(
        1042,
        3,
        "Symmetrical Jogging Accelerations Negative",
        U32,
        RW,
        Unit::Acceleration,
        Source::JogRecord(Jog::Negative, RecordField::BothAccelerations),
    ),
    p(1050, 0, "Homing Method", I8, RW, Unit::None, Source::HomingMethod),
    p(1051, 0, "Home Offset", I32, RW, Unit::Position, obj(0x607C, 0)),
    p(1060, 0, "Thread Speed", I32, RW, Unit::Velocity, obj(J404, 0)),
    p(
        1100,
        0,
        "Position Actual Value",
        I32,
        RO,
        Unit::Position,
        obj(0x6064, 0),
    ),
    p(
        1101,
        0,
        "Velocity Actual Value",
        I32,
        RO,
        Unit::Velocity,
        obj(0x606C, 0),
    ),
    p(
        1102,
        0,
        "Current Actual Value",
        I32,
        RO,
        Unit::None,
        obj(0x6078, 0),
    ),
    // the sample input is touch probe 1 (60B8h configures it, 60D0h:01 its
    // source): its positive and negative edge values (P-188)
    p(
        1110,
        0,
        "Sampling Position Rising Edge",
        I32,
        RO,
        Unit::Position,
        obj(0x60BA, 0),
    ),
    p(
        1110,
        1,
        "Sampling Position Falling Edge",
        I32,
        RO,
        Unit::Position,
        obj(0x60BB, 0),
    ),
    p(
        1141,
        0,
        "Digital Inputs",
        U32,
        RO,
        Unit::None,
        Source::DigitalInputs,
    ),
    // P-157: a RECORD of max sub 2 in the manual, whose subindices 0 and 1
    // it does not name: only .2 exists here (0 and 1 answer error 0x03)
    p(
        1270,
        2,
        "Position Error Tolerance Window",
        U32,
        RW,
        Unit::Position,
        obj(drive_core::params::I23, 0),
    ),
    p(
        1271,
        0,
        "Target Window",
        U32,
        RW,
        Unit::Position,
        obj(drive_core::params::I22, 0),
    ),
    p(
        1272,
        0,
        "Following Error Window",
        U32,
        RW,
        Unit::Position,
        obj(0x6065, 0),
    ),
    // P-160: the second, larger window; its reaction is always the fault 54-2
    p(
        1273,
        0,
        "Position Error Limit",
        U32,
        RW,
        Unit::Position,
        obj(drive_core::params::I21, 0),
    ),
    p(
        1500,
        0,
        "Operating Mode",
        U8,
        RW,
        Unit::None,
        Source::OperatingMode,
    ),
    p(1600, 0, "Last Error Code", U16, RO, Unit::None, Source::LastError),
    // the telegram editor (ours, P-069): selector, the selected telegram's
    // entries and association, apply
    p(
        2020,
        0,
        "Telegram Selector",
        U8,
        RW,
        Unit::None,
        Source::TelegramEditor,
    ),
    p(
        2021,
        0,
        "Telegram Entry 1",
        U32,
        RW,
        Unit::None,
        Source::TelegramEditor,
    ),
    p(
        2021,
        1,
        "Telegram Entry 2",
        U32,
        RW,
        Unit::None,
        Source::TelegramEditor,
    ),
    p(
        2021,
        2,
        "Telegram Entry 3",
        U32,
        RW,
        Unit::None,
        Source::TelegramEditor,
    ),
    p(
        2021,
        3,
        "Telegram Entry 4",
        U32,
        RW,
        Unit::None,
        Source::TelegramEditor,
    ),
    p(
        2021,
        4,
        "Telegram Entry 5",
        U32,
        RW,
        Unit::None,
        Source::TelegramEditor,
    ),
    p(
        2021,
        5,
        "Telegram Entry 6",
        U32,
        RW,
        Unit::None,
        Source::TelegramEditor,
    ),
    p(
        2021,
        6,
        "Telegram Entry 7",
        U32,
        RW,
        Unit::None,
        Source::TelegramEditor,
    ),
    p(
        2021,
        7,
        "Telegram Entry 8",
        U32,
        RW,
        Unit::None,
        Source::TelegramEditor,
    ),
    p(
        2021,
        8,
        "Telegram Entry 9",
        U32,
        RW,
        Unit::None,
        Source::TelegramEditor,
    ),
    p(
        2021,
        9,
        "Telegram Entry 10",
        U32,
        RW,
        Unit::None,
        Source::TelegramEditor,
    ),
    p(
        2021,
        10,
        "Associated Response Telegram",
        U8,
        RW,
        Unit::None,
        Source::TelegramEditor,
    ),
    p(
        2022,
        0,
        "Apply Telegram",
        U16,
        RW,
        Unit::None,
        Source::TelegramEditor,
    ),
    p(0x2415, 2, "limit_current", I32, RW, Unit::None, Source::Own),
    p(0x2416, 2, "limit_speed", I32, RW, Unit::None, Source::Own),
];

/// The entry of `addr`: 0x00 when the PNU does not exist, 0x03 when it
/// exists without this subindex.
pub fn find(addr: Addr) -> Result<&'static Pnu, PdError> {
    let mut known = false;
    for p in CATALOGUE {
        if p.addr.index == addr.index {
            if p.addr.sub == addr.sub {
                return Ok(p);
            }
            known = true;
        }
    }
    Err(if known {
        PdError::FAULTY_SUBINDEX
    } else {
        PdError::IMPERMISSIBLE_PNU
    })
}

/// Whether `index` is in the catalogue's part of the index space (PNUs,
/// and the two Metronix CANopen indices it serves itself).
pub fn is_catalogue_index(index: u16) -> bool {
    index < 0x1000 || CATALOGUE.iter().any(|p| p.addr.index == index)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn p190_the_catalogue_is_sorted_without_duplicates() {
        for w in CATALOGUE.windows(2) {
            let (a, b) = (w[0].addr, w[1].addr);
            assert!((a.index, a.sub) < (b.index, b.sub), "{a:?} before {b:?}");
        }
    }

    #[test]
    fn p190_a_missing_pnu_or_subindex_gets_its_error() {
        assert_eq!(
            find(Addr::new(1001, 5)).unwrap().name,
            "All Accelerations Positioning"
        );
        assert_eq!(find(Addr::new(1001, 6)), Err(PdError::FAULTY_SUBINDEX));
        assert_eq!(find(Addr::new(1007, 0)), Err(PdError::IMPERMISSIBLE_PNU));
        assert!(is_catalogue_index(999) && is_catalogue_index(0x2415) && !is_catalogue_index(0x6040));
    }

    /// Every PNU that is a view of a core object names one the drive
    /// declares, with the access the PNU promises (PNU 1271 once named
    /// 6067h, which this drive does not have).
    #[test]
    fn p190_every_object_view_names_a_declared_entry() {
        use od::Dictionary;
        let objects = drive_core::DriveObjects::new();
        for p in CATALOGUE {
            if let Source::Object { index, sub } = p.source {
                let object = objects.object(index);
                let entry = object.and_then(|o| o.entry(sub));
                let Some(entry) = entry else {
                    panic!(
                        "PNU {:?} ({}): {index:#06x}:{sub} is not declared",
                        p.addr, p.name
                    );
                };
                assert_eq!(p.readable, entry.access.readable(), "{}", p.name);
                if p.writable {
                    assert!(entry.access.writable(), "{}", p.name);
                }
            }
        }
    }
}
