//! Host figures of the PROFINET device: cyclic frames per second through
//! `Device` (an output frame received, the input frame built and sent: one
//! RT_CLASS_1 exchange), and the cost of a DCP Identify answer.
//!
//! `cargo run --release -p profinet --features testing --example pn_bench`
//!
//! A host benchmark, not device code: it may index and unwrap its own fixed
//! frames.
#![allow(clippy::indexing_slicing, clippy::expect_used, clippy::unwrap_used)]

use nanos::Nanos;
use profinet::device::Device;
use profinet::testing::{self, connect_frame, CONTROLLER_MAC as CTRL};
use profinet::wire::MacAddr;
use std::time::Instant;

fn device() -> Device {
    Device::plain(testing::device_config())
}

fn connect(d: &mut Device) {
    d.receive(Nanos::ZERO, &connect_frame(), &mut |_: &[u8]| {});
}

fn output_frame(d: &Device) -> Vec<u8> {
    testing::output_frame(d.cm().ar().expect("connected"), 0, 0).to_vec()
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
