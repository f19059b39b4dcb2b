//! The PROFINET operating parameters A270…A278 (spec §2.4) through DCP
//! frames, the dictionary and restarts over the same flash.

use super::tests::{drive, hardware, rpc_frame, run, send, TestFlash};
use super::*;
use core::net::Ipv4Addr;
use drive_core::params::{A272, A273, A274, A275, A276, A277, A278};
use drive_core::PERSISTENT_IMAGE_BYTES;
use od::{CommState, Dictionary, SdoAbort};
use profinet::dcp::pdu::{BlockRepr, BlockType, ServiceId, Value};
use profinet::wire::{EthFrame, MacAddr};
use std::vec::Vec;

const OUR: MacAddr = MacAddr([2, 0, 0, 0, 0, 0x50]);
const PLC: MacAddr = MacAddr([2, 0, 0, 0, 0, 0xC0]);

fn fresh() -> PnDrive<TestFlash> {
    PnDrive::new(TestFlash::new(), hardware())
}

/// Save & Reset's reset: a new drive over the same flash.
fn restart(d: PnDrive<TestFlash>) -> PnDrive<TestFlash> {
    PnDrive::new(d.into_flash(), hardware())
}

fn dcp(dst: MacAddr, frame_id: u16, service: ServiceId, blocks: &[BlockRepr<'_>]) -> Vec<u8> {
    let delay = if service == ServiceId::Identify { 1 } else { 0 };
    let mut f = profinet::testing::dcp_request(dst, PLC, frame_id, service, 7, delay, blocks).to_vec();
    f.resize(f.len().max(60), 0);
    f
}

fn identify_all() -> Vec<u8> {
    let all = BlockRepr {
        kind: BlockType::All,
        prefix: None,
        value: Value::Empty,
    };
    dcp(MacAddr::DCP_IDENTIFY, 0xFEFE, ServiceId::Identify, &[all])
}

fn set(kind: BlockType, qualifier: u16, value: Value<'_>) -> Vec<u8> {
    let block = BlockRepr {
        kind,
        prefix: Some(qualifier),
        value,
    };
    dcp(OUR, 0xFEFD, ServiceId::Set, &[block])
}

const PERMANENT: u16 = 1;
const TEMPORARY: u16 = 0;

fn set_name(name: &str, qualifier: u16) -> Vec<u8> {
    set(BlockType::NameOfStation, qualifier, Value::Bytes(name.as_bytes()))
}

fn set_ip(suite: IpSuite, qualifier: u16) -> Vec<u8> {
    set(BlockType::IpParameter, qualifier, Value::IpParameter(suite))
}

/// Reset to factory with BlockQualifier mode `mode` (1, 2, 4 or 8).
fn reset(mode: u16) -> Vec<u8> {
    set(BlockType::ControlResetToFactory, mode << 1, Value::Empty)
}

/// The Identify answer, if the drive gives one.
fn identify(d: &mut PnDrive<TestFlash>) -> Option<Vec<u8>> {
    send(d, &identify_all()).into_iter().find(|f| {
        EthFrame::parse(f).is_some_and(|e| e.dst == PLC && e.payload.get(..2) == Some(&[0xFE, 0xFF]))
    })
}

fn suite(ip: [u8; 4], mask: [u8; 4], gw: [u8; 4]) -> IpSuite {
    IpSuite {
        ip: Ipv4Addr::from(ip),
        mask: Ipv4Addr::from(mask),
        gateway: Ipv4Addr::from(gw),
    }
}

fn name(d: &mut PnDrive<TestFlash>) -> std::string::String {
    settings::name_of_station(d.objects_mut()).as_str().into()
}

fn sdo_write(d: &mut PnDrive<TestFlash>, index: u16, data: &[u8]) -> Result<(), SdoAbort> {
    d.objects_mut().write(index, 0, data, CommState::PreOp)
}

#[test]
fn p007_a_permanent_dcp_name_is_stored_and_is_the_name_at_the_next_start() {
    let mut d = fresh();
    assert_eq!(d.startup(), Startup::Defaults);
    assert!(d.device().dcp().name_of_station().is_empty(), "shipped unnamed");
    assert!(
        !send(&mut d, &set_name("axis-7", PERMANENT)).is_empty(),
        "Set answered"
    );
    assert_eq!(name(&mut d), "axis-7", "A271 written");
    let mut d = restart(d);
    assert_eq!(d.startup(), Startup::Loaded);
    assert_eq!(d.device().dcp().name_of_station().as_str(), "axis-7");
    let answer = identify(&mut d).expect("Identify answered");
    assert!(answer.windows(6).any(|w| w == b"axis-7"), "named from A271");
}

#[test]
fn p007_a_temporary_dcp_name_is_used_until_restart_and_clears_the_stored_one() {
    let mut d = super::tests::commissioned();
    send(&mut d, &set_name("temp-1", TEMPORARY));
    assert_eq!(d.device().dcp().name_of_station().as_str(), "temp-1");
    assert_eq!(name(&mut d), "temp-1", "A271 in RAM");
    // a later save of other parameters does not store the temporary name
    d.objects_mut().set(A278, 0, 9000).unwrap();
    assert!(d.save());
    assert_eq!(name(&mut d), "temp-1", "RAM keeps it");
    let mut d = restart(d);
    assert!(
        d.device().dcp().name_of_station().is_empty(),
        "neither temp-1 nor drive-1"
    );
    assert_eq!(name(&mut d), "");
    assert_eq!(d.objects().get(A278, 0), Ok(9000));
}

#[test]
fn p009_a_permanent_dcp_ip_overwrites_the_stored_static_ip() {
    let mut d = super::tests::commissioned();
    let new = suite([10, 0, 0, 5], [255, 0, 0, 0], [10, 0, 0, 1]);
    send(&mut d, &set_ip(new, PERMANENT));
    assert_eq!(d.device().dcp().ip_suite(), new);
    assert_eq!(
        d.objects().get(A272, 0),
        Ok(0x0A00_0005),
        "first octet in the MSB"
    );
    assert_eq!(d.objects().get(A273, 0), Ok(0xFF00_0000));
    assert_eq!(d.objects().get(A274, 0), Ok(0x0A00_0001));
    let d = restart(d);
    assert_eq!(
        d.device().dcp().ip_suite(),
        new,
        "the DCP IP is the stored one now"
    );
}

#[test]
fn p009_a_temporary_dcp_ip_clears_the_stored_static_ip() {
    let mut d = super::tests::commissioned();
    let temp = suite([10, 0, 0, 6], [255, 0, 0, 0], [0, 0, 0, 0]);
    send(&mut d, &set_ip(temp, TEMPORARY));
    assert_eq!(d.device().dcp().ip_suite(), temp);
    assert_eq!(d.objects().get(A272, 0), Ok(0x0A00_0006), "A272 in RAM");
    let d = restart(d);
    assert_eq!(
        d.device().dcp().ip_suite(),
        IpSuite::UNSET,
        "192.168.0.50 does not come back"
    );
    assert_eq!(d.objects().get(A272, 0), Ok(0));
}

#[test]
fn p010_the_static_ip_of_the_objects_is_the_device_ip_at_start() {
    let mut d = fresh();
    assert_eq!(d.device().dcp().ip_suite(), IpSuite::UNSET, "shipped without IP");
    sdo_write(&mut d, A272, &0xC0A8_0056u32.to_le_bytes()).unwrap();
    sdo_write(&mut d, A273, &0xFFFF_FF00u32.to_le_bytes()).unwrap();
    sdo_write(&mut d, A274, &0xC0A8_0001u32.to_le_bytes()).unwrap();
    assert_eq!(
        d.device().dcp().ip_suite(),
        IpSuite::UNSET,
        "valid after Save & Reset"
    );
    assert!(d.save());
    let mut d = restart(d);
    let stored = suite([192, 168, 0, 86], [255, 255, 255, 0], [192, 168, 0, 1]);
    assert_eq!(d.device().dcp().ip_suite(), stored);
    assert_eq!(d.device().ip().config().addr, stored.ip, "the IP stack uses it");
    // a stored suite DCP would refuse (no mask) counts as none
    d.objects_mut().set(A273, 0, 0).unwrap();
    assert!(d.save());
    let d = restart(d);
    assert_eq!(d.device().dcp().ip_suite(), IpSuite::UNSET);
}

#[test]
fn p012_profinet_active_on_takes_effect_only_after_save_and_restart() {
    let mut d = super::tests::commissioned();
    assert_eq!(d.objects().get(A270, 0), Ok(1), "shipped active");
    d.objects_mut().set(A270, 0, 0).unwrap();
    assert!(d.save());
    let mut d = restart(d);
    assert!(identify(&mut d).is_none(), "off from power-on");
    assert_eq!(d.dropped_inactive(), 1);
    sdo_write(&mut d, A270, &[1]).unwrap();
    assert!(identify(&mut d).is_none(), "on in RAM: not yet");
    assert!(d.save());
    assert!(identify(&mut d).is_none(), "saved: not before the restart");
    let mut d = restart(d);
    assert!(identify(&mut d).is_some(), "on after Save & Reset");
}

#[test]
fn p013_profinet_active_off_takes_effect_at_once() {
    let mut d = drive();
    run(&mut d, 0, 50, true);
    assert!(d.device().exchanging());
    assert!(identify(&mut d).is_some());
    sdo_write(&mut d, A270, &[0]).unwrap();
    assert!(identify(&mut d).is_none(), "the next frame is dropped");
    // nothing goes out any more (no LLDP, no alarms, no cyclic frames) and
    // the controller's frames are dropped: the AR's watchdog runs out
    let mut sent = 0;
    for ms in 50..200 {
        d.poll(Nanos::from_ms(ms), &mut |_: &[u8]| sent += 1, &mut |_| {});
        d.control_cycle(Nanos::from_ms(ms), &[AxisIo::ready(0), AxisIo::ready(0)]);
    }
    assert_eq!(sent, 0);
    assert!(d.device().cm().ar().is_none(), "the AR is lost");
    for a in d.axes() {
        assert!(a.state().is_fault(), "event 52 as for any lost AR");
    }
    // switching it on again does not bring PROFINET back before a restart
    d.objects_mut().set(A270, 0, 1).unwrap();
    assert!(identify(&mut d).is_none());
    assert!(!d.profinet_active());
}

#[test]
fn p014_the_protocol_is_only_the_standard_protocol() {
    let mut d = fresh();
    assert_eq!(d.objects().get(A276, 0), Ok(0), "0 = standard protocol");
    assert_eq!(sdo_write(&mut d, A276, &[0]), Ok(()));
    assert_eq!(sdo_write(&mut d, A276, &[1]), Err(SdoAbort::VALUE_TOO_HIGH));
    assert_eq!(sdo_write(&mut d, A276, &[255]), Err(SdoAbort::VALUE_TOO_HIGH));
    assert_eq!(d.objects().get(A276, 0), Ok(0));
}

#[test]
fn p015_profienergy_is_switched_by_a_persistent_parameter() {
    let mut d = fresh();
    assert_eq!(d.objects().get(A275, 0), Ok(0), "inactive by default");
    assert_eq!(sdo_write(&mut d, A275, &[2]), Err(SdoAbort::VALUE_TOO_HIGH));
    assert_eq!(sdo_write(&mut d, A275, &[1]), Ok(()));
    assert!(d.save());
    let d = restart(d);
    assert_eq!(d.objects().get(A275, 0), Ok(1));
}

#[test]
fn p017_the_parameterisation_interface_is_automatic_on_board_or_profinet() {
    let mut d = fresh();
    assert_eq!(d.objects().get(A277, 0), Ok(0), "automatic by default");
    for v in 0..=2u8 {
        assert_eq!(sdo_write(&mut d, A277, &[v]), Ok(()), "{v}");
    }
    assert_eq!(sdo_write(&mut d, A277, &[3]), Err(SdoAbort::VALUE_TOO_HIGH));
    assert!(d.save());
    assert_eq!(restart(d).objects().get(A277, 0), Ok(2));
}

#[test]
fn p018_the_vendor_service_port_is_8802_and_configurable() {
    let mut d = fresh();
    assert_eq!(d.objects().get(A278, 0), Ok(8802));
    assert_eq!(
        sdo_write(&mut d, A278, &0u16.to_le_bytes()),
        Err(SdoAbort::VALUE_TOO_LOW)
    );
    assert_eq!(
        sdo_write(&mut d, A278, &[1, 2, 3]),
        Err(SdoAbort::LENGTH_TOO_HIGH)
    );
    assert_eq!(sdo_write(&mut d, A278, &20000u16.to_le_bytes()), Ok(()));
    assert!(d.save());
    assert_eq!(restart(d).objects().get(A278, 0), Ok(20000));
}

#[test]
fn p019_save_and_reset_persists_the_operating_parameters() {
    let mut d = fresh();
    sdo_write(&mut d, A271, b"line-2-drive").unwrap();
    sdo_write(&mut d, A272, &0x0A01_0203u32.to_le_bytes()).unwrap();
    sdo_write(&mut d, A273, &0xFFFF_0000u32.to_le_bytes()).unwrap();
    sdo_write(&mut d, A275, &[1]).unwrap();
    sdo_write(&mut d, A277, &[1]).unwrap();
    sdo_write(&mut d, A278, &8803u16.to_le_bytes()).unwrap();
    assert!(
        d.device().dcp().name_of_station().is_empty(),
        "not valid before the reset"
    );
    assert!(d.save());
    assert_eq!(d.objects().get(A00, 3), Ok(0), "A00[2]: saved");
    let mut d = restart(d);
    assert_eq!(d.startup(), Startup::Loaded);
    assert_eq!(d.device().dcp().name_of_station().as_str(), "line-2-drive");
    assert_eq!(
        d.device().dcp().ip_suite(),
        suite([10, 1, 2, 3], [255, 255, 0, 0], [0; 4])
    );
    assert_eq!(d.objects().get(A275, 0), Ok(1));
    assert_eq!(d.objects().get(A277, 0), Ok(1));
    assert_eq!(d.objects().get(A278, 0), Ok(8803));
    assert!(identify(&mut d).is_some_and(|f| f.windows(12).any(|w| w == b"line-2-drive")));
}

#[test]
fn p019_a_240_character_name_is_stored_and_used() {
    // labels of at most 63 characters: 63 + 1 + 63 + 1 + 63 + 1 + 48 = 240
    let long = ["a".repeat(63), "b".repeat(63), "c".repeat(63), "d".repeat(48)].join(".");
    let long = long.as_str();
    assert_eq!(long.len(), 240);
    let mut d = fresh();
    send(&mut d, &set_name(long, PERMANENT));
    assert_eq!(d.device().dcp().name_of_station().as_str(), long);
    let mut d = restart(d);
    assert_eq!(name(&mut d), long);
    assert_eq!(d.device().dcp().name_of_station().as_str(), long);
}

#[test]
fn p007_p009_reset_to_factory_clears_name_and_ip_and_mode_all_every_default() {
    let ip = suite([192, 168, 0, 50], [255, 255, 255, 0], [0; 4]);
    let setup = || {
        let mut d = super::tests::commissioned();
        d.objects_mut().set(A278, 0, 9000).unwrap();
        d.objects_mut().set(parameter(150), 0, 2000).unwrap();
        assert!(d.save());
        restart(d)
    };
    // (reset mode; after the restart: name of station, IP suite, A278, parameter 150)
    let cases = [
        // mode 2, communication: name and IP only
        (2, "", IpSuite::UNSET, 9000, 2000),
        // mode 8, all: every parameter back to its default
        (8, "", IpSuite::UNSET, 8802, 1000),
        // mode 1, application data: the drive's defaults, the PROFINET ones kept
        (1, "drive-1", ip, 9000, 1000),
    ];
    for (mode, name, ip, a278, p150) in cases {
        let mut d = setup();
        send(&mut d, &reset(mode));
        if mode == 2 {
            // the name goes at once
            assert!(d.device().dcp().name_of_station().is_empty());
        }
        let d = restart(d);
        assert_eq!(d.device().dcp().name_of_station().as_str(), name, "mode {mode}");
        assert_eq!(d.device().dcp().ip_suite(), ip, "mode {mode}");
        assert_eq!(d.objects().get(A278, 0), Ok(a278), "mode {mode}");
        assert_eq!(d.objects().get(parameter(150), 0), Ok(p150), "mode {mode}");
    }
}

fn parameter(line: u16) -> u16 {
    drive_core::parameter_index(0, line)
}

/// Sends profinet-py's RPC request `req` (vectors, sequence number `seq`)
/// over UDP to the commissioned drive at 192.168.0.50; returns whether an
/// answer went out.
fn rpc(d: &mut PnDrive<TestFlash>, req: &str, seq: u32) -> bool {
    let mut req = profinet::testing::hex(req).to_vec();
    req[64..68].copy_from_slice(&seq.to_be_bytes());
    !send(d, &rpc_frame(&req)).is_empty()
}

#[test]
fn p039_im1_to_im4_written_by_a_controller_survive_a_restart_and_reset_to_factory_clears_them() {
    use super::tests::vectors::{CONNECT, WRITE_IM1, WRITE_IM2};
    // the PROFINET images' parameter flash holds the image and I&M1…4
    assert!(STORED_BYTES <= store::ParamStore::<PnParamFlash>::new(PnParamFlash::new()).capacity());
    let mut d = super::tests::commissioned();
    assert!(rpc(&mut d, CONNECT, 10));
    assert!(rpc(&mut d, WRITE_IM1, 11));
    assert!(rpc(&mut d, WRITE_IM2, 12));
    let im = *d.device().cm().im_data();
    assert_eq!(&im.tag_location[..9], b"Cabinet 3");
    assert_eq!(&im.date, b"2024-05-28 10:30");
    // power off and on: the board's hardware data carries no I&M, the store does
    let mut d = restart(d);
    assert_eq!(*d.device().cm().im_data(), im);
    assert_eq!(name(&mut d), "drive-1", "the parameters came back with them");
    // a restart without a new write keeps them (they are saved with every save)
    assert!(d.save());
    let mut d = restart(d);
    assert_eq!(*d.device().cm().im_data(), im);
    // DCP Reset to factory, mode 2 (communication): I&M1…4 blank, saved so
    send(&mut d, &reset(2));
    assert_eq!(*d.device().cm().im_data(), ImData::default());
    let d = restart(d);
    assert_eq!(*d.device().cm().im_data(), ImData::default());
}

#[test]
fn p039_a_store_saved_before_i_m_was_kept_loads_with_the_boards_i_m() {
    // the parameter image alone (as saved before I&M1…4 were kept) loads as it did
    let mut img = std::vec![0u8; PERSISTENT_IMAGE_BYTES];
    let mut d = fresh();
    settings::write_name(d.objects_mut(), &"old-1".parse().unwrap());
    let n = d.objects_mut().persistent_image(&mut img).unwrap();
    let mut store = store::ParamStore::new(d.into_flash());
    store.save(&img[..n], drive_core::objects::LAYOUT_HASH).unwrap();
    let mut hw = hardware();
    hw.im.tag_function[..5].copy_from_slice(b"board");
    let mut d = PnDrive::new(store.into_inner(), hw);
    assert_eq!(name(&mut d), "old-1");
    assert_eq!(&d.device().cm().im_data().tag_function[..5], b"board");
    // split_stored: a record without the tag is all parameters
    let (params, im) = settings::split_stored(&img[..n]);
    assert_eq!((params.len(), im), (n, None));
}
