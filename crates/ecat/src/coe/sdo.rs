//! SDO request parsing and the transfer state machine (spec §6.2–6.4).

use super::{
    complete, sdo_frame, service, CoeServer, Failure, Transfer, Writer, COE_HEADER_LEN, MAX_TRANSFER, SDO_LEN,
};
use nanos::Nanos;
use od::{CommState, Dictionary, SdoAbort};

/// Data bytes of a CAN-style segment (the minimum segment).
const MIN_SEGMENT: usize = 7;

/// A parsed SDO request (the bytes after the CoE header).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SdoRequest<'a> {
    /// Initiate download (ccs = 1): expedited (23h/27h/2Bh/2Fh, 22h without
    /// size) or normal (21h with size, 20h without), with the data this frame
    /// carries.
    InitiateDownload {
        /// Index.
        index: u16,
        /// Subindex.
        sub: u8,
        /// Complete access (bit 4).
        complete_access: bool,
        /// Expedited (e = 1): `data` is the whole value.
        expedited: bool,
        /// Announced size (s = 1): the data bytes of an expedited transfer, the
        /// complete size of a normal one.
        size: Option<u32>,
        /// Data in this frame (normal: at most `size` bytes).
        data: &'a [u8],
    },
    /// Download segment (ccs = 0).
    DownloadSegment {
        /// Toggle bit.
        toggle: bool,
        /// c = 1: last segment.
        last: bool,
        /// Segment data (7-byte segments: without the n unused bytes).
        data: &'a [u8],
    },
    /// Initiate upload (ccs = 2, 40h, 50h with complete access).
    InitiateUpload {
        /// Index.
        index: u16,
        /// Subindex.
        sub: u8,
        /// Complete access (bit 4).
        complete_access: bool,
    },
    /// Upload segment (ccs = 3, 60h/70h).
    UploadSegment {
        /// Toggle bit.
        toggle: bool,
    },
    /// Abort transfer (80h).
    Abort {
        /// Index.
        index: u16,
        /// Subindex.
        sub: u8,
        /// Abort code.
        code: SdoAbort,
    },
    /// A command specifier the server does not know (block transfers, 7):
    /// answered with 0504 0001h.
    Unknown {
        /// The command byte.
        command: u8,
        /// Index (bytes 1..2).
        index: u16,
        /// Subindex.
        sub: u8,
    },
}

impl<'a> SdoRequest<'a> {
    /// Parses `sdo` (the bytes after the CoE header, as many as the mailbox
    /// header's length says); `None` when shorter than 8 bytes.
    pub fn parse(sdo: &'a [u8]) -> Option<Self> {
        let (cmd, index, sub, d) = match sdo.get(..SDO_LEN)? {
            &[c, i0, i1, s, d0, d1, d2, d3] => (c, u16::from_le_bytes([i0, i1]), s, [d0, d1, d2, d3]),
            _ => return None,
        };
        let bit4 = cmd & 0x10 != 0;
        Some(match cmd >> 5 {
            0 => {
                let seg = sdo.get(1..).unwrap_or_default();
                // n (bits 1..3) counts unused bytes of a 7-byte segment only; a
                // longer segment is as long as the mailbox data says
                let unused = if seg.len() == MIN_SEGMENT {
                    usize::from((cmd >> 1) & 0x07)
                } else {
                    0
                };
                SdoRequest::DownloadSegment {
                    toggle: bit4,
                    last: cmd & 0x01 != 0,
                    data: seg.get(..seg.len().saturating_sub(unused)).unwrap_or_default(),
                }
            }
            1 => {
                let expedited = cmd & 0x02 != 0;
                let sized = cmd & 0x01 != 0;
                let (size, data) = if expedited {
                    let n = if sized { usize::from((cmd >> 2) & 0x03) } else { 0 };
                    let data = sdo.get(4..SDO_LEN - n).unwrap_or_default();
                    (sized.then_some(data.len() as u32), data)
                } else {
                    let rest = sdo.get(SDO_LEN..).unwrap_or_default();
                    if sized {
                        let size = u32::from_le_bytes(d);
                        let n = rest.len().min(usize::try_from(size).unwrap_or(usize::MAX));
                        (Some(size), rest.get(..n).unwrap_or_default())
                    } else {
                        (None, rest)
                    }
                };
                SdoRequest::InitiateDownload {
                    index,
                    sub,
                    complete_access: bit4,
                    expedited,
                    size,
                    data,
                }
            }
            2 => SdoRequest::InitiateUpload {
                index,
                sub,
                complete_access: bit4,
            },
            3 => SdoRequest::UploadSegment { toggle: bit4 },
            4 => SdoRequest::Abort {
                index,
                sub,
                code: SdoAbort(u32::from_le_bytes(d)),
            },
            _ => SdoRequest::Unknown {
                command: cmd,
                index,
                sub,
            },
        })
    }
}

