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

impl Axis {
    /// Builds what [`cycle_cached`](Self::cycle_cached) keeps in `cache`
    /// (the resolved slots; the snapshot when the configuration generation
    /// moved) and the configuration it applies from them (`configure`, when
    /// the generation, the cycle or the mode class moved) outside the
    /// control cycle: where the configuration changes (start-up, a record
    /// or parameter write in the bus task), so the next cycle reads only the
    /// set-points (issue 36: no long first or reconfiguration cycle).
    /// Nothing the cycle computes differs: it would read the same snapshot
    /// at the same generation and configure with it at its start, before
    /// anything of the cycle changed the axis (`configure` reads no cyclic
    /// set-point of the snapshot).
    pub fn prepare(&mut self, cache: &mut AxisCache, od: &mut DriveObjects) {
        let generation = od.axis_config_generation(usize::from(self.window.axis));
        let slots = slots_of(&mut cache.slots, od, self.window);
        let cached: &CachedSnapshot = match &mut cache.snapshot {
            Some(cached) if cached.generation == generation => cached,
            stale => stale.insert(self.read_snapshot(od, generation)),
        };
        // as the cycle's step 2 keys it (`cycle_cached`)
        let (dt_ns, key) = (cached.dt_ns, self.config_key(generation, cached.dt_ns));
        if self.configured != Some(key) {
            let converted;
            let o = if cached.in_increments {
                &cached.snapshot
            } else {
                converted = cached.snapshot.to_increments(&self.scaling);
                &converted
            };
            self.configure(od, slots, o, dt_ns);
            self.configured = Some(key);
        }
    }

    /// The whole snapshot of this axis at `generation`, with what follows
    /// from it alone (the scaling in force from here on).
    pub(super) fn read_snapshot(&mut self, od: &DriveObjects, generation: u32) -> CachedSnapshot {
        let fresh = Snapshot::read(od, self.window);
        // C-109: user units at the objects, increments inside
        self.scaling = fresh.scaling();
        self.velocity_decimals = fresh.decimal_factors().0 as f32;
        CachedSnapshot {
            generation,
            in_increments: fresh.in_increments(&self.scaling),
            dt_ns: application_cycle_ns(u32::from(fresh.control_cycle_us).saturating_mul(1000))
                .unwrap_or(crate::params::A150_FALLBACK_US * 1000),
            snapshot: fresh,
        }
    }
}

/// The axis' resolved slots in `slots`, resolved on first use (the cache's
/// field, so the snapshot beside it stays borrowable).
#[inline(always)]
pub(super) fn slots_of<'a>(
    slots: &'a mut Option<CyclicSlots>,
    od: &DriveObjects,
    window: Window,
) -> &'a CyclicSlots {
    slots.get_or_insert_with(|| CyclicSlots::resolve(od, window))
}

impl Axis {
    /// What [`configure`](Self::configure) last ran for, as the cycle's
    /// step 2 compares it: the configuration generation, the cycle and the
    /// mode class (homing, jog, other).
    #[inline(always)]
    pub(super) fn config_key(&self, generation: u32, dt_ns: u32) -> (u32, u32, u8) {
        let class = match self.running {
            Running::Homing => 1,
            Running::Jog(_) => 2,
            _ => 0,
        };
        (generation, dt_ns, class)
    }
}
