//! PDInterfaceAdjust (index 0x8071, block 0x0250) of the interface subslot
//! 0x8000: MultipleInterfaceMode, whose bit 0 (NameOfDevice) says how LLDP
//! names the device (IEC 61158-6-10):
//!
//! | NameOfDevice | LLDP Port ID | LLDP Chassis ID |
//! |---|---|---|
//! | 0 (and while nothing is adjusted) | `port-001` | the name of station |
//! | 1 | `port-001.<name of station>` | the name of station (unchanged) |
//!
//! A write carries BlockHeader (version 1.0), two padding octets and the
//! u32 MultipleInterfaceMode; a reserved bit (1…31) set, another block type
//! or version: "invalid parameter" (0xB8); other lengths: "write length
//! error" (0xB1); nothing changes on a refusal. Read back as written (empty
//! while nothing is adjusted); it holds until the next start.

use crate::cm::ndr::emit_block;
use crate::cm::RecordError;
use crate::lldp::PortIdForm;
use crate::rpc::cursor::{Endian, Reader, Writer};

/// Block type of PDInterfaceAdjust.
pub const PD_INTERFACE_ADJUST: u16 = 0x0250;
/// MultipleInterfaceMode.NameOfDevice.
pub const NAME_OF_DEVICE: u32 = 1;

/// The LLDP Port ID form a MultipleInterfaceMode asks for.
pub fn port_id_form(mode: Option<u32>) -> PortIdForm {
    if mode.is_some_and(|m| m & NAME_OF_DEVICE != 0) {
        PortIdForm::WithName
    } else {
        PortIdForm::Short
    }
}

/// Writes the PDInterfaceAdjust record (nothing while not adjusted).
pub fn emit(w: &mut Writer<'_>, mode: Option<u32>) -> Option<()> {
    let Some(m) = mode else {
        return Some(());
    };
    emit_block(w, PD_INTERFACE_ADJUST, |w| {
        w.zeros(2)?;
        w.u32(m)
    })
}

/// Checks a PDInterfaceAdjust record whole; the MultipleInterfaceMode.
pub fn parse(data: &[u8]) -> Result<u32, RecordError> {
    let body = super::single_block(data, PD_INTERFACE_ADJUST)?;
    let mut r = Reader::new(body, Endian::Big);
    let m = (|| {
        r.skip(2)?;
        r.u32()
    })()
    .ok_or(RecordError::WriteLength)?;
    if r.remaining() != 0 {
        return Err(RecordError::WriteLength);
    }
    if m & !NAME_OF_DEVICE != 0 {
        return Err(RecordError::InvalidParameter);
    }
    Ok(m)
}
