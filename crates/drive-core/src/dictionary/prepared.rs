//! Prepared bus accesses ([`Prepared`]): a CiA 402 entry's bus read or
//! write ([`Dictionary::read`] / [`Dictionary::write`] of a [`DriveObjects`])
//! with what depends only on the configuration looked up once (the visible
//! entry in the active template, its access rights in a state, the place it
//! lives, its range and value list), then done with the value's checks and a
//! load or store of its bytes while the configuration generation
//! ([`DriveObjects::config_generation`]) stands. A personality that reads
//! and writes the same entries every cycle (the PROFIdrive profile's
//! telegrams) uses it; the answers are those of the full path.

use super::*;

/// An entry prepared for bus reads and writes by
/// [`DriveObjects::prepare`]. It goes stale when the configuration
/// generation moves (visibility, template and every parameter count there);
/// [`DriveObjects::read_prepared`] / [`DriveObjects::write_prepared`] then
/// answer `None` and the caller takes the full path (and prepares again).
#[derive(Debug, Clone, Copy)]
pub struct Prepared {
    generation: u32,
    /// The value in the RAM image (the target entry, aliases followed; its
    /// type is the visible entry's).
    slot: Slot,
    readable: bool,
    writable: bool,
    /// The target has a value list ([`enumeration`], looked up at a write).
    listed: bool,
    /// The target entry's record in [`crate::objects::ENTRY_TABLE`] (type, range).
    target: crate::objects::EntryRecord,
    /// The target object's index (for its value list).
    index: u16,
}

impl Prepared {
    /// The type of the entry as the bus sees it.
    pub fn data_type(&self) -> DataType {
        // the slot's type is the target's (`prepare`), one slot type per
        // data type: no decode of the packed table, which cost ~25
        // instructions a time on the host, up to four times per written
        // entry (issue 36)
        self.slot.kind.data_type()
    }
}

impl DriveObjects {
    /// `index`:`sub` (numbering of the active template, as the bus reads it)
    /// prepared for bus accesses in `state`: `Some` for an integer entry of
    /// a visible CiA 402 object (6000h…6FFFh, either axis) whose value lives
    /// in the RAM image; `None` for everything else (which keeps the full
    /// path: objects with consistency checks, records, side effects,
    /// commands, strings, constants).
    pub fn prepare(&self, index: u16, sub: u8, state: CommState) -> Option<Prepared> {
        if !(0x6000..=0x6FFF).contains(&index) {
            return None;
        }
        let loc = self.locate(index, sub).ok()?;
        let o = loc.object().ok()?;
        let e = loc.record().ok()?;
        let target = follow(loc).ok()?;
        let (to, te) = (target.object().ok()?, target.record().ok()?);
        let t = te.data_type();
        if o.has_rx_view() || !matches!(to.value, Value::Ram | Value::Live) || e.data_type() != t {
            return None;
        }
        let range = target.slot().ok()?;
        if range.end > IMAGE_BYTES || range.len() != t.bytes() {
            return None;
        }
        Some(Prepared {
            generation: self.config_generation,
            slot: Slot {
                at: u16::try_from(range.start).ok()?,
                kind: SlotType::of(t)?,
                config: is_config(to),
            },
            readable: e.access().readable(),
            // a live entry's write goes to its provider first: not here
            writable: e.access().writable()
                && e.access().writable_in(state.access_bit())
                && matches!(to.value, Value::Ram),
            listed: enumeration(to.info.index, te.sub()).is_some(),
            target: te,
            index: to.info.index,
        })
    }

    /// Whether `p` is still current (the configuration generation it was
    /// prepared at stands).
    #[inline]
    pub fn is_current(&self, p: &Prepared) -> bool {
        p.generation == self.config_generation
    }

    /// The value [`Dictionary::read`] of the prepared entry gives (its bytes
    /// as its type reads them); `None` when `p` is stale or the entry is not
    /// readable (take the full path).
    #[inline]
    pub fn read_prepared(&self, p: &Prepared) -> Option<i64> {
        (self.is_current(p) && p.readable).then(|| self.load_slot(p.slot))
    }