/// A segment response (download: scs = 1; upload: scs = 0 with data): CoE
/// header, command, then at least 7 bytes.
fn segment_frame(out: &mut [u8], cmd: u8, data: &[u8]) -> Option<usize> {
    let mut w = Writer::new(out);
    w.coe_header(service::SDO_RESPONSE)?;
    w.u8(cmd)?;
    w.bytes(data)?;
    w.zeros(MIN_SEGMENT.saturating_sub(data.len()))?;
    Some(w.len())
}

/// Writes a complete download value: one `write`, or the complete-access
/// sequence.
fn store<D: Dictionary>(
    dict: &mut D,
    index: u16,
    sub: u8,
    complete_access: bool,
    data: &[u8],
    state: CommState,
) -> Result<(), Failure> {
    if complete_access {
        complete::download(dict, index, sub, data, state)
    } else {
        dict.write(index, sub, data, state)
    }
    .map_err(|e| (index, sub, e))
}

impl CoeServer {
    /// Acts on one SDO request.
    pub(super) fn sdo<D: Dictionary>(
        &mut self,
        request: SdoRequest<'_>,
        out: &mut [u8],
        dict: &mut D,
        state: CommState,
        now: Nanos,
    ) -> Result<Option<usize>, Failure> {
        match request {
            SdoRequest::Abort { .. } => {
                self.transfer = Transfer::Idle;
                self.len = 0;
                Ok(None)
            }
            SdoRequest::InitiateDownload {
                index,
                sub,
                complete_access,
                expedited,
                size,
                data,
            } => {
                // a new initiate ends whatever was in progress
                self.transfer = Transfer::Idle;
                self.len = 0;
                self.initiate_download(
                    out,
                    dict,
                    state,
                    now,
                    (index, sub, complete_access),
                    expedited,
                    size,
                    data,
                )
                .map(Some)
            }
            SdoRequest::DownloadSegment { toggle, last, data } => self
                .download_segment(out, dict, state, now, toggle, last, data)
                .map(Some),
            SdoRequest::InitiateUpload {
                index,
                sub,
                complete_access,
            } => {
                self.transfer = Transfer::Idle;
                self.len = 0;
                self.initiate_upload(out, dict, state, now, index, sub, complete_access)
                    .map(Some)
            }
            SdoRequest::UploadSegment { toggle } => self.upload_segment(out, now, toggle).map(Some),
            SdoRequest::Unknown { index, sub, .. } => Err((index, sub, SdoAbort::INVALID_COMMAND)),
        }
    }

    fn check_complete_access<D: Dictionary>(&self, dict: &D, index: u16, sub: u8) -> Result<(), Failure> {
        if !self.config.complete_access {
            return Err((index, sub, SdoAbort::UNSUPPORTED_ACCESS));
        }
        complete::object(dict, index, sub)
            .map(|_| ())
            .map_err(|e| (index, sub, e))
    }

