//! Lookups of the cyclic path, cheap (issue 17, cycle cost): the PNU
//! catalogue by binary search (it is sorted by PNU and subindex, which
//! `p190_the_catalogue_is_sorted_without_duplicates` keeps) with the answers
//! of [`pnu::find`] / [`pnu::is_catalogue_index`], and the CiA 402 entries a
//! telegram reads and writes every cycle prepared once per configuration
//! generation ([`PreparedCache`], [`drive_core::Prepared`]) instead of
//! looked up and checked by the dictionary at each access.

use super::pnu::{self, Pnu};
use core::num::NonZeroU16;
use core::sync::atomic::{AtomicU32, Ordering};
use drive_core::axis::Axis;
use drive_core::{DriveObjects, Prepared, Slot};
use od::CommState;
use profidrive::{Addr, PdError};

/// A catalogue address as one number, in the catalogue's order:
/// `index << 8 | sub` (24 bits).
const fn key(a: Addr) -> u32 {
    (a.index as u32) << 8 | a.sub as u32
}

/// The catalogue's addresses as [`key`]s, in its order (built at compile
/// time: an index out of range here is a compile error, not a panic).
#[allow(clippy::indexing_slicing)]
static KEYS: [u32; pnu::CATALOGUE.len()] = {
    let c = pnu::CATALOGUE;
    let mut keys = [0u32; pnu::CATALOGUE.len()];
    let mut i = 0;
    while i < keys.len() {
        keys[i] = key(c[i].addr);
        i += 1;
    }
    keys
};

/// [`pnu::find`]: the entry of `addr`, 0x00 without the PNU, 0x03 without
/// the subindex.
pub fn find(addr: Addr) -> Result<&'static Pnu, PdError> {
    let i = find_at(addr)?;
    pnu::CATALOGUE.get(i).ok_or(PdError::IMPERMISSIBLE_PNU)
}

/// [`find`]'s position of `addr` in [`pnu::CATALOGUE`] (a telegram's
/// handle, issue 36).
pub fn position(addr: Addr) -> Result<usize, PdError> {
    find_at(addr)
}

/// [`find`]'s position of `addr` in the catalogue.
fn find_at(addr: Addr) -> Result<usize, PdError> {
    let c = pnu::CATALOGUE;
    // searched in the dense keys (4 bytes an entry, not the entries' own
    // stride): issue 36, some 10 lookups per telegram
    let i = KEYS.partition_point(|&k| k < key(addr));
    let here = c.get(i);
    if here.is_some_and(|p| p.addr == addr) {
        return Ok(i);
    }
    // the PNU's other subindices sit just before or at `i`
    let known = |p: Option<&Pnu>| p.is_some_and(|p| p.addr.index == addr.index);
    Err(if known(here) || known(i.checked_sub(1).and_then(|j| c.get(j))) {
        PdError::FAULTY_SUBINDEX
    } else {
        PdError::IMPERMISSIBLE_PNU
    })
}

/// A telegram entry resolved where the telegrams are configured or
/// prepared for (issue 36, [`profidrive::telegram::compiled`]): the
/// cyclic path reads and writes it without the catalogue's memo and the
/// catalogue-index test. Two bytes (80 slots): the low 15 bits a catalogue
/// entry's position in [`pnu::CATALOGUE`] plus one, or all ones for a
/// CANopen object outside the catalogue (its index mapped to the axis at
/// the access, as the address path does); bit 15 set for an entry of a
/// receive telegram whose write is a configuration change
/// ([`super::access::DriveAccess::is_config_entry`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Handle(NonZeroU16);

impl Handle {
    /// A CANopen object outside the catalogue.
    const OBJECT: u16 = 0x7FFF;
    /// The configuration-entry flag.
    const CONFIG: u16 = 0x8000;

    fn new(v: u16, config: bool) -> Option<Handle> {
        NonZeroU16::new(if config { v | Self::CONFIG } else { v }).map(Handle)
    }

    /// The handle of the catalogue entry at `i`.
    pub fn pnu(i: usize, config: bool) -> Option<Handle> {
        let v = u16::try_from(i.checked_add(1)?).ok()?;
        if v >= Self::OBJECT {
            return None;
        }
        Self::new(v, config)
    }

