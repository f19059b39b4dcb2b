//! The device end to end through Ethernet frames: the frames profinet-py
//! sends (DCP from `dcp::tests_frames`, RPC from `cm::tests_vectors`).

use super::*;
use crate::testing::{self, connect_frame, CONTROLLER_MAC as CTRL_MAC, DEVICE_MAC as OUR_MAC};
use std::vec::Vec;

fn device() -> Device {
    Device::plain(testing::device_config())
}

fn identify_all() -> Vec<u8> {
    let mut f = std::vec![0u8; 60];
    f[..6].copy_from_slice(&MacAddr::DCP_IDENTIFY.0);
    f[6..12].copy_from_slice(&CTRL_MAC.0);
    f[12..14].copy_from_slice(&0x8892u16.to_be_bytes());
    // FrameID FEFE, Identify request, xid 1, delay factor 1, 4 bytes: All
    f[14..30].copy_from_slice(&[
        0xFE, 0xFE, 0x05, 0x00, 0, 0, 0, 1, 0x00, 0x01, 0x00, 0x04, 0xFF, 0xFF, 0x00, 0x00,
    ]);
    f
}

fn sent(d: &mut Device, now: Nanos, frame: &[u8]) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    d.receive(now, frame, &mut |f: &[u8]| out.push(f.to_vec()));
    out
}

#[test]
fn p008_identify_through_the_device_answers_with_our_name() {
    let mut d = device();
    let out = sent(&mut d, Nanos::ZERO, &identify_all());
    assert_eq!(out.len(), 1);
    let f = EthFrame::parse(&out[0]).unwrap();
    assert_eq!((f.dst, f.src, f.ethertype), (CTRL_MAC, OUR_MAC, 0x8892));
    assert_eq!(
        split_frame_id(f.payload).unwrap().0,
        FrameKind::DcpIdentifyResponse
    );
    assert!(out[0].windows(7).any(|w| w == b"drive-1"));
}

#[test]
fn p042_unknown_frame_ids_and_frames_for_others_are_dropped_and_counted() {
    let mut d = device();
    let mut f = identify_all();
    f[14..16].copy_from_slice(&0x0100u16.to_be_bytes());
    assert!(sent(&mut d, Nanos::ZERO, &f).is_empty());
    f[..6].copy_from_slice(&[0x02, 0, 0, 0, 0, 0x99]);
    assert!(sent(&mut d, Nanos::ZERO, &f).is_empty());
    f[..6].copy_from_slice(&OUR_MAC.0);
    f[14..16].copy_from_slice(&0xC001u16.to_be_bytes());
    assert!(sent(&mut d, Nanos::ZERO, &f).is_empty());
    assert_eq!(sent(&mut d, Nanos::ZERO, &f[..10]).len(), 0);
    let c = d.counters();
    assert_eq!((c.unknown_frame_id, c.not_for_us, c.no_ar, c.runt), (1, 1, 1, 1));
}

#[test]
fn p010_p041_connect_over_udp_to_the_stored_static_ip_establishes_the_ar() {
    let mut d = device();
    let out = sent(&mut d, Nanos::ZERO, &connect_frame());
    assert_eq!(out.len(), 1, "one Connect response");
    let f = EthFrame::parse(&out[0]).unwrap();
    assert_eq!((f.dst, f.ethertype), (CTRL_MAC, 0x0800));
    assert!(d.cm().ar().is_some());
    assert!(matches!(
        d.take_event(),
        Some(DeviceEvent::Cm(CmEvent::Connected(_)))
    ));
    // in operation: DCP refuses a new name now (0x06), so nothing else changed
    assert_eq!(d.take_event(), None);
}

