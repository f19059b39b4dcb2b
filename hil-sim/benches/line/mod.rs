//! What the `eoe` and `foe` benches share: the in-process master brings up
//! a line (DC static sync of 100 iterations) and hands its first SubDevice
//! to the bench; the `--runs N` argument.

use ethercrab::{SubDevice, SubDeviceRef};
use hil_sim::sim::{Node, Simulation};
use std::cell::RefCell;
use std::sync::atomic::{AtomicU64, Ordering};

/// Runs `body` with the first SubDevice of `sim`'s line and the master's
/// clock; its result.
pub fn with_first_subdevice<N: Node, T>(
    sim: &RefCell<Simulation<N>>,
    body: impl for<'g> AsyncFnOnce(SubDeviceRef<'g, &'g SubDevice>, &'g AtomicU64) -> T,
) -> T {
    let config = ethercrab::MainDeviceConfig {
        dc_static_sync_iterations: 100,
        ..Default::default()
    };
    hil_sim::master::run_with(
        sim,
        hil_sim::master::in_process_timeouts(),
        config,
        async |md, clock| {
            let group = md
                .init_single_group::<2, 64>(|| clock.load(Ordering::Relaxed))
                .await
                .expect("init");
            let sd = group.subdevice(md, 0).expect("slave");
            body(sd, clock).await
        },
    )
}

/// The number after `--runs` on the command line, else `default`.
pub fn runs_arg(default: usize) -> usize {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == "--runs")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}
