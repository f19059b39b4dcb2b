//! What the `eoe` and `foe` benches share: the `--runs N` argument (the
//! line they run on: [`hil_sim::master::with_first_subdevice`]).

/// The number after `--runs` on the command line, else `default`.
pub fn runs_arg(default: usize) -> usize {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == "--runs")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}
