//! Diagnosis history 10F3h (ETG.1020, spec §16, items E-144..E-146): a volatile ring
//! of [`MAX_MESSAGES`] messages, always in overwrite mode.
//!
//! | sub | type | meaning |
//! |---|---|---|
//! | 00h | UINT8 ro | highest subindex: 25 (19h) |
//! | 01h | UINT8 ro | maximum messages: 20 |
//! | 02h | UINT8 ro | subindex of the newest message (06h..19h), 0 = none |
//! | 03h | UINT8 rw | subindex of the newest acknowledged message, 0 = none |
//! | 04h | BOOL ro | a message newer than the newest acknowledged one exists (TxPDO, A250) |
//! | 05h | UINT16 rw | [`flags`]: bits 1..3 filter types; bit 0 stays 1, bit 4 stays 0 |
//! | 06h..19h | OCTET_STRING ro | the messages, see [`DiagMessage::encode`] |
//!
//! Writing 03h (overwrite mode, ETG.1020): 0 deletes all messages; 1..5 → 0609 0032h;
//! 06h..19h acknowledges that message and every older one (0609 0030h when the
//! subindex holds no message); above 19h → 0609 0031h. Overwriting a message that was not
//! acknowledged sets 03h to 0 and sets flag bit 5.

use nanos::Nanos;
use od::SdoAbort;

/// Messages kept.
pub const MAX_MESSAGES: usize = 20;
/// Subindex of the first message slot.
pub const FIRST_MESSAGE_SUB: u8 = 6;
/// Highest subindex (10F3h:00).
pub const LAST_SUB: u8 = FIRST_MESSAGE_SUB + MAX_MESSAGES as u8 - 1;
/// Parameters a message may carry.
pub const MAX_PARAMS: usize = 2;
/// Longest encoded message: 16 fixed bytes + 6 per parameter.
pub const MESSAGE_MAX_LEN: usize = 16 + 6 * MAX_PARAMS;

/// Bits of 10F3h:05.
pub mod flags {
    /// Send new messages as emergency; the device keeps it set (spec §16).
    pub const EMERGENCY: u16 = 1 << 0;
    /// Do not store info messages.
    pub const DISABLE_INFO: u16 = 1 << 1;
    /// Do not store warnings.
    pub const DISABLE_WARNING: u16 = 1 << 2;
    /// Do not store errors.
    pub const DISABLE_ERROR: u16 = 1 << 3;
    /// Acknowledge mode; the device keeps it clear (overwrite mode, spec §16).
    pub const ACK_MODE: u16 = 1 << 4;
    /// Read only: an unacknowledged message was overwritten.
    pub const OVERWRITTEN: u16 = 1 << 5;
    /// The bits a master may change.
    pub const WRITABLE: u16 = DISABLE_INFO | DISABLE_WARNING | DISABLE_ERROR;
}

/// Parameter flags of a UINT32 parameter (ETG.1020: data type index 0007h).
const PARAM_U32: u16 = 0x0007;

/// Message type (message flags bits 0..3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DiagType {
    /// Info (0).
    Info = 0,
    /// Warning (1).
    Warning = 1,
    /// Error (2).
    Error = 2,
}

impl DiagType {
    /// The 10F3h:05 bit that filters this type.
    const fn disable_flag(self) -> u16 {
        match self {
            DiagType::Info => flags::DISABLE_INFO,
            DiagType::Warning => flags::DISABLE_WARNING,
            DiagType::Error => flags::DISABLE_ERROR,
        }
    }
}

/// One diagnosis message (the time stamp is added by [`DiagHistory::push`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DiagMessage {
    /// Diag code (ETG.1020 UINT32, e.g. E800h + EMCY code in bits 16..31 per ETG).
    pub code: u32,
    /// Type.
    pub kind: DiagType,
    /// Text ID (texts live in the ESI).
    pub text_id: u16,
    /// Optional UINT32 parameters; the present ones are encoded in order.
    pub params: [Option<u32>; MAX_PARAMS],
}

