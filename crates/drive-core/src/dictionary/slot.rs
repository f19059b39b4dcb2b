//! Resolved slots: an entry's place in the RAM image with its type, for
//! the PDO copy and the runtime's entries without a dictionary lookup
//! ([`Slot`], [`Typed`]); and the control cycle's loads and stores at the
//! fixed places of its axis' block (`cycle_read`, `cycle_write`).

use super::*;
use crate::objects::{CycleField, AXIS_BLOCK};

/// Reads `N` bytes at `at`.
pub(super) fn bytes_at<const N: usize>(image: &[u8], at: usize) -> Option<[u8; N]> {
    image.get(at..at + N)?.try_into().ok()
}

/// The value in `slot`, or `default` without one (an entry that is not
/// an integer in RAM).
#[inline(always)]
pub fn read_slot(od: &DriveObjects, slot: Option<Slot>, default: i64) -> i64 {
    slot.map_or(default, |s| od.load_slot(s))
}

/// Stores `value` in `slot`; dropped without one or out of the type's
/// range (a runtime value must never stop the cycle that writes it).
#[inline(always)]
pub fn write_slot(od: &mut DriveObjects, slot: Option<Slot>, value: i64) {
    if let Some(s) = slot {
        od.store_slot(s, value);
    }
}

/// Copies `N` bytes from `src` at `from` to `dst` at `to`; `false`
/// (nothing copied) when either range is outside its slice.
#[inline(always)]
pub(super) fn copy_bytes<const N: usize>(src: &[u8], from: usize, dst: &mut [u8], to: usize) -> bool {
    match bytes_at::<N>(src, from) {
        Some(b) => put_at(dst, to, b),
        None => false,
    }
}

/// Writes `N` bytes at `at`; `false` (nothing written) outside `image`.
#[inline]
pub(super) fn put_at<const N: usize>(image: &mut [u8], at: usize, bytes: [u8; N]) -> bool {
    match image
        .get_mut(at..at + N)
        .and_then(|s| <&mut [u8; N]>::try_from(s).ok())
    {
        Some(dst) => {
            *dst = bytes;
            true
        }
        None => false,
    }
}

/// The value of type `t` at `at` in `image` (the common widths without the
/// generic decoder's copy and shifts).
pub(super) fn load(image: &[u8], at: usize, t: DataType) -> Result<i64, SdoAbort> {
    let v = match t {
        DataType::Bool | DataType::U8 => bytes_at::<1>(image, at).map(|[b]| i64::from(b)),
        DataType::I8 => bytes_at::<1>(image, at).map(|[b]| i64::from(b as i8)),
        DataType::U16 => bytes_at(image, at).map(|b| i64::from(u16::from_le_bytes(b))),
        DataType::I16 => bytes_at(image, at).map(|b| i64::from(i16::from_le_bytes(b))),
        DataType::U32 => bytes_at(image, at).map(|b| i64::from(u32::from_le_bytes(b))),
        DataType::I32 => bytes_at(image, at).map(|b| i64::from(i32::from_le_bytes(b))),
        _ => return t.decode(image.get(at..at + t.bytes()).ok_or(SdoAbort::GENERAL)?),
    };
    v.ok_or(SdoAbort::GENERAL)
}

/// A resolved integer entry in the RAM image: the handle the control cycle
/// and the process-data copy use for the entries they touch every cycle
/// (resolved once, then a load or store of one to eight bytes). It depends
/// only on the declaration, so it stays valid for every [`DriveObjects`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Slot {
    /// Byte offset in the RAM image.
    pub(super) at: u16,
    /// The entry's type.
    pub(super) kind: SlotType,
    /// A changed value is a configuration change.
    pub(super) config: bool,
}

/// The types a [`Slot`] holds (one byte, so a slot is four).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SlotType {
    Bool,
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    U64,
    I64,
}

impl SlotType {
    pub(super) const fn of(t: DataType) -> Option<Self> {
        Some(match t {
            DataType::Bool => Self::Bool,
            DataType::U8 => Self::U8,
            DataType::I8 => Self::I8,
            DataType::U16 => Self::U16,
            DataType::I16 => Self::I16,
            DataType::U32 => Self::U32,
            DataType::I32 => Self::I32,
            DataType::U64 => Self::U64,
            DataType::I64 => Self::I64,
            _ => return None,
        })
    }

