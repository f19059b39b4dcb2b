//! Unit tests of DCP: the PDU, the name rules, the server and the signal.

use std::vec::Vec;

use super::pdu::*;
use super::*;
use crate::wire::{EthFrame, MacAddr};
use core::net::Ipv4Addr;
use nanos::Nanos;

pub(super) const DEV: MacAddr = MacAddr([0x02, 0x00, 0x00, 0x00, 0x00, 0xAA]);
pub(super) const PLC: MacAddr = MacAddr([0x02, 0x00, 0x00, 0x00, 0x00, 0x01]);
const PLC2: MacAddr = MacAddr([0x02, 0x00, 0x00, 0x00, 0x00, 0x02]);

pub(super) fn server(name: &str) -> DcpServer {
    DcpServer::new(
        DEV,
        Identity::DRIVE,
        name.parse().unwrap(),
        suite([192, 168, 0, 86], [255, 255, 255, 0], [192, 168, 0, 86]),
    )
}

/// `ev` is exactly the one NameOfStation event of `name`, `permanent` or not.
#[track_caller]
pub(super) fn assert_name_event(ev: &[Event], name: NameOfStation, permanent: bool) {
    assert_eq!(ev, [Event::NameOfStation { name, permanent }]);
}

/// `ev` is exactly the one IpSuite event of `suite`, `permanent` or not.
#[track_caller]
pub(super) fn assert_suite_event(ev: &[Event], suite: IpSuite, permanent: bool) {
    assert_eq!(ev, [Event::IpSuite { suite, permanent }]);
}

pub(super) fn suite(ip: [u8; 4], mask: [u8; 4], gw: [u8; 4]) -> IpSuite {
    IpSuite {
        ip: Ipv4Addr::from(ip),
        mask: Ipv4Addr::from(mask),
        gateway: Ipv4Addr::from(gw),
    }
}

