//! The telegram configuration in the parameter set (P-069) and its editor
//! over the bus (ours; the manual's drive is configured by its tool):
//!
//! * A280 holds the configuration in its stored form
//!   ([`profidrive::telegram::TelegramSet::to_bytes`]), saved with the
//!   parameters; version byte 0 (the declaration's default) = the Example
//!   Function block's telegrams. It is read at start; a stored form that
//!   does not check or configure leaves the FB's telegrams in force.
//! * PNU 2020 selects a telegram (0…3 receive, 4…7 response) and loads it
//!   into the edit copy; PNU 2021.0…9 are its entries as
//!   `index << 16 | sub << 8 | bits` (CiA 301's PDO mapping form; the drive
//!   fills the length on read, ignores it on write) with the entry check of
//!   spec §4.2 at each write (the object exists, its type has a telegram
//!   size, its access fits the direction: P-058…P-060); 2021.10 the
//!   associated response telegram of a receive telegram (P-055).
//! * PNU 2022 = 1 applies the edit copy: the whole set is checked
//!   ([`profidrive::telegram::Telegrams::configure`]); refused, the PKW write
//!   answers 0x18 (values inconsistent), PNU 2022 reads why, and nothing
//!   changes; taken, it is the configuration in force and A280 holds it.
//!
//! Select and apply answer [`Completion::Pending`] first: the profile
//! carries them out after the PKW step, where the telegrams are at hand.

use drive_core::params::A280;
use od::{CommState, Dictionary};
use profidrive::telegram::{
    check_entry, ConfigError, Dir, Entries, Reason, TelegramSet, Telegrams, MAX_SERIAL_BYTES, TELEGRAMS,
    UNUSED,
};
use profidrive::{Addr, Completion, ParamAccess, PdError};

/// PNU 2020: the telegram selector.
pub const SELECT: u16 = 2020;
/// PNU 2021: the selected telegram's entries (sub 10: its association).
pub const ENTRIES: u16 = 2021;
/// PNU 2022: apply (write 1) and the last refusal (read).
pub const APPLY: u16 = 2022;
/// PNU 2021's subindex of the associated response telegram.
pub const ASSOCIATED_SUB: u8 = 10;

/// What waits for the profile after the PKW step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Request {
    /// Load telegram 0…7 into the edit copy.
    Select(u8),
    /// Check and take the edit copy.
    Apply,
}

/// The edit copy of one telegram and the editor's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TelegramEdit {
    /// The telegram being edited: 0…3 receive, 4…7 response.
    pub selected: u8,
    /// Its entries as edited.
    pub entries: Entries,
    /// Its associated response telegram (receive telegrams).
    pub associated: u8,
    /// A select or apply waiting for the profile.
    pub request: Option<Request>,
    /// How the last select or apply ended (the pending PKW write's answer).
    pub result: Result<(), PdError>,
    /// Why the last apply was refused (PNU 2022; 0: taken).
    pub refusal: u16,
}

impl Default for TelegramEdit {
    fn default() -> Self {
        TelegramEdit {
            selected: 0,
            entries: [UNUSED; 10],
            associated: 0,
            request: None,
            result: Ok(()),
            refusal: 0,
        }
    }
}

/// Direction and number of selector value `k`.
fn telegram_of(k: u8) -> (Dir, u8) {
    if k < TELEGRAMS as u8 {
        (Dir::Receive, k)
    } else {
        (Dir::Response, k - TELEGRAMS as u8)
    }
}

/// PNU 2022's code of a refusal: 0x8000, direction (0x4000 = response),
/// telegram × 0x1000, entry (0xF = the whole telegram) × 0x100, reason.
pub fn refusal_code(e: &ConfigError) -> u16 {
    let reason = match e.reason {
        Reason::NoObject(_) => 1,
        Reason::UnsupportedType => 2,
        Reason::ReadOnlyInReceive => 3,
        Reason::WriteOnlyInResponse => 4,
        Reason::Byte1NotOneByte => 5,
        Reason::ControlWordNotAtOffset2 => 6,
        Reason::ControlWordTwice => 7,
        Reason::StatusWordInReceive => 8,
        Reason::PkwTwice => 9,
        Reason::PkwNotInBoth => 10,
        Reason::TooLong => 11,
        Reason::BadAssociation => 12,
    };
    let dir = if e.dir == Dir::Response { 0x4000 } else { 0 };
    0x8000 | dir | u16::from(e.telegram & 3) << 12 | u16::from(e.entry.unwrap_or(0xF) & 0xF) << 8 | reason
}

/// The PROFIdrive error of an entry the check refuses.
fn entry_error(r: Reason) -> PdError {
    match r {
        Reason::NoObject(e) => e,
        Reason::UnsupportedType => PdError::INCORRECT_DATA_TYPE,
        _ => PdError::VALUE_IMPERMISSIBLE,
    }
}

/// An entry as PNU 2021 shows it.
fn encode(addr: Addr, size: u8) -> i64 {
    i64::from(addr.index) << 16 | i64::from(addr.sub) << 8 | (i64::from(size) * 8)
}

impl TelegramEdit {
    /// PNU 2020…2022 read.
    pub fn read(&self, addr: Addr, access: &impl ParamAccess) -> Result<i64, PdError> {
        match (addr.index, addr.sub) {
            (SELECT, 0) => Ok(i64::from(self.selected)),
            (ENTRIES, ASSOCIATED_SUB) => Ok(i64::from(self.associated)),
            (ENTRIES, k) => {
                let e = *self.entries.get(usize::from(k)).ok_or(PdError::FAULTY_SUBINDEX)?;
                let (dir, _) = telegram_of(self.selected);
                Ok(encode(e, check_entry(dir, e, access).unwrap_or(0)))
            }
            (APPLY, 0) => Ok(i64::from(self.refusal)),
            _ => Err(PdError::FAULTY_SUBINDEX),
        }
    }

