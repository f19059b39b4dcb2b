//! The process-data codec (spec §5.4, E-032…E-035): the assigned PDOs of
//! 1C12h/1C13h and their mapping entries compiled into one fixed-size table per
//! direction, and the copy between the process images and the objects.
//!
//! - [`PdoImage::compile`] resolves every mapping entry (index << 16 | sub << 8
//!   | bits) once, whenever the mapping may have changed (the runtime calls it
//!   on every change into Safe-Op, i.e. at Pre-Op → Safe-Op, E-019);
//! - [`PdoImage::apply_outputs`] decodes the RxPDO image into the objects
//!   (the runtime calls it in Op for every new SM2 frame, E-034);
//! - [`PdoImage::fill_inputs`] encodes the objects into the TxPDO image
//!   (every poll in Safe-Op and Op, E-032);
//! - [`PdoImage::capture_fallbacks`] records, on entering Op, the values of
//!   the RxPDO-mapped *parameters* (persistent entries such as 6060h modes of
//!   operation = A541) before the master overrides them;
//! - [`PdoImage::restore_rx_defaults`] puts the RxPDO-mapped objects back to
//!   the "internal default set values" (on leaving Op, E-035): the declared
//!   default for set-points (controlword, target values: not persistent), the
//!   captured value for parameters, so a saved or SDO-configured parameter is
//!   not silently replaced by the declaration's default.
//!
//! Encoding: little-endian, entries packed in mapping order without padding,
//! PDOs in assignment order (the SM length is the bit sum rounded up to bytes,
//! as [`od::Dictionary::process_data_bytes`] computes it). Entries at any bit
//! offset are handled: byte-aligned entries are copied as byte slices (any
//! length, strings included), the others (BOOLEAN, or whatever follows a
//! BOOLEAN) bit by bit, up to 64 bits. Values are the raw little-endian
//! encoding of the entry's data type, so the sign of a signed type is carried
//! by its two's complement bits. Gap entries (index 0) take their bits and
//! are skipped (RxPDO) or sent as zeros (TxPDO).
//!
//! Subindices: a mapping entry names its object in the subindex numbering of
//! the active template (as the mapping check does); the table holds the
//! runtime ("EtherCAT Rx SDO Info") numbering of [`DriveObjects::get`] and
//! [`DriveObjects::set_bytes`].

use crate::dictionary::{DriveObjects, Slot, Template};
use crate::objects::find;
use crate::MAPPING_ENTRIES;
use od::{Access, DataType, EntryInfo};

/// Assigned PDOs per direction (1C12h/1C13h sub 1–4, spec §5.1).
pub const MAX_PDOS: usize = 4;
/// Table capacity per direction: 4 PDOs of 24 entries.
pub const MAX_ENTRIES: usize = MAX_PDOS * MAPPING_ENTRIES as usize;
/// Longest process image per direction in bits (4 × 24 × 32 bits = 384 bytes,
/// the slave stack's `MAX_PDO_BYTES`).
pub const MAX_IMAGE_BITS: usize = MAX_ENTRIES * 32;

/// Entry info of unused table slots.
const UNUSED: EntryInfo = EntryInfo::new(0, "", DataType::U8, Access::RO);

/// One mapped object entry of a process image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageEntry {
    /// Position of the entry's first bit in the image (byte = `bit_offset / 8`).
    pub bit_offset: u16,
    /// Length in bits (the mapping's bit length = the data type's).
    pub bits: u8,
    /// Object index.
    pub index: u16,
    /// Subindex in the runtime ("EtherCAT Rx SDO Info") numbering.
    pub sub: u8,
    /// The entry's declaration (data type, default, persistence).
    pub info: &'static EntryInfo,
    /// The value [`PdoImage::restore_rx_defaults`] restores (RxPDO): the
    /// declared default, for persistent entries the value captured by
    /// [`PdoImage::capture_fallbacks`].
    pub fallback: i64,
    /// The entry's RAM slot when it is an integer of exactly `bits` at a
    /// byte boundary: copied as bytes without a dictionary lookup.
    pub slot: Option<Slot>,
}

impl ImageEntry {
    const UNUSED: Self = Self {
        bit_offset: 0,
        bits: 0,
        index: 0,
        sub: 0,
        info: &UNUSED,
        fallback: 0,
        slot: None,
    };