    #[allow(clippy::too_many_arguments)]
    fn initiate_download<D: Dictionary>(
        &mut self,
        out: &mut [u8],
        dict: &mut D,
        state: CommState,
        now: Nanos,
        (index, sub, complete_access): (u16, u8, bool),
        expedited: bool,
        size: Option<u32>,
        data: &[u8],
    ) -> Result<usize, Failure> {
        let response = |out: &mut [u8]| {
            sdo_frame(out, service::SDO_RESPONSE, 0x60, index, sub, [0; 4]).ok_or((
                index,
                sub,
                SdoAbort::OUT_OF_MEMORY,
            ))
        };
        if complete_access {
            self.check_complete_access(dict, index, sub)?;
        }
        if expedited {
            // 22h (no size): 4 bytes; cut to the entry's size when it is known
            let data = match size {
                None if !complete_access => {
                    let n = dict
                        .object(index)
                        .and_then(|o| o.entry(sub))
                        .map(|e| e.data_type)
                        .filter(|t| !t.is_string())
                        .map_or(data.len(), |t| t.bytes());
                    data.get(..n).unwrap_or(data)
                }
                _ => data,
            };
            store(dict, index, sub, complete_access, data, state)?;
            return response(out);
        }
        let size = match size {
            Some(s) => match usize::try_from(s) {
                Ok(s) if s <= MAX_TRANSFER => Some(s),
                _ => return Err((index, sub, SdoAbort::OUT_OF_MEMORY)),
            },
            None => None,
        };
        let dst = self
            .buf
            .get_mut(..data.len())
            .ok_or((index, sub, SdoAbort::OUT_OF_MEMORY))?;
        dst.copy_from_slice(data);
        if size == Some(data.len()) {
            // all data in the initiate frame
            store(dict, index, sub, complete_access, data, state)?;
            return response(out);
        }
        let n = response(out)?;
        self.len = data.len();
        self.transfer = Transfer::Download {
            index,
            sub,
            complete_access,
            size,
            toggle: false,
            last: now,
        };
        Ok(n)
    }

    #[allow(clippy::too_many_arguments)]
    fn download_segment<D: Dictionary>(
        &mut self,
        out: &mut [u8],
        dict: &mut D,
        state: CommState,
        now: Nanos,
        toggle: bool,
        last: bool,
        data: &[u8],
    ) -> Result<usize, Failure> {
        let (index, sub, complete_access, size) = match self.transfer {
            Transfer::Download {
                index,
                sub,
                complete_access,
                size,
                toggle: expected,
                ..
            } => {
                if toggle != expected {
                    return Err((index, sub, SdoAbort::TOGGLE_BIT));
                }
                (index, sub, complete_access, size)
            }
            Transfer::TimedOut { index, sub } => return Err((index, sub, SdoAbort::TIMEOUT)),
            Transfer::Upload { index, sub, .. } => return Err((index, sub, SdoAbort::INVALID_COMMAND)),
            Transfer::Idle => return Err((0, 0, SdoAbort::INVALID_COMMAND)),
        };
        let end = self.len.saturating_add(data.len());
        if size.is_some_and(|s| end > s) {
            return Err((index, sub, SdoAbort::TYPE_MISMATCH));
        }
        let dst = self
            .buf
            .get_mut(self.len..end)
            .ok_or((index, sub, SdoAbort::OUT_OF_MEMORY))?;
        // equal lengths unless `end` saturated (then the range fails above)
        for (d, s) in dst.iter_mut().zip(data) {
            *d = *s;
        }
        self.len = end;
        let cmd = 0x20 | if toggle { 0x10 } else { 0 };
        if last {
            self.transfer = Transfer::Idle;
            if size.is_some_and(|s| s != end) {
                return Err((index, sub, SdoAbort::TYPE_MISMATCH));
            }
            let value = self.buf.get(..end).unwrap_or_default();
            store(dict, index, sub, complete_access, value, state)?;
            self.len = 0;
        } else {
            self.transfer = Transfer::Download {
                index,
                sub,
                complete_access,
                size,
                toggle: !toggle,
                last: now,
            };
        }
        segment_frame(out, cmd, &[]).ok_or((index, sub, SdoAbort::OUT_OF_MEMORY))
    }

