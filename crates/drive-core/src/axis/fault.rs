//! The axis' fault: the event it latches ([`Axis::raise`]) and what T13
//! and T15 do to 603Fh, the error register and the reported
//! [`FaultChange`].

use super::*;

impl Axis {
    /// Latches `ev` as the axis' fault (T13 in the next cycle); a fault
    /// already present or latched keeps its own.
    pub(super) fn raise(&mut self, ev: Event) {
        self.raise_with(ev, None);
    }

    /// [`raise`](Self::raise) with the event's own reaction (`None`: 605Eh).
    pub(super) fn raise_with(&mut self, ev: Event, reaction: Option<FaultReaction>) {
        if self.dc.state().is_fault() || self.event.is_some() {
            return;
        }
        let code = fault_code_for_event(ev.number.min(255) as u8).map_or(0x1000, |(c, _)| c);
        self.event = Some(ev);
        self.dc.raise_fault(FaultEvent { code, reaction });
    }

    /// The fault change, 603Fh and the error register on T13 / T15.
    pub(super) fn on_transition(
        &mut self,
        t: Option<Transition>,
        od: &mut DriveObjects,
    ) -> Option<FaultChange> {
        let t = t?;
        match t.number {
            13 => {
                let fault = match self.event {
                    Some(ev) => Fault::for_event(ev.number.min(255) as u8, ev.cause),
                    None => Fault {
                        code: self.dc.fault().map_or(GENERIC_ERROR, |f| f.code),
                        register: error_register::GENERIC,
                        event: 0,
                        cause: 0,
                    },
                };
                self.error_code = fault.code;
                self.error_register = fault.register | error_register::GENERIC;
                self.window.put(od, 0x603F, 0, i64::from(fault.code));
                Some(FaultChange::Raised(fault))
            }
            15 => {
                self.event = None;
                self.error_code = 0;
                self.error_register = 0;
                self.window.put(od, 0x603F, 0, 0);
                Some(FaultChange::Cleared)
            }
            _ => None,
        }
    }
}
