//! The stored form of a [`TelegramSet`] (P-069): compact bytes, checked.
//!
//! Layout: version (1), the four associations (4), then for each of the
//! eight telegrams (receive 0…3, response 0…3) the number k of entries up
//! to the last one that is not 2011.0 (1 byte, ≤ 10) and k × (index
//! big-endian, subindex); last a CRC-16/CCITT-FALSE (big-endian) over all
//! bytes before it. At most [`MAX_SERIAL_BYTES`].

use super::{TelegramSet, MAX_ENTRIES, TELEGRAMS, UNUSED};
use crate::Addr;

/// The longest stored form.
pub const MAX_SERIAL_BYTES: usize = 1 + TELEGRAMS + 2 * TELEGRAMS * (1 + 3 * MAX_ENTRIES) + 2;
const VERSION: u8 = 1;

/// Why bytes are not a stored telegram set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FormatError {
    /// Too short for what it announces.
    Truncated,
    /// Bytes after the checksum.
    TrailingBytes,
    /// Unknown version byte.
    Version,
    /// More than 10 entries in a telegram.
    TooManyEntries,
    /// The checksum does not match.
    Checksum,
    /// The output buffer is too small.
    BufferTooSmall,
}

fn crc16(data: &[u8]) -> u16 {
    let mut crc: u16 = 0xFFFF;
    for &b in data {
        crc ^= u16::from(b) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
        }
    }
    crc
}

struct Writer<'a> {
    buf: &'a mut [u8],
    at: usize,
}

impl Writer<'_> {
    fn put(&mut self, b: u8) -> Result<(), FormatError> {
        *self.buf.get_mut(self.at).ok_or(FormatError::BufferTooSmall)? = b;
        self.at += 1;
        Ok(())
    }
}

struct Reader<'a> {
    data: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], FormatError> {
        let s = self
            .data
            .get(self.at..self.at + n)
            .ok_or(FormatError::Truncated)?;
        self.at += n;
        Ok(s)
    }
}

impl TelegramSet {
    /// Writes the stored form into `out`, returning its length.
    pub fn to_bytes(&self, out: &mut [u8]) -> Result<usize, FormatError> {
        let mut w = Writer { buf: out, at: 0 };
        w.put(VERSION)?;
        for &a in &self.associated {
            w.put(a)?;
        }
        for entries in self.receive.iter().chain(&self.response) {
            let k = entries.iter().rposition(|&e| e != UNUSED).map_or(0, |p| p + 1);
            w.put(k as u8)?;
            for e in entries.iter().take(k) {
                let [hi, lo] = e.index.to_be_bytes();
                w.put(hi)?;
                w.put(lo)?;
                w.put(e.sub)?;
            }
        }
        let n = w.at;
        let crc = crc16(w.buf.get(..n).ok_or(FormatError::BufferTooSmall)?);
        let [hi, lo] = crc.to_be_bytes();
        w.put(hi)?;
        w.put(lo)?;
        Ok(w.at)
    }

    /// Reads a stored form (all of `data`). Only the form is checked here;
    /// [`super::Telegrams::configure`] checks the content.
    pub fn from_bytes(data: &[u8]) -> Result<Self, FormatError> {
        let mut r = Reader { data, at: 0 };
        if r.take(1)? != [VERSION] {
            return Err(FormatError::Version);
        }
        let mut set = TelegramSet::EMPTY;
        set.associated.copy_from_slice(r.take(TELEGRAMS)?);
        for entries in set.receive.iter_mut().chain(set.response.iter_mut()) {
            let k = usize::from(*r.take(1)?.first().ok_or(FormatError::Truncated)?);
            if k > MAX_ENTRIES {
                return Err(FormatError::TooManyEntries);
            }
            for e in entries.iter_mut().take(k) {
                if let [hi, lo, sub] = *r.take(3)? {
                    *e = Addr::new(u16::from_be_bytes([hi, lo]), sub);
                }
            }
        }
        let body = r.at;
        let crc = r.take(2)?;
        let want = crc16(data.get(..body).ok_or(FormatError::Truncated)?).to_be_bytes();
        if crc != want {
            return Err(FormatError::Checksum);
        }
        if data.len() != body + 2 {
            return Err(FormatError::TrailingBytes);
        }
        Ok(set)
    }
}
