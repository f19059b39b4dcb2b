//! The IO controller's side of the alarm CR (RTA, P-043), as profinet-py
//! answers the drive (`alarm_listener.AlarmListener`; its frames are the
//! vectors of `profinet::alarm`'s tests): every DATA-RTA-PDU of the drive is
//! transport-acknowledged at once (an ACK-RTA-PDU: SendSeqNum our last
//! acknowledged one, AckSeqNum the drive's), and an alarm notification in
//! it is answered with an AlarmAck DATA-RTA-PDU (TACK, the alarm's type,
//! location and specifier echoed, PNIOStatus OK) that the drive in turn
//! acknowledges. A repeat of the DATA last taken is ACKed again, not
//! acknowledged twice. Our AlarmAck is sent again after the alarm CR's
//! timeout while the drive has not ACKed it, RTARetries times at most.
//!
//! Sequence numbers as in [`profinet::alarm::rta`]: both sides start at
//! 0xFFFF and count modulo 0x8000 after each acknowledged PDU.

use nanos::Nanos;
use profinet::alarm::rta::{next_seq, SEQ_START, SEQ_START_O};
use profinet::alarm::{AlarmAck, AlarmSpecifier, PduType, PnioStatus, Priority, RtaHeader};
use profinet::wire::{emit_header, ethertype, split_frame_id, EthFrame, FrameKind, MacAddr, MIN_FRAME_LEN};

/// The controller's counters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AlarmStats {
    /// Alarm notifications taken (each once).
    pub received: u32,
    /// Repeats of a DATA already taken (ACKed again).
    pub repeated: u32,
    /// AlarmAcks sent (first transmissions).
    pub acknowledged: u32,
    /// AlarmAcks sent again (the drive's ACK did not come in time).
    pub retransmitted: u32,
    /// Our AlarmAcks the drive transport-acknowledged.
    pub confirmed: u32,
    /// Alarm frames not taken (not ours, malformed, out of sequence).
    pub refused: u32,
}

/// An AlarmAck waiting for the drive's ACK.
#[derive(Clone, Debug)]
struct Pending {
    frame: Vec<u8>,
    deadline: Nanos,
    retries: u16,
}

/// One priority's RTA state.
#[derive(Clone, Debug)]
struct Channel {
    /// The drive's next SendSeqNum, and the last one taken.
    exp_seq: u16,
    exp_seq_o: u16,
    /// Our next SendSeqNum, and the last one the drive acknowledged.
    send_seq: u16,
    send_seq_o: u16,
    pending: Option<Pending>,
}

impl Channel {
    const fn new() -> Channel {
        Channel {
            exp_seq: SEQ_START,
            exp_seq_o: SEQ_START_O,
            send_seq: SEQ_START,
            send_seq_o: SEQ_START_O,
            pending: None,
        }
    }
}

/// What one received alarm frame was.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Received {
    /// An alarm notification, acknowledged: its AlarmType, slot, subslot
    /// and sequence number.
    Alarm {
        /// AlarmType (0x0001 diagnosis, 0x000C diagnosis disappears, …).
        alarm_type: u16,
        /// SlotNumber.
        slot: u16,
        /// SubslotNumber.
        subslot: u16,
        /// The AlarmSpecifier's sequence number.
        sequence: u16,
    },
    /// The drive aborted the AR (ERR-RTA-PDU) with this PNIOStatus.
    Abort(PnioStatus),
    /// Anything else (ACK, a repeat, a refused frame).
    Other,
}

/// The controller's alarm endpoint of one AR.
#[derive(Clone, Debug)]
pub struct AlarmAcker {
    local: MacAddr,
    device: MacAddr,
    timeout: Nanos,
    retries: u16,
    high: Channel,
    low: Channel,
    stats: AlarmStats,
}

/// The AlarmAck of an AlarmNotification block (`var`): its priority (the
/// block type), AlarmType (at 6), API (8), slot (12), subslot (14) and
/// AlarmSpecifier (24) echoed, PNIOStatus OK.
fn notification_fields(var: &[u8]) -> Option<AlarmAck> {
    let be16 = |at: usize| var.get(at..at + 2).map(|b| u16::from_be_bytes([b[0], b[1]]));
    let priority = match be16(0)? {
        0x0001 => Priority::High,
        0x0002 => Priority::Low,
        _ => return None,
    };
    let api = var.get(8..12)?;
    Some(AlarmAck {
        priority,
        alarm_type: be16(6)?,
        api: u32::from_be_bytes([api[0], api[1], api[2], api[3]]),
        slot: be16(12)?,
        subslot: be16(14)?,
        specifier: AlarmSpecifier(be16(24)?),
        status: PnioStatus::OK,
    })
}

