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

/// Error code and CiA error register for a device fault with E82 event `e82` (spec
/// §8.3, S Tab. 23); `None` for events S does not list. Event 80 (1000h,
/// generic) is from P.
pub fn fault_code_for_event(e82: u8) -> Option<(u16, u8)> {
    Some(match e82 {
        30 => (0x0000, 0x00),
        31 => (0x2110, CUR),
        32 => (0x2230, CUR),
        33 => (0x2310, CUR),
        36 => (0x3110, VOLT),
        46 => (0x3120, VOLT),
        83 => (0x3130, GEN),
        84 => (0x3180, GEN),
        38 => (0x4210, TEMP),
        39 | 59 => (0x4280, TEMP),
        41 => (0x4310, TEMP),
        45 => (0x4380, TEMP),
        34 => (0x5200, GEN),
        35 | 57 | 71 => (0x6010, GEN),
        40 | 70 => (0x6320, GEN),
        86 => (0x6330, GEN),
        48 | 49 | 72 | 73 => (0x7110, GEN),
        42 => (0x7110, TEMP),
        69 | 81 => (0x7120, GEN),
        37 => (0x7303, GEN),
        76 | 77 | 79 => (0x7304, GEN),
        52 => (0x7500, COM),
        88 => (0x7580, GEN),
        47 => (0x8311, GEN),
        56 => (0x8400, GEN),
        53 => (0x8500, GEN),
        85 => (0x8510, GEN),
        51 => (0x8600, GEN),
        54 => (0x8611, GEN),
        78 => (0x8612, GEN),
        60..=67 => (0xFF00 + u16::from(e82 - 60), GEN),
        44 => (0xFF09, GEN),
        68 => (0xFF0A, GEN),
        80 => (GENERIC_ERROR, GEN),
        _ => return None,
    })
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
    fn e090_brake_chopper_register() {
        assert_eq!(fault_code_for_event(42), Some((0x7110, 0x08)));
        for e82 in [48, 49, 72, 73] {
            assert_eq!(fault_code_for_event(e82), Some((0x7110, 0x01)));
        }
    }
}
