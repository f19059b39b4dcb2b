//! The drive on PROFINET through frames: a fault becomes a diagnosis alarm
//! and goes with the reset; a lost AR faults both axes.

use super::*;
use core::net::Ipv4Addr;
use profinet::cm::{CmEvent, Im0, ImData};
use profinet::dcp::IpSuite;
use profinet::ip::{Endpoint, IpConfig, Stack, UdpTx, RPC_PORT, UDP_PAYLOAD_OFFSET};
use profinet::wire::{EthFrame, MacAddr};
use std::vec::Vec;

pub(crate) const OUR: MacAddr = MacAddr([2, 0, 0, 0, 0, 0x50]);
pub(crate) const CTRL: MacAddr = MacAddr([2, 0, 0, 0, 0, 0xC0]);

#[path = "../../profinet/src/cm/tests_vectors.rs"]
#[allow(dead_code)]
pub(crate) mod vectors;

fn hex(s: &str) -> Vec<u8> {
    let s: std::string::String = s.chars().filter(|c| c.is_ascii_hexdigit()).collect();
    (0..s.len() / 2)
        .map(|i| u8::from_str_radix(&s[2 * i..2 * i + 2], 16).unwrap())
        .collect()
}

/// The flash of these tests (the board's parameter flash: 2 × 2 KiB).
pub(crate) type TestFlash = PnParamFlash;

/// The board's data of the test device.
pub(crate) fn hardware() -> Hardware {
    Hardware {
        mac: OUR,
        port_macs: [MacAddr([2, 0, 0, 0, 0, 0x51]), MacAddr([2, 0, 0, 0, 0, 0x52])],
        im0: Im0::drive("T1"),
        im: ImData::default(),
        boot_time: 1,
    }
}

/// A drive commissioned as "drive-1" at 192.168.0.50/24 (saved, restarted).
pub(crate) fn commissioned() -> PnDrive<TestFlash> {
    let mut d = PnDrive::new(TestFlash::new(), hardware());
    settings::write_name(&mut d.objects, &"drive-1".parse().unwrap());
    settings::write_ip(
        &mut d.objects,
        IpSuite {
            ip: Ipv4Addr::new(192, 168, 0, 50),
            mask: Ipv4Addr::new(255, 255, 255, 0),
            gateway: Ipv4Addr::UNSPECIFIED,
        },
    );
    assert!(d.save());
    PnDrive::new(d.into_flash(), hardware())
}

/// [`commissioned`], with profinet-py's AR connected.
pub(crate) fn drive() -> PnDrive<TestFlash> {
    connected(commissioned())
}

/// `d` (commissioned as "drive-1") with profinet-py's AR connected.
pub(crate) fn connected(mut d: PnDrive<TestFlash>) -> PnDrive<TestFlash> {
    let frame = rpc_frame(&hex(vectors::CONNECT));
    let mut connected = false;
    d.receive(Nanos::ZERO, &frame, &mut |_: &[u8]| {}, &mut |e| {
        connected |= matches!(e, DeviceEvent::Cm(CmEvent::Connected(_)))
    });
    assert!(connected);
    d
}

/// The frame carrying the RPC request `req` over UDP from the controller
/// (192.168.0.10, port C000h) to the commissioned drive at 192.168.0.50.
pub(crate) fn rpc_frame(req: &[u8]) -> Vec<u8> {
    let mut ctrl = Stack::new(
        CTRL,
        IpConfig {
            addr: Ipv4Addr::new(192, 168, 0, 10),
            netmask: Ipv4Addr::new(255, 255, 255, 0),
            gateway: Ipv4Addr::UNSPECIFIED,
        },
    );
    let ep = Endpoint {
        ip: Ipv4Addr::new(192, 168, 0, 50),
        port: RPC_PORT,
    };
    ctrl.learn(Nanos::ZERO, ep.ip, OUR);
    let mut tx = std::vec![0u8; 1600];
    tx[UDP_PAYLOAD_OFFSET..UDP_PAYLOAD_OFFSET + req.len()].copy_from_slice(req);
    let Ok(UdpTx::Frame(n)) = ctrl.emit_udp(Nanos::ZERO, &mut tx, 0xC000, ep, req.len()) else {
        panic!("no frame")
    };
    tx.truncate(n);
    tx
}

/// The frames the drive sends for `frame` (received at 1 ms).
pub(crate) fn send(d: &mut PnDrive<TestFlash>, frame: &[u8]) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    d.receive(
        Nanos::from_ms(1),
        frame,
        &mut |f: &[u8]| out.push(f.to_vec()),
        &mut |_| {},
    );
    out
}

fn output_frame(d: &PnDrive<TestFlash>, counter: u16) -> Vec<u8> {
    let cr = d.device().cm().ar().unwrap().output_cr.clone().unwrap();
    let n = 14 + 2 + cr.data_length as usize + 4;
    let mut f = std::vec![0u8; n];
    f[..6].copy_from_slice(&OUR.0);
    f[6..12].copy_from_slice(&CTRL.0);
    f[12..14].copy_from_slice(&0x8892u16.to_be_bytes());
    f[14..16].copy_from_slice(&cr.frame_id.to_be_bytes());
    for o in &cr.data {
        f[16 + o.frame_offset as usize + o.data_len as usize] = 0x80;
    }
    for c in &cr.iocs {
        f[16 + c.frame_offset as usize] = 0x80;
    }
    f[n - 4..n - 2].copy_from_slice(&counter.to_be_bytes());
    f[n - 2] = 0x35;
    f
}

