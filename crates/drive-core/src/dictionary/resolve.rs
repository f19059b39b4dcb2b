//! Where an entry lives: the resolution of (index, subindex) to its object,
//! entry and place in the RAM image (`Loc`, `Resolved`), and the
//! process-global cache of resolutions the control cycle's lookups hit.

use super::*;

/// An entry: object position in [`OBJECTS`], entry position in its
/// "EtherCAT Rx SDO Info" entries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Loc {
    pub(super) obj: usize,
    pub(super) pos: usize,
}

impl Loc {
    pub(super) fn object(self) -> Result<&'static Object, SdoAbort> {
        OBJECTS.get(self.obj).ok_or(SdoAbort::NO_OBJECT)
    }

    pub(super) fn entry(self) -> Result<EntryInfo, SdoAbort> {
        self.object()?
            .info
            .entries
            .get(self.pos)
            .ok_or(SdoAbort::NO_SUBINDEX)
    }

    /// The entry's data type (from its record, not decoded).
    pub(super) fn data_type(self) -> Result<DataType, SdoAbort> {
        self.object()?
            .info
            .entries
            .data_type(self.pos)
            .ok_or(SdoAbort::NO_SUBINDEX)
    }

    /// The entry's packed record in [`crate::objects::ENTRY_TABLE`].
    pub(super) fn record(self) -> Result<crate::objects::EntryRecord, SdoAbort> {
        self.object()?
            .info
            .entries
            .record(self.pos)
            .map(crate::objects::EntryRecord::of)
            .ok_or(SdoAbort::NO_SUBINDEX)
    }

    /// Byte range of the entry in the RAM image.
    pub(super) fn slot(self) -> Result<core::ops::Range<usize>, SdoAbort> {
        let o = self.object()?;
        let base = usize::from(*OFFSETS.get(self.obj).ok_or(SdoAbort::NO_OBJECT)?);
        let entries = o.info.entries;
        let before: usize = (0..self.pos)
            .filter_map(|k| entries.data_type(k))
            .map(DataType::bytes)
            .sum();
        let at = base + before;
        Ok(at..at + self.data_type()?.bytes())
    }
}

/// The entry `index`:`sub` in "EtherCAT Rx SDO Info" numbering, visible or not.
pub(super) fn canonical(index: u16, sub: u8) -> Result<Loc, SdoAbort> {
    let (obj, o) = find(index).ok_or(SdoAbort::NO_OBJECT)?;
    let pos = o.info.entries.position(sub).ok_or(SdoAbort::NO_SUBINDEX)?;
    Ok(Loc { obj, pos })
}

/// Where the value of `loc` lives: the entry itself or, for mirrors and
/// aliases, the target entry.
pub(super) fn follow(loc: Loc) -> Result<Loc, SdoAbort> {
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
pub(super) fn in_ram(loc: Loc) -> Result<bool, SdoAbort> {
    Ok(matches!(loc.object()?.value, Value::Ram | Value::Live))
}

pub(super) fn put(buf: &mut [u8], data: &[u8]) -> Result<usize, SdoAbort> {
    buf.get_mut(..data.len())
        .ok_or(SdoAbort::OUT_OF_MEMORY)?
        .copy_from_slice(data);
    Ok(data.len())
}

/// Where an integer/REAL32 entry's value lives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Place {
    /// A slot in the RAM image starting at this byte.
    Ram(u16),
    /// A constant (the declared default as its type reads it), ≤ 32 bits.
    Const(i64),
}

/// What [`DriveObjects::get`] and [`DriveObjects::set`] resolve
/// `index`:`sub` to (aliases and mirrors followed). Depends only on the
/// declaration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Resolved {
    /// `index << 8 | sub` of the request (24 bits).
    pub(super) key: u32,
    pub(super) place: Place,
    /// The entry's type (its width is the slot's).
    pub(super) data_type: DataType,
    /// A write to it is a configuration change ([`is_config`]).
    pub(super) config: bool,
}

