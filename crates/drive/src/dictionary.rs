//! [`DriveObjects`]: the values of the declaration in [`crate::objects`] and
//! the CoE access rules (spec §6.5 abort codes, §5 PDO mapping/assignment,
//! §2.4 visibility, §2.5 save/restore).
//!
//! Subindex numbering: the bus side ([`od::Dictionary`]) uses the active
//! [`Template`]; the runtime side ([`DriveObjects::get`], [`DriveObjects::set`],
//! [`LiveValues`]) always uses the "EtherCAT Rx SDO Info" numbering
//! (element + 1 for manufacturer arrays), so it does not change with the
//! template.

use core::cell::Cell;
use core::marker::PhantomData;
use core::sync::atomic::{AtomicU32, Ordering};

use crate::objects::{self, enumeration, find, Object, Value, IMAGE_BYTES, INITIAL_IMAGE, OBJECTS, OFFSETS};
use crate::pdo_image::{CopyOp, WIDTH_SHIFT};
use crate::{parameter_index, MAPPING_ENTRIES, SOFTWARE_BUILD};
use od::{CommState, DataType, Dictionary, EntryInfo, ObjectInfo, SdoAbort};

/// Signature written to 1010h:01 to save ("save", CiA 301).
pub const SAVE_SIGNATURE: u32 = 0x6576_6173;
/// Signature written to 1011h:01 to restore defaults ("load", CiA 301).
pub const LOAD_SIGNATURE: u32 = 0x6461_6F6C;
/// Longest PDO in bits: 24 entries of 32 bits (spec §5.3, inference).
pub const MAX_PDO_BITS: u32 = MAPPING_ENTRIES as u32 * 32;

/// The subindex template of manufacturer arrays and records (spec §2.6).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Template {
    /// "EtherCAT Rx": subindex = element number; no SDO Info.
    Rx,
    /// "EtherCAT Rx SDO Info": subindex = element number + 1 (default).
    SdoInfo,
}

/// Revision number 1018h:03 in `template` (E-008): the software build
/// number shifted left by one, bit 0 = 1 for "EtherCAT Rx SDO Info".
/// [`SOFTWARE_BUILD`] is the revision of the default template.
pub const fn revision(template: Template) -> u32 {
    (SOFTWARE_BUILD & !1)
        | match template {
            Template::Rx => 0,
            Template::SdoInfo => 1,
        }
}
const _: () = assert!(
    SOFTWARE_BUILD & 1 == 1,
    "SOFTWARE_BUILD is the SDO-Info template revision"
);

/// Requests for the runtime, set by bus writes, cleared by
/// [`DriveObjects::take_requests`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Requests {
    /// Save the persistent values ([`DriveObjects::persistent_image`]):
    /// 1010h:01 = "save" or A00\[0\] = 1.
    pub save: bool,
    /// Restart the device: A09\[0\] = 1.
    pub restart: bool,
    /// 1011h:01 = "load" restored the defaults in RAM (the stored image is
    /// unchanged until the next save).
    pub defaults_restored: bool,
}

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

const IMAGE_MAGIC: [u8; 4] = *b"DOD1";
const IMAGE_HEADER: usize = 12;
/// Size of a persistent image: 12-byte header (magic "DOD1", layout hash
/// u32, payload length u16, template u8, 0) + the persistent values.
pub const PERSISTENT_IMAGE_BYTES: usize = IMAGE_HEADER + objects::PERSISTENT_BYTES;

/// Values owned by other parts of the firmware ([`Value::Live`] objects):
/// the statusword, actual values, error register, diagnosis history, ESM
/// state… A provider answers what it owns and returns `None` for the rest,
/// which the dictionary then answers from its RAM image (where the runtime
/// may also push values with [`DriveObjects::set`]). Indices and subindices
/// use the "EtherCAT Rx SDO Info" numbering.
pub trait LiveValues {
    /// Reads `index`:`sub` into `buf`: `Some(byte count or abort)` if owned.
    fn read(&mut self, index: u16, sub: u8, buf: &mut [u8]) -> Option<Result<usize, SdoAbort>> {
        let _ = (index, sub, buf);
        None
    }

    /// A checked write (access, size, range) to a live entry, before the
    /// dictionary stores it in its RAM image; an error refuses the write.
    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        let _ = (index, sub, data);
        Ok(())
    }
}

/// No live-value provider: live entries answer from the RAM image.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoLive;
impl LiveValues for NoLive {}

/// An entry: object position in [`OBJECTS`], entry position in its
/// "EtherCAT Rx SDO Info" entries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Loc {
    obj: usize,
    pos: usize,
}