    #[allow(clippy::too_many_arguments)]
    fn initiate_upload<D: Dictionary>(
        &mut self,
        out: &mut [u8],
        dict: &mut D,
        state: CommState,
        now: Nanos,
        index: u16,
        sub: u8,
        complete_access: bool,
    ) -> Result<usize, Failure> {
        let n = if complete_access {
            self.check_complete_access(dict, index, sub)?;
            complete::upload(dict, index, sub, &mut self.buf, state)
        } else {
            dict.read(index, sub, &mut self.buf, state)
        }
        .map_err(|e| (index, sub, e))?;
        let value = self.buf.get(..n).ok_or((index, sub, SdoAbort::OUT_OF_MEMORY))?;
        let oom = (index, sub, SdoAbort::OUT_OF_MEMORY);
        if (1..=4).contains(&n) {
            // 43h/47h/4Bh/4Fh: expedited, size indicated, n = 4 − len unused bytes
            let mut d = [0u8; 4];
            d.get_mut(..n).ok_or(oom)?.copy_from_slice(value);
            let cmd = 0x43 | (((4 - n) as u8) << 2);
            return sdo_frame(out, service::SDO_RESPONSE, cmd, index, sub, d).ok_or(oom);
        }
        let size = (n as u32).to_le_bytes();
        let head = sdo_frame(out, service::SDO_RESPONSE, 0x41, index, sub, size).ok_or(oom)?;
        if let Some(dst) = out.get_mut(head..head.saturating_add(n)) {
            // normal transfer: everything in the initiate response
            dst.copy_from_slice(value);
            return Ok(head + n);
        }
        // segmented: the initiate response carries the size only (spec §6.4;
        // ethercrab 0.7.1 ignores data in a segmented initiate response)
        if out.len() < COE_HEADER_LEN + 1 + MIN_SEGMENT {
            return Err(oom);
        }
        self.len = n;
        self.transfer = Transfer::Upload {
            index,
            sub,
            pos: 0,
            toggle: false,
            last: now,
        };
        Ok(head)
    }

    fn upload_segment(&mut self, out: &mut [u8], now: Nanos, toggle: bool) -> Result<usize, Failure> {
        let (index, sub, pos) = match self.transfer {
            Transfer::Upload {
                index,
                sub,
                pos,
                toggle: expected,
                ..
            } => {
                if toggle != expected {
                    return Err((index, sub, SdoAbort::TOGGLE_BIT));
                }
                (index, sub, pos)
            }
            Transfer::TimedOut { index, sub } => return Err((index, sub, SdoAbort::TIMEOUT)),
            Transfer::Download { index, sub, .. } => return Err((index, sub, SdoAbort::INVALID_COMMAND)),
            Transfer::Idle => return Err((0, 0, SdoAbort::INVALID_COMMAND)),
        };
        let oom = (index, sub, SdoAbort::OUT_OF_MEMORY);
        // segment data length = mailbox data length − 3 (CoE header, command)
        let room = out.len().saturating_sub(COE_HEADER_LEN + 1);
        let rest = self.buf.get(pos..self.len).unwrap_or_default();
        let seg = rest.len().min(room);
        let data = rest.get(..seg).ok_or(oom)?;
        let last = seg == rest.len();
        // n: unused bytes of a 7-byte segment
        let unused = MIN_SEGMENT.saturating_sub(seg) as u8;
        let cmd = if toggle { 0x10 } else { 0 } | (unused << 1) | u8::from(last);
        let len = segment_frame(out, cmd, data).ok_or(oom)?;
        self.transfer = if last {
            self.len = 0;
            Transfer::Idle
        } else {
            Transfer::Upload {
                index,
                sub,
                pos: pos + seg,
                toggle: !toggle,
                last: now,
            }
        };
        Ok(len)
    }
}