impl DiagMessage {
    /// A message without parameters.
    pub const fn new(code: u32, kind: DiagType, text_id: u16) -> Self {
        Self {
            code,
            kind,
            text_id,
            params: [None; MAX_PARAMS],
        }
    }

    /// Message flags: type in bits 0..3, parameter count in bits 8..15 (bit 4 "local
    /// time stamp" stays 0).
    pub fn flags(&self) -> u16 {
        let count = self.params.iter().flatten().count() as u16;
        self.kind as u16 | (count << 8)
    }

    /// ETG.1020 encoding into `out`: diag code u32, flags u16, text ID u16, time stamp
    /// u64 (ns), then per parameter flags u16 (0007h = UINT32) and the u32 value, all
    /// little-endian. Returns the length, `None` when `out` is too short.
    pub fn encode(&self, time: Nanos, out: &mut [u8]) -> Option<usize> {
        let mut w = Writer { out, at: 0 };
        w.put(&self.code.to_le_bytes())?;
        w.put(&self.flags().to_le_bytes())?;
        w.put(&self.text_id.to_le_bytes())?;
        w.put(&time.as_ns().to_le_bytes())?;
        for v in self.params.iter().flatten() {
            w.put(&PARAM_U32.to_le_bytes())?;
            w.put(&v.to_le_bytes())?;
        }
        Some(w.at)
    }
}

struct Writer<'a> {
    out: &'a mut [u8],
    at: usize,
}

impl Writer<'_> {
    fn put(&mut self, bytes: &[u8]) -> Option<()> {
        let end = self.at.checked_add(bytes.len())?;
        self.out.get_mut(self.at..end)?.copy_from_slice(bytes);
        self.at = end;
        Some(())
    }
}

#[derive(Debug, Clone, Copy)]
struct Entry {
    msg: DiagMessage,
    time: Nanos,
    /// 1 for the first message since restart; never wraps.
    seq: u64,
}

/// The diagnosis history object 10F3h. Volatile: a new one after every restart (E-145).
#[derive(Debug, Clone)]
pub struct DiagHistory {
    ring: [Option<Entry>; MAX_MESSAGES],
    /// Slot of the next message.
    next: usize,
    /// Sequence number of the newest message (0 = none yet).
    seq: u64,
    /// Sequence number of the newest acknowledged message (0 = none).
    acked: u64,
    flags: u16,
}

impl Default for DiagHistory {
    fn default() -> Self {
        Self::new()
    }
}

impl DiagHistory {
    /// An empty history, emergency flag set, overwrite mode.
    pub const fn new() -> Self {
        Self {
            ring: [None; MAX_MESSAGES],
            next: 0,
            seq: 0,
            acked: 0,
            flags: flags::EMERGENCY,
        }
    }

    /// Stores `msg` with time stamp `now` (DC or SNTP time, 0 when unknown; spec
    /// §17), overwriting the oldest message when full. Returns `false` when the type
    /// is filtered out by 10F3h:05 (nothing stored).
    pub fn push(&mut self, msg: DiagMessage, now: Nanos) -> bool {
        if self.flags & msg.kind.disable_flag() != 0 {
            return false;
        }
        self.seq += 1;
        let slot = self.next;
        self.next = (slot + 1) % MAX_MESSAGES;
        if let Some(cell) = self.ring.get_mut(slot) {
            if cell.is_some_and(|old| old.seq > self.acked) {
                self.acked = 0;
                self.flags |= flags::OVERWRITTEN;
            }
            *cell = Some(Entry {
                msg,
                time: now,
                seq: self.seq,
            });
        }
        true
    }

    /// 10F3h:04 (for the TxPDO through A250).
    pub fn new_messages(&self) -> bool {
        self.seq > self.acked
    }

    /// 10F3h:05.
    pub fn flags(&self) -> u16 {
        self.flags
    }

    /// 10F3h:02: subindex of the newest message, 0 when there is none.
    pub fn newest_subindex(&self) -> u8 {
        self.subindex_of(self.seq)
    }

    /// 10F3h:03: subindex of the newest acknowledged message, 0 when none.
    pub fn newest_acknowledged_subindex(&self) -> u8 {
        self.subindex_of(self.acked)
    }

