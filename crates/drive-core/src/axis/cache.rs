//! What an axis keeps between control cycles about the dictionary
//! ([`AxisCache`]): the snapshot with its configuration generation and the
//! resolved slots of the cyclic entries.

use super::*;

/// What an axis keeps between control cycles about the dictionary: the
/// snapshot of its objects with the configuration generation it was read
/// at (while the generation stands only the cyclic set-points are read
/// again) and the resolved slots of its cyclic entries
/// (docs/architecture.md, cycle cost).
#[derive(Debug, Clone, Default)]
pub struct AxisCache {
    pub(super) snapshot: Option<CachedSnapshot>,
    pub(super) slots: Option<CyclicSlots>,
}

/// The snapshot with the configuration generation it was read at and what
/// follows from it alone.
#[derive(Debug, Clone)]
pub(super) struct CachedSnapshot {
    pub(super) generation: u32,
    pub(super) snapshot: Snapshot,
    /// The user units are increments (no conversion of the snapshot).
    pub(super) in_increments: bool,
    /// The control cycle A150, ns (`A150_FALLBACK_US` when A150 is not one
    /// of the cycles).
    pub(super) dt_ns: u32,
}

impl AxisCache {
    /// Empty: the first cycle reads everything.
    pub const fn new() -> Self {
        Self {
            snapshot: None,
            slots: None,
        }
    }
}