/// The scalar types a cache slot can hold, by code (0 = empty slot).
pub(super) const CACHED_TYPES: [DataType; 10] = [
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
pub(super) const CONST_FLAG: u32 = 0x80;

/// Type-code flag of a configuration entry.
pub(super) const CONFIG_FLAG: u32 = 0x40;

/// Set-points the control cycle reads every cycle and the process outputs
/// a master writes every cycle (axis-A indices; axis B at +800h / +8000h):
/// writes to them are not configuration changes.
pub(super) const CYCLIC_SETPOINTS: [u16; 15] = [
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
    // digital outputs (standard RxPDO, C-130): a process output, which no
    // snapshot reads; as configuration, a master changing them every frame
    // would reconfigure both axes every cycle (issue 36)
    0x60FE,
    // the record window, start number and override (written cyclically by
    // a telegram; the axis reads them at a start, not every cycle)
    crate::objects::records::J401,
    crate::objects::records::J402,
    crate::objects::records::J403,
];

/// Whether a changed value of object `o` is a configuration change
/// ([`DriveObjects::config_generation`]): RAM values (parameters and
/// set-points) except the cyclic set-points; live values (actual values,
/// diagnosis, fed by the runtime) never are.
pub(super) fn is_config(o: &Object) -> bool {
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
    pub(super) fn pack(self) -> Option<(u32, u32)> {
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

    pub(super) fn unpack(key: u32, word: u32, value: u32) -> Option<Self> {
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
pub(super) const CACHE_SLOTS: usize = 512;

/// Probes before a lookup gives up on the cache (the entry is then resolved
/// without being cached).
pub(super) const MAX_PROBES: usize = 16;

/// A slot being filled.
pub(super) const BUSY: u32 = u32::MAX;

pub(super) static CACHE_KEYS: [AtomicU32; CACHE_SLOTS] = [const { AtomicU32::new(0) }; CACHE_SLOTS];

pub(super) static CACHE_AT: [AtomicU32; CACHE_SLOTS] = [const { AtomicU32::new(0) }; CACHE_SLOTS];

/// The home slot of `key` (multiplicative hash, top 9 bits).
pub(super) fn home_slot(key: u32) -> usize {
    (key.wrapping_mul(0x9E37_79B1) >> 23) as usize % CACHE_SLOTS
}

/// Where integer/REAL32 entry `index`:`sub` ("EtherCAT Rx SDO Info"
/// numbering, aliases followed) lives, from the cache or resolved and
/// cached; `None` for entries that are neither in RAM nor constant.
pub(super) fn resolve(index: u16, sub: u8) -> Option<Resolved> {
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

/// The value of a cached entry straight from its two packed words (what
/// [`Resolved::unpack`] and [`load`] answer together, without building the
/// [`Resolved`]): `None` when the words do not unpack.
#[inline(always)]
pub(super) fn load_packed(image: &[u8], word: u32, value: u32) -> Option<Result<i64, SdoAbort>> {
    let code = (word & 0x3F) as usize;
    if word & CONST_FLAG != 0 {
        let t = *CACHED_TYPES.get(code.checked_sub(1)?)?;
        return Some(Ok(match t {
            DataType::I8 | DataType::I16 | DataType::I32 => i64::from(value as i32),
            _ => i64::from(value),
        }));
    }
    let at = usize::from(u16::try_from(value).ok()?);
    // the codes are the positions in `CACHED_TYPES` + 1
    // (`packed_loads_answer_as_unpack_and_load` meets each in RAM)
    let v = match code {
        1 | 5 => bytes_at::<1>(image, at).map(|[b]| i64::from(b)),
        2 => bytes_at::<1>(image, at).map(|[b]| i64::from(b as i8)),
        3 => bytes_at(image, at).map(|b| i64::from(i16::from_le_bytes(b))),
        4 => bytes_at(image, at).map(|b| i64::from(i32::from_le_bytes(b))),
        6 => bytes_at(image, at).map(|b| i64::from(u16::from_le_bytes(b))),
        7 => bytes_at(image, at).map(|b| i64::from(u32::from_le_bytes(b))),
        _ => return Some(load(image, at, *CACHED_TYPES.get(code.checked_sub(1)?)?)),
    };
    Some(v.ok_or(SdoAbort::GENERAL))
}

/// [`DriveObjects::set`] of a cached RAM integer of up to 32 bits (type
/// codes 1…7) from its packed words: its range check and store, answering
/// whether a configuration entry changed; `None` for the other entries
/// (the general path).
#[inline(always)]
pub(super) fn store_packed(
    image: &mut [u8],
    word: u32,
    at: u32,
    value: i64,
) -> Option<Result<bool, SdoAbort>> {
    if word & CONST_FLAG != 0 {
        return None;
    }
    // (min, max, bytes) of Bool, I8, I16, I32, U8, U16, U32
    let (min, max, n) = match word & 0x3F {
        1 => (0, 1, 1),
        2 => (i64::from(i8::MIN), i64::from(i8::MAX), 1),
        3 => (i64::from(i16::MIN), i64::from(i16::MAX), 2),
        4 => (i64::from(i32::MIN), i64::from(i32::MAX), 4),
        5 => (0, i64::from(u8::MAX), 1),
        6 => (0, i64::from(u16::MAX), 2),
        7 => (0, i64::from(u32::MAX), 4),
        _ => return None,
    };
    if value < min {
        return Some(Err(SdoAbort::VALUE_TOO_LOW));
    }
    if value > max {
        return Some(Err(SdoAbort::VALUE_TOO_HIGH));
    }
    let at = usize::from(u16::try_from(at).ok()?);
    let [b0, b1, b2, b3, ..] = value.to_le_bytes();
    let changed = match n {
        1 => put_if_changed(image, at, [b0]),
        2 => put_if_changed(image, at, [b0, b1]),
        _ => put_if_changed(image, at, [b0, b1, b2, b3]),
    };
    Some(
        changed
            .map(|c| c && word & CONFIG_FLAG != 0)
            .ok_or(SdoAbort::GENERAL),
    )
}

/// Writes `new` at `at` when it differs from the bytes there; whether it
/// did, `None` outside `image`.
#[inline(always)]
fn put_if_changed<const N: usize>(image: &mut [u8], at: usize, new: [u8; N]) -> Option<bool> {
    let old = <&mut [u8; N]>::try_from(image.get_mut(at..at + N)?).ok()?;
    let changed = *old != new;
    *old = new;
    Some(changed)
}

/// The packed words of `index`:`sub` when the cache holds them (no
/// insertion: a miss is [`resolve`]'s).
#[inline(always)]
pub(super) fn cached(index: u16, sub: u8) -> Option<(u32, u32)> {
    let key = (u32::from(index) << 8) | u32::from(sub);
    let mut at = home_slot(key);
    for _ in 0..MAX_PROBES {
        let (k, a) = (CACHE_KEYS.get(at)?, CACHE_AT.get(at)?);
        match k.load(Ordering::Acquire) {
            0 | BUSY => return None,
            word if word >> 8 == key => return Some((word, a.load(Ordering::Relaxed))),
            _ => at = (at + 1) % CACHE_SLOTS,
        }
    }
    None
}

/// Resolves `key` from the declaration: `None` for entries that are not
/// an integer/REAL32 in RAM or a constant (strings, 1018h, commands, unknown).
pub(super) fn lookup(key: u32) -> Option<Resolved> {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Every cached RAM integer stores from its packed words as the general
    /// path of [`DriveObjects::set`] does: the same answer, image and
    /// configuration generations, for values in, at and beyond its range.
    #[test]
    fn packed_stores_answer_as_the_general_set() {
        let base = DriveObjects::new();
        let mut checked = 0;
        for o in OBJECTS {
            for sub in 0..=u8::MAX {
                let key = (u32::from(o.info.index) << 8) | u32::from(sub);
                let Some((word, at)) = lookup(key).and_then(Resolved::pack) else {
                    continue;
                };
                for value in [
                    0,
                    1,
                    -1,
                    127,
                    128,
                    -129,
                    255,
                    256,
                    65_535,
                    65_536,
                    -32_769,
                    i64::from(u32::MAX),
                    1 << 32,
                    i64::MIN,
                ] {
                    let mut fast = base.clone();
                    let mut general = base.clone();
                    let Some(r) = store_packed(&mut fast.image, word, at, value) else {
                        continue;
                    };
                    let r = r.map(|config| {
                        if config {
                            fast.config_changed_at(o.info.index);
                        }
                    });
                    assert_eq!(
                        r,
                        general.set_general(o.info.index, sub, value),
                        "{key:06X} {value}"
                    );
                    assert!(fast == general, "{key:06X} {value}");
                    assert_eq!(fast.config_generation(), general.config_generation());
                    assert_eq!(
                        [fast.axis_config_generation(0), fast.axis_config_generation(1)],
                        [
                            general.axis_config_generation(0),
                            general.axis_config_generation(1)
                        ]
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 5000, "{checked}");
    }

    /// Every cacheable entry of the declaration loads from its packed words
    /// as its unpacked resolution does (RAM values over varied bytes,
    /// constants of every type and sign).
    #[test]
    fn packed_loads_answer_as_unpack_and_load() {
        let mut od = DriveObjects::new();
        for (i, b) in od.image.iter_mut().enumerate() {
            *b = (i as u8).wrapping_mul(37) ^ 0xA5;
        }
        let (mut checked, mut ram_codes) = (0, 0u64);
        for o in OBJECTS {
            for sub in 0..=u8::MAX {
                let key = (u32::from(o.info.index) << 8) | u32::from(sub);
                let Some((word, value)) = lookup(key).and_then(Resolved::pack) else {
                    continue;
                };
                let unpacked = Resolved::unpack(key, word, value).map(|r| match r.place {
                    Place::Ram(at) => load(&od.image, usize::from(at), r.data_type),
                    Place::Const(v) => Ok(v),
                });
                assert_eq!(load_packed(&od.image, word, value), unpacked, "{key:06X}");
                checked += 1;
                if word & CONST_FLAG == 0 {
                    ram_codes |= 1 << (word & 0x3F);
                }
            }
        }
        assert!(checked > 500, "{checked}");
        // every code `load_packed` matches on literally (Bool … U32, the
        // positions in CACHED_TYPES + 1) met in RAM: a reordered table
        // fails here, with the entry's key
        assert_eq!(ram_codes & 0xFE, 0xFE, "RAM type codes met: {ram_codes:#b}");
    }
}
