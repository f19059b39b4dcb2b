//! The position records in the dictionary ([`crate::objects::records`]):
//! J401 is the window on the record J400 selects. A bus write of J401 goes
//! through to the record at once; a write of J400 first puts the window back
//! into the record it showed (a cyclic mapping of J401 writes the window
//! only) and then shows the new one. J401\[5\] "all accelerations" (P-144):
//! a bus write sets \[3\] and \[4\]; it reads as \[3\] (a write of \[3\]
//! sets it too); a value a cyclic mapping wrote into \[5\] (it differs from
//! what was last synchronised) sets both accelerations when the record is
//! used ([`DriveObjects::take_record`]).

use super::*;
pub(super) use crate::objects::records::ALL_ACCELERATIONS_DEFAULT;
use crate::objects::records::{
    place, Record, FIELDBUS, J400, J401, J410, J411, OPT_IMMEDIATE, OPT_RELATIVE, RECORDS, RECORD_BYTES,
    TASK_STATE_AT, TASK_STATE_BYTES,
};
use crate::AXIS_B_MANUFACTURER;

/// The axis (0, 1) of per-axis record object `index`, if it is `object`
/// (axis-A numbering) or its axis-B copy.
fn axis_of(index: u16, object: u16) -> Option<u8> {
    if index == object {
        Some(0)
    } else if index == object.wrapping_add(AXIS_B_MANUFACTURER) {
        Some(1)
    } else {
        None
    }
}

/// `index` of axis `axis` (axis-A numbering given).
fn at_axis(index: u16, axis: u8) -> u16 {
    if axis == 0 {
        index
    } else {
        index.wrapping_add(AXIS_B_MANUFACTURER)
    }
}

/// Where the values of J410, J411 (axis A) and J411 (axis B) start in the
/// image (compile time).
const J410_AT: usize = objects::image_offset(J410);
const J411_AT: [usize; 2] = [
    objects::image_offset(J411),
    objects::image_offset(J411 + AXIS_B_MANUFACTURER),
];
const _: () = assert!(J410_AT > 0 && J411_AT[0] > 0 && J411_AT[1] > 0);

/// Where the values of the window J401 of axis A and B start in the image
/// (compile time): sub 0, then the elements \[0\] (INTEGER32), \[1\]…\[5\]
/// (UNSIGNED32) and \[6\] (UNSIGNED8).
const J401_AT: [usize; 2] = [
    objects::image_offset(J401),
    objects::image_offset(J401 + AXIS_B_MANUFACTURER),
];
const _: () = assert!(J401_AT[0] > 0 && J401_AT[1] > 0);

/// Bytes of the window's elements \[0\]…\[6\].
const WINDOW_BYTES: usize = 6 * 4 + 1;

/// Where J411 of `axis` starts in the image.
fn j411_at(axis: u8) -> usize {
    if axis == 0 {
        J411_AT[0]
    } else {
        J411_AT[1]
    }
}

/// Copies `src` into `dst` (as far as both reach; no length panic).
fn copy(dst: &mut [u8], src: &[u8]) {
    for (d, s) in dst.iter_mut().zip(src) {
        *d = *s;
    }
}

/// J401 element `k` in the runtime ("SDO Info") numbering.
const fn data_sub(k: u8) -> u8 {
    k + 1
}

impl DriveObjects {
    /// Where the record positioning state of `axis` lives in the image.
    fn task_state_range(axis: u8) -> core::ops::Range<usize> {
        let at = j411_at(axis) + 1 + TASK_STATE_AT;
        at..at + TASK_STATE_BYTES
    }

    /// The record positioning state of `axis` (decoded).
    pub(crate) fn record_tasks(&self, axis: u8) -> crate::axis::RecordTasks {
        let bytes = self.image.get(Self::task_state_range(axis)).unwrap_or(&[]);
        crate::axis::RecordTasks::from_bytes(bytes)
    }

