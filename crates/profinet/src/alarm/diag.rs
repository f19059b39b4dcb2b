//! The diagnosis model: a bounded list of active drive errors per submodule,
//! the "appears" / "disappears" diagnosis alarms it owes the controller (in
//! the order the changes happened, one at a time: diagnosis alarms are low
//! priority and a priority has one outstanding alarm), and the diagnosis
//! records.
//!
//! Alarms for one entry:
//!
//! | change | AlarmType | ChannelProperties.Specifier |
//! |---|---|---|
//! | appears | Diagnosis (0x0001) | Appears |
//! | disappears, others remain on the submodule | Diagnosis (0x0001) | Disappears but others remain |
//! | the submodule's last one disappears | Diagnosis disappears (0x000C) | Disappears |
//!
//! AlarmSpecifier: ChannelDiagnosis and SubmoduleDiagnosisState say whether
//! the submodule still has diagnosis after the change, ARDiagnosisState
//! whether any submodule has.
//!
//! An error that appears and disappears before its alarm went out costs no
//! alarm. Without an AR ([`DiagList::set_alarms`] off) the list follows the
//! changes silently; a new AR sees the present entries in the records and the
//! StationProblemIndicator, not as alarms.

use super::blocks::{
    AlarmSpecifier, AlarmType, ChannelDirection, ChannelProperties, DiagItem, Maintenance, Notification,
    Specifier, Writer, CHANNEL_SUBMODULE, USI_EXT_CHANNEL_DIAGNOSIS,
};
use super::Priority;

/// A drive error HH-S (spec §2.7): main index 1…96; sub-index 0…15
/// ([`crate::model::SUB_ERRORS`]: the manual's S is 0…9, the drive's event
/// causes, which S carries, go to 15 — the GSDML's ExtChannelDiagList); or
/// one of the standard's port diagnoses ([`DriveError::port`]: a topology
/// mismatch of PDPortDataCheck).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct DriveError {
    error_type: u16,
    ext: u16,
}

impl DriveError {
    /// The error HH-S, if HH is 1…96 and S 0…15.
    pub const fn new(main: u8, sub: u8) -> Option<DriveError> {
        if main >= 1 && main <= 96 && sub <= *crate::model::SUB_ERRORS.end() {
            Some(DriveError {
                error_type: 0x1000 + main as u16,
                ext: 0x1000 + sub as u16,
            })
        } else {
            None
        }
    }
    /// A diagnosis of the standard's ChannelErrorType range (0x8000…,
    /// IEC 61158-6-10) with its ExtChannelErrorType, as a port raises it.
    pub const fn port(error_type: u16, ext: u16) -> DriveError {
        DriveError { error_type, ext }
    }
    /// HH (the low octet of ChannelErrorType).
    pub const fn main(self) -> u8 {
        (self.error_type & 0xFF) as u8
    }
    /// S (the low octet of ExtChannelErrorType).
    pub const fn sub(self) -> u8 {
        (self.ext & 0xFF) as u8
    }
    /// ChannelErrorType = 0x1000 + HH, HH as a binary number (Q-13: 22 →
    /// 0x1016, not 0x1022); a port's as given.
    pub const fn channel_error_type(self) -> u16 {
        self.error_type
    }
    /// ExtChannelErrorType = 0x1000 + S; a port's as given.
    pub const fn ext_channel_error_type(self) -> u16 {
        self.ext
    }
}

/// A submodule: where a diagnosis sits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Location {
    /// API.
    pub api: u32,
    /// Slot.
    pub slot: u16,
    /// Subslot.
    pub subslot: u16,
    /// Its module ident number.
    pub module_ident: u32,
    /// Its submodule ident number.
    pub submodule_ident: u32,
}

impl Location {
    fn same(&self, o: &Location) -> bool {
        self.api == o.api && self.slot == o.slot && self.subslot == o.subslot
    }
}

/// Which entries a record read wants.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DiagScope {
    /// One submodule (0x800x).
    Subslot {
        /// API.
        api: u32,
        /// Slot.
        slot: u16,
        /// Subslot.
        subslot: u16,
    },
    /// One slot (0xC00x).
    Slot {
        /// API.
        api: u32,
        /// Slot.
        slot: u16,
    },
    /// One API (0xF00x).
    Api {
        /// API.
        api: u32,
    },
    /// Every submodule of the AR (0xE00x).
    Ar,
}

