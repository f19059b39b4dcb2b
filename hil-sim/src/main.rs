//! `hil-sim`: the simulated drive on a PC.
//!
//! - `hil-sim demo [--pcap FILE] [--plot FILE.svg] [--plant rigid|electrical]`
//!   (the default): a real EtherCAT master (ethercrab, in-process) brings one
//!   simulated drive to OP, enables axis A, homes it, runs a csp profile and
//!   plots the run (`--plant electrical`: through the 16 kHz current loop).
//! - `hil-sim demo --fieldbus profinet [--pcap FILE] [--plot FILE.svg]`: a
//!   scripted IO controller (in-process) runs the Example Function block's
//!   sequence against one simulated PROFINET drive and plots the run.
//! - `hil-sim serve --iface IF [--slaves N] [--axes 1|2] [--pcap FILE] [--seconds S]`:
//!   the simulated line answers EtherCAT frames on a raw Ethernet interface
//!   (`--axes 1`: single-axis drives, SI6A061).
//! - `hil-sim serve --fieldbus profinet --iface IF [--name NAME] [--pcap FILE]`:
//!   one simulated drive answers as a PROFINET IO device on the interface.
//! - `hil-sim scope-plot TRACE.csv [--svg FILE] [--png FILE]`: plots a
//!   trace of the drive's scope (group T) that `hil-sim/tests/soem/scope.py`
//!   read through SOEM.
//!
//! `hil-sim --help` and `hil-sim SUBCOMMAND --help` list every option.

mod cli;

use clap::Parser;
use cli::args::{Cli, Command, DemoArgs, Fieldbus};
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        None => cli::demo::demo(&DemoArgs::default()),
        Some(Command::Demo(a)) if a.fieldbus == Fieldbus::Profinet => cli::demo_pn::demo(a),
        Some(Command::Demo(a)) => cli::demo::demo(a),
        Some(Command::Serve(a)) => cli::serve::serve(a),
        Some(Command::ScopePlot(a)) => cli::scope::plot(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("hil-sim: {e}");
            ExitCode::FAILURE
        }
    }
}
