//! SDO Information service (CoE service 8; ETG.1000.6 §5.6.3, spec §7).
//!
//! Frame after the CoE header: opcode byte (bits 0..6 opcode, bit 7
//! incomplete), reserved byte, fragments left (u16), then the service data.
//!
//! - Get OD List (1 → 2): list type u16, then u16 indices; list type 0 answers
//!   the five list lengths. A list that does not fit one mailbox is sent in
//!   fragments: all but the last have the incomplete bit set, and fragments-left
//!   counts down to 0; only the first carries the list type. The remaining
//!   fragments are produced by [`crate::coe::CoeServer::next_fragment`], one per
//!   free send mailbox; any new CoE request ends the list.
//! - Get Object Description (3 → 4): index, data type, max subindex, object
//!   code, name.
//! - Get Entry Description (5 → 6): index, subindex, value info, data type, bit
//!   length, object access ([`od::Access`] bits), the default/minimum/maximum
//!   values when asked for and known (integers), name. The unit type is not
//!   supplied.
//! - SDO Info Error (7): abort code u32 (0602 0000h unknown object, 0609 0011h
//!   unknown subindex).
//!
//! Names longer than the mailbox are cut to fit.

use crate::coe::{complete, service, Writer, COE_HEADER_LEN};
use crate::mailbox::MailboxError;
use od::{DataType, Dictionary, EntryInfo, ObjectCode, ObjectInfo, SdoAbort};

/// Length of the SDO Info header (opcode, reserved, fragments left).
pub const INFO_HEADER_LEN: usize = 4;

/// SDO Info opcodes.
pub mod opcode {
    /// Get OD List request.
    pub const OD_LIST_REQ: u8 = 1;
    /// Get OD List response.
    pub const OD_LIST_RESP: u8 = 2;
    /// Get Object Description request.
    pub const OBJECT_DESC_REQ: u8 = 3;
    /// Get Object Description response.
    pub const OBJECT_DESC_RESP: u8 = 4;
    /// Get Entry Description request.
    pub const ENTRY_DESC_REQ: u8 = 5;
    /// Get Entry Description response.
    pub const ENTRY_DESC_RESP: u8 = 6;
    /// SDO Info Error request.
    pub const ERROR: u8 = 7;
    /// Incomplete flag (more fragments follow).
    pub const INCOMPLETE: u8 = 0x80;
}

/// OD list types.
pub mod list_type {
    /// The lengths of the five lists.
    pub const LENGTHS: u16 = 0;
    /// All objects.
    pub const ALL: u16 = 1;
    /// Objects with an RxPDO-mappable entry.
    pub const RXPDO: u16 = 2;
    /// Objects with a TxPDO-mappable entry.
    pub const TXPDO: u16 = 3;
    /// Backup objects (not supported: empty, spec §7).
    pub const BACKUP: u16 = 4;
    /// Settings objects (not supported: empty, spec §7).
    pub const SETTINGS: u16 = 5;
}

/// Value info bits of an entry description (ETG.1000.6).
pub mod value_info {
    /// Access rights supplied (always).
    pub const ACCESS: u8 = 0x01;
    /// Object category supplied (always).
    pub const OBJECT: u8 = 0x02;
    /// PDO mapping supplied (always).
    pub const MAPPABLE: u8 = 0x04;
    /// Unit type (not supplied).
    pub const UNIT: u8 = 0x08;
    /// Default value.
    pub const DEFAULT: u8 = 0x10;
    /// Minimum value.
    pub const MIN: u8 = 0x20;
    /// Maximum value.
    pub const MAX: u8 = 0x40;
}

/// A parsed SDO Info request (the bytes after the CoE header).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InfoRequest {
    /// Get OD List.
    OdList {
        /// List type (see [`list_type`]).
        list_type: u16,
    },
    /// Get Object Description.
    ObjectDescription {
        /// Index.
        index: u16,
    },
    /// Get Entry Description.
    EntryDescription {
        /// Index.
        index: u16,
        /// Subindex.
        sub: u8,
        /// Requested value info (see [`value_info`]).
        value_info: u8,
    },
    /// Another opcode (answered with an SDO Info error 0504 0001h).
    Other {
        /// The opcode (bits 0..6).
        opcode: u8,
    },
}

impl InfoRequest {
    /// Parses `body` (the bytes after the CoE header); `None` when too short
    /// for its opcode.
    pub fn parse(body: &[u8]) -> Option<Self> {
        let (&op, _) = body.split_first()?;
        let data = body.get(INFO_HEADER_LEN..)?;
        let u16_at = |i: usize| match data.get(i..i + 2)? {
            &[a, b] => Some(u16::from_le_bytes([a, b])),
            _ => None,
        };
        Some(match op & 0x7F {
            opcode::OD_LIST_REQ => InfoRequest::OdList {
                list_type: u16_at(0)?,
            },
            opcode::OBJECT_DESC_REQ => InfoRequest::ObjectDescription { index: u16_at(0)? },
            opcode::ENTRY_DESC_REQ => InfoRequest::EntryDescription {
                index: u16_at(0)?,
                sub: *data.get(2)?,
                value_info: data.get(3).copied().unwrap_or(0),
            },
            opcode => InfoRequest::Other { opcode },
        })
    }
}

