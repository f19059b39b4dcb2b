//! The drive's faults in CiA terms (spec §8.3): each E82 event has a CiA
//! 402 error code (603Fh) and CiA 301 error register bits, from S Tab. 23.
//! An axis reports a fault change ([`FaultChange`]); a fieldbus personality
//! turns it into its bus's message (EtherCAT: an EMCY, `crate::emcy`).

use od::error_register::{COMMUNICATION as COM, CURRENT as CUR, GENERIC as GEN};
use od::error_register::{TEMPERATURE as TEMP, VOLTAGE as VOLT};

/// 1000h: generic error (P's code for event 80; the code of an event the
/// table does not list).
pub const GENERIC_ERROR: u16 = 0x1000;

/// A fault an axis raised.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fault {
    /// CiA 402 error code (603Fh).
    pub code: u16,
    /// CiA 301 error register bits of the fault.
    pub register: u8,
    /// E82 event type (0 when the fault has no event).
    pub event: u8,
    /// E43 cause.
    pub cause: u8,
}

impl Fault {
    /// The fault of event `e82` with cause `e43`: code and register from
    /// [`fault_code_for_event`], 1000h / 01h for an event the table lacks.
    pub fn for_event(e82: u8, e43: u8) -> Self {
        let (code, register) = fault_code_for_event(e82).unwrap_or((GENERIC_ERROR, GEN));
        Self {
            code,
            register,
            event: e82,
            cause: e43,
        }
    }
}

/// What changed in an axis' fault state in a cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaultChange {
    /// The axis entered Fault (T13).
    Raised(Fault),
    /// The axis left Fault (T15).
    Cleared,
}

/// E82 event 30 "Inactive": byte 4 of the fault-cleared EMCY.
pub const E82_INACTIVE: u8 = 30;

/// One E82 event of the drive's fault table (spec §8.3, S Tab. 23): its
/// number, the name the manual prints, its CiA 402 error code and CiA 301
/// error register bits. The one declaration of the drive's faults: the EMCY
/// codes ([`fault_code_for_event`]) and the PROFINET diagnosis texts of the
/// GSDML (`crates/gsdml`, `ChannelDiagList`) both read it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EventInfo {
    /// E82 event number.
    pub number: u8,
    /// Name as S prints it (P's where only P lists the event).
    pub name: &'static str,
    /// CiA 402 error code (603Fh); 0000h for event 30 "Inactive".
    pub code: u16,
    /// CiA 301 error register bits.
    pub register: u8,
}

const fn ev(number: u8, name: &'static str, code: u16, register: u8) -> EventInfo {
    EventInfo {
        number,
        name,
        code,
        register,
    }
}

/// The drive's E82 events in S Tab. 23 order (event 80 from P). Event 30
/// "Inactive" is no fault: it marks a fault cleared.
pub const EVENTS: [EventInfo; 51] = [
    ev(30, "Inactive", 0x0000, 0x00),
    ev(31, "Short/ground", 0x2110, CUR),
    ev(32, "Short/ground internal", 0x2230, CUR),
    ev(33, "Overcurrent", 0x2310, CUR),
    ev(36, "High voltage", 0x3110, VOLT),
    ev(46, "Low voltage", 0x3120, VOLT),
    ev(83, "Failure of one/all phases (mains)", 0x3130, GEN),
    ev(84, "Drop in mains voltage with power section active", 0x3180, GEN),
    ev(38, "Temperature drive controller sensor", 0x4210, TEMP),
    ev(39, "Overtemperature drive controller i2t", 0x4280, TEMP),
    ev(59, "Overtemperature drive controller i2t", 0x4280, TEMP),
    ev(41, "Temp.MotorTMP", 0x4310, TEMP),
    ev(45, "Overtemp.motor i2t", 0x4380, TEMP),
    ev(34, "Hardware fault", 0x5200, GEN),
    ev(35, "Watchdog", 0x6010, GEN),
    ev(57, "Runtime requirement", 0x6010, GEN),
    ev(71, "Firmware", 0x6010, GEN),
    ev(40, "Invalid data", 0x6320, GEN),
    ev(70, "Parameter consistency", 0x6320, GEN),
    ev(86, "Unknown LeanMotor", 0x6330, GEN),
    ev(48, "Brake release monitoring", 0x7110, GEN),
    ev(49, "Brake", 0x7110, GEN),
    ev(72, "Brake test timeout", 0x7110, GEN),
    ev(73, "Axis 2 brake test timeout", 0x7110, GEN),
    ev(42, "TempBrakeRes", 0x7110, TEMP),
    ev(69, "Motor connection", 0x7120, GEN),
    ev(81, "Motor allocation", 0x7120, GEN),
    ev(37, "Motor encoder", 0x7303, GEN),
    ev(76, "Position encoder", 0x7304, GEN),
    ev(77, "Master encoder", 0x7304, GEN),
    ev(79, "Motor/position encoder plausibility", 0x7304, GEN),
    ev(52, "Communication", 0x7500, COM),
    ev(88, "Control panel", 0x7580, GEN),
    ev(47, "Torque/force-max. limit", 0x8311, GEN),
    ev(56, "Overspeed", 0x8400, GEN),
    ev(53, "Limit switch", 0x8500, GEN),
    ev(85, "Excessive jump in reference value", 0x8510, GEN),
    ev(51, "Virtual master software limit switch", 0x8600, GEN),
    ev(54, "Following error", 0x8611, GEN),
    ev(78, "Position limit cyclic", 0x8612, GEN),
    ev(60, "Application event 0", 0xFF00, GEN),
    ev(61, "Application event 1", 0xFF01, GEN),
    ev(62, "Application event 2", 0xFF02, GEN),
    ev(63, "Application event 3", 0xFF03, GEN),
    ev(64, "Application event 4", 0xFF04, GEN),
    ev(65, "Application event 5", 0xFF05, GEN),
    ev(66, "Application event 6", 0xFF06, GEN),
    ev(67, "Application event 7", 0xFF07, GEN),
    ev(44, "External fault 1", 0xFF09, GEN),
    ev(68, "External fault 2", 0xFF0A, GEN),
    ev(80, "Illegal action", GENERIC_ERROR, GEN),
];