#[test]
fn p006_p037_poll_sends_lldp_from_both_port_macs_then_waits_5_s() {
    let mut d = device();
    let mut out = Vec::new();
    // one port's LLDPDU per poll (issue 36: a poll stays short); the first
    // asks to be called again at once for the second port
    let next = d.poll(Nanos::ZERO, &mut |f: &[u8]| out.push(f.to_vec()));
    assert_eq!((out.len(), next), (1, Nanos::ZERO));
    let next = d.poll(Nanos::ZERO, &mut |f: &[u8]| out.push(f.to_vec()));
    assert_eq!(out.len(), 2);
    for (f, port_mac) in out.iter().zip([0x51, 0x52]) {
        let e = EthFrame::parse(f).unwrap();
        assert_eq!(
            (e.dst, e.src.0[5], e.ethertype),
            (MacAddr::LLDP, port_mac, 0x88CC)
        );
    }
    assert!(next > Nanos::ZERO && next <= Nanos::from_secs(5));
    out.clear();
    d.poll(Nanos::from_secs(1), &mut |f: &[u8]| out.push(f.to_vec()));
    assert!(out.is_empty());
    out = poll(&mut d, Nanos::from_secs(5));
    assert_eq!(out.len(), 2);
}

/// The device after profinet-py's Connect (slot 1 OUT 18 words, slot 2 IN 18
/// words; 1 ms × 8, watchdog and data hold 6 cycles).
fn connected() -> Device {
    let mut d = device();
    sent(&mut d, Nanos::ZERO, &connect_frame());
    while d.take_event().is_some() {}
    d
}

/// A controller output frame with `fill` in slot 2's 36 bytes.
fn output_frame(d: &Device, counter: u16, fill: u8) -> Vec<u8> {
    testing::output_frame(d.cm().ar().unwrap(), counter, fill).to_vec()
}

/// What the device sends at `now`: polls until nothing more is due then
/// (one port's LLDPDU per poll; a poll that left one due returns `now`).
fn poll(d: &mut Device, now: Nanos) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    for _ in 0..4 {
        if d.poll(now, &mut |f: &[u8]| out.push(f.to_vec())) > now {
            break;
        }
    }
    out
}

fn frame_id(f: &[u8]) -> Option<u16> {
    let e = EthFrame::parse(f)?;
    (e.ethertype == 0x8892).then(|| u16::from_be_bytes([e.payload[0], e.payload[1]]))
}

#[test]
fn p027_p042_cyclic_outputs_reach_the_drive_and_inputs_go_out_every_cycle() {
    let mut d = connected();
    let input_id = d.cm().ar().unwrap().input_cr.as_ref().unwrap().frame_id;
    assert_eq!(d.output_data(2), None, "nothing before the first frame");
    let cycle = Nanos::from_ms(8);
    let mut provided = 0;
    for k in 0..20u16 {
        let now = cycle * u64::from(k);
        let f = output_frame(&d, k * 256, k as u8);
        sent(&mut d, now, &f);
        assert_eq!(d.output_data(2), Some(&[k as u8; 36][..]));
        assert!(d.set_input_data(1, &[0xA5; 36]));
        for f in poll(&mut d, now) {
            if frame_id(&f) == Some(input_id) {
                provided += 1;
                assert!(f.windows(36).any(|w| w == [0xA5; 36]));
            }
        }
    }
    assert!(provided >= 19, "{provided} input frames in 20 cycles");
    assert!(d.exchanging());
    assert!(!d.set_input_data(2, &[0; 36]), "slot 2 is an IN module");
    let events: Vec<_> = std::iter::from_fn(|| d.take_event()).collect();
    assert!(
        matches!(events[..], [DeviceEvent::Rt(RtEvent::Exchanging(_))]),
        "{events:?}"
    );
}

/// Issue 36: the response written in place and the outputs read beside the
/// hook reach the same bytes as `set_input_data` and `output_data`.
#[test]
fn p027_p042_inputs_written_in_place_and_outputs_read_beside_the_hook() {
    let mut d = connected();
    let input_id = d.cm().ar().unwrap().input_cr.as_ref().unwrap().frame_id;
    assert_eq!(
        d.output_data_with_hook(2).0,
        None,
        "nothing before the first frame"
    );
    let cycle = Nanos::from_ms(8);
    for k in 0..4u16 {
        let now = cycle * u64::from(k);
        let f = output_frame(&d, k * 256, 0x10 + k as u8);
        sent(&mut d, now, &f);
        assert_eq!(d.output_data_with_hook(2).0, Some(&[0x10 + k as u8; 36][..]));
        let data = d.input_data_mut(1).expect("slot 1 carries the inputs");
        assert_eq!(data.len(), 36, "the module's configured length");
        data.fill(0x5A + k as u8);
        let sent_inputs: Vec<_> = poll(&mut d, now)
            .into_iter()
            .filter(|f| frame_id(f) == Some(input_id))
            .collect();
        assert!(!sent_inputs.is_empty(), "an input frame in cycle {k}");
        for f in sent_inputs {
            assert!(f.windows(36).any(|w| w == [0x5A + k as u8; 36]), "cycle {k}");
        }
    }
    assert!(d.input_data_mut(2).is_none(), "slot 2 is an IN module");
}

