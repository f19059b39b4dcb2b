//! Arbitrary Ethernet frames into the drive's EoE interface, polled by its
//! IP stack (smoltcp, the UDP parameter service, the SNTP client, DHCP):
//! whatever the master tunnels, nothing may panic. Input: records of
//! `kind, len (2 bytes), bytes`; kind 0 = the bytes as a raw frame, 1 = a
//! UDP datagram with the bytes as payload to the parameter service, 2 = the
//! bytes as an SNTP answer from the configured server (both with valid
//! checksums, so they get past smoltcp's checks). Time advances 60 s per
//! record, so the SNTP client has requests outstanding. Each input starts
//! from a copy of one powered-up drive.
#![no_main]

use drive_ecat::runtime::Drive;
use ecat::eoe::{EthernetPort, IpParams};
use hil_sim::eoe::net_settings;
use hil_sim::sim::SimFlash;
use libfuzzer_sys::fuzz_target;
use net::smoltcp::iface::SocketStorage;
use net::smoltcp::phy::ChecksumCapabilities;
use net::smoltcp::wire::{
    EthernetAddress, EthernetFrame, EthernetProtocol, EthernetRepr, IpAddress, IpProtocol, Ipv4Address,
    Ipv4Packet, Ipv4Repr, UdpPacket, UdpRepr,
};
use net::{NetBuffers, NetConfig, NetStack, SOCKETS};

const DRIVE: [u8; 4] = [10, 0, 0, 20];
const HOST: [u8; 4] = [10, 0, 0, 1];
const DRIVE_MAC: [u8; 6] = [2, 0, 0, 0, 0, 0x14];

/// Ethernet + IPv4 + UDP from HOST:`src_port` to DRIVE:`dst_port`.
fn udp_frame(src_port: u16, dst_port: u16, payload: &[u8]) -> Vec<u8> {
    let payload = &payload[..payload.len().min(1400)];
    let udp = UdpRepr { src_port, dst_port };
    let ip = Ipv4Repr {
        src_addr: Ipv4Address::from(HOST),
        dst_addr: Ipv4Address::from(DRIVE),
        next_header: IpProtocol::Udp,
        payload_len: udp.header_len() + payload.len(),
        hop_limit: 64,
    };
    let eth = EthernetRepr {
        src_addr: EthernetAddress([2, 0, 0, 0, 0, 1]),
        dst_addr: EthernetAddress(DRIVE_MAC),
        ethertype: EthernetProtocol::Ipv4,
    };
    let mut buf = vec![0u8; eth.buffer_len() + ip.buffer_len() + ip.payload_len];
    let caps = ChecksumCapabilities::default();
    let mut f = EthernetFrame::new_unchecked(&mut buf[..]);
    eth.emit(&mut f);
    let mut p = Ipv4Packet::new_unchecked(f.payload_mut());
    ip.emit(&mut p, &caps);
    let mut u = UdpPacket::new_unchecked(p.payload_mut());
    udp.emit(
        &mut u,
        &IpAddress::Ipv4(Ipv4Address::from(HOST)),
        &IpAddress::Ipv4(Ipv4Address::from(DRIVE)),
        payload.len(),
        |b| b.copy_from_slice(payload),
        &caps,
    );
    buf
}

/// A powered-up drive with SNTP on (server 1 = the host).
fn sntp_drive() -> Drive<SimFlash> {
    let mut drive = Drive::new(SimFlash::new());
    for (sub, v) in [(1u8, 1i64), (2, 0x0A00_0001), (3, 0x0A00_0002)] {
        let _ = drive.objects_mut().set(0x20C7, sub, v);
    }
    drive
}

thread_local! {
    /// [`sntp_drive`] once per process: each input starts from a copy (a
    /// power-up builds the dictionary's image from the declaration, which
    /// cost nine tenths of an input).
    static POWERED: Drive<SimFlash> = sntp_drive();
}

fuzz_target!(|data: &[u8]| {
    let mut drive = POWERED.with(Drive::clone);
    // buffers on the stack (hil-sim's DriveNet leaks them: not for a fuzzer)
    let mut bufs = NetBuffers::new();
    let mut slots = [SocketStorage::EMPTY; SOCKETS];
    let cfg = NetConfig {
        mac: DRIVE_MAC,
        seed: 1,
    };
    let mut net = NetStack::new(cfg, &mut bufs, &mut slots, drive.eoe_mut(), nanos::Nanos::ZERO);
    drive.eoe_mut().ip_changed(&IpParams {
        ip: Some(DRIVE),
        mask: Some([255, 255, 255, 0]),
        gateway: Some(HOST),
        ..IpParams::default()
    });
    let mut t = nanos::Nanos::ZERO;
    let mut rest = data;
    let mut out = [0u8; 1536];
    while let [kind, l0, l1, tail @ ..] = rest {
        let n = usize::from(u16::from_le_bytes([*l0, *l1])).min(tail.len());
        let (bytes, next) = tail.split_at(n);
        rest = next;
        let frame = match kind % 3 {
            0 => bytes.to_vec(),
            1 => udp_frame(40_000, net::param::PARAM_PORT, bytes),
            _ => udp_frame(123, 123, bytes),
        };
        drive.eoe_mut().receive(&frame);
        t += nanos::Nanos::from_secs(60);
        // the frames arrive as if the master tunnelled them: the tunnel is open (E-098)
        let settings = net::NetSettings {
            tunnel_open: true,
            ..net_settings(&drive)
        };
        drive.with_eoe(|q, dict, state| net.poll(t, q, dict, state, &settings));
        while drive.eoe_mut().transmit(&mut out).is_some() {}
    }
});