impl Loc {
    fn object(self) -> Result<&'static Object, SdoAbort> {
        OBJECTS.get(self.obj).ok_or(SdoAbort::NO_OBJECT)
    }

    fn entry(self) -> Result<&'static EntryInfo, SdoAbort> {
        self.object()?
            .info
            .entries
            .get(self.pos)
            .ok_or(SdoAbort::NO_SUBINDEX)
    }

    /// Byte range of the entry in the RAM image.
    fn slot(self) -> Result<core::ops::Range<usize>, SdoAbort> {
        let o = self.object()?;
        let base = usize::from(*OFFSETS.get(self.obj).ok_or(SdoAbort::NO_OBJECT)?);
        let before: usize = o
            .info
            .entries
            .iter()
            .take(self.pos)
            .map(|e| e.data_type.bytes())
            .sum();
        let at = base + before;
        Ok(at..at + self.entry()?.data_type.bytes())
    }
}

/// The entry `index`:`sub` in "EtherCAT Rx SDO Info" numbering, visible or not.
fn canonical(index: u16, sub: u8) -> Result<Loc, SdoAbort> {
    let (obj, o) = find(index).ok_or(SdoAbort::NO_OBJECT)?;
    let pos = o
        .info
        .entries
        .iter()
        .position(|e| e.sub == sub)
        .ok_or(SdoAbort::NO_SUBINDEX)?;
    Ok(Loc { obj, pos })
}

/// Where the value of `loc` lives: the entry itself or, for mirrors and
/// aliases, the target entry.
fn follow(loc: Loc) -> Result<Loc, SdoAbort> {
    match loc.object()?.value {
        Value::Mirror { index, sub0 } if loc.pos > 0 || sub0 => {
            let (obj, _) = find(index).ok_or(SdoAbort::NO_OBJECT)?;
            Ok(Loc { obj, pos: loc.pos })
        }
        Value::Alias(list) => match list.get(loc.pos) {
            Some(&(index, sub)) if index != 0 => canonical(index, sub),
            _ => Ok(loc),
        },
        _ => Ok(loc),
    }
}

/// Does `loc` have a slot in the RAM image?
fn in_ram(loc: Loc) -> Result<bool, SdoAbort> {
    Ok(matches!(loc.object()?.value, Value::Ram | Value::Live))
}

fn put(buf: &mut [u8], data: &[u8]) -> Result<usize, SdoAbort> {
    buf.get_mut(..data.len())
        .ok_or(SdoAbort::OUT_OF_MEMORY)?
        .copy_from_slice(data);
    Ok(data.len())
}

/// Where an integer/REAL32 entry's value lives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Place {
    /// A slot in the RAM image starting at this byte.
    Ram(u16),
    /// A constant (the declared default as its type reads it), ≤ 32 bits.
    Const(i64),
}

/// What [`DriveObjects::get`] and [`DriveObjects::set`] resolve
/// `index`:`sub` to (aliases and mirrors followed). Depends only on the
/// declaration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Resolved {
    /// `index << 8 | sub` of the request (24 bits).
    key: u32,
    place: Place,
    /// The entry's type (its width is the slot's).
    data_type: DataType,
    /// A write to it is a configuration change ([`is_config`]).
    config: bool,
}

/// The scalar types a cache slot can hold, by code (0 = empty slot).
const CACHED_TYPES: [DataType; 10] = [
    DataType::Bool,
    DataType::I8,
    DataType::I16,
    DataType::I32,
    DataType::U8,
    DataType::U16,
    DataType::U32,
    DataType::F32,
    DataType::I64,
    DataType::U64,
];

/// Type-code flag of a constant.
const CONST_FLAG: u32 = 0x80;
/// Type-code flag of a configuration entry.
const CONFIG_FLAG: u32 = 0x40;

/// Set-points the control cycle reads every cycle (axis-A indices; axis B
/// at +800h / +8000h): writes to them are not configuration changes.
const CYCLIC_SETPOINTS: [u16; 11] = [
    0x6040,
    0x6060,
    0x607A,
    0x60C1,
    0x60FF,
    0x6071,
    0x60B1,
    0x60B2,
    0x6042,
    0x60B8,
    parameter_index(8, 210),
];

/// Whether a changed value of object `o` is a configuration change
/// ([`DriveObjects::config_generation`]): RAM values (parameters and
/// set-points) except the cyclic set-points; live values (actual values,
/// diagnosis, fed by the runtime) never are.
fn is_config(o: &Object) -> bool {
    let index = o.info.index;
    let a = match index {
        0x6800..=0x6FFF => index - crate::AXIS_B_CIA402,
        0xA000..=0xFFFF => index.wrapping_sub(crate::AXIS_B_MANUFACTURER),
        _ => index,
    };
    o.value == Value::Ram && !CYCLIC_SETPOINTS.contains(&a)
}

