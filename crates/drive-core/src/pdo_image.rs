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
//! The copy program: [`PdoImage::compile`] also turns the entries that have a
//! RAM [`Slot`] (integers of their full width at a byte boundary, the usual
//! case) into a compact program of `CopyOp`s, two offsets each, grouped by
//! width (1, 2, 4, 8 bytes; RxPDO configuration entries, any width, in a
//! group of their own). Entries adjacent in both the RAM image and the
//! process image are merged into wider copies. One cycle's copy is then a few
//! tight loops of fixed-size loads and stores, with a bounds check per op but
//! no lookup, no dispatch per entry and no `memcmp`. Each group is found from
//! its start and length (`Program::groups`), without a running cursor, which
//! keeps the loops' registers free. Everything else (gaps, entries off byte
//! boundaries, strings) keeps the per-entry copy, which also serves a byte
//! slice shorter than the image (entries beyond it are skipped whole) and an
//! RxPDO mapping that stores twice into the same RAM bytes (the order of the
//! stores matters there, and the program's groups do not keep it). The
//! results are those of the per-entry copy, byte for byte and configuration
//! change for configuration change.
//!
//! The standard layout (the defaults of 1600h/1601h, 1A00h/1A01h, of axis A
//! or of both axes, in that order) needs no program: its values lie in two
//! runs per axis at compile-time places of the axis' block of the RAM image
//! (`objects::layout`), so `compile` recognises it (`standard.rs`) and the
//! copy is straight-line loads and stores at constant offsets
//! ([`DriveObjects`]' `copy_in_standard`/`copy_out_standard`), the same
//! bytes the program would move.
//!
//! Subindices: a mapping entry names its object in the subindex numbering of
//! the active template (as the mapping check does); the table holds the
//! runtime ("EtherCAT Rx SDO Info") numbering of [`DriveObjects::get`] and
//! [`DriveObjects::set_bytes`].

use crate::dictionary::{DriveObjects, Slot, Template};
use crate::objects::EntryRecord;
use crate::objects::{find, IMAGE_BYTES};
use crate::MAPPING_ENTRIES;
use od::DataType;

/// Assigned PDOs per direction (1C12h/1C13h sub 1–4, spec §5.1).
pub const MAX_PDOS: usize = 4;
/// Table capacity per direction: 4 PDOs of 24 entries.
pub const MAX_ENTRIES: usize = MAX_PDOS * MAPPING_ENTRIES as usize;
/// Longest process image per direction in bits (4 × 24 × 32 bits = 384 bytes,
/// the slave stack's `MAX_PDO_BYTES`).
pub const MAX_IMAGE_BITS: usize = MAX_ENTRIES * 32;

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
    /// The entry's declaration (data type, default, persistence): its
    /// record in [`crate::objects::ENTRY_TABLE`].
    pub info: EntryRecord,
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
        info: EntryRecord::UNUSED,
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
    program: Program,
}

