//! The RTA-PDU header: `AlarmDstEndpoint (2) | AlarmSrcEndpoint (2) |
//! PDUType (1: type bits 0…3, version bits 4…7) | AddFlags (1: WindowSize bits
//! 0…3, TACK bit 4) | SendSeqNum (2) | AckSeqNum (2) | VarPartLen (2)`, then
//! the var part (an alarm block for DATA, a PNIOStatus for ERR, nothing for
//! ACK and NACK).
//!
//! Sequence numbers: both sides start with SendSeqNum 0xFFFF (and a last
//! acknowledged 0xFFFE); after an acknowledged PDU the number advances
//! modulo 0x8000, so the sequence is 0xFFFF, 0, 1, … 0x7FFF, 0, …

/// Length of the RTA header.
pub const HEADER_LEN: usize = 12;
/// The first SendSeqNum (and expected sequence number).
pub const SEQ_START: u16 = 0xFFFF;
/// The "last acknowledged" value before the first PDU.
pub const SEQ_START_O: u16 = 0xFFFE;
/// The only PDU version.
pub const VERSION: u8 = 1;
/// AddFlags TACK bit.
pub const TACK: u8 = 0x10;

/// The sequence number after `seq` (0xFFFF → 0, 0x7FFF → 0).
pub const fn next_seq(seq: u16) -> u16 {
    seq.wrapping_add(1) & 0x7FFF
}

/// PDUType.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PduType {
    /// DATA-RTA-PDU (alarm notification or acknowledgement).
    Data = 1,
    /// NACK-RTA-PDU.
    Nack = 2,
    /// ACK-RTA-PDU (transport acknowledgement).
    Ack = 3,
    /// ERR-RTA-PDU (AR abort).
    Err = 4,
}

impl PduType {
    /// From the type nibble.
    pub const fn from_nibble(v: u8) -> Option<PduType> {
        match v {
            1 => Some(PduType::Data),
            2 => Some(PduType::Nack),
            3 => Some(PduType::Ack),
            4 => Some(PduType::Err),
            _ => None,
        }
    }
}

/// Why an RTA header was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HeaderError {
    /// Fewer than 12 bytes, or VarPartLen past the end.
    Truncated,
    /// Unknown PDU type.
    PduType,
    /// Version other than 1.
    Version,
}

/// A parsed RTA header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RtaHeader {
    /// AlarmDstEndpoint: the receiver's alarm reference.
    pub dst_endpoint: u16,
    /// AlarmSrcEndpoint: the sender's alarm reference.
    pub src_endpoint: u16,
    /// PDU type.
    pub pdu_type: PduType,
    /// WindowSize (1).
    pub window: u8,
    /// TACK: the receiver shall transport-acknowledge.
    pub tack: bool,
    /// SendSeqNum.
    pub send_seq: u16,
    /// AckSeqNum.
    pub ack_seq: u16,
    /// VarPartLen.
    pub var_part_len: u16,
}

impl RtaHeader {
    /// Parses the bytes after the FrameID; returns the header and its var
    /// part (padding after it is dropped).
    pub fn parse(b: &[u8]) -> Result<(RtaHeader, &[u8]), HeaderError> {
        let (h, rest) = b
            .split_first_chunk::<HEADER_LEN>()
            .ok_or(HeaderError::Truncated)?;
        let [d0, d1, s0, s1, pdu, flags, q0, q1, a0, a1, v0, v1] = *h;
        if pdu >> 4 != VERSION {
            return Err(HeaderError::Version);
        }
        let pdu_type = PduType::from_nibble(pdu & 0x0F).ok_or(HeaderError::PduType)?;
        let header = RtaHeader {
            dst_endpoint: u16::from_be_bytes([d0, d1]),
            src_endpoint: u16::from_be_bytes([s0, s1]),
            pdu_type,
            window: flags & 0x0F,
            tack: flags & TACK != 0,
            send_seq: u16::from_be_bytes([q0, q1]),
            ack_seq: u16::from_be_bytes([a0, a1]),
            var_part_len: u16::from_be_bytes([v0, v1]),
        };
        let var = rest
            .get(..header.var_part_len as usize)
            .ok_or(HeaderError::Truncated)?;
        Ok((header, var))
    }

    /// Writes the 12 header bytes; `None` if `buf` is shorter.
    pub fn emit(&self, buf: &mut [u8]) -> Option<usize> {
        let h = buf.first_chunk_mut::<HEADER_LEN>()?;
        let flags = (self.window & 0x0F) | if self.tack { TACK } else { 0 };
        let [d0, d1] = self.dst_endpoint.to_be_bytes();
        let [s0, s1] = self.src_endpoint.to_be_bytes();
        let [q0, q1] = self.send_seq.to_be_bytes();
        let [a0, a1] = self.ack_seq.to_be_bytes();
        let [v0, v1] = self.var_part_len.to_be_bytes();
        *h = [
            d0,
            d1,
            s0,
            s1,
            (VERSION << 4) | self.pdu_type as u8,
            flags,
            q0,
            q1,
            a0,
            a1,
            v0,
            v1,
        ];
        Some(HEADER_LEN)
    }
}