    /// The message and its time stamp at subindex `sub` (06h..19h).
    pub fn message(&self, sub: u8) -> Option<(DiagMessage, Nanos)> {
        let e = self.entry(sub)?;
        Some((e.msg, e.time))
    }

    fn entry(&self, sub: u8) -> Option<&Entry> {
        let slot = usize::from(sub.checked_sub(FIRST_MESSAGE_SUB)?);
        self.ring.get(slot)?.as_ref()
    }

    fn subindex_of(&self, seq: u64) -> u8 {
        if seq == 0 {
            return 0;
        }
        (0u8..)
            .zip(&self.ring)
            .find(|(_, e)| e.is_some_and(|e| e.seq == seq))
            .map_or(0, |(i, _)| FIRST_MESSAGE_SUB + i)
    }

    /// Deletes all messages (10F3h:03 := 0).
    fn clear(&mut self) {
        self.ring = [None; MAX_MESSAGES];
        self.acked = self.seq;
        self.flags &= !flags::OVERWRITTEN;
    }

    /// SDO upload of 10F3h:`sub` into `buf`; returns the length (0 for an empty
    /// message slot).
    pub fn read(&self, sub: u8, buf: &mut [u8]) -> Result<usize, SdoAbort> {
        let mut small = [0u8; MESSAGE_MAX_LEN];
        let flag_bytes = self.flags.to_le_bytes();
        let data: &[u8] = match sub {
            0 => &[LAST_SUB],
            1 => &[MAX_MESSAGES as u8],
            2 => &[self.newest_subindex()],
            3 => &[self.newest_acknowledged_subindex()],
            4 => &[u8::from(self.new_messages())],
            5 => &flag_bytes,
            FIRST_MESSAGE_SUB..=LAST_SUB => match self.entry(sub) {
                Some(e) => {
                    let n = e.msg.encode(e.time, &mut small).ok_or(SdoAbort::GENERAL)?;
                    small.get(..n).unwrap_or_default()
                }
                None => &[],
            },
            _ => return Err(SdoAbort::NO_SUBINDEX),
        };
        buf.get_mut(..data.len())
            .ok_or(SdoAbort::OUT_OF_MEMORY)?
            .copy_from_slice(data);
        Ok(data.len())
    }

    /// SDO download of `data` to 10F3h:`sub`.
    pub fn write(&mut self, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        match sub {
            3 => {
                let &[v] = exact::<1>(data)?;
                match v {
                    0 => self.clear(),
                    1..FIRST_MESSAGE_SUB => return Err(SdoAbort::VALUE_TOO_LOW),
                    FIRST_MESSAGE_SUB..=LAST_SUB => {
                        self.acked = self.entry(v).ok_or(SdoAbort::INVALID_VALUE)?.seq;
                    }
                    _ => return Err(SdoAbort::VALUE_TOO_HIGH),
                }
                Ok(())
            }
            5 => {
                let &[a, b] = exact::<2>(data)?;
                // Emergency stays on, overwrite mode stays, bit 5 belongs to the device.
                let keep = flags::EMERGENCY | (self.flags & flags::OVERWRITTEN);
                self.flags = keep | (u16::from_le_bytes([a, b]) & flags::WRITABLE);
                Ok(())
            }
            0..=LAST_SUB => Err(SdoAbort::READ_ONLY),
            _ => Err(SdoAbort::NO_SUBINDEX),
        }
    }
}