/// An OD list being sent in fragments.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OdListCursor {
    list_type: u16,
    /// Last index sent (`None`: none yet).
    after: Option<u16>,
    /// Fragments still to send after the next one.
    fragments_left: u16,
    /// The next fragment is the first (carries the list type).
    first: bool,
}

/// Handles one SDO Info request; the reply goes to `out`.
pub(crate) fn handle<D: Dictionary>(
    body: &[u8],
    out: &mut [u8],
    dict: &mut D,
    cursor: &mut Option<OdListCursor>,
) -> Result<Option<usize>, MailboxError> {
    *cursor = None;
    let request = InfoRequest::parse(body).ok_or(MailboxError::SIZE_TOO_SHORT)?;
    let reply = match request {
        InfoRequest::OdList {
            list_type: list_type::LENGTHS,
        } => lengths(out, dict),
        InfoRequest::OdList { list_type } if list_type <= list_type::SETTINGS => {
            let payload = frag_payload(out.len());
            if payload == 0 {
                return Err(MailboxError::NO_MORE_MEMORY);
            }
            let bytes = 2 + 2 * usize::from(count(dict, list_type));
            let fragments = bytes.div_ceil(payload);
            let mut c = OdListCursor {
                list_type,
                after: None,
                fragments_left: u16::try_from(fragments.saturating_sub(1)).unwrap_or(u16::MAX),
                first: true,
            };
            let n = od_list_fragment(out, dict, &mut c);
            if n.is_some() && c.fragments_left > 0 {
                c.fragments_left -= 1;
                *cursor = Some(c);
            }
            n.ok_or(SdoAbort::OUT_OF_MEMORY)
        }
        InfoRequest::OdList { .. } => Err(SdoAbort::GENERAL),
        InfoRequest::ObjectDescription { index } => object_description(out, dict, index),
        InfoRequest::EntryDescription {
            index,
            sub,
            value_info,
        } => entry_description(out, dict, index, sub, value_info),
        InfoRequest::Other { .. } => Err(SdoAbort::INVALID_COMMAND),
    };
    match reply {
        Ok(n) => Ok(Some(n)),
        Err(code) => error_frame(out, code)
            .map(Some)
            .ok_or(MailboxError::NO_MORE_MEMORY),
    }
}

/// The next fragment of the list in `cursor`, if any.
pub(crate) fn next_fragment<D: Dictionary>(
    out: &mut [u8],
    dict: &mut D,
    cursor: &mut Option<OdListCursor>,
) -> Option<usize> {
    let mut c = cursor.take()?;
    let n = od_list_fragment(out, dict, &mut c)?;
    if c.fragments_left > 0 {
        c.fragments_left -= 1;
        *cursor = Some(c);
    }
    Some(n)
}

/// Bytes of list data one fragment carries (even).
fn frag_payload(out_len: usize) -> usize {
    out_len.saturating_sub(COE_HEADER_LEN + INFO_HEADER_LEN) & !1
}

fn info_header(w: &mut Writer<'_>, op: u8, fragments_left: u16) -> Option<()> {
    w.coe_header(service::SDO_INFO)?;
    w.u8(if fragments_left > 0 {
        op | opcode::INCOMPLETE
    } else {
        op
    })?;
    w.u8(0)?;
    w.u16(fragments_left)
}

fn error_frame(out: &mut [u8], code: SdoAbort) -> Option<usize> {
    let mut w = Writer::new(out);
    info_header(&mut w, opcode::ERROR, 0)?;
    w.u32(code.0)?;
    Some(w.len())
}

/// Does `info` belong to list `list_type`? (Reads the entries' access
/// only: a list walks the whole dictionary, once per fragment and five
/// times for the list lengths.)
fn listed(info: &ObjectInfo, list_type: u16) -> bool {
    let any = |f: fn(od::Access) -> bool| {
        (0..info.entries.len()).any(|pos| info.entries.access(pos).is_some_and(f))
    };
    match list_type {
        list_type::ALL => true,
        list_type::RXPDO => any(od::Access::rx_mappable),
        list_type::TXPDO => any(od::Access::tx_mappable),
        _ => false,
    }
}

/// The next object of the list after `after` (indices strictly increase, so a
/// misbehaving dictionary cannot loop).
fn next_listed<D: Dictionary>(dict: &D, list_type: u16, mut after: Option<u16>) -> Option<u16> {
    if matches!(list_type, list_type::BACKUP | list_type::SETTINGS) {
        return None;
    }
    loop {
        let o = dict.next_object(after)?;
        if after.is_some_and(|a| o.index <= a) {
            return None;
        }
        if listed(o, list_type) && dict.listed(o.index) {
            return Some(o.index);
        }
        after = Some(o.index);
    }
}

fn count<D: Dictionary>(dict: &D, list_type: u16) -> u16 {
    let mut n = 0u16;
    let mut after = None;
    while let Some(i) = next_listed(dict, list_type, after) {
        n = n.saturating_add(1);
        after = Some(i);
    }
    n
}

