//! The alarm CR of one AR: two RTA channels (high, low), each the sender
//! (APMS) and receiver (APMR) of IEC 61158-6-10 with window size 1.
//!
//! Sending: [`AlarmCr::send`] takes one alarm per priority; it goes out as a
//! DATA-RTA-PDU with TACK at the next [`AlarmCr::poll`], is retransmitted
//! every RTATimeoutFactor × 100 ms until the controller's ACK (or a DATA
//! carrying its AckSeqNum) confirms it, RTARetries times at most; then the AR
//! is aborted ([`AlarmEvent::Abort`] with
//! [`AbortCode::ALARM_SEND_CNF_NEG`], and an ERR-RTA-PDU). The alarm stays
//! outstanding until the controller's AlarmAck (a DATA of its own, which we
//! transport-acknowledge) names it: [`AlarmEvent::Acked`].
//!
//! Receiving: a DATA with the expected SendSeqNum is taken and ACKed; a
//! repeat of the last one is ACKed again; any other number is NACKed. An ERR
//! from the controller ends the AR ([`AlarmEvent::ErrReceived`]).

use super::blocks::{AlarmAck, Notification};
use super::rta::{next_seq, PduType, RtaHeader, HEADER_LEN, SEQ_START, SEQ_START_O};
use super::{AbortCode, PnioStatus, Priority};
use crate::wire::{emit_header, ethertype, split_frame_id, EthFrame, FrameKind, MacAddr, MIN_FRAME_LEN};
use nanos::Nanos;

/// The alarm CR's parameters, as the connection management takes them from
/// the AlarmCRBlockReq (and our AlarmCRBlockRes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AlarmCrConfig {
    /// Our LocalAlarmReference (AlarmCRBlockRes): the controller's
    /// AlarmDstEndpoint.
    pub local_ref: u16,
    /// The controller's LocalAlarmReference: our AlarmDstEndpoint.
    pub remote_ref: u16,
    /// RTATimeoutFactor (1…100): the retransmission timeout in 100 ms.
    pub rta_timeout_factor: u16,
    /// RTARetries (3…15).
    pub rta_retries: u16,
    /// MaxAlarmDataLength (200…1432): longest alarm block we may send.
    pub max_alarm_data_length: u16,
    /// AlarmCRProperties.Priority = 1: every alarm goes low priority.
    pub only_low_priority: bool,
    /// AlarmCRTagHeaderHigh as 802.1Q TCI (0xC000: priority 6), `None` untagged.
    pub tag_high: Option<u16>,
    /// AlarmCRTagHeaderLow as 802.1Q TCI (0xA000: priority 5), `None` untagged.
    pub tag_low: Option<u16>,
    /// Our MAC.
    pub local: MacAddr,
    /// The controller's MAC.
    pub remote: MacAddr,
}

impl AlarmCrConfig {
    /// The retransmission timeout.
    pub const fn timeout(&self) -> Nanos {
        Nanos::from_ms(self.rta_timeout_factor as u64 * 100)
    }

    /// Checks RTATimeoutFactor, RTARetries and MaxAlarmDataLength.
    pub fn validate(&self) -> Result<(), RtaError> {
        let ok = (1..=100).contains(&self.rta_timeout_factor)
            && (3..=15).contains(&self.rta_retries)
            && (200..=1432).contains(&self.max_alarm_data_length);
        if ok {
            Ok(())
        } else {
            Err(RtaError::Config)
        }
    }
}

/// What the alarm CR reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AlarmEvent {
    /// The controller acknowledged our alarm: the channel is free again.
    Acked {
        /// The channel.
        priority: Priority,
        /// The acknowledged alarm.
        notification: Notification,
        /// The controller's PNIOStatus (OK, or a negative acknowledgement).
        status: PnioStatus,
    },
    /// We abort the AR (the ERR-RTA-PDU goes out at the next poll).
    Abort(AbortCode),
    /// The controller sent an ERR-RTA-PDU: the AR is gone.
    ErrReceived(PnioStatus),
}

/// What [`AlarmCr::poll`] yields.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Output {
    /// A frame of this many bytes is in the buffer: send it.
    Frame(usize),
    /// Something happened.
    Event(AlarmEvent),
}

/// Why a received frame was refused (counted, no state change unless
/// said).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RtaError {
    /// Not an alarm frame (EtherType, FrameID).
    NotAlarm,
    /// Wrong source or destination MAC.
    WrongAddress,
    /// Malformed RTA header (length, type, version).
    Malformed,
    /// AlarmDstEndpoint / AlarmSrcEndpoint not this CR's.
    WrongEndpoint,
    /// SendSeqNum neither the expected nor the last one: NACKed.
    Sequence,
    /// A DATA whose block is not an AlarmAck of its priority (ACKed, dropped).
    UnexpectedBlock,
    /// An AlarmAck for no outstanding alarm (ACKed, dropped).
    UnexpectedAck,
    /// The CR is closed.
    Closed,
    /// An invalid configuration.
    Config,
}