fn exact<const N: usize>(data: &[u8]) -> Result<&[u8; N], SdoAbort> {
    match data.len() {
        n if n < N => Err(SdoAbort::LENGTH_TOO_LOW),
        n if n > N => Err(SdoAbort::LENGTH_TOO_HIGH),
        _ => data.try_into().map_err(|_| SdoAbort::TYPE_MISMATCH),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn msg(n: u32) -> DiagMessage {
        DiagMessage::new(0xE800_0000 | n, DiagType::Error, n as u16)
    }

    fn read_u8(h: &DiagHistory, sub: u8) -> u8 {
        let mut b = [0u8; 32];
        assert_eq!(h.read(sub, &mut b), Ok(1));
        b[0]
    }

    fn code_at(h: &DiagHistory, sub: u8) -> u32 {
        h.message(sub).unwrap().0.code & 0xFFFF
    }

    #[test]
    fn e144_subindices_and_encoding() {
        let mut h = DiagHistory::new();
        assert_eq!(read_u8(&h, 0), 25);
        assert_eq!(read_u8(&h, 1), 20);
        assert_eq!(read_u8(&h, 2), 0);
        assert_eq!(read_u8(&h, 4), 0);
        let mut b = [0u8; 64];
        assert_eq!(h.read(5, &mut b), Ok(2));
        assert_eq!(b[..2], [0x01, 0x00]);
        assert_eq!(h.read(6, &mut b), Ok(0), "empty slot");
        assert_eq!(h.read(26, &mut b), Err(SdoAbort::NO_SUBINDEX));

        let mut m = DiagMessage::new(0x4310_E800, DiagType::Warning, 0x1234);
        m.params = [Some(0xAABB_CCDD), Some(7)];
        assert!(h.push(m, Nanos::from_ns(0x0102_0304_0506_0708)));
        assert_eq!(read_u8(&h, 2), 6);
        assert_eq!(h.read(6, &mut b), Ok(MESSAGE_MAX_LEN));
        assert_eq!(
            b[..MESSAGE_MAX_LEN],
            [
                0x00, 0xE8, 0x10, 0x43, // diag code
                0x01, 0x02, // flags: warning, 2 parameters
                0x34, 0x12, // text ID
                0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01, // time stamp
                0x07, 0x00, 0xDD, 0xCC, 0xBB, 0xAA, // UINT32 parameter
                0x07, 0x00, 0x07, 0x00, 0x00, 0x00,
            ]
        );
        assert!(h.push(DiagMessage::new(1, DiagType::Info, 2), Nanos::ZERO));
        assert_eq!(h.read(7, &mut b), Ok(16));
        assert_eq!(b[4..6], [0x00, 0x00], "info, no parameters");
        assert_eq!(h.read(7, &mut [0u8; 15]), Err(SdoAbort::OUT_OF_MEMORY));
    }

    #[test]
    fn e144_ring_overwrites_oldest_at_21() {
        let mut h = DiagHistory::new();
        for n in 1..=20 {
            h.push(msg(n), Nanos::from_ns(u64::from(n)));
        }
        assert_eq!(h.newest_subindex(), 25);
        assert_eq!(code_at(&h, 6), 1);
        h.push(msg(21), Nanos::from_ns(21));
        // Newest wraps to 06h; the oldest (message 2) now sits in 07h.
        assert_eq!(h.newest_subindex(), 6);
        assert_eq!(code_at(&h, 6), 21);
        assert_eq!(code_at(&h, 7), 2);
        assert_eq!(code_at(&h, 25), 20);
        for n in 22..=45 {
            h.push(msg(n), Nanos::ZERO);
        }
        assert_eq!(h.newest_subindex(), 6 + (45 - 1) % 20);
        assert!((6..=25).all(|s| h.message(s).is_some()));
    }

    #[test]
    fn e145_new_history_is_empty() {
        let h = DiagHistory::default();
        assert_eq!(h.newest_subindex(), 0);
        assert_eq!(h.newest_acknowledged_subindex(), 0);
        assert!(!h.new_messages());
        assert!((6..=25).all(|s| h.message(s).is_none()));
    }

    #[test]
    fn e146_acknowledge_and_new_flag() {
        let mut h = DiagHistory::new();
        for n in 1..=3 {
            h.push(msg(n), Nanos::ZERO);
        }
        assert!(h.new_messages());
        assert_eq!(read_u8(&h, 4), 1);
        // Acknowledge up to message 2 (sub 07h): message 3 is still new.
        assert_eq!(h.write(3, &[7]), Ok(()));
        assert_eq!(read_u8(&h, 3), 7);
        assert!(h.new_messages());
        assert_eq!(h.write(3, &[8]), Ok(()));
        assert!(!h.new_messages());
        assert_eq!(read_u8(&h, 4), 0);
        h.push(msg(4), Nanos::ZERO);
        assert!(h.new_messages());
        assert_eq!(read_u8(&h, 3), 8);

        assert_eq!(h.write(3, &[9]), Ok(()));
        assert_eq!(h.write(3, &[10]), Err(SdoAbort::INVALID_VALUE), "empty slot");
        assert_eq!(h.write(3, &[5]), Err(SdoAbort::VALUE_TOO_LOW));
        assert_eq!(h.write(3, &[1]), Err(SdoAbort::VALUE_TOO_LOW));
        assert_eq!(h.write(3, &[26]), Err(SdoAbort::VALUE_TOO_HIGH));
        assert_eq!(h.write(3, &[]), Err(SdoAbort::LENGTH_TOO_LOW));
        assert_eq!(h.write(3, &[6, 0]), Err(SdoAbort::LENGTH_TOO_HIGH));
        for sub in [0, 1, 2, 4, 6, 25] {
            assert_eq!(h.write(sub, &[0]), Err(SdoAbort::READ_ONLY), "sub {sub}");
        }
        assert_eq!(h.write(26, &[0]), Err(SdoAbort::NO_SUBINDEX));

        // Writing 0 deletes everything; numbering continues.
        assert_eq!(h.write(3, &[0]), Ok(()));
        assert_eq!((h.newest_subindex(), h.newest_acknowledged_subindex()), (0, 0));
        assert!(!h.new_messages());
        h.push(msg(5), Nanos::ZERO);
        assert_eq!(h.newest_subindex(), 10);
        assert!(h.new_messages());
    }

    #[test]
    fn e146_overwriting_unacknowledged_resets_ack() {
        let mut h = DiagHistory::new();
        for n in 1..=20 {
            h.push(msg(n), Nanos::ZERO);
        }
        // All acknowledged: overwriting acknowledged messages keeps the ack state.
        h.write(3, &[25]).unwrap();
        h.push(msg(21), Nanos::ZERO);
        assert_eq!(h.newest_acknowledged_subindex(), 25);
        assert_eq!(h.flags() & flags::OVERWRITTEN, 0);
        // 20 more: message 21 (unacknowledged) is overwritten.
        for n in 22..=41 {
            h.push(msg(n), Nanos::ZERO);
        }
        assert_eq!(h.newest_acknowledged_subindex(), 0);
        assert_ne!(h.flags() & flags::OVERWRITTEN, 0);
        h.write(3, &[0]).unwrap();
        assert_eq!(h.flags() & flags::OVERWRITTEN, 0);
    }

    #[test]
    fn e146_type_filter_and_ignored_flag_clears() {
        let mut h = DiagHistory::new();
        // Try to disable emergencies, select acknowledge mode and filter warnings.
        h.write(5, &(flags::ACK_MODE | flags::DISABLE_WARNING).to_le_bytes())
            .unwrap();
        assert_eq!(h.flags(), flags::EMERGENCY | flags::DISABLE_WARNING);
        assert!(!h.push(DiagMessage::new(1, DiagType::Warning, 0), Nanos::ZERO));
        assert_eq!(h.newest_subindex(), 0);
        assert!(h.push(DiagMessage::new(2, DiagType::Info, 0), Nanos::ZERO));
        assert!(h.push(DiagMessage::new(3, DiagType::Error, 0), Nanos::ZERO));
        h.write(5, &(flags::DISABLE_INFO | flags::DISABLE_ERROR).to_le_bytes())
            .unwrap();
        assert!(!h.push(DiagMessage::new(4, DiagType::Info, 0), Nanos::ZERO));
        assert!(!h.push(DiagMessage::new(5, DiagType::Error, 0), Nanos::ZERO));
        assert!(h.push(DiagMessage::new(6, DiagType::Warning, 0), Nanos::ZERO));
        assert_eq!(h.newest_subindex(), 8);
        assert_eq!(h.write(5, &[0]), Err(SdoAbort::LENGTH_TOO_LOW));
        h.write(5, &0u16.to_le_bytes()).unwrap();
        assert_eq!(h.flags(), flags::EMERGENCY);
    }
}