    /// Stores the record positioning state of `axis`.
    pub(crate) fn set_record_tasks(&mut self, axis: u8, t: &crate::axis::RecordTasks) {
        if let Some(dst) = self.image.get_mut(Self::task_state_range(axis)) {
            copy(dst, &t.to_bytes());
        }
    }

    /// The record selector J400 of `axis`.
    pub fn record_selector(&self, axis: u8) -> u16 {
        self.get(at_axis(J400, axis), 0)
            .map_or(FIELDBUS, |v| u16::try_from(v).unwrap_or(FIELDBUS))
    }

    /// The [`Slot`] of J400 of `axis` (`None` when it has none: then
    /// [`record_selector`](Self::record_selector) reads it).
    pub fn record_selector_slot(&self, axis: u8) -> Option<Slot> {
        self.slot(at_axis(J400, axis), 0)
    }

    /// [`record_selector`](Self::record_selector) through J400's
    /// [`record_selector_slot`](Self::record_selector_slot): a load where
    /// `get` looks J400 up (issue 36: ~170 instructions per telegram 0).
    pub fn record_selector_at(&self, slot: Slot) -> u16 {
        u16::try_from(self.load_slot(slot)).unwrap_or(FIELDBUS)
    }

    /// Byte range of record `n` of `axis` in the image and of its options.
    fn record_range(axis: u8, n: u16) -> Option<(core::ops::Range<usize>, usize)> {
        let (object, at, options) = place(n)?;
        // arrays: the elements follow sub 0 (UNSIGNED8)
        let base = if object == J410 { J410_AT } else { j411_at(axis) } + 1;
        Some((base + at..base + at + RECORD_BYTES, base + options))
    }

    /// Record `n` (0 … 267) of `axis` as stored (a cyclic write of the
    /// window J401 not yet put back is not in it; see
    /// [`take_record`](Self::take_record)).
    pub fn record(&self, axis: u8, n: u16) -> Option<Record> {
        let (range, options) = Self::record_range(axis, n)?;
        let options = self.image.get(options).copied().unwrap_or(0);
        Record::from_bytes(self.image.get(range)?, options)
    }

    /// Stores record `n` of `axis`;
    /// the window J401 follows when it shows `n`. `false`: no such record.
    pub fn set_record(&mut self, axis: u8, n: u16, r: &Record) -> bool {
        if !self.store_record(axis, n, r) {
            return false;
        }
        if self.record_selector(axis) == n {
            self.show_record(axis, n);
        }
        true
    }

    /// Word `w` of record `n` of `axis` (0 target, 1 profile velocity,
    /// 2 end velocity, 3 acceleration, 4 deceleration: [`Record::to_bytes`])
    /// set to `value` where it holds another, the window J401 following
    /// when it shows `n` (as [`set_record`](Self::set_record) of the whole
    /// record with that word changed). `Some(true)` stored, `Some(false)`
    /// it held `value`, `None` no such record or word (issue 36: a field of
    /// the jog records written by telegram 0 without the record read and
    /// compared whole).
    pub fn set_record_word(&mut self, axis: u8, n: u16, w: usize, value: u32) -> Option<bool> {
        if w >= RECORD_BYTES / 4 {
            return None;
        }
        let (range, _) = Self::record_range(axis, n)?;
        let at = range.start + 4 * w;
        let dst = self.image.get_mut(at..at + 4)?;
        let bytes = value.to_le_bytes();
        if *dst == bytes {
            return Some(false);
        }
        copy(dst, &bytes);
        if self.record_selector(axis) == n {
            self.show_record(axis, n);
        }
        Some(true)
    }

    fn store_record(&mut self, axis: u8, n: u16, r: &Record) -> bool {
        let Some((range, options)) = Self::record_range(axis, n) else {
            return false;
        };
        let Some(dst) = self.image.get_mut(range) else {
            return false;
        };
        copy(dst, &r.to_bytes());
        if let Some(b) = self.image.get_mut(options) {
            *b = r.options & (OPT_RELATIVE | OPT_IMMEDIATE);
        }
        true
    }