/// Runs 1 ms steps from `from` to `to`: output frames every 8 ms while
/// `frames`, a control cycle every ms; returns the alarm frames sent.
pub(crate) fn run(d: &mut PnDrive<TestFlash>, from: u64, to: u64, frames: bool) -> Vec<Vec<u8>> {
    run_io(d, from, to, frames, &[AxisIo::ready(0), AxisIo::ready(0)])
}

/// [`run`] with the axes' inputs `io`.
fn run_io(d: &mut PnDrive<TestFlash>, from: u64, to: u64, frames: bool, io: &[AxisIo; 2]) -> Vec<Vec<u8>> {
    let mut alarms = Vec::new();
    let io = *io;
    for ms in from..to {
        let now = Nanos::from_ms(ms);
        let mut tx = |f: &[u8]| {
            if let Some(e) = EthFrame::parse(f) {
                if e.ethertype == 0x8892 && e.payload.get(..2) == Some(&[0xFE, 0x01]) {
                    alarms.push(f.to_vec());
                }
            }
        };
        if frames && ms % 8 == 0 {
            let f = output_frame(d, (ms / 8 * 256) as u16);
            d.receive(now, &f, &mut tx, &mut |_| {});
        }
        d.poll(now, &mut tx, &mut |_| {});
        d.control_cycle(now, &io);
    }
    alarms
}

#[test]
fn p030_p035_a_drive_fault_is_a_diagnosis_alarm_and_goes_with_the_reset() {
    let mut d = drive();
    run(&mut d, 0, 50, true);
    // a following error (event 54) on axis A
    d.axes_mut()[0].raise_event(motion::Event { number: 54, cause: 2 });
    let alarms = run(&mut d, 50, 60, true);
    assert_eq!(alarms.len(), 1, "one appears alarm");
    assert!(
        alarms[0].windows(4).any(|w| w == [0x10, 0x36, 0x10, 0x02]),
        "0x1036 / 0x1002"
    );
    assert!(d.device().diagnosis_present());
    assert_eq!(d.objects().get(E82, 0).unwrap(), 54);
    // fault reset: controlword 0x80 on axis A
    d.objects_mut().set(0x6040, 0, 0x80).unwrap();
    run(&mut d, 60, 70, true);
    assert!(!d.device().diagnosis_present(), "the reset clears the diagnosis");
}

/// E-089's event table on PROFINET (issue 34): an over-current trip of
/// axis A's current loop is the PROFIdrive fault of event 33: a diagnosis
/// alarm, E82 = 33, 603Fh = 2310h; the acknowledge clears it once the loop
/// reports no trip.
#[test]
fn p030_e089_a_current_loop_over_current_trip_is_a_diagnosis_alarm_with_event_33() {
    use drive_core::axis::{CurrentActual, CurrentTrip};
    let mut d = drive();
    run(&mut d, 0, 50, true);
    let mut tripped = AxisIo::ready(0);
    tripped.current = Some(CurrentActual {
        trip: Some(CurrentTrip::OverCurrent),
        ..CurrentActual::measured(0.0, 0.0)
    });
    let alarms = run_io(&mut d, 50, 60, true, &[tripped, AxisIo::ready(0)]);
    assert_eq!(alarms.len(), 1, "one appears alarm");
    assert!(d.device().diagnosis_present());
    assert_eq!(d.objects().get(E82, 0).unwrap(), 33);
    assert_eq!(d.objects().get(0x603F, 0).unwrap(), 0x2310);
    assert!(d.axes()[0].state().is_fault());
    d.objects_mut().set(0x6040, 0, 0x80).unwrap();
    run(&mut d, 60, 70, true);
    assert!(!d.device().diagnosis_present(), "the reset clears the diagnosis");
}

#[test]
fn p036_a_lost_ar_faults_both_axes_with_event_52() {
    let mut d = drive();
    run(&mut d, 0, 50, true);
    run(&mut d, 50, 200, false);
    assert!(d.device().cm().ar().is_none(), "the watchdog ended the AR");
    for a in d.axes() {
        assert!(a.state().is_fault(), "{:?}", a.state());
    }
    assert_eq!(d.objects().get(E82, 0).unwrap(), i64::from(AR_LOST_EVENT));
    assert_eq!(d.objects().get(E43, 0).unwrap(), i64::from(AR_LOST_CAUSE));
    assert!(d.device().diagnosis_present(), "kept for the next AR's records");
}

/// The free-running control cycle follows A150 (there is no SYNC0 on
/// PROFINET); a value A150 does not allow falls back to the default.
#[test]
fn c144_the_control_period_is_a150() {
    let mut d = commissioned();
    assert_eq!(d.control_period(), Nanos::from_us(u64::from(A150_FALLBACK_US)));
    d.objects_mut().set(A150, 0, 250).unwrap();
    assert_eq!(d.control_period(), Nanos::from_us(250));
    d.objects_mut().set(A150, 0, 2000).unwrap();
    assert_eq!(d.control_period(), Nanos::from_ms(2));
}
