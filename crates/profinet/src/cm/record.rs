//! Records: the IODReadReq/Res and IODWriteReq/Res headers (and the multiple
//! write, index 0xE040), I&M0…I&M4, and the hook for the records the profile
//! adds later ([`RecordHook`]).

use super::ndr::{emit_block, BLOCK_HEADER_LEN};
use super::status::{PnioStatus, RecordError};
use crate::rpc::cursor::{Endian, Reader, Writer};
use crate::rpc::Uuid;

/// Block type IODWriteReqHeader.
pub const IOD_WRITE_REQ: u16 = 0x0008;
/// Block type IODReadReqHeader.
pub const IOD_READ_REQ: u16 = 0x0009;
/// Block type IODWriteResHeader.
pub const IOD_WRITE_RES: u16 = 0x8008;
/// Block type IODReadResHeader.
pub const IOD_READ_RES: u16 = 0x8009;
/// Length of the read/write headers (block header included).
pub const RW_HEADER_LEN: usize = 64;

/// Record indices the CM serves itself.
pub mod index {
    /// I&M0 (read only).
    pub const IM0: u16 = 0xAFF0;
    /// I&M1 (tag function, tag location).
    pub const IM1: u16 = 0xAFF1;
    /// I&M2 (installation date).
    pub const IM2: u16 = 0xAFF2;
    /// I&M3 (descriptor).
    pub const IM3: u16 = 0xAFF3;
    /// I&M4 (signature).
    pub const IM4: u16 = 0xAFF4;
    /// ModuleDiffBlock of the AR.
    pub const MODULE_DIFF: u16 = 0xE002;
    /// Multiple write.
    pub const WRITE_MULTIPLE: u16 = 0xE040;
    /// I&M0FilterData (read only, device scope).
    pub const IM0_FILTER_DATA: u16 = 0xF840;
    /// RealIdentificationData (read only, device scope).
    pub const REAL_IDENTIFICATION_DATA: u16 = 0xF000;
}

/// Where a record lives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RecordAddr {
    /// API.
    pub api: u32,
    /// Slot.
    pub slot: u16,
    /// Subslot.
    pub subslot: u16,
    /// Index.
    pub index: u16,
}

/// An IODReadReq or IODWriteReq header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RwRequest {
    /// Read or write.
    pub write: bool,
    /// SeqNumber.
    pub seq: u16,
    /// ARUUID (nil in an implicit read).
    pub ar_uuid: Uuid,
    /// Address.
    pub addr: RecordAddr,
    /// RecordDataLength: bytes to write, or the most bytes to read.
    pub record_len: u32,
    /// TargetARUUID (implicit read only).
    pub target_ar_uuid: Uuid,
}

impl RwRequest {
    /// Parses a read or write header block at the start of `b`; returns it and
    /// the bytes after it. `None` if the block is not a 1.0 read/write header.
    pub fn parse(b: &[u8]) -> Option<(RwRequest, &[u8])> {
        let mut r = Reader::new(b, Endian::Big);
        let write = match r.u16()? {
            IOD_WRITE_REQ => true,
            IOD_READ_REQ => false,
            _ => return None,
        };
        if r.u16()? != 60 || r.u8()? != 1 || r.u8()? != 0 {
            return None;
        }
        let seq = r.u16()?;
        let ar_uuid = Uuid(r.array()?);
        let api = r.u32()?;
        let slot = r.u16()?;
        let subslot = r.u16()?;
        r.skip(2)?;
        let index = r.u16()?;
        let record_len = r.u32()?;
        let target_ar_uuid = if write { Uuid::NIL } else { Uuid(r.array()?) };
        r.skip(if write { 24 } else { 8 })?;
        Some((
            RwRequest {
                write,
                seq,
                ar_uuid,
                addr: RecordAddr {
                    api,
                    slot,
                    subslot,
                    index,
                },
                record_len,
                target_ar_uuid,
            },
            r.rest(),
        ))
    }
}

/// Writes an IODReadResHeader (`record_len` bytes of data follow).
pub fn emit_read_res(w: &mut Writer<'_>, req: &RwRequest, record_len: u32) -> Option<()> {
    emit_block(w, IOD_READ_RES, |w| {
        emit_res_head(w, req, record_len)?;
        w.zeros(20)
    })
}