    /// Byte offset of the entry in the image (of its first bit).
    pub const fn byte_offset(&self) -> usize {
        self.bit_offset as usize / 8
    }

    /// Whether the entry starts and ends on byte boundaries.
    pub const fn byte_aligned(&self) -> bool {
        self.bit_offset % 8 == 0 && self.bits % 8 == 0
    }
}

/// The compiled table of one direction.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    entries: [ImageEntry; MAX_ENTRIES],
    len: usize,
    bits: usize,
}

impl Channel {
    const EMPTY: Self = Self {
        entries: [ImageEntry::UNUSED; MAX_ENTRIES],
        len: 0,
        bits: 0,
    };

    /// The mapped object entries in image order (gaps left out).
    pub fn entries(&self) -> &[ImageEntry] {
        self.entries.get(..self.len).unwrap_or_default()
    }

    /// Length of the image in bits (gaps included).
    pub fn bits(&self) -> usize {
        self.bits
    }

    /// Length of the image in bytes (the SyncManager length).
    pub fn bytes(&self) -> usize {
        self.bits.div_ceil(8)
    }

    /// Compiles the PDOs assigned in `assign` (1C12h or 1C13h).
    fn compile(objects: &DriveObjects, assign: u16) -> Result<Self, PdoImageError> {
        let mut ch = Self::EMPTY;
        let sdo_info = objects.template() == Template::SdoInfo;
        for pdo in objects.assigned_pdos(assign) {
            for mapping in objects.mapping(pdo) {
                let (index, sub, bits) = ((mapping >> 16) as u16, (mapping >> 8) as u8, mapping as u8);
                let at = ch.bits;
                let end = at + usize::from(bits);
                if end > MAX_IMAGE_BITS {
                    return Err(PdoImageError::TooLong { pdo });
                }
                ch.bits = end;
                if index == 0 {
                    continue; // gap
                }
                let bad = |kind| PdoImageError::Entry {
                    pdo,
                    index,
                    sub,
                    kind,
                };
                let info = resolve(index, sub, sdo_info).ok_or(bad(EntryFault::Unknown))?;
                if info.bit_len() != u16::from(bits) {
                    return Err(bad(EntryFault::BitLength));
                }
                let mut entry = ImageEntry {
                    bit_offset: u16::try_from(at).map_err(|_| PdoImageError::TooLong { pdo })?,
                    bits,
                    index,
                    sub: info.sub,
                    info,
                    fallback: info.default,
                    slot: None,
                };
                if entry.byte_aligned() {
                    entry.slot = objects
                        .slot(index, info.sub)
                        .filter(|s| s.bytes() * 8 == usize::from(bits));
                }
                if !entry.byte_aligned() && bits > 64 {
                    return Err(bad(EntryFault::Unaligned));
                }
                let slot = ch.entries.get_mut(ch.len).ok_or(PdoImageError::TooManyEntries)?;
                *slot = entry;
                ch.len += 1;
            }
        }
        Ok(ch)
    }
}

/// The declaration of the entry a mapping names with `index`:`sub` in the
/// active template (the runtime subindex is `EntryInfo::sub`).
fn resolve(index: u16, sub: u8, sdo_info: bool) -> Option<&'static EntryInfo> {
    let (_, o) = find(index)?;
    let view = o.view(sdo_info);
    let p = view.entries.iter().position(|e| e.sub == sub)?;
    // the "EtherCAT Rx" view of a manufacturer array has element e at
    // position e, the runtime numbering at e + 1 (after sub 0)
    let pos = if !sdo_info && o.rx.is_some() { p + 1 } else { p };
    o.info.entries.get(pos)
}

/// Why a mapping could not be compiled. The mapping checks of the dictionary
/// keep these from happening for mappings written through the bus; they
/// remain possible after a template switch or a corrupted saved mapping.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PdoImageError {
    /// More than [`MAX_ENTRIES`] entries in one direction.
    TooManyEntries,
    /// The image of one direction exceeds [`MAX_IMAGE_BITS`] at PDO `pdo`.
    TooLong {
        /// The PDO (1600h…, 1A00h…) where the limit was passed.
        pdo: u16,
    },
    /// A mapping entry that cannot be served.
    Entry {
        /// The PDO holding the entry.
        pdo: u16,
        /// Mapped index.
        index: u16,
        /// Mapped subindex (active template).
        sub: u8,
        /// What is wrong with it.
        kind: EntryFault,
    },
}

