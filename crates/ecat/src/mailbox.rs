//! Mailbox data-link layer (ETG.1000.4 §5.6, ETG.1000.6 §5.6): the 6-byte
//! mailbox header and the mailbox error reply.

/// Length of the mailbox header.
pub const HEADER_LEN: usize = 6;

/// Mailbox protocol types (header byte 5, bits 0..3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MailboxType {
    /// Mailbox error reply (0).
    Error,
    /// ADS over EtherCAT (1).
    Aoe,
    /// Ethernet over EtherCAT (2).
    Eoe,
    /// CAN application protocol over EtherCAT (3).
    Coe,
    /// File access over EtherCAT (4).
    Foe,
    /// Servo profile over EtherCAT (5).
    Soe,
    /// Vendor specific (15).
    Voe,
    /// Reserved codes 6..14.
    Reserved(u8),
}

impl MailboxType {
    /// Decodes the 4-bit type.
    pub const fn from_code(code: u8) -> Self {
        match code & 0x0F {
            0 => MailboxType::Error,
            1 => MailboxType::Aoe,
            2 => MailboxType::Eoe,
            3 => MailboxType::Coe,
            4 => MailboxType::Foe,
            5 => MailboxType::Soe,
            15 => MailboxType::Voe,
            c => MailboxType::Reserved(c),
        }
    }

    /// The 4-bit type code.
    pub const fn code(self) -> u8 {
        match self {
            MailboxType::Error => 0,
            MailboxType::Aoe => 1,
            MailboxType::Eoe => 2,
            MailboxType::Coe => 3,
            MailboxType::Foe => 4,
            MailboxType::Soe => 5,
            MailboxType::Voe => 15,
            MailboxType::Reserved(c) => c & 0x0F,
        }
    }
}

/// The parsed mailbox header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MailboxHeader {
    /// Bytes of data after the header.
    pub length: u16,
    /// Station address of the source (master: 0).
    pub address: u16,
    /// Channel (bits 0..5).
    pub channel: u8,
    /// Priority (bits 6..7).
    pub priority: u8,
    /// Protocol.
    pub kind: MailboxType,
    /// Counter 1..7 (0 = not used).
    pub counter: u8,
}

impl MailboxHeader {
    /// Parses the header at the start of `buf`; `None` when `buf` is shorter than
    /// the header. Checks against the buffer length are [`MailboxHeader::check`]'s.
    pub fn parse(buf: &[u8]) -> Option<Self> {
        match buf.get(..HEADER_LEN)? {
            &[l0, l1, a0, a1, ch, ty] => Some(Self {
                length: u16::from_le_bytes([l0, l1]),
                address: u16::from_le_bytes([a0, a1]),
                channel: ch & 0x3F,
                priority: ch >> 6,
                kind: MailboxType::from_code(ty),
                counter: (ty >> 4) & 0x07,
            }),
            _ => None,
        }
    }

    /// Checks the header of a request read from a mailbox of `buf_len` bytes and
    /// returns the header, or the mailbox error code to reply with.
    pub fn check(buf: &[u8]) -> Result<Self, MailboxError> {
        let h = Self::parse(buf).ok_or(MailboxError::SIZE_TOO_SHORT)?;
        if usize::from(h.length) > buf.len() - HEADER_LEN {
            return Err(MailboxError::INVALID_SIZE);
        }
        if h.length == 0 {
            return Err(MailboxError::SIZE_TOO_SHORT);
        }
        if h.channel != 0 {
            return Err(MailboxError::INVALID_CHANNEL);
        }
        match h.kind {
            MailboxType::Error => Err(MailboxError::INVALID_HEADER),
            // a type the slave does not speak (issue 33: what masters
            // expect, not the header syntax error 0001h)
            MailboxType::Reserved(_) => Err(MailboxError::UNSUPPORTED_PROTOCOL),
            _ => Ok(h),
        }
    }