    /// PNU 2020…2022 write.
    pub fn write(
        &mut self,
        addr: Addr,
        value: i64,
        access: &impl ParamAccess,
    ) -> Result<Completion, PdError> {
        match (addr.index, addr.sub) {
            (SELECT, 0) => {
                let k = u8::try_from(value).ok().filter(|k| *k < 2 * TELEGRAMS as u8);
                self.request = Some(Request::Select(k.ok_or(PdError::LIMIT_EXCEEDED)?));
                Ok(Completion::Pending)
            }
            (ENTRIES, ASSOCIATED_SUB) => {
                if telegram_of(self.selected).0 != Dir::Receive {
                    return Err(PdError::VALUE_IMPERMISSIBLE);
                }
                let n = u8::try_from(value).ok().filter(|n| *n < TELEGRAMS as u8);
                self.associated = n.ok_or(PdError::LIMIT_EXCEEDED)?;
                Ok(Completion::Done)
            }
            (ENTRIES, k) => {
                let v = u32::try_from(value).map_err(|_| PdError::LIMIT_EXCEEDED)?;
                let e = Addr::new((v >> 16) as u16, (v >> 8) as u8);
                let (dir, _) = telegram_of(self.selected);
                check_entry(dir, e, access).map_err(entry_error)?;
                *self
                    .entries
                    .get_mut(usize::from(k))
                    .ok_or(PdError::FAULTY_SUBINDEX)? = e;
                Ok(Completion::Done)
            }
            (APPLY, 0) => match value {
                1 => {
                    self.request = Some(Request::Apply);
                    Ok(Completion::Pending)
                }
                _ => Err(PdError::VALUE_IMPERMISSIBLE),
            },
            _ => Err(PdError::FAULTY_SUBINDEX),
        }
    }

    /// The pending write's state (PKW asks again).
    pub fn poll(&self) -> Result<Completion, PdError> {
        if self.request.is_some() {
            return Ok(Completion::Pending);
        }
        self.result.map(|()| Completion::Done)
    }

    /// The editor on receive telegram 0 of `set`.
    pub fn of(set: &TelegramSet) -> TelegramEdit {
        let mut e = TelegramEdit::default();
        e.load(set, 0);
        e
    }

    /// Loads telegram `k` of `set` into the edit copy.
    fn load(&mut self, set: &TelegramSet, k: u8) {
        let (dir, n) = telegram_of(k);
        self.selected = k;
        if let Some(e) = set.entries(dir, n) {
            self.entries = *e;
        }
        self.associated = set.associated.get(usize::from(n)).copied().unwrap_or(n);
    }
}

/// Carries out the editor's waiting request against the telegrams in force
/// (`access` answers the checks and stores A280).
pub fn serve<A: ParamAccess + StoreA280>(edit: &mut TelegramEdit, telegrams: &mut Telegrams, access: &mut A) {
    let Some(request) = edit.request.take() else {
        return;
    };
    edit.result = match request {
        Request::Select(k) => {
            let set = *telegrams.set();
            edit.load(&set, k);
            Ok(())
        }
        Request::Apply => {
            let mut set = *telegrams.set();
            let (dir, n) = telegram_of(edit.selected);
            let slot = match dir {
                Dir::Receive => set.receive.get_mut(usize::from(n)),
                Dir::Response => set.response.get_mut(usize::from(n)),
            };
            if let Some(slot) = slot {
                *slot = edit.entries;
            }
            if dir == Dir::Receive {
                if let Some(a) = set.associated.get_mut(usize::from(n)) {
                    *a = edit.associated;
                }
            }
            match telegrams.configure(&set, access) {
                Ok(()) => {
                    edit.refusal = 0;
                    access.store_a280(&set);
                    Ok(())
                }
                Err(e) => {
                    edit.refusal = refusal_code(&e);
                    Err(PdError::VALUES_INCONSISTENT)
                }
            }
        }
    };
}

/// Writes a telegram set into A280.
pub trait StoreA280 {
    /// A280 := `set`'s stored form.
    fn store_a280(&mut self, set: &TelegramSet);
}

impl StoreA280 for drive_core::DriveObjects {
    fn store_a280(&mut self, set: &TelegramSet) {
        // the whole entry: the stored form, then zeros
        let mut buf = [0u8; MAX_SERIAL_BYTES];
        if set.to_bytes(&mut buf).is_ok() {
            let _ = self.set_bytes(A280, 0, &buf);
        }
    }
}

/// The length of the stored form at the start of `data` (from its counts),
/// `None` when it cannot be one.
fn stored_len(data: &[u8]) -> Option<usize> {
    let mut at = 1 + TELEGRAMS;
    for _ in 0..2 * TELEGRAMS {
        let k = usize::from(*data.get(at)?);
        at = at.checked_add(1 + 3 * k)?;
    }
    let len = at.checked_add(2)?;
    (len <= data.len()).then_some(len)
}

/// The telegram set A280 holds: `None` for version 0 (the FB's telegrams)
/// or a stored form that does not check.
pub fn stored(objects: &mut drive_core::DriveObjects) -> Option<TelegramSet> {
    let mut buf = [0u8; MAX_SERIAL_BYTES];
    let n = objects.read(A280, 0, &mut buf, CommState::Op).ok()?;
    let data = buf.get(..n)?;
    if data.first().copied().unwrap_or(0) == 0 {
        return None;
    }
    TelegramSet::from_bytes(data.get(..stored_len(data)?)?).ok()
}