    /// The handle of an object outside the catalogue.
    pub fn object(config: bool) -> Option<Handle> {
        Self::new(Self::OBJECT, config)
    }

    /// The catalogue entry, `None` for an object.
    pub fn entry(self) -> Option<&'static Pnu> {
        match self.0.get() & Self::OBJECT {
            Self::OBJECT => None,
            v => pnu::CATALOGUE.get(usize::from(v).checked_sub(1)?),
        }
    }

    /// A receive entry whose write is a configuration change.
    pub fn is_config(self) -> bool {
        self.0.get() & Self::CONFIG != 0
    }
}

/// Places of [`WrittenConfig`] (telegram 1 has one configuration entry).
const WRITTEN: usize = 2;

/// The configuration entries a receive telegram wrote last through their
/// handles, each with the bus value and the configuration generation after
/// the write (issue 36): the same value again at the same generation is
/// written already (telegram 1's ramps, four prepared writes, every
/// telegram).
#[derive(Debug, Clone, Copy, Default)]
pub struct WrittenConfig {
    /// `(key, value, generation)`, key 0 = free.
    places: [(u32, i64, u32); WRITTEN],
    next: u8,
    /// A write since this was cleared took the dictionary's full path (no
    /// prepared access): its answer may depend on more than the value and
    /// the configuration, it is not remembered.
    pub unprepared: bool,
}

impl WrittenConfig {
    /// Empty.
    pub const fn new() -> Self {
        Self {
            places: [(0, 0, 0); WRITTEN],
            next: 0,
            unprepared: false,
        }
    }

    /// The key of `addr` on axis `axis` (never 0).
    pub fn key(axis: u8, addr: Addr) -> u32 {
        1 << 31 | u32::from(axis & 0x7F) << 24 | key(addr)
    }

    /// `value` was written to `key` and the generation is still `g`.
    pub fn holds(&self, key: u32, value: i64, g: u32) -> bool {
        self.places.contains(&(key, value, g))
    }

    /// `value` written to `key`, the generation `g` after it.
    pub fn put(&mut self, key: u32, value: i64, g: u32) {
        let at = match self.places.iter().position(|p| p.0 == key) {
            Some(at) => at,
            None => {
                let at = usize::from(self.next) % WRITTEN;
                self.next = (at + 1) as u8;
                at
            }
        };
        if let Some(p) = self.places.get_mut(at) {
            *p = (key, value, g);
        }
    }
}

/// Places of the memo of catalogue entries found (a power of two).
const MEMO_PLACES: usize = 32;

/// Places a lookup in the memo tries from its home place.
const MEMO_PROBES: usize = 4;

/// The memo of [`find_and_remember`]: per place one word, the address'
/// [`key`] in the top 24 bits and its catalogue position + 1 in the low 8
/// (0 = free). A memo of the constant catalogue, shared by every profile
/// and task: a word is written whole; an address takes the first free
/// place of its probes, or its home place when none is (issue 36: the
/// binary searches of a telegram's entries cost up to ~1,000 instructions
/// per telegram on QEMU).
static MEMO: [AtomicU32; MEMO_PLACES] = [const { AtomicU32::new(0) }; MEMO_PLACES];

/// The places `key` may have in the memo, its home place first.
fn memo_places(key: u32) -> impl Iterator<Item = &'static AtomicU32> {
    let home = (key.wrapping_mul(0x9E37_79B1) >> 27) as usize;
    (0..MEMO_PROBES).filter_map(move |j| MEMO.get((home + j) % MEMO_PLACES))
}

/// The catalogue entry of `addr` when the memo holds it: what [`find`]
/// answers for an address [`find_and_remember`] found before; `None`
/// otherwise (the caller takes the full path).
pub fn memoised(addr: Addr) -> Option<&'static Pnu> {
    let k = key(addr);
    for place in memo_places(k) {
        let word = place.load(Ordering::Relaxed);
        if word >> 8 == k && word & 0xFF != 0 {
            return pnu::CATALOGUE.get(usize::from(word as u8).checked_sub(1)?);
        }
        if word == 0 {
            return None;
        }
    }
    None
}