    /// Record `n` of `axis` for a start or a jog: the window J401 when it
    /// shows `n` (with a value a cyclic mapping left in J401\[5\] applied to
    /// both accelerations), put back into the record; else the record.
    pub fn take_record(&mut self, axis: u8, n: u16) -> Option<Record> {
        if n >= RECORDS {
            return None;
        }
        if self.record_selector(axis) != n {
            return self.record(axis, n);
        }
        let r = self.window(axis)?;
        self.store_record(axis, n, &r);
        Some(r)
    }

    /// The window J401 of `axis` as a record: a new value in \[5\] set both
    /// accelerations; afterwards \[5\] = \[3\].
    fn window(&mut self, axis: u8) -> Option<Record> {
        let w = at_axis(J401, axis);
        let get = |k: u8| self.get(w, data_sub(k)).ok();
        let all = get(5).and_then(|v| u32::try_from(v).ok()).unwrap_or(0);
        let mut r = Record {
            target: i32::try_from(get(0)?).ok()?,
            profile_velocity: u32::try_from(get(1)?).ok()?,
            end_velocity: u32::try_from(get(2)?).ok()?,
            acceleration: u32::try_from(get(3)?).ok()?,
            deceleration: u32::try_from(get(4)?).ok()?,
            options: u8::try_from(get(6)?).ok()?,
        };
        let seen = self.all_accelerations.get_mut(usize::from(axis))?;
        if all != *seen {
            r.acceleration = all;
            r.deceleration = all;
            let _ = self.set(w, data_sub(4), i64::from(all));
        }
        self.sync_all_accelerations(axis, r.acceleration);
        Some(r)
    }

    /// J401\[3\] and \[5\] of `axis` = `acceleration`, synchronised.
    fn sync_all_accelerations(&mut self, axis: u8, acceleration: u32) {
        let w = at_axis(J401, axis);
        let _ = self.set(w, data_sub(3), i64::from(acceleration));
        let _ = self.set(w, data_sub(5), i64::from(acceleration));
        if let Some(seen) = self.all_accelerations.get_mut(usize::from(axis)) {
            *seen = acceleration;
        }
    }

    /// Shows record `n` of `axis` in the window J401: its elements written
    /// straight into the image, as the `set` of each (set-points: no
    /// configuration change; every value in its type's range) would, with
    /// \[3\] and \[5\] synchronised (issue 36: eight `set`s per telegram
    /// that writes a record's fields).
    fn show_record(&mut self, axis: u8, n: u16) {
        let Some(r) = self.record(axis, n) else {
            return;
        };
        let mut w = [0u8; WINDOW_BYTES];
        let words = [
            r.target as u32,
            r.profile_velocity,
            r.end_velocity,
            r.acceleration,
            r.deceleration,
            r.acceleration,
        ];
        for (dst, v) in w.chunks_exact_mut(4).zip(words) {
            copy(dst, &v.to_le_bytes());
        }
        if let Some(last) = w.last_mut() {
            *last = r.options;
        }
        let at = if axis == 0 { J401_AT[0] } else { J401_AT[1] } + 1;
        if let Some(dst) = self.image.get_mut(at..at + WINDOW_BYTES) {
            copy(dst, &w);
        }
        if let Some(seen) = self.all_accelerations.get_mut(usize::from(axis)) {
            *seen = r.acceleration;
        }
    }

    /// [`show_record`](Self::show_record) through `set` (the reference of
    /// its test).
    #[cfg(test)]
    pub(crate) fn show_record_by_set(&mut self, axis: u8, n: u16) {
        let Some(r) = self.record(axis, n) else {
            return;
        };
        let w = at_axis(J401, axis);
        let values = [
            i64::from(r.target),
            i64::from(r.profile_velocity),
            i64::from(r.end_velocity),
            i64::from(r.acceleration),
            i64::from(r.deceleration),
        ];
        for (k, v) in (0u8..).zip(values) {
            let _ = self.set(w, data_sub(k), v);
        }
        let _ = self.set(w, data_sub(6), i64::from(r.options));
        self.sync_all_accelerations(axis, r.acceleration);
    }