/// A request frame built with our own emitters.
fn request(
    dst: MacAddr,
    src: MacAddr,
    frame_id: u16,
    service: ServiceId,
    delay: u16,
    blocks: &[BlockRepr<'_>],
) -> Vec<u8> {
    crate::testing::dcp_request(dst, src, frame_id, service, 0x0102_0304, delay, blocks).to_vec()
}

fn filter(kind: BlockType, value: Value<'_>) -> BlockRepr<'_> {
    BlockRepr {
        kind,
        prefix: None,
        value,
    }
}

fn set_block(kind: BlockType, qualifier: u16, value: Value<'_>) -> BlockRepr<'_> {
    BlockRepr {
        kind,
        prefix: Some(qualifier),
        value,
    }
}

fn identify(blocks: &[BlockRepr<'_>], delay: u16) -> Vec<u8> {
    request(
        MacAddr::DCP_IDENTIFY,
        PLC,
        0xFEFE,
        ServiceId::Identify,
        delay,
        blocks,
    )
}

fn set(blocks: &[BlockRepr<'_>]) -> Vec<u8> {
    request(DEV, PLC, 0xFEFD, ServiceId::Set, 0, blocks)
}

fn get(pairs: &[u8]) -> Vec<u8> {
    let mut f = request(DEV, PLC, 0xFEFD, ServiceId::Get, 0, &[]);
    f.extend_from_slice(pairs);
    let n = pairs.len() as u16;
    f[24..26].copy_from_slice(&n.to_be_bytes());
    f
}

/// A parsed answer: header and its blocks as (type, prefix-and-value bytes).
pub(super) struct Answer {
    pub eth_dst: MacAddr,
    pub frame_id: u16,
    pub header: Header,
    pub blocks: Vec<(BlockType, Vec<u8>)>,
}

pub(super) fn parse_answer(frame: &[u8]) -> Answer {
    assert!(frame.len() >= 60, "padded to the Ethernet minimum");
    let eth = EthFrame::parse(frame).unwrap();
    assert_eq!(eth.src, DEV);
    assert_eq!(eth.ethertype, 0x8892);
    let frame_id = u16::from_be_bytes([eth.payload[0], eth.payload[1]]);
    let p = Packet::new_checked(&eth.payload[2..]).unwrap();
    let blocks = Blocks::new(p.data())
        .map(|b| {
            let b = b.unwrap();
            (b.kind, b.data.to_vec())
        })
        .collect();
    Answer {
        eth_dst: eth.dst,
        frame_id,
        header: Header::parse(&p),
        blocks,
    }
}

impl Answer {
    fn block(&self, kind: BlockType) -> Option<&[u8]> {
        self.blocks
            .iter()
            .find(|(k, _)| *k == kind)
            .map(|(_, d)| d.as_slice())
    }

    /// The BlockErrors of the Control/Response blocks, in order.
    pub fn errors(&self) -> Vec<(BlockType, BlockError)> {
        self.blocks
            .iter()
            .filter(|(k, _)| *k == BlockType::ControlResponse)
            .map(
                |(_, d)| match Value::parse(BlockType::ControlResponse, d).unwrap() {
                    Value::Response(k, e) => (k, e),
                    _ => unreachable!(),
                },
            )
            .collect()
    }
}

/// A Set of the one block `kind` with `qualifier` and `value` at time zero.
fn set_one(
    s: &mut DcpServer,
    kind: BlockType,
    qualifier: u16,
    value: Value<'_>,
) -> (Option<(Answer, Nanos)>, Events) {
    run(s, Nanos::ZERO, &set(&[set_block(kind, qualifier, value)]))
}

fn run(s: &mut DcpServer, now: Nanos, frame: &[u8]) -> (Option<(Answer, Nanos)>, Events) {
    let mut out = [0u8; 1514];
    let o = s.handle_frame(now, frame, &mut out);
    let a = o.reply.map(|r| (parse_answer(&out[..r.len]), r.send_at));
    (a, o.events)
}

#[test]
fn p008_identify_all_answers_with_name_and_ids() {
    let mut s = server("drive-1");
    let t = Nanos::from_secs(5);
    let (a, ev) = run(&mut s, t, &identify(&[filter(BlockType::All, Value::Empty)], 1));
    let (a, at) = a.expect("answered");
    assert!(ev.is_empty());
    assert_eq!(at, t, "factor 1: at once");
    assert_eq!((a.eth_dst, a.frame_id), (PLC, 0xFEFF));
    assert_eq!(a.header.service, ServiceId::Identify);
    assert_eq!(a.header.service_type, service_type::RESPONSE_SUCCESS);
    assert_eq!(a.header.xid, 0x0102_0304);
    assert_eq!(a.block(BlockType::NameOfStation), Some(&b"\0\0drive-1"[..]));
    let vendor = [&[0u8, 0][..], crate::model::STATION_TYPE.as_bytes()].concat();
    assert_eq!(a.block(BlockType::DeviceVendor), Some(&vendor[..]));
    assert_eq!(
        a.block(BlockType::DeviceId),
        Some(&[0, 0, 0xFE, 0xFE, 0x00, 0x01][..])
    );
    assert_eq!(a.block(BlockType::DeviceRole), Some(&[0, 0, 1, 0][..]));
    assert_eq!(a.block(BlockType::DeviceInstance), Some(&[0, 0, 0, 1][..]));
    assert_eq!(
        a.block(BlockType::IpParameter),
        Some(&[0, 1, 192, 168, 0, 86, 255, 255, 255, 0, 192, 168, 0, 86][..])
    );
    let opts = a.block(BlockType::DeviceOptions).unwrap();
    assert_eq!(&opts[2..], &server::DEVICE_OPTIONS[..]);
    assert_eq!(a.block(BlockType::AliasName), None);
}

#[test]
fn p008_identify_by_name_answers_only_the_configured_name() {
    let mut s = server("drive-1");
    let f = |n: &'static [u8]| identify(&[filter(BlockType::NameOfStation, Value::Bytes(n))], 0);
    assert!(run(&mut s, Nanos::ZERO, &f(b"drive-1")).0.is_some());
    assert!(run(&mut s, Nanos::ZERO, &f(b"drive-2")).0.is_none());
    assert!(run(&mut s, Nanos::ZERO, &f(b"drive-")).0.is_none());
    // Two filters must both match.
    let both = identify(
        &[
            filter(BlockType::NameOfStation, Value::Bytes(b"drive-1")),
            filter(
                BlockType::DeviceId,
                Value::DeviceId {
                    vendor_id: 0xFEFE,
                    device_id: 2,
                },
            ),
        ],
        0,
    );
    assert!(run(&mut s, Nanos::ZERO, &both).0.is_none());
    // Unknown filters, an empty filter and All with others select nobody.
    for blocks in [
        &[filter(BlockType::Other(0x80, 1), Value::Bytes(b"x"))][..],
        &[],
        &[
            filter(BlockType::All, Value::Empty),
            filter(BlockType::NameOfStation, Value::Bytes(b"drive-1")),
        ],
    ] {
        assert!(run(&mut s, Nanos::ZERO, &identify(blocks, 0)).0.is_none());
    }
    // A station without a name is found by other filters, never by name.
    let mut unnamed = server("");
    let by_id = identify(
        &[filter(
            BlockType::DeviceId,
            Value::DeviceId {
                vendor_id: 0xFEFE,
                device_id: 1,
            },
        )],
        0,
    );
    let (a, _) = run(&mut unnamed, Nanos::ZERO, &by_id);
    assert_eq!(a.unwrap().0.block(BlockType::NameOfStation), Some(&[0u8, 0][..]));
    assert!(run(&mut unnamed, Nanos::ZERO, &f(b"")).0.is_none());
    // Get/Set FrameID or a unicast to another device: not an Identify for us.
    let mut other = identify(&[filter(BlockType::All, Value::Empty)], 0);
    other[..6].copy_from_slice(&PLC2.0);
    assert!(run(&mut s, Nanos::ZERO, &other).0.is_none());
}

#[test]
fn p008_identify_by_alias_answers_with_the_alias() {
    let mut s = server("drive-1");
    let f = identify(
        &[filter(BlockType::AliasName, Value::Bytes(b"port-001.switch-1"))],
        0,
    );
    assert!(run(&mut s, Nanos::ZERO, &f).0.is_none());
    assert!(s.set_alias(1, Some(b"port-001.switch-1")));
    assert!(!s.set_alias(2, Some(b"x")));
    let (a, _) = run(&mut s, Nanos::ZERO, &f);
    let a = a.unwrap().0;
    assert_eq!(a.block(BlockType::AliasName), Some(&b"\0\0port-001.switch-1"[..]));
}

#[test]
fn p008_identify_response_delay_is_spread_by_the_mac() {
    let s = server("drive-1");
    // h = 0x0200 ^ 0x0000 ^ 0x00AA = 0x02AA = 682.
    assert_eq!(s.response_delay(0), Nanos::ZERO);
    assert_eq!(s.response_delay(1), Nanos::ZERO);
    assert_eq!(s.response_delay(0x80), Nanos::from_ms(10 * (682 % 128)));
    assert_eq!(s.response_delay(0xFFFF), s.response_delay(0x1900));
    for f in 2..400u16 {
        assert!(s.response_delay(f) < Nanos::from_ms(10 * u64::from(f)));
    }
    let mut s = s;
    let t = Nanos::from_secs(1);
    let (a, _) = run(
        &mut s,
        t,
        &identify(&[filter(BlockType::All, Value::Empty)], 0x80),
    );
    assert_eq!(a.unwrap().1, t + Nanos::from_ms(420));
    let other = DcpServer::new(PLC2, Identity::DRIVE, NameOfStation::EMPTY, IpSuite::UNSET);
    assert_ne!(other.response_delay(0x80), s.response_delay(0x80));
}

#[test]
fn p009_set_ip_permanent_overwrites_the_stored_static_ip() {
    let mut s = server("drive-1");
    let new = suite([10, 0, 0, 7], [255, 0, 0, 0], [0, 0, 0, 0]);
    let (a, ev) = set_one(&mut s, BlockType::IpParameter, 1, Value::IpParameter(new));
    let a = a.unwrap().0;
    assert_eq!(
        (a.eth_dst, a.frame_id, a.header.service),
        (PLC, 0xFEFD, ServiceId::Set)
    );
    assert_eq!(a.errors(), [(BlockType::IpParameter, BlockError::NoError)]);
    assert_suite_event(&ev, new, true);
    assert_eq!(s.ip_suite(), new);
    // Temporary: applied, reported as temporary (the store clears its copy).
    let tmp = suite([10, 0, 0, 8], [255, 0, 0, 0], [10, 0, 0, 1]);
    let (_, ev) = set_one(&mut s, BlockType::IpParameter, 0, Value::IpParameter(tmp));
    assert_suite_event(&ev, tmp, false);
    assert_eq!(s.ip_suite(), tmp);
    // All zero clears the address.
    let (_, ev) = set_one(
        &mut s,
        BlockType::IpParameter,
        1,
        Value::IpParameter(IpSuite::UNSET),
    );
    assert_suite_event(&ev, IpSuite::UNSET, true);
}

#[test]
fn p009_invalid_ip_suites_are_refused_and_change_nothing() {
    let mut s = server("drive-1");
    let before = s.ip_suite();
    for bad in [
        suite([192, 168, 0, 5], [255, 0, 255, 0], [0; 4]),
        suite([127, 0, 0, 1], [255, 0, 0, 0], [0; 4]),
        suite([224, 0, 0, 1], [240, 0, 0, 0], [0; 4]),
        suite([0, 0, 1, 10], [255, 255, 0, 0], [0; 4]),
        suite([192, 168, 0, 0], [255, 255, 255, 0], [0; 4]),
        suite([192, 168, 0, 255], [255, 255, 255, 0], [0; 4]),
        suite([192, 168, 1, 4], [255, 255, 255, 0], [192, 168, 0, 1]),
        suite([192, 168, 1, 4], [0; 4], [0; 4]),
        suite([0; 4], [255, 255, 255, 0], [0; 4]),
    ] {
        assert!(!server::ip_suite_valid(&bad), "{bad:?}");
        let (a, ev) = set_one(&mut s, BlockType::IpParameter, 1, Value::IpParameter(bad));
        assert_eq!(
            a.unwrap().0.errors(),
            [(BlockType::IpParameter, BlockError::SuboptionNotSet)]
        );
        assert!(ev.is_empty());
        assert_eq!(s.ip_suite(), before);
    }
    // Wrong length (10 bytes of IP data).
    let (a, ev) = run(
        &mut s,
        Nanos::ZERO,
        &set(&[set_block(BlockType::IpParameter, 1, Value::Bytes(&[10; 10]))]),
    );
    assert_eq!(
        a.unwrap().0.errors(),
        [(BlockType::IpParameter, BlockError::SuboptionNotSet)]
    );
    assert!(ev.is_empty());
    assert!(server::ip_suite_valid(&suite(
        [10, 0, 0, 1],
        [255, 255, 255, 255],
        [0; 4]
    )));
}

#[test]
fn p007_set_name_of_station_permanent_and_temporary() {
    let mut s = server("drive-1");
    let (a, ev) = set_one(&mut s, BlockType::NameOfStation, 1, Value::Bytes(b"axis-a"));
    assert_eq!(
        a.unwrap().0.errors(),
        [(BlockType::NameOfStation, BlockError::NoError)]
    );
    let name: NameOfStation = "axis-a".parse().unwrap();
    assert_name_event(&ev, name.clone(), true);
    assert_eq!(s.name_of_station(), &name);
    let (_, ev) = set_one(&mut s, BlockType::NameOfStation, 0, Value::Bytes(b""));
    assert_name_event(&ev, NameOfStation::EMPTY, false);
    assert!(s.name_of_station().is_empty());
}

#[test]
fn p007_invalid_name_is_refused_with_suboption_not_set() {
    let mut s = server("drive-1");
    for bad in [&b"Drive-1"[..], b"1.2.3.4", b"port-001", b"a..b", &[b'a'; 241]] {
        let (a, ev) = set_one(&mut s, BlockType::NameOfStation, 1, Value::Bytes(bad));
        assert_eq!(
            a.unwrap().0.errors(),
            [(BlockType::NameOfStation, BlockError::SuboptionNotSet)]
        );
        assert!(ev.is_empty());
        assert_eq!(s.name_of_station().as_str(), "drive-1");
    }
}

#[test]
fn set_with_start_and_stop_transaction_answers_every_block() {
    let mut s = server("");
    let ip = suite([192, 168, 1, 20], [255, 255, 255, 0], [192, 168, 1, 1]);
    let (a, ev) = run(
        &mut s,
        Nanos::ZERO,
        &set(&[
            set_block(BlockType::ControlStart, 1, Value::Empty),
            set_block(BlockType::NameOfStation, 1, Value::Bytes(b"drive-7")),
            set_block(BlockType::IpParameter, 1, Value::IpParameter(ip)),
            set_block(BlockType::ControlStop, 1, Value::Empty),
        ]),
    );
    assert_eq!(
        a.unwrap().0.errors(),
        [
            (BlockType::ControlStart, BlockError::NoError),
            (BlockType::NameOfStation, BlockError::NoError),
            (BlockType::IpParameter, BlockError::NoError),
            (BlockType::ControlStop, BlockError::NoError),
        ]
    );
    assert_eq!(ev.len(), 2);
    assert_eq!((s.name_of_station().as_str(), s.ip_suite()), ("drive-7", ip));
}

#[test]
fn set_of_what_cannot_be_set_answers_the_block_error() {
    let mut s = server("drive-1");
    let (a, ev) = run(
        &mut s,
        Nanos::ZERO,
        &set(&[
            set_block(BlockType::IpMac, 1, Value::Mac(PLC)),
            set_block(BlockType::IpFullSuite, 1, Value::Bytes(&[0; 28])),
            set_block(BlockType::DeviceId, 1, Value::Bytes(&[0; 4])),
            set_block(BlockType::Other(2, 0x42), 1, Value::Empty),
            set_block(BlockType::Dhcp(61), 1, Value::Bytes(b"x")),
            set_block(BlockType::Other(0x80, 1), 1, Value::Empty),
            set_block(BlockType::ControlResponse, 0, Value::Bytes(&[2, 2, 0])),
            set_block(BlockType::ControlResetToFactory, 3 << 1, Value::Empty),
            set_block(BlockType::ControlSignal, 0, Value::Signal(0x0200)),
            set_block(BlockType::ControlStart, 1, Value::Bytes(&[1, 2])),
        ]),
    );
    use BlockError::*;
    let errs: Vec<BlockError> = a.unwrap().0.errors().into_iter().map(|(_, e)| e).collect();
    assert_eq!(
        errs,
        [
            SuboptionNotSupported,
            SuboptionNotSupported,
            SuboptionNotSupported,
            SuboptionNotSupported,
            OptionNotSupported,
            OptionNotSupported,
            SuboptionNotSupported,
            SuboptionNotSupported,
            SuboptionNotSet,
            SuboptionNotSet,
        ]
    );
    assert!(ev.is_empty());
    assert_eq!(s.name_of_station().as_str(), "drive-1");
}

#[test]
fn in_operation_changes_are_refused_but_the_same_value_is_accepted() {
    let mut s = server("drive-1");
    s.set_in_operation(true);
    let ip = s.ip_suite();
    let other = suite([10, 0, 0, 7], [255, 0, 0, 0], [0; 4]);
    let (a, ev) = run(
        &mut s,
        Nanos::ZERO,
        &set(&[
            set_block(BlockType::NameOfStation, 1, Value::Bytes(b"axis-b")),
            set_block(BlockType::NameOfStation, 1, Value::Bytes(b"drive-1")),
            set_block(BlockType::IpParameter, 1, Value::IpParameter(other)),
            set_block(BlockType::IpParameter, 1, Value::IpParameter(ip)),
            set_block(BlockType::ControlResetToFactory, 2 << 1, Value::Empty),
            set_block(BlockType::ControlSignal, 0, Value::Signal(0x0100)),
        ]),
    );
    use BlockError::*;
    let errs: Vec<BlockError> = a.unwrap().0.errors().into_iter().map(|(_, e)| e).collect();
    assert_eq!(
        errs,
        [InOperation, NoError, InOperation, NoError, InOperation, NoError]
    );
    assert_eq!(ev.len(), 3, "name, ip (unchanged, re-stored) and signal");
    assert_eq!(s.name_of_station().as_str(), "drive-1");
}

#[test]
fn reset_to_factory_modes() {
    for (qualifier, mode, clears) in [
        (0x0002, ResetMode::ApplicationData, false),
        (0x0004, ResetMode::Communication, true),
        (0x0008, ResetMode::All, true),
        (0x0010, ResetMode::All, true),
    ] {
        let mut s = server("drive-1");
        let (a, ev) = set_one(&mut s, BlockType::ControlResetToFactory, qualifier, Value::Empty);
        assert_eq!(
            a.unwrap().0.errors(),
            [(BlockType::ControlResetToFactory, BlockError::NoError)]
        );
        assert_eq!(ev[0], Event::ResetToFactory(mode));
        assert_eq!(s.name_of_station().is_empty(), clears);
        assert_eq!(s.ip_suite().is_unset(), clears);
        if clears {
            assert!(ev.contains(&Event::NameOfStation {
                name: NameOfStation::EMPTY,
                permanent: true
            }));
            assert!(ev.contains(&Event::IpSuite {
                suite: IpSuite::UNSET,
                permanent: true
            }));
        } else {
            assert_eq!(ev.len(), 1);
        }
    }
    let mut s = server("drive-1");
    let (_, ev) = set_one(&mut s, BlockType::ControlFactoryReset, 0, Value::Empty);
    assert_eq!(ev[0], Event::ResetToFactory(ResetMode::All));
    assert!(s.name_of_station().is_empty());
}

#[test]
fn p011_signal_flashes_the_sf_led_at_1_hz_for_3_s() {
    let mut s = server("drive-1");
    let t0 = Nanos::from_secs(100);
    let (a, ev) = run(
        &mut s,
        t0,
        &set(&[set_block(BlockType::ControlSignal, 0, Value::Signal(0x0100))]),
    );
    assert_eq!(
        a.unwrap().0.errors(),
        [(BlockType::ControlSignal, BlockError::NoError)]
    );
    assert_eq!(
        &ev[..],
        [Event::Signal {
            until: t0 + Nanos::from_secs(3)
        }]
    );
    let sig = *s.signal();
    let lit = |ms: u64| sig.is_lit(t0 + Nanos::from_ms(ms));
    let pattern: Vec<bool> = (0..8).map(|i| lit(i * 500 + 250)).collect();
    assert_eq!(pattern, [true, false, true, false, true, false, false, false]);
    assert!(!sig.is_lit(t0 - Nanos::from_ms(1)));
    assert!(lit(0) && !lit(500) && lit(1000) && lit(2499) && !lit(3000));
    // A second Signal while flashing keeps the rhythm.
    let mut again = sig;
    assert_eq!(again.trigger(t0 + Nanos::from_ms(1200)), t0 + Nanos::from_secs(3));
    assert_eq!(again, sig);
    assert_eq!(again.trigger(t0 + Nanos::from_secs(4)), t0 + Nanos::from_secs(7));
    assert_eq!(
        sig.until(t0 + Nanos::from_secs(1)),
        Some(t0 + Nanos::from_secs(3))
    );
    assert_eq!(sig.until(t0 + Nanos::from_secs(3)), None);
    assert!(!Signal::default().is_lit(t0));
}

#[test]
fn get_answers_values_and_negative_responses() {
    let mut s = server("drive-1");
    let (a, _) = run(
        &mut s,
        Nanos::ZERO,
        &get(&[2, 2, 1, 2, 1, 1, 3, 61, 2, 6, 5, 1, 0x80, 1, 2, 0x42, 1, 3]),
    );
    let a = a.unwrap().0;
    assert_eq!(a.header.service, ServiceId::Get);
    assert_eq!(a.blocks[0], (BlockType::NameOfStation, b"\0\0drive-1".to_vec()));
    assert_eq!(a.blocks[1].0, BlockType::IpParameter);
    assert_eq!(a.blocks[2], (BlockType::IpMac, [&[0u8, 0][..], &DEV.0].concat()));
    use BlockError::*;
    assert_eq!(
        a.errors(),
        [
            (BlockType::Dhcp(61), OptionNotSupported),
            (BlockType::AliasName, SuboptionNotSupported),
            (BlockType::ControlStart, SuboptionNotSupported),
            (BlockType::Other(0x80, 1), OptionNotSupported),
            (BlockType::Other(2, 0x42), SuboptionNotSupported),
        ]
    );
    let full = a.block(BlockType::IpFullSuite).unwrap();
    assert_eq!(full.len(), 2 + 28);
    // All: every readable block.
    let (a, _) = run(&mut s, Nanos::ZERO, &get(&[0xFF, 0xFF]));
    assert_eq!(a.unwrap().0.blocks.len(), 11);
    // Odd or empty lists are dropped.
    assert!(run(&mut s, Nanos::ZERO, &get(&[2])).0.is_none());
    assert!(run(&mut s, Nanos::ZERO, &get(&[])).0.is_none());
}

#[test]
fn other_controllers_are_locked_out_for_3_s_after_a_get_or_set() {
    let mut s = server("drive-1");
    let t = Nanos::from_secs(10);
    assert!(run(&mut s, t, &get(&[2, 2])).0.is_some());
    let mut from2 = get(&[2, 2]);
    from2[6..12].copy_from_slice(&PLC2.0);
    assert!(run(&mut s, t + Nanos::from_ms(2999), &from2).0.is_none());
    assert!(run(&mut s, t + Nanos::from_ms(2999), &get(&[2, 2])).0.is_some());
    assert!(run(&mut s, t + Nanos::from_ms(6000), &from2).0.is_some());
    // Identify is never locked.
    let id = identify(&[filter(BlockType::All, Value::Empty)], 0);
    let mut id2 = id.clone();
    id2[6..12].copy_from_slice(&PLC.0);
    assert!(run(&mut s, t + Nanos::from_ms(6001), &id2).0.is_some());
}

#[test]
fn unknown_services_answer_not_supported_and_responses_are_ignored() {
    let mut s = server("drive-1");
    let f = request(DEV, PLC, 0xFEFD, ServiceId::Other(9), 0, &[]);
    let (a, _) = run(&mut s, Nanos::ZERO, &f);
    let a = a.unwrap().0;
    assert_eq!(a.header.service_type, service_type::RESPONSE_NOT_SUPPORTED);
    assert_eq!(a.header.service, ServiceId::Other(9));
    assert!(a.blocks.is_empty());
    // A response (service type 1), a Hello, multicast Get, a multicast source.
    let mut resp = get(&[2, 2]);
    resp[17] = 1;
    assert!(run(&mut s, Nanos::ZERO, &resp).0.is_none());
    let hello = request(MacAddr::DCP_HELLO, PLC, 0xFEFC, ServiceId::Hello, 0, &[]);
    assert!(run(&mut s, Nanos::ZERO, &hello).0.is_none());
    let mut mc = get(&[2, 2]);
    mc[..6].copy_from_slice(&MacAddr::BROADCAST.0);
    assert!(run(&mut s, Nanos::ZERO, &mc).0.is_none());
    let mut mcsrc = get(&[2, 2]);
    mcsrc[6] = 1;
    assert!(run(&mut s, Nanos::ZERO, &mcsrc).0.is_none());
}

#[test]
fn malformed_requests_are_dropped_and_change_nothing() {
    let ip = suite([10, 0, 0, 7], [255, 0, 0, 0], [0; 4]);
    let frames = [
        set(&[
            set_block(BlockType::NameOfStation, 1, Value::Bytes(b"axis-b")),
            set_block(BlockType::IpParameter, 1, Value::IpParameter(ip)),
            set_block(BlockType::ControlResetToFactory, 4, Value::Empty),
        ]),
        identify(&[filter(BlockType::NameOfStation, Value::Bytes(b"drive-1"))], 0),
        get(&[2, 2, 1, 2]),
    ];
    for f in &frames {
        // Every truncation, and every DCPDataLength past the end.
        for cut in 0..f.len() {
            let mut s = server("drive-1");
            let (a, ev) = run(&mut s, Nanos::ZERO, &f[..cut]);
            assert!(a.is_none() && ev.is_empty(), "cut {cut}");
            assert_eq!(s.name_of_station().as_str(), "drive-1");
        }
        let mut long = f.clone();
        let n = u16::from_be_bytes([long[24], long[25]]) + 1;
        long[24..26].copy_from_slice(&n.to_be_bytes());
        let mut s = server("drive-1");
        assert!(run(&mut s, Nanos::ZERO, &long).0.is_none());
    }
    // A block running past DCPDataLength inside the frame.
    let mut f = frames[0].clone();
    f[27 + 2] = 0x40;
    let mut s = server("drive-1");
    let (a, ev) = run(&mut s, Nanos::ZERO, &f);
    assert!(a.is_none() && ev.is_empty());
    // A Set block without a qualifier.
    let f = request(
        DEV,
        PLC,
        0xFEFD,
        ServiceId::Set,
        0,
        &[filter(BlockType::NameOfStation, Value::Bytes(b"x"))],
    );
    assert!(run(&mut s, Nanos::ZERO, &f).0.is_none());
    // Random bytes never panic.
    let mut x = 0x1234_5678u32;
    for _ in 0..2000 {
        let mut f = set(&[set_block(BlockType::NameOfStation, 1, Value::Bytes(b"abc"))]);
        for b in f.iter_mut().skip(16) {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            if x % 5 == 0 {
                *b = x as u8;
            }
        }
        let mut out = [0u8; 1514];
        let _ = s.handle_frame(Nanos::ZERO, &f, &mut out);
        let _ = s.handle_frame(Nanos::ZERO, &f, &mut out[..40]);
    }
}

#[test]
fn hello_announces_the_station() {
    let s = server("drive-1");
    let mut out = [0u8; 1514];
    let n = s.hello(&mut out).unwrap();
    let eth = EthFrame::parse(&out[..n]).unwrap();
    assert_eq!(eth.dst, MacAddr::DCP_HELLO);
    let a = parse_answer(&out[..n]);
    assert_eq!(a.frame_id, 0xFEFC);
    assert_eq!(a.header.service, ServiceId::Hello);
    assert_eq!(a.header.service_type, service_type::REQUEST);
    assert_eq!(a.block(BlockType::DeviceInitiative), Some(&[0u8, 0, 0, 0][..]));
    assert!(s.hello(&mut out[..30]).is_none());
}
