//! `hil-sim serve`: the simulated line answers EtherCAT frames on a raw
//! Ethernet interface, paced by the wall clock.

use super::args::ServeArgs;
use super::print_new_changes;
use hil_sim::sim::{SimDrive, Simulation};
use std::time::{Duration, Instant};

/// Runs `serve` until `--seconds` have passed (or forever).
pub fn serve(args: &ServeArgs) -> Result<(), String> {
    let slaves = usize::from(args.slaves);
    // drives with firmware slots: an FoE download in Bootstrap is accepted
    let mut sim = Simulation::with_nodes((0..slaves).map(|_| SimDrive::with_firmware_slots()).collect());
    // the recording first: an unwritable path fails before anything else
    if let Some(p) = &args.pcap {
        sim.record_pcap(p)
            .map_err(|e| format!("cannot write the pcap file {}: {e}", p.display()))?;
    }
    let iface = &args.iface;
    let sock = hil_sim::raw::RawSocket::open(iface).map_err(|e| format!("{iface}: {e}"))?;
    // every drive answers ping and the UDP parameter service on its EoE
    // interface once the master set its IP address (docs/eoe.md)
    for (i, d) in (1u8..).zip(sim.drives_mut()) {
        d.bind_net([0x02, 0x00, 0x00, 0x00, 0x00, i], u64::from(i), 0);
    }
    println!(
        "hil-sim serve: {slaves} simulated double-axis drive(s) on {iface} (--axes {}: a single-axis variant is not modelled yet)",
        args.axes
    );
    println!(
        "EoE: ping and the UDP parameter service (port {}) answer at the IP address the master sets",
        net::param::PARAM_PORT
    );
    if let Some(p) = &args.pcap {
        println!("recording frames to {}", p.display());
    }
    let start = Instant::now();
    let mut printed = Vec::new();
    let mut buf = [0u8; 1600];
    let mut last_flush = start;
    loop {
        let elapsed = start.elapsed();
        if args.seconds.is_some_and(|s| elapsed.as_secs_f64() >= s) {
            break;
        }
        // The simulation is paced by the wall clock.
        sim.catch_up(u64::try_from(elapsed.as_nanos()).unwrap_or(u64::MAX));
        if let Some(n) = sock
            .recv(&mut buf, Duration::from_millis(1))
            .map_err(|e| e.to_string())?
        {
            let frame = &mut buf[..n];
            sim.exchange(frame);
            sock.send(frame).map_err(|e| format!("send: {e}"))?;
        }
        print_new_changes(&sim, &mut printed);
        if last_flush.elapsed() >= Duration::from_secs(1) {
            last_flush = Instant::now();
            flush_recording(&mut sim, args)?;
        }
    }
    flush_recording(&mut sim, args)?;
    println!("{} frames served", sim.frames());
    Ok(())
}

/// Flushes the pcap recording: a write error ends `serve` with a message.
fn flush_recording(sim: &mut Simulation, args: &ServeArgs) -> Result<(), String> {
    match (&args.pcap, sim.flush()) {
        (Some(p), Err(e)) => Err(format!("the pcap file {} is incomplete: {e}", p.display())),
        _ => Ok(()),
    }
}
