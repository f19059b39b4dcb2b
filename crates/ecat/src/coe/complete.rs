//! SDO complete access (command bit 4; E-078, spec §6.1, a design decision).
//!
//! Only ARRAY and RECORD objects with metadata ([`Dictionary::object`]); a VAR,
//! an object without metadata, or a subindex other than 0 or 1 is refused with
//! 0601 0000h.
//!
//! Layout (ETG.1000.6): starting at subindex 0, the value of subindex 0 comes
//! first and occupies 16 bits (UINT8 + one padding byte); then entries
//! 1..=n follow in subindex order, each with its full byte size (strings with
//! their declared length, zero-padded). Starting at subindex 1, subindex 0 is
//! left out. Entries are byte-aligned: a BOOLEAN takes one byte (bit packing of
//! BOOLEAN/BITn entries is not supported). Subindices without an entry (gaps in
//! a RECORD) take no bytes.
//!
//! Upload: n = the present value of subindex 0 (at most the object's
//! capacity). Download from subindex 0: n = the first byte; download from
//! subindex 1: as many entries as the data holds.
//!
//! Download order (CiA 301 for mapping/assignment objects): when subindex 0 is
//! writable, it is written to 0 first, then entries 1..=n, then subindex 0 to
//! n, whether the download starts at subindex 0 or at subindex 1 (then n is
//! the number of entries the data holds). Before anything is written the whole
//! value is checked: length, access rights in the present state, and the
//! integer ranges of the metadata. A refusal by the dictionary after that
//! (e.g. a PDO-mapping consistency check) aborts with its code, and the
//! entries written until then and subindex 0 get their old values back, so
//! the object reads as before (up to 128 bytes of entries: every mapping and
//! assignment object; a bigger one keeps what was written).

use od::{CommState, DataType, Dictionary, EntryInfo, ObjectCode, ObjectInfo, SdoAbort};

/// Bytes subindex 0 occupies in a complete access from subindex 0.
pub const SUB0_BYTES: usize = 2;

/// The object `index` if complete access to it from `sub` is possible.
pub fn object<D: Dictionary>(dict: &D, index: u16, sub: u8) -> Result<&'static ObjectInfo, SdoAbort> {
    let info = dict.object(index).ok_or(SdoAbort::UNSUPPORTED_ACCESS)?;
    match info.code {
        ObjectCode::Array | ObjectCode::Record if sub <= 1 => Ok(info),
        _ => Err(SdoAbort::UNSUPPORTED_ACCESS),
    }
}

/// Highest subindex the object can have. An ARRAY may be declared with one
/// entry standing for all elements (sub 1); its capacity is then the `max` of
/// subindex 0 (or its default).
pub fn capacity(info: &ObjectInfo) -> u8 {
    let declared = info.max_sub();
    if info.code != ObjectCode::Array {
        return declared;
    }
    let sub0 = info.entry(0).map_or(0, |e| e.max.unwrap_or(e.default));
    declared.max(u8::try_from(sub0.clamp(0, 255)).unwrap_or(u8::MAX))
}

/// The metadata of entry `sub` (an ARRAY's element template for elements
/// without an entry of their own).
pub fn element(info: &ObjectInfo, sub: u8) -> Option<EntryInfo> {
    if let Some(e) = info.entry(sub) {
        return Some(e);
    }
    if info.code == ObjectCode::Array && sub >= 1 && sub <= capacity(info) {
        return info.entries.iter().rev().find(|e| e.sub >= 1);
    }
    None
}