/// The fields a read and a write response header share: SeqNumber, ARUUID,
/// the address, RecordDataLength, AdditionalValue1 and 2 (zero).
fn emit_res_head(w: &mut Writer<'_>, req: &RwRequest, record_len: u32) -> Option<()> {
    w.u16(req.seq)?;
    w.bytes(&req.ar_uuid.0)?;
    w.u32(req.addr.api)?;
    w.u16(req.addr.slot)?;
    w.u16(req.addr.subslot)?;
    w.zeros(2)?;
    w.u16(req.addr.index)?;
    w.u32(record_len)?;
    w.u16(0)?; // AdditionalValue1
    w.u16(0) // AdditionalValue2
}

/// Writes an IODWriteResHeader carrying `status`.
pub fn emit_write_res(
    w: &mut Writer<'_>,
    req: &RwRequest,
    record_len: u32,
    status: PnioStatus,
) -> Option<()> {
    emit_block(w, IOD_WRITE_RES, |w| {
        emit_res_head(w, req, record_len)?;
        w.bytes(&status.to_bytes())?;
        w.zeros(16)
    })
}

/// The read-only identification of I&M0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Im0 {
    /// Vendor ID.
    pub vendor_id: u16,
    /// Order ID (20 visible characters, blank padded).
    pub order_id: [u8; 20],
    /// Serial number (16 visible characters, blank padded).
    pub serial_number: [u8; 16],
    /// Hardware revision.
    pub hardware_revision: u16,
    /// Software revision: prefix ('V', 'R', 'P', 'U', 'T') and three numbers.
    pub software_revision: (u8, u8, u8, u8),
    /// Revision counter.
    pub revision_counter: u16,
    /// Profile ID (0xF600 generic device: the profile is manufacturer specific).
    pub profile_id: u16,
    /// Profile specific type.
    pub profile_specific_type: u16,
    /// I&M version (1.1 = 0x0101).
    pub im_version: u16,
    /// I&M supported: bit n = I&Mn (1…4 offered: 0x001E).
    pub im_supported: u16,
}

impl Im0 {
    /// The drive's I&M0 from [`crate::model`] with its serial number.
    pub fn drive(serial_number: &str) -> Im0 {
        Im0 {
            vendor_id: crate::model::VENDOR_ID,
            order_id: visible(crate::model::ORDER_NUMBER),
            serial_number: visible(serial_number),
            hardware_revision: crate::model::HARDWARE_REVISION,
            software_revision: crate::model::SOFTWARE_REVISION,
            revision_counter: 0,
            profile_id: 0xF600,
            profile_specific_type: 0,
            im_version: 0x0101,
            im_supported: 0x001E,
        }
    }
}

/// Pads `s` with blanks into N visible characters (non-ASCII becomes '?').
pub fn visible<const N: usize>(s: &str) -> [u8; N] {
    let mut out = [b' '; N];
    for (o, c) in out.iter_mut().zip(s.bytes()) {
        *o = if (0x20..0x7F).contains(&c) { c } else { b'?' };
    }
    out
}

/// The writable I&M1…I&M4 data (persisted by the application, see
/// [`super::CmEvent::ImWritten`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImData {
    /// I&M1 IM_Tag_Function (32).
    pub tag_function: [u8; 32],
    /// I&M1 IM_Tag_Location (22).
    pub tag_location: [u8; 22],
    /// I&M2 IM_Date "YYYY-MM-DD HH:MM" (16).
    pub date: [u8; 16],
    /// I&M3 IM_Descriptor (54).
    pub descriptor: [u8; 54],
    /// I&M4 IM_Signature (54, binary).
    pub signature: [u8; 54],
}

impl Default for ImData {
    fn default() -> Self {
        ImData {
            tag_function: [b' '; 32],
            tag_location: [b' '; 22],
            date: [b' '; 16],
            descriptor: [b' '; 54],
            signature: [0; 54],
        }
    }
}

/// Which I&M record changed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImRecord {
    /// I&M1.
    Im1,
    /// I&M2.
    Im2,
    /// I&M3.
    Im3,
    /// I&M4.
    Im4,
}

/// I&M0FilterData (index 0xF840): which submodules carry I&M data — the
/// DAP's subslot 1 only, the one submodule with I&M0 — as
/// I&M0FilterDataSubmodule (block 0x0030) and I&M0FilterDataDevice (0x0032,
/// the submodule that answers for the device); no module of its own carries
/// I&M, so no I&M0FilterDataModule block. Each: NumberOfAPIs, API,
/// NumberOfSlots, slot, module ident, NumberOfSubslots, subslot, submodule
/// ident.
pub fn emit_im0_filter(w: &mut Writer<'_>) -> Option<()> {
    for block in [0x0030u16, 0x0032] {
        emit_block(w, block, |w| {
            w.u16(1)?;
            w.u32(0)?;
            w.u16(1)?;
            w.u16(0)?;
            w.u32(crate::model::DAP_MODULE_IDENT)?;
            w.u16(1)?;
            w.u16(1)?;
            w.u32(crate::model::DAP_SUBMODULE_IDENT)
        })?;
    }
    Some(())
}

