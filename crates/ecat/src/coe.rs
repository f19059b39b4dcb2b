//! CAN application protocol over EtherCAT: CoE header, SDO expedited/normal
//! initiate transfers, abort (spec §6.1–6.2, §6.5).
//!
//! Objects are read and written through [`od::Dictionary`], which the drive's
//! object dictionary implements.

use crate::mailbox::MailboxError;
use esc::AlState;

/// Length of the CoE header.
pub const COE_HEADER_LEN: usize = 2;
/// Length of an SDO initiate/abort frame after the CoE header.
pub const SDO_LEN: usize = 8;

pub use od::{CommState, Dictionary, SdoAbort};

/// CoE services (CoE header bits 12..15).
pub mod service {
    /// Emergency.
    pub const EMERGENCY: u8 = 1;
    /// SDO request.
    pub const SDO_REQUEST: u8 = 2;
    /// SDO response.
    pub const SDO_RESPONSE: u8 = 3;
    /// SDO information.
    pub const SDO_INFO: u8 = 8;
}

/// The CoE header: number (bits 0..8), service (bits 12..15).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CoeHeader {
    /// Number (PDO number / EMCY: 0).
    pub number: u16,
    /// Service (see [`service`]).
    pub service: u8,
}

impl CoeHeader {
    /// Parses the first two bytes of `buf`.
    pub fn parse(buf: &[u8]) -> Option<Self> {
        match buf.get(..COE_HEADER_LEN)? {
            &[a, b] => {
                let raw = u16::from_le_bytes([a, b]);
                Some(Self {
                    number: raw & 0x01FF,
                    service: (raw >> 12) as u8,
                })
            }
            _ => None,
        }
    }

    /// The two header bytes.
    pub fn to_bytes(self) -> [u8; 2] {
        ((self.number & 0x01FF) | (u16::from(self.service & 0x0F) << 12)).to_le_bytes()
    }
}

/// A parsed SDO request (the 8 bytes after the CoE header, plus data of a normal
/// download in the same frame).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SdoRequest<'a> {
    /// Initiate upload (command 40h).
    Upload {
        /// Index.
        index: u16,
        /// Subindex.
        sub: u8,
        /// Complete access bit.
        complete_access: bool,
    },
    /// Initiate download, expedited (23h/27h/2Bh/2Fh/22h) or normal with all data
    /// in this frame (21h).
    Download {
        /// Index.
        index: u16,
        /// Subindex.
        sub: u8,
        /// Complete access bit.
        complete_access: bool,
        /// The data.
        data: &'a [u8],
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
    /// Anything else (segments, block transfers, a normal download whose data
    /// does not fit this frame): answered with [`SdoAbort::INVALID_COMMAND`].
    Unsupported {
        /// Index.
        index: u16,
        /// Subindex.
        sub: u8,
    },
}

impl<'a> SdoRequest<'a> {
    /// Parses `sdo` (the bytes after the CoE header); `None` when shorter than 8 bytes.
    pub fn parse(sdo: &'a [u8]) -> Option<Self> {
        let (cmd, index, sub, data) = match sdo.get(..SDO_LEN)? {
            &[c, i0, i1, s, d0, d1, d2, d3] => (c, u16::from_le_bytes([i0, i1]), s, [d0, d1, d2, d3]),
            _ => return None,
        };
        let complete_access = cmd & 0x10 != 0;
        Some(match cmd >> 5 {
            // initiate download
            1 => {
                let expedited = cmd & 0x02 != 0;
                let sized = cmd & 0x01 != 0;
                let payload = if expedited {
                    let n = if sized { usize::from((cmd >> 2) & 0x03) } else { 0 };
                    sdo.get(4..8 - n)
                } else if sized {
                    let size = u32::from_le_bytes(data) as usize;
                    sdo.get(SDO_LEN..SDO_LEN.saturating_add(size))
                } else {
                    None
                };
                match payload {
                    Some(data) => SdoRequest::Download {
                        index,
                        sub,
                        complete_access,
                        data,
                    },
                    None => SdoRequest::Unsupported { index, sub },
                }
            }
            2 => SdoRequest::Upload {
                index,
                sub,
                complete_access,
            },
            4 => SdoRequest::Abort {
                index,
                sub,
                code: SdoAbort(u32::from_le_bytes(data)),
            },
            _ => SdoRequest::Unsupported { index, sub },
        })
    }
}

