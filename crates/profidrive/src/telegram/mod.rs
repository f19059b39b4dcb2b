//! The telegram mapping (spec §4, P-047…P-075): four receive telegrams
//! (identifier 0xE0 + n in byte 0) and four response telegrams (0xF0 + n),
//! each up to 10 entries after the identifier, packed big-endian without
//! padding (Q-01, P-068).
//!
//! - [`TelegramSet`]: the configuration as entered (entries with the
//!   2011.0 fill, the associated response telegram of each receive
//!   telegram, P-055); [`TelegramSet::to_bytes`] / [`TelegramSet::from_bytes`]
//!   give it a checked byte form the drive stores in an object (P-069).
//! - [`Telegrams::configure`] checks a whole set against the drive
//!   ([`ParamAccess::describe`]) and compiles the layouts; a refused set
//!   changes nothing and says why ([`ConfigError`]).
//! - Per cycle ([`cyclic`]): [`Telegrams::apply_receive`] picks the receive
//!   telegram by byte 0, writes every entry but CW1 (RAM only) and returns
//!   CW1 and the PKW request; the caller runs the PKW step and applies CW1
//!   last (spec §4.3, P-066). [`Telegrams::build_response`] packs the
//!   associated response telegram.
//! - [`fb_receive`]: the Example Function block's receive telegrams 0…2 as a
//!   controller writes them ([`FbPositioning`], [`FbSpeed`], [`FbTorque`]),
//!   for the host side (benchmarks, tests, the QEMU runs).
//!
//! Rules (spec §4.2): in receive telegrams 0…2 CW1 (967.0) sits at offset 2
//! and in response telegrams 0…2 ZSW1 (968.0), so byte 1 is one 1-byte entry
//! (P-061…P-063); telegram 3 is free format (Q-09: CW1 wherever mapped, at
//! most once). Placeholders 2010.0/.1/.2 take 1/2/4 bytes and carry 0
//! (P-064); 2011.0 is "unused" and takes no bytes (P-065). PKW (2000.0, 8
//! bytes) at most once per telegram, and in a receive telegram exactly when
//! in its associated response telegram (P-198). Receive telegrams refuse
//! read-only objects, response telegrams write-only ones (P-059, P-060). A
//! telegram is at most [`MAX_TELEGRAM_BYTES`] long (the longest module).

use crate::{int_size, Addr, DataType, ParamAccess, PdError};

pub mod compiled;
pub mod cyclic;
mod defaults;
pub mod fb_receive;
mod serial;

pub use cyclic::{ModeBinding, RxOutcome, TxOutcome, Warnings};
pub use defaults::FB_DEFAULTS;
pub use fb_receive::{FbPositioning, FbSpeed, FbTorque, FB_RECEIVE_BYTES};
pub use serial::{FormatError, MAX_SERIAL_BYTES};

/// Entries per telegram (the identifier not counted, P-056).
pub const MAX_ENTRIES: usize = 10;
/// Telegrams per direction.
pub const TELEGRAMS: usize = 4;
/// The longest telegram: the longest module, 19 words (P-026).
pub const MAX_TELEGRAM_BYTES: usize = 38;

/// CW1, control word 1 (PNU 967.0).
pub const CW1: Addr = Addr::new(967, 0);
/// ZSW1, status word 1 (PNU 968.0).
pub const ZSW1: Addr = Addr::new(968, 0);
/// The PKW channel (PNU 2000.0, 2 × UINT32).
pub const PKW: Addr = Addr::new(2000, 0);
/// Placeholder of 1 byte.
pub const PAD8: Addr = Addr::new(2010, 0);
/// Placeholder of 2 bytes.
pub const PAD16: Addr = Addr::new(2010, 1);
/// Placeholder of 4 bytes.
pub const PAD32: Addr = Addr::new(2010, 2);
/// An unused entry (takes no bytes).
pub const UNUSED: Addr = Addr::new(2011, 0);

/// Receive (controller → drive) or response (drive → controller).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dir {
    /// Receive telegram, identifier 0xE0 + n.
    Receive,
    /// Response telegram, identifier 0xF0 + n.
    Response,
}

impl Dir {
    /// The identifier of telegram `n`.
    pub const fn identifier(self, n: u8) -> u8 {
        match self {
            Dir::Receive => 0xE0 + (n & 3),
            Dir::Response => 0xF0 + (n & 3),
        }
    }
}