/// [`find`], the entry found remembered for [`memoised`].
pub fn find_and_remember(addr: Addr) -> Result<&'static Pnu, PdError> {
    let i = find_at(addr)?;
    let k = key(addr);
    if let Ok(n) = u8::try_from(i + 1) {
        let free = memo_places(k).find(|p| {
            let w = p.load(Ordering::Relaxed);
            w == 0 || w >> 8 == k
        });
        if let Some(place) = free.or_else(|| memo_places(k).next()) {
            place.store(k << 8 | u32::from(n), Ordering::Relaxed);
        }
    }
    pnu::CATALOGUE.get(i).ok_or(PdError::IMPERMISSIBLE_PNU)
}

/// The catalogue's last (highest) index: an index above it is none of
/// the catalogue's (built at compile time from the sorted catalogue).
const LAST_INDEX: u16 = match pnu::CATALOGUE.last() {
    Some(p) => p.addr.index,
    None => 0,
};

/// [`pnu::is_catalogue_index`]: an index above the catalogue's last (a
/// CiA 402 object of a telegram, 6071h, 6077h) without the search (issue
/// 36).
pub fn is_catalogue_index(index: u16) -> bool {
    let c = pnu::CATALOGUE;
    index < 0x1000
        || index <= LAST_INDEX
            && c.get(c.partition_point(|p| p.addr.index < index))
                .is_some_and(|p| p.addr.index == index)
}

/// Entries kept (the default telegrams touch nine CiA 402 entries, eight
/// of them with telegram 1).
const ENTRIES: usize = 8;

/// The CiA 402 entries last accessed, prepared (Op, the profile's state);
/// a stale one is prepared again, a new one takes the oldest place. Handed
/// out by reference: a handle is too large to copy cheaply.
#[derive(Debug)]
pub struct PreparedCache {
    /// `1 << 24 | index << 8 | sub`, 0 = free.
    keys: [u32; ENTRIES],
    handles: [Option<Prepared>; ENTRIES],
    next: usize,
}

impl Default for PreparedCache {
    fn default() -> Self {
        Self::new()
    }
}

impl PreparedCache {
    /// Empty.
    pub const fn new() -> Self {
        Self {
            keys: [0; ENTRIES],
            handles: [None; ENTRIES],
            next: 0,
        }
    }

    /// Every entry kept prepared again where it went stale (the
    /// configuration moved): outside the control cycle, so its telegram
    /// finds the handles current (issue 36). The same handles
    /// [`get`](Self::get) would prepare at its next access.
    pub fn refresh(&mut self, objects: &DriveObjects) {
        for (key, handle) in self.keys.iter_mut().zip(self.handles.iter_mut()) {
            if *key == 0 || handle.as_ref().is_some_and(|p| objects.is_current(p)) {
                continue;
            }
            let (index, sub) = ((*key >> 8) as u16, *key as u8);
            *handle = objects.prepare(index, sub, CommState::Op);
            if handle.is_none() {
                *key = 0;
            }
        }
    }

    /// `index`:`sub` prepared and current, or `None` (not a CiA 402 entry
    /// [`DriveObjects::prepare`] takes: the full path).
    pub fn get(&mut self, objects: &DriveObjects, index: u16, sub: u8) -> Option<&Prepared> {
        if !(0x6000..=0x6FFF).contains(&index) {
            return None;
        }
        let key = 1 << 24 | u32::from(index) << 8 | u32::from(sub);
        let at = match self.keys.iter().position(|&k| k == key) {
            Some(at)
                if self
                    .handles
                    .get(at)?
                    .as_ref()
                    .is_some_and(|p| objects.is_current(p)) =>
            {
                return self.handles.get(at)?.as_ref();
            }
            Some(at) => at,
            None => {
                let at = self.next % ENTRIES;
                self.next = at + 1;
                at
            }
        };
        let p = objects.prepare(index, sub, CommState::Op);
        *self.keys.get_mut(at)? = if p.is_some() { key } else { 0 };
        let slot = self.handles.get_mut(at)?;
        *slot = p;
        slot.as_ref()
    }
}

/// The core entries the profile itself reads and writes every cycle
/// ([`DriveObjects::get`] / [`DriveObjects::set`], no bus rules).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Core {
    /// 6040h controlword.
    Controlword,
    /// 6060h modes of operation.
    Mode,
    /// 6061h modes of operation display.
    ModeDisplay,
    /// 60FDh digital inputs.
    Inputs,
    /// 6041h statusword.
    Statusword,
}

