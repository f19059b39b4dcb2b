//! Unit tests of the RTA header and the alarm CR (P-043).

use super::rta::{next_seq, HeaderError, SEQ_START};
use super::*;
use crate::wire::{EthFrame, MacAddr};
use nanos::Nanos;

pub(super) const CTL: MacAddr = MacAddr([0x02, 0, 0, 0, 0, 0x01]);
pub(super) const DEV: MacAddr = MacAddr([0x02, 0, 0, 0, 0, 0x02]);
/// Our alarm reference and the controller's.
pub(super) const DEV_REF: u16 = 0x0003;
pub(super) const CTL_REF: u16 = 0x0001;

pub(super) fn config() -> AlarmCrConfig {
    AlarmCrConfig {
        local_ref: DEV_REF,
        remote_ref: CTL_REF,
        rta_timeout_factor: 1,
        rta_retries: 3,
        max_alarm_data_length: 200,
        only_low_priority: false,
        tag_high: Some(0xC000),
        tag_low: Some(0xA000),
        local: DEV,
        remote: CTL,
    }
}

/// Error 08-6 appearing on slot 1 / subslot 1.
pub(super) fn diag_notification() -> Notification {
    let e = DriveError::new(8, 6).unwrap();
    Notification {
        priority: Priority::Low,
        alarm_type: AlarmType::DIAGNOSIS,
        api: 0,
        slot: 1,
        subslot: 1,
        module_ident: 0x212,
        submodule_ident: 1,
        specifier: AlarmSpecifier::new(true, false, true, true),
        item: Some(DiagItem {
            channel: 0x8000,
            properties: ChannelProperties::new(
                0,
                false,
                Maintenance::Fault,
                Specifier::Appears,
                ChannelDirection::Manufacturer,
            ),
            error_type: e.channel_error_type(),
            ext_error_type: e.ext_channel_error_type(),
            add_value: 0,
        }),
    }
}

/// A controller frame on `prio`'s FrameID with the given RTA header fields
/// and var part (tag 0xA000 / 0xC000 as profinet-py sends).
pub(super) fn ctl_rta(
    prio: Priority,
    pdu: u8,
    flags: u8,
    send: u16,
    ack: u16,
    var: &[u8],
) -> std::vec::Vec<u8> {
    let mut f = std::vec::Vec::new();
    f.extend_from_slice(&DEV.0);
    f.extend_from_slice(&CTL.0);
    let tci: u16 = if prio == Priority::High { 0xC000 } else { 0xA000 };
    f.extend_from_slice(&[0x81, 0x00]);
    f.extend_from_slice(&tci.to_be_bytes());
    f.extend_from_slice(&[0x88, 0x92]);
    f.extend_from_slice(&prio.frame_id().to_be_bytes());
    for v in [DEV_REF, CTL_REF] {
        f.extend_from_slice(&v.to_be_bytes());
    }
    f.extend_from_slice(&[0x10 | pdu, flags]);
    for v in [send, ack, var.len() as u16] {
        f.extend_from_slice(&v.to_be_bytes());
    }
    f.extend_from_slice(var);
    f
}

/// The controller's DATA-RTA (with TACK) carrying an AlarmAck of `n` (status
/// OK) as SendSeqNum `send`, AckSeqNum 0xFFFF.
pub(super) fn ctl_alarm_ack(n: &Notification, send: u16) -> std::vec::Vec<u8> {
    ctl_rta(
        Priority::Low,
        1,
        0x11,
        send,
        0xFFFF,
        &ack_block(n, PnioStatus::OK),
    )
}

/// The controller's AlarmAck for `n` as a var part.
pub(super) fn ack_block(n: &Notification, status: PnioStatus) -> std::vec::Vec<u8> {
    let a = AlarmAck {
        priority: n.priority,
        alarm_type: n.alarm_type,
        api: n.api,
        slot: n.slot,
        subslot: n.subslot,
        specifier: n.specifier,
        status,
    };
    let mut b = [0u8; 22];
    assert_eq!(a.emit(&mut b), Some(22));
    b.to_vec()
}

