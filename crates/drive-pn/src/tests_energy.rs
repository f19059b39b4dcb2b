//! PROFIenergy on the drive (P-015, P-016): A275 switches record 0x80A0, a
//! pause switches both power stages off and is only taken with the axes
//! idle, End_Pause, the end of the AR and A275 = 0 end it.

use super::tests::{drive, run, TestFlash};
use super::*;
use cia402::State;
use drive_core::params::A275;
use profinet::cm::PnioStatus;
use profinet::ip::UDP_PAYLOAD_OFFSET;
use profinet::profienergy::INDEX;
use std::vec::Vec;

use super::tests::vectors;

fn hex(s: &str) -> Vec<u8> {
    let s: std::string::String = s.chars().filter(|c| c.is_ascii_hexdigit()).collect();
    (0..s.len() / 2)
        .map(|i| u8::from_str_radix(&s[2 * i..2 * i + 2], 16).unwrap())
        .collect()
}

/// A record read or write of 0x80A0 at slot 0 subslot 1 as the Connect's
/// AR: the PNIO status, and for a read the record data.
fn record(d: &mut PnDrive<TestFlash>, seq: u32, write: bool, data: &[u8]) -> (PnioStatus, Vec<u8>) {
    record_at(d, seq, write, INDEX, data)
}

/// A record read or write of `index` at slot 0 subslot 1 as the Connect's
/// AR: the PNIO status, and for a read the record data.
pub(crate) fn record_at(
    d: &mut PnDrive<TestFlash>,
    seq: u32,
    write: bool,
    index: u16,
    data: &[u8],
) -> (PnioStatus, Vec<u8>) {
    let mut rpc = hex(vectors::READ_IM0);
    rpc[64..68].copy_from_slice(&seq.to_be_bytes());
    rpc[68..70].copy_from_slice(&(if write { 3u16 } else { 2 }).to_be_bytes());
    rpc[101] = if write { 0x08 } else { 0x09 };
    rpc[100 + 34..100 + 36].copy_from_slice(&index.to_be_bytes());
    if write {
        rpc[100 + 36..100 + 40].copy_from_slice(&(data.len() as u32).to_be_bytes());
        rpc.extend_from_slice(data);
        let args = (rpc.len() - 100) as u32;
        rpc[84..88].copy_from_slice(&args.to_be_bytes());
        rpc[96..100].copy_from_slice(&args.to_be_bytes());
        let body = (rpc.len() - 80) as u16;
        rpc[74..76].copy_from_slice(&body.to_be_bytes());
    }
    let frame = profinet::testing::udp_to_device(&rpc);
    let mut out = Vec::new();
    d.receive(
        Nanos::ZERO,
        &frame,
        &mut |f: &[u8]| out.push(f.to_vec()),
        &mut |_| {},
    );
    let p = &out[0][UDP_PAYLOAD_OFFSET + 80..];
    let status = PnioStatus::from_u32(u32::from_be_bytes(p[..4].try_into().unwrap()));
    let args = &p[20..];
    let len = u32::from_be_bytes(args[36..40].try_into().unwrap()) as usize;
    let rec = if write {
        Vec::new()
    } else {
        args[64..64 + len].to_vec()
    };
    (status, rec)
}

/// A PROFIenergy request and its response (block and header stripped:
/// service, reference, status, DSI_RS, data).
fn service(d: &mut PnDrive<TestFlash>, seq: u32, req: &[u8]) -> Vec<u8> {
    let mut v = std::vec![0x08, 0x00, 0, 0, 1, 0];
    v.extend_from_slice(req);
    let len = (v.len() - 4) as u16;
    v[2..4].copy_from_slice(&len.to_be_bytes());
    assert_eq!(record(d, seq, true, &v).0, PnioStatus::OK);
    let (status, resp) = record(d, seq + 1, false, &[]);
    assert_eq!(status, PnioStatus::OK);
    assert_eq!(&resp[..2], &[0x08, 0x01]);
    resp[6..].to_vec()
}