impl Core {
    const ALL: [Core; 5] = [
        Core::Controlword,
        Core::Mode,
        Core::ModeDisplay,
        Core::Inputs,
        Core::Statusword,
    ];

    /// The axis-A index.
    const fn index(self) -> u16 {
        match self {
            Core::Controlword => 0x6040,
            Core::Mode => 0x6060,
            Core::ModeDisplay => 0x6061,
            Core::Inputs => 0x60FD,
            Core::Statusword => 0x6041,
        }
    }
}

/// [`Core`]'s entries of one axis resolved once to their [`Slot`]s: a load
/// or store where `get`/`set` hash and probe the dictionary's cache (the
/// same values: these are integers in RAM).
#[derive(Debug, Clone, Copy, Default)]
pub struct CoreSlots {
    axis: Option<u8>,
    slots: [Option<Slot>; 5],
    /// J400, the record selector (the record fields of telegram 0).
    selector: Option<Slot>,
}

impl CoreSlots {
    /// Nothing resolved yet.
    pub const fn new() -> Self {
        Self {
            axis: None,
            slots: [None; 5],
            selector: None,
        }
    }

    /// Resolves the entries of `axis` (once; again for another axis).
    pub fn resolve(&mut self, objects: &DriveObjects, axis: &Axis) {
        if self.axis != Some(axis.index()) {
            for (s, e) in self.slots.iter_mut().zip(Core::ALL) {
                *s = objects.slot(axis.cia402_index(e.index()), 0);
            }
            self.selector = objects.record_selector_slot(axis.index());
            self.axis = Some(axis.index());
        }
    }

    fn slot(&self, axis: &Axis, e: Core) -> Option<Slot> {
        if self.axis != Some(axis.index()) {
            return None;
        }
        self.slots.get(e as usize).copied().flatten()
    }

    /// `objects.record_selector(axis)`.
    pub fn record_selector(&self, objects: &DriveObjects, axis: &Axis) -> u16 {
        match self.selector {
            Some(s) if self.axis == Some(axis.index()) => objects.record_selector_at(s),
            _ => objects.record_selector(axis.index()),
        }
    }

    /// `objects.get(e of axis, 0).unwrap_or(0)`.
    pub fn get(&self, objects: &DriveObjects, axis: &Axis, e: Core) -> i64 {
        match self.slot(axis, e) {
            Some(s) => objects.load_slot(s),
            None => objects.get(axis.cia402_index(e.index()), 0).unwrap_or(0),
        }
    }

