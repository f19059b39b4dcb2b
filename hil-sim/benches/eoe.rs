//! IP through EoE in simulated time: ping round-trip time and UDP
//! parameter-read latency from a master-side host interface (smoltcp on
//! `hil_sim::eoe::EoeTunnel`) through ethercrab in-process, the simulated
//! ESC, the slave's EoE server and the drive's `net::NetStack`.
//!
//! `cargo bench -p hil-sim --bench eoe [-- --runs N]`
//!
//! The tunnel moves one mailbox message each way per round (SM1 status
//! read, SM1 read, SM0 status read, SM0 write): the figures are those of a
//! master that polls the mailbox back to back, with a 256-byte mailbox.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod line;
use hil_sim::eoe::{set_ip_request, HostNet};
use hil_sim::sim::Simulation;
use nanos::Nanos;
use std::cell::RefCell;
use std::sync::atomic::Ordering;

const DRIVE_IP: [u8; 4] = [10, 0, 0, 20];
const HOST_IP: [u8; 4] = [10, 0, 0, 1];

fn stats(v: &mut [Nanos]) -> (f64, f64, f64) {
    v.sort_unstable();
    let mean = v.iter().map(|t| t.as_ns()).sum::<u64>() as f64 / v.len() as f64;
    (
        v[0].as_ns() as f64 / 1e3,
        mean / 1e3,
        v[v.len() - 1].as_ns() as f64 / 1e3,
    )
}

fn main() {
    let runs = line::runs_arg(50);
    let sim = RefCell::new(Simulation::new(1));
    sim.borrow_mut().drives_mut()[0].bind_net([2, 0, 0, 0, 0, 0x14], 1, Nanos::ZERO);
    let wall = std::time::Instant::now();
    let (mut ping, mut big, mut read, frames) =
        hil_sim::master::with_first_subdevice(&sim, async |sd, clock| {
            let mut host = HostNet::new(
                [2, 0, 0, 0, 0, 1],
                &[(HOST_IP, 24)],
                Nanos::from_ns(clock.load(Ordering::Relaxed)),
            );
            assert!(
                host.tunnel
                    .request(&sd, &set_ip_request(DRIVE_IP, [255, 255, 255, 0], HOST_IP))
                    .await
            );
            while host.tunnel.responses.pop_front().is_none() {
                host.step(&sd, clock).await;
            }
            // the first ping resolves the addresses (ARP both ways): not counted
            host.ping(&sd, clock, DRIVE_IP, 0, 1000)
                .await
                .expect("first ping");
            let f0 = sim.borrow().frames();
            let mut ping = Vec::new();
            let mut big = Vec::new();
            let mut read = Vec::new();
            for i in 1..=runs {
                ping.push(
                    host.ping(&sd, clock, DRIVE_IP, i as u16, 1000)
                        .await
                        .expect("ping"),
                );
                big.push(
                    host.ping_with(&sd, clock, DRIVE_IP, 0x8000 | i as u16, 1472, 1000)
                        .await
                        .expect("ping 1472"),
                );
                // the service takes one request per 10 ms beyond a burst of 16
                // (docs/eoe.md): each read after a refill, so none is dropped
                let now = sim.borrow().now();
                sim.borrow_mut().catch_up(now + net::PARAM_REFILL);
                host.step(&sd, clock).await; // the master's clock follows
                let (answer, ns) = host
                    .param_request(&sd, clock, DRIVE_IP, "R A150", 1000)
                    .await
                    .expect("answer");
                assert_eq!(answer, "OK 1000");
                read.push(ns);
            }
            (ping, big, read, sim.borrow().frames() - f0)
        })
        .expect("the line's first SubDevice");
    let wall = wall.elapsed();
    let tunnel_frames = frames as f64 / runs as f64;
    println!("IP over EoE, 1 drive, mailbox 256 bytes, {runs} runs (simulated time)");
    let (lo, mean, hi) = stats(&mut ping);
    println!("ping (56-byte payload) round trip: min {lo:.1} µs, mean {mean:.1} µs, max {hi:.1} µs");
    let (lo, mean, hi) = stats(&mut big);
    println!("ping (1472-byte payload, 7 fragments each way) round trip: min {lo:.1} µs, mean {mean:.1} µs, max {hi:.1} µs");
    let (lo, mean, hi) = stats(&mut read);
    println!("UDP parameter read (R A150) latency: min {lo:.1} µs, mean {mean:.1} µs, max {hi:.1} µs");
    println!(
        "{tunnel_frames:.1} EtherCAT frames per run (two pings + one read), {:.0} ms wall clock",
        wall.as_secs_f64() * 1e3
    );
}