fn ms(v: u64) -> Nanos {
    Nanos::from_ms(v)
}

fn frame(cr: &mut AlarmCr, now: Nanos) -> std::vec::Vec<u8> {
    let mut buf = [0u8; 256];
    match cr.poll(now, &mut buf) {
        Some(Output::Frame(n)) => buf[..n].to_vec(),
        other => panic!("expected a frame, got {other:?}"),
    }
}

fn rta_of(f: &[u8]) -> (RtaHeader, std::vec::Vec<u8>) {
    let e = EthFrame::parse(f).unwrap();
    let (h, v) = RtaHeader::parse(&e.payload[2..]).unwrap();
    (h, v.to_vec())
}

#[test]
fn p043_rta_header_round_trip_and_refusals() {
    let h = RtaHeader {
        dst_endpoint: 1,
        src_endpoint: 3,
        pdu_type: PduType::Data,
        window: 1,
        tack: true,
        send_seq: 0xFFFF,
        ack_seq: 0xFFFE,
        var_part_len: 2,
    };
    let mut b = [0u8; 14];
    assert_eq!(h.emit(&mut b), Some(12));
    assert_eq!(&b[..12], &[0, 1, 0, 3, 0x11, 0x11, 0xFF, 0xFF, 0xFF, 0xFE, 0, 2]);
    b[12..].copy_from_slice(&[9, 9]);
    let (p, var) = RtaHeader::parse(&b).unwrap();
    assert_eq!((p, var), (h, &[9u8, 9][..]));
    assert_eq!(RtaHeader::parse(&b[..13]).unwrap_err(), HeaderError::Truncated);
    assert_eq!(RtaHeader::parse(&b[..11]).unwrap_err(), HeaderError::Truncated);
    b[4] = 0x21;
    assert_eq!(RtaHeader::parse(&b).unwrap_err(), HeaderError::Version);
    b[4] = 0x15;
    assert_eq!(RtaHeader::parse(&b).unwrap_err(), HeaderError::PduType);
    assert!(h.emit(&mut [0u8; 11]).is_none());
}

#[test]
fn p043_sequence_numbers_start_at_ffff_and_wrap_at_7fff() {
    assert_eq!(next_seq(SEQ_START), 0);
    assert_eq!(next_seq(0), 1);
    assert_eq!(next_seq(0x7FFF), 0);
}

#[test]
fn p043_alarm_goes_out_with_tack_and_is_done_by_the_controllers_ack() {
    let mut cr = AlarmCr::new(config()).unwrap();
    assert!(cr.can_send(Priority::Low));
    assert_eq!(cr.poll_at(ms(0)), Nanos::MAX);
    let sent = cr.send(ms(0), &diag_notification()).unwrap();
    assert_eq!(sent.specifier.sequence(), 0);
    assert!(!cr.can_send(Priority::Low));
    assert!(cr.can_send(Priority::High));
    assert_eq!(cr.send(ms(0), &diag_notification()).unwrap_err(), SendError::Busy);
    assert_eq!(cr.poll_at(ms(0)), ms(0));
    let f = frame(&mut cr, ms(0));
    assert_eq!(&f[12..20], &[0x81, 0x00, 0xA0, 0x00, 0x88, 0x92, 0xFE, 0x01]);
    let (h, var) = rta_of(&f);
    assert_eq!((h.dst_endpoint, h.src_endpoint), (CTL_REF, DEV_REF));
    assert_eq!((h.pdu_type, h.window, h.tack), (PduType::Data, 1, true));
    assert_eq!((h.send_seq, h.ack_seq), (0xFFFF, 0xFFFE));
    assert_eq!(var.len(), 40);
    assert_eq!(cr.poll(ms(0), &mut [0u8; 128]), None);
    assert_eq!(cr.poll_at(ms(0)), ms(100));
    // transport ACK from the controller
    let ack = ctl_rta(Priority::Low, 3, 0x01, 0xFFFE, 0xFFFF, &[]);
    assert_eq!(cr.receive(ms(5), &EthFrame::parse(&ack).unwrap()), Ok(None));
    assert_eq!(cr.poll_at(ms(5)), Nanos::MAX, "no retransmission after TACK");
    assert!(!cr.can_send(Priority::Low), "outstanding until the AlarmAck");
    // the AlarmAck in a DATA of the controller
    let data = ctl_alarm_ack(&sent, 0xFFFF);
    let ev = cr
        .receive(ms(6), &EthFrame::parse(&data).unwrap())
        .unwrap()
        .unwrap();
    assert_eq!(
        ev,
        AlarmEvent::Acked {
            priority: Priority::Low,
            notification: sent,
            status: PnioStatus::OK
        }
    );
    assert!(cr.can_send(Priority::Low));
    // we transport-acknowledge its DATA
    let f = frame(&mut cr, ms(6));
    assert_eq!(f.len(), 60, "padded");
    let (h, var) = rta_of(&f);
    assert_eq!(
        (h.pdu_type, h.tack, h.send_seq, h.ack_seq),
        (PduType::Ack, false, 0xFFFF, 0xFFFF)
    );
    assert!(var.is_empty());
    // the next alarm: SendSeqNum 0, AlarmSpecifier sequence 1
    let sent = cr.send(ms(10), &diag_notification()).unwrap();
    assert_eq!(sent.specifier.sequence(), 1);
    let (h, _) = rta_of(&frame(&mut cr, ms(10)));
    assert_eq!((h.send_seq, h.ack_seq), (0, 0xFFFF));
    assert_eq!(cr.stats().acked, 1);
}

