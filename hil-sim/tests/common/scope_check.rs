//! The physics a scope trace of a move must show (issue 35), checked on the
//! CSV a host script read back (`tests/soem/scope.py` through SOEM,
//! `tests/profinet/scope.py` through profinet-py), and its plot.

use hil_sim::scope_plot::{svg_to_png, ScopeTrace};
use std::path::Path;

/// Checks the trace in `csv` (channels "speed set-point [inc/s]", "speed
/// actual [inc/s]", "6064h position actual [inc]"): `samples` samples; the
/// trigger sample (t = 0) is sample `samples · pre / 100`, the first at or
/// above `level` on the set-point, the one before it below, no crossing
/// before it; the speed actual value integrated over the trace (trapezoids)
/// is 6064h's change within 1 % plus 2,000 inc; the drive moved more than a
/// revolution. Prints the figures and plots the trace beside the CSV
/// (`title`; SVG, and PNG where a converter runs).
pub fn check_move(csv: &Path, samples: usize, pre: usize, level: f64, title: &str) {
    let trace = ScopeTrace::from_csv(&std::fs::read_to_string(csv).expect("the CSV")).unwrap();
    assert_eq!(trace.t_ms.len(), samples);
    let set = trace.channel("speed set-point [inc/s]").unwrap();
    let vel = trace.channel("speed actual [inc/s]").unwrap();
    let pos = trace.channel("6064h position actual [inc]").unwrap();
    let trig = trace.t_ms.iter().position(|&t| t == 0.0).expect("t = 0");
    assert_eq!(trig, samples * pre / 100, "the trigger index");
    assert!(
        set[trig] >= level && set[trig - 1] < level,
        "the edge: {} -> {}",
        set[trig - 1],
        set[trig]
    );
    assert!(set[..trig].iter().all(|&v| v < level), "no earlier crossing");
    let dt = (trace.t_ms[1] - trace.t_ms[0]) * 1e-3;
    let integral: f64 = vel.windows(2).map(|w| (w[0] + w[1]) / 2.0 * dt).sum();
    let moved = pos[samples - 1] - pos[0];
    println!(
        "scope trace: trigger at sample {trig} ({} ms), speed set-point {} -> {} inc/s at the edge, {} ms \
         per sample; integral of the speed actual value {integral:.0} inc, 6064h moved {moved:.0} inc ({:+.3} %)",
        trace.t_ms[trig],
        set[trig - 1],
        set[trig],
        dt * 1e3,
        (integral - moved) / moved * 100.0
    );
    assert!(moved > f64::from(1 << 20), "the drive moved: {moved} inc");
    assert!(
        (integral - moved).abs() <= 0.01 * moved.abs() + 2000.0,
        "integral {integral} vs 6064h {moved}"
    );
    let (svg, png) = (csv.with_extension("svg"), csv.with_extension("png"));
    std::fs::write(&svg, trace.svg(title).unwrap()).unwrap();
    match svg_to_png(&svg, &png) {
        Ok(()) => println!("plot: {}, {}", svg.display(), png.display()),
        Err(e) => println!("plot: {} (no PNG: {e})", svg.display()),
    }
}
