//! The NDR argument header of every PNIO call and the PROFINET block header.
//!
//! Request: ArgsMaximum, ArgsLength, MaximumCount, Offset, ActualCount (u32
//! each, in the RPC `drep` order), then ArgsLength bytes of blocks. Response:
//! PNIOStatus instead of ArgsMaximum. Blocks are always big-endian.

use crate::rpc::cursor::{Endian, Reader, Writer};

use super::status::PnioStatus;

/// Length of the NDR header.
pub const NDR_LEN: usize = 20;
/// Length of a block header (type, length, version high, version low).
pub const BLOCK_HEADER_LEN: usize = 6;

/// A parsed request NDR header with its arguments.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NdrRequest<'a> {
    /// Largest response arguments the client accepts.
    pub args_maximum: u32,
    /// MaximumCount of the array.
    pub maximum_count: u32,
    /// The ArgsLength bytes of arguments (blocks).
    pub args: &'a [u8],
}

impl<'a> NdrRequest<'a> {
    /// Parses and checks the header: ArgsLength fits the body, Offset 0,
    /// ActualCount = ArgsLength, ArgsLength ≤ MaximumCount.
    pub fn parse(body: &'a [u8], endian: Endian) -> Option<NdrRequest<'a>> {
        let (mut r, args_maximum, args_length, maximum_count) = Self::header(body, endian)?;
        let args = r.bytes(args_length)?;
        Some(NdrRequest {
            args_maximum,
            maximum_count,
            args,
        })
    }

    /// The same checks for the beginning of a request that was longer than
    /// the buffer ([`crate::rpc::Call::truncated`]): `args` are the
    /// arguments that arrived, shorter than ArgsLength.
    pub fn parse_truncated(body: &'a [u8], endian: Endian) -> Option<NdrRequest<'a>> {
        let (r, args_maximum, args_length, maximum_count) = Self::header(body, endian)?;
        let args = r.rest();
        (args.len() < args_length).then_some(NdrRequest {
            args_maximum,
            maximum_count,
            args,
        })
    }

    /// Reads and checks the five header words; returns the reader past them,
    /// ArgsMaximum, ArgsLength and MaximumCount.
    fn header(body: &'a [u8], endian: Endian) -> Option<(Reader<'a>, u32, usize, u32)> {
        let mut r = Reader::new(body, endian);
        let args_maximum = r.u32()?;
        let args_length = r.u32()?;
        let maximum_count = r.u32()?;
        let offset = r.u32()?;
        let actual_count = r.u32()?;
        if offset != 0 || actual_count != args_length || args_length > maximum_count {
            return None;
        }
        Some((r, args_maximum, usize::try_from(args_length).ok()?, maximum_count))
    }
}

/// Writes a response NDR header in front of `args_len` bytes already at
/// `out[NDR_LEN..]`; returns the total length.
pub fn emit_response(
    out: &mut [u8],
    endian: Endian,
    status: PnioStatus,
    maximum_count: u32,
    args_len: usize,
) -> Option<usize> {
    let n = u32::try_from(args_len).ok()?;
    let mut w = Writer::new(out, endian);
    w.u32(status.to_u32())?;
    w.u32(n)?;
    w.u32(maximum_count.max(n))?;
    w.u32(0)?;
    w.u32(n)?;
    NDR_LEN.checked_add(args_len)
}

/// Writes a request NDR header in front of `args_len` bytes at `out[NDR_LEN..]`.
pub fn emit_request(out: &mut [u8], endian: Endian, args_maximum: u32, args_len: usize) -> Option<usize> {
    let n = u32::try_from(args_len).ok()?;
    let mut w = Writer::new(out, endian);
    w.u32(args_maximum)?;
    w.u32(n)?;
    w.u32(args_maximum)?;
    w.u32(0)?;
    w.u32(n)?;
    NDR_LEN.checked_add(args_len)
}

/// A block as found in the arguments.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Block<'a> {
    /// BlockType.
    pub block_type: u16,
    /// BlockVersionHigh.
    pub version_high: u8,
    /// BlockVersionLow.
    pub version_low: u8,
    /// The body after the version octets (BlockLength − 2 bytes).
    pub body: &'a [u8],
}

/// Why the next block could not be cut out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlockError {
    /// Fewer bytes than a block header.
    Truncated,
    /// BlockLength < 2 or beyond the arguments (carries the block type).
    Length(u16),
}

/// Iterates the blocks of a byte string (blocks back to back, no padding).
#[derive(Clone, Debug)]
pub struct Blocks<'a> {
    r: Reader<'a>,
}

impl<'a> Blocks<'a> {
    /// Blocks of `args`.
    pub fn new(args: &'a [u8]) -> Blocks<'a> {
        Blocks {
            r: Reader::new(args, Endian::Big),
        }
    }

    /// Bytes not consumed yet.
    pub fn remaining(&self) -> usize {
        self.r.remaining()
    }

    /// The next block; `None` at the end.
    pub fn next_block(&mut self) -> Option<Result<Block<'a>, BlockError>> {
        if self.r.remaining() == 0 {
            return None;
        }
        if self.r.remaining() < BLOCK_HEADER_LEN {
            return Some(Err(BlockError::Truncated));
        }
        let block_type = self.r.u16()?;
        let len = usize::from(self.r.u16()?);
        let Some(body_len) = len.checked_sub(2) else {
            return Some(Err(BlockError::Length(block_type)));
        };
        let version_high = self.r.u8()?;
        let version_low = self.r.u8()?;
        match self.r.bytes(body_len) {
            Some(body) => Some(Ok(Block {
                block_type,
                version_high,
                version_low,
                body,
            })),
            None => Some(Err(BlockError::Length(block_type))),
        }
    }

    /// Skips zero padding up to the next multiple of 4 (between the blocks of
    /// a multiple write).
    pub fn align4(&mut self) {
        let _ = self.r.align(4);
    }
}

/// Writes a block: header, then `body` fills it; the length is patched in.
pub fn emit_block(
    w: &mut Writer<'_>,
    block_type: u16,
    body: impl FnOnce(&mut Writer<'_>) -> Option<()>,
) -> Option<()> {
    emit_block_v(w, block_type, 0, body)
}

/// [`emit_block`] with BlockVersionLow `version_low` (high 1).
pub fn emit_block_v(
    w: &mut Writer<'_>,
    block_type: u16,
    version_low: u8,
    body: impl FnOnce(&mut Writer<'_>) -> Option<()>,
) -> Option<()> {
    let start = w.pos();
    w.u16(block_type)?;
    w.u16(0)?;
    w.u8(1)?;
    w.u8(version_low)?;
    body(w)?;
    let len = u16::try_from(w.pos().checked_sub(start)?.checked_sub(4)?).ok()?;
    w.patch_u16(start.checked_add(2)?, len)
}