/// What is wrong with a mapping entry ([`PdoImageError::Entry`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EntryFault {
    /// No such object entry.
    Unknown,
    /// The mapped bit length differs from the data type's.
    BitLength,
    /// Longer than 64 bits and not on byte boundaries.
    Unaligned,
}

/// The compiled process images: RxPDO (SM2, outputs of the master) and TxPDO
/// (SM3, inputs of the master).
#[derive(Debug, Clone, PartialEq)]
pub struct PdoImage {
    rx: Channel,
    tx: Channel,
}

impl Default for PdoImage {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl PdoImage {
    /// No entries in either direction.
    pub const EMPTY: Self = Self {
        rx: Channel::EMPTY,
        tx: Channel::EMPTY,
    };

    /// Compiles the current mapping: the PDOs assigned in 1C12h (RxPDO) and
    /// 1C13h (TxPDO), in assignment order, with their entries.
    pub fn compile(objects: &DriveObjects) -> Result<Self, PdoImageError> {
        Ok(Self {
            rx: Channel::compile(objects, 0x1C12)?,
            tx: Channel::compile(objects, 0x1C13)?,
        })
    }

    /// The RxPDO table (master → drive).
    pub fn rx(&self) -> &Channel {
        &self.rx
    }

    /// The TxPDO table (drive → master).
    pub fn tx(&self) -> &Channel {
        &self.tx
    }

    /// Decodes every mapped RxPDO entry of `rx_bytes` and writes it into its
    /// object (runtime access: no SDO access, state or range check; the value
    /// is a process-data set-point whose plausibility is the consumer's
    /// business). Entries beyond `rx_bytes` and entries the dictionary
    /// refuses (no RAM slot) are skipped. Returns the number of entries
    /// written.
    pub fn apply_outputs(&self, rx_bytes: &[u8], objects: &mut DriveObjects) -> usize {
        let mut written = 0;
        for e in self.rx.entries() {
            let ok = if let Some(slot) = e.slot {
                objects.copy_slot_from(slot, rx_bytes, e.byte_offset())
            } else if e.byte_aligned() {
                let at = e.byte_offset();
                rx_bytes
                    .get(at..at + usize::from(e.bits / 8))
                    .is_some_and(|raw| objects.set_bytes(e.index, e.sub, raw).is_ok())
            } else {
                let mut raw = [0u8; 8];
                extract(rx_bytes, usize::from(e.bit_offset), usize::from(e.bits), &mut raw)
                    && raw
                        .get(..usize::from(e.bits).div_ceil(8))
                        .is_some_and(|raw| objects.set_bytes(e.index, e.sub, raw).is_ok())
            };
            written += usize::from(ok);
        }
        written
    }

    /// Encodes every mapped TxPDO entry from its object into `tx_bytes`
    /// (gaps and unused bits are 0). Objects that have no integer value
    /// ([`DriveObjects::get`] refuses strings) are sent as zeros; entries
    /// beyond `tx_bytes` are left out.
    pub fn fill_inputs(&self, objects: &DriveObjects, tx_bytes: &mut [u8]) {
        tx_bytes.fill(0);
        for e in self.tx.entries() {
            if let Some(slot) = e.slot {
                objects.copy_slot_to(slot, tx_bytes, e.byte_offset());
                continue;
            }
            let Ok(value) = objects.get(e.index, e.sub) else {
                continue;
            };
            let raw = value.to_le_bytes();
            if e.byte_aligned() {
                let at = e.byte_offset();
                let n = usize::from(e.bits / 8);
                if let (Some(dst), Some(src)) = (tx_bytes.get_mut(at..at + n), raw.get(..n)) {
                    dst.copy_from_slice(src);
                }
            } else {
                insert(tx_bytes, usize::from(e.bit_offset), usize::from(e.bits), &raw);
            }
        }
    }

    /// Records the current values of the RxPDO-mapped persistent entries
    /// (parameters, e.g. 6060h = A541) as their fallbacks; set-points keep
    /// their declared defaults. Call it on entering Op, before the first
    /// [`apply_outputs`](Self::apply_outputs).
    pub fn capture_fallbacks(&mut self, objects: &DriveObjects) {
        let len = self.rx.len;
        for e in self.rx.entries.iter_mut().take(len) {
            e.fallback = if e.info.persistent {
                objects.get(e.index, e.sub).unwrap_or(e.info.default)
            } else {
                e.info.default
            };
        }
    }