/// Why [`AlarmCr::send`] refused an alarm.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SendError {
    /// An alarm of that priority is still outstanding.
    Busy,
    /// Longer than MaxAlarmDataLength.
    TooLong,
    /// The CR is closed.
    Closed,
}

/// Counters (wrapping).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AlarmStats {
    /// Alarms sent (first transmissions).
    pub sent: u32,
    /// Retransmissions.
    pub retransmitted: u32,
    /// Alarms acknowledged by the controller.
    pub acked: u32,
    /// NACKs received.
    pub nacks_received: u32,
    /// Frames refused ([`RtaError`]).
    pub refused: u32,
}

#[derive(Clone, Copy, Debug)]
struct Pending {
    notification: Notification,
    /// Retransmissions left.
    retries: u16,
    /// When to retransmit.
    deadline: Nanos,
    /// Transport-acknowledged.
    tacked: bool,
    /// To (re)transmit at the next poll.
    due: bool,
}

#[derive(Clone, Copy, Debug)]
struct Channel {
    priority: Priority,
    send_seq: u16,
    send_seq_o: u16,
    exp_seq: u16,
    exp_seq_o: u16,
    alarm_seq: u16,
    pending: Option<Pending>,
    ack_due: bool,
    nack_due: bool,
}

impl Channel {
    const fn new(priority: Priority) -> Channel {
        Channel {
            priority,
            send_seq: SEQ_START,
            send_seq_o: SEQ_START_O,
            exp_seq: SEQ_START,
            exp_seq_o: SEQ_START_O,
            alarm_seq: 0,
            pending: None,
            ack_due: false,
            nack_due: false,
        }
    }

    /// A DATA or ACK carrying `ack_seq` confirms our outstanding DATA.
    fn take_ack_seq(&mut self, ack_seq: u16) {
        if let Some(p) = self.pending.as_mut() {
            if !p.tacked && ack_seq == self.send_seq {
                p.tacked = true;
                p.due = false;
                self.send_seq_o = self.send_seq;
                self.send_seq = next_seq(self.send_seq);
            }
        }
    }
}

/// The alarm CR of one AR.
#[derive(Clone, Debug)]
pub struct AlarmCr {
    cfg: AlarmCrConfig,
    high: Channel,
    low: Channel,
    closed: bool,
    err_due: Option<AbortCode>,
    stats: AlarmStats,
}

impl AlarmCr {
    /// The alarm CR for `cfg` ([`AlarmCrConfig::validate`]).
    pub fn new(cfg: AlarmCrConfig) -> Result<AlarmCr, RtaError> {
        cfg.validate()?;
        Ok(AlarmCr {
            cfg,
            high: Channel::new(Priority::High),
            low: Channel::new(Priority::Low),
            closed: false,
            err_due: None,
            stats: AlarmStats::default(),
        })
    }

    /// Its configuration.
    pub fn config(&self) -> &AlarmCrConfig {
        &self.cfg
    }

    /// Its counters.
    pub fn stats(&self) -> &AlarmStats {
        &self.stats
    }

    /// Closed (aborted, or the controller's ERR).
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// The channel an alarm of `priority` uses (low if the CR allows only low).
    pub fn effective(&self, priority: Priority) -> Priority {
        if self.cfg.only_low_priority {
            Priority::Low
        } else {
            priority
        }
    }

    fn channel(&mut self, p: Priority) -> &mut Channel {
        match self.effective(p) {
            Priority::High => &mut self.high,
            Priority::Low => &mut self.low,
        }
    }

    /// An alarm of `priority` may be sent now (none outstanding).
    pub fn can_send(&self, priority: Priority) -> bool {
        let ch = match self.effective(priority) {
            Priority::High => &self.high,
            Priority::Low => &self.low,
        };
        !self.closed && ch.pending.is_none()
    }