#[test]
fn p043_retransmits_after_timeout_then_aborts_the_ar() {
    let mut cfg = config();
    cfg.rta_timeout_factor = 2;
    let mut cr = AlarmCr::new(cfg).unwrap();
    cr.send(ms(0), &diag_notification()).unwrap();
    let first = frame(&mut cr, ms(0));
    for k in 1..=3u64 {
        assert_eq!(cr.poll(ms(200 * k - 1), &mut [0u8; 128]), None);
        assert_eq!(frame(&mut cr, ms(200 * k)), first, "the same PDU again");
    }
    assert_eq!(cr.stats().retransmitted, 3);
    let mut buf = [0u8; 128];
    assert_eq!(
        cr.poll(ms(800), &mut buf),
        Some(Output::Event(AlarmEvent::Abort(AbortCode::ALARM_SEND_CNF_NEG)))
    );
    assert!(cr.is_closed());
    let (h, var) = rta_of(&frame(&mut cr, ms(800)));
    assert_eq!((h.pdu_type, h.tack), (PduType::Err, false));
    assert_eq!(var, [0xCF, 0x81, 0xFD, 0x08]);
    assert_eq!(cr.poll(ms(800), &mut buf), None);
    assert_eq!(
        cr.send(ms(900), &diag_notification()).unwrap_err(),
        SendError::Closed
    );
}

#[test]
fn p043_ack_with_the_wrong_number_does_not_stop_retransmission() {
    let mut cr = AlarmCr::new(config()).unwrap();
    cr.send(ms(0), &diag_notification()).unwrap();
    frame(&mut cr, ms(0));
    let ack = ctl_rta(Priority::Low, 3, 0x01, 0xFFFE, 0x0005, &[]);
    cr.receive(ms(1), &EthFrame::parse(&ack).unwrap()).unwrap();
    assert_eq!(cr.poll_at(ms(1)), ms(100));
    // a NACK is counted; the timer repeats the DATA
    let nack = ctl_rta(Priority::Low, 2, 0x01, 0xFFFE, 0xFFFE, &[]);
    cr.receive(ms(2), &EthFrame::parse(&nack).unwrap()).unwrap();
    assert_eq!(cr.stats().nacks_received, 1);
    let (h, _) = rta_of(&frame(&mut cr, ms(100)));
    assert_eq!((h.pdu_type, h.send_seq), (PduType::Data, 0xFFFF));
}

