//! A scripted controller for tests, benchmarks, fuzz targets and the QEMU
//! measurement image (feature `testing`, never in a product image): the
//! device settings the tests use, profinet-py's Connect as a UDP frame, and
//! controller output frames for an established AR.
//!
//! `no_std` and heap-free: every frame is a [`Frame`] (a `heapless::Vec` of
//! up to [`FRAME_CAP`] bytes), so the firmware's QEMU image can script a
//! controller too.

use core::net::Ipv4Addr;

use nanos::Nanos;

use crate::cm::{Ar, Im0, ImData};
use crate::dcp::pdu::{service_type, BlockRepr, BlockWriter, Header, ServiceId, HEADER_LEN};
use crate::dcp::IpSuite;
use crate::device::DeviceConfig;
use crate::ip::{Endpoint, IpConfig, Stack, UdpTx, RPC_PORT, UDP_PAYLOAD_OFFSET};
use crate::wire::{emit_header, ethertype, MacAddr};

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

/// The longest frame these helpers build, bytes.
pub const FRAME_CAP: usize = 1600;

/// A frame (or payload) built by these helpers.
pub type Frame = heapless::Vec<u8, FRAME_CAP>;

fn nibble(c: u8) -> Option<u8> {
    match c {
        b'0'..=b'9' => Some(c - b'0'),
        b'a'..=b'f' => Some(c - b'a' + 10),
        b'A'..=b'F' => Some(c - b'A' + 10),
        _ => None,
    }
}

/// Hex text (anything but hex digits ignored) as bytes; an odd last digit
/// and anything beyond [`FRAME_CAP`] bytes are dropped.
pub fn hex(s: &str) -> Frame {
    let mut out = Frame::new();
    let mut high: Option<u8> = None;
    for d in s.bytes().filter_map(nibble) {
        match high.take() {
            None => high = Some(d),
            Some(h) => {
                if out.push(h << 4 | d).is_err() {
                    break;
                }
            }
        }
    }
    out
}

/// `payload` (cut to 1400 bytes) as a UDP datagram from the controller
/// (port 0xC000) to the device's RPC port, as a whole Ethernet frame.
pub fn udp_to_device(payload: &[u8]) -> Frame {
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
    let mut tx = [0u8; FRAME_CAP];
    if let Some(dst) = tx.get_mut(UDP_PAYLOAD_OFFSET..UDP_PAYLOAD_OFFSET + payload.len()) {
        dst.copy_from_slice(payload);
    }
    let ep = Endpoint {
        ip: DEVICE_IP,
        port: RPC_PORT,
    };
    match ctrl.emit_udp(Nanos::ZERO, &mut tx, 0xC000, ep, payload.len()) {
        Ok(UdpTx::Frame(n)) => tx
            .get(..n)
            .and_then(|f| Frame::from_slice(f).ok())
            .unwrap_or_default(),
        _ => Frame::new(),
    }
}

/// A DCP request frame from `src` to `dst` (no VLAN tag): FrameID
/// `frame_id`, `service` with transaction `xid` and `response_delay`, then
/// `blocks`. Empty when the blocks do not fit a frame.
pub fn dcp_request(
    dst: MacAddr,
    src: MacAddr,
    frame_id: u16,
    service: ServiceId,
    xid: u32,
    response_delay: u16,
    blocks: &[BlockRepr<'_>],
) -> Frame {
    let mut buf = [0u8; 1514];
    let built = (|| {
        let eth = emit_header(&mut buf, dst, src, None, ethertype::PROFINET)?;
        buf.get_mut(eth..eth + 2)?
            .copy_from_slice(&frame_id.to_be_bytes());
        let mut w = BlockWriter::new(buf.get_mut(eth + 2 + HEADER_LEN..)?);
        for b in blocks {
            w.push(b).ok()?;
        }
        let n = w.len();
        Header {
            service,
            service_type: service_type::REQUEST,
            xid,
            response_delay,
            data_length: u16::try_from(n).ok()?,
        }
        .emit(buf.get_mut(eth + 2..)?)
        .ok()?;
        Some(eth + 2 + HEADER_LEN + n)
    })();
    built
        .and_then(|len| buf.get(..len))
        .and_then(|f| Frame::from_slice(f).ok())
        .unwrap_or_default()
}

/// profinet-py's Connect (slot 1 OUT 18 words, slot 2 IN 18 words; 1 ms × 8,
/// watchdog and data hold 6 cycles) as a frame to the device.
pub fn connect_frame() -> Frame {
    udp_to_device(&hex(vectors::CONNECT))
}

/// A controller output frame for `ar`'s output CR: every data object filled
/// with `fill`, IOPS and IOCS good, DataStatus 0x35, cycle counter `counter`.
/// Empty when the AR has no output CR or its data does not fit a [`Frame`].
pub fn output_frame(ar: &Ar, counter: u16, fill: u8) -> Frame {
    let Some(cr) = ar.output_cr.as_ref() else {
        return Frame::new();
    };
    let len = usize::from(cr.data_length);
    let mut csdu_buf = [0u8; FRAME_CAP];
    let Some(csdu) = csdu_buf.get_mut(..len) else {
        return Frame::new();
    };
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
    let mut f = Frame::new();
    let parts: [&[u8]; 7] = [
        &DEVICE_MAC.0,
        &CONTROLLER_MAC.0,
        &0x8892u16.to_be_bytes(),
        &cr.frame_id.to_be_bytes(),
        csdu,
        &counter.to_be_bytes(),
        &[0x35, 0x00],
    ];
    for p in parts {
        if f.extend_from_slice(p).is_err() {
            return Frame::new();
        }
    }
    f
}
