//! Alarm frames exactly as profinet-py 0.6.6 (the CI controller,
//! `alarm_listener.AlarmListener`) answers ours, and ours as it parses them.

use super::tests_cr::{config, diag_notification};
use super::*;
use crate::rt::tests_vectors::{hex, write_pcap};
use crate::wire::EthFrame;
use nanos::Nanos;

fn frame(cr: &mut AlarmCr, now: Nanos) -> std::vec::Vec<u8> {
    let mut buf = [0u8; 256];
    match cr.poll(now, &mut buf) {
        Some(Output::Frame(n)) => buf[..n].to_vec(),
        other => panic!("expected a frame, got {other:?}"),
    }
}

/// Our frames for the pcap / profinet-py check: the 08-6 appears alarm, the
/// ACK of the controller's AlarmAck, the disappears alarm, an ERR.
pub(super) fn our_frames() -> std::vec::Vec<std::vec::Vec<u8>> {
    let mut cr = AlarmCr::new(config()).unwrap();
    let mut d = DiagList::<4>::new();
    d.set_alarms(true);
    let loc = Location {
        api: 0,
        slot: 1,
        subslot: 1,
        module_ident: 0x212,
        submodule_ident: 1,
    };
    let e = DriveError::new(8, 6).unwrap();
    d.raise(loc, e, Maintenance::Fault, 0).unwrap();
    let n = cr.send(Nanos::ZERO, &d.next_alarm().unwrap()).unwrap();
    d.sent();
    assert_eq!(n, diag_notification());
    let mut out = std::vec![frame(&mut cr, Nanos::ZERO)];
    for f in [PY_TACK_1, PY_ALARM_ACK_1] {
        let f = hex(f);
        if let Some(AlarmEvent::Acked { .. }) =
            cr.receive(Nanos::ZERO, &EthFrame::parse(&f).unwrap()).unwrap()
        {
            d.acked();
        }
    }
    out.push(frame(&mut cr, Nanos::ZERO));
    d.clear(&loc, e);
    cr.send(Nanos::ZERO, &d.next_alarm().unwrap()).unwrap();
    out.push(frame(&mut cr, Nanos::ZERO));
    cr.abort(AbortCode::CONSUMER_DHT_EXPIRED);
    out.push(frame(&mut cr, Nanos::ZERO));
    out
}

/// profinet-py's transport ACK of our first DATA (SendSeqNum 0xFFFF):
/// `_send_transport_ack`, tag 0xA000, SendSeqNum 0xFFFE, AckSeqNum 0xFFFF.
const PY_TACK_1: &str = "0200000000020200000000018100a0008892fe01000300011301fffeffff0000";
/// profinet-py's AlarmAck of it: DATA with TACK, SendSeqNum 0xFFFF,
/// AlarmAck Low (0x8002), the AlarmSpecifier echoed, PNIOStatus OK.
const PY_ALARM_ACK_1: &str =
    "0200000000020200000000018100a0008892fe01000300011111ffffffff001680020012010000010000000000010001a80000000000";

/// profinet-py's transport ACK of our second DATA (SendSeqNum 0) and its
/// AlarmAck (its SendSeqNum 0, AlarmType 0x000C, sequence 1).
const PY_TACK_2: &str = "0200000000020200000000018100a0008892fe01000300011301ffff00000000";
const PY_ALARM_ACK_2: &str =
    "0200000000020200000000018100a0008892fe01000300011111000000000016800200120100000c0000000000010001000100000000";

/// Our frames, as profinet-py took them (it answered with the frames
/// above, decoded "Diagnosis" / "DiagnosisDisappears" at 0:1:0x0001 with
/// ChannelErrorType 0x1008, ExtChannelErrorType 0x1006, and logged our ERR
/// as PNIOStatus 0xCF81FD05).
const OURS: [&str; 4] = [
    "0200000000010200000000028100a0008892fe01000100031111fffffffe0028000200240100000100000000000100010000021200000001a8008002800008001008100600000000",
    "0200000000010200000000028100a0008892fe01000100031301ffffffff000000000000000000000000000000000000000000000000000000000000",
    "0200000000010200000000028100a0008892fe010001000311110000ffff0028000200240100000c0000000000010001000002120000000100018002800010001008100600000000",
    "0200000000010200000000028100a0008892fe010001000314010000ffff0004cf81fd05000000000000000000000000000000000000000000000000",
];

#[test]
fn p043_our_alarm_frames_are_the_ones_profinet_py_accepted() {
    let frames = our_frames();
    assert_eq!(frames.len(), 4);
    for (f, want) in frames.iter().zip(OURS) {
        assert_eq!(f, &hex(want));
    }
    let mut all = std::vec::Vec::new();
    for (i, f) in frames.iter().enumerate() {
        all.push(f.clone());
        match i {
            0 => all.extend([hex(PY_TACK_1), hex(PY_ALARM_ACK_1)]),
            2 => all.extend([hex(PY_TACK_2), hex(PY_ALARM_ACK_2)]),
            _ => {}
        }
    }
    write_pcap("alarm.pcap", &all);
}

#[test]
fn p043_profinet_py_acks_complete_our_disappears_alarm() {
    let mut cr = AlarmCr::new(config()).unwrap();
    let mut n = diag_notification();
    cr.send(Nanos::ZERO, &n).unwrap();
    frame(&mut cr, Nanos::ZERO);
    for f in [PY_TACK_1, PY_ALARM_ACK_1] {
        cr.receive(Nanos::ZERO, &EthFrame::parse(&hex(f)).unwrap())
            .unwrap();
    }
    frame(&mut cr, Nanos::ZERO);
    n.alarm_type = AlarmType::DIAGNOSIS_DISAPPEARS;
    n.specifier = AlarmSpecifier::new(false, false, false, false);
    let sent = cr.send(Nanos::from_ms(1), &n).unwrap();
    assert_eq!(sent.specifier.sequence(), 1);
    frame(&mut cr, Nanos::from_ms(1));
    let r = cr.receive(Nanos::from_ms(2), &EthFrame::parse(&hex(PY_TACK_2)).unwrap());
    assert_eq!(r, Ok(None));
    assert_eq!(
        cr.poll_at(Nanos::from_ms(2)),
        Nanos::MAX,
        "transport-acknowledged"
    );
    let r = cr.receive(Nanos::from_ms(3), &EthFrame::parse(&hex(PY_ALARM_ACK_2)).unwrap());
    assert_eq!(
        r,
        Ok(Some(AlarmEvent::Acked {
            priority: Priority::Low,
            notification: sent,
            status: PnioStatus::OK
        }))
    );
    let mut buf = [0u8; 128];
    assert_eq!(cr.poll(Nanos::from_ms(3), &mut buf), Some(Output::Frame(60)));
    assert_eq!(cr.poll(Nanos::from_ms(3), &mut buf), None);
}