/// The entries of one telegram as entered: 10 addresses, unused = 2011.0.
pub type Entries = [Addr; MAX_ENTRIES];

/// A telegram configuration as entered (what is stored).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TelegramSet {
    /// Receive telegrams 0…3.
    pub receive: [Entries; TELEGRAMS],
    /// Response telegrams 0…3.
    pub response: [Entries; TELEGRAMS],
    /// The associated response telegram of each receive telegram (P-055).
    pub associated: [u8; TELEGRAMS],
}

impl TelegramSet {
    /// Every telegram empty (all 2011.0), receive n answered by response n.
    /// Not a valid configuration by itself (CW1/ZSW1 missing).
    pub const EMPTY: Self = Self {
        receive: [[UNUSED; MAX_ENTRIES]; TELEGRAMS],
        response: [[UNUSED; MAX_ENTRIES]; TELEGRAMS],
        associated: [0, 1, 2, 3],
    };

    /// The entries of `dir` telegram `n` (`None` for n > 3).
    pub fn entries(&self, dir: Dir, n: u8) -> Option<&Entries> {
        match dir {
            Dir::Receive => self.receive.get(usize::from(n)),
            Dir::Response => self.response.get(usize::from(n)),
        }
    }

    /// `entries` padded with 2011.0 up to 10 (more than 10: `None`).
    pub fn pad(entries: &[Addr]) -> Option<Entries> {
        let mut out = [UNUSED; MAX_ENTRIES];
        if entries.len() > MAX_ENTRIES {
            return None;
        }
        for (o, e) in out.iter_mut().zip(entries) {
            *o = *e;
        }
        Some(out)
    }
}

/// What one mapped entry is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// An object of the drive, of this type.
    Object(DataType),
    /// CW1 (receive: returned, not written; response: read as an object).
    Cw1,
    /// The PKW channel.
    Pkw,
    /// A placeholder (carries 0; ignored on receive).
    Pad,
}

/// One mapped entry of a compiled layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Slot {
    /// Address as configured.
    pub addr: Addr,
    /// Byte offset in the telegram (the identifier is byte 0).
    pub offset: u8,
    /// Size in bytes.
    pub size: u8,
    /// What it is.
    pub kind: Kind,
}

/// A compiled telegram: the entries that take bytes, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    slots: [Slot; MAX_ENTRIES],
    count: u8,
    len: u8,
}

impl Layout {
    const EMPTY: Self = Self {
        slots: [Slot {
            addr: UNUSED,
            offset: 0,
            size: 0,
            kind: Kind::Pad,
        }; MAX_ENTRIES],
        count: 0,
        len: 1,
    };

    /// The entries that take bytes, in order (offsets ascending).
    pub fn slots(&self) -> &[Slot] {
        self.slots.get(..usize::from(self.count)).unwrap_or(&[])
    }

    /// Total length in bytes, identifier included.
    pub fn len(&self) -> usize {
        usize::from(self.len)
    }

    /// Only the identifier?
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The slot of the PKW channel, if mapped.
    pub fn pkw(&self) -> Option<Slot> {
        self.slots().iter().copied().find(|s| s.kind == Kind::Pkw)
    }
}

/// Why a configuration was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reason {
    /// The drive does not know the object (its PROFIdrive error).
    NoObject(PdError),
    /// The object's type has no telegram size (strings, REAL32).
    UnsupportedType,
    /// A read-only object in a receive telegram (P-059).
    ReadOnlyInReceive,
    /// A write-only object in a response telegram (P-060).
    WriteOnlyInResponse,
    /// Telegrams 0…2: the entry at offset 1 is not one byte (P-063).
    Byte1NotOneByte,
    /// Telegrams 0…2: CW1 / ZSW1 not at offset 2 (P-061, P-062).
    ControlWordNotAtOffset2,
    /// CW1 or ZSW1 mapped a second time, or at another offset.
    ControlWordTwice,
    /// ZSW1 in a receive telegram.
    StatusWordInReceive,
    /// PKW mapped twice in one telegram (P-198).
    PkwTwice,
    /// PKW in a receive telegram but not in its associated response
    /// telegram, or the other way round (P-198).
    PkwNotInBoth,
    /// Longer than [`MAX_TELEGRAM_BYTES`].
    TooLong,
    /// An associated response telegram number above 3.
    BadAssociation,
}

