//! The recorder as the provider of its objects T00…T11
//! ([`crate::objects::scope`]): reads and writes from either fieldbus land
//! here after the dictionary's checks (access, length, declared range).
//! Subindices in the "EtherCAT Rx SDO Info" numbering (element k at k + 1).

use super::{decode_channel, Config, Recorder, State, BLOCKS, MAX_CHANNELS};
use crate::dictionary::LiveValues;
use crate::params::{T00, T01, T02, T03, T04, T05, T06, T07, T08, T09, T10, T11};
use od::SdoAbort;

/// `v` as `bytes` little-endian bytes into `buf`.
fn put(buf: &mut [u8], v: i64, bytes: usize) -> Result<usize, SdoAbort> {
    let out = buf.get_mut(..bytes).ok_or(SdoAbort::OUT_OF_MEMORY)?;
    out.copy_from_slice(v.to_le_bytes().get(..bytes).ok_or(SdoAbort::GENERAL)?);
    Ok(bytes)
}

/// `data` (1, 2 or 4 bytes, little-endian) as an unsigned value.
fn unsigned(data: &[u8]) -> u32 {
    data.iter().rev().fold(0, |v, &b| v << 8 | u32::from(b))
}

impl<S: AsRef<[u32]> + AsMut<[u32]>> LiveValues for Recorder<S> {
    fn read(&mut self, index: u16, sub: u8, buf: &mut [u8]) -> Option<Result<usize, SdoAbort>> {
        let c = &self.config;
        let (v, bytes) = match (index, sub) {
            (T00, 0) => (i64::from(self.state.code()), 1),
            (T01, 0) => (MAX_CHANNELS as i64, 1),
            (T01, k) => (i64::from(*c.channels.get(usize::from(k) - 1)?), 4),
            (T02, 0) => (i64::from(c.count), 1),
            (T03, 0) => (i64::from(c.divider), 2),
            (T04, 0) => (i64::from(c.length), 4),
            (T05, 0) => (i64::from(c.source), 2),
            (T06, 0) => (i64::from(c.condition), 1),
            (T07, 0) => (i64::from(c.level), 4),
            (T08, 0) => (i64::from(c.pre_percent), 1),
            (T09, 0) => (i64::from(c.normal), 1),
            (T10, 0) => (4, 1),
            (T10, 1) => (i64::from(self.frames_if_complete()), 4),
            (T10, 2) => (i64::from(self.trigger_index()), 4),
            (T10, 3) => (i64::from(self.traces), 4),
            (T10, 4) => (self.capacity() as i64, 4),
            (T11, 0) => (i64::from(BLOCKS), 1),
            (T11, k) => return Some(self.read_block(k - 1, buf)),
            _ => return None,
        };
        Some(put(buf, v, bytes))
    }

    fn provide(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        let v = unsigned(data);
        if index == T00 {
            return match v {
                0 => {
                    self.stop();
                    Ok(())
                }
                1 => self.arm(),
                _ => Err(SdoAbort::INVALID_VALUE),
            };
        }
        let mut c: Config = self.config;
        match (index, sub) {
            (T01, k @ 1..) => {
                let slot = c
                    .channels
                    .get_mut(usize::from(k) - 1)
                    .ok_or(SdoAbort::NO_SUBINDEX)?;
                decode_channel(v)?;
                *slot = v;
            }
            (T02, 0) => c.count = v as u8,
            (T03, 0) => c.divider = v as u16,
            (T04, 0) => c.length = v,
            (T05, 0) => c.source = v as u16,
            (T06, 0) => c.condition = v as u8,
            (T07, 0) => c.level = v as i32,
            (T08, 0) => c.pre_percent = v as u8,
            (T09, 0) => c.normal = v != 0,
            _ => return Err(SdoAbort::READ_ONLY),
        }
        self.configure(c)
    }
}

impl<S: AsRef<[u32]> + AsMut<[u32]>> Recorder<S> {
    /// T10\[0\]: samples per channel of the complete trace, 0 before.
    fn frames_if_complete(&self) -> u32 {
        if self.state == State::Complete {
            self.frames
        } else {
            0
        }
    }
}