impl AlarmAcker {
    /// The endpoint of controller `local` towards `device`, with the alarm
    /// CR's retransmission timeout and RTARetries.
    pub fn new(local: MacAddr, device: MacAddr, timeout: Nanos, retries: u16) -> AlarmAcker {
        AlarmAcker {
            local,
            device,
            timeout,
            retries,
            high: Channel::new(),
            low: Channel::new(),
            stats: AlarmStats::default(),
        }
    }

    /// Its counters.
    pub fn stats(&self) -> AlarmStats {
        self.stats
    }

    /// Takes one frame from the drive at `now` (anything but an alarm frame
    /// is `None`); the answers go into `out`.
    pub fn receive(&mut self, now: Nanos, frame: &[u8], out: &mut Vec<Vec<u8>>) -> Option<Received> {
        let e = EthFrame::parse(frame)?;
        if e.ethertype != ethertype::PROFINET {
            return None;
        }
        let (kind, rest) = split_frame_id(e.payload)?;
        let priority = match kind {
            FrameKind::AlarmHigh => Priority::High,
            FrameKind::AlarmLow => Priority::Low,
            _ => return None,
        };
        let r = self.take(now, &e, priority, rest, out);
        if r.is_none() {
            self.stats.refused = self.stats.refused.wrapping_add(1);
        }
        Some(r.unwrap_or(Received::Other))
    }

    fn take(
        &mut self,
        now: Nanos,
        e: &EthFrame<'_>,
        priority: Priority,
        rest: &[u8],
        out: &mut Vec<Vec<u8>>,
    ) -> Option<Received> {
        if e.src != self.device || e.dst != self.local {
            return None;
        }
        let (h, var) = RtaHeader::parse(rest).ok()?;
        let (timeout, retries) = (self.timeout, self.retries);
        let ch = match priority {
            Priority::High => &mut self.high,
            Priority::Low => &mut self.low,
        };
        // our outstanding AlarmAck is confirmed by an ACK or a DATA
        // carrying its number
        if h.ack_seq == ch.send_seq && ch.pending.is_some() && h.pdu_type != PduType::Err {
            ch.pending = None;
            ch.send_seq_o = ch.send_seq;
            ch.send_seq = next_seq(ch.send_seq);
            self.stats.confirmed = self.stats.confirmed.wrapping_add(1);
        }
        // our answers go back to the endpoints the drive named
        let reply = |t: PduType, tack: bool, send_seq: u16, ack_seq: u16, body: &[u8]| {
            let header = RtaHeader {
                dst_endpoint: h.src_endpoint,
                src_endpoint: h.dst_endpoint,
                pdu_type: t,
                window: 1,
                tack,
                send_seq,
                ack_seq,
                var_part_len: u16::try_from(body.len()).unwrap_or(0),
            };
            frame(self.device, self.local, e.vlan_tci, priority, &header, body)
        };
        match h.pdu_type {
            PduType::Ack | PduType::Nack => Some(Received::Other),
            PduType::Err => {
                let status = var.first_chunk::<4>().map_or(PnioStatus::OK, |s| PnioStatus(*s));
                Some(Received::Abort(status))
            }
            PduType::Data if h.send_seq == ch.exp_seq => {
                let ack = notification_fields(var)?;
                ch.exp_seq_o = ch.exp_seq;
                ch.exp_seq = next_seq(ch.exp_seq);
                out.push(reply(PduType::Ack, false, ch.send_seq_o, ch.exp_seq_o, &[])?);
                self.stats.received = self.stats.received.wrapping_add(1);
                let mut body = [0u8; profinet::alarm::blocks::ACK_LEN];
                ack.emit(&mut body)?;
                // window 1: a new AlarmAck only once the last is confirmed
                if ch.pending.is_none() {
                    let f = reply(PduType::Data, true, ch.send_seq, ch.exp_seq_o, &body)?;
                    out.push(f.clone());
                    ch.pending = Some(Pending {
                        frame: f,
                        deadline: now.saturating_add(timeout),
                        retries,
                    });
                    self.stats.acknowledged = self.stats.acknowledged.wrapping_add(1);
                }
                Some(Received::Alarm {
                    alarm_type: ack.alarm_type,
                    slot: ack.slot,
                    subslot: ack.subslot,
                    sequence: ack.specifier.sequence(),
                })
            }
            PduType::Data if h.send_seq == ch.exp_seq_o => {
                out.push(reply(PduType::Ack, false, ch.send_seq_o, ch.exp_seq_o, &[])?);
                self.stats.repeated = self.stats.repeated.wrapping_add(1);
                Some(Received::Other)
            }
            PduType::Data => None,
        }
    }

    /// Our AlarmAcks due again at `now` (the drive's ACK did not come
    /// within the timeout) go into `out`.
    pub fn poll(&mut self, now: Nanos, out: &mut Vec<Vec<u8>>) {
        let timeout = self.timeout;
        for ch in [&mut self.high, &mut self.low] {
            let Some(p) = ch.pending.as_mut() else {
                continue;
            };
            if now < p.deadline {
                continue;
            }
            if p.retries == 0 {
                // given up: the drive's alarm CR decides about the AR
                ch.pending = None;
                continue;
            }
            p.retries -= 1;
            p.deadline = now.saturating_add(timeout);
            out.push(p.frame.clone());
            self.stats.retransmitted = self.stats.retransmitted.wrapping_add(1);
        }
    }
}

