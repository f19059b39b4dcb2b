//! The in-process IO controller ([`PnController`]) acknowledges the drive's
//! diagnosis alarms as profinet-py does (P-043: a transport ACK, then an
//! AlarmAck DATA), so a fault raised and reset while cyclic data runs
//! (P-030, P-035, P-227) leaves the AR up: no retransmission runs out and
//! aborts it.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use hil_sim::fb::controller::PnController;
use hil_sim::fb::rig::FbRig;
use hil_sim::fb::FbOutputs;
use hil_sim::pcap::Recording;
use hil_sim::pn::Command;

common::fb_rig!(Rig);

impl Rig {
    fn new(pcap: Option<Recording>) -> Rig {
        Rig(FbRig::recorded(PnController::drive(), pcap).expect("connect"))
    }

    fn cycle(&mut self) {
        self.0.cycle().expect("exchange");
    }

    fn until(&mut self, ms: u64, done: impl Fn(&FbOutputs) -> bool) -> bool {
        self.0.until(ms, done).expect("exchange")
    }

    fn enable(&mut self) {
        let enabled = self.0.enable_within(500).expect("exchange");
        assert!(enabled, "enabled: {:#06x}", self.o.zsw1);
    }

    /// Event 44 cause 1 on axis A, then the FB's fault_reset until the
    /// fault is gone.
    fn fault_and_reset(&mut self) {
        let line = self.ctl.sim_mut().command(Command::Fault {
            axis: 0,
            event: 44,
            cause: 1,
        });
        assert!(line.contains("raised"), "{line}");
        assert!(self.until(200, |o| o.fault), "fault shown: {:#06x}", self.o.zsw1);
        // the controller sits in the fault for a while (longer than the
        // alarm CR's retransmissions would last)
        assert!(!self.until(1000, |o| !o.fault), "the fault stays until reset");
        self.i.fault_reset = true;
        assert!(self.until(200, |o| !o.fault), "fault reset: {:#06x}", self.o.zsw1);
        self.i.fault_reset = false;
    }
}

#[test]
fn p043_p227_fault_alarms_are_acknowledged_and_the_ar_stays_up() {
    let mut r = Rig::new(None);
    assert!(r.until(100, |o| o.identifier != 0), "a response telegram");
    r.enable();
    let before = r.ctl.sim().device().alarm_stats().expect("an alarm CR");
    assert_eq!(before.sent, 0);
    r.fault_and_reset();
    r.enable();
    // seconds of cyclic exchange after the fault and its reset
    for _ in 0..5000 {
        r.cycle();
    }
    assert!(r.ctl.sim().device().exchanging(), "the AR is up");
    assert!(r.o.drive_is_enabled, "enabled again: {:#06x}", r.o.zsw1);
    let s = r
        .ctl
        .sim()
        .device()
        .alarm_stats()
        .expect("the same AR's alarm CR");
    assert!(s.sent >= 2, "appears and disappears sent: {s:?}");
    assert_eq!(s.acked, s.sent, "every alarm acknowledged: {s:?}");
    assert_eq!(s.retransmitted, 0, "none repeated: {s:?}");
    assert_eq!(s.refused, 0, "none of the controller's frames refused: {s:?}");
    let c = r.ctl.alarm_stats();
    assert_eq!(c.received, s.sent, "the controller took each alarm once: {c:?}");
    assert_eq!(c.acknowledged, s.sent, "and acknowledged it: {c:?}");
    let events = r.ctl.take_events();
    assert!(
        !events
            .iter()
            .any(|(_, e)| e.contains("lost") || e.contains("aborted")),
        "{events:?}"
    );
}

#[test]
fn p043_a_second_fault_is_acknowledged_too() {
    let mut r = Rig::new(None);
    assert!(r.until(100, |o| o.identifier != 0), "a response telegram");
    r.enable();
    for _ in 0..2 {
        r.fault_and_reset();
        r.enable();
    }
    for _ in 0..2000 {
        r.cycle();
    }
    let s = r.ctl.sim().device().alarm_stats().expect("an alarm CR");
    assert!(s.sent >= 4, "two appears and two disappears: {s:?}");
    assert_eq!((s.acked, s.retransmitted), (s.sent, 0), "{s:?}");
}

/// The alarm frames both ways are in the recording: the drive's DATA
/// (FrameID 0xFE01, PDU type 1), the controller's ACK (type 3) and AlarmAck
/// (type 1, block 0x8002).
#[test]
fn p043_the_recording_holds_the_alarms_and_their_acknowledgements() {
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("pn_alarms.pcap");
    let rec = Recording::create(&path).expect("pcap");
    let mut r = Rig::new(Some(rec));
    assert!(r.until(100, |o| o.identifier != 0), "a response telegram");
    r.enable();
    r.fault_and_reset();
    for _ in 0..100 {
        r.cycle();
    }
    r.ctl.take_recording().expect("recording").flush().expect("flush");
    let b = std::fs::read(&path).expect("read");
    // pcap records: 16-byte header, then the frame; alarm frames are tagged
    // (802.1Q) low-priority RTA: FrameID at 18, PDU type at 24, block at 32
    let mut at = 24;
    let (mut data_from_drive, mut acks, mut alarm_acks) = (0, 0, 0);
    while at + 16 <= b.len() {
        let n = u32::from_le_bytes(b[at + 8..at + 12].try_into().unwrap()) as usize;
        let f = &b[at + 16..at + 16 + n];
        at += 16 + n;
        if f.len() < 30 || f[12..14] != [0x81, 0x00] || f[16..18] != [0x88, 0x92] {
            continue;
        }
        if f[18..20] != [0xFE, 0x01] {
            continue;
        }
        let from_drive = f[6..12] == profinet::testing::DEVICE_MAC.0;
        match (from_drive, f[24] & 0x0F) {
            (true, 1) => data_from_drive += 1,
            (false, 3) => acks += 1,
            (false, 1) if f[32..34] == [0x80, 0x02] => alarm_acks += 1,
            _ => {}
        }
    }
    assert!(data_from_drive >= 2, "appears and disappears");
    assert_eq!(acks, data_from_drive, "a transport ACK for each");
    assert_eq!(alarm_acks, data_from_drive, "an AlarmAck for each");
}