    /// The type's value range.
    pub(super) const fn range(self) -> (i64, i64) {
        match self {
            Self::Bool => (0, 1),
            Self::U8 => (0, u8::MAX as i64),
            Self::I8 => (i8::MIN as i64, i8::MAX as i64),
            Self::U16 => (0, u16::MAX as i64),
            Self::I16 => (i16::MIN as i64, i16::MAX as i64),
            Self::U32 => (0, u32::MAX as i64),
            Self::I32 => (i32::MIN as i64, i32::MAX as i64),
            Self::U64 => (0, i64::MAX),
            Self::I64 => (i64::MIN, i64::MAX),
        }
    }

    /// Width in bytes.
    pub(super) const fn bytes(self) -> usize {
        match self {
            Self::Bool | Self::U8 | Self::I8 => 1,
            Self::U16 | Self::I16 => 2,
            Self::U32 | Self::I32 => 4,
            Self::U64 | Self::I64 => 8,
        }
    }

    pub(super) const fn data_type(self) -> DataType {
        match self {
            Self::Bool => DataType::Bool,
            Self::U8 => DataType::U8,
            Self::I8 => DataType::I8,
            Self::U16 => DataType::U16,
            Self::I16 => DataType::I16,
            Self::U32 => DataType::U32,
            Self::I32 => DataType::I32,
            Self::U64 => DataType::U64,
            Self::I64 => DataType::I64,
        }
    }
}

/// A [`Slot`] whose type was checked once against `T` ([`Slot::typed`]):
/// the control cycle's loads and stores of its set-points and actual
/// values, without a type dispatch or range check.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Typed<T> {
    pub(super) at: u16,
    pub(super) config: bool,
    pub(super) value: PhantomData<T>,
}

/// The Rust type of a [`Typed`] slot's entry.
pub(crate) trait SlotValue: Copy {
    /// The entry type that holds it.
    const KIND: SlotType;
    /// The value at `at` of `image`; `None` outside it.
    fn load(image: &[u8], at: usize) -> Option<Self>;
    /// Writes the value at `at` of `image`; `false` outside it.
    fn store(self, image: &mut [u8], at: usize) -> bool;
    /// The value widened for [`DriveObjects::store_slot`].
    fn wide(self) -> i64;
}

macro_rules! slot_value {
    ($($t:ty => $kind:ident, $n:literal;)*) => {$(
        impl SlotValue for $t {
            const KIND: SlotType = SlotType::$kind;
            #[inline(always)]
            fn load(image: &[u8], at: usize) -> Option<Self> {
                bytes_at::<$n>(image, at).map(<$t>::from_le_bytes)
            }
            #[inline(always)]
            fn store(self, image: &mut [u8], at: usize) -> bool {
                put_at(image, at, self.to_le_bytes())
            }
            #[inline(always)]
            fn wide(self) -> i64 {
                i64::from(self)
            }
        }
    )*};
}

slot_value! {
    u8 => U8, 1;
    i8 => I8, 1;
    u16 => U16, 2;
    i16 => I16, 2;
    u32 => U32, 4;
    i32 => I32, 4;
}

impl<T> Typed<T> {
    /// Byte offset in the RAM image.
    #[cfg(test)]
    pub(crate) fn at(self) -> u16 {
        self.at
    }
}

impl Slot {
    /// The slot as a [`Typed`] one when its entry holds a `T`.
    pub(crate) fn typed<T: SlotValue>(self) -> Option<Typed<T>> {
        (self.kind == T::KIND).then_some(Typed {
            at: self.at,
            config: self.config,
            value: PhantomData,
        })
    }

    /// Width of the value in bytes.
    #[inline]
    pub fn bytes(self) -> usize {
        self.kind.bytes()
    }

    /// The entry's type.
    pub fn data_type(self) -> DataType {
        self.kind.data_type()
    }

    /// Byte offset of the value in the RAM image (for the PDO copy
    /// program, [`crate::pdo_image`]).
    pub(crate) fn ram_offset(self) -> u16 {
        self.at
    }

    /// Whether a changed value is a configuration change
    /// ([`DriveObjects::config_generation`]).
    pub fn is_config(self) -> bool {
        self.config
    }
}

impl DriveObjects {
    /// The [`Slot`] of integer entry `index`:`sub` ("EtherCAT Rx SDO Info"
    /// numbering, aliases followed) when its value is in RAM; `None` for
    /// constants, strings, REAL32 and unknown entries.
    pub fn slot(&self, index: u16, sub: u8) -> Option<Slot> {
        let r = resolve(index, sub)?;
        let Place::Ram(at) = r.place else {
            return None;
        };
        let kind = SlotType::of(r.data_type)?;
        let fits = usize::from(at) + r.data_type.bytes() <= IMAGE_BYTES;
        fits.then_some(Slot {
            at,
            kind,
            config: r.config,
        })
    }

