//! The per-cycle path (spec §4.3): a received frame into the drive, the
//! response telegram out of it, and the live view of both (P-070).
//!
//! Order of one cycle, for the caller:
//! 1. [`Telegrams::apply_receive`]: selects receive telegram n by byte 0
//!    (the [`ModeBinding`] to apply when it changed), writes every entry
//!    except CW1 (RAM only, every cycle, P-067), returns CW1 and the PKW
//!    request;
//! 2. the PKW step ([`crate::pkw::Pkw::step`]) with that request;
//! 3. CW1 last (P-066): [`crate::cw1::Cw1Decoder`] and the core;
//! 4. [`Telegrams::build_response`] of the associated response telegram
//!    ([`RxOutcome::response`]) with the PKW response.
//!
//! Length: the module the controller configured may be longer or
//! shorter than the telegram. Received: entries that do not lie wholly
//! inside the frame are not written (their objects keep their values; a
//! CW1 outside is "no CW1"), bytes after the telegram are ignored. Sent:
//! the telegram is cut to the module, or zero-padded up to it. Either sets
//! [`Warnings::LENGTH_MISMATCH`].

use super::{Dir, Kind, Telegrams, MAX_TELEGRAM_BYTES, TELEGRAMS};
use crate::{decode_be, encode_be, fits, Addr, ParamAccess};

/// The operating mode a receive telegram's identifier binds (spec §4.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModeBinding {
    /// 0xE0: positioning (PNU 1500 = 0x10, P-051).
    Positioning,
    /// 0xE1: speed control (PNU 1500 = 0x08, P-052).
    Speed,
    /// 0xE2/0xE3: the mode stays as PNU 1500 sets it (P-053).
    None,
}

impl ModeBinding {
    /// The binding of receive telegram `n`.
    pub const fn of(n: u8) -> Self {
        match n {
            0 => ModeBinding::Positioning,
            1 => ModeBinding::Speed,
            _ => ModeBinding::None,
        }
    }
}

/// Warnings of one cycle (bits; ).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Warnings(pub u8);

impl Warnings {
    /// Byte 0 is no configured receive identifier (or the frame is empty):
    /// the payload was ignored.
    pub const UNKNOWN_IDENTIFIER: u8 = 1 << 0;
    /// The frame / module is not as long as the telegram.
    pub const LENGTH_MISMATCH: u8 = 1 << 1;
    /// The drive refused at least one cyclic write / read (the entry was
    /// skipped / sent as 0).
    pub const ACCESS_REFUSED: u8 = 1 << 2;

    /// None set?
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Is `bit` set?
    pub const fn has(self, bit: u8) -> bool {
        self.0 & bit != 0
    }
}

/// What [`Telegrams::apply_receive`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RxOutcome {
    /// The receive telegram (`None`: unknown identifier, nothing applied).
    pub telegram: Option<u8>,
    /// Its mode binding (`None` for an unknown identifier too).
    pub mode: ModeBinding,
    /// The receive telegram differs from the previous frame's.
    pub changed: bool,
    /// The response telegram to send (the associated one; after an unknown
    /// identifier the last one sent, `None` before any).
    pub response: Option<u8>,
    /// CW1 to apply last (`None`: not mapped or outside the frame).
    pub cw1: Option<u16>,
    /// The PKW request, if mapped.
    pub pkw: Option<[u8; 8]>,
    /// Warnings.
    pub warnings: Warnings,
}

/// What [`Telegrams::build_response`] wrote.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TxOutcome {
    /// Bytes written (the module length).
    pub len: usize,
    /// Warnings.
    pub warnings: Warnings,
}

/// A frame's bytes on a word boundary: the copies into the live view run
/// word by word (issue 36: the response's copy to an odd address ran byte
/// by byte, ~220 instructions per telegram on QEMU).
#[derive(Debug, Clone, Copy)]
#[repr(C, align(4))]
struct Bytes([u8; MAX_TELEGRAM_BYTES]);