    /// The 6 header bytes.
    pub fn to_bytes(&self) -> [u8; HEADER_LEN] {
        let [l0, l1] = self.length.to_le_bytes();
        let [a0, a1] = self.address.to_le_bytes();
        [
            l0,
            l1,
            a0,
            a1,
            (self.channel & 0x3F) | (self.priority << 6),
            self.kind.code() | ((self.counter & 0x07) << 4),
        ]
    }

    /// The data after the header (`length` bytes), when `buf` holds them.
    pub fn payload<'a>(&self, buf: &'a [u8]) -> Option<&'a [u8]> {
        buf.get(HEADER_LEN..HEADER_LEN + usize::from(self.length))
    }
}

/// Mailbox error reply detail codes (ETG.1000.4 Table 30).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MailboxError(pub u16);

impl MailboxError {
    /// 0001h Syntax of the 6-octet header is wrong.
    pub const SYNTAX: Self = Self(0x0001);
    /// 0002h The mailbox protocol is not supported.
    pub const UNSUPPORTED_PROTOCOL: Self = Self(0x0002);
    /// 0003h Channel field contains a wrong value.
    pub const INVALID_CHANNEL: Self = Self(0x0003);
    /// 0004h The service in the mailbox protocol is not supported.
    pub const SERVICE_NOT_SUPPORTED: Self = Self(0x0004);
    /// 0005h The mailbox protocol header is wrong.
    pub const INVALID_HEADER: Self = Self(0x0005);
    /// 0006h Length of received mailbox data is too short.
    pub const SIZE_TOO_SHORT: Self = Self(0x0006);
    /// 0007h Mailbox protocol cannot be processed (no memory).
    pub const NO_MORE_MEMORY: Self = Self(0x0007);
    /// 0008h The length of the data is inconsistent.
    pub const INVALID_SIZE: Self = Self(0x0008);

    /// The error reply's data (type = ERR): service 0001h, detail code.
    pub fn to_bytes(self) -> [u8; 4] {
        let [d0, d1] = self.0.to_le_bytes();
        [0x01, 0x00, d0, d1]
    }
}

/// The next counter in the cycle 1..7 (never 0).
pub const fn next_counter(c: u8) -> u8 {
    if c >= 7 {
        1
    } else {
        c + 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mailbox_header_round_trip() {
        let h = MailboxHeader {
            length: 10,
            address: 0x1001,
            channel: 0,
            priority: 2,
            kind: MailboxType::Coe,
            counter: 5,
        };
        let b = h.to_bytes();
        assert_eq!(b, [10, 0, 0x01, 0x10, 0x80, 0x53]);
        assert_eq!(MailboxHeader::parse(&b), Some(h));
        assert_eq!(MailboxHeader::parse(&b[..5]), None);
    }

    #[test]
    fn mailbox_header_check_codes() {
        let mut buf = [0u8; 32];
        buf[..6].copy_from_slice(&[27, 0, 0, 0, 0, 0x13]);
        assert_eq!(MailboxHeader::check(&buf), Err(MailboxError::INVALID_SIZE));
        buf[0] = 26;
        assert!(MailboxHeader::check(&buf).is_ok());
        buf[0] = 0;
        assert_eq!(MailboxHeader::check(&buf), Err(MailboxError::SIZE_TOO_SHORT));
        buf[0] = 4;
        buf[4] = 1;
        assert_eq!(MailboxHeader::check(&buf), Err(MailboxError::INVALID_CHANNEL));
        buf[4] = 0;
        for ty in 6..=14u8 {
            buf[5] = 0x10 | ty;
            assert_eq!(
                MailboxHeader::check(&buf),
                Err(MailboxError::UNSUPPORTED_PROTOCOL),
                "reserved type {ty}"
            );
        }
        assert_eq!(MailboxHeader::check(&buf[..3]), Err(MailboxError::SIZE_TOO_SHORT));
    }

    #[test]
    fn counter_cycles_1_to_7() {
        let mut c = 0;
        let mut seen = [0u8; 8];
        for _ in 0..14 {
            c = next_counter(c);
            seen[c as usize] += 1;
        }
        assert_eq!(seen, [0, 2, 2, 2, 2, 2, 2, 2]);
    }
}