    /// Queues an alarm; it goes out at the next [`AlarmCr::poll`]. The CR
    /// sets its priority (the effective one) and AlarmSpecifier sequence
    /// number; returns the notification as it will be sent.
    pub fn send(&mut self, now: Nanos, n: &Notification) -> Result<Notification, SendError> {
        if self.closed {
            return Err(SendError::Closed);
        }
        if n.len() > self.cfg.max_alarm_data_length as usize {
            return Err(SendError::TooLong);
        }
        let priority = self.effective(n.priority);
        let retries = self.cfg.rta_retries;
        let timeout = self.cfg.timeout();
        let ch = self.channel(priority);
        if ch.pending.is_some() {
            return Err(SendError::Busy);
        }
        let mut n = *n;
        n.priority = priority;
        n.specifier = n.specifier.with_sequence(ch.alarm_seq);
        ch.alarm_seq = (ch.alarm_seq + 1) & 0x07FF;
        ch.pending = Some(Pending {
            notification: n,
            retries,
            deadline: now.saturating_add(timeout),
            tacked: false,
            due: true,
        });
        self.stats.sent = self.stats.sent.wrapping_add(1);
        Ok(n)
    }

    /// Aborts the AR from our side: an ERR-RTA-PDU with `code` goes out (low
    /// priority) at the next poll; the CR is closed afterwards.
    pub fn abort(&mut self, code: AbortCode) {
        if !self.closed {
            self.closed = true;
            self.err_due = Some(code);
        }
    }

    /// Takes a received alarm frame (FrameID 0xFC01 / 0xFE01).
    pub fn receive(&mut self, now: Nanos, frame: &EthFrame<'_>) -> Result<Option<AlarmEvent>, RtaError> {
        let r = self.receive_inner(now, frame);
        if r.is_err() {
            self.stats.refused = self.stats.refused.wrapping_add(1);
        }
        r
    }

    fn receive_inner(&mut self, _now: Nanos, frame: &EthFrame<'_>) -> Result<Option<AlarmEvent>, RtaError> {
        if frame.ethertype != ethertype::PROFINET {
            return Err(RtaError::NotAlarm);
        }
        let (kind, rest) = split_frame_id(frame.payload).ok_or(RtaError::NotAlarm)?;
        let priority = match kind {
            FrameKind::AlarmHigh => Priority::High,
            FrameKind::AlarmLow => Priority::Low,
            _ => return Err(RtaError::NotAlarm),
        };
        if frame.src != self.cfg.remote || frame.dst != self.cfg.local {
            return Err(RtaError::WrongAddress);
        }
        let (h, var) = RtaHeader::parse(rest).map_err(|_| RtaError::Malformed)?;
        if h.dst_endpoint != self.cfg.local_ref || h.src_endpoint != self.cfg.remote_ref {
            return Err(RtaError::WrongEndpoint);
        }
        if self.closed {
            return Err(RtaError::Closed);
        }
        let ch = match priority {
            Priority::High => &mut self.high,
            Priority::Low => &mut self.low,
        };
        match h.pdu_type {
            PduType::Ack => {
                ch.take_ack_seq(h.ack_seq);
                Ok(None)
            }
            PduType::Nack => {
                // window 1: the retransmission timer repeats the DATA
                self.stats.nacks_received = self.stats.nacks_received.wrapping_add(1);
                Ok(None)
            }
            PduType::Err => {
                let status = var.first_chunk::<4>().map_or(PnioStatus::OK, |s| PnioStatus(*s));
                self.closed = true;
                Ok(Some(AlarmEvent::ErrReceived(status)))
            }
            PduType::Data if !h.tack => Ok(None),
            PduType::Data if h.send_seq == ch.exp_seq => {
                ch.take_ack_seq(h.ack_seq);
                ch.exp_seq_o = ch.exp_seq;
                ch.exp_seq = next_seq(ch.exp_seq);
                ch.ack_due = true;
                let ack = AlarmAck::parse(var)
                    .filter(|a| a.priority == ch.priority)
                    .ok_or(RtaError::UnexpectedBlock)?;
                let p = ch
                    .pending
                    .filter(|p| ack.matches(&p.notification))
                    .ok_or(RtaError::UnexpectedAck)?;
                ch.pending = None;
                self.stats.acked = self.stats.acked.wrapping_add(1);
                Ok(Some(AlarmEvent::Acked {
                    priority,
                    notification: p.notification,
                    status: ack.status,
                }))
            }
            PduType::Data if h.send_seq == ch.exp_seq_o => {
                // a repeat of what we took: ACK it again
                ch.take_ack_seq(h.ack_seq);
                ch.ack_due = true;
                Ok(None)
            }
            PduType::Data => {
                ch.nack_due = true;
                Err(RtaError::Sequence)
            }
        }
    }

