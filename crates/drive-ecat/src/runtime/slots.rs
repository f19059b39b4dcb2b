//! The entries the runtime reads or writes in every control cycle, SYNC0
//! and frame event, resolved once.

use super::*;

/// The entries the runtime reads or writes in every control cycle, SYNC0
/// and frame event, resolved once (a load or store each instead of a
/// dictionary lookup; docs/architecture.md, cycle cost). `None`: not an
/// integer in RAM (reads give the default, writes are dropped).
#[derive(Debug, Clone, Copy)]
pub(super) struct RuntimeSlots {
    pub(super) a149: Option<Slot>,
    pub(super) a150: Option<Slot>,
    pub(super) a290: Option<Slot>,
    pub(super) a291: Option<Slot>,
    pub(super) a292: Option<Slot>,
    pub(super) a296: Option<Slot>,
    pub(super) a298: Option<Slot>,
    pub(super) a261: [Option<Slot>; 4],
    /// 1C32h:0B, 1C33h:0B SM-event missed.
    pub(super) sm_missed: [Option<Slot>; 2],
    /// 1C32h:20, 1C33h:20 sync error.
    pub(super) sync_error: [Option<Slot>; 2],
    /// 1001h error register.
    pub(super) error_register: Option<Slot>,
    /// 10F3h:04 (A250) new messages.
    pub(super) new_messages: Option<Slot>,
    /// A255 device state (ESM state, +16 with an error).
    pub(super) a255: Option<Slot>,
}

impl RuntimeSlots {
    pub(super) const NONE: Self = Self {
        a149: None,
        a150: None,
        a290: None,
        a291: None,
        a292: None,
        a296: None,
        a298: None,
        a261: [None; 4],
        sm_missed: [None; 2],
        sync_error: [None; 2],
        error_register: None,
        new_messages: None,
        a255: None,
    };

    pub(super) fn resolve(od: &DriveObjects) -> Self {
        let s = |index: u16, sub: u8| od.slot(index, sub);
        Self {
            a149: s(A149, 0),
            a150: s(A150, 0),
            a290: s(A290, 0),
            a291: s(A291, 0),
            a292: s(A292, 0),
            a296: s(A296, 0),
            a298: s(A298, 0),
            a261: [s(A261, 1), s(A261, 2), s(A261, 3), s(A261, 4)],
            sm_missed: [s(0x1C32, 0x0B), s(0x1C33, 0x0B)],
            sync_error: [s(0x1C32, 0x20), s(0x1C33, 0x20)],
            error_register: s(0x1001, 0),
            new_messages: s(0x10F3, 4),
            a255: s(A255, 0),
        }
    }

    /// Every slot, for the completeness test.
    #[cfg(test)]
    pub(super) fn all(&self) -> [Option<Slot>; 18] {
        let [r0, r1, r2, r3] = self.a261;
        let [m0, m1] = self.sm_missed;
        let [e0, e1] = self.sync_error;
        [
            self.a149,
            self.a150,
            self.a290,
            self.a291,
            self.a292,
            self.a296,
            self.a298,
            r0,
            r1,
            r2,
            r3,
            m0,
            m1,
            e0,
            e1,
            self.error_register,
            self.new_messages,
            self.a255,
        ]
    }
}

#[cfg(test)]
mod slot_tests {
    use super::*;

    /// Every entry the cyclic paths write has a RAM slot (a missing one
    /// would drop A261, 1C32h or 1001h silently), and no two share one.
    #[test]
    fn runtime_slots_resolve_every_entry() {
        let all = RuntimeSlots::resolve(&DriveObjects::new()).all();
        for (k, s) in all.iter().enumerate() {
            assert!(s.is_some(), "slot {k} missing");
            assert!(!all[..k].contains(s), "slot {k} shared");
        }
    }
}
