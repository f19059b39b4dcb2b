//! The acyclic real-time alarm channel (RTA over the alarm CR, P-043) and the
//! diagnosis alarms of drive errors (P-030…P-035).
//!
//! - [`rta`]: the RTA-PDU header (DATA / NACK / ACK / ERR), sequence numbers.
//! - [`blocks`]: the AlarmNotification and AlarmAck blocks, AlarmSpecifier,
//!   ChannelProperties and the extended channel diagnosis item (USI 0x8002).
//! - [`cr`]: [`AlarmCr`], the alarm CR of one AR: a high and a low priority
//!   channel, each with one outstanding alarm, transport ACK (TACK),
//!   retransmission after RTATimeoutFactor × 100 ms up to RTARetries, then AR
//!   abort; the controller's AlarmAck ends an alarm.
//! - [`diag`]: [`DiagList`], the bounded list of active drive errors (HH-S)
//!   that yields "appears" and "disappears" alarms in order and writes the
//!   diagnosis records (0x800A, 0xC00A, 0xE00C, …).
//!
//! Encoding of a drive error HH-S (spec §2.7, Q-13 decided: binary):
//! ChannelErrorType = 0x1000 + HH (22 → 0x1016), ExtChannelErrorType =
//! 0x1000 + S, on ChannelNumber 0x8000 (the whole submodule).

pub mod blocks;
pub mod cr;
pub mod diag;
pub mod rta;

pub use blocks::{
    AlarmAck, AlarmSpecifier, AlarmType, ChannelDirection, ChannelProperties, DiagItem, Maintenance,
    Notification, Specifier,
};
pub use cr::{AlarmCr, AlarmCrConfig, AlarmEvent, AlarmStats, Output, RtaError, SendError};
pub use diag::{DiagFilter, DiagFull, DiagList, DiagScope, DriveError, Location, RecordError};
pub use rta::{PduType, RtaHeader};

/// Alarm priority: the channel (FrameID 0xFC01 high, 0xFE01 low) and the
/// block types (0x0001/0x8001 high, 0x0002/0x8002 low).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Priority {
    /// High priority.
    High,
    /// Low priority (diagnosis alarms).
    Low,
}

impl Priority {
    /// Its FrameID.
    pub const fn frame_id(self) -> u16 {
        match self {
            Priority::High => 0xFC01,
            Priority::Low => 0xFE01,
        }
    }
    /// Its AlarmNotification block type.
    pub const fn notification_block(self) -> u16 {
        match self {
            Priority::High => 0x0001,
            Priority::Low => 0x0002,
        }
    }
    /// Its AlarmAck block type.
    pub const fn ack_block(self) -> u16 {
        match self {
            Priority::High => 0x8001,
            Priority::Low => 0x8002,
        }
    }
}

/// PNIOStatus: ErrorCode, ErrorDecode, ErrorCode1, ErrorCode2.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PnioStatus(pub [u8; 4]);

impl PnioStatus {
    /// All zero: OK.
    pub const OK: PnioStatus = PnioStatus([0; 4]);

    /// The status of an ERR-RTA-PDU that aborts an AR: ErrorCode 0xCF (RTA
    /// error), ErrorDecode 0x81 (PNIO), ErrorCode1 0xFD (RTA_ERR_CLS_PROTOCOL),
    /// ErrorCode2 the abort code.
    pub const fn rta_abort(code: AbortCode) -> PnioStatus {
        PnioStatus([0xCF, 0x81, 0xFD, code.0])
    }

    /// `true` for OK.
    pub const fn is_ok(self) -> bool {
        u32::from_be_bytes(self.0) == 0
    }
}

/// ErrorCode2 of an AR abort (with ErrorCode1 RTA_ERR_CLS_PROTOCOL), IEC
/// 61158-6-10.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AbortCode(pub u8);

impl AbortCode {
    /// Sequence number error (RTA).
    pub const CODE_SEQ: AbortCode = AbortCode(0x01);
    /// Instance closed.
    pub const INSTANCE_CLOSED: AbortCode = AbortCode(0x02);
    /// Consumer DHT / watchdog expired (our [`crate::rt::ConsumerEvent::WatchdogExpired`]).
    pub const CONSUMER_DHT_EXPIRED: AbortCode = AbortCode(0x05);
    /// CMI timeout.
    pub const CMI_TIMEOUT: AbortCode = AbortCode(0x06);
    /// An alarm was not transport-acknowledged after all retries.
    pub const ALARM_SEND_CNF_NEG: AbortCode = AbortCode(0x08);
    /// An alarm acknowledgement was not transport-acknowledged.
    pub const ALARM_ACK_SEND_CNF_NEG: AbortCode = AbortCode(0x09);
    /// Alarm data too long.
    pub const ALARM_DATA_TOO_LONG: AbortCode = AbortCode(0x0A);
    /// Alarm indication error.
    pub const ALARM_IND_ERROR: AbortCode = AbortCode(0x0B);
    /// Abort requested by the application.
    pub const ABORT_REQ: AbortCode = AbortCode(0x0D);
    /// Protocol violation.
    pub const PROTOCOL_VIOLATION: AbortCode = AbortCode(0x12);
    /// Link down.
    pub const LINK_DOWN: AbortCode = AbortCode(0x1B);
}

#[cfg(test)]
mod tests_cr;
#[cfg(test)]
mod tests_diag;
#[cfg(test)]
mod tests_records;
#[cfg(test)]
mod tests_vectors;