/// Which severities a record read wants.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DiagFilter {
    /// Faults only (records 0x…A and 0x…B).
    Faults,
    /// Faults and maintenance (records 0x…C).
    All,
}

impl DiagScope {
    /// The scope and filter of a diagnosis record index (0x800A/B/C,
    /// 0xC00A/B/C, 0xE00A/B/C, 0xF00A/B/C), for the submodule addressed by
    /// the read; `None` for other indices.
    pub fn for_record(index: u16, api: u32, slot: u16, subslot: u16) -> Option<(DiagScope, DiagFilter)> {
        let filter = match index & 0x0FFF {
            0x00A | 0x00B => DiagFilter::Faults,
            0x00C => DiagFilter::All,
            _ => return None,
        };
        let scope = match index & 0xF000 {
            0x8000 => DiagScope::Subslot { api, slot, subslot },
            0xC000 => DiagScope::Slot { api, slot },
            0xE000 => DiagScope::Ar,
            0xF000 => DiagScope::Api { api },
            _ => return None,
        };
        Some((scope, filter))
    }

    fn contains(&self, l: &Location) -> bool {
        match *self {
            DiagScope::Subslot { api, slot, subslot } => {
                l.api == api && l.slot == slot && l.subslot == subslot
            }
            DiagScope::Slot { api, slot } => l.api == api && l.slot == slot,
            DiagScope::Api { api } => l.api == api,
            DiagScope::Ar => true,
        }
    }
}

/// Why a record could not be written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RecordError {
    /// The buffer is too short.
    BufferTooShort,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    /// Appeared; its alarm has not gone out.
    PendingAppear,
    /// Its appears alarm is outstanding; `then_clear`: it disappeared since.
    InFlightAppear { then_clear: bool },
    /// Reported (or present without an AR).
    Active,
    /// Disappeared; its alarm has not gone out.
    PendingDisappear,
    /// Its disappears alarm is outstanding; `then_raise`: it appeared again.
    InFlightDisappear { then_raise: bool },
}

impl State {
    /// Present for the controller's view (records, LEDs, specifier).
    fn present(self) -> bool {
        matches!(
            self,
            State::PendingAppear
                | State::InFlightAppear { then_clear: false }
                | State::Active
                | State::InFlightDisappear { then_raise: true }
        )
    }
}

#[derive(Clone, Copy, Debug)]
struct Entry {
    loc: Location,
    error: DriveError,
    maintenance: Maintenance,
    add_value: u32,
    state: State,
    /// Order of the pending change.
    stamp: u64,
}

impl Entry {
    fn is(&self, loc: &Location, error: DriveError) -> bool {
        self.loc.same(loc) && self.error == error
    }

    fn properties(&self, specifier: Specifier) -> ChannelProperties {
        ChannelProperties::new(
            0,
            false,
            self.maintenance,
            specifier,
            ChannelDirection::Manufacturer,
        )
    }

    fn item(&self, specifier: Specifier) -> DiagItem {
        DiagItem {
            channel: CHANNEL_SUBMODULE,
            properties: self.properties(specifier),
            error_type: self.error.channel_error_type(),
            ext_error_type: self.error.ext_channel_error_type(),
            add_value: self.add_value,
        }
    }
}

/// The list is full.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DiagFull;

/// Active diagnoses (at most `N`, disappearing ones included until their
/// alarm is acknowledged).
#[derive(Clone, Debug)]
pub struct DiagList<const N: usize> {
    entries: heapless::Vec<Entry, N>,
    alarms: bool,
    next_stamp: u64,
}

impl<const N: usize> Default for DiagList<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> DiagList<N> {
    /// Empty, alarms off (no AR).
    pub const fn new() -> Self {
        DiagList {
            entries: heapless::Vec::new(),
            alarms: false,
            next_stamp: 0,
        }
    }

    fn stamp(&mut self) -> u64 {
        self.next_stamp = self.next_stamp.wrapping_add(1);
        self.next_stamp
    }

    /// Alarms on (an AR with an alarm CR is up) or off. Either way the
    /// present entries become reported and the absent ones go: a new AR gets
    /// no alarms for what was there before it; an ended AR owes none.
    pub fn set_alarms(&mut self, on: bool) {
        self.alarms = on;
        self.entries.retain(|e| e.state.present());
        for e in self.entries.iter_mut() {
            e.state = State::Active;
        }
    }