/// Handles one CoE mailbox payload (`req` = CoE header + service data) and writes
/// the response's mailbox data into `out` (capacity = SM1 length − 6).
/// Returns the response length, `None` when nothing is to be sent, or the
/// mailbox error to reply with.
pub fn handle<A: Dictionary>(
    req: &[u8],
    out: &mut [u8],
    app: &mut A,
    state: AlState,
) -> Result<Option<usize>, MailboxError> {
    let header = CoeHeader::parse(req).ok_or(MailboxError::SIZE_TOO_SHORT)?;
    if header.service != service::SDO_REQUEST {
        return Err(MailboxError::SERVICE_NOT_SUPPORTED);
    }
    let sdo = req.get(COE_HEADER_LEN..).unwrap_or_default();
    let request = SdoRequest::parse(sdo).ok_or(MailboxError::SIZE_TOO_SHORT)?;
    let result = match request {
        SdoRequest::Abort { .. } => return Ok(None),
        SdoRequest::Upload {
            complete_access: true,
            index,
            sub,
        }
        | SdoRequest::Download {
            complete_access: true,
            index,
            sub,
            ..
        } => Err((index, sub, SdoAbort::UNSUPPORTED_ACCESS)),
        SdoRequest::Unsupported { index, sub } => Err((index, sub, SdoAbort::INVALID_COMMAND)),
        SdoRequest::Upload { index, sub, .. } => upload(out, app, index, sub, comm_state(state)),
        SdoRequest::Download { index, sub, data, .. } => match app.write(index, sub, data, comm_state(state))
        {
            Ok(()) => sdo_frame(out, service::SDO_RESPONSE, 0x60, index, sub, [0; 4]),
            Err(e) => Err((index, sub, e)),
        },
    };
    match result {
        Ok(n) => Ok(Some(n)),
        Err((index, sub, code)) => {
            sdo_frame(out, service::SDO_REQUEST, 0x80, index, sub, code.0.to_le_bytes())
                .map(Some)
                .map_err(|_| MailboxError::NO_MORE_MEMORY)
        }
    }
}

type Failure = (u16, u8, SdoAbort);

/// The access state of an ESM state (Bootstrap has no CoE; treated as Init).
pub fn comm_state(state: AlState) -> CommState {
    match state {
        AlState::Init | AlState::Bootstrap => CommState::Init,
        AlState::PreOp => CommState::PreOp,
        AlState::SafeOp => CommState::SafeOp,
        AlState::Op => CommState::Op,
    }
}

/// Writes CoE header + 8-byte SDO frame into `out`; returns 10.
fn sdo_frame(
    out: &mut [u8],
    service: u8,
    cmd: u8,
    index: u16,
    sub: u8,
    data: [u8; 4],
) -> Result<usize, Failure> {
    let frame = out
        .get_mut(..COE_HEADER_LEN + SDO_LEN)
        .ok_or((index, sub, SdoAbort::OUT_OF_MEMORY))?;
    let [c0, c1] = CoeHeader { number: 0, service }.to_bytes();
    let [i0, i1] = index.to_le_bytes();
    let [d0, d1, d2, d3] = data;
    frame.copy_from_slice(&[c0, c1, cmd, i0, i1, sub, d0, d1, d2, d3]);
    Ok(COE_HEADER_LEN + SDO_LEN)
}

