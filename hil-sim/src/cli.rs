//! The `hil-sim` binary's parts: the command line, `demo` and `serve`
//! (EtherCAT in `demo` and `serve`, PROFINET in `demo_pn` and `serve_pn`).

pub mod args;
pub mod demo;
pub mod demo_pn;
pub mod realtime;
pub mod scope;
pub mod serve;
pub mod serve_pn;
mod serve_stats;

use hil_sim::sim::Simulation;

/// Prints the state changes of every drive logged since the last call.
pub fn print_new_changes(sim: &Simulation, printed: &mut Vec<usize>) {
    printed.resize(sim.drives().len(), 0);
    for (i, d) in sim.drives().iter().enumerate() {
        for (t, c) in d.state_log.iter().skip(printed[i]) {
            println!("  [{:>10.3} ms] slave {i}: {c}", t.as_ns() as f64 / 1e6);
        }
        printed[i] = d.state_log.len();
    }
}