    /// A drive error appears on `loc` with severity `maintenance` and
    /// ExtChannelAddValue `add_value`. `Ok(true)` if it is new; `Ok(false)`
    /// if it was present already; `Err` if the list is full.
    pub fn raise(
        &mut self,
        loc: Location,
        error: DriveError,
        maintenance: Maintenance,
        add_value: u32,
    ) -> Result<bool, DiagFull> {
        let stamp = self.stamp();
        let alarms = self.alarms;
        // the order of a new entry's appears alarm; an existing entry's
        // pending change keeps its place
        if let Some(e) = self.entries.iter_mut().find(|e| e.is(&loc, error)) {
            let (state, new) = match e.state {
                State::PendingDisappear => (State::Active, false),
                State::InFlightAppear { .. } => (State::InFlightAppear { then_clear: false }, false),
                State::InFlightDisappear { .. } => (State::InFlightDisappear { then_raise: true }, true),
                s => (s, false),
            };
            e.state = state;
            return Ok(new);
        }
        let state = if alarms {
            State::PendingAppear
        } else {
            State::Active
        };
        self.entries
            .push(Entry {
                loc,
                error,
                maintenance,
                add_value,
                state,
                stamp,
            })
            .map_err(|_| DiagFull)?;
        Ok(true)
    }

    /// A drive error disappears from `loc` (acknowledged). `true` if it was
    /// present.
    pub fn clear(&mut self, loc: &Location, error: DriveError) -> bool {
        let stamp = self.stamp();
        let alarms = self.alarms;
        let Some(i) = self.entries.iter().position(|e| e.is(loc, error)) else {
            return false;
        };
        let Some(e) = self.entries.get_mut(i) else {
            return false;
        };
        let was = e.state.present();
        let state = match e.state {
            State::Active if alarms => Some(State::PendingDisappear),
            State::Active | State::PendingAppear => None,
            State::InFlightAppear { .. } => Some(State::InFlightAppear { then_clear: true }),
            State::InFlightDisappear { .. } => Some(State::InFlightDisappear { then_raise: false }),
            s => Some(s),
        };
        match state {
            Some(s) => {
                if s == State::PendingDisappear && e.state != s {
                    e.stamp = stamp;
                }
                e.state = s;
            }
            None => {
                self.entries.remove(i);
            }
        }
        was
    }

    /// Clears every error on `loc` (`None`: everywhere).
    pub fn clear_all(&mut self, loc: Option<&Location>) {
        let mut hits: heapless::Vec<(Location, DriveError), N> = heapless::Vec::new();
        for e in self.entries.iter().filter(|e| loc.is_none_or(|l| e.loc.same(l))) {
            let _ = hits.push((e.loc, e.error));
        }
        for (l, err) in hits {
            self.clear(&l, err);
        }
    }

    /// Some diagnosis is present (SF LED, StationProblemIndicator).
    pub fn any_present(&self) -> bool {
        self.entries.iter().any(|e| e.state.present())
    }