impl Channel {
    const EMPTY: Self = Self {
        entries: [ImageEntry::UNUSED; MAX_ENTRIES],
        len: 0,
        bits: 0,
        program: Program::NONE,
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

    /// Compiles the PDOs assigned in `assign` (1C12h or 1C13h) into `ch`,
    /// an empty channel (in place: a channel is ~2.7 KiB).
    fn compile(ch: &mut Self, objects: &DriveObjects, assign: u16) -> Result<(), PdoImageError> {
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
                if info.data_type().bits() != u16::from(bits) {
                    return Err(bad(EntryFault::BitLength));
                }
                let mut entry = ImageEntry {
                    bit_offset: u16::try_from(at).map_err(|_| PdoImageError::TooLong { pdo })?,
                    bits,
                    index,
                    sub: info.sub(),
                    info,
                    fallback: info.default_value(),
                    slot: None,
                };
                if entry.byte_aligned() {
                    entry.slot = objects
                        .slot(index, info.sub())
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
        let rx = assign == 0x1C12;
        let bytes = ch.bytes();
        let entries = ch.entries.get(..ch.len).unwrap_or_default();
        Program::build(&mut ch.program, entries, bytes, rx, objects);
        Ok(())
    }

    /// Decodes every entry of `rx_bytes` one by one (the copy the program
    /// stands for); returns the number of entries written.
    fn apply_each(&self, rx_bytes: &[u8], objects: &mut DriveObjects) -> usize {
        self.entries()
            .iter()
            .map(|e| usize::from(apply_entry(e, rx_bytes, objects)))
            .sum()
    }

    /// Encodes every entry into `tx_bytes` one by one, after zeroing it (the
    /// copy the program stands for).
    fn fill_each(&self, objects: &DriveObjects, tx_bytes: &mut [u8]) {
        tx_bytes.fill(0);
        for e in self.entries() {
            match e.slot {
                Some(slot) => {
                    objects.copy_slot_to(slot, tx_bytes, e.byte_offset());
                }
                None => fill_entry(e, objects, tx_bytes),
            }
        }
    }
}

/// Decodes entry `e` of `rx_bytes` into its object; `false` when it lies
/// beyond `rx_bytes` or the dictionary refuses it.
fn apply_entry(e: &ImageEntry, rx_bytes: &[u8], objects: &mut DriveObjects) -> bool {
    if let Some(slot) = e.slot {
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
    }
}

/// Encodes entry `e`, one without a slot, from its object into `tx_bytes`
/// (its bits only; nothing for an object without an integer value or an
/// entry beyond `tx_bytes`).
fn fill_entry(e: &ImageEntry, objects: &DriveObjects, tx_bytes: &mut [u8]) {
    let Ok(value) = objects.get(e.index, e.sub) else {
        return;
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

/// One copy of a [`Channel`]'s copy program: bytes between the RAM image of
/// [`DriveObjects`] (from offset `ram`) and the process image (from byte
/// `img`), as many as its group's width. Four bytes, so a group's ops are
/// found with a shift.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct CopyOp {
    /// Byte offset in the RAM image.
    pub(crate) ram: u16,
    /// Byte offset in the process image; in the group of configuration
    /// entries (any width) the width's log2 is in the bits from
    /// [`WIDTH_SHIFT`] on ([`CopyOp::config`]).
    pub(crate) img: u16,
}

/// Where a configuration op keeps its width's log2 (in `img`).
pub(crate) const WIDTH_SHIFT: u32 = 14;
// image offsets stay below it
const _: () = assert!(MAX_IMAGE_BITS / 8 <= 1 << WIDTH_SHIFT);

impl CopyOp {
    /// A configuration op: `width` (1, 2, 4 or 8) bytes at `img`.
    fn config(ram: u16, img: u16, width: usize) -> Option<Self> {
        let log2 = u16::try_from(width.trailing_zeros()).ok()?;
        (img >> WIDTH_SHIFT == 0 && width.is_power_of_two() && width <= 8).then_some(Self {
            ram,
            img: img | log2 << WIDTH_SHIFT,
        })
    }

    /// Width in bytes of a configuration op.
    #[cfg(test)]
    fn width(self) -> usize {
        1 << (self.img >> WIDTH_SHIFT)
    }
}

/// Widths of the copies in bytes: groups `0..4` copy these.
const WIDTHS: [usize; 4] = [1, 2, 4, 8];
/// Group of the RxPDO configuration entries, any width.
const CONFIG: usize = WIDTHS.len();
/// Groups of a copy program.
const GROUPS: usize = CONFIG + 1;

// group sizes are bytes
const _: () = assert!(MAX_ENTRIES <= u8::MAX as usize);

/// The copy program of one direction (see the module docs): the ops of
/// group 0, then those of group 1, …; group `g` is the `groups[g].1` ops
/// from `groups[g].0` on.
#[derive(Debug, Clone, PartialEq)]
struct Program {
    ops: [CopyOp; MAX_ENTRIES],
    groups: [(u8, u8); GROUPS],
    /// Mapped entries the program copies.
    entries: usize,
    /// The shortest byte slice the program serves (the image's length);
    /// `usize::MAX` when it does not stand for the per-entry copy (an
    /// RxPDO mapping storing twice into the same RAM bytes).
    min_len: usize,
    /// TxPDO: the image's length when the program writes every byte of it
    /// (no gaps, no other entries): a slice of this length needs no zeroing
    /// first; `usize::MAX` otherwise.
    whole_len: usize,
    /// Entries (not gaps) outside the program: copied one by one after it.
    others: bool,
    /// The channel is exactly the standard layout of this many axes (1 or
    /// 2; 0: another mapping): the straight-line copy stands for the
    /// program (`standard.rs`).
    standard: u8,
}

impl Program {
    const NONE: Self = Self {
        ops: [CopyOp { ram: 0, img: 0 }; MAX_ENTRIES],
        groups: [(0, 0); GROUPS],
        entries: 0,
        min_len: usize::MAX,
        whole_len: usize::MAX,
        others: false,
        standard: 0,
    };

    /// Makes `p` the program of `entries`, an image of `bytes` bytes; RxPDO
    /// configuration entries (`rx`) go to a group of their own. In place:
    /// the caller's frame holds two channels already.
    fn build(p: &mut Self, entries: &[ImageEntry], bytes: usize, rx: bool, objects: &DriveObjects) {
        (p.groups, p.entries, p.min_len, p.whole_len, p.others, p.standard) =
            ([(0, 0); GROUPS], 0, usize::MAX, usize::MAX, false, 0);
        if rx && stores_overlap(entries, objects) {
            return;
        }
        let mut ok = true;
        let mut at = 0usize;
        for g in 0..GROUPS {
            let start = at;
            chunks(entries, rx, |group, ram, img, width| {
                if group != g {
                    return;
                }
                let fits = ram + width <= IMAGE_BYTES && img + width <= bytes;
                let op = match (u16::try_from(ram), u16::try_from(img)) {
                    (Ok(ram), Ok(img)) if g == CONFIG => CopyOp::config(ram, img, width),
                    (Ok(ram), Ok(img)) => Some(CopyOp { ram, img }),
                    _ => None,
                };
                match (p.ops.get_mut(at), op) {
                    (Some(slot), Some(op)) if fits => {
                        *slot = op;
                        at += 1;
                    }
                    _ => ok = false,
                }
            });
            match (p.groups.get_mut(g), u8::try_from(start), u8::try_from(at - start)) {
                (Some(group), Ok(from), Ok(n)) => *group = (from, n),
                _ => ok = false,
            }
        }
        if !ok {
            return;
        }
        let mut covered = 0;
        for e in entries {
            match e.slot {
                Some(slot) => {
                    p.entries += 1;
                    covered += slot.bytes();
                }
                None => p.others = true,
            }
        }
        p.min_len = bytes;
        // the slot entries are disjoint in the image: their sum is all of
        // it only without gaps and other entries
        if !p.others && covered == bytes {
            p.whole_len = bytes;
        }
        p.standard = standard::standard_axes(entries, bytes, rx);
    }

    /// Whether the program serves byte slices of the image's length.
    #[cfg(test)]
    fn usable(&self) -> bool {
        self.min_len != usize::MAX
    }

    /// The ops of group `g` (`None` only for a program that was not built).
    #[inline(always)]
    fn group(&self, g: usize) -> Option<&[CopyOp]> {
        let &(from, n) = self.groups.get(g)?;
        let from = usize::from(from);
        self.ops.get(from..from + usize::from(n))
    }

    /// Runs the RxPDO program: `src` into the objects.
    #[inline(always)]
    fn copy_in(&self, src: &[u8], objects: &mut DriveObjects) {
        if let Some(ops) = self.group(0) {
            objects.copy_in::<1>(ops, src);
        }
        if let Some(ops) = self.group(1) {
            objects.copy_in::<2>(ops, src);
        }
        if let Some(ops) = self.group(2) {
            objects.copy_in::<4>(ops, src);
        }
        if let Some(ops) = self.group(3) {
            objects.copy_in::<8>(ops, src);
        }
        if let Some(ops) = self.group(CONFIG) {
            objects.copy_in_config(ops, src);
        }
    }

    /// Runs the TxPDO program: the objects into `dst`.
    #[inline(always)]
    fn copy_out(&self, objects: &DriveObjects, dst: &mut [u8]) {
        if let Some(ops) = self.group(0) {
            objects.copy_out::<1>(ops, dst);
        }
        if let Some(ops) = self.group(1) {
            objects.copy_out::<2>(ops, dst);
        }
        if let Some(ops) = self.group(2) {
            objects.copy_out::<4>(ops, dst);
        }
        if let Some(ops) = self.group(3) {
            objects.copy_out::<8>(ops, dst);
        }
    }
}

/// Calls `f(group, ram, img, width)` for every copy of the program of
/// `entries`: runs of slot entries adjacent in both images cut into copies
/// of 8, 4, 2 and 1 bytes, the largest first (never more copies than the
/// run has entries); RxPDO configuration entries (`rx`) one by one, in group
/// [`CONFIG`].
fn chunks(entries: &[ImageEntry], rx: bool, mut f: impl FnMut(usize, usize, usize, usize)) {
    // a run: copies of the widths, the largest first
    let emit = |f: &mut dyn FnMut(usize, usize, usize, usize), (mut ram, mut img, mut len)| {
        while let Some((g, &w)) = WIDTHS.iter().enumerate().rev().find(|&(_, &w)| w <= len) {
            f(g, ram, img, w);
            (ram, img, len) = (ram + w, img + w, len - w);
        }
    };
    // the open run: RAM offset, image offset, length
    let mut run: Option<(usize, usize, usize)> = None;
    for e in entries {
        let Some(slot) = e.slot else {
            continue;
        };
        let (ram, img, w) = (usize::from(slot.ram_offset()), e.byte_offset(), slot.bytes());
        if rx && slot.is_config() {
            f(CONFIG, ram, img, w);
            continue;
        }
        run = match run {
            Some((r, i, len)) if r + len == ram && i + len == img => Some((r, i, len + w)),
            Some(done) => {
                emit(&mut f, done);
                Some((ram, img, w))
            }
            None => Some((ram, img, w)),
        };
    }
    if let Some(done) = run {
        emit(&mut f, done);
    }
}

/// Whether two of the RxPDO `entries` store into the same RAM bytes (one
/// object mapped twice, or an alias and its target): the last store must win,
/// so the copy keeps the mapping order.
fn stores_overlap(entries: &[ImageEntry], objects: &DriveObjects) -> bool {
    // the RAM bytes of an entry (integers only; pairwise: no array on the
    // stack of the compile, which holds two channels already)
    let ram = |e: &ImageEntry| {
        let s = e.slot.or_else(|| objects.slot(e.index, e.sub))?;
        let at = usize::from(s.ram_offset());
        Some((at, at + s.bytes()))
    };
    entries.iter().enumerate().any(|(i, a)| {
        ram(a).is_some_and(|(a0, a1)| {
            entries
                .iter()
                .skip(i + 1)
                .any(|b| ram(b).is_some_and(|(b0, b1)| a0 < b1 && b0 < a1))
        })
    })
}

/// The declaration of the entry a mapping names with `index`:`sub` in the
/// active template (the runtime subindex is `EntryInfo::sub`).
fn resolve(index: u16, sub: u8, sdo_info: bool) -> Option<EntryRecord> {
    let (_, o) = find(index)?;
    let view = o.view(sdo_info);
    let p = view.entries.position(sub)?;
    // the "EtherCAT Rx" view of a manufacturer array has element e at
    // position e, the runtime numbering at e + 1 (after sub 0)
    let pos = if !sdo_info && o.has_rx_view() { p + 1 } else { p };
    o.info.entries.record(pos).map(EntryRecord::of)
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
        let mut img = Self::EMPTY;
        Channel::compile(&mut img.rx, objects, 0x1C12)?;
        Channel::compile(&mut img.tx, objects, 0x1C13)?;
        Ok(img)
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
        let p = &self.rx.program;
        if rx_bytes.len() < p.min_len {
            return self.rx.apply_each(rx_bytes, objects);
        }
        if p.standard > 0 {
            objects.copy_in_standard(rx_bytes, p.standard);
        } else {
            p.copy_in(rx_bytes, objects);
        }
        let mut written = p.entries;
        if p.others {
            for e in self.rx.entries().iter().filter(|e| e.slot.is_none()) {
                written += usize::from(apply_entry(e, rx_bytes, objects));
            }
        }
        written
    }

    /// Encodes every mapped TxPDO entry from its object into `tx_bytes`
    /// (gaps and unused bits are 0). Objects that have no integer value
    /// ([`DriveObjects::get`] refuses strings) are sent as zeros; entries
    /// beyond `tx_bytes` are left out.
    pub fn fill_inputs(&self, objects: &DriveObjects, tx_bytes: &mut [u8]) {
        let p = &self.tx.program;
        if tx_bytes.len() < p.min_len {
            return self.tx.fill_each(objects, tx_bytes);
        }
        if tx_bytes.len() != p.whole_len {
            tx_bytes.fill(0);
        }
        if p.standard > 0 {
            objects.copy_out_standard(tx_bytes, p.standard);
        } else {
            p.copy_out(objects, tx_bytes);
        }
        if p.others {
            for e in self.tx.entries().iter().filter(|e| e.slot.is_none()) {
                fill_entry(e, objects, tx_bytes);
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
            e.fallback = if e.info.persistent() {
                objects.get(e.index, e.sub).unwrap_or(e.info.default_value())
            } else {
                e.info.default_value()
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
            let _ = match e.info.data_type() {
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

mod standard;
#[cfg(test)]
mod tests;