/// An alarm frame from `src` to `dst`: Ethernet header (tagged as the
/// drive's frame was), FrameID of `priority`, `header`, `body`, padded to
/// the minimum frame length.
fn frame(
    dst: MacAddr,
    src: MacAddr,
    tag: Option<u16>,
    priority: Priority,
    header: &RtaHeader,
    body: &[u8],
) -> Option<Vec<u8>> {
    let mut buf = vec![0u8; 18 + 2 + profinet::alarm::rta::HEADER_LEN + body.len()];
    let at = emit_header(&mut buf, dst, src, tag, ethertype::PROFINET)?;
    buf.get_mut(at..at + 2)?
        .copy_from_slice(&priority.frame_id().to_be_bytes());
    header.emit(buf.get_mut(at + 2..)?)?;
    let var = at + 2 + profinet::alarm::rta::HEADER_LEN;
    buf.get_mut(var..var + body.len())?.copy_from_slice(body);
    buf.truncate(var + body.len());
    if buf.len() < MIN_FRAME_LEN {
        buf.resize(MIN_FRAME_LEN, 0);
    }
    Some(buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    const DEVICE: MacAddr = MacAddr([2, 0, 0, 0, 0, 2]);
    const CONTROLLER: MacAddr = MacAddr([2, 0, 0, 0, 0, 1]);

    fn hex(s: &str) -> Vec<u8> {
        (0..s.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
            .collect()
    }

    /// `f` is `want` padded with zeros.
    fn same(f: &[u8], want: &str) {
        let want = hex(want);
        assert_eq!(&f[..want.len()], &want[..]);
        assert!(f[want.len()..].iter().all(|b| *b == 0), "padding only");
    }

    /// The drive's first two alarms (appears, disappears), its ACK of our
    /// first AlarmAck between them: we answer byte for byte as profinet-py
    /// did (the vectors of `profinet::alarm::tests_vectors`, padded to 60).
    #[test]
    fn p043_our_acks_are_profinet_pys() {
        // the drive's frames: `OURS` 0, 1, 2
        let appears = hex("0200000000010200000000028100a0008892fe01000100031111fffffffe0028000200240100000100000000000100010000021200000001a8008002800008001008100600000000");
        let device_ack = hex("0200000000010200000000028100a0008892fe01000100031301ffffffff000000000000000000000000000000000000000000000000000000000000");
        let disappears = hex("0200000000010200000000028100a0008892fe010001000311110000ffff0028000200240100000c0000000000010001000002120000000100018002800010001008100600000000");
        let mut a = AlarmAcker::new(CONTROLLER, DEVICE, Nanos::from_ms(100), 3);
        let mut out = Vec::new();
        let r = a.receive(Nanos::ZERO, &appears, &mut out);
        assert_eq!(
            r,
            Some(Received::Alarm {
                alarm_type: 1,
                slot: 1,
                subslot: 1,
                sequence: 0
            })
        );
        assert_eq!(out.len(), 2);
        // PY_TACK_1, PY_ALARM_ACK_1
        same(
            &out[0],
            "0200000000020200000000018100a0008892fe01000300011301fffeffff0000",
        );
        same(
            &out[1],
            "0200000000020200000000018100a0008892fe01000300011111ffffffff001680020012010000010000000000010001a80000000000",
        );
        out.clear();
        a.receive(Nanos::from_ms(1), &device_ack, &mut out);
        assert!(out.is_empty());
        assert_eq!(a.stats().confirmed, 1);
        a.receive(Nanos::from_ms(2), &disappears, &mut out);
        // PY_TACK_2, PY_ALARM_ACK_2
        same(
            &out[0],
            "0200000000020200000000018100a0008892fe01000300011301ffff00000000",
        );
        same(
            &out[1],
            "0200000000020200000000018100a0008892fe01000300011111000000000016800200120100000c0000000000010001000100000000",
        );
        // the drive repeats the disappears alarm: ACKed again, not
        // acknowledged twice
        out.clear();
        a.receive(Nanos::from_ms(3), &disappears, &mut out);
        assert_eq!(out.len(), 1);
        assert_eq!(out[0][24] & 0x0F, 3, "an ACK");
        let s = a.stats();
        assert_eq!((s.received, s.acknowledged, s.repeated), (2, 2, 1));
        // no ACK of the second AlarmAck: sent again after the timeout
        out.clear();
        a.poll(Nanos::from_ms(50), &mut out);
        assert!(out.is_empty());
        a.poll(Nanos::from_ms(102), &mut out);
        assert_eq!(out.len(), 1);
        assert_eq!(a.stats().retransmitted, 1);
    }
}
