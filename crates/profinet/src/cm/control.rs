//! IODControlReq/Res (PrmEnd; ApplicationReady sent by the device) and
//! IODReleaseReq/Res: one block layout, told apart by block type and command.

use super::ndr::{emit_block, Block};
use super::status::PnioStatus;
use crate::rpc::cursor::{Endian, Reader, Writer};
use crate::rpc::Uuid;

/// Block types of the control blocks.
pub mod block_type {
    /// IODControlReq PrmEnd.
    pub const PRM_END_REQ: u16 = 0x0110;
    /// IODControlRes PrmEnd.
    pub const PRM_END_RES: u16 = 0x8110;
    /// IODControlReq ApplicationReady (device → controller).
    pub const APP_READY_REQ: u16 = 0x0112;
    /// IODControlRes ApplicationReady (controller → device).
    pub const APP_READY_RES: u16 = 0x8112;
    /// IODReleaseReq.
    pub const RELEASE_REQ: u16 = 0x0114;
    /// IODReleaseRes.
    pub const RELEASE_RES: u16 = 0x8114;
    /// PrmBeginReq (not offered).
    pub const PRM_BEGIN_REQ: u16 = 0x0118;
}

/// ControlCommand bits.
pub mod command {
    /// PrmEnd.
    pub const PRM_END: u16 = 0x0001;
    /// ApplicationReady.
    pub const APPLICATION_READY: u16 = 0x0002;
    /// Release.
    pub const RELEASE: u16 = 0x0004;
    /// Done (in every response).
    pub const DONE: u16 = 0x0008;
}

/// A control block's fields.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ControlBlock {
    /// ARUUID.
    pub ar_uuid: Uuid,
    /// SessionKey.
    pub session_key: u16,
    /// ControlCommand.
    pub command: u16,
    /// ControlBlockProperties.
    pub properties: u16,
}

impl ControlBlock {
    /// Parses a control block; errors name field `n` of block `code1` for
    /// service `code` (1 = length, 2/3 = version).
    pub fn parse(blk: &Block<'_>, code: u8, code1: u8) -> Result<ControlBlock, PnioStatus> {
        let err = |field| PnioStatus::pnio(code, code1, field);
        if blk.version_high != 1 {
            return Err(err(2));
        }
        if blk.version_low != 0 {
            return Err(err(3));
        }
        if blk.body.len() != 26 {
            return Err(err(1));
        }
        let mut r = Reader::new(blk.body, Endian::Big);
        let c = (|| {
            r.skip(2)?;
            let ar_uuid = Uuid(r.array()?);
            let session_key = r.u16()?;
            r.skip(2)?;
            Some(ControlBlock {
                ar_uuid,
                session_key,
                command: r.u16()?,
                properties: r.u16()?,
            })
        })();
        c.ok_or(err(1))
    }

    /// Writes the block as `block_type`.
    pub fn emit(&self, w: &mut Writer<'_>, block_type: u16) -> Option<()> {
        emit_block(w, block_type, |w| {
            w.zeros(2)?;
            w.bytes(&self.ar_uuid.0)?;
            w.u16(self.session_key)?;
            w.zeros(2)?;
            w.u16(self.command)?;
            w.u16(self.properties)
        })
    }
}