    /// The present errors of a submodule.
    pub fn present(&self, loc: &Location) -> impl Iterator<Item = DriveError> + '_ {
        let loc = *loc;
        self.entries
            .iter()
            .filter(move |e| e.loc.same(&loc) && e.state.present())
            .map(|e| e.error)
    }

    /// A diagnosis alarm is outstanding.
    pub fn in_flight(&self) -> bool {
        self.entries.iter().any(|e| {
            matches!(
                e.state,
                State::InFlightAppear { .. } | State::InFlightDisappear { .. }
            )
        })
    }

    /// The next diagnosis alarm to send (low priority; sequence number 0
    /// until the alarm CR sets it), or `None` if none is owed or one is
    /// outstanding. Does not change the list: call [`DiagList::sent`] once
    /// the alarm CR took it.
    pub fn next_alarm(&self) -> Option<Notification> {
        if !self.alarms || self.in_flight() {
            return None;
        }
        let e = self
            .entries
            .iter()
            .filter(|e| matches!(e.state, State::PendingAppear | State::PendingDisappear))
            .min_by_key(|e| e.stamp)?;
        let others = |f: &dyn Fn(&Entry) -> bool| {
            self.entries
                .iter()
                .any(|o| !core::ptr::eq(o, e) && o.state.present() && f(o))
        };
        let submodule_has = others(&|o| o.loc.same(&e.loc));
        let ar_has = others(&|_| true);
        let (alarm_type, specifier, sub_diag, ar_diag) = match e.state {
            State::PendingAppear => (AlarmType::DIAGNOSIS, Specifier::Appears, true, true),
            _ if submodule_has => (
                AlarmType::DIAGNOSIS,
                Specifier::DisappearsOthersRemain,
                true,
                true,
            ),
            _ => (
                AlarmType::DIAGNOSIS_DISAPPEARS,
                Specifier::Disappears,
                false,
                ar_has,
            ),
        };
        Some(Notification {
            priority: Priority::Low,
            alarm_type,
            api: e.loc.api,
            slot: e.loc.slot,
            subslot: e.loc.subslot,
            module_ident: e.loc.module_ident,
            submodule_ident: e.loc.submodule_ident,
            specifier: AlarmSpecifier::new(sub_diag, false, sub_diag, ar_diag),
            item: Some(e.item(specifier)),
        })
    }

    /// The alarm [`DiagList::next_alarm`] returned went to the alarm CR.
    pub fn sent(&mut self) {
        if self.in_flight() {
            return;
        }
        let e = self
            .entries
            .iter_mut()
            .filter(|e| matches!(e.state, State::PendingAppear | State::PendingDisappear))
            .min_by_key(|e| e.stamp);
        if let Some(e) = e {
            e.state = match e.state {
                State::PendingAppear => State::InFlightAppear { then_clear: false },
                _ => State::InFlightDisappear { then_raise: false },
            };
        }
    }

    /// The controller acknowledged the outstanding diagnosis alarm.
    pub fn acked(&mut self) {
        let stamp = self.stamp();
        let Some(i) = self.entries.iter().position(|e| {
            matches!(
                e.state,
                State::InFlightAppear { .. } | State::InFlightDisappear { .. }
            )
        }) else {
            return;
        };
        let Some(e) = self.entries.get_mut(i) else {
            return;
        };
        let next = match e.state {
            State::InFlightAppear { then_clear: true } => Some(State::PendingDisappear),
            State::InFlightAppear { then_clear: false } => Some(State::Active),
            State::InFlightDisappear { then_raise: true } => Some(State::PendingAppear),
            _ => None,
        };
        match next {
            Some(s) => {
                e.state = s;
                e.stamp = stamp;
            }
            None => {
                self.entries.remove(i);
            }
        }
    }

    /// Writes the diagnosis record data for `scope`/`filter`: one
    /// DiagnosisData block (type 0x0010, version 1.1) per submodule with
    /// present entries, in the order they first appeared: BlockHeader, API,
    /// Slot, Subslot, ChannelNumber 0x8000, ChannelProperties (appears), USI
    /// 0x8002, then one ExtChannelDiagnosisData per entry. Nothing to report
    /// writes 0 bytes.
    pub fn write_record(
        &self,
        scope: DiagScope,
        filter: DiagFilter,
        buf: &mut [u8],
    ) -> Result<usize, RecordError> {
        let wanted = |e: &Entry| {
            e.state.present()
                && scope.contains(&e.loc)
                && (filter == DiagFilter::All || e.maintenance == Maintenance::Fault)
        };
        let mut w = Writer::new(buf);
        for (i, first) in self.entries.iter().enumerate() {
            let earlier = self
                .entries
                .iter()
                .take(i)
                .any(|o| wanted(o) && o.loc.same(&first.loc));
            if !wanted(first) || earlier {
                continue;
            }
            write_block(
                &mut w,
                first,
                self.entries
                    .iter()
                    .filter(|e| wanted(e) && e.loc.same(&first.loc)),
            )
            .ok_or(RecordError::BufferTooShort)?;
        }
        Ok(w.pos)
    }
}

fn write_block<'e>(w: &mut Writer<'_>, head: &Entry, items: impl Iterator<Item = &'e Entry>) -> Option<()> {
    let start = w.pos;
    w.bytes(&[0x00, 0x10, 0, 0, 1, 1])?;
    w.u32(head.loc.api)?;
    w.u16(head.loc.slot)?;
    w.u16(head.loc.subslot)?;
    w.u16(CHANNEL_SUBMODULE)?;
    w.u16(
        ChannelProperties::new(
            0,
            false,
            Maintenance::Fault,
            Specifier::Appears,
            ChannelDirection::Manufacturer,
        )
        .0,
    )?;
    w.u16(USI_EXT_CHANNEL_DIAGNOSIS)?;
    for e in items {
        e.item(Specifier::Appears).write(w)?;
    }
    let len = u16::try_from(w.pos - start - 4).ok()?;
    w.patch_u16(start + 2, len)
}