/// Upload: expedited response for 1..4 bytes, normal initiate response with the
/// complete data otherwise (it must fit the mailbox).
fn upload<A: Dictionary>(
    out: &mut [u8],
    app: &mut A,
    index: u16,
    sub: u8,
    state: CommState,
) -> Result<usize, Failure> {
    const DATA: usize = COE_HEADER_LEN + SDO_LEN;
    let buf = out.get_mut(DATA..).ok_or((index, sub, SdoAbort::OUT_OF_MEMORY))?;
    let n = app.read(index, sub, buf, state).map_err(|e| (index, sub, e))?;
    if n > buf.len() {
        return Err((index, sub, SdoAbort::OUT_OF_MEMORY));
    }
    if (1..=4).contains(&n) {
        let mut d = [0u8; 4];
        d.get_mut(..n)
            .zip(buf.get(..n))
            .map(|(d, s)| d.copy_from_slice(s))
            .ok_or((index, sub, SdoAbort::OUT_OF_MEMORY))?;
        // 43h/47h/4Bh/4Fh: expedited, size indicated, n = 4 − len unused bytes
        let cmd = 0x43 | (((4 - n) as u8) << 2);
        sdo_frame(out, service::SDO_RESPONSE, cmd, index, sub, d)
    } else {
        sdo_frame(
            out,
            service::SDO_RESPONSE,
            0x41,
            index,
            sub,
            (n as u32).to_le_bytes(),
        )?;
        Ok(DATA + n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 0x2000:0 = u16 0x1234, 0x2001:0 = 6 bytes, 0x2002:0 = 200 bytes, 0x2003 writable u32.
    struct Objs {
        written: Option<(u16, u8, heapless::Vec<u8, 8>)>,
    }

    impl Dictionary for Objs {
        fn object(&self, _: u16) -> Option<&'static od::ObjectInfo> {
            None
        }
        fn next_object(&self, _: Option<u16>) -> Option<&'static od::ObjectInfo> {
            None
        }
        fn read(&mut self, index: u16, sub: u8, buf: &mut [u8], _: CommState) -> Result<usize, SdoAbort> {
            let data: &[u8] = match (index, sub) {
                (0x2000, 0) => &[0x34, 0x12],
                (0x2001, 0) => b"abcdef",
                (0x2002, 0) => &[7; 200],
                (0x2000..=0x2003, _) => return Err(SdoAbort::NO_SUBINDEX),
                _ => return Err(SdoAbort::NO_OBJECT),
            };
            let dst = buf.get_mut(..data.len()).ok_or(SdoAbort::OUT_OF_MEMORY)?;
            dst.copy_from_slice(data);
            Ok(data.len())
        }
        fn write(&mut self, index: u16, sub: u8, data: &[u8], _: CommState) -> Result<(), SdoAbort> {
            if index != 0x2003 {
                return Err(SdoAbort::READ_ONLY);
            }
            self.written = Some((index, sub, heapless::Vec::from_slice(data).unwrap()));
            Ok(())
        }
    }

    fn run(req: &[u8], cap: usize) -> (Result<Option<usize>, MailboxError>, [u8; 64], Objs) {
        let mut out = [0u8; 64];
        let mut o = Objs { written: None };
        let r = handle(req, &mut out[..cap], &mut o, AlState::PreOp);
        (r, out, o)
    }

    #[test]
    fn e063_expedited_upload_with_size() {
        let (r, out, _) = run(&[0x00, 0x20, 0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0], 64);
        assert_eq!(r, Ok(Some(10)));
        assert_eq!(
            &out[..10],
            &[0x00, 0x30, 0x4B, 0x00, 0x20, 0x00, 0x34, 0x12, 0, 0]
        );
    }

    #[test]
    fn e064_normal_upload_carries_size_and_data() {
        let (r, out, _) = run(&[0x00, 0x20, 0x40, 0x01, 0x20, 0x00, 0, 0, 0, 0], 64);
        assert_eq!(r, Ok(Some(16)));
        assert_eq!(
            &out[..16],
            &[0x00, 0x30, 0x41, 0x01, 0x20, 0x00, 6, 0, 0, 0, b'a', b'b', b'c', b'd', b'e', b'f']
        );
    }

    #[test]
    fn e069_upload_too_large_aborts_out_of_memory() {
        let (r, out, _) = run(&[0x00, 0x20, 0x40, 0x02, 0x20, 0x00, 0, 0, 0, 0], 64);
        assert_eq!(r, Ok(Some(10)));
        assert_eq!(
            &out[..10],
            &[0x00, 0x20, 0x80, 0x02, 0x20, 0x00, 0x05, 0x00, 0x04, 0x05]
        );
    }

    #[test]
    fn e063_expedited_download_sizes() {
        for (cmd, len) in [(0x2F, 1), (0x2B, 2), (0x27, 3), (0x23, 4), (0x22, 4)] {
            let (r, out, o) = run(&[0x00, 0x20, cmd, 0x03, 0x20, 0x01, 1, 2, 3, 4], 64);
            assert_eq!(r, Ok(Some(10)));
            assert_eq!(&out[..10], &[0x00, 0x30, 0x60, 0x03, 0x20, 0x01, 0, 0, 0, 0]);
            let (i, s, d) = o.written.unwrap();
            assert_eq!((i, s), (0x2003, 1));
            assert_eq!(d.as_slice(), &[1, 2, 3, 4][..len]);
        }
    }

    #[test]
    fn e069_unknown_command_and_abort_codes() {
        // segment upload request (ccs 3) is not supported yet
        let (r, out, _) = run(&[0x00, 0x20, 0x60, 0x00, 0x20, 0x00, 0, 0, 0, 0], 64);
        assert_eq!(r, Ok(Some(10)));
        assert_eq!(&out[2..10], &[0x80, 0x00, 0x20, 0x00, 0x01, 0x00, 0x04, 0x05]);
        // write to a read-only object
        let (_, out, _) = run(&[0x00, 0x20, 0x2F, 0x00, 0x20, 0x00, 1, 0, 0, 0], 64);
        assert_eq!(&out[2..10], &[0x80, 0x00, 0x20, 0x00, 0x02, 0x00, 0x01, 0x06]);
        // unknown object
        let (_, out, _) = run(&[0x00, 0x20, 0x40, 0x00, 0x30, 0x00, 0, 0, 0, 0], 64);
        assert_eq!(u32::from_le_bytes(out[6..10].try_into().unwrap()), 0x0602_0000);
        // complete access not supported
        let (_, out, _) = run(&[0x00, 0x20, 0x50, 0x00, 0x20, 0x00, 0, 0, 0, 0], 64);
        assert_eq!(u32::from_le_bytes(out[6..10].try_into().unwrap()), 0x0601_0000);
    }

    #[test]
    fn abort_from_master_gets_no_reply_and_short_frames_are_errors() {
        let (r, _, _) = run(&[0x00, 0x20, 0x80, 0x00, 0x20, 0x00, 0, 0, 0, 0], 64);
        assert_eq!(r, Ok(None));
        let (r, _, _) = run(&[0x00, 0x20, 0x40, 0x00, 0x20], 64);
        assert_eq!(r, Err(MailboxError::SIZE_TOO_SHORT));
        let (r, _, _) = run(&[0x00, 0x80, 0x01, 0x00, 0, 0, 0, 0, 0, 0], 64);
        assert_eq!(r, Err(MailboxError::SERVICE_NOT_SUPPORTED));
    }
}
