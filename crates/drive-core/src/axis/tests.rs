use super::*;

/// The snapshot reads only entries the dictionary declares, on both axes
/// and with the decimal places of A213 = 0, so none of its values falls back
/// to a number written down a second time (the defaults live in the object
/// declaration); a fresh dictionary gives the declared defaults.
#[test]
fn snapshot_reads_only_declared_entries() {
    use crate::axis::snapshot::{Snapshot, Window, A213};
    let mut od = DriveObjects::new();
    for axis in [0, 1] {
        let (s, misses) = Snapshot::read_counting(&od, Window { axis });
        assert_eq!(misses, 0, "axis {axis}");
        assert_eq!(
            i64::from(s.mode),
            od.get(Window { axis }.cia402(0x6060), 0).unwrap()
        );
        assert_eq!(
            i64::from(s.max_torque),
            od.get(Window { axis }.cia402(0x6072), 0).unwrap()
        );
        assert_eq!(
            i64::from(s.following_error_window),
            od.get(Window { axis }.cia402(0x6065), 0).unwrap()
        );
    }
    od.set(A213, 1, 0).unwrap();
    for axis in [0, 1] {
        assert_eq!(
            Snapshot::read_counting(&od, Window { axis }).1,
            0,
            "axis {axis}, A213 = 0"
        );
    }
}

/// The cycle keeps its configuration while the dictionary's configuration
/// generation stands and reads only the cyclic set-points again: for a write
/// of a changed value to every scalar entry of the dictionary, either the
/// axis' configuration generation moves or its refreshed snapshot equals a
/// fresh read (each axis on its own: a write to the other axis' objects
/// leaves its generation, issue 36). A Live object feeding the snapshot, a
/// set-point missing from the refresh, or an entry of one axis' window that
/// the other axis reads, fails here; the writes that leave one axis'
/// generation are counted, so the per-axis rule is exercised.
#[test]
fn cached_snapshot_equals_a_fresh_read_after_any_write() {
    use crate::axis::snapshot::{Snapshot, Window};
    use crate::objects::OBJECTS;
    let (mut checked, mut one_axis) = (0, 0);
    for o in OBJECTS.iter() {
        for e in o.info.entries {
            if !e.data_type.is_integer() {
                continue;
            }
            let mut od = DriveObjects::new();
            let windows = [Window { axis: 0 }, Window { axis: 1 }];
            let before = windows.map(|w| Snapshot::read(&od, w));
            let g0 = [0, 1].map(|a| od.axis_config_generation(a));
            let Ok(v) = od.get(o.info.index, e.sub) else {
                continue;
            };
            let v = if v < e.data_type.max_value() { v + 1 } else { v - 1 };
            if od.set(o.info.index, e.sub, v).is_err() {
                continue;
            }
            checked += 1;
            let moved = [0, 1].map(|a| od.axis_config_generation(a) != g0[a]);
            if moved[0] != moved[1] {
                one_axis += 1;
            }
            for (w, mut cached) in windows.into_iter().zip(before) {
                if moved[usize::from(w.axis)] {
                    continue;
                }
                cached.refresh_setpoints(&od, w.axis);
                assert_eq!(
                    cached,
                    Snapshot::read(&od, w),
                    "{:04X}:{} axis {}",
                    o.info.index,
                    e.sub,
                    w.axis
                );
            }
        }
    }
    assert!(checked > 300, "{checked} writes");
    assert!(
        one_axis > 100,
        "{one_axis} writes moved one axis' generation only"
    );
}

/// Every entry the control cycle reads or writes each cycle has a RAM slot
/// of the type the cycle uses on both axes (a missing or differently typed
/// one would silently read the default or drop an actual value), and no two
/// per-axis entries share one (A291, the last, is global).
#[test]
fn cyclic_slots_resolve_every_entry_on_both_axes() {
    use crate::axis::snapshot::{CyclicSlots, Window};
    let od = DriveObjects::new();
    let a = CyclicSlots::resolve(&od, Window { axis: 0 }).all();
    let b = CyclicSlots::resolve(&od, Window { axis: 1 }).all();
    let mut seen = std::vec::Vec::new();
    let n = a.len() - 1;
    assert_eq!(a[n], b[n]);
    for (k, s) in a.iter().take(n).chain(b.iter()).enumerate() {
        let s = s.unwrap_or_else(|| panic!("slot {k} missing"));
        assert!(!seen.contains(&s), "slot {k} shared");
        seen.push(s);
    }
}