    /// The value in `slot` (as [`get`](Self::get) reads it).
    #[inline(always)]
    pub fn load_slot(&self, slot: Slot) -> i64 {
        let (img, at) = (&self.image, usize::from(slot.at));
        let v = match slot.kind {
            SlotType::Bool | SlotType::U8 => bytes_at::<1>(img, at).map(|[b]| i64::from(b)),
            SlotType::I8 => bytes_at::<1>(img, at).map(|[b]| i64::from(b as i8)),
            SlotType::U16 => bytes_at(img, at).map(|b| i64::from(u16::from_le_bytes(b))),
            SlotType::I16 => bytes_at(img, at).map(|b| i64::from(i16::from_le_bytes(b))),
            SlotType::U32 => bytes_at(img, at).map(|b| i64::from(u32::from_le_bytes(b))),
            SlotType::I32 => bytes_at(img, at).map(|b| i64::from(i32::from_le_bytes(b))),
            SlotType::U64 => bytes_at(img, at).map(|b| u64::from_le_bytes(b) as i64),
            SlotType::I64 => bytes_at(img, at).map(i64::from_le_bytes),
        };
        v.unwrap_or(0)
    }

    /// Stores `value` in `slot` (as [`set`](Self::set): a value outside the
    /// type's range changes nothing and returns `false`).
    #[inline(always)]
    pub fn store_slot(&mut self, slot: Slot, value: i64) -> bool {
        let (lo, hi) = slot.kind.range();
        if value < lo || value > hi {
            return false;
        }
        if slot.config && self.load_slot(slot) != value {
            self.config_changed();
        }
        let (img, at) = (&mut self.image, usize::from(slot.at));
        match slot.kind {
            SlotType::Bool | SlotType::U8 | SlotType::I8 => put_at(img, at, [value as u8]),
            SlotType::U16 | SlotType::I16 => put_at(img, at, (value as u16).to_le_bytes()),
            SlotType::U32 | SlotType::I32 => put_at(img, at, (value as u32).to_le_bytes()),
            SlotType::U64 | SlotType::I64 => put_at(img, at, value.to_le_bytes()),
        }
    }

    /// Axis `axis`' block at the start of the RAM image (axis B's for any
    /// `axis` but 0); both ranges are constant, so the checks fold away.
    #[inline(always)]
    fn axis_block(&self, axis: u8) -> Option<&[u8; AXIS_BLOCK]> {
        let (a, rest) = self.image.split_first_chunk::<AXIS_BLOCK>()?;
        if axis == 0 {
            Some(a)
        } else {
            rest.first_chunk::<AXIS_BLOCK>()
        }
    }

    /// The value of the cycle field `f` of axis `axis` (0 = A): a load at a
    /// constant offset in the axis' block, no lookup, no `Option` to test.
    #[inline(always)]
    pub(crate) fn cycle_read<T: SlotValue + Default>(&self, axis: u8, f: CycleField<T>) -> T {
        self.axis_block(axis)
            .and_then(|b| T::load(b, f.at))
            .unwrap_or_default()
    }

    /// Stores `value` in the cycle field `f` of axis `axis` (0 = A). The
    /// fields the cycle writes are actual values, never configuration
    /// entries (`c134_cycle_fields_are_the_slots_of_both_axes`), so no
    /// configuration change is noted.
    #[inline(always)]
    pub(crate) fn cycle_write<T: SlotValue>(&mut self, axis: u8, f: CycleField<T>, value: T) {
        let Some((a, rest)) = self.image.split_first_chunk_mut::<AXIS_BLOCK>() else {
            return;
        };
        let block = if axis == 0 {
            Some(a)
        } else {
            rest.first_chunk_mut::<AXIS_BLOCK>()
        };
        if let Some(b) = block {
            value.store(b, f.at);
        }
    }

    /// Stores `value` in a typed slot (dropped without one); a
    /// configuration entry goes through [`store_slot`](Self::store_slot),
    /// which notes a change.
    #[inline(always)]
    pub(crate) fn write_typed<T: SlotValue>(&mut self, slot: Option<Typed<T>>, value: T) {
        match slot {
            Some(s) if s.config => {
                let slot = Slot {
                    at: s.at,
                    kind: T::KIND,
                    config: true,
                };
                self.store_slot(slot, value.wide());
            }
            Some(s) => {
                value.store(&mut self.image, usize::from(s.at));
            }
            None => {}
        }
    }