/// A refused configuration: where and why.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ConfigError {
    /// The telegram's direction.
    pub dir: Dir,
    /// The telegram's number.
    pub telegram: u8,
    /// The entry (0…9), when one entry is the cause.
    pub entry: Option<u8>,
    /// Why.
    pub reason: Reason,
}

/// The configured telegrams and the state of the cyclic exchange.
#[derive(Debug, Clone)]
pub struct Telegrams {
    set: TelegramSet,
    configured: bool,
    receive: [Layout; TELEGRAMS],
    response: [Layout; TELEGRAMS],
    live: cyclic::Live,
    /// The stamp of the layouts in force ([`compiled::stamp`]): a new one
    /// at every configuration, unique across instances, so handles
    /// compiled for other layouts are never used (issue 36).
    stamp: u32,
}

impl Default for Telegrams {
    fn default() -> Self {
        Self::new()
    }
}

impl Telegrams {
    /// Nothing configured: every frame is an unknown identifier.
    pub const fn new() -> Self {
        Self {
            set: TelegramSet::EMPTY,
            configured: false,
            receive: [Layout::EMPTY; TELEGRAMS],
            response: [Layout::EMPTY; TELEGRAMS],
            live: cyclic::Live::NEW,
            stamp: 0,
        }
    }

    /// The Example Function block's telegrams (P-071…P-074), checked
    /// against `access`.
    pub fn with_defaults(access: &impl ParamAccess) -> Result<Self, ConfigError> {
        let mut t = Self::new();
        t.configure(&FB_DEFAULTS, access)?;
        Ok(t)
    }

    /// Checks `set` against `access` and makes it the configuration.
    /// Refused: nothing changes.
    pub fn configure(&mut self, set: &TelegramSet, access: &impl ParamAccess) -> Result<(), ConfigError> {
        let mut receive = [Layout::EMPTY; TELEGRAMS];
        let mut response = [Layout::EMPTY; TELEGRAMS];
        for n in 0..TELEGRAMS as u8 {
            for dir in [Dir::Receive, Dir::Response] {
                let Some(entries) = set.entries(dir, n) else {
                    continue;
                };
                let layout = compile(dir, n, entries, access)?;
                let target = match dir {
                    Dir::Receive => receive.get_mut(usize::from(n)),
                    Dir::Response => response.get_mut(usize::from(n)),
                };
                if let Some(t) = target {
                    *t = layout;
                }
            }
        }
        for (n, (&assoc, rx)) in set.associated.iter().zip(&receive).enumerate() {
            let err = |reason| ConfigError {
                dir: Dir::Receive,
                telegram: n as u8,
                entry: None,
                reason,
            };
            let tx = response
                .get(usize::from(assoc))
                .ok_or(err(Reason::BadAssociation))?;
            if rx.pkw().is_some() != tx.pkw().is_some() {
                return Err(err(Reason::PkwNotInBoth));
            }
        }
        self.set = *set;
        self.receive = receive;
        self.response = response;
        self.configured = true;
        self.live = cyclic::Live::NEW;
        self.stamp = compiled::stamp();
        Ok(())
    }

    /// Replaces `dir` telegram `n` only (the rest of the set stays), checked
    /// as a whole set.
    pub fn set_telegram(
        &mut self,
        dir: Dir,
        n: u8,
        entries: &Entries,
        access: &impl ParamAccess,
    ) -> Result<(), ConfigError> {
        let mut set = self.set;
        let slot = match dir {
            Dir::Receive => set.receive.get_mut(usize::from(n)),
            Dir::Response => set.response.get_mut(usize::from(n)),
        };
        let Some(slot) = slot else {
            return Err(ConfigError {
                dir,
                telegram: n,
                entry: None,
                reason: Reason::BadAssociation,
            });
        };
        *slot = *entries;
        self.configure(&set, access)
    }

    /// Sets the associated response telegram of receive telegram `n`.
    pub fn set_associated(
        &mut self,
        n: u8,
        response: u8,
        access: &impl ParamAccess,
    ) -> Result<(), ConfigError> {
        let mut set = self.set;
        let err = ConfigError {
            dir: Dir::Receive,
            telegram: n,
            entry: None,
            reason: Reason::BadAssociation,
        };
        *set.associated.get_mut(usize::from(n)).ok_or(err)? = response;
        self.configure(&set, access)
    }