    /// Puts every RxPDO-mapped object back to its fallback, the "internal
    /// default set value" (E-032/E-035): the declared default of set-points
    /// (controlword 6040h = 0, target position/velocity/torque = 0, digital
    /// outputs = 0), the value before Op of parameters (modes of operation
    /// 6060h: A541, declared default 8). Strings become empty
    /// (VISIBLE_STRING) or stay (OCTET_STRING).
    pub fn restore_rx_defaults(&self, objects: &mut DriveObjects) {
        for e in self.rx.entries() {
            let _ = match e.info.data_type {
                DataType::VisibleString(_) => objects.set_bytes(e.index, e.sub, &[]),
                DataType::OctetString(_) => Ok(()),
                _ => objects.set(e.index, e.sub, e.fallback),
            };
        }
    }
}

/// Copies `bits` bits (≤ 64) from bit `offset` of `src` into `out`, from its
/// bit 0 on; `false` if `src` is too short.
fn extract(src: &[u8], offset: usize, bits: usize, out: &mut [u8; 8]) -> bool {
    if bits > 64 || (offset + bits).div_ceil(8) > src.len() {
        return false;
    }
    *out = [0; 8];
    for i in 0..bits {
        let (from, to) = (offset + i, i);
        let bit = src.get(from / 8).map_or(0, |b| (b >> (from % 8)) & 1);
        if let Some(d) = out.get_mut(to / 8) {
            *d |= bit << (to % 8);
        }
    }
    true
}

/// Copies the low `bits` bits (≤ 64) of `value` (little-endian) into `dst` at
/// bit `offset`; bits beyond `dst` are dropped.
fn insert(dst: &mut [u8], offset: usize, bits: usize, value: &[u8; 8]) {
    for i in 0..bits.min(64) {
        let (from, to) = (i, offset + i);
        let bit = value.get(from / 8).map_or(0, |b| (b >> (from % 8)) & 1);
        if let Some(d) = dst.get_mut(to / 8) {
            *d = (*d & !(1 << (to % 8))) | (bit << (to % 8));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PdoLayout;
    use od::{CommState, Dictionary};
    use std::vec::Vec;

    /// Mapping entry: index << 16 | sub << 8 | bit length.
    const fn m(index: u16, sub: u8, bits: u8) -> u32 {
        (index as u32) << 16 | (sub as u32) << 8 | bits as u32
    }

    /// Writes `entries` into `pdo` as a startup list would (Pre-Op).
    fn map(objects: &mut DriveObjects, pdo: u16, entries: &[u32]) {
        objects.write(pdo, 0, &[0], CommState::PreOp).unwrap();
        for (sub, e) in (1u8..).zip(entries) {
            objects
                .write(pdo, sub, &e.to_le_bytes(), CommState::PreOp)
                .unwrap();
        }
        objects
            .write(pdo, 0, &[entries.len() as u8], CommState::PreOp)
            .unwrap();
    }

    fn assign(objects: &mut DriveObjects, index: u16, pdos: &[u16]) {
        objects.write(index, 0, &[0], CommState::PreOp).unwrap();
        for (sub, p) in (1u8..).zip(pdos) {
            objects
                .write(index, sub, &p.to_le_bytes(), CommState::PreOp)
                .unwrap();
        }
        objects
            .write(index, 0, &[pdos.len() as u8], CommState::PreOp)
            .unwrap();
    }

    #[test]
    fn default_layout_offsets_match_the_spec() {
        let objects = DriveObjects::new();
        let img = PdoImage::compile(&objects).unwrap();
        assert_eq!((img.rx().bytes(), img.tx().bytes()), (23, 29));
        assert_eq!(
            (objects.process_data_bytes()),
            Some((img.rx().bytes(), img.tx().bytes()))
        );
        let rx: Vec<_> = img
            .rx()
            .entries()
            .iter()
            .map(|e| (e.byte_offset(), e.index, e.bits))
            .collect();
        assert_eq!(
            rx,
            [
                (0, 0x6040, 16),
                (2, 0x6060, 8),
                (3, 0x607A, 32),
                (7, 0x60FF, 32),
                (11, 0x60B1, 32),
                (15, 0x60B2, 16),
                (17, 0x6071, 16),
                (19, 0x60FE, 32),
            ]
        );
        assert_eq!(img.tx().entries()[2].index, 0x6064);
        assert_eq!(img.tx().entries()[2].byte_offset(), 3);
        assert_eq!(img.tx().entries()[9].byte_offset(), 27);
    }

    #[test]
    fn outputs_decode_little_endian_with_sign() {
        let mut objects = DriveObjects::new();
        let img = PdoImage::compile(&objects).unwrap();
        let mut rx = [0u8; 23];
        rx[0..2].copy_from_slice(&0x000Fu16.to_le_bytes());
        rx[2] = (-1i8) as u8;
        rx[3..7].copy_from_slice(&(-123_456i32).to_le_bytes());
        rx[7..11].copy_from_slice(&0x1234_5678i32.to_le_bytes());
        rx[17..19].copy_from_slice(&(-300i16).to_le_bytes());
        rx[19..23].copy_from_slice(&0xDEAD_BEEFu32.to_le_bytes());
        assert_eq!(img.apply_outputs(&rx, &mut objects), 8);
        assert_eq!(objects.get(0x6040, 0), Ok(0x000F));
        assert_eq!(objects.get(0x6060, 0), Ok(-1));
        assert_eq!(objects.get(0x607A, 0), Ok(-123_456));
        assert_eq!(objects.get(0x60FF, 0), Ok(0x1234_5678));
        assert_eq!(objects.get(0x6071, 0), Ok(-300));
        assert_eq!(objects.get(0x60FE, 1), Ok(0xDEAD_BEEF));

        // a short image: the entries it covers only
        let mut short = DriveObjects::new();
        assert_eq!(img.apply_outputs(&rx[..7], &mut short), 3);
        assert_eq!(short.get(0x607A, 0), Ok(-123_456));
        assert_eq!(short.get(0x60FF, 0), Ok(0));

        img.restore_rx_defaults(&mut objects);
        for (index, sub) in [(0x6040, 0), (0x6060, 0), (0x607A, 0), (0x6071, 0), (0x60FE, 1)] {
            let default = find(index).unwrap().1.info.entry(sub).unwrap().default;
            assert_eq!(objects.get(index, sub), Ok(default), "{index:04X}h");
        }
    }

    #[test]
    fn leaving_op_restores_set_points_and_captured_parameters() {
        let mut objects = DriveObjects::new();
        objects.set(0x6060, 0, 9).unwrap(); // a saved/configured A541 (csv)
        objects.set(0x6040, 0, 0x0006).unwrap(); // an SDO-written controlword
        let mut img = PdoImage::compile(&objects).unwrap();
        img.capture_fallbacks(&objects);
        let mut rx = [0u8; 23];
        rx[0] = 0x0F;
        rx[2] = 1;
        rx[3] = 5;
        img.apply_outputs(&rx, &mut objects);
        assert_eq!(objects.get(0x6060, 0), Ok(1));
        img.restore_rx_defaults(&mut objects);
        assert_eq!(objects.get(0x6060, 0), Ok(9), "parameter: the value before Op");
        assert_eq!(objects.get(0x6040, 0), Ok(0), "set-point: the declared default");
        assert_eq!(objects.get(0x607A, 0), Ok(0));
    }

    #[test]
    fn inputs_encode_little_endian_with_sign() {
        let mut objects = DriveObjects::new();
        let img = PdoImage::compile(&objects).unwrap();
        objects.set(0x6041, 0, 0x0237).unwrap();
        objects.set(0x6061, 0, -1).unwrap();
        objects.set(0x6064, 0, -2).unwrap();
        objects.set(0x6077, 0, -1000).unwrap();
        objects.set(0x60FD, 0, 0x8000_0001).unwrap();
        let mut tx = [0xAAu8; 29];
        img.fill_inputs(&objects, &mut tx);
        assert_eq!(&tx[0..2], &[0x37, 0x02]);
        assert_eq!(tx[2], 0xFF);
        assert_eq!(&tx[3..7], &[0xFE, 0xFF, 0xFF, 0xFF]);
        assert_eq!(&tx[11..13], &(-1000i16).to_le_bytes());
        assert_eq!(&tx[17..21], &[0x01, 0, 0, 0x80]);
        // a short buffer: no panic, the entries that fit
        let mut short = [0u8; 5];
        img.fill_inputs(&objects, &mut short);
        assert_eq!(short, [0x37, 0x02, 0xFF, 0, 0]);
    }

    /// E-034/E-032: the direct slot copy of byte-aligned integer entries
    /// decodes and encodes exactly what the copy through the dictionary
    /// does, on every layout, and it is the path the default layouts take.
    #[test]
    fn e034_slot_copy_equals_the_dictionary_copy() {
        for layout in [PdoLayout::Standard, PdoLayout::Ip, PdoLayout::Vl] {
            let mut objects = DriveObjects::new();
            objects.apply_map(layout).unwrap();
            let img = PdoImage::compile(&objects).unwrap();
            let mut slow = img.clone();
            for e in slow.rx.entries.iter_mut().chain(slow.tx.entries.iter_mut()) {
                e.slot = None;
            }
            let with_slots = img
                .rx
                .entries()
                .iter()
                .chain(img.tx.entries())
                .filter(|e| e.slot.is_some());
            assert_eq!(
                with_slots.count(),
                img.rx.entries().len() + img.tx.entries().len(),
                "{layout:?}"
            );
            let rx: Vec<u8> = (0..img.rx.bytes()).map(|i| (i * 37 + 201) as u8).collect();
            let (mut a, mut b) = (objects.clone(), objects.clone());
            assert_eq!(img.apply_outputs(&rx, &mut a), slow.apply_outputs(&rx, &mut b));
            assert_eq!(a, b, "{layout:?}");
            a.set(0x6041, 0, 0x1637).unwrap();
            a.set(0x6064, 0, -123_456).unwrap();
            a.set(0x6044, 0, -77).unwrap();
            let (mut fast_tx, mut slow_tx) = (
                std::vec![0x55u8; img.tx.bytes()],
                std::vec![0xAAu8; img.tx.bytes()],
            );
            img.fill_inputs(&a, &mut fast_tx);
            slow.fill_inputs(&a, &mut slow_tx);
            assert_eq!(fast_tx, slow_tx, "{layout:?}");
        }
    }

    #[test]
    fn remapped_layouts_with_gaps_and_two_pdos() {
        let mut objects = DriveObjects::new();
        objects.apply_map(PdoLayout::Vl).unwrap();
        // 1601h: a gap of 8 bits then axis B's controlword
        map(&mut objects, 0x1601, &[m(0, 0, 8), m(0x6840, 0, 16)]);
        assign(&mut objects, 0x1C12, &[0x1600, 0x1601]);
        let img = PdoImage::compile(&objects).unwrap();
        assert_eq!(img.rx().bytes(), 5 + 3);
        assert_eq!(objects.process_data_bytes().unwrap().0, 8);
        let rx = [0x06, 0x00, 0x02, 0x10, 0xFF, 0xEE, 0x07, 0x00];
        assert_eq!(img.apply_outputs(&rx, &mut objects), 4);
        assert_eq!(objects.get(0x6040, 0), Ok(6));
        assert_eq!(objects.get(0x6060, 0), Ok(2));
        assert_eq!(objects.get(0x6042, 0), Ok(-240));
        assert_eq!(objects.get(0x6840, 0), Ok(7), "after the gap");

        let mut tx = [0u8; 5];
        objects.set(0x6044, 0, -2).unwrap();
        img.fill_inputs(&objects, &mut tx);
        assert_eq!(&tx[3..5], &[0xFE, 0xFF]);
    }

    #[test]
    fn bit_packed_entries() {
        let mut objects = DriveObjects::new();
        // 10F3h:04 (BOOL, TxPDO) between two byte-sized entries: 6041h then
        // the BOOL at bit 16, 7 bits of gap, 6061h at bit 24
        map(
            &mut objects,
            0x1A00,
            &[m(0x6041, 0, 16), m(0x10F3, 4, 1), m(0, 0, 3), m(0x6061, 0, 8)],
        );
        let img = PdoImage::compile(&objects).unwrap();
        assert_eq!(img.tx().bits(), 28);
        assert_eq!(img.tx().bytes(), 4);
        objects.set(0x6041, 0, 0x1234).unwrap();
        objects.set(0x10F3, 4, 1).unwrap();
        objects.set(0x6061, 0, -3).unwrap();
        let mut tx = [0u8; 4];
        img.fill_inputs(&objects, &mut tx);
        // -3 = FDh from bit 20 on: low nibble D at bits 20..24, high F in byte 3
        assert_eq!(tx, [0x34, 0x12, 0x01 | 0xD0, 0x0F]);

        // the helpers both ways at an odd offset
        let mut buf = [0u8; 3];
        insert(&mut buf, 5, 16, &0xBEEFu64.to_le_bytes());
        let mut out = [0u8; 8];
        assert!(extract(&buf, 5, 16, &mut out));
        assert_eq!(u16::from_le_bytes([out[0], out[1]]), 0xBEEF);
        assert!(!extract(&buf, 9, 16, &mut out), "beyond the buffer");
    }

    #[test]
    fn unaligned_rx_entries_are_decoded() {
        let mut objects = DriveObjects::new();
        // a 4-bit gap puts the controlword at bit 4
        map(&mut objects, 0x1600, &[m(0, 0, 4), m(0x6040, 0, 16), m(0, 0, 4)]);
        let img = PdoImage::compile(&objects).unwrap();
        assert_eq!(img.rx().bytes(), 3);
        let rx = [0xF0, 0xED, 0x0B];
        assert_eq!(img.apply_outputs(&rx, &mut objects), 1);
        assert_eq!(objects.get(0x6040, 0), Ok(0xBEDF));
    }

    #[test]
    fn rx_template_subindices_resolve_to_the_runtime_numbering() {
        // A00 "Save values" (2000h): element 0 is subindex 0 in the "EtherCAT
        // Rx" template and subindex 1 in the runtime numbering
        let a00 = crate::parameter_index(0, 0);
        assert_eq!(resolve(a00, 0, false).map(|e| e.sub), Some(1));
        assert_eq!(resolve(a00, 2, false).map(|e| e.sub), Some(3));
        assert_eq!(resolve(a00, 1, true).map(|e| e.sub), Some(1));
        assert_eq!(resolve(a00, 3, false), None, "three elements");
        // standard objects are the same in both templates
        assert_eq!(resolve(0x6040, 0, false).map(|e| e.sub), Some(0));
        assert_eq!(resolve(0x60FE, 1, false).map(|e| e.sub), Some(1));
        let mut objects = DriveObjects::new();
        objects.set_template(Template::Rx);
        let img = PdoImage::compile(&objects).unwrap();
        assert_eq!((img.rx().bytes(), img.tx().bytes()), (23, 29));
    }

    #[test]
    fn compile_refuses_what_it_cannot_serve() {
        assert_eq!(resolve(0x6040, 1, true), None);
        assert_eq!(resolve(0x5555, 0, true), None);
        assert_eq!(PdoImage::default(), PdoImage::EMPTY);
        assert!(PdoImage::EMPTY.rx().entries().is_empty());
        // the bus checks keep such entries out; the runtime `set` does not
        let mut objects = DriveObjects::new();
        objects.set(0x1600, 2, i64::from(m(0x5555, 0, 16))).unwrap();
        assert_eq!(
            PdoImage::compile(&objects),
            Err(PdoImageError::Entry {
                pdo: 0x1600,
                index: 0x5555,
                sub: 0,
                kind: EntryFault::Unknown
            })
        );
        objects.set(0x1600, 2, i64::from(m(0x6060, 0, 16))).unwrap();
        assert_eq!(
            PdoImage::compile(&objects),
            Err(PdoImageError::Entry {
                pdo: 0x1600,
                index: 0x6060,
                sub: 0,
                kind: EntryFault::BitLength
            })
        );
        // 24 gaps of 255 bits in each of four PDOs: beyond 384 bytes
        let mut objects = DriveObjects::new();
        for pdo in 0x1600..=0x1602u16 {
            objects.set(pdo, 0, 24).unwrap();
            for s in 1..=24 {
                objects.set(pdo, s, 0xFF).unwrap();
            }
        }
        objects.set(0x1C12, 0, 3).unwrap();
        objects.set(0x1C12, 2, 0x1601).unwrap();
        objects.set(0x1C12, 3, 0x1602).unwrap();
        assert!(matches!(
            PdoImage::compile(&objects),
            Err(PdoImageError::TooLong { .. })
        ));
    }
}