/// The last frames both ways (P-070).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Live {
    rx: Bytes,
    rx_len: u8,
    tx: Bytes,
    tx_len: u8,
    last_rx: Option<u8>,
    last_tx: Option<u8>,
    unknown: u32,
}

impl Live {
    pub(crate) const NEW: Self = Self {
        rx: Bytes([0; MAX_TELEGRAM_BYTES]),
        rx_len: 0,
        tx: Bytes([0; MAX_TELEGRAM_BYTES]),
        tx_len: 0,
        last_rx: None,
        last_tx: None,
        unknown: 0,
    };
}

/// [`fits`] of `v`, decoded from a slot of type `t` (the slot is the
/// type's size, [`super::check_entry`]): every integer type's decode is
/// in its range by construction, only BOOLEAN's byte may be beyond 0/1
/// (issue 36: the range test of every entry every telegram;
/// `issue36_a_decoded_entry_fits_its_type`).
#[inline]
fn decoded_fits(t: od::DataType, v: i64) -> bool {
    t != od::DataType::Bool || fits(t, v)
}

impl Telegrams {
    /// Applies a received frame (the OUT module's data): see the
    /// [module](self) for the order of a cycle.
    pub fn apply_receive(&mut self, frame: &[u8], access: &mut impl ParamAccess) -> RxOutcome {
        self.receive_through(frame, access, |a, _, _, addr, v| a.write(addr, v, true).is_ok())
    }

    /// [`apply_receive`](Self::apply_receive) with `write(access, n, i,
    /// addr, value)` writing the object entries (`n` the telegram, `i` the
    /// slot's position in its layout): the address path or a compiled
    /// handle's ([`super::compiled`]).
    pub(super) fn receive_through<A: ParamAccess>(
        &mut self,
        frame: &[u8],
        access: &mut A,
        mut write: impl FnMut(&mut A, u8, usize, Addr, i64) -> bool,
    ) -> RxOutcome {
        let mut out = RxOutcome {
            telegram: None,
            mode: ModeBinding::None,
            changed: false,
            response: self.live.last_tx,
            cw1: None,
            pkw: None,
            warnings: Warnings::default(),
        };
        let n = match frame.first() {
            Some(&id) if self.configured && (0xE0..0xE0 + TELEGRAMS as u8).contains(&id) => id - 0xE0,
            _ => {
                out.warnings.0 |= Warnings::UNKNOWN_IDENTIFIER;
                self.live.unknown = self.live.unknown.wrapping_add(1);
                return out;
            }
        };
        // borrowed, not copied (issue 36: a layout's copy cost ~170
        // instructions per telegram on QEMU)
        let Some(layout) = self.receive.get(usize::from(n)) else {
            return out;
        };
        out.telegram = Some(n);
        out.mode = ModeBinding::of(n);
        out.changed = self.live.last_rx != Some(n);
        out.response = self.associated(n);
        self.live.last_rx = Some(n);
        if frame.len() != layout.len() {
            out.warnings.0 |= Warnings::LENGTH_MISMATCH;
        }
        let keep = frame.len().min(MAX_TELEGRAM_BYTES);
        if let (Some(dst), Some(src)) = (self.live.rx.0.get_mut(..keep), frame.get(..keep)) {
            dst.copy_from_slice(src);
            self.live.rx_len = keep as u8;
        }
        for (i, s) in layout.slots().iter().enumerate() {
            let at = usize::from(s.offset);
            let Some(bytes) = frame.get(at..at + usize::from(s.size)) else {
                continue;
            };
            match s.kind {
                Kind::Pad => {}
                Kind::Cw1 => out.cw1 = Some(decode_be(od::DataType::U16, bytes) as u16),
                Kind::Pkw => {
                    // the slot's size is 8 by construction, which the
                    // compiler cannot see: a checked conversion (no panic
                    // path), one copy instead of a byte loop (issue 36)
                    out.pkw = Some(<[u8; 8]>::try_from(bytes).unwrap_or_else(|_| {
                        let mut p = [0u8; 8];
                        for (d, b) in p.iter_mut().zip(bytes) {
                            *d = *b;
                        }
                        p
                    }));
                }
                Kind::Object(t) => {
                    let v = decode_be(t, bytes);
                    let ok = decoded_fits(t, v) && write(access, n, i, s.addr, v);
                    if !ok {
                        out.warnings.0 |= Warnings::ACCESS_REFUSED;
                    }
                }
            }
        }
        out
    }

