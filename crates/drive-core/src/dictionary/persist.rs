//! The persistent image: what A00 saves and a restart loads (the values of
//! the persistent entries with a header naming the layout), restoring the
//! defaults.

use super::*;

/// Why a persistent image was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageError {
    /// The output buffer is shorter than [`PERSISTENT_IMAGE_BYTES`].
    BufferTooSmall,
    /// Wrong length, magic or template byte.
    Malformed,
    /// Saved by another declaration (layout hash differs).
    ForeignLayout,
}

pub(super) const IMAGE_MAGIC: [u8; 4] = *b"DOD1";

pub(super) const IMAGE_HEADER: usize = 12;

/// Size of a persistent image: 12-byte header (magic "DOD1", layout hash
/// u32, payload length u16, template u8, 0) + the persistent values.
pub const PERSISTENT_IMAGE_BYTES: usize = IMAGE_HEADER + objects::PERSISTENT_BYTES;

/// Writes into `image` the defaults of the entries `pick` (object index,
/// entry) selects, as the declaration gives them: a number its default, the
/// record memory (J410, J411 of either axis) its records' defaults, another
/// string zeros. The image the dictionary starts with, filled at start instead
/// of a 9 KB constant in flash (`objects::INITIAL_IMAGE`, the same bytes).
pub(super) fn write_defaults(image: &mut [u8], mut pick: impl FnMut(u16, &EntryInfo) -> bool) {
    use objects::records::{initial_byte, J410, J411};
    for (o, &base) in OBJECTS.iter().zip(OFFSETS.iter()) {
        if !matches!(o.value, Value::Ram | Value::Live) {
            continue;
        }
        let index = o.info.index;
        let memory = index.checked_sub(crate::AXIS_B_MANUFACTURER).unwrap_or(index);
        let record_memory = memory == J410 || memory == J411;
        let (mut at, mut memory_at) = (usize::from(base), 0);
        for e in o.info.entries {
            let n = e.data_type.bytes();
            let string = e.data_type.is_string();
            if pick(index, &e) {
                if let Some(dst) = image.get_mut(at..at + n) {
                    if !string {
                        let _ = e.data_type.encode(e.default, dst);
                    } else {
                        for (k, d) in dst.iter_mut().enumerate() {
                            *d = if record_memory {
                                initial_byte(memory, memory_at + k).unwrap_or(0)
                            } else {
                                0
                            };
                        }
                    }
                }
            }
            if string && record_memory {
                memory_at += n;
            }
            at += n;
        }
    }
}

impl DriveObjects {
    /// The layout hash of this device's saved sets ([`Variant::layout_hash`]):
    /// what [`persistent_image`](Self::persistent_image) writes and
    /// [`load_persistent`](Self::load_persistent) and the store's load
    /// require.
    pub fn layout_hash(&self) -> u32 {
        self.variant.layout_hash()
    }

    /// Writes the defaults of the entries `pick` selects of the objects this
    /// device declares again ([`Variant::redeclared`]) over those
    /// [`write_defaults`] wrote from the double-axis declaration.
    pub(super) fn write_variant_defaults(&mut self, mut pick: impl FnMut(&EntryInfo) -> bool) {
        for o in self.variant.redeclared() {
            if !matches!(o.value, Value::Ram | Value::Live) {
                continue;
            }
            for e in o
                .info
                .entries
                .iter()
                .filter(|e| !e.data_type.is_string() && pick(e))
            {
                let Ok(slot) = canonical(o.info.index, e.sub).and_then(Loc::slot) else {
                    continue;
                };
                if let Some(dst) = self.image.get_mut(slot) {
                    let _ = e.data_type.encode(e.default, dst);
                }
            }
        }
    }

    /// The byte ranges of the persistent values, in declaration order.
    pub(super) fn persistent_slots() -> impl Iterator<Item = core::ops::Range<usize>> {
        OBJECTS.iter().enumerate().flat_map(|(obj, o)| {
            let ram = matches!(o.value, Value::Ram | Value::Live);
            o.info
                .entries
                .iter()
                .enumerate()
                .filter(move |(_, e)| ram && e.persistent)
                .filter_map(move |(pos, _)| Loc { obj, pos }.slot().ok())
        })
    }