impl Resolved {
    /// Packed into two words: key (24 bits) | constant flag | type code
    /// (1..=10; the word is never 0 or [`BUSY`]), then the RAM offset or the
    /// constant's 32 bits.
    fn pack(self) -> Option<(u32, u32)> {
        let code = CACHED_TYPES.iter().position(|&t| t == self.data_type)? as u32 + 1;
        let code = code | if self.config { CONFIG_FLAG } else { 0 };
        match self.place {
            Place::Ram(at) => Some(((self.key << 8) | code, u32::from(at))),
            Place::Const(v) => {
                let bits = match self.data_type {
                    DataType::I8 | DataType::I16 | DataType::I32 => i32::try_from(v).ok()? as u32,
                    DataType::I64 | DataType::U64 => return None,
                    _ => u32::try_from(v).ok()?,
                };
                Some(((self.key << 8) | CONST_FLAG | code, bits))
            }
        }
    }

    fn unpack(key: u32, word: u32, value: u32) -> Option<Self> {
        let data_type = *CACHED_TYPES.get(((word & 0x3F) as usize).checked_sub(1)?)?;
        let config = word & CONFIG_FLAG != 0;
        let place = if word & CONST_FLAG == 0 {
            Place::Ram(u16::try_from(value).ok()?)
        } else if matches!(data_type, DataType::I8 | DataType::I16 | DataType::I32) {
            Place::Const(i64::from(value as i32))
        } else {
            Place::Const(i64::from(value))
        };
        Some(Self {
            key,
            place,
            data_type,
            config,
        })
    }
}

/// Slots of the resolution cache (a power of two), two words each: key and
/// type code, then the RAM offset or constant. Open addressing, no eviction; the runtime
/// touches ~250 distinct entries. The cache is a memo of the (constant)
/// declaration, shared by every [`DriveObjects`] and every task: a slot is
/// claimed with a compare-and-swap to [`BUSY`], its offset written, then its
/// key published (release); readers take a slot only with its key (acquire).
const CACHE_SLOTS: usize = 512;
/// Probes before a lookup gives up on the cache (the entry is then resolved
/// without being cached).
const MAX_PROBES: usize = 16;
/// A slot being filled.
const BUSY: u32 = u32::MAX;

static CACHE_KEYS: [AtomicU32; CACHE_SLOTS] = [const { AtomicU32::new(0) }; CACHE_SLOTS];
static CACHE_AT: [AtomicU32; CACHE_SLOTS] = [const { AtomicU32::new(0) }; CACHE_SLOTS];

/// The home slot of `key` (multiplicative hash, top 9 bits).
fn home_slot(key: u32) -> usize {
    (key.wrapping_mul(0x9E37_79B1) >> 23) as usize % CACHE_SLOTS
}

/// Where integer/REAL32 entry `index`:`sub` ("EtherCAT Rx SDO Info"
/// numbering, aliases followed) lives, from the cache or resolved and
/// cached; `None` for entries that are neither in RAM nor constant.
fn resolve(index: u16, sub: u8) -> Option<Resolved> {
    let key = (u32::from(index) << 8) | u32::from(sub);
    let mut at = home_slot(key);
    for _ in 0..MAX_PROBES {
        let (k, a) = (CACHE_KEYS.get(at)?, CACHE_AT.get(at)?);
        match k.load(Ordering::Acquire) {
            0 => {
                let r = lookup(key)?;
                if let Some((word, value)) = r.pack() {
                    if k.compare_exchange(0, BUSY, Ordering::AcqRel, Ordering::Relaxed)
                        .is_ok()
                    {
                        a.store(value, Ordering::Relaxed);
                        k.store(word, Ordering::Release);
                    }
                }
                return Some(r);
            }
            BUSY => return lookup(key),
            word if word >> 8 == key => return Resolved::unpack(key, word, a.load(Ordering::Relaxed)),
            _ => at = (at + 1) % CACHE_SLOTS,
        }
    }
    lookup(key)
}

/// Resolves `key` from the declaration: `None` for entries that are not
/// an integer/REAL32 in RAM or a constant (strings, 1018h, commands, unknown).
fn lookup(key: u32) -> Option<Resolved> {
    let (index, sub) = ((key >> 8) as u16, key as u8);
    let loc = follow(canonical(index, sub).ok()?).ok()?;
    let e = loc.entry().ok()?;
    let data_type = e.data_type;
    if !CACHED_TYPES.contains(&data_type) {
        return None;
    }
    let o = loc.object().ok()?;
    let place = match o.value {
        Value::Ram | Value::Live => Place::Ram(u16::try_from(loc.slot().ok()?.start).ok()?),
        Value::Const => {
            let mut raw = [0u8; 8];
            let n = data_type.encode(e.default, &mut raw).ok()?;
            Place::Const(data_type.decode(raw.get(..n)?).ok()?)
        }
        _ => return None,
    };
    Some(Resolved {
        key,
        place,
        data_type,
        config: is_config(o),
    })
}

/// Reads `N` bytes at `at`.
fn bytes_at<const N: usize>(image: &[u8], at: usize) -> Option<[u8; N]> {
    image.get(at..at + N)?.try_into().ok()
}

