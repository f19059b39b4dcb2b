//! `hil-sim demo --fieldbus profinet`: a scripted IO controller (in-process,
//! simulated time) with a model of the Example Function block
//! ([`hil_sim::fb`]) runs the FB's sequence against one simulated PROFINET
//! drive: enable, home, a positioning chain with end velocities and a
//! relative move, a speed segment, jog, PKW accesses, a provoked fault and
//! its acknowledgement. Every state change and FB output change is printed;
//! the plot shows position, velocity, torque, following error and the ZSW1
//! state with the phases marked.

use super::args::{create_output, plot_path_or, DemoArgs, Plant, DEFAULT_PLOT_PN};
use hil_sim::fb::sequence::{self, Observer, Options, Phase, Report, Sample, INC_PER_REV};
use hil_sim::fb::{state_name, zsw1_state};
use hil_sim::pcap::Recording;
use hil_sim::plot::Trace;
use nanos::Nanos;
use profidrive::zsw1::{OP, RTSO, SO};

/// Prints lines above a progress bar (one step per phase) and keeps the
/// trace for the plot.
struct Printer {
    bar: indicatif::ProgressBar,
    trace: Trace,
    /// The run's phases, in order (the bar's steps).
    phases: Vec<Phase>,
}

/// The ZSW1 state as a number for the plot: −1 fault, 0 SOI, 1 RTSO,
/// 2 SO, 3 OP.
fn state_value(zsw1: u16) -> f64 {
    if zsw1 & profidrive::zsw1::FAULT != 0 {
        return -1.0;
    }
    match zsw1_state(zsw1) {
        RTSO => 1.0,
        SO => 2.0,
        OP => 3.0,
        _ => 0.0,
    }
}

impl Observer for Printer {
    fn line(&mut self, t: Nanos, text: &str) {
        let line = format!("  [{:>10.3} ms] {text}", t.as_ns() as f64 / 1e6);
        if self.bar.is_hidden() {
            // not a terminal: the bar draws nothing, and neither would its println
            println!("{line}");
        } else {
            self.bar.println(line);
        }
    }

    fn phase(&mut self, t: Nanos, phase: Phase) {
        let k = self.phases.iter().position(|p| *p == phase).unwrap_or(0);
        self.bar.set_position(k as u64);
        self.bar.set_message(phase.name());
        self.trace.mark_phase(t, phase.name());
    }

    fn sample(&mut self, s: &Sample) {
        self.trace.push(
            s.t,
            s.set_inc,
            s.pos_inc,
            s.vel_inc_s,
            s.torque_permille,
            s.ferr_inc,
        );
        self.trace.push_state(state_value(s.zsw1));
    }
}

fn ms(t: Nanos) -> f64 {
    t.as_ns() as f64 / 1e6
}

