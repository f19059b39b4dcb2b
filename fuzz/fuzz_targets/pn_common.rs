//! A PROFINET device for the fuzz targets: unnamed and fresh, or connected by
//! profinet-py's Connect (the crate's test vector) with its AR up.
#![allow(dead_code)]

#[path = "../../crates/profinet/src/cm/tests_vectors.rs"]
mod vectors;

use core::net::Ipv4Addr;
use nanos::Nanos;
use profinet::cm::{Im0, ImData};
use profinet::dcp::IpSuite;
use profinet::device::{Device, DeviceConfig};
use profinet::ip::{Endpoint, IpConfig, Stack, UdpTx, RPC_PORT, UDP_PAYLOAD_OFFSET};
use profinet::wire::MacAddr;

pub const OUR_MAC: MacAddr = MacAddr([0x02, 0, 0, 0, 0, 0x50]);
pub const CTRL_MAC: MacAddr = MacAddr([0x02, 0, 0, 0, 0, 0xC0]);
pub const OUR_IP: Ipv4Addr = Ipv4Addr::new(192, 168, 0, 50);

pub fn device() -> Device {
    Device::plain(DeviceConfig {
        mac: OUR_MAC,
        port_macs: [MacAddr([0x02, 0, 0, 0, 0, 0x51]), MacAddr([0x02, 0, 0, 0, 0, 0x52])],
        name: "drive-1".parse().unwrap(),
        ip: IpSuite {
            ip: OUR_IP,
            mask: Ipv4Addr::new(255, 255, 255, 0),
            gateway: Ipv4Addr::UNSPECIFIED,
        },
        im0: Im0::drive("FUZZ"),
        im: ImData::default(),
        boot_time: 1,
    })
}

fn hex(s: &str) -> Vec<u8> {
    let s: String = s.chars().filter(|c| c.is_ascii_hexdigit()).collect();
    (0..s.len() / 2).map(|i| u8::from_str_radix(&s[2 * i..2 * i + 2], 16).unwrap()).collect()
}

/// `payload` as a UDP datagram from the controller (192.168.0.10:0xC000) to
/// the device's RPC port, as a whole Ethernet frame.
pub fn udp_to_device(payload: &[u8]) -> Vec<u8> {
    let mut ctrl = Stack::new(
        CTRL_MAC,
        IpConfig {
            addr: Ipv4Addr::new(192, 168, 0, 10),
            netmask: Ipv4Addr::new(255, 255, 255, 0),
            gateway: Ipv4Addr::UNSPECIFIED,
        },
    );
    ctrl.learn(Nanos::ZERO, OUR_IP, OUR_MAC);
    let payload = &payload[..payload.len().min(1400)];
    let mut tx = vec![0u8; 1600];
    tx[UDP_PAYLOAD_OFFSET..UDP_PAYLOAD_OFFSET + payload.len()].copy_from_slice(payload);
    let ep = Endpoint { ip: OUR_IP, port: RPC_PORT };
    match ctrl.emit_udp(Nanos::ZERO, &mut tx, 0xC000, ep, payload.len()) {
        Ok(UdpTx::Frame(n)) => tx[..n].to_vec(),
        _ => Vec::new(),
    }
}

/// The device with profinet-py's AR established.
pub fn connected() -> Device {
    let mut d = device();
    d.receive(Nanos::ZERO, &udp_to_device(&hex(vectors::CONNECT)), &mut |_: &[u8]| {});
    assert!(d.cm().ar().is_some(), "the vector connects");
    d
}

/// An Ethernet frame to `dst` from the controller with EtherType 0x8892,
/// `frame_id` and `rest`.
pub fn rt_frame(dst: MacAddr, frame_id: u16, rest: &[u8]) -> Vec<u8> {
    let mut f = Vec::with_capacity(16 + rest.len());
    f.extend_from_slice(&dst.0);
    f.extend_from_slice(&CTRL_MAC.0);
    f.extend_from_slice(&0x8892u16.to_be_bytes());
    f.extend_from_slice(&frame_id.to_be_bytes());
    f.extend_from_slice(rest);
    f
}
