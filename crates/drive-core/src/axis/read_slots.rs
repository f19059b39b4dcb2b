//! The snapshot's reads resolved to their [`Slot`]s ([`ReadSlots`], kept in
//! the [`AxisCache`](super::AxisCache)): a reconfiguration re-reads the
//! whole snapshot with a load per entry where a dictionary lookup (hash,
//! probe, decode) took about twenty times as long (issue 36: no long
//! reconfiguration cycle).
//!
//! The snapshot reads its entries in one order (the same code, the same
//! calls); the n-th read's slot is recorded at the first read and loaded
//! at the next ones. A running hash of the entries read, in order, checks
//! that order: a read whose hash or count differs from the recorded one is
//! done again through the dictionary (and recorded anew), so a slot is
//! never taken for another entry's value.

use core::cell::Cell;

use crate::dictionary::{DriveObjects, Slot};

/// Reads recorded (the snapshot reads about 130 entries; later ones go
/// through the dictionary).
pub(crate) const READS: usize = 144;

/// The recorded slots of one axis' snapshot reads.
#[derive(Debug, Clone)]
pub struct ReadSlots {
    slots: [Cell<Option<Slot>>; READS],
    /// Hash of the entries read, in order, and their count, at recording;
    /// `None`: nothing recorded yet.
    recorded: Cell<Option<(u32, u16)>>,
}

impl Default for ReadSlots {
    fn default() -> Self {
        Self::new()
    }
}

impl ReadSlots {
    /// Nothing recorded.
    pub const fn new() -> Self {
        Self {
            slots: [const { Cell::new(None) }; READS],
            recorded: Cell::new(None),
        }
    }

    /// The recorded order's hash and count of reads.
    #[cfg(test)]
    pub fn recorded(&self) -> Option<(u32, u16)> {
        self.recorded.get()
    }
}

/// One snapshot read in progress: the entries that could not be read, the
/// position in the order, the hash of the order so far, and the slots it
/// replays (`replay`) or records.
pub(crate) struct Reads<'a> {
    misses: Cell<u32>,
    at: Cell<u16>,
    hash: Cell<u32>,
    slots: Option<&'a ReadSlots>,
    replay: bool,
}

impl<'a> Reads<'a> {
    /// A read through the dictionary alone.
    #[cfg(test)]
    pub fn plain() -> Self {
        Self::with(None, false)
    }

    fn with(slots: Option<&'a ReadSlots>, replay: bool) -> Self {
        Self {
            misses: Cell::new(0),
            at: Cell::new(0),
            hash: Cell::new(0),
            slots,
            replay,
        }
    }

    /// `read` with the slots of `slots`: replayed when recorded, checked
    /// against the recorded order afterwards (read again and recorded when
    /// it differs); recorded when not.
    pub fn run<T>(slots: &'a ReadSlots, mut read: impl FnMut(&Reads<'_>) -> T) -> (T, u32) {
        let recorded = slots.recorded.get();
        if recorded.is_some() {
            let r = Reads::with(Some(slots), true);
            let out = read(&r);
            if recorded == Some((r.hash.get(), r.at.get())) {
                return (out, r.misses.get());
            }
        }
        let r = Reads::with(Some(slots), false);
        let out = read(&r);
        slots.recorded.set(Some((r.hash.get(), r.at.get())));
        (out, r.misses.get())
    }

    /// Entries that could not be read (0 in the snapshot).
    #[cfg(test)]
    pub fn misses(&self) -> u32 {
        self.misses.get()
    }

    /// Entry `index`:`sub`, or 0 with the miss counted.
    pub fn read(&self, od: &DriveObjects, index: u16, sub: u8) -> i64 {
        let at = self.at.get();
        self.at.set(at.saturating_add(1));
        let key = u32::from(index) << 8 | u32::from(sub);
        self.hash
            .set(self.hash.get().rotate_left(5).wrapping_mul(0x9E37_79B1) ^ key);
        if let Some(cell) = self.slots.and_then(|s| s.slots.get(usize::from(at))) {
            if !self.replay {
                cell.set(od.slot(index, sub));
            }
            if let Some(slot) = cell.get() {
                return od.load_slot(slot);
            }
        }
        od.get(index, sub).unwrap_or_else(|_| {
            self.misses.set(self.misses.get().saturating_add(1));
            0
        })
    }
}