#[test]
fn p043_receiver_acks_repeats_and_nacks_wrong_numbers() {
    let mut cr = AlarmCr::new(config()).unwrap();
    let sent = cr.send(ms(0), &diag_notification()).unwrap();
    frame(&mut cr, ms(0));
    // an AlarmAck piggybacking the transport ACK (AckSeqNum = ours)
    let data = ctl_alarm_ack(&sent, 0xFFFF);
    assert!(matches!(
        cr.receive(ms(1), &EthFrame::parse(&data).unwrap()),
        Ok(Some(AlarmEvent::Acked { .. }))
    ));
    frame(&mut cr, ms(1));
    // the controller repeats it (our ACK got lost): ACKed again, no event
    assert_eq!(cr.receive(ms(2), &EthFrame::parse(&data).unwrap()), Ok(None));
    let (h, _) = rta_of(&frame(&mut cr, ms(2)));
    assert_eq!((h.pdu_type, h.ack_seq), (PduType::Ack, 0xFFFF));
    // out of sequence: NACK
    let wrong = ctl_alarm_ack(&sent, 7);
    assert_eq!(
        cr.receive(ms(3), &EthFrame::parse(&wrong).unwrap()),
        Err(RtaError::Sequence)
    );
    let (h, _) = rta_of(&frame(&mut cr, ms(3)));
    assert_eq!(
        (h.pdu_type, h.send_seq, h.ack_seq),
        (PduType::Nack, 0xFFFF, 0xFFFF)
    );
    // an AlarmAck for nothing outstanding: ACKed, refused
    let stray = ctl_alarm_ack(&sent, 0);
    assert_eq!(
        cr.receive(ms(4), &EthFrame::parse(&stray).unwrap()),
        Err(RtaError::UnexpectedAck)
    );
    assert_eq!(rta_of(&frame(&mut cr, ms(4))).0.pdu_type, PduType::Ack);
    // a DATA without TACK is ignored
    let plain = ctl_rta(Priority::Low, 1, 0x01, 1, 0xFFFF, &[]);
    assert_eq!(cr.receive(ms(5), &EthFrame::parse(&plain).unwrap()), Ok(None));
    assert_eq!(cr.poll(ms(5), &mut [0u8; 128]), None);
}

#[test]
fn p043_err_from_the_controller_closes_and_foreign_frames_are_refused() {
    let mut cr = AlarmCr::new(config()).unwrap();
    let mut other_ref = ctl_rta(Priority::Low, 3, 0x01, 0xFFFE, 0xFFFF, &[]);
    other_ref[21] = 0x09;
    assert_eq!(
        cr.receive(ms(0), &EthFrame::parse(&other_ref).unwrap()),
        Err(RtaError::WrongEndpoint)
    );
    let mut stranger = ctl_rta(Priority::Low, 3, 0x01, 0xFFFE, 0xFFFF, &[]);
    stranger[11] = 0x77;
    assert_eq!(
        cr.receive(ms(0), &EthFrame::parse(&stranger).unwrap()),
        Err(RtaError::WrongAddress)
    );
    let mut short = ctl_rta(Priority::Low, 1, 0x11, 0xFFFF, 0xFFFE, &[1, 2, 3]);
    short.pop();
    assert_eq!(
        cr.receive(ms(0), &EthFrame::parse(&short).unwrap()),
        Err(RtaError::Malformed)
    );
    let mut cyclic = ctl_rta(Priority::Low, 3, 0x01, 0, 0, &[]);
    cyclic[18..20].copy_from_slice(&[0x80, 0x00]);
    assert_eq!(
        cr.receive(ms(0), &EthFrame::parse(&cyclic).unwrap()),
        Err(RtaError::NotAlarm)
    );
    assert_eq!(cr.stats().refused, 4);
    let err = ctl_rta(Priority::Low, 4, 0x01, 0xFFFF, 0xFFFE, &[0xCF, 0x81, 0xFD, 0x0F]);
    assert_eq!(
        cr.receive(ms(1), &EthFrame::parse(&err).unwrap()),
        Ok(Some(AlarmEvent::ErrReceived(PnioStatus([
            0xCF, 0x81, 0xFD, 0x0F
        ]))))
    );
    assert!(cr.is_closed());
    assert_eq!(cr.poll(ms(1), &mut [0u8; 128]), None, "no ERR back");
    let ack = ctl_rta(Priority::Low, 3, 0x01, 0xFFFE, 0xFFFF, &[]);
    assert_eq!(
        cr.receive(ms(2), &EthFrame::parse(&ack).unwrap()),
        Err(RtaError::Closed)
    );
}

