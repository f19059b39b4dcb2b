//! A PROFINET device for the fuzz targets: fresh, or connected by
//! profinet-py's Connect (`profinet::testing`) with its AR up. It serves
//! PROFIenergy (record 0x80A0, switched on, pausing allowed) besides the
//! CM's and PDev records, so record writes reach every parser.
#![allow(dead_code, unused_imports)]

use nanos::Nanos;
use profinet::cm::NoRecords;
use profinet::device::Device;
use profinet::profienergy::{ModeTimes, PeApplication, ProfiEnergy, WithProfiEnergy};
use profinet::testing::{self, CONTROLLER_MAC};
use profinet::wire::MacAddr;

pub use profinet::testing::{udp_to_device, DEVICE_MAC as OUR_MAC};

/// A product with PROFIenergy on that may always pause.
#[derive(Debug, Default)]
pub struct Energy;

impl PeApplication for Energy {
    fn enabled(&self) -> bool {
        true
    }
    fn may_pause(&self) -> bool {
        true
    }
    fn mode(&self) -> ModeTimes {
        ModeTimes {
            min_pause: 1000,
            to_pause: 0,
            to_operate: 0,
            min_stay: 0,
            max_stay: u32::MAX,
        }
    }
}

pub type Hook = WithProfiEnergy<Energy, NoRecords>;

pub fn device() -> Device<Hook> {
    let hook = WithProfiEnergy {
        pe: ProfiEnergy::default(),
        app: Energy,
        inner: NoRecords,
    };
    Device::new(testing::device_config(), hook)
}

/// The device with profinet-py's AR established.
pub fn connected() -> Device<Hook> {
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