    /// [`Dictionary::write`] of `data` to the prepared entry (the state it
    /// was prepared for); `None` when `p` is stale, the entry is not
    /// writable there or `data` is not the value's width (take the full
    /// path).
    pub fn write_prepared(&mut self, p: &Prepared, data: &[u8]) -> Option<Result<(), SdoAbort>> {
        if !self.is_current(p) || !p.writable || data.len() != p.slot.bytes() {
            return None;
        }
        // the checks of `write_with` for an entry without consistency
        // checks, record hooks or side effects (`load`: the value as
        // `decode` reads it at the type's own width), then its store: the
        // same bytes, a changed configuration value counted
        let check = load(data, 0, p.data_type()).and_then(|v| {
            p.target.check_range(v)?;
            match p.listed.then(|| enumeration(p.index, p.target.sub())).flatten() {
                Some(list) if !list.contains(&v) => Err(SdoAbort::INVALID_VALUE),
                _ => Ok(v),
            }
        });
        Some(check.map(|v| {
            // a changed configuration value counted for the axes whose
            // entry it is (`config_changed_at`), not for both
            let changed = p.slot.config && self.load_slot(p.slot) != v;
            self.store_slot(
                Slot {
                    config: false,
                    ..p.slot
                },
                v,
            );
            if changed {
                self.config_changed_at(p.index);
            }
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(od: &mut DriveObjects, index: u16, sub: u8) -> Result<std::vec::Vec<u8>, SdoAbort> {
        let mut buf = [0u8; 8];
        let n = Dictionary::read(od, index, sub, &mut buf, CommState::Op)?;
        Ok(buf[..n].to_vec())
    }

    /// A slot type answers the data type it was made of (what
    /// [`Prepared::data_type`] relies on), for every integer type.
    #[test]
    fn issue36_slot_types_answer_their_data_type() {
        use DataType::*;
        for t in [Bool, I8, I16, I32, I64, U8, U16, U32, U64] {
            assert_eq!(SlotType::of(t).map(SlotType::data_type), Some(t));
        }
        for t in [F32, VisibleString(4), OctetString(4)] {
            assert!(SlotType::of(t).is_none());
        }
    }

    /// P-045, P-067 (any object from a telegram, written every cycle): a
    /// prepared read or write answers as the full path, for good values, values out of range or off the value list,
    /// wrong lengths, read-only entries; a configuration change makes it
    /// stale.
    #[test]
    fn p045_p067_prepared_accesses_answer_as_the_full_path() {
        let mut od = DriveObjects::new();
        // 6042h (INTEGER16 set-point), 6048h:01 (a ramp, a parameter), 6060h
        // (modes: a value list), 6064h (read-only, live), 6077h
        for (index, sub) in [
            (0x6042, 0),
            (0x6048, 1),
            (0x6060, 0),
            (0x6064, 0),
            (0x6077, 0),
            (0x6842, 0),
        ] {
            let p = od.prepare(index, sub, CommState::Op).expect("prepared");
            let width = p.data_type().bytes();
            for v in [0i64, 1, -1, 3, 6, 7, 100, -32768, 40_000, i64::from(u32::MAX)] {
                let bytes = v.to_le_bytes();
                for len in [width, width + 1, width.saturating_sub(1)] {
                    let data = &bytes[..len.min(8)];
                    let mut full = od.clone();
                    let expected = Dictionary::write(&mut full, index, sub, data, CommState::Op);
                    let mut fast = od.clone();
                    let got = fast.write_prepared(&p, data).unwrap_or_else(|| {
                        assert!(!p.writable || len != width, "{index:04X}:{sub} fell back");
                        Dictionary::write(&mut fast, index, sub, data, CommState::Op)
                    });
                    assert_eq!(got, expected, "{index:04X}:{sub} = {v} ({len} bytes)");
                    assert!(fast == full, "{index:04X}:{sub} = {v}: the dictionaries differ");
                    assert_eq!(
                        fast.config_generation() != od.config_generation(),
                        full.config_generation() != od.config_generation()
                    );
                }
            }
            assert_eq!(p.data_type(), p.target.data_type(), "{index:04X}:{sub}");
            let v = od.read_prepared(&p).expect("readable");
            let bytes = read(&mut od, index, sub).unwrap();
            assert_eq!(Ok(v), p.data_type().decode(&bytes), "{index:04X}:{sub}");
        }
        // a parameter changed: stale
        let p = od.prepare(0x6042, 0, CommState::Op).unwrap();
        od.set(0x6048, 1, 77).unwrap();
        assert!(od.write_prepared(&p, &[1, 0]).is_none());
        assert!(od.read_prepared(&p).is_none());
        // not prepared: outside the CiA 402 range, records, unknown entries
        for (index, sub) in [(0x1010, 1), (0x1600, 0), (0x2000, 1), (0x6042, 9), (0x6FFF, 0)] {
            assert!(
                od.prepare(index, sub, CommState::Op).is_none(),
                "{index:04X}:{sub}"
            );
        }
    }
}
