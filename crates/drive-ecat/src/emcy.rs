//! The drive's emergency messages (spec §8.2): the EMCY of a fault change
//! (E82 event, E43 cause, axis; code and register from [`crate::faults`]).
//! The EtherCAT personality sends them through the slave's queue
//! ([`ecat::emcy::Emcy`]).
//!
//! | bytes | 1–2 | 3 | 4 | 5 | 6–7 | 8 |
//! |---|---|---|---|---|---|---|
//! | device fault | error code (LE) | error register | E82 event | E43 cause | 0 | axis |
//! | fault cleared | 0000h | 00h | 1Eh | 0 | 0 | axis |

use crate::faults::{Fault, FaultChange};
use ecat::emcy::{code, Emcy};

/// E82 event 30 "Inactive": byte 4 of the fault-cleared EMCY.
pub const E82_INACTIVE: u8 = 30;

/// Device fault: E82 event type, E43 cause, `axis` 0 = axis A or global, 1 = axis B.
pub const fn device_fault(code: u16, register: u8, e82: u8, e43: u8, axis: u8) -> Emcy {
    Emcy::new(code, register, [e82, e43, 0, 0, axis])
}

/// Device fault for event `e82` with code and register from
/// [`crate::faults::fault_code_for_event`];
/// events outside the table send 1000h / 01h (generic error).
pub fn for_event(e82: u8, e43: u8, axis: u8) -> Emcy {
    of_fault(&Fault::for_event(e82, e43), axis)
}

/// The device-fault EMCY of `fault` on `axis`.
pub const fn of_fault(fault: &Fault, axis: u8) -> Emcy {
    device_fault(fault.code, fault.register, fault.event, fault.cause, axis)
}

/// The EMCY of an axis' fault change: the fault on T13, "fault cleared" on T15.
pub const fn of_change(change: &FaultChange, axis: u8) -> Emcy {
    match change {
        FaultChange::Raised(f) => of_fault(f, axis),
        FaultChange::Cleared => fault_cleared(axis),
    }
}

/// Fault cleared (device left the Fault state): 0000h, 00h, 1Eh (S; P sends 00h).
pub const fn fault_cleared(axis: u8) -> Emcy {
    device_fault(code::NO_ERROR, 0, E82_INACTIVE, 0, axis)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn e087_device_fault_layout() {
        let e = device_fault(0x2310, ecat::emcy::register::CURRENT, 33, 2, 1);
        assert_eq!(e.to_bytes(), [0x10, 0x23, 0x02, 33, 2, 0, 0, 1]);
        assert_eq!(Emcy::parse(&e.to_bytes()), Some(e));
        // Axis A / global.
        assert_eq!(for_event(33, 2, 0).to_bytes()[7], 0);
    }

    /// P's example `43 10 01 29 00 00 00 00` (4310h, Temp.MotorTMP, axis A), read per
    /// the spec's [design] note: error code little-endian (CiA 301) and the table's
    /// register 08h instead of the printed 01h.
    #[test]
    fn e087_p_example_motor_temperature() {
        let e = for_event(41, 0, 0);
        assert_eq!((e.code, e.register), (0x4310, 0x08));
        assert_eq!(e.to_bytes(), [0x10, 0x43, 0x08, 0x29, 0, 0, 0, 0]);
    }

    #[test]
    fn e088_fault_cleared() {
        assert_eq!(fault_cleared(0).to_bytes(), [0, 0, 0, 0x1E, 0, 0, 0, 0]);
        assert_eq!(fault_cleared(1).to_bytes(), [0, 0, 0, 0x1E, 0, 0, 0, 1]);
    }
}