    /// `let _ = objects.set(e of axis, 0, v)`.
    pub fn set(&self, objects: &mut DriveObjects, axis: &Axis, e: Core, v: i64) {
        match self.slot(axis, e) {
            Some(s) => {
                objects.store_slot(s, v);
            }
            None => {
                let _ = objects.set(axis.cia402_index(e.index()), 0, v);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// P-190: the binary search answers as the catalogue's own lookups, for
    /// every PNU and subindex around the catalogue's.
    #[test]
    fn p190_the_lookups_answer_as_the_catalogue() {
        let mut indices: std::vec::Vec<u16> = (0..1200).chain(0x1000..0x1010).collect();
        for p in pnu::CATALOGUE {
            indices.extend([p.addr.index.saturating_sub(1), p.addr.index, p.addr.index + 1]);
        }
        indices.extend([0x2415, 0x2416, 0x2417, 0x6040, u16::MAX]);
        for index in indices {
            assert_eq!(
                is_catalogue_index(index),
                pnu::is_catalogue_index(index),
                "{index}"
            );
            for sub in 0..=8 {
                let a = Addr::new(index, sub);
                assert_eq!(find(a).map(|p| p.addr), pnu::find(a).map(|p| p.addr), "{a:?}");
            }
            assert_eq!(
                find(Addr::new(index, 255)).map(|p| p.addr),
                pnu::find(Addr::new(index, 255)).map(|p| p.addr)
            );
        }
    }

    /// The memo of catalogue entries answers as [`find`] for every address
    /// it answers at all, and holds an entry just found.
    #[test]
    fn the_memo_answers_as_find() {
        let mut addrs: std::vec::Vec<Addr> = std::vec::Vec::new();
        for p in pnu::CATALOGUE {
            for sub in 0..=8 {
                addrs.extend([Addr::new(p.addr.index, sub), Addr::new(p.addr.index + 1, sub)]);
            }
        }
        addrs.extend([Addr::new(0, 0), Addr::new(0x6040, 0), Addr::new(u16::MAX, 255)]);
        for round in 0..2 {
            for &a in &addrs {
                let found = find(a).map(|p| p.addr);
                assert_eq!(find_and_remember(a).map(|p| p.addr), found, "{a:?}");
                if found.is_ok() && round == 0 {
                    assert_eq!(memoised(a).map(|p| p.addr), Some(a), "{a:?}");
                }
            }
            for &a in &addrs {
                if let Some(p) = memoised(a) {
                    assert_eq!(Ok(p.addr), find(a).map(|p| p.addr), "{a:?}");
                }
            }
        }
    }

    /// P-051, P-052 (the mode the telegram selects): the resolved entries
    /// read and write as `get` / `set`, for both axes.
    #[test]
    fn p051_p052_core_slots_read_and_write_as_get_and_set() {
        let mut od = DriveObjects::new();
        let mut core = CoreSlots::new();
        for axis in [Axis::new(0), Axis::new(1)] {
            core.resolve(&od, &axis);
            for (e, v) in [
                (Core::Controlword, 0x0F),
                (Core::Mode, 2),
                (Core::Mode, -1),
                (Core::Controlword, 0x1F),
            ] {
                let mut full = od.clone();
                let _ = full.set(axis.cia402_index(e.index()), 0, v);
                core.set(&mut od, &axis, e, v);
                assert!(od == full && od.config_generation() == full.config_generation());
            }
            for e in Core::ALL {
                let index = axis.cia402_index(e.index());
                od.set(index, 0, 1).unwrap();
                assert_eq!(core.get(&od, &axis, e), od.get(index, 0).unwrap());
            }
        }
        // another axis than resolved: the dictionary's answer
        let b = Axis::new(1);
        core.resolve(&od, &Axis::new(0));
        od.set(b.cia402_index(0x6061), 0, 3).unwrap();
        assert_eq!(core.get(&od, &b, Core::ModeDisplay), 3);
    }

    /// P-141: J400 through its resolved slot reads as
    /// [`DriveObjects::record_selector`], for both axes and another axis
    /// than resolved.
    #[test]
    fn p141_the_selector_slot_reads_as_record_selector() {
        use drive_core::objects::records::J400;
        let mut od = DriveObjects::new();
        let mut core = CoreSlots::new();
        for axis in [Axis::new(0), Axis::new(1)] {
            core.resolve(&od, &axis);
            assert!(od.record_selector_slot(axis.index()).is_some());
            for v in [0, 1, 17, 255, 256, 267] {
                od.set(axis.manufacturer_index(J400), 0, v).unwrap();
                let full = od.record_selector(axis.index());
                assert_eq!(full, v as u16);
                assert_eq!(core.record_selector(&od, &axis), full, "{v}");
                let other = Axis::new(1 - axis.index());
                assert_eq!(
                    core.record_selector(&od, &other),
                    od.record_selector(other.index())
                );
            }
        }
    }

    /// P-067: the cache hands out current handles and prepares stale ones
    /// again; entries outside the CiA 402 range get none.
    #[test]
    fn p067_the_prepared_cache_follows_the_configuration() {
        let mut od = DriveObjects::new();
        let mut cache = PreparedCache::new();
        let p = *cache.get(&od, 0x6042, 0).unwrap();
        assert!(od.is_current(&p));
        od.set(0x6048, 1, 99).unwrap();
        assert!(!od.is_current(&p));
        let q = cache.get(&od, 0x6042, 0).unwrap();
        assert!(od.is_current(q));
        assert!(cache.get(&od, 0x2000, 1).is_none());
        assert!(cache.get(&od, 0x6042, 99).is_none());
        // more entries than places: every one still answers
        for sub in 0..=2 {
            for index in [
                0x6040, 0x6042, 0x6048, 0x6049, 0x6060, 0x6064, 0x606C, 0x6071, 0x6077,
            ] {
                if od.prepare(index, sub, CommState::Op).is_some() {
                    assert!(cache.get(&od, index, sub).is_some(), "{index:04X}:{sub}");
                }
            }
        }
    }
}