#[test]
fn p043_high_and_low_are_independent_and_only_low_folds_them() {
    let mut cr = AlarmCr::new(config()).unwrap();
    let mut high = diag_notification();
    high.priority = Priority::High;
    high.alarm_type = AlarmType::PROCESS;
    high.item = None;
    cr.send(ms(0), &high).unwrap();
    cr.send(ms(0), &diag_notification()).unwrap();
    let f = frame(&mut cr, ms(0));
    assert_eq!(&f[14..16], &[0xC0, 0x00]);
    assert_eq!(&f[18..20], &[0xFC, 0x01], "high first");
    let (_, var) = rta_of(&f);
    assert_eq!(&var[..2], &[0x00, 0x01]);
    assert_eq!(&f[18..20], &0xFC01u16.to_be_bytes());
    let f = frame(&mut cr, ms(0));
    assert_eq!(&f[18..20], &[0xFE, 0x01]);
    // AlarmCRProperties.Priority: everything low
    let mut cfg = config();
    cfg.only_low_priority = true;
    let mut cr = AlarmCr::new(cfg).unwrap();
    let sent = cr.send(ms(0), &high).unwrap();
    assert_eq!(sent.priority, Priority::Low);
    assert!(!cr.can_send(Priority::High));
    let (_, var) = rta_of(&frame(&mut cr, ms(0)));
    assert_eq!(&var[..2], &[0x00, 0x02]);
    // too long for MaxAlarmDataLength, bad configuration
    let mut cfg = config();
    cfg.rta_retries = 2;
    assert!(AlarmCr::new(cfg).is_err());
    let mut cfg = config();
    cfg.max_alarm_data_length = 200;
    let mut cr = AlarmCr::new(cfg).unwrap();
    cr.abort(AbortCode::ABORT_REQ);
    let (h, var) = rta_of(&frame(&mut cr, ms(0)));
    assert_eq!(
        (h.pdu_type, var),
        (PduType::Err, std::vec![0xCF, 0x81, 0xFD, 0x0D])
    );
    assert_eq!(cr.poll_at(ms(0)), Nanos::MAX);
}

#[test]
fn p043_alarm_cr_never_panics_on_mutated_or_truncated_frames() {
    let n = diag_notification();
    let valid = [
        ctl_rta(Priority::Low, 3, 0x01, 0xFFFE, 0xFFFF, &[]),
        ctl_alarm_ack(&n, 0xFFFF),
        ctl_rta(Priority::High, 4, 0x01, 0xFFFF, 0xFFFE, &[0xCF, 0x81, 0xFD, 0x0F]),
    ];
    let mut seed = 0x0F0F_1234_5678_9ABCu64;
    let mut buf = [0u8; 128];
    for i in 0..20_000u64 {
        let mut cr = AlarmCr::new(config()).unwrap();
        cr.send(ms(0), &n).unwrap();
        let _ = cr.poll(ms(0), &mut buf);
        let mut f = valid[(i % 3) as usize].clone();
        for _ in 0..crate::rt::tests::xorshift(&mut seed) % 4 {
            let at = (crate::rt::tests::xorshift(&mut seed) as usize) % f.len();
            f[at] = crate::rt::tests::xorshift(&mut seed) as u8;
        }
        let cut = (crate::rt::tests::xorshift(&mut seed) as usize) % (f.len() + 8);
        f.resize(cut, 0);
        if let Some(e) = EthFrame::parse(&f) {
            let _ = cr.receive(ms(1), &e);
            let _ = RtaHeader::parse(e.payload);
            let _ = AlarmAck::parse(e.payload);
        }
        while cr.poll(ms(i % 1000), &mut buf).is_some() {}
        // short buffers get nothing, never a panic
        let _ = cr.poll(ms(5000), &mut [0u8; 20]);
    }
}