    /// Writes the object entries of `frame` (a receive telegram, as
    /// [`apply_receive`](Self::apply_receive) writes them) that `pick`
    /// selects, and nothing else: no CW1, no PKW, no live view, no telegram
    /// switch. An entry is written when `pick` selects it (it sees the
    /// access and the entry's address) and, unless `every`, its bytes differ
    /// from the frame applied last (or the telegram does). For
    /// a personality that writes the configuration values a telegram
    /// carries where the configuration changes, ahead of the control cycle
    /// that applies the telegram and writes them again, unchanged (issue
    /// 36). Returns the entries written.
    pub fn write_ahead<A: ParamAccess>(
        &self,
        frame: &[u8],
        access: &mut A,
        every: bool,
        mut pick: impl FnMut(&A, Addr) -> bool,
    ) -> usize {
        let n = match frame.first() {
            Some(&id) if self.configured && (0xE0..0xE0 + TELEGRAMS as u8).contains(&id) => id - 0xE0,
            _ => return 0,
        };
        let Some(layout) = self.receive.get(usize::from(n)) else {
            return 0;
        };
        let last = (self.live.last_rx == Some(n)).then(|| self.live_receive());
        // the frame applied last again (a controller repeats its telegram):
        // no entry changed
        if !every && last == Some(frame) {
            return 0;
        }
        let mut written = 0;
        for s in layout.slots() {
            let Kind::Object(t) = s.kind else {
                continue;
            };
            let at = usize::from(s.offset);
            let Some(bytes) = frame.get(at..at + usize::from(s.size)) else {
                continue;
            };
            // a byte loop (two or four bytes), not a slice compare's call
            let changed = match last.and_then(|l| l.get(at..at + usize::from(s.size))) {
                Some(l) => l.iter().zip(bytes).any(|(a, b)| a != b),
                None => true,
            };
            if !(changed || every) || !pick(access, s.addr) {
                continue;
            }
            let v = decode_be(t, bytes);
            if decoded_fits(t, v) && access.write(s.addr, v, true).is_ok() {
                written += 1;
            }
        }
        written
    }

    /// Packs response telegram `n` into `buf` (the IN module; its length is
    /// the module length): identifier, the entries read from `access` in
    /// bus order, placeholders 0, `pkw` in the PKW slot. `None` when `n` is
    /// not a configured telegram.
    pub fn build_response(
        &mut self,
        n: u8,
        access: &mut impl ParamAccess,
        pkw: [u8; 8],
        buf: &mut [u8],
    ) -> Option<TxOutcome> {
        self.respond_through(n, access, pkw, buf, |a, _, addr| a.read(addr))
    }

