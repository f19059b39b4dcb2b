//! A tiny bounded neighbour cache: IPv4 → MAC, learned from ARP and from the
//! IPv4 packets we receive, used to address replies and the device's own
//! requests (CControl). The oldest entry is replaced when the cache is full.

use super::Ipv4Addr;
use crate::wire::MacAddr;
use nanos::Nanos;

/// How long an entry stays valid without being refreshed.
pub const NEIGHBOUR_TTL: Nanos = Nanos::from_secs(300);

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Entry {
    ip: Ipv4Addr,
    mac: MacAddr,
    seen: Nanos,
}

/// A neighbour cache of `N` entries.
#[derive(Clone, Debug)]
pub struct NeighbourCache<const N: usize> {
    entries: [Option<Entry>; N],
}

impl<const N: usize> Default for NeighbourCache<N> {
    fn default() -> Self {
        NeighbourCache { entries: [None; N] }
    }
}

impl<const N: usize> NeighbourCache<N> {
    /// Records (or refreshes) `ip` at `mac`. Unspecified, broadcast and
    /// multicast sources are never recorded.
    pub fn learn(&mut self, now: Nanos, ip: Ipv4Addr, mac: MacAddr) {
        if ip == Ipv4Addr::UNSPECIFIED || ip == Ipv4Addr::BROADCAST || mac.is_multicast() {
            return;
        }
        let fresh = Some(Entry { ip, mac, seen: now });
        if let Some(e) = self
            .entries
            .iter_mut()
            .find(|e| matches!(e, Some(x) if x.ip == ip))
        {
            *e = fresh;
            return;
        }
        if let Some(e) = self.entries.iter_mut().find(|e| e.is_none()) {
            *e = fresh;
            return;
        }
        // Full: replace the entry seen longest ago.
        if let Some(e) = self
            .entries
            .iter_mut()
            .min_by_key(|e| e.map_or(Nanos::ZERO, |x| x.seen))
        {
            *e = fresh;
        }
    }

    /// The MAC of `ip`, if known and not older than [`NEIGHBOUR_TTL`].
    pub fn lookup(&self, now: Nanos, ip: Ipv4Addr) -> Option<MacAddr> {
        self.entries
            .iter()
            .flatten()
            .find(|e| e.ip == ip && now - e.seen <= NEIGHBOUR_TTL)
            .map(|e| e.mac)
    }

    /// Forgets every entry (after an IP address change).
    pub fn clear(&mut self) {
        self.entries = [None; N];
    }
}