    /// What is due at `now`: an ERR, ACKs and NACKs, (re)transmissions, an
    /// abort after the last retry. Call until `None`; a frame is written into
    /// `buf` (at least 60 bytes long; shorter buffers get nothing).
    pub fn poll(&mut self, now: Nanos, buf: &mut [u8]) -> Option<Output> {
        if let Some(code) = self.err_due.take() {
            let status = PnioStatus::rta_abort(code);
            let ch = self.low;
            let h = self.header(PduType::Err, false, ch.send_seq, ch.exp_seq_o, 4);
            let out = self.emit(buf, Priority::Low, &h, |b| {
                b.get_mut(..4).map(|d| d.copy_from_slice(&status.0))
            });
            if out.is_none() {
                self.err_due = Some(code);
            }
            return out;
        }
        if self.closed {
            return None;
        }
        for p in [Priority::High, Priority::Low] {
            if let Some(out) = self.poll_channel(now, p, buf) {
                return Some(out);
            }
        }
        None
    }

    fn poll_channel(&mut self, now: Nanos, p: Priority, buf: &mut [u8]) -> Option<Output> {
        let timeout = self.cfg.timeout();
        let mut ch = match p {
            Priority::High => self.high,
            Priority::Low => self.low,
        };
        let out = if ch.ack_due || ch.nack_due {
            let t = if ch.ack_due { PduType::Ack } else { PduType::Nack };
            ch.ack_due = false;
            ch.nack_due = false;
            let h = self.header(t, false, ch.send_seq_o, ch.exp_seq_o, 0);
            self.emit(buf, p, &h, |_| Some(()))
        } else if let Some(mut pend) = ch.pending.filter(|x| !x.tacked) {
            let retransmit = !pend.due && now >= pend.deadline;
            if retransmit && pend.retries == 0 {
                ch.pending = None;
                self.abort(AbortCode::ALARM_SEND_CNF_NEG);
                Some(Output::Event(AlarmEvent::Abort(AbortCode::ALARM_SEND_CNF_NEG)))
            } else if pend.due || retransmit {
                if retransmit {
                    pend.retries -= 1;
                    self.stats.retransmitted = self.stats.retransmitted.wrapping_add(1);
                }
                pend.due = false;
                pend.deadline = now.saturating_add(timeout);
                ch.pending = Some(pend);
                let n = pend.notification;
                let len = n.len() as u16;
                let h = self.header(PduType::Data, true, ch.send_seq, ch.exp_seq_o, len);
                self.emit(buf, p, &h, |b| n.emit(b).map(|_| ()))
            } else {
                None
            }
        } else {
            None
        };
        if out.is_some() {
            match p {
                Priority::High => self.high = ch,
                Priority::Low => self.low = ch,
            }
        }
        out
    }

    /// When [`AlarmCr::poll`] must run next: now if something is due, the
    /// earliest retransmission deadline, or [`Nanos::MAX`].
    pub fn poll_at(&self, now: Nanos) -> Nanos {
        if self.err_due.is_some() {
            return now;
        }
        if self.closed {
            return Nanos::MAX;
        }
        [self.high, self.low]
            .iter()
            .map(|ch| {
                if ch.ack_due || ch.nack_due {
                    return now;
                }
                match ch.pending {
                    Some(p) if p.due => now,
                    Some(p) if !p.tacked => p.deadline,
                    _ => Nanos::MAX,
                }
            })
            .min()
            .unwrap_or(Nanos::MAX)
    }

    fn header(
        &self,
        pdu_type: PduType,
        tack: bool,
        send_seq: u16,
        ack_seq: u16,
        var_part_len: u16,
    ) -> RtaHeader {
        RtaHeader {
            dst_endpoint: self.cfg.remote_ref,
            src_endpoint: self.cfg.local_ref,
            pdu_type,
            window: 1,
            tack,
            send_seq,
            ack_seq,
            var_part_len,
        }
    }

    /// Ethernet header, FrameID, RTA header, var part (by `var`), padding to 60.
    fn emit(
        &self,
        buf: &mut [u8],
        p: Priority,
        h: &RtaHeader,
        var: impl FnOnce(&mut [u8]) -> Option<()>,
    ) -> Option<Output> {
        let tag = match p {
            Priority::High => self.cfg.tag_high,
            Priority::Low => self.cfg.tag_low,
        };
        let at = emit_header(buf, self.cfg.remote, self.cfg.local, tag, ethertype::PROFINET)?;
        let body = buf.get_mut(at..)?;
        body.get_mut(..2)?.copy_from_slice(&p.frame_id().to_be_bytes());
        h.emit(body.get_mut(2..)?)?;
        let var_at = 2 + HEADER_LEN;
        let var_len = h.var_part_len as usize;
        var(body.get_mut(var_at..var_at + var_len)?)?;
        let end = at + var_at + var_len;
        let len = end.max(MIN_FRAME_LEN);
        buf.get_mut(end..len)?.fill(0);
        Some(Output::Frame(len))
    }
}