/// Reads the whole object into `buf`; returns the byte count.
pub fn upload<D: Dictionary>(
    dict: &mut D,
    index: u16,
    sub: u8,
    buf: &mut [u8],
    state: CommState,
) -> Result<usize, SdoAbort> {
    let info = object(dict, index, sub)?;
    let count = sub0_value(dict, index, state)?.min(capacity(info));
    let mut pos = 0;
    if sub == 0 {
        let dst = buf.get_mut(..SUB0_BYTES).ok_or(SdoAbort::OUT_OF_MEMORY)?;
        dst.copy_from_slice(&[count, 0]);
        pos = SUB0_BYTES;
    }
    for s in 1..=count {
        let Some(entry) = element(info, s) else {
            continue;
        };
        let size = entry.data_type.bytes();
        let end = pos.checked_add(size).ok_or(SdoAbort::OUT_OF_MEMORY)?;
        let dst = buf.get_mut(pos..end).ok_or(SdoAbort::OUT_OF_MEMORY)?;
        let n = dict.read(index, s, dst, state)?;
        // shorter strings are zero-padded to the declared length
        if let Some(rest) = dst.get_mut(n.min(size)..) {
            rest.fill(0);
        }
        pos = end;
    }
    Ok(pos)
}

/// Writes the whole object from `data` (see the module documentation).
pub fn download<D: Dictionary>(
    dict: &mut D,
    index: u16,
    sub: u8,
    data: &[u8],
    state: CommState,
) -> Result<(), SdoAbort> {
    let info = object(dict, index, sub)?;
    let cap = capacity(info);
    let bit = state.access_bit();
    let sub0 = info.entry(0);
    let sub0_writable = sub0.is_some_and(|e| e.access.writable_in(bit));
    let (count, body) = if sub == 0 {
        let (&count, rest) = data.split_first().ok_or(SdoAbort::LENGTH_TOO_LOW)?;
        let body = rest.get(SUB0_BYTES - 1..).ok_or(SdoAbort::LENGTH_TOO_LOW)?;
        if count > cap {
            return Err(SdoAbort::VALUE_TOO_HIGH);
        }
        if let Some(e) = sub0 {
            check_range(&e, &[count])?;
        }
        if !sub0_writable && count != sub0_value(dict, index, state)? {
            return Err(SdoAbort::READ_ONLY);
        }
        (count, body)
    } else {
        (entries_in(info, data.len())?, data)
    };
    // check everything before the first write
    let mut pos = 0usize;
    for s in 1..=count {
        let Some(entry) = element(info, s) else {
            continue;
        };
        let end = pos.saturating_add(entry.data_type.bytes());
        let value = body.get(pos..end).ok_or(SdoAbort::LENGTH_TOO_LOW)?;
        if !entry.access.writable_in(bit) {
            return Err(if entry.access.writable() {
                SdoAbort::DEVICE_STATE
            } else {
                SdoAbort::READ_ONLY
            });
        }
        check_range(&entry, value)?;
        pos = end;
    }
    if pos != body.len() {
        return Err(SdoAbort::LENGTH_TOO_HIGH);
    }
    // from subindex 1 too (ethercrab's complete access starts there): the
    // entries of a mapping/assignment object change only while sub 0 = 0
    let order_sub0 = sub0_writable;
    let mut undo = Undo::new(if order_sub0 {
        sub0_value(dict, index, state)?
    } else {
        0
    });
    if order_sub0 {
        dict.write(index, 0, &[0], state)?;
    }
    let mut pos = 0usize;
    let mut result = Ok(());
    for s in 1..=count {
        let Some(entry) = element(info, s) else {
            continue;
        };
        let end = pos.saturating_add(entry.data_type.bytes());
        undo.keep(dict, index, s, entry.data_type.bytes(), state);
        result = dict.write(index, s, body.get(pos..end).unwrap_or_default(), state);
        if result.is_err() {
            break;
        }
        pos = end;
    }
    if result.is_ok() && order_sub0 {
        result = dict.write(index, 0, &[count], state);
    }
    if result.is_err() {
        undo.restore(dict, info, order_sub0, state);
    }
    result
}

/// Entry bytes a refused complete download puts back (a PDO mapping object
/// holds 24 × 4).
const UNDO_BYTES: usize = 128;

/// The values a complete download overwrote, to put back when the
/// dictionary refuses a later entry or the final subindex 0 (the object
/// then reads as before; bus input that is refused changes nothing).
struct Undo {
    bytes: [u8; UNDO_BYTES],
    len: usize,
    /// Entries 1..=`upto` are kept, in subindex order.
    upto: u8,
    sub0: u8,
    /// An entry did not fit or did not read: nothing is put back.
    lost: bool,
}