#[test]
fn p036_no_output_frames_for_the_watchdog_time_loses_the_ar() {
    let mut d = connected();
    let cycle = Nanos::from_ms(8);
    for k in 0..5u16 {
        let f = output_frame(&d, k * 256, 1);
        sent(&mut d, cycle * u64::from(k), &f);
        poll(&mut d, cycle * u64::from(k));
    }
    while d.take_event().is_some() {}
    let mut err_pdu = false;
    let mut t = cycle * 5;
    while t < Nanos::from_ms(200) {
        for f in poll(&mut d, t) {
            err_pdu |= matches!(frame_id(&f), Some(0xFC01 | 0xFE01));
        }
        t += Nanos::from_ms(1);
    }
    let events: Vec<_> = std::iter::from_fn(|| d.take_event()).collect();
    assert!(
        events
            .iter()
            .any(|e| matches!(e, DeviceEvent::Rt(RtEvent::ArLost(_)))),
        "{events:?}"
    );
    assert!(
        events
            .iter()
            .any(|e| matches!(e, DeviceEvent::Cm(CmEvent::Aborted(..)))),
        "{events:?}"
    );
    assert!(err_pdu, "the ERR-RTA-PDU tells the controller");
    assert!(d.cm().ar().is_none());
    assert_eq!(d.output_data(2), None);
    assert!(d.leds(t).0, "SF steady after a watchdog expiry (P-021)");
}

#[test]
fn p030_a_drive_error_goes_out_as_a_diagnosis_alarm_with_0x1000_plus_hh_s() {
    let mut d = connected();
    let f = output_frame(&d, 0, 1);
    sent(&mut d, Nanos::ZERO, &f);
    assert!(d.raise_diagnosis(54, 3));
    let frames = poll(&mut d, Nanos::ZERO);
    let alarm = frames
        .iter()
        .find(|f| frame_id(f) == Some(0xFE01))
        .expect("a low-priority alarm frame");
    // ChannelErrorType 0x1036 (HH 54), ExtChannelErrorType 0x1003 (S 3)
    assert!(alarm.windows(4).any(|w| w == [0x10, 0x36, 0x10, 0x03]));
    assert!(d.diagnosis_present());
    assert!(!d.raise_diagnosis(97, 0), "HH outside 1…96");
}

/// The low-priority alarm frames among `frames`.
fn alarms(frames: &[Vec<u8>]) -> Vec<Vec<u8>> {
    frames
        .iter()
        .filter(|f| frame_id(f) == Some(0xFE01) && f.len() > 40)
        .cloned()
        .collect()
}

/// Whether an alarm frame carries AlarmType `ty` for subslot `subslot` with
/// (ChannelErrorType, ExtChannelErrorType) `types`.
fn alarm_is(f: &[u8], ty: u16, subslot: u16, types: (u16, u16)) -> bool {
    let mut at = std::vec::Vec::new();
    at.extend_from_slice(&ty.to_be_bytes());
    let mut e = std::vec::Vec::new();
    e.extend_from_slice(&types.0.to_be_bytes());
    e.extend_from_slice(&types.1.to_be_bytes());
    f.windows(2).any(|w| w == at)
        && f.windows(2).any(|w| w == subslot.to_be_bytes())
        && f.windows(4).any(|w| w == e)
}