    /// Writes the persistent values into `out` (header + values, see
    /// [`PERSISTENT_IMAGE_BYTES`]) for the non-volatile store; returns the
    /// byte count.
    pub fn persistent_image(&self, out: &mut [u8]) -> Result<usize, ImageError> {
        let out = out
            .get_mut(..PERSISTENT_IMAGE_BYTES)
            .ok_or(ImageError::BufferTooSmall)?;
        let (header, mut payload) = out.split_at_mut(IMAGE_HEADER);
        let len = (objects::PERSISTENT_BYTES as u16).to_le_bytes();
        let hash = self.layout_hash().to_le_bytes();
        let [m0, m1, m2, m3] = IMAGE_MAGIC;
        let [h0, h1, h2, h3] = hash;
        let t = u8::from(self.template == Template::SdoInfo);
        header.copy_from_slice(&[m0, m1, m2, m3, h0, h1, h2, h3, len[0], len[1], t, 0]);
        for slot in Self::persistent_slots() {
            let n = slot.len();
            let src = self.image.get(slot).ok_or(ImageError::Malformed)?;
            let (dst, rest) = payload.split_at_mut(n.min(payload.len()));
            dst.copy_from_slice(src.get(..dst.len()).ok_or(ImageError::Malformed)?);
            payload = rest;
        }
        Ok(PERSISTENT_IMAGE_BYTES)
    }

    /// Loads an image made by [`persistent_image`](Self::persistent_image) of
    /// the same declaration; anything else is refused and changes nothing.
    pub fn load_persistent(&mut self, data: &[u8]) -> Result<(), ImageError> {
        if data.len() != PERSISTENT_IMAGE_BYTES {
            return Err(ImageError::Malformed);
        }
        let (header, mut payload) = data.split_at(IMAGE_HEADER);
        let template = match header {
            [m0, m1, m2, m3, _, _, _, _, l0, l1, t, 0]
                if [*m0, *m1, *m2, *m3] == IMAGE_MAGIC
                    && usize::from(u16::from_le_bytes([*l0, *l1])) == objects::PERSISTENT_BYTES =>
            {
                match t {
                    0 => Template::Rx,
                    1 => Template::SdoInfo,
                    _ => return Err(ImageError::Malformed),
                }
            }
            _ => return Err(ImageError::Malformed),
        };
        if header.get(4..8) != Some(&self.layout_hash().to_le_bytes()[..]) {
            return Err(ImageError::ForeignLayout);
        }
        for slot in Self::persistent_slots() {
            let (src, rest) = payload.split_at(slot.len().min(payload.len()));
            if let Some(dst) = self.image.get_mut(slot) {
                // equal lengths after the size check above; zip keeps it panic-free
                for (d, s) in dst.iter_mut().zip(src) {
                    *d = *s;
                }
            }
            payload = rest;
        }
        self.template = template;
        self.records_reloaded(false);
        self.config_changed();
        Ok(())
    }

    /// Sets every persistent value back to its default in RAM (1011h, CiA
    /// 301 "restore default parameters"; the stored image changes with the
    /// next save). Live and set-point values are untouched.
    pub fn restore_defaults(&mut self) {
        write_defaults(&mut self.image, |_, e| e.persistent);
        self.write_variant_defaults(|e| e.persistent);
        self.records_reloaded(true);
        self.config_changed();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_image_filled_at_start_and_by_a_restore_is_the_declared_one() {
        let mut od = DriveObjects::new();
        assert!(od.image == objects::INITIAL_IMAGE, "start");
        od.image = [0xA5; IMAGE_BYTES];
        od.restore_defaults();
        let mut restored = 0;
        for slot in DriveObjects::persistent_slots() {
            assert_eq!(
                od.image[slot.clone()],
                objects::INITIAL_IMAGE[slot.clone()],
                "{slot:?}"
            );
            restored += slot.len();
        }
        assert_eq!(restored, objects::PERSISTENT_BYTES);
        // the record memory of both axes is restored too
        for index in [
            objects::records::J410,
            objects::records::J411,
            objects::records::J411 + crate::AXIS_B_MANUFACTURER,
        ] {
            let (i, o) = find(index).unwrap();
            let at = usize::from(OFFSETS[i]);
            let r = at..at + o.ram_bytes();
            assert_eq!(od.image[r.clone()], objects::INITIAL_IMAGE[r], "{index:04X}h");
        }
    }
}
