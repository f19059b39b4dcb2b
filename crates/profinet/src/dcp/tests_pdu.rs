//! Unit tests of the DCP PDU and of the name-of-station rules.

use std::format;

use super::pdu::*;
use super::tests::{suite, DEV};
use super::*;
use core::net::Ipv4Addr;

#[test]
fn p007_name_of_station_rules() {
    for ok in [
        "drive-1",
        "a",
        "a1.2.3.4",
        "axis-a.line-2.plant",
        "xn--mhle1-kva.plant",
        "port-xyz",
        "port-12",
        "1.2.3",
        &"a".repeat(63),
    ] {
        assert_eq!(name::validate(ok.as_bytes()), Ok(()), "{ok}");
    }
    let long240 = [
        &"a".repeat(63)[..],
        &"b".repeat(63),
        &"c".repeat(63),
        &"d".repeat(48),
    ]
    .join(".");
    assert_eq!(long240.len(), 240);
    assert_eq!(name::validate(long240.as_bytes()), Ok(()));
    let long241 = format!("{long240}d");
    use NameError::*;
    for (bad, why) in [
        (long241.as_str(), TooLong),
        ("Drive-1", Character),
        ("name_1", Character),
        ("name/1", Character),
        ("-name", Hyphen),
        ("name-", Hyphen),
        ("name.-name", Hyphen),
        ("name.", LabelLength),
        (".name", LabelLength),
        ("a..b", LabelLength),
        (&"a".repeat(64), LabelLength),
        ("1.2.3.4", IpLike),
        ("192.168.000.1", IpLike),
        ("port-123", PortLike),
        ("port-123-98765", PortLike),
        ("port-001.switch", PortLike),
    ] {
        assert_eq!(name::validate(bad.as_bytes()), Err(why), "{bad}");
    }
    assert!(NameOfStation::new(b"").unwrap().is_empty());
}

#[test]
fn values_round_trip_through_emit_and_parse() {
    let ip = suite([192, 168, 0, 50], [255, 255, 255, 0], [192, 168, 0, 1]);
    let cases: [(BlockType, Value<'_>); 10] = [
        (BlockType::IpMac, Value::Mac(DEV)),
        (BlockType::IpParameter, Value::IpParameter(ip)),
        (
            BlockType::IpFullSuite,
            Value::IpFullSuite(ip, [Ipv4Addr::new(8, 8, 8, 8); 4]),
        ),
        (BlockType::NameOfStation, Value::Bytes(b"odd")),
        (
            BlockType::DeviceId,
            Value::DeviceId {
                vendor_id: 0x1234,
                device_id: 0x5678,
            },
        ),
        (BlockType::DeviceRole, Value::DeviceRole(1)),
        (BlockType::DeviceInstance, Value::DeviceInstance(0, 1)),
        (BlockType::DeviceInitiative, Value::DeviceInitiative(1)),
        (BlockType::ControlSignal, Value::Signal(0x0100)),
        (
            BlockType::ControlResponse,
            Value::Response(BlockType::IpParameter, BlockError::SetNotPossible),
        ),
    ];
    for (kind, value) in cases {
        let b = BlockRepr {
            kind,
            prefix: Some(7),
            value,
        };
        let mut buf = [0xEEu8; 64];
        let n = b.emit(&mut buf).unwrap();
        assert_eq!(n % 2, 0);
        assert_eq!(n, b.buffer_len());
        let raw = Blocks::new(&buf[..n]).next().unwrap().unwrap();
        assert_eq!(raw.kind, kind);
        let (prefix, v) = raw.split_prefix().unwrap();
        assert_eq!((prefix, Value::parse(kind, v).unwrap()), (7, value));
        assert!(b.emit(&mut buf[..n - 1]).is_err());
    }
    for o in 0..=255u8 {
        for s in [0u8, 1, 2, 3, 4, 5, 6, 7, 61, 255] {
            assert_eq!(BlockType::from_pair(o, s).pair(), (o, s));
        }
    }
    for e in 0..=255u8 {
        assert_eq!(u8::from(BlockError::from(e)), e);
    }
}
