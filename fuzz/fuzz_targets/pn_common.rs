//! A PROFINET device for the fuzz targets: fresh, or connected by
//! profinet-py's Connect (`profinet::testing`) with its AR up.
#![allow(dead_code, unused_imports)]

use nanos::Nanos;
use profinet::device::Device;
use profinet::testing::{self, CONTROLLER_MAC};
use profinet::wire::MacAddr;

pub use profinet::testing::{udp_to_device, DEVICE_MAC as OUR_MAC};

pub fn device() -> Device {
    Device::plain(testing::device_config())
}

/// The device with profinet-py's AR established.
pub fn connected() -> Device {
    let mut d = device();
    d.receive(Nanos::ZERO, &testing::connect_frame(), &mut |_: &[u8]| {});
    assert!(d.cm().ar().is_some(), "the vector connects");
    d
}

/// An Ethernet frame to `dst` from the controller with EtherType 0x8892,
/// `frame_id` and `rest`.
pub fn rt_frame(dst: MacAddr, frame_id: u16, rest: &[u8]) -> Vec<u8> {
    let mut f = Vec::with_capacity(16 + rest.len());
    f.extend_from_slice(&dst.0);
    f.extend_from_slice(&CONTROLLER_MAC.0);
    f.extend_from_slice(&0x8892u16.to_be_bytes());
    f.extend_from_slice(&frame_id.to_be_bytes());
    f.extend_from_slice(rest);
    f
}
