//! Simulated frames processed per second on a 2-slave line.
//!
//! `cargo bench -p hil-sim --bench frames [-- --cycles N]`
//!
//! 1. ethercrab (in-process) brings two simulated drives to OP, then runs
//!    process-data cycles through the whole chain (master, link, ESCs, slave
//!    firmware): frames per wall-clock second, the figure users feel.
//! 2. The same line alone: one cyclic LRW frame (both drives' PDOs) replayed
//!    through `Simulation::exchange` (ESCs + slave firmware, no master).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::cell::RefCell;
use std::sync::atomic::Ordering;
use std::time::Instant;

fn lrw_frame(len: usize) -> Vec<u8> {
    let mut f = vec![0xFF; 6];
    f.extend_from_slice(&[0x10; 6]);
    f.extend_from_slice(&0x88A4u16.to_be_bytes());
    let area = 10 + len + 2;
    f.extend_from_slice(&((area as u16) | 0x1000).to_le_bytes());
    f.push(12); // LRW
    f.push(0); // index
    f.extend_from_slice(&0u32.to_le_bytes()); // logical address 0 (ethercrab's group start)
    f.extend_from_slice(&(len as u16).to_le_bytes());
    f.extend_from_slice(&0u16.to_le_bytes()); // irq
    f.extend(std::iter::repeat_n(0u8, len));
    f.extend_from_slice(&0u16.to_le_bytes()); // wkc
    f
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let cycles: usize = args
        .iter()
        .position(|a| a == "--cycles")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(20_000);

    let sim = RefCell::new(hil_sim::sim::Simulation::new(2));
    let (wall, frames, sim_ns, pdi_bytes) =
        hil_sim::master::run(&sim, hil_sim::master::in_process_timeouts(), async |md, clock| {
            let group = md
                .init_single_group::<2, 256>(|| clock.load(Ordering::Relaxed))
                .await
                .expect("init");
            let group = group.into_op(md).await.expect("OP");
            let pdi: usize = group
                .iter(md)
                .map(|s| s.io_raw().inputs().len() + s.io_raw().outputs().len())
                .sum();
            let f0 = sim.borrow().frames();
            let t0 = sim.borrow().now().as_ns();
            let start = Instant::now();
            for _ in 0..cycles {
                group.tx_rx(md).await.expect("cycle");
            }
            let wall = start.elapsed();
            let s = sim.borrow();
            (wall, s.frames() - f0, s.now().as_ns() - t0, pdi)
        });
    println!("2-slave line, {cycles} process-data cycles, {pdi_bytes} PDI bytes per cycle");
    println!("{:<44} {:>14} {:>16}", "path", "frames/s wall", "sim µs/frame");
    println!(
        "{:<44} {:>14.0} {:>16.2}",
        "ethercrab -> link -> ESCs -> slave firmware",
        frames as f64 / wall.as_secs_f64(),
        sim_ns as f64 / frames as f64 / 1e3
    );

    let mut s = sim.borrow_mut();
    let frame = lrw_frame(pdi_bytes);
    let mut buf = frame.clone();
    let t0 = s.now().as_ns();
    let start = Instant::now();
    for _ in 0..cycles {
        buf.copy_from_slice(&frame);
        s.exchange(&mut buf);
    }
    let wall = start.elapsed();
    let wkc = u16::from_le_bytes([buf[buf.len() - 2], buf[buf.len() - 1]]);
    println!(
        "{:<44} {:>14.0} {:>16.2}",
        format!("LRW replay -> ESCs -> slave firmware (wkc {wkc})"),
        cycles as f64 / wall.as_secs_f64(),
        (s.now().as_ns() - t0) as f64 / cycles as f64 / 1e3
    );
}