fn lengths<D: Dictionary>(out: &mut [u8], dict: &D) -> Result<usize, SdoAbort> {
    let mut w = Writer::new(out);
    let put = |w: &mut Writer<'_>| -> Option<()> {
        info_header(w, opcode::OD_LIST_RESP, 0)?;
        w.u16(list_type::LENGTHS)?;
        for t in list_type::ALL..=list_type::SETTINGS {
            w.u16(count(dict, t))?;
        }
        Some(())
    };
    put(&mut w).ok_or(SdoAbort::OUT_OF_MEMORY)?;
    Ok(w.len())
}

/// One fragment of an OD list; advances the cursor (not the fragment count).
fn od_list_fragment<D: Dictionary>(out: &mut [u8], dict: &D, c: &mut OdListCursor) -> Option<usize> {
    let payload = frag_payload(out.len());
    let mut w = Writer::new(out);
    info_header(&mut w, opcode::OD_LIST_RESP, c.fragments_left)?;
    let end = w.len().saturating_add(payload);
    if c.first {
        w.u16(c.list_type)?;
        c.first = false;
    }
    while w.len() + 2 <= end {
        let Some(index) = next_listed(dict, c.list_type, c.after) else {
            break;
        };
        w.u16(index)?;
        c.after = Some(index);
    }
    Some(w.len())
}

/// The data type of an object as a whole: the entry type of a VAR, the element
/// type of an ARRAY, the CiA 301 structure type of the standard RECORDs, else
/// DEFTYPE RECORD (002Ah).
fn object_type(info: &ObjectInfo) -> u16 {
    match info.code {
        ObjectCode::Var => info.entry(0).map_or(0, |e| e.data_type.code()),
        ObjectCode::Array => complete::element(info, 1)
            .or_else(|| info.entry(0))
            .map_or(0, |e| e.data_type.code()),
        ObjectCode::Record => match info.index {
            0x1018 => 0x0023,                            // IDENTITY
            0x1400..=0x15FF | 0x1800..=0x19FF => 0x0020, // PDO_COMMUNICATION_PARAMETER
            0x1600..=0x17FF | 0x1A00..=0x1BFF => 0x0021, // PDO_MAPPING
            0x1C32..=0x1C33 => 0x0029,                   // SYNC_MANAGER_PARAMETER
            _ => 0x002A,                                 // RECORD
        },
    }
}

fn object_description<D: Dictionary>(out: &mut [u8], dict: &D, index: u16) -> Result<usize, SdoAbort> {
    let info = dict.object(index).ok_or(SdoAbort::NO_OBJECT)?;
    let mut w = Writer::new(out);
    let put = |w: &mut Writer<'_>| -> Option<()> {
        info_header(w, opcode::OBJECT_DESC_RESP, 0)?;
        w.u16(index)?;
        w.u16(object_type(info))?;
        w.u8(complete::capacity(info))?;
        w.u8(info.code.code())?;
        w.truncated(info.name.as_bytes());
        Some(())
    };
    put(&mut w).ok_or(SdoAbort::OUT_OF_MEMORY)?;
    Ok(w.len())
}

/// An integer value in the entry's encoding (little-endian, its byte size).
fn encode(entry: &EntryInfo, v: i64) -> Option<([u8; 8], usize)> {
    let n = match entry.data_type {
        DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::I32 | DataType::U32 => 4,
        DataType::I64 | DataType::U64 => 8,
        _ => return None,
    };
    Some((v.to_le_bytes(), n))
}

fn entry_description<D: Dictionary>(
    out: &mut [u8],
    dict: &D,
    index: u16,
    sub: u8,
    requested: u8,
) -> Result<usize, SdoAbort> {
    let info = dict.object(index).ok_or(SdoAbort::NO_OBJECT)?;
    let entry = complete::element(info, sub).ok_or(SdoAbort::NO_SUBINDEX)?;
    let values = [
        (value_info::DEFAULT, Some(entry.default)),
        (value_info::MIN, entry.min),
        (value_info::MAX, entry.max),
    ];
    let mut supplied = requested & (value_info::ACCESS | value_info::OBJECT | value_info::MAPPABLE);
    for (bit, v) in values {
        if requested & bit != 0 && v.is_some() && encode(&entry, 0).is_some() {
            supplied |= bit;
        }
    }
    let mut w = Writer::new(out);
    let put = |w: &mut Writer<'_>| -> Option<()> {
        info_header(w, opcode::ENTRY_DESC_RESP, 0)?;
        w.u16(index)?;
        w.u8(sub)?;
        w.u8(supplied)?;
        w.u16(entry.data_type.code())?;
        w.u16(entry.bit_len())?;
        w.u16(entry.access.0)?;
        for (bit, v) in values {
            if let (true, Some(v)) = (supplied & bit != 0, v) {
                let (bytes, n) = encode(&entry, v)?;
                w.bytes(bytes.get(..n)?)?;
            }
        }
        w.truncated(entry.name.as_bytes());
        Some(())
    };
    put(&mut w).ok_or(SdoAbort::OUT_OF_MEMORY)?;
    Ok(w.len())
}