    /// Copies the raw little-endian bytes of `slot` to `dst` at `at`
    /// (the TxPDO copy); `false` when they do not fit there.
    #[inline(always)]
    pub fn copy_slot_to(&self, slot: Slot, dst: &mut [u8], at: usize) -> bool {
        let from = usize::from(slot.at);
        match slot.kind.bytes() {
            1 => copy_bytes::<1>(&self.image, from, dst, at),
            2 => copy_bytes::<2>(&self.image, from, dst, at),
            4 => copy_bytes::<4>(&self.image, from, dst, at),
            _ => copy_bytes::<8>(&self.image, from, dst, at),
        }
    }

    /// Stores the slot's width of raw little-endian bytes from `src` at
    /// `at` (the RxPDO copy); `false` (nothing changed) when `src` is too
    /// short.
    #[inline(always)]
    pub fn copy_slot_from(&mut self, slot: Slot, src: &[u8], at: usize) -> bool {
        let n = slot.kind.bytes();
        let Some(data) = src.get(at..at + n) else {
            return false;
        };
        let to = usize::from(slot.at);
        if slot.config {
            if self.image.get(to..to + n) == Some(data) {
                return true;
            }
            self.config_changed();
        }
        match n {
            1 => copy_bytes::<1>(src, at, &mut self.image, to),
            2 => copy_bytes::<2>(src, at, &mut self.image, to),
            4 => copy_bytes::<4>(src, at, &mut self.image, to),
            _ => copy_bytes::<8>(src, at, &mut self.image, to),
        }
    }

    /// The RxPDO copy program's stores of one width ([`crate::pdo_image`]):
    /// `N` bytes of `src` at each `op.img` into the RAM image at `op.ram`, as
    /// [`copy_slot_from`](Self::copy_slot_from) stores a slot that is not a
    /// configuration entry. An op outside either buffer is skipped (the
    /// program is checked when it is built, so none is).
    #[inline(always)]
    pub(crate) fn copy_in<const N: usize>(&mut self, ops: &[CopyOp], src: &[u8]) {
        for op in ops {
            if let Some(b) = bytes_at::<N>(src, usize::from(op.img)) {
                put_at(&mut self.image, usize::from(op.ram), b);
            }
        }
    }

    /// The RxPDO copy program's stores of configuration entries (any of the
    /// widths 1, 2, 4, 8, its log2 in `op.img` from [`WIDTH_SHIFT`] on), as
    /// [`copy_slot_from`](Self::copy_slot_from) stores them: a value that
    /// differs from the one in RAM is a configuration change, the same value
    /// is not.
    #[inline(always)]
    pub(crate) fn copy_in_config(&mut self, ops: &[CopyOp], src: &[u8]) {
        const OFFSET: u16 = (1 << WIDTH_SHIFT) - 1;
        for op in ops {
            let (ram, img) = (usize::from(op.ram), usize::from(op.img & OFFSET));
            match op.img >> WIDTH_SHIFT {
                2 => self.store_config::<4>(ram, src, img),
                1 => self.store_config::<2>(ram, src, img),
                0 => self.store_config::<1>(ram, src, img),
                _ => self.store_config::<8>(ram, src, img),
            }
        }
    }

    /// Stores the `N` bytes of `src` at `img` at `ram` if they differ from
    /// the value there (compared as one `N`-byte word, no `memcmp`), as a
    /// configuration change.
    #[inline(always)]
    pub(super) fn store_config<const N: usize>(&mut self, ram: usize, src: &[u8], img: usize) {
        if let (Some(new), Some(old)) = (bytes_at::<N>(src, img), bytes_at::<N>(&self.image, ram)) {
            if new != old {
                self.config_changed();
                put_at(&mut self.image, ram, new);
            }
        }
    }

    /// The TxPDO copy program's loads of one width ([`crate::pdo_image`]):
    /// `N` bytes of the RAM image at each `op.ram` into `dst` at `op.img`,
    /// as [`copy_slot_to`](Self::copy_slot_to) does; an op outside either
    /// buffer is skipped.
    #[inline(always)]
    pub(crate) fn copy_out<const N: usize>(&self, ops: &[CopyOp], dst: &mut [u8]) {
        for op in ops {
            let (ram, img) = (usize::from(op.ram), usize::from(op.img));
            // the destination first: its check and the source's share one
            // predicated block
            let to = dst
                .get_mut(img..img + N)
                .and_then(|d| <&mut [u8; N]>::try_from(d).ok());
            if let (Some(to), Some(b)) = (to, bytes_at::<N>(&self.image, ram)) {
                *to = b;
            }
        }
    }
}
