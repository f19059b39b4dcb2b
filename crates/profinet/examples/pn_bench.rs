//! Host figures of the PROFINET device: cyclic frames per second through
//! `Device` (an output frame received, the input frame built and sent: one
//! RT_CLASS_1 exchange), and the cost of a DCP Identify answer.
//!
//! `cargo run --release -p profinet --example pn_bench`
//!
//! A host benchmark, not device code: it may index and unwrap its own fixed
//! frames.
#![allow(clippy::indexing_slicing, clippy::expect_used, clippy::unwrap_used)]

#[path = "../src/cm/tests_vectors.rs"]
#[allow(dead_code)]
mod vectors;

use core::net::Ipv4Addr;
use nanos::Nanos;
use profinet::cm::{Im0, ImData};
use profinet::dcp::IpSuite;
use profinet::device::{Device, DeviceConfig};
use profinet::ip::{Endpoint, IpConfig, Stack, UdpTx, RPC_PORT, UDP_PAYLOAD_OFFSET};
use profinet::wire::MacAddr;
use std::time::Instant;

const OUR: MacAddr = MacAddr([2, 0, 0, 0, 0, 0x50]);
const CTRL: MacAddr = MacAddr([2, 0, 0, 0, 0, 0xC0]);

fn hex(s: &str) -> Vec<u8> {
    let s: String = s.chars().filter(|c| c.is_ascii_hexdigit()).collect();
    (0..s.len() / 2)
        .map(|i| u8::from_str_radix(&s[2 * i..2 * i + 2], 16).unwrap_or(0))
        .collect()
}

fn device() -> Device {
    Device::plain(DeviceConfig {
        mac: OUR,
        port_macs: [MacAddr([2, 0, 0, 0, 0, 0x51]), MacAddr([2, 0, 0, 0, 0, 0x52])],
        name: "drive-1".parse().expect("a valid name"),
        ip: IpSuite {
            ip: Ipv4Addr::new(192, 168, 0, 50),
            mask: Ipv4Addr::new(255, 255, 255, 0),
            gateway: Ipv4Addr::UNSPECIFIED,
        },
        im0: Im0::drive("BENCH"),
        im: ImData::default(),
        boot_time: 1,
    })
}

fn connect(d: &mut Device) {
    let mut ctrl = Stack::new(
        CTRL,
        IpConfig {
            addr: Ipv4Addr::new(192, 168, 0, 10),
            netmask: Ipv4Addr::new(255, 255, 255, 0),
            gateway: Ipv4Addr::UNSPECIFIED,
        },
    );
    let ep = Endpoint {
        ip: Ipv4Addr::new(192, 168, 0, 50),
        port: RPC_PORT,
    };
    ctrl.learn(Nanos::ZERO, ep.ip, OUR);
    let req = hex(vectors::CONNECT);
    let mut tx = vec![0u8; 1600];
    tx[UDP_PAYLOAD_OFFSET..UDP_PAYLOAD_OFFSET + req.len()].copy_from_slice(&req);
    if let Ok(UdpTx::Frame(n)) = ctrl.emit_udp(Nanos::ZERO, &mut tx, 0xC000, ep, req.len()) {
        d.receive(Nanos::ZERO, &tx[..n], &mut |_: &[u8]| {});
    }
}

fn output_frame(d: &Device) -> Vec<u8> {
    let cr = d.cm().ar().and_then(|a| a.output_cr.clone()).expect("connected");
    let n = 14 + 2 + cr.data_length as usize + 4;
    let mut f = vec![0u8; n];
    f[..6].copy_from_slice(&OUR.0);
    f[6..12].copy_from_slice(&CTRL.0);
    f[12..14].copy_from_slice(&0x8892u16.to_be_bytes());
    f[14..16].copy_from_slice(&cr.frame_id.to_be_bytes());
    for o in &cr.data {
        f[16 + o.frame_offset as usize + o.data_len as usize] = 0x80;
    }
    for c in &cr.iocs {
        f[16 + c.frame_offset as usize] = 0x80;
    }
    f[n - 2] = 0x35;
    f
}

fn main() {
    let mut d = device();
    connect(&mut d);
    let cycle = d
        .cm()
        .ar()
        .and_then(|a| a.output_cr.as_ref())
        .map_or(Nanos::from_ms(1), |c| c.cycle());
    let mut frame = output_frame(&d);
    let n = frame.len();
    let cycles = 200_000u32;
    let mut sent = 0u64;
    let start = Instant::now();
    for k in 0..cycles {
        let now = cycle.saturating_mul(u64::from(k));
        let counter = (k as u16).wrapping_mul(256);
        frame[n - 4..n - 2].copy_from_slice(&counter.to_be_bytes());
        d.receive(now, &frame, &mut |_: &[u8]| {});
        d.poll(now, &mut |_: &[u8]| sent += 1);
    }
    let el = start.elapsed();
    let per = el.as_nanos() as f64 / f64::from(cycles);
    println!(
        "figure: PROFINET cyclic exchange on the host: {:.0} ns per cycle (output frame in, input frame out), {:.0} exchanges/s, {sent} frames sent over {cycles} cycles",
        per,
        1e9 / per
    );
    assert!(d.output_data(2).is_some(), "outputs valid at the end");

    let mut ident = vec![0u8; 60];
    ident[..6].copy_from_slice(&MacAddr::DCP_IDENTIFY.0);
    ident[6..12].copy_from_slice(&CTRL.0);
    ident[12..14].copy_from_slice(&0x8892u16.to_be_bytes());
    ident[14..30].copy_from_slice(&[0xFE, 0xFE, 5, 0, 0, 0, 0, 1, 0, 1, 0, 4, 0xFF, 0xFF, 0, 0]);
    let mut fresh = device();
    let rounds = 100_000u32;
    let mut answers = 0u64;
    let start = Instant::now();
    for k in 0..rounds {
        fresh.receive(Nanos::from_ms(u64::from(k)), &ident, &mut |_: &[u8]| answers += 1);
    }
    let per = start.elapsed().as_nanos() as f64 / f64::from(rounds);
    println!("figure: DCP Identify All answered in {per:.0} ns on the host ({answers} answers)");
}