    /// The configuration in force (as entered).
    pub fn set(&self) -> &TelegramSet {
        &self.set
    }

    /// Is a configuration in force?
    pub fn configured(&self) -> bool {
        self.configured
    }

    /// The compiled layout of `dir` telegram `n`.
    pub fn layout(&self, dir: Dir, n: u8) -> Option<&Layout> {
        if !self.configured {
            return None;
        }
        match dir {
            Dir::Receive => self.receive.get(usize::from(n)),
            Dir::Response => self.response.get(usize::from(n)),
        }
    }

    /// The response telegram associated with receive telegram `n` (P-055).
    pub fn associated(&self, n: u8) -> Option<u8> {
        self.set.associated.get(usize::from(n)).copied()
    }
}

/// Checks one entry for a `dir` telegram as it is entered (spec §4.2's
/// entry check: the object exists, its type has a telegram size, its
/// access fits the direction; P-058…P-060); returns its size in bytes (0
/// for 2011.0). The whole telegram is checked when it is configured.
pub fn check_entry(dir: Dir, addr: Addr, access: &impl ParamAccess) -> Result<u8, Reason> {
    Ok(entry_kind(dir, addr, access)?.map_or(0, |(size, _)| size))
}

/// Size and kind of one configured entry.
fn entry_kind(dir: Dir, addr: Addr, access: &impl ParamAccess) -> Result<Option<(u8, Kind)>, Reason> {
    match addr {
        UNUSED => return Ok(None),
        PAD8 => return Ok(Some((1, Kind::Pad))),
        PAD16 => return Ok(Some((2, Kind::Pad))),
        PAD32 => return Ok(Some((4, Kind::Pad))),
        PKW => return Ok(Some((8, Kind::Pkw))),
        _ => {}
    }
    if dir == Dir::Receive && addr == ZSW1 {
        return Err(Reason::StatusWordInReceive);
    }
    let d = access.describe(addr).map_err(Reason::NoObject)?;
    let size = int_size(d.data_type).map_err(|_| Reason::UnsupportedType)? as u8;
    match dir {
        Dir::Receive if !d.writable => Err(Reason::ReadOnlyInReceive),
        Dir::Response if !d.readable => Err(Reason::WriteOnlyInResponse),
        Dir::Receive if addr == CW1 => Ok(Some((size, Kind::Cw1))),
        _ => Ok(Some((size, Kind::Object(d.data_type)))),
    }
}

/// Checks and lays out one telegram.
fn compile(dir: Dir, n: u8, entries: &Entries, access: &impl ParamAccess) -> Result<Layout, ConfigError> {
    let err = |entry: Option<usize>, reason| ConfigError {
        dir,
        telegram: n,
        entry: entry.map(|e| e as u8),
        reason,
    };
    let word = match dir {
        Dir::Receive => CW1,
        Dir::Response => ZSW1,
    };
    let fixed = n < 3;
    let mut layout = Layout::EMPTY;
    let mut offset = 1usize;
    let mut word_seen = false;
    let mut pkw_seen = false;
    for (i, &addr) in entries.iter().enumerate() {
        let Some((size, kind)) = entry_kind(dir, addr, access).map_err(|r| err(Some(i), r))? else {
            continue;
        };
        if fixed && offset == 1 && size != 1 {
            return Err(err(Some(i), Reason::Byte1NotOneByte));
        }
        if fixed && offset == 2 && addr != word {
            return Err(err(Some(i), Reason::ControlWordNotAtOffset2));
        }
        if addr == word {
            if word_seen || (fixed && offset != 2) {
                return Err(err(Some(i), Reason::ControlWordTwice));
            }
            word_seen = true;
        }
        if kind == Kind::Pkw {
            if pkw_seen {
                return Err(err(Some(i), Reason::PkwTwice));
            }
            pkw_seen = true;
        }
        let slot = Slot {
            addr,
            offset: offset as u8,
            size,
            kind,
        };
        offset += usize::from(size);
        if offset > MAX_TELEGRAM_BYTES {
            return Err(err(Some(i), Reason::TooLong));
        }
        if let Some(s) = layout.slots.get_mut(usize::from(layout.count)) {
            *s = slot;
            layout.count += 1;
        }
    }
    if fixed && !word_seen {
        return Err(err(None, Reason::ControlWordNotAtOffset2));
    }
    layout.len = offset as u8;
    Ok(layout)
}