/// The controller's answer to our alarm frame `ours` as profinet-py sends
/// it: a transport ACK, then an AlarmAck (DATA, its send sequence number
/// `seq`) naming the alarm, with status OK.
fn ack_alarm(d: &mut Device, ours: &[u8], seq: u16, now: Nanos) {
    let e = EthFrame::parse(ours).unwrap();
    let (h, v) = crate::alarm::RtaHeader::parse(&e.payload[2..]).unwrap();
    let frame = |pdu: u8, flags: u8, send: u16, var: &[u8]| {
        let mut f = std::vec::Vec::new();
        f.extend_from_slice(&OUR_MAC.0);
        f.extend_from_slice(&CTRL_MAC.0);
        f.extend_from_slice(&[0x81, 0x00, 0xA0, 0x00, 0x88, 0x92, 0xFE, 0x01]);
        for x in [h.src_endpoint, h.dst_endpoint] {
            f.extend_from_slice(&x.to_be_bytes());
        }
        f.extend_from_slice(&[pdu, flags]);
        for x in [send, h.send_seq, var.len() as u16] {
            f.extend_from_slice(&x.to_be_bytes());
        }
        f.extend_from_slice(var);
        f.resize(f.len().max(60), 0);
        f
    };
    // its last DATA's number (0xFFFF before the first)
    let last = if seq == 0xFFFF || seq == 0 {
        0xFFFF
    } else {
        seq - 1
    };
    sent(d, now, &frame(0x13, 0x01, last, &[]));
    // AlarmAck-Low: AlarmType, API, slot, subslot of the notification, its specifier, OK
    let mut ack = std::vec![0x80, 0x02, 0x00, 0x12, 0x01, 0x00];
    ack.extend_from_slice(&v[6..16]);
    ack.extend_from_slice(&v[24..26]);
    ack.extend_from_slice(&[0; 4]);
    sent(d, now, &frame(0x11, 0x11, seq, &ack));
    poll(d, now);
}

#[test]
fn p040_a_topology_mismatch_raises_a_port_diagnosis_alarm_that_disappears_when_it_matches() {
    use crate::pdev::tests::{lldp_from_switch, record_rpc};
    use crate::pdev::tests_check::{check, LINK_UP_CHECK, PEERS_SW1};
    let mut d = connected();
    let f = output_frame(&d, 0, 1);
    sent(&mut d, Nanos::ZERO, &f);
    poll(&mut d, Nanos::ZERO);
    assert!(!d.diagnosis_present());
    // TIA's check: port-003 of sw-1 on port 1, link up; port 1 has no neighbour yet
    let mut subs = crate::rpc::tests::hex(PEERS_SW1);
    subs.extend_from_slice(&crate::rpc::tests::hex(LINK_UP_CHECK));
    let rpc = record_rpc(
        true,
        300,
        0,
        0x8001,
        crate::pdev::index::PD_PORT_DATA_CHECK,
        &check(0x8001, &subs),
    );
    let out = sent(&mut d, Nanos::ZERO, &testing::udp_to_device(&rpc));
    assert_eq!(out.len(), 1);
    let a = alarms(&poll(&mut d, Nanos::from_ms(1)));
    assert_eq!(a.len(), 1, "one appears alarm");
    assert!(
        alarm_is(&a[0], 0x0001, 0x8001, (0x8001, 0x8005)),
        "no peer detected"
    );
    assert!(d.diagnosis_present());
    ack_alarm(&mut d, &a[0], 0xFFFF, Nanos::from_ms(1));
    // the expected neighbour answers: the diagnosis disappears
    sent(&mut d, Nanos::from_ms(2), &lldp_from_switch());
    let a = alarms(&poll(&mut d, Nanos::from_ms(2)));
    assert_eq!(a.len(), 1, "one disappears alarm");
    assert!(alarm_is(&a[0], 0x000C, 0x8001, (0x8001, 0x8005)));
    ack_alarm(&mut d, &a[0], 0, Nanos::from_ms(2));
    assert!(!d.diagnosis_present());
    // another station on port 1: peer name of station mismatch
    let mut other = lldp_from_switch();
    let at = other.windows(4).position(|w| w == b"sw-1").unwrap();
    other[at + 3] = b'2';
    sent(&mut d, Nanos::from_ms(3), &other);
    let a = alarms(&poll(&mut d, Nanos::from_ms(3)));
    assert!(
        alarm_is(&a[0], 0x0001, 0x8001, (0x8001, 0x8000)),
        "station mismatch"
    );
    ack_alarm(&mut d, &a[0], 1, Nanos::from_ms(3));
    sent(&mut d, Nanos::from_ms(4), &lldp_from_switch());
    let a = alarms(&poll(&mut d, Nanos::from_ms(4)));
    assert!(alarm_is(&a[0], 0x000C, 0x8001, (0x8001, 0x8000)));
    ack_alarm(&mut d, &a[0], 2, Nanos::from_ms(4));
    // the link goes down: link state mismatch on port 1's subslot
    d.set_port_link(1, false);
    let a = alarms(&poll(&mut d, Nanos::from_ms(5)));
    assert!(alarm_is(&a[0], 0x0001, 0x8001, (0x8000, 0x8000)), "link down");
    ack_alarm(&mut d, &a[0], 3, Nanos::from_ms(5));
    assert!(d.diagnosis_present());
    // port 2 has no check: its link changes raise nothing
    d.set_port_link(2, true);
    assert!(alarms(&poll(&mut d, Nanos::from_ms(6))).is_empty());
}