/// The value in `slot`, or `default` without one (an entry that is not
/// an integer in RAM).
#[inline(always)]
pub(crate) fn read_slot(od: &DriveObjects, slot: Option<Slot>, default: i64) -> i64 {
    slot.map_or(default, |s| od.load_slot(s))
}

/// Stores `value` in `slot`; dropped without one or out of the type's
/// range (a runtime value must never stop the cycle that writes it).
#[inline(always)]
pub(crate) fn write_slot(od: &mut DriveObjects, slot: Option<Slot>, value: i64) {
    if let Some(s) = slot {
        od.store_slot(s, value);
    }
}

/// Copies `N` bytes from `src` at `from` to `dst` at `to`; `false`
/// (nothing copied) when either range is outside its slice.
#[inline(always)]
fn copy_bytes<const N: usize>(src: &[u8], from: usize, dst: &mut [u8], to: usize) -> bool {
    match bytes_at::<N>(src, from) {
        Some(b) => put_at(dst, to, b),
        None => false,
    }
}

/// Writes `N` bytes at `at`; `false` (nothing written) outside `image`.
#[inline]
fn put_at<const N: usize>(image: &mut [u8], at: usize, bytes: [u8; N]) -> bool {
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
fn load(image: &[u8], at: usize, t: DataType) -> Result<i64, SdoAbort> {
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
    at: u16,
    /// The entry's type.
    kind: SlotType,
    /// A changed value is a configuration change.
    config: bool,
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
    const fn of(t: DataType) -> Option<Self> {
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
    const fn range(self) -> (i64, i64) {
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
    const fn bytes(self) -> usize {
        match self {
            Self::Bool | Self::U8 | Self::I8 => 1,
            Self::U16 | Self::I16 => 2,
            Self::U32 | Self::I32 => 4,
            Self::U64 | Self::I64 => 8,
        }
    }

    const fn data_type(self) -> DataType {
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
    at: u16,
    config: bool,
    value: PhantomData<T>,
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
    pub(crate) fn is_config(self) -> bool {
        self.config
    }
}

/// The drive's object dictionary: the RAM image of every value, the active
/// template and the requests for the runtime. Implements [`od::Dictionary`]
/// (live entries from the RAM image; see [`DriveObjects::with_live`]).
///
/// [`get`](Self::get)/[`set`](Self::set) resolve `index`:`sub` through a
/// shared cache (open addressing, filled on first use): a hash, a compare
/// and a load instead of a binary search, an entry scan and an offset sum.
/// The entries the control cycle and the process-data copy touch every
/// cycle are resolved once into a [`Slot`] and then read and written with
/// [`load_slot`](Self::load_slot)/[`store_slot`](Self::store_slot) and their
/// typed forms (docs/architecture.md, cycle cost).
///
/// (`repr(C)`: the RAM image first, at the struct's address, so the control
/// cycle's loads and stores at a slot's offset need no extra add.)
#[derive(Debug, Clone)]
#[repr(C)]
pub struct DriveObjects {
    image: [u8; IMAGE_BYTES],
    template: Template,
    requests: Requests,
    /// Counts configuration changes ([`Self::config_generation`]).
    config_generation: u32,
    /// The SyncManager lengths of the mapping (RxPDO, TxPDO bytes) with the
    /// configuration generation they were summed at: the slave asks every
    /// poll, the mapping changes only with the generation.
    pdo_bytes: Cell<Option<(u32, (usize, usize))>>,
}

/// Equal dictionaries hold the same values and template; how they got
/// there (the configuration generation) does not count.
impl PartialEq for DriveObjects {
    fn eq(&self, other: &Self) -> bool {
        self.image == other.image && self.template == other.template && self.requests == other.requests
    }
}

impl Eq for DriveObjects {}

impl Default for DriveObjects {
    fn default() -> Self {
        Self::new()
    }
}

/// [`DriveObjects`] with a [`LiveValues`] provider, as the CoE server sees it.
#[derive(Debug)]
pub struct WithLive<'a, L: LiveValues> {
    /// The dictionary.
    pub objects: &'a mut DriveObjects,
    /// The provider of live values.
    pub live: &'a mut L,
}

impl DriveObjects {
    /// Every value at its default, template "EtherCAT Rx SDO Info".
    pub const fn new() -> Self {
        Self {
            image: INITIAL_IMAGE,
            template: Template::SdoInfo,
            requests: Requests {
                save: false,
                restart: false,
                defaults_restored: false,
            },
            config_generation: 0,
            pdo_bytes: Cell::new(None),
        }
    }

    /// A counter that changes whenever a configuration value may have
    /// changed: a changed RAM value other than a cyclic set-point (6040h,
    /// 6060h, 607Ah, 60C1h, 60FFh, 6071h, 60B1h, 60B2h, 6042h, 60B8h, I210 of
    /// either axis), a load, a restore or a template switch. Live values never
    /// change it. The axes re-read their configuration only when it moved.
    pub fn config_generation(&self) -> u32 {
        self.config_generation
    }

    fn config_changed(&mut self) {
        self.config_generation = self.config_generation.wrapping_add(1);
    }

    /// This dictionary with `live` answering the live entries.
    pub fn with_live<'a, L: LiveValues>(&'a mut self, live: &'a mut L) -> WithLive<'a, L> {
        WithLive { objects: self, live }
    }

    /// The active subindex template.
    pub fn template(&self) -> Template {
        self.template
    }

    /// Switches the subindex template (a configuration setting of the
    /// device; it changes 1018h:03, the addressing of manufacturer arrays and
    /// the availability of SDO Info at once; the SII/ESI must follow).
    pub fn set_template(&mut self, template: Template) {
        self.template = template;
        self.config_changed();
    }

    /// The requests set since the last call, cleared.
    pub fn take_requests(&mut self) -> Requests {
        core::mem::take(&mut self.requests)
    }

    /// Requests a save (as A00\[0\] = 1 does).
    pub fn request_save(&mut self) {
        self.requests.save = true;
    }

    /// The requests set since the last [`take_requests`](Self::take_requests).
    pub fn requests(&self) -> Requests {
        self.requests
    }

    /// The access level of CoE accesses, A10\[2\] (E-017).
    pub fn access_level(&self) -> u8 {
        self.get(parameter_index(0, 10), 3).map_or(0, |v| v as u8)
    }

    fn visible(&self, o: &Object) -> bool {
        o.level <= self.access_level()
    }

    fn sdo_info(&self) -> bool {
        self.template == Template::SdoInfo
    }

    /// The visible entry `index`:`sub` in the active template.
    fn locate(&self, index: u16, sub: u8) -> Result<Loc, SdoAbort> {
        let (obj, o) = find(index).ok_or(SdoAbort::NO_OBJECT)?;
        if !self.visible(o) {
            return Err(SdoAbort::NO_OBJECT);
        }
        let rx_view = !self.sdo_info() && o.rx.is_some();
        let view = o.view(self.sdo_info());
        let p = view
            .entries
            .iter()
            .position(|e| e.sub == sub)
            .ok_or(SdoAbort::NO_SUBINDEX)?;
        Ok(Loc {
            obj,
            pos: if rx_view { p + 1 } else { p },
        })
    }

    fn ram(&self, loc: Loc) -> Result<&[u8], SdoAbort> {
        self.image.get(loc.slot()?).ok_or(SdoAbort::GENERAL)
    }

    /// The value of a target entry (after [`follow`]) from RAM or declaration.
    fn read_loc(&self, loc: Loc, buf: &mut [u8]) -> Result<usize, SdoAbort> {
        let o = loc.object()?;
        let e = loc.entry()?;
        match o.value {
            Value::Ram | Value::Live => {
                let raw = self.ram(loc)?;
                let len = match e.data_type {
                    DataType::VisibleString(_) => raw.iter().position(|&b| b == 0).unwrap_or(raw.len()),
                    _ => raw.len(),
                };
                put(buf, raw.get(..len).ok_or(SdoAbort::GENERAL)?)
            }
            Value::Text(s) => put(buf, s.as_bytes()),
            Value::Identity if e.sub == 3 => e.data_type.encode(i64::from(revision(self.template)), buf),
            _ if e.data_type.is_string() => Ok(0),
            _ => e.data_type.encode(e.default, buf),
        }
    }

    /// The integer value of `index`:`sub` ("EtherCAT Rx SDO Info" numbering,
    /// aliases followed; live entries as last set in the RAM image).
    pub fn get(&self, index: u16, sub: u8) -> Result<i64, SdoAbort> {
        if let Some(r) = resolve(index, sub) {
            return match r.place {
                Place::Ram(at) => load(&self.image, usize::from(at), r.data_type),
                Place::Const(v) => Ok(v),
            };
        }
        let loc = follow(canonical(index, sub)?)?;
        let t = loc.entry()?.data_type;
        let mut buf = [0u8; 8];
        let n = self.read_loc(loc, &mut buf)?;
        t.decode(buf.get(..n).ok_or(SdoAbort::GENERAL)?)
    }

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

    /// The value in a typed slot; `None` without one.
    #[inline(always)]
    pub(crate) fn read_typed<T: SlotValue>(&self, slot: Option<Typed<T>>) -> Option<T> {
        slot.and_then(|s| T::load(&self.image, usize::from(s.at)))
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
    fn store_config<const N: usize>(&mut self, ram: usize, src: &[u8], img: usize) {
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

    /// Sets `index`:`sub` from the runtime (statusword, actual values, ESM
    /// state, …): no access, state or level check, only the type's bounds.
    /// "EtherCAT Rx SDO Info" numbering; entries without a RAM slot
    /// (constants) answer 0601 0002h.
    pub fn set(&mut self, index: u16, sub: u8, value: i64) -> Result<(), SdoAbort> {
        let resolved = resolve(index, sub);
        let t = match resolved {
            Some(r) => r.data_type,
            None => follow(canonical(index, sub)?)?.entry()?.data_type,
        };
        if !t.is_integer() && t != DataType::F32 {
            return Err(SdoAbort::TYPE_MISMATCH);
        }
        if t.is_integer() && (value < t.min_value() || value > t.max_value()) {
            return Err(if value < t.min_value() {
                SdoAbort::VALUE_TOO_LOW
            } else {
                SdoAbort::VALUE_TOO_HIGH
            });
        }
        if let Some(r) = resolved {
            let Place::Ram(at) = r.place else {
                return Err(SdoAbort::READ_ONLY);
            };
            let at = usize::from(at);
            let slot = self.image.get_mut(at..at + t.bytes()).ok_or(SdoAbort::GENERAL)?;
            let mut new = [0u8; 8];
            let n = t.encode(value, &mut new)?;
            let new = new.get(..n).ok_or(SdoAbort::GENERAL)?;
            if slot != new {
                for (d, s) in slot.iter_mut().zip(new) {
                    *d = *s;
                }
                if r.config {
                    self.config_changed();
                }
            }
            return Ok(());
        }
        let mut raw = [0u8; 8];
        let n = t.encode(value, &mut raw)?;
        self.set_bytes(index, sub, raw.get(..n).ok_or(SdoAbort::GENERAL)?)
    }

    /// Sets `index`:`sub` from raw little-endian bytes or string bytes (e.g.
    /// the A257 texts), like [`set`](Self::set); strings shorter than the
    /// entry are padded with 0.
    pub fn set_bytes(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        if let Some(Resolved {
            place: Place::Ram(at),
            data_type,
            config,
            ..
        }) = resolve(index, sub)
        {
            // a scalar of its full width: straight into its slot
            if data.len() == data_type.bytes() {
                let at = usize::from(at);
                let slot = self.image.get_mut(at..at + data.len()).ok_or(SdoAbort::GENERAL)?;
                if slot != data {
                    for (d, s) in slot.iter_mut().zip(data) {
                        *d = *s;
                    }
                    if config {
                        self.config_changed();
                    }
                }
                return Ok(());
            }
        }
        let loc = follow(canonical(index, sub)?)?;
        if !in_ram(loc)? {
            return Err(SdoAbort::READ_ONLY);
        }
        loc.entry()?.data_type.check_len(data.len())?;
        self.store(loc, data)
    }

    fn store(&mut self, loc: Loc, data: &[u8]) -> Result<(), SdoAbort> {
        let config = is_config(loc.object()?);
        let slot = self.image.get_mut(loc.slot()?).ok_or(SdoAbort::GENERAL)?;
        if data.len() > slot.len() {
            return Err(SdoAbort::LENGTH_TOO_HIGH);
        }
        let mut changed = false;
        for (k, d) in slot.iter_mut().enumerate() {
            let v = data.get(k).copied().unwrap_or(0);
            changed |= *d != v;
            *d = v;
        }
        if changed && config {
            self.config_changed();
        }
        Ok(())
    }

    fn read_with<L: LiveValues>(
        &self,
        live: &mut L,
        index: u16,
        sub: u8,
        buf: &mut [u8],
    ) -> Result<usize, SdoAbort> {
        let loc = self.locate(index, sub)?;
        if !loc.entry()?.access.readable() {
            return Err(SdoAbort::WRITE_ONLY);
        }
        let target = follow(loc)?;
        let o = target.object()?;
        if o.value == Value::Live {
            if let Some(r) = live.read(o.info.index, target.entry()?.sub, buf) {
                return r;
            }
        }
        self.read_loc(target, buf)
    }

    fn write_with<L: LiveValues>(
        &mut self,
        live: &mut L,
        index: u16,
        sub: u8,
        data: &[u8],
        state: CommState,
    ) -> Result<(), SdoAbort> {
        let loc = self.locate(index, sub)?;
        let access = loc.entry()?.access;
        if !access.writable() {
            return Err(SdoAbort::READ_ONLY);
        }
        if !access.writable_in(state.access_bit()) {
            return Err(SdoAbort::DEVICE_STATE);
        }
        let target = follow(loc)?;
        let (o, e) = (target.object()?, target.entry()?);
        e.data_type.check_len(data.len())?;
        let value = if e.data_type.is_string() {
            None
        } else {
            Some(e.data_type.decode(data)?)
        };
        if let Some(v) = value {
            self.check_consistency(o, e, v)?;
            e.check_range(v)?;
            if let Some(list) = enumeration(o.info.index, e.sub) {
                if !list.contains(&v) {
                    return Err(SdoAbort::INVALID_VALUE);
                }
            }
        }
        if o.value == Value::Live {
            live.write(o.info.index, e.sub, data)?;
        }
        match (o.value, o.info.index) {
            (Value::Command, 0x1010) => self.requests.save = true,
            (Value::Command, _) => {
                self.restore_defaults();
                self.requests.defaults_restored = true;
            }
            _ => {
                self.store(target, data)?;
                self.side_effects(o.info.index, e.sub, value);
            }
        }
        Ok(())
    }

    /// Object-specific checks of a write of `v` to entry `e` of `o`, before
    /// the range check: PDO mapping (§5.3), PDO assignment, command
    /// signatures.
    fn check_consistency(&self, o: &Object, e: &EntryInfo, v: i64) -> Result<(), SdoAbort> {
        let index = o.info.index;
        match (index, o.value) {
            (0x1010, Value::Command) if v != i64::from(SAVE_SIGNATURE) => Err(SdoAbort::TRANSFER),
            (0x1011, Value::Command) if v != i64::from(LOAD_SIGNATURE) => Err(SdoAbort::TRANSFER),
            (0x1600..=0x1603 | 0x1A00..=0x1A03, _) => {
                let rx = index < 0x1A00;
                if e.sub == 0 {
                    // the count is checked against the entries (CiA 301 step d)
                    let n = u8::try_from(v).map_err(|_| SdoAbort::PDO_LENGTH)?;
                    if n > MAPPING_ENTRIES {
                        return Err(SdoAbort::PDO_LENGTH);
                    }
                    let mut bits = 0;
                    for s in 1..=n {
                        bits += self.mapped_bits(self.get(index, s)? as u32, rx)?;
                    }
                    if bits > MAX_PDO_BITS {
                        return Err(SdoAbort::PDO_LENGTH);
                    }
                    Ok(())
                } else if self.get(index, 0)? != 0 {
                    // entries change only while sub 0 = 0 (CiA 301 step b)
                    Err(SdoAbort::DEVICE_STATE)
                } else {
                    self.mapped_bits(v as u32, rx).map(|_| ())
                }
            }
            (0x1C12 | 0x1C13, _) => {
                let pdos = if index == 0x1C12 {
                    0x1600..=0x1603
                } else {
                    0x1A00..=0x1A03
                };
                if e.sub == 0 {
                    if v > 4 {
                        return Err(SdoAbort::VALUE_TOO_HIGH);
                    }
                    for s in 1..=(v as u8) {
                        let pdo = self.get(index, s)?;
                        let twice = (1..s).any(|t| self.get(index, t).ok() == Some(pdo));
                        if !pdos.contains(&pdo) || twice {
                            return Err(SdoAbort::PARAMETER_INCOMPATIBLE);
                        }
                    }
                    Ok(())
                } else if self.get(index, 0)? != 0 {
                    Err(SdoAbort::DEVICE_STATE)
                } else if v != 0 && !pdos.contains(&v) {
                    Err(SdoAbort::PARAMETER_INCOMPATIBLE)
                } else {
                    Ok(())
                }
            }
            _ => Ok(()),
        }
    }

    /// Bits of mapping entry `m` (index << 16 | sub << 8 | bits) in a PDO of
    /// direction `rx`: index 0 is a gap of `bits`; otherwise the entry must
    /// exist, be visible and mappable in that direction (0604 0041h) and
    /// have that bit length (0604 0043h).
    fn mapped_bits(&self, m: u32, rx: bool) -> Result<u32, SdoAbort> {
        let (index, sub, bits) = ((m >> 16) as u16, (m >> 8) as u8, m & 0xFF);
        if index == 0 {
            return Ok(bits);
        }
        let e = self
            .locate(index, sub)
            .and_then(Loc::entry)
            .map_err(|_| SdoAbort::NOT_MAPPABLE)?;
        let mappable = if rx {
            e.access.rx_mappable()
        } else {
            e.access.tx_mappable()
        };
        if !mappable {
            Err(SdoAbort::NOT_MAPPABLE)
        } else if u32::from(e.bit_len()) != bits {
            Err(SdoAbort::PARAMETER_INCOMPATIBLE)
        } else {
            Ok(bits)
        }
    }

    /// Actions started by a write: A00[0] = 1 save, A09[0] = 1 restart.
    fn side_effects(&mut self, index: u16, sub: u8, value: Option<i64>) {
        match (index, sub, value) {
            (0x2000, 1, Some(1)) => self.requests.save = true,
            (0x2009, 1, Some(1)) => self.requests.restart = true,
            _ => {}
        }
    }

    /// The byte ranges of the persistent values, in declaration order.
    fn persistent_slots() -> impl Iterator<Item = core::ops::Range<usize>> {
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
        let hash = objects::LAYOUT_HASH.to_le_bytes();
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
        if header.get(4..8) != Some(&objects::LAYOUT_HASH.to_le_bytes()[..]) {
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
        self.config_changed();
        Ok(())
    }

    /// Sets every persistent value back to its default in RAM (1011h, CiA
    /// 301 "restore default parameters"; the stored image changes with the
    /// next save). Live and set-point values are untouched.
    pub fn restore_defaults(&mut self) {
        for slot in Self::persistent_slots() {
            if let (Some(dst), Some(src)) = (self.image.get_mut(slot.clone()), INITIAL_IMAGE.get(slot)) {
                for (d, s) in dst.iter_mut().zip(src) {
                    *d = *s;
                }
            }
        }
        self.config_changed();
    }

    /// Puts `layout` into 1600h/1A00h (axis A), as a startup list in Pre-Op
    /// would: sub 0 = 0, the entries, sub 0 = n (CiA 301 order), through the
    /// same checks as a bus write. Takes effect at the next Pre-Op → Safe-Op.
    pub fn apply_map(&mut self, layout: crate::PdoLayout) -> Result<(), SdoAbort> {
        let (rx, tx) = layout.entries();
        for (pdo, entries) in [(0x1600u16, rx), (0x1A00, tx)] {
            self.write(pdo, 0, &[0], CommState::PreOp)?;
            for (sub, e) in (1u8..).zip(entries) {
                self.write(pdo, sub, &e.mapping_value().to_le_bytes(), CommState::PreOp)?;
            }
            let n = u8::try_from(entries.len()).map_err(|_| SdoAbort::PDO_LENGTH)?;
            self.write(pdo, 0, &[n], CommState::PreOp)?;
        }
        Ok(())
    }

    /// The PDOs assigned in `assign` (1C12h or 1C13h), in order.
    pub fn assigned_pdos(&self, assign: u16) -> impl Iterator<Item = u16> + '_ {
        let n = self.get(assign, 0).unwrap_or(0).clamp(0, 4) as u8;
        (1..=n).filter_map(move |s| self.get(assign, s).ok().map(|v| v as u16))
    }

    /// The mapping entries (index << 16 | sub << 8 | bits) of PDO `pdo`.
    pub fn mapping(&self, pdo: u16) -> impl Iterator<Item = u32> + '_ {
        let n = self.get(pdo, 0).unwrap_or(0).clamp(0, i64::from(MAPPING_ENTRIES)) as u8;
        (1..=n).filter_map(move |s| self.get(pdo, s).ok().map(|v| v as u32))
    }

    fn sm_bytes(&self, assign: u16) -> usize {
        let bits: u32 = self
            .assigned_pdos(assign)
            .flat_map(|pdo| self.mapping(pdo))
            .map(|m| m & 0xFF)
            .sum();
        (bits as usize).div_ceil(8)
    }

    fn object_info(&self, o: &'static Object) -> Option<&'static ObjectInfo> {
        self.visible(o).then(|| o.view(self.sdo_info()))
    }
}

impl Dictionary for DriveObjects {
    fn object(&self, index: u16) -> Option<&'static ObjectInfo> {
        find(index).and_then(|(_, o)| self.object_info(o))
    }

    fn next_object(&self, after: Option<u16>) -> Option<&'static ObjectInfo> {
        let start = after.map_or(0, |a| OBJECTS.partition_point(|o| o.info.index <= a));
        OBJECTS.get(start..)?.iter().find_map(|o| self.object_info(o))
    }

    fn read(&mut self, index: u16, sub: u8, buf: &mut [u8], _state: CommState) -> Result<usize, SdoAbort> {
        self.read_with(&mut NoLive, index, sub, buf)
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8], state: CommState) -> Result<(), SdoAbort> {
        self.write_with(&mut NoLive, index, sub, data, state)
    }

    fn process_data_bytes(&self) -> Option<(usize, usize)> {
        let generation = self.config_generation;
        let bytes = match self.pdo_bytes.get() {
            Some((g, bytes)) if g == generation => bytes,
            _ => {
                let bytes = (self.sm_bytes(0x1C12), self.sm_bytes(0x1C13));
                self.pdo_bytes.set(Some((generation, bytes)));
                bytes
            }
        };
        Some(bytes)
    }

    fn sdo_info_enabled(&self) -> bool {
        self.sdo_info()
    }
}

impl<L: LiveValues> Dictionary for WithLive<'_, L> {
    fn object(&self, index: u16) -> Option<&'static ObjectInfo> {
        self.objects.object(index)
    }

    fn next_object(&self, after: Option<u16>) -> Option<&'static ObjectInfo> {
        self.objects.next_object(after)
    }

    fn read(&mut self, index: u16, sub: u8, buf: &mut [u8], _state: CommState) -> Result<usize, SdoAbort> {
        self.objects.read_with(self.live, index, sub, buf)
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8], state: CommState) -> Result<(), SdoAbort> {
        self.objects.write_with(self.live, index, sub, data, state)
    }

    fn process_data_bytes(&self) -> Option<(usize, usize)> {
        self.objects.process_data_bytes()
    }

    fn sdo_info_enabled(&self) -> bool {
        self.objects.sdo_info_enabled()
    }
}