/// Writes the I&M0 record (block 0x0020) into `w`.
pub fn emit_im0(w: &mut Writer<'_>, im: &Im0) -> Option<()> {
    emit_block(w, 0x0020, |w| {
        w.u16(im.vendor_id)?;
        w.bytes(&im.order_id)?;
        w.bytes(&im.serial_number)?;
        w.u16(im.hardware_revision)?;
        let (p, a, b, c) = im.software_revision;
        w.bytes(&[p, a, b, c])?;
        w.u16(im.revision_counter)?;
        w.u16(im.profile_id)?;
        w.u16(im.profile_specific_type)?;
        w.u16(im.im_version)?;
        w.u16(im.im_supported)
    })
}

/// Writes I&M1…4 (`index` 0xAFF1…0xAFF4) into `w`.
pub fn emit_im(w: &mut Writer<'_>, index: u16, d: &ImData) -> Option<()> {
    let (t, parts): (u16, [&[u8]; 2]) = match index {
        self::index::IM1 => (0x0021, [&d.tag_function, &d.tag_location]),
        self::index::IM2 => (0x0022, [&d.date, &[]]),
        self::index::IM3 => (0x0023, [&d.descriptor, &[]]),
        self::index::IM4 => (0x0024, [&d.signature, &[]]),
        _ => return None,
    };
    emit_block(w, t, |w| {
        for p in parts {
            w.bytes(p)?;
        }
        Some(())
    })
}

/// Applies a write of I&M1…4 (`data` = the block). The standard layout (block
/// header, fields) is taken, and also the one with two padding octets after
/// the header that profinet-py 0.6.6 writes. Returns the changed record.
pub fn write_im(index: u16, data: &[u8], d: &mut ImData) -> Result<ImRecord, RecordError> {
    let (t, len, rec) = match index {
        self::index::IM1 => (0x0021, 54, ImRecord::Im1),
        self::index::IM2 => (0x0022, 16, ImRecord::Im2),
        self::index::IM3 => (0x0023, 54, ImRecord::Im3),
        self::index::IM4 => (0x0024, 54, ImRecord::Im4),
        _ => return Err(RecordError::InvalidIndex),
    };
    let mut r = Reader::new(data, Endian::Big);
    let (bt, bl, vh, vl) =
        (|| Some((r.u16()?, r.u16()?, r.u8()?, r.u8()?)))().ok_or(RecordError::WriteLength)?;
    if bt != t || vh != 1 || vl != 0 {
        return Err(RecordError::InvalidParameter);
    }
    let body = r.rest();
    let fields = match body.len() {
        n if n == len && usize::from(bl) == len + 2 => body,
        n if n == len + 2 && usize::from(bl) == len + 4 && body.get(..2) == Some(&[0, 0]) => {
            body.get(2..).unwrap_or(&[])
        }
        _ => return Err(RecordError::WriteLength),
    };
    let _ = BLOCK_HEADER_LEN;
    let copy = |dst: &mut [u8], src: Option<&[u8]>| {
        if let Some(s) = src {
            dst.copy_from_slice(s);
        }
    };
    match rec {
        ImRecord::Im1 => {
            copy(&mut d.tag_function, fields.get(..32));
            copy(&mut d.tag_location, fields.get(32..54));
        }
        ImRecord::Im2 => copy(&mut d.date, fields.get(..16)),
        ImRecord::Im3 => copy(&mut d.descriptor, fields.get(..54)),
        ImRecord::Im4 => copy(&mut d.signature, fields.get(..54)),
    }
    Ok(rec)
}

/// Records beyond the CM's own (profile parameters, PDev records, …).
///
/// Called for every index the CM does not serve itself, with the AR the access
/// belongs to (None for an implicit read). The default refuses everything with
/// "invalid index".
pub trait RecordHook {
    /// Reads a record into `out`; returns its length.
    fn read(&mut self, _addr: RecordAddr, _out: &mut [u8]) -> Result<usize, RecordError> {
        Err(RecordError::InvalidIndex)
    }

    /// Writes a record.
    fn write(&mut self, _addr: RecordAddr, _data: &[u8]) -> Result<(), RecordError> {
        Err(RecordError::InvalidIndex)
    }
}

/// A [`RecordHook`] without records.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoRecords;

impl RecordHook for NoRecords {}
