//! The record fields of the PROFIdrive parameter access (PNU 1001, the
//! selected record; PNU 1040…1042, the jog records 259/260): the pending
//! record edited in place and stored at the next other access, and the jog
//! records' fields written word by word where neither is pending (issue 36).

use super::*;

impl DriveAccess<'_> {
    pub(super) fn record_number(&self, jog: Option<Jog>) -> u16 {
        match jog {
            Some(Jog::Negative) => JOG_NEGATIVE,
            Some(_) => JOG_POSITIVE,
            None => self.core.record_selector(self.objects, self.axis),
        }
    }

    /// Stores the record the last field writes left pending (and shows it
    /// when the window J401 shows it), as each of those writes did before.
    #[inline(always)]
    pub fn flush_record(&mut self) {
        // the test inline, the store out of line: every read and every
        // other write asks, mostly with nothing pending (issue 36)
        if self.pending.is_some() {
            self.store_pending();
        }
    }

    /// [`flush_record`](Self::flush_record) of a pending record.
    #[inline(never)]
    fn store_pending(&mut self) {
        // compared where it is, not moved out (`take`)
        let Some((axis, n, _, r, read)) = &self.pending else {
            return;
        };
        // record `n` was read just before: it is there to store
        if r != read {
            let _ = self.objects.set_record(*axis, *n, r);
        }
        self.pending = None;
    }

    pub(super) fn read_record(
        &mut self,
        jog: Option<Jog>,
        field: RecordField,
        unit: Unit,
    ) -> Result<i64, PdError> {
        self.flush_record();
        let n = self.record_number(jog);
        let r = self
            .objects
            .record(self.axis.index(), n)
            .ok_or(PdError::NOT_IN_STATE)?;
        let v = match field {
            RecordField::Target => i64::from(r.target),
            RecordField::ProfileVelocity => i64::from(r.profile_velocity),
            RecordField::EndVelocity => i64::from(r.end_velocity),
            RecordField::Acceleration | RecordField::BothAccelerations => i64::from(r.acceleration),
            RecordField::Deceleration => i64::from(r.deceleration),
        };
        self.bus_of(unit, v)
    }

    pub(super) fn write_record(
        &mut self,
        jog: Option<Jog>,
        field: RecordField,
        unit: Unit,
        bus: i64,
    ) -> Result<(), PdError> {
        let value = self.object_of(unit, bus)?;
        let numbers: &[u16] = match jog {
            Some(Jog::Both) => &[JOG_POSITIVE, JOG_NEGATIVE],
            _ => &[0],
        };
        let axis = self.axis.index();
        if let Some(j) = jog {
            let one = [self.record_number(Some(j))];
            let jogs = if j == Jog::Both { numbers } else { &one[..] };
            if !matches!(self.pending, Some((a, m, ..)) if a == axis && jogs.contains(&m)) {
                return self.write_jog_words(axis, jogs, field, value);
            }
        }
        for &k in numbers {
            let selected = k == 0 && jog.is_none();
            let n = match self.pending {
                Some((a, m, true, ..)) if selected && a == axis => m,
                _ if k == 0 => self.record_number(jog),
                _ => k,
            };
            // the pending record of `n` is edited in place (issue 36: the
            // two records copied out and back per field cost more than the
            // edit); another one is stored first and `n` read (a field the
            // record refuses leaves it as read: nothing to store)
            if !matches!(self.pending, Some((a, m, ..)) if (a, m) == (axis, n)) {
                self.flush_record();
                let read = self.objects.record(axis, n).ok_or(PdError::NOT_IN_STATE)?;
                self.pending = Some((axis, n, false, read, read));
            }
            let Some((_, _, flag, r, _)) = self.pending.as_mut() else {
                return Err(PdError::NOT_IN_STATE);
            };
            let as_u32 = || u32::try_from(value).map_err(|_| PdError::LIMIT_EXCEEDED);
            match field {
                RecordField::Target => {
                    r.target = i32::try_from(value).map_err(|_| PdError::LIMIT_EXCEEDED)?
                }
                RecordField::ProfileVelocity => r.profile_velocity = as_u32()?,
                RecordField::EndVelocity => r.end_velocity = as_u32()?,
                RecordField::Acceleration => r.acceleration = as_u32()?,
                RecordField::Deceleration => r.deceleration = as_u32()?,
                RecordField::BothAccelerations => {
                    r.acceleration = as_u32()?;
                    r.deceleration = r.acceleration;
                }
            }
            // stored at the next other access (a record that was read is
            // there to store: set_record cannot refuse it)
            *flag = selected;
        }
        Ok(())
    }

    /// A field of the jog records `numbers` (none of them pending) written
    /// word by word where it changed (`DriveObjects::set_record_word`), as
    /// the pending edit and its store would leave them, without reading
    /// and comparing the records whole (issue 36: PNU 1040 in telegram 0
    /// took two records through the pending edit every telegram). The
    /// selected record stays pending.
    fn write_jog_words(
        &mut self,
        axis: u8,
        numbers: &[u16],
        field: RecordField,
        value: i64,
    ) -> Result<(), PdError> {
        let word = match field {
            RecordField::Target => i32::try_from(value).map_err(|_| PdError::LIMIT_EXCEEDED)? as u32,
            _ => u32::try_from(value).map_err(|_| PdError::LIMIT_EXCEEDED)?,
        };
        let words: &[usize] = match field {
            RecordField::Target => &[0],
            RecordField::ProfileVelocity => &[1],
            RecordField::EndVelocity => &[2],
            RecordField::Acceleration => &[3],
            RecordField::Deceleration => &[4],
            RecordField::BothAccelerations => &[3, 4],
        };
        for &n in numbers {
            for &w in words {
                self.objects
                    .set_record_word(axis, n, w, word)
                    .ok_or(PdError::NOT_IN_STATE)?;
            }
        }
        Ok(())
    }
}