#[test]
fn p038_lldp_counters_move_when_lldpdus_go_out_and_come_in() {
    use crate::pdev::tests::lldp_from_switch;
    let mut d = device();
    let a = d.lldp_agent();
    // the timing LLDP-MIB shows is what the transmitter uses: 5 s, TTL 20 s = 4 x 5 s
    assert_eq!((a.tx_interval, a.hold), (5, 4));
    assert_eq!(a.stats, snmp::LldpStats::default());
    // two polls 5 s apart: two LLDPDUs on each port
    poll(&mut d, Nanos::ZERO);
    let out = poll(&mut d, Nanos::from_secs(5));
    let ttl = EthFrame::parse(&out[0]).unwrap().payload;
    // chassis, port ID TLVs, then the TTL TLV's value = interval x hold
    let skip = 2 + usize::from(ttl[1]);
    let skip = skip + 2 + usize::from(ttl[skip + 1]);
    let ttl = u32::from(u16::from_be_bytes([ttl[skip + 2], ttl[skip + 3]]));
    assert_eq!(ttl, a.tx_interval * a.hold);
    assert_eq!(d.lldp_agent().stats.tx, [2, 2]);
    // a neighbour's LLDPDU with a reserved TLV type (9) before End: inserted once
    let mut f = lldp_from_switch();
    let end = 14 + 7 + 11 + 4;
    f.splice(end..end, [9 << 1, 1, 0xAA]);
    f.truncate(60);
    sent(&mut d, Nanos::from_secs(6), &f);
    sent(&mut d, Nanos::from_secs(7), &lldp_from_switch());
    let s = d.lldp_agent().stats;
    assert_eq!((s.rx[0].frames, s.rx[0].discarded, s.rx[0].errors), (2, 0, 0));
    assert_eq!(s.rx[0].tlvs_unrecognized, 1);
    assert_eq!((s.inserts, s.last_change_cs), (1, 600));
    // a malformed LLDPDU (TTL TLV missing): counted as discarded and in error, nothing else
    let mut bad = lldp_from_switch();
    bad[14 + 7 + 11] = 0;
    sent(&mut d, Nanos::from_secs(8), &bad);
    let s = d.lldp_agent().stats;
    assert_eq!((s.rx[0].frames, s.rx[0].discarded, s.rx[0].errors), (3, 1, 1));
    assert_eq!((s.inserts, s.ageouts), (1, 0));
    assert!(d.cm().pdev().port(1).unwrap().peer.is_some());
    // the TTL (20 s) runs out: one ageout on port 1, and the table changed then
    poll(&mut d, Nanos::from_secs(28));
    let s = d.lldp_agent().stats;
    assert_eq!((s.ageouts, s.rx[0].ageouts, s.rx[1].ageouts), (1, 1, 0));
    assert_eq!(s.last_change_cs, 2800);
    assert!(d.cm().pdev().port(1).unwrap().peer.is_none());
}