fn summary(r: &Report) {
    println!("summary:");
    for p in &r.phases {
        println!(
            "  {:<12} {:>9.1} ms  ({:>9.1} … {:>9.1} ms)  {}",
            p.phase.name(),
            ms(p.end) - ms(p.start),
            ms(p.start),
            ms(p.end),
            p.summary
        );
    }
    let states: Vec<&str> = r.enable_states.iter().map(|s| state_name(*s)).collect();
    println!("  enable sequence: {}", states.join(" -> "));
    for (rpm, end) in &r.passing_rpm {
        println!("  chain: an intermediate target passed at {rpm} rpm (end velocity {end} rpm)");
    }
    for t in &r.targets {
        println!(
            "  {}: commanded {} inc ({:.4} rev), reached {} inc, error {:+} inc",
            t.label,
            t.commanded_inc,
            t.commanded_inc as f64 / INC_PER_REV as f64,
            t.reached_inc,
            t.error_inc()
        );
    }
    if let Some(t) = &r.self_tune {
        println!(
            "  self-tuning (B44 through PKW): A69 {:#06x}, B44[0] {}, J {:.4e} kg·m², Fc {:.4} N·m, \
             B {:.3e} N·m·s/rad; C31 {} µN·m·s/rad, C32 {} µs, I20 {} × 0.1/s",
            t.a69,
            t.code,
            f64::from(t.inertia) * 1e-7,
            f64::from(t.coulomb) * 1e-6,
            f64::from(t.viscous) * 1e-9,
            t.gains[0],
            t.gains[1],
            t.gains[2]
        );
    }
    for m in &r.moves {
        println!(
            "  positioning move {}: following error max {} inc, rms {:.1} inc",
            m.label, m.max_inc, m.rms_inc
        );
    }
    println!(
        "  following error max {} inc ({:.3}°)",
        r.max_following_error_inc,
        r.max_following_error_inc as f64 / INC_PER_REV as f64 * 360.0
    );
    println!(
        "  {} controller cycles, {} output frames, {} input frames",
        r.cycles, r.frames.0, r.frames.1
    );
    if r.deviations.is_empty() {
        println!("  no deviations from the spec seen");
    } else {
        println!("  {} deviation(s) from the spec:", r.deviations.len());
        for d in &r.deviations {
            println!("    deviation: {d}");
        }
    }
}

/// Runs the demo. Both output files are created before the run: a path that
/// cannot be written fails at once, never after the run claiming a file.
pub fn demo(args: &DemoArgs) -> Result<(), String> {
    let pcap = match &args.pcap {
        Some(p) => {
            let r = Recording::create(p)
                .map_err(|e| format!("cannot write the pcap file {}: {e}", p.display()))?;
            println!("recording frames to {}", p.display());
            Some(r)
        }
        None => None,
    };
    let plot_path = plot_path_or(&args.plot, DEFAULT_PLOT_PN)?;
    let options = Options {
        plant: args.plant().into(),
        self_tune: args.self_tune,
        mechanics: args.mechanics()?,
        bandwidth_hz: None,
    };
    let mut plot_file = create_output(&plot_path, "plot")?;
    println!(
        "hil-sim demo --fieldbus profinet: Example Function block (in-process IO controller, 1 ms) -> \
         simulated PROFINET drive -> {}",
        match args.plant() {
            Plant::Rigid => "simulated motor (rigid, torque in)",
            Plant::Electrical => "current loop (16 kHz) -> simulated PMSM and inverter",
        }
    );
    let phases = Phase::of_run(options.self_tune);
    let bar = indicatif::ProgressBar::new(phases.len() as u64);
    if let Ok(style) = indicatif::ProgressStyle::with_template("  phase [{bar:21}] {pos}/{len} {msg}") {
        bar.set_style(style);
    }
    let mut printer = Printer {
        bar,
        trace: Trace {
            set_name: "commanded target".into(),
            state_name: "ZSW1 state (-1 fault, 0 SOI, 1 RTSO, 2 SO, 3 OP)".into(),
            ..Trace::default()
        },
        phases,
    };
    let result = sequence::run_with(&mut printer, pcap, options);
    printer.bar.finish_and_clear();
    let (report, pcap) = match result {
        Ok(r) => r,
        Err(e) => {
            drop(plot_file);
            let _ = std::fs::remove_file(&plot_path);
            return Err(e);
        }
    };
    summary(&report);
    if let Err(e) = printer.trace.write_svg(
        &mut plot_file,
        "hil-sim demo --fieldbus profinet: the Example Function block's sequence, axis A",
    ) {
        drop(plot_file);
        let _ = std::fs::remove_file(&plot_path);
        return Err(format!("cannot write the plot {}: {e}", plot_path.display()));
    }
    println!("  plot: {}", plot_path.display());
    if let (Some(p), Some(mut r)) = (&args.pcap, pcap) {
        r.flush()
            .map_err(|e| format!("the pcap file {} is incomplete: {e}", p.display()))?;
    }
    Ok(())
}
