//! `hil-sim`: the simulated drive on a PC.
//!
//! - `hil-sim demo [--pcap FILE]`: a real EtherCAT master (ethercrab, in-process)
//!   brings one simulated drive to OP and back, printing each state change and
//!   the identity read from the SII.
//! - `hil-sim serve --iface IF [--slaves N] [--axes 1|2] [--pcap FILE] [--seconds S]`:
//!   the simulated line answers EtherCAT frames on a raw Ethernet interface.

use hil_sim::sim::Simulation;
use std::cell::RefCell;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("demo") | None => demo(&args),
        Some("serve") => serve(&args),
        Some("-h" | "--help" | "help") => {
            println!("{}", USAGE);
            Ok(())
        }
        Some(other) => Err(format!("unknown command `{other}`\n{USAGE}")),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("hil-sim: {e}");
            ExitCode::FAILURE
        }
    }
}

const USAGE: &str = "usage: hil-sim demo [--pcap FILE]
       hil-sim serve --iface IF [--slaves N] [--axes 1|2] [--pcap FILE] [--seconds S]";

/// The value after `--name`, if given.
fn opt(args: &[String], name: &str) -> Result<Option<String>, String> {
    match args.iter().position(|a| a == name) {
        None => Ok(None),
        Some(i) => args
            .get(i + 1)
            .cloned()
            .map(Some)
            .ok_or(format!("{name} needs a value")),
    }
}

fn print_new_changes(sim: &Simulation, printed: &mut Vec<usize>) {
    printed.resize(sim.drives().len(), 0);
    for (i, d) in sim.drives().iter().enumerate() {
        for (t, c) in d.state_log.iter().skip(printed[i]) {
            println!("  [{:>10.3} ms] slave {i}: {c}", *t as f64 / 1e6);
        }
        printed[i] = d.state_log.len();
    }
}

fn demo(args: &[String]) -> Result<(), String> {
    let sim = RefCell::new(Simulation::new(1));
    if let Some(p) = opt(args, "--pcap")? {
        sim.borrow_mut()
            .record_pcap(&PathBuf::from(&p))
            .map_err(|e| format!("{p}: {e}"))?;
        println!("recording frames to {p}");
    }
    println!("hil-sim demo: ethercrab (in-process) -> simulated ESC -> drive firmware stack");
    let mut printed = Vec::new();
    let result = hil_sim::master::run(&sim, hil_sim::master::in_process_timeouts(), async |md, clock| {
        let group = md
            .init_single_group::<4, 256>(|| clock.load(Ordering::Relaxed))
            .await
            .map_err(|e| format!("init: {e}"))?;
        println!("found {} slave(s)", group.len());
        for sd in group.iter(md) {
            let id = sd.identity();
            println!(
                "  {:#06x} \"{}\": vendor {:#010x}, product {:#010x}, revision {:#010x}, serial {:#010x}",
                sd.configured_address(),
                sd.name(),
                id.vendor_id,
                id.product_id,
                id.revision,
                id.serial
            );
        }
        print_new_changes(&sim.borrow(), &mut printed);
        let group = group
            .into_op(md)
            .await
            .map_err(|e| format!("PRE-OP -> OP: {e}"))?;
        print_new_changes(&sim.borrow(), &mut printed);
        for sd in group.iter(md) {
            let io = sd.io_raw();
            println!(
                "  process data: {} input bytes, {} output bytes",
                io.inputs().len(),
                io.outputs().len()
            );
        }
        for _ in 0..100 {
            group.tx_rx(md).await.map_err(|e| format!("cycle: {e}"))?;
        }
        println!("  100 process-data cycles in OP");
        let group = group
            .into_safe_op(md)
            .await
            .map_err(|e| format!("OP -> SAFE-OP: {e}"))?;
        let group = group
            .into_pre_op(md)
            .await
            .map_err(|e| format!("SAFE-OP -> PRE-OP: {e}"))?;
        let _group = group
            .into_init(md)
            .await
            .map_err(|e| format!("PRE-OP -> INIT: {e}"))?;
        print_new_changes(&sim.borrow(), &mut printed);
        Ok::<(), String>(())
    });
    let mut s = sim.borrow_mut();
    s.flush().map_err(|e| e.to_string())?;
    println!(
        "{} frames in {:.3} ms of simulated time",
        s.frames(),
        s.now_ns() as f64 / 1e6
    );
    result
}

fn serve(args: &[String]) -> Result<(), String> {
    let iface = opt(args, "--iface")?.ok_or("serve needs --iface IF")?;
    let slaves: usize = opt(args, "--slaves")?
        .map_or(Ok(1), |s| s.parse())
        .map_err(|_| "--slaves N")?;
    let axes: u8 = opt(args, "--axes")?
        .map_or(Ok(1), |s| s.parse())
        .map_err(|_| "--axes 1|2")?;
    if !(1..=2).contains(&axes) {
        return Err("--axes takes 1 or 2".into());
    }
    if !(1..=16).contains(&slaves) {
        return Err("--slaves takes 1..16".into());
    }
    let seconds: Option<f64> = opt(args, "--seconds")?
        .map(|s| s.parse())
        .transpose()
        .map_err(|_| "--seconds S")?;
    let sock = hil_sim::raw::RawSocket::open(&iface).map_err(|e| format!("{iface}: {e}"))?;
    let mut sim = Simulation::new(slaves);
    if let Some(p) = opt(args, "--pcap")? {
        sim.record_pcap(&PathBuf::from(&p))
            .map_err(|e| format!("{p}: {e}"))?;
    }
    println!("hil-sim serve: {slaves} simulated drive(s) with {axes} axis/axes on {iface}");
    let start = Instant::now();
    let mut printed = Vec::new();
    let mut buf = [0u8; 1600];
    loop {
        let elapsed = start.elapsed();
        if seconds.is_some_and(|s| elapsed.as_secs_f64() >= s) {
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
    }
    sim.flush().map_err(|e| e.to_string())?;
    println!("{} frames served", sim.frames());
    Ok(())
}