impl Undo {
    fn new(sub0: u8) -> Self {
        Self {
            bytes: [0; UNDO_BYTES],
            len: 0,
            upto: 0,
            sub0,
            lost: false,
        }
    }

    /// Keeps the present value of `index`:`sub` (`size` bytes) before it is
    /// written.
    fn keep<D: Dictionary>(&mut self, dict: &mut D, index: u16, sub: u8, size: usize, state: CommState) {
        let end = self.len.saturating_add(size);
        let Some(dst) = self.bytes.get_mut(self.len..end) else {
            self.lost = true;
            return;
        };
        match dict.read(index, sub, dst, state) {
            Ok(n) if n == size => {
                self.len = end;
                self.upto = sub;
            }
            _ => self.lost = true,
        }
    }

    /// Writes the kept values back (sub 0 = 0 still set when `order_sub0`),
    /// then the old subindex 0.
    fn restore<D: Dictionary>(&self, dict: &mut D, info: &ObjectInfo, order_sub0: bool, state: CommState) {
        if self.lost {
            return;
        }
        let index = info.index;
        let mut pos = 0usize;
        for s in 1..=self.upto {
            let Some(entry) = element(info, s) else {
                continue;
            };
            let end = pos.saturating_add(entry.data_type.bytes());
            if let Some(v) = self.bytes.get(pos..end) {
                let _ = dict.write(index, s, v, state);
            }
            pos = end;
        }
        if order_sub0 {
            let _ = dict.write(index, 0, &[self.sub0], state);
        }
    }
}

/// The present value of subindex 0 (0 when it reads as nothing).
fn sub0_value<D: Dictionary>(dict: &mut D, index: u16, state: CommState) -> Result<u8, SdoAbort> {
    let mut b = [0u8; 8];
    let n = dict.read(index, 0, &mut b, state)?;
    Ok(if n == 0 {
        0
    } else {
        b.first().copied().unwrap_or(0)
    })
}

/// How many entries from subindex 1 `len` bytes hold exactly.
fn entries_in(info: &ObjectInfo, len: usize) -> Result<u8, SdoAbort> {
    let mut pos = 0usize;
    let mut count = 0u8;
    for s in 1..=capacity(info) {
        if pos == len {
            return Ok(count);
        }
        if let Some(entry) = element(info, s) {
            pos = pos.saturating_add(entry.data_type.bytes());
            if pos > len {
                return Err(SdoAbort::TYPE_MISMATCH);
            }
        }
        count = s;
    }
    if pos == len {
        Ok(count)
    } else {
        Err(SdoAbort::LENGTH_TOO_HIGH)
    }
}

/// Checks an integer value against the entry's `min`/`max`.
fn check_range(entry: &EntryInfo, value: &[u8]) -> Result<(), SdoAbort> {
    let signed = entry.data_type.signed();
    let integer = matches!(
        entry.data_type,
        DataType::I8
            | DataType::I16
            | DataType::I32
            | DataType::I64
            | DataType::U8
            | DataType::U16
            | DataType::U32
            | DataType::U64
    );
    if !integer || value.is_empty() || value.len() > 8 {
        return Ok(());
    }
    let mut b = [0u8; 8];
    if let Some(dst) = b.get_mut(..value.len()) {
        dst.copy_from_slice(value);
    }
    let v = if signed {
        let shift = 64 - 8 * value.len() as u32;
        (i64::from_le_bytes(b) << shift) >> shift
    } else {
        i64::try_from(u64::from_le_bytes(b)).unwrap_or(i64::MAX)
    };
    if entry.min.is_some_and(|m| v < m) {
        return Err(SdoAbort::VALUE_TOO_LOW);
    }
    if entry.max.is_some_and(|m| v > m) {
        return Err(SdoAbort::VALUE_TOO_HIGH);
    }
    Ok(())
}