    /// [`build_response`](Self::build_response) with `read(access, i,
    /// addr)` reading the entries (`i` the slot's position in the layout):
    /// the address path or a compiled handle's ([`super::compiled`]).
    pub(super) fn respond_through<A: ParamAccess>(
        &mut self,
        n: u8,
        access: &mut A,
        pkw: [u8; 8],
        buf: &mut [u8],
        mut read: impl FnMut(&mut A, usize, Addr) -> Result<i64, crate::PdError>,
    ) -> Option<TxOutcome> {
        // `layout`'s answer, borrowed from the field (not copied: ~150
        // instructions per telegram; issue 36)
        if !self.configured {
            return None;
        }
        let layout = self.response.get(usize::from(n))?;
        let mut warnings = Warnings::default();
        if buf.len() != layout.len() {
            warnings.0 |= Warnings::LENGTH_MISMATCH;
        }
        buf.fill(0);
        if let Some(b) = buf.first_mut() {
            *b = Dir::Response.identifier(n);
        }
        for (i, s) in layout.slots().iter().enumerate() {
            let at = usize::from(s.offset);
            let Some(dst) = buf.get_mut(at..at + usize::from(s.size)) else {
                continue;
            };
            match s.kind {
                Kind::Pad => {}
                Kind::Pkw => match <&mut [u8; 8]>::try_from(&mut *dst) {
                    // one copy instead of a byte loop (issue 36)
                    Ok(d) => *d = pkw,
                    Err(_) => {
                        for (d, b) in dst.iter_mut().zip(pkw) {
                            *d = b;
                        }
                    }
                },
                Kind::Cw1 | Kind::Object(_) => match read(access, i, s.addr) {
                    Ok(v) => encode_be(v, dst),
                    Err(_) => warnings.0 |= Warnings::ACCESS_REFUSED,
                },
            }
        }
        let keep = buf.len().min(MAX_TELEGRAM_BYTES);
        if let (Some(dst), Some(src)) = (self.live.tx.0.get_mut(..keep), buf.get(..keep)) {
            dst.copy_from_slice(src);
            self.live.tx_len = keep as u8;
        }
        self.live.last_tx = Some(n);
        Some(TxOutcome {
            len: buf.len(),
            warnings,
        })
    }

    /// The last received frame as it came (up to [`MAX_TELEGRAM_BYTES`]).
    pub fn live_receive(&self) -> &[u8] {
        self.live.rx.0.get(..usize::from(self.live.rx_len)).unwrap_or(&[])
    }

    /// The last response telegram sent.
    pub fn live_response(&self) -> &[u8] {
        self.live.tx.0.get(..usize::from(self.live.tx_len)).unwrap_or(&[])
    }

    /// The receive telegram of the last frame with a known identifier.
    pub fn active_receive(&self) -> Option<u8> {
        self.live.last_rx
    }

    /// Frames with an unknown identifier since the configuration.
    pub fn unknown_frames(&self) -> u32 {
        self.live.unknown
    }

    /// The entries of the last frames for diagnosis (P-070): each mapped
    /// entry of `dir`'s last telegram with its value as it travelled
    /// (big-endian decoded, placeholders and PKW as raw unsigned), in order.
    /// Calls `f(addr, offset, size, value)`; entries outside the frame are
    /// skipped.
    pub fn for_each_live(&self, dir: Dir, mut f: impl FnMut(Addr, u8, u8, i64)) {
        let (n, bytes) = match dir {
            Dir::Receive => (self.live.last_rx, self.live_receive()),
            Dir::Response => (self.live.last_tx, self.live_response()),
        };
        let Some(layout) = n.and_then(|n| self.layout(dir, n)) else {
            return;
        };
        for s in layout.slots() {
            let at = usize::from(s.offset);
            if let Some(b) = bytes.get(at..at + usize::from(s.size)) {
                let t = match s.kind {
                    Kind::Object(t) => t,
                    _ => od::DataType::U64,
                };
                f(s.addr, s.offset, s.size, decode_be(t, b));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use od::DataType;

    /// Issue 36: a value decoded from a slot of an integer type's size
    /// fits that type, so only BOOLEAN needs [`fits`]'s test (P-067: a
    /// BOOLEAN byte beyond 0/1 is refused).
    #[test]
    fn issue36_a_decoded_entry_fits_its_type() {
        let types = crate::tests_be::SLOT_TYPES;
        let patterns = [0x00u8, 0x01, 0x02, 0x7F, 0x80, 0xFF, 0x5A];
        for t in types {
            let size = crate::int_size(t).unwrap();
            for &first in &patterns {
                for &rest in &patterns {
                    let mut bytes = [rest; 8];
                    bytes[0] = first;
                    let v = decode_be(t, &bytes[..size]);
                    assert_eq!(decoded_fits(t, v), fits(t, v), "{t:?} {bytes:?}");
                    if t != DataType::Bool {
                        assert!(fits(t, v), "{t:?} {bytes:?}");
                    }
                }
            }
        }
        assert!(!decoded_fits(DataType::Bool, 2));
    }
}