/// C-134 and issue 36 (the cycle's values at fixed places): every cycle field is,
/// on both axes, the entry the dictionary resolves for its index and
/// subindex (aliases followed), at the field's offset in that axis' block
/// and of the field's type; the fields the cycle writes are no
/// configuration entries (their stores note no configuration change); and
/// a value written through the dictionary reads back through the field and
/// the other way round. A layout that moved an entry out of its block, a
/// wrong subindex or type, or a written entry that is configuration, fails.
#[test]
fn c134_cycle_fields_are_the_slots_of_both_axes() {
    use crate::axis::snapshot::Window;
    use crate::dictionary::SlotValue;
    use crate::objects::{cycle as f, CycleField, AXIS_BLOCK};
    use crate::params::{A67, E47, E48, E49, E80, I210};
    fn check<T: SlotValue + Default + TryFrom<i64> + Into<i64> + PartialEq + core::fmt::Debug>(
        index: u16,
        sub: u8,
        field: CycleField<T>,
        written: bool,
        seen: &mut std::vec::Vec<usize>,
    ) {
        for axis in 0..2u8 {
            let mut od = DriveObjects::new();
            let w = Window { axis };
            let i = if index >= 0x6000 {
                w.cia402(index)
            } else {
                w.manufacturer(index)
            };
            let slot = od
                .slot(i, sub)
                .unwrap_or_else(|| panic!("{i:04X}:{sub} has no slot"));
            let at = usize::from(axis) * AXIS_BLOCK + field.at();
            assert_eq!(usize::from(slot.ram_offset()), at, "{i:04X}:{sub}");
            assert!(slot.typed::<T>().is_some(), "{i:04X}:{sub} type");
            if written {
                assert!(!slot.is_config(), "{i:04X}:{sub} is configuration");
            }
            assert!(!seen.contains(&at), "{i:04X}:{sub} shares its place");
            seen.push(at);
            let v = T::try_from(if written { 0x55 } else { 0x2A }).unwrap_or_default();
            od.set(i, sub, v.into()).unwrap();
            assert_eq!(od.cycle_read(axis, field), v, "{i:04X}:{sub} read");
            let z = T::default();
            od.cycle_write(axis, field, z);
            assert_eq!(od.get(i, sub), Ok(z.into()), "{i:04X}:{sub} write");
        }
    }
    let mut seen = std::vec::Vec::new();
    let s = &mut seen;
    check(0x6040, 0, f::CONTROLWORD, false, s);
    check(0x6060, 0, f::MODE, false, s);
    check(0x607A, 0, f::TARGET_POSITION, false, s);
    check(0x60C1, 1, f::IP_SETPOINT, false, s);
    check(0x60FF, 0, f::TARGET_VELOCITY, false, s);
    check(0x6071, 0, f::TARGET_TORQUE, false, s);
    check(0x60B1, 0, f::VELOCITY_OFFSET, false, s);
    check(0x60B2, 0, f::TORQUE_OFFSET, false, s);
    check(0x60B8, 0, f::PROBE_FUNCTION, false, s);
    check(0x6042, 0, f::VL_TARGET, false, s);
    check(I210, 0, f::I210, false, s);
    check(0x6041, 0, f::STATUSWORD, true, s);
    check(0x6061, 0, f::MODE_DISPLAY, true, s);
    check(0x6064, 0, f::POSITION, true, s);
    check(0x606C, 0, f::VELOCITY, true, s);
    check(0x6077, 0, f::TORQUE, true, s);
    check(0x6078, 0, f::CURRENT, true, s);
    check(0x60F4, 0, f::FOLLOWING_ERROR, true, s);
    check(0x60B9, 0, f::PROBE_STATUS, true, s);
    for (k, field) in f::PROBE_VALUES.into_iter().enumerate() {
        check(0x60BA + k as u16, 0, field, true, s);
    }
    check(0x60E4, 1, f::ADDITIONAL_POSITION, true, s);
    check(0x6043, 0, f::VL_DEMAND, true, s);
    check(0x6044, 0, f::VL_ACTUAL, true, s);
    check(0x60FD, 0, f::DIGITAL_INPUTS, true, s);
    check(E80, 0, f::E80_FIELD, true, s);
    check(E48, 0, f::E48_FIELD, true, s);
    check(E47, 0, f::E47_FIELD, true, s);
    check(E49, 0, f::E49_FIELD, true, s);
    check(A67, 0, f::A67_FIELD, true, s);
    assert_eq!(seen.len(), 2 * 32);
}

/// Issue 36 (no long first or reconfiguration cycle): an axis prepared
/// outside the control cycle ([`Axis::prepare`]: its snapshot and the
/// configuration from it) cycles exactly as one that builds both at the
/// start of its cycle: the same reports, objects and axis state, from the
/// first cycle through configuration changes (A150, the vl ramps, the
/// position window) and the enable sequence into profile velocity.
#[test]
fn issue36_a_prepared_axis_cycles_as_one_configured_in_its_cycle() {
    let mut prepared_od = DriveObjects::new();
    let mut plain_od = prepared_od.clone();
    let (mut prepared, mut plain) = (Axis::new(0), Axis::new(0));
    let (mut prepared_cache, mut plain_cache) = (AxisCache::new(), AxisCache::new());
    let changes: [(u16, u8, i64); 8] = [
        (0x6060, 0, 3),
        (0x6040, 0, 6),
        (crate::params::A150, 0, 250),
        (0x6040, 0, 7),
        (0x6048, 1, 12_345),
        (0x6040, 0, 0x0F),
        (0x60FF, 0, 50_000),
        (0x6065, 0, 77),
    ];
    let mut io = AxisIo::ready(0);
    for k in 0..64u64 {
        if let Some(&(index, sub, v)) = changes.get((k / 8) as usize).filter(|_| k % 8 == 4) {
            prepared_od.set(index, sub, v).unwrap();
            plain_od.set(index, sub, v).unwrap();
        }
        io.position_inc = io.position_inc.wrapping_add(100);
        let now = Nanos::from_us(250 * k);
        prepared.prepare(&mut prepared_cache, &mut prepared_od);
        let a = prepared.cycle_cached(&mut prepared_cache, &mut prepared_od, &io, now, true);
        let b = plain.cycle_cached(&mut plain_cache, &mut plain_od, &io, now, true);
        assert_eq!(std::format!("{a:?}"), std::format!("{b:?}"), "cycle {k}");
        assert!(prepared_od == plain_od, "cycle {k}: the objects");
        assert_eq!(
            std::format!("{prepared:?}"),
            std::format!("{plain:?}"),
            "cycle {k}: the axis"
        );
    }
    assert_eq!(prepared.mode(), Mode::ProfileVelocity, "the sequence ran");
}