/// The event `e82` of [`EVENTS`], if the table lists it.
pub fn event(e82: u8) -> Option<&'static EventInfo> {
    EVENTS.iter().find(|e| e.number == e82)
}

/// Error code and CiA error register for a device fault with E82 event `e82` (spec
/// §8.3, S Tab. 23), from [`EVENTS`]; `None` for events S does not list. Event 80
/// (1000h, generic) is from P.
pub fn fault_code_for_event(e82: u8) -> Option<(u16, u8)> {
    event(e82).map(|e| (e.code, e.register))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn e089_fault_table() {
        let cases: &[(u8, u16, u8)] = &[
            (30, 0x0000, 0x00),
            (31, 0x2110, 0x02),
            (32, 0x2230, 0x02),
            (33, 0x2310, 0x02),
            (36, 0x3110, 0x04),
            (46, 0x3120, 0x04),
            (83, 0x3130, 0x01),
            (84, 0x3180, 0x01),
            (38, 0x4210, 0x08),
            (39, 0x4280, 0x08),
            (59, 0x4280, 0x08),
            (41, 0x4310, 0x08),
            (45, 0x4380, 0x08),
            (34, 0x5200, 0x01),
            (35, 0x6010, 0x01),
            (57, 0x6010, 0x01),
            (71, 0x6010, 0x01),
            (40, 0x6320, 0x01),
            (70, 0x6320, 0x01),
            (86, 0x6330, 0x01),
            (69, 0x7120, 0x01),
            (81, 0x7120, 0x01),
            (37, 0x7303, 0x01),
            (76, 0x7304, 0x01),
            (77, 0x7304, 0x01),
            (79, 0x7304, 0x01),
            (52, 0x7500, 0x10),
            (88, 0x7580, 0x01),
            (47, 0x8311, 0x01),
            (56, 0x8400, 0x01),
            (53, 0x8500, 0x01),
            (85, 0x8510, 0x01),
            (51, 0x8600, 0x01),
            (54, 0x8611, 0x01),
            (78, 0x8612, 0x01),
            (44, 0xFF09, 0x01),
            (68, 0xFF0A, 0x01),
            (80, 0x1000, 0x01),
        ];
        for &(e82, code, reg) in cases {
            assert_eq!(fault_code_for_event(e82), Some((code, reg)), "event {e82}");
        }
        for n in 0..8u8 {
            assert_eq!(fault_code_for_event(60 + n), Some((0xFF00 + u16::from(n), 0x01)));
        }
        // FF08h is unused; unlisted events have no entry and fall back to 1000h/01h.
        for e82 in (0..=255u8).filter(|e| fault_code_for_event(*e).is_some()) {
            assert_ne!(fault_code_for_event(e82).unwrap().0, 0xFF08);
        }
        for e82 in [0u8, 29, 43, 50, 55, 58, 74, 75, 82, 87, 89, 255] {
            assert_eq!(fault_code_for_event(e82), None, "event {e82}");
            let e = Fault::for_event(e82, 0);
            assert_eq!((e.code, e.register), (0x1000, 0x01));
        }
    }

    #[test]
    fn e089_events_are_listed_once_with_a_name() {
        for (i, e) in EVENTS.iter().enumerate() {
            assert!(!e.name.is_empty(), "event {}", e.number);
            assert!(
                EVENTS.iter().skip(i + 1).all(|o| o.number != e.number),
                "event {} twice",
                e.number
            );
        }
        assert_eq!(event(54).map(|e| e.name), Some("Following error"));
    }

    #[test]
    fn e090_brake_chopper_register() {
        assert_eq!(fault_code_for_event(42), Some((0x7110, 0x08)));
        for e82 in [48, 49, 72, 73] {
            assert_eq!(fault_code_for_event(e82), Some((0x7110, 0x01)));
        }
    }
}
