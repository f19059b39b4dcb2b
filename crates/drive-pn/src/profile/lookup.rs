//! Lookups of the cyclic path, cheap (issue 17, cycle cost): the PNU
//! catalogue by binary search (it is sorted by PNU and subindex, which
//! `p190_the_catalogue_is_sorted_without_duplicates` keeps) with the answers
//! of [`pnu::find`] / [`pnu::is_catalogue_index`], and the CiA 402 entries a
//! telegram reads and writes every cycle prepared once per configuration
//! generation ([`PreparedCache`], [`drive_core::Prepared`]) instead of
//! looked up and checked by the dictionary at each access.

use super::pnu::{self, Pnu};
use core::cell::Cell;
use drive_core::{DriveObjects, Prepared};
use od::CommState;
use profidrive::{Addr, PdError};

/// [`pnu::find`]: the entry of `addr`, 0x00 without the PNU, 0x03 without
/// the subindex.
pub fn find(addr: Addr) -> Result<&'static Pnu, PdError> {
    let c = pnu::CATALOGUE;
    let key = |a: Addr| u32::from(a.index) << 8 | u32::from(a.sub);
    let i = c.partition_point(|p| key(p.addr) < key(addr));
    let here = c.get(i);
    if let Some(p) = here.filter(|p| p.addr == addr) {
        return Ok(p);
    }
    // the PNU's other subindices sit just before or at `i`
    let known = |p: Option<&Pnu>| p.is_some_and(|p| p.addr.index == addr.index);
    Err(if known(here) || known(i.checked_sub(1).and_then(|j| c.get(j))) {
        PdError::FAULTY_SUBINDEX
    } else {
        PdError::IMPERMISSIBLE_PNU
    })
}

/// [`pnu::is_catalogue_index`].
pub fn is_catalogue_index(index: u16) -> bool {
    let c = pnu::CATALOGUE;
    index < 0x1000
        || c.get(c.partition_point(|p| p.addr.index < index))
            .is_some_and(|p| p.addr.index == index)
}

/// Entries kept (the default telegrams touch nine CiA 402 entries).
const ENTRIES: usize = 12;

/// The CiA 402 entries last accessed, prepared (Op, the profile's state);
/// a stale one is prepared again, a new one takes the oldest place.
#[derive(Debug)]
pub struct PreparedCache {
    /// `1 << 24 | index << 8 | sub`, 0 = free.
    keys: [Cell<u32>; ENTRIES],
    handles: [Cell<Option<Prepared>>; ENTRIES],
    next: Cell<usize>,
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
            keys: [const { Cell::new(0) }; ENTRIES],
            handles: [const { Cell::new(None) }; ENTRIES],
            next: Cell::new(0),
        }
    }

    /// `index`:`sub` prepared and current, or `None` (not a CiA 402 entry
    /// [`DriveObjects::prepare`] takes: the full path).
    pub fn get(&self, objects: &DriveObjects, index: u16, sub: u8) -> Option<Prepared> {
        if !(0x6000..=0x6FFF).contains(&index) {
            return None;
        }
        let key = 1 << 24 | u32::from(index) << 8 | u32::from(sub);
        let at = match self.keys.iter().position(|k| k.get() == key) {
            Some(at) => {
                if let Some(p) = self.handles.get(at)?.get().filter(|p| objects.is_current(p)) {
                    return Some(p);
                }
                at
            }
            None => {
                let at = self.next.get() % ENTRIES;
                self.next.set(at + 1);
                at
            }
        };
        let p = objects.prepare(index, sub, CommState::Op);
        self.keys.get(at)?.set(if p.is_some() { key } else { 0 });
        self.handles.get(at)?.set(p);
        p
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

    /// P-067: the cache hands out current handles and prepares stale ones
    /// again; entries outside the CiA 402 range get none.
    #[test]
    fn p067_the_prepared_cache_follows_the_configuration() {
        let mut od = DriveObjects::new();
        let cache = PreparedCache::new();
        let p = cache.get(&od, 0x6042, 0).unwrap();
        assert!(od.is_current(&p));
        od.set(0x6048, 1, 99).unwrap();
        assert!(!od.is_current(&p));
        let q = cache.get(&od, 0x6042, 0).unwrap();
        assert!(od.is_current(&q));
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