    /// Before a bus write of `index`: puts the window back before the
    /// selector moves.
    pub(super) fn record_write_check(&mut self, index: u16) {
        if let Some(axis) = axis_of(index, J400) {
            let n = self.record_selector(axis);
            if let Some(r) = self.window(axis) {
                self.store_record(axis, n, &r);
            }
        }
    }

    /// After a bus write of `index`:`sub`: the window goes through to its
    /// record, a new selector shows its record.
    pub(super) fn record_written(&mut self, index: u16, sub: u8, value: Option<i64>) {
        if let Some(axis) = axis_of(index, J401) {
            let w = at_axis(J401, axis);
            let v = value.and_then(|v| u32::try_from(v).ok());
            match v {
                Some(v) if sub == data_sub(5) => {
                    let _ = self.set(w, data_sub(4), i64::from(v));
                    self.sync_all_accelerations(axis, v);
                }
                Some(v) if sub == data_sub(3) => self.sync_all_accelerations(axis, v),
                _ => {}
            }
            let n = self.record_selector(axis);
            if let Some(r) = self.window(axis) {
                self.store_record(axis, n, &r);
            }
        } else if let Some(axis) = axis_of(index, J400) {
            let n = self.record_selector(axis);
            self.show_record(axis, n);
        }
    }

    /// After the defaults were restored or a saved set loaded: the record
    /// memory at its defaults where it is not kept (restore), and every
    /// window showing its record.
    pub(super) fn records_reloaded(&mut self, restore: bool) {
        self.refresh_module_idents();
        if restore {
            let memory = [J410, J411, J411 + AXIS_B_MANUFACTURER];
            super::persist::write_defaults(&mut self.image, |index, _| memory.contains(&index));
        }
        for axis in [0, 1] {
            let n = self.record_selector(axis);
            self.show_record(axis, n);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The window shows a record as the `set`s of its elements did: image,
    /// synchronised "all accelerations" and generations the same, on both
    /// axes, for standard and per-axis records.
    #[test]
    fn the_window_shows_a_record_as_its_sets_did() {
        let base = DriveObjects::new();
        let records = [
            (
                0u16,
                Record {
                    target: -123_456,
                    profile_velocity: u32::MAX,
                    end_velocity: 7,
                    acceleration: 0x0102_0304,
                    deceleration: 99,
                    options: 3,
                },
            ),
            (
                266,
                Record {
                    target: i32::MIN,
                    profile_velocity: 1,
                    end_velocity: 0,
                    acceleration: 0,
                    deceleration: u32::MAX,
                    options: 0,
                },
            ),
            (
                267,
                Record {
                    target: i32::MAX,
                    profile_velocity: 5000,
                    end_velocity: 400,
                    acceleration: 10_000,
                    deceleration: 20_000,
                    options: 1,
                },
            ),
        ];
        for axis in [0u8, 1] {
            for (n, r) in records {
                let mut od = base.clone();
                assert!(od.store_record(axis, n, &r));
                // the window showed something else
                let _ = od.set(at_axis(J401, axis), data_sub(5), 5);
                let _ = od.set(at_axis(J401, axis), data_sub(0), -1);
                let mut reference = od.clone();
                od.show_record(axis, n);
                reference.show_record_by_set(axis, n);
                assert!(od == reference, "axis {axis} record {n}");
                assert_eq!(od.all_accelerations, reference.all_accelerations);
                assert_eq!(od.config_generation(), reference.config_generation());
                assert_eq!(od.record(axis, n).map(|x| x.target), Some(r.target));
            }
        }
    }
}
