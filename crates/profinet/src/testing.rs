//! A scripted controller for tests, benchmarks and fuzz targets (feature
//! `testing`, never in the firmware): the device settings the tests use,
//! profinet-py's Connect as a UDP frame, and controller output frames for an
//! established AR.

use core::net::Ipv4Addr;
use std::vec::Vec;

use nanos::Nanos;

use crate::cm::{Ar, Im0, ImData};
use crate::dcp::IpSuite;
use crate::device::DeviceConfig;
use crate::ip::{Endpoint, IpConfig, Stack, UdpTx, RPC_PORT, UDP_PAYLOAD_OFFSET};
use crate::wire::MacAddr;

/// profinet-py 0.6.6's requests (see the module's own documentation).
#[allow(dead_code)]
#[path = "cm/tests_vectors.rs"]
pub mod vectors;

/// The device's interface MAC in these tests.
pub const DEVICE_MAC: MacAddr = MacAddr([0x02, 0, 0, 0, 0, 0x50]);
/// The controller's MAC (the one in profinet-py's Connect vector).
pub const CONTROLLER_MAC: MacAddr = MacAddr([0x02, 0, 0, 0, 0, 0xC0]);
/// The device's IP.
pub const DEVICE_IP: Ipv4Addr = Ipv4Addr::new(192, 168, 0, 50);
/// The controller's IP.
pub const CONTROLLER_IP: Ipv4Addr = Ipv4Addr::new(192, 168, 0, 10);

/// A device named "drive-1" at [`DEVICE_IP`]/24 with port MACs …51, …52.
pub fn device_config() -> DeviceConfig {
    DeviceConfig {
        mac: DEVICE_MAC,
        port_macs: [
            MacAddr([0x02, 0, 0, 0, 0, 0x51]),
            MacAddr([0x02, 0, 0, 0, 0, 0x52]),
        ],
        name: crate::dcp::NameOfStation::new(b"drive-1").unwrap_or(crate::dcp::NameOfStation::EMPTY),
        ip: IpSuite {
            ip: DEVICE_IP,
            mask: Ipv4Addr::new(255, 255, 255, 0),
            gateway: Ipv4Addr::UNSPECIFIED,
        },
        im0: Im0::drive("TEST0001"),
        im: ImData::default(),
        boot_time: 1,
    }
}

/// Hex text (whitespace and line breaks ignored) as bytes.
pub fn hex(s: &str) -> Vec<u8> {
    let digits: Vec<u8> = s.bytes().filter(u8::is_ascii_hexdigit).collect();
    digits
        .chunks(2)
        .filter_map(|p| core::str::from_utf8(p).ok())
        .filter_map(|p| u8::from_str_radix(p, 16).ok())
        .collect()
}

/// `payload` (cut to 1400 bytes) as a UDP datagram from the controller
/// (port 0xC000) to the device's RPC port, as a whole Ethernet frame.
pub fn udp_to_device(payload: &[u8]) -> Vec<u8> {
    let mut ctrl = Stack::new(
        CONTROLLER_MAC,
        IpConfig {
            addr: CONTROLLER_IP,
            netmask: Ipv4Addr::new(255, 255, 255, 0),
            gateway: Ipv4Addr::UNSPECIFIED,
        },
    );
    ctrl.learn(Nanos::ZERO, DEVICE_IP, DEVICE_MAC);
    let payload = payload.get(..payload.len().min(1400)).unwrap_or(&[]);
    let mut tx = std::vec![0u8; 1600];
    if let Some(dst) = tx.get_mut(UDP_PAYLOAD_OFFSET..UDP_PAYLOAD_OFFSET + payload.len()) {
        dst.copy_from_slice(payload);
    }
    let ep = Endpoint {
        ip: DEVICE_IP,
        port: RPC_PORT,
    };
    match ctrl.emit_udp(Nanos::ZERO, &mut tx, 0xC000, ep, payload.len()) {
        Ok(UdpTx::Frame(n)) => tx.get(..n).map(<[u8]>::to_vec).unwrap_or_default(),
        _ => Vec::new(),
    }
}

/// profinet-py's Connect (slot 1 OUT 18 words, slot 2 IN 18 words; 1 ms × 8,
/// watchdog and data hold 6 cycles) as a frame to the device.
pub fn connect_frame() -> Vec<u8> {
    udp_to_device(&hex(vectors::CONNECT))
}

/// A controller output frame for `ar`'s output CR: every data object filled
/// with `fill`, IOPS and IOCS good, DataStatus 0x35, cycle counter `counter`.
pub fn output_frame(ar: &Ar, counter: u16, fill: u8) -> Vec<u8> {
    let Some(cr) = ar.output_cr.as_ref() else {
        return Vec::new();
    };
    let len = usize::from(cr.data_length);
    let mut f = Vec::with_capacity(16 + len + 4);
    f.extend_from_slice(&DEVICE_MAC.0);
    f.extend_from_slice(&CONTROLLER_MAC.0);
    f.extend_from_slice(&0x8892u16.to_be_bytes());
    f.extend_from_slice(&cr.frame_id.to_be_bytes());
    let mut csdu = std::vec![0u8; len];
    for o in &cr.data {
        let at = usize::from(o.frame_offset);
        let n = usize::from(o.data_len);
        if let Some(d) = csdu.get_mut(at..at + n) {
            d.fill(fill);
        }
        if let Some(iops) = csdu.get_mut(at + n) {
            *iops = 0x80;
        }
    }
    for c in &cr.iocs {
        if let Some(iocs) = csdu.get_mut(usize::from(c.frame_offset)) {
            *iocs = 0x80;
        }
    }
    f.extend_from_slice(&csdu);
    f.extend_from_slice(&counter.to_be_bytes());
    f.extend_from_slice(&[0x35, 0x00]);
    f
}