fn start_pause(d: &mut PnDrive<TestFlash>, seq: u32) -> Vec<u8> {
    let mut req = std::vec![1, 1, 0, 1];
    req.extend_from_slice(&60_000u32.to_be_bytes());
    service(d, seq, &req)
}

/// Controlword Shutdown, Switch on, Enable operation on axis A, a few
/// cycles each.
fn enable_axis_a(d: &mut PnDrive<TestFlash>, from: u64) -> u64 {
    let mut t = from;
    for cw in [0x06, 0x07, 0x0F] {
        d.objects_mut().set(0x6040, 0, cw).unwrap();
        run(d, t, t + 5, true);
        t += 5;
    }
    t
}

fn energy_on() -> PnDrive<TestFlash> {
    let mut d = drive();
    d.objects_mut().set(A275, 0, 1).unwrap();
    run(&mut d, 0, 20, true);
    d
}

#[test]
fn p015_p016_with_a275_off_record_0x80a0_is_an_invalid_index() {
    let mut d = drive();
    assert_eq!(d.objects().get(A275, 0), Ok(0));
    let pe_identify = hex("0800 0006 0100 05 01 00 00");
    assert_eq!(
        record(&mut d, 300, true, &pe_identify).0,
        PnioStatus::rw(0xDF, 0xB0)
    );
    assert_eq!(record(&mut d, 301, false, &[]).0, PnioStatus::rw(0xDE, 0xB0));
    d.objects_mut().set(A275, 0, 1).unwrap();
    assert_eq!(
        service(&mut d, 302, &[5, 1, 0, 0]),
        hex("05 01 01 01 05 0102030405")
    );
}

#[test]
fn p016_a_pause_switches_both_power_stages_off_until_end_pause() {
    let mut d = energy_on();
    assert_eq!(start_pause(&mut d, 300), hex("01 01 01 01 01 00"));
    assert!(d.energy_paused());
    // the controller enables axis A: without supply it stays switch-on disabled
    let t = enable_axis_a(&mut d, 20);
    assert_eq!(d.axes()[0].state(), State::SwitchOnDisabled);
    let cmds = d.control_cycle(Nanos::from_ms(t), &[AxisIo::ready(0), AxisIo::ready(0)]);
    assert!(cmds.iter().all(|c| !c.power_stage));
    // PEM_Status: in mode 1
    assert_eq!(
        &service(&mut d, 310, &[4, 2, 0, 0])[..6],
        &hex("04 02 01 01 01 01")[..]
    );
    assert_eq!(service(&mut d, 320, &[2, 3, 0, 0]), hex("02 03 01 01 00000000"));
    assert!(!d.energy_paused());
    let t = enable_axis_a(&mut d, t + 1);
    assert_eq!(d.axes()[0].state(), State::OperationEnabled);
    let cmds = d.control_cycle(Nanos::from_ms(t), &[AxisIo::ready(0), AxisIo::ready(0)]);
    assert!(cmds[0].power_stage);
}

#[test]
fn p016_start_pause_is_refused_while_an_axis_is_enabled() {
    let mut d = energy_on();
    enable_axis_a(&mut d, 20);
    assert_eq!(d.axes()[0].state(), State::OperationEnabled);
    // error 0x53: no switch to energy saving mode because of state operate
    assert_eq!(start_pause(&mut d, 300), hex("01 01 02 ff 53 00"));
    assert!(!d.energy_paused());
}

#[test]
fn p016_the_pause_ends_with_a275_off_and_with_the_ar() {
    let mut d = energy_on();
    start_pause(&mut d, 300);
    d.objects_mut().set(A275, 0, 0).unwrap();
    run(&mut d, 20, 21, true);
    assert!(!d.energy_paused(), "A275 = 0 ends the pause");
    d.objects_mut().set(A275, 0, 1).unwrap();
    start_pause(&mut d, 310);
    assert!(d.energy_paused());
    // no output frames: the watchdog ends the AR, and the pause with it
    run(&mut d, 21, 200, false);
    assert!(d.device().cm().ar().is_none());
    assert!(!d.energy_paused());
}
