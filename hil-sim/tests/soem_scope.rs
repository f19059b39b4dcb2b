//! The drive's scope through SOEM (pysoem) against `hil-sim serve` (issue
//! 35; no spec item names the scope): `scope.py` arms a trace over the group
//! T objects, runs a known move, reads the trace back by segmented SDO
//! upload and writes it as CSV; this test checks it against physics and
//! plots it (`hil-sim scope-plot`'s code). Needs root and `PYSOEM_PYTHON`;
//! skipped otherwise, like `soem.rs`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::soem_line::{pysoem_python, scratch, Line};
use hil_sim::scope_plot::{svg_to_png, ScopeTrace};

const SAMPLES: usize = 2000;
const PRE: usize = 20;
const LEVEL: f64 = 100_000.0;

/// Issue 35, the scope read back through SOEM (`scope.py`: bad input refused
/// with its abort codes, 0800 0022h before the trace is complete, 0800 0024h
/// beyond its end): a pv move to 2,000,000 inc/s recorded at every 1 ms
/// control cycle, triggered on the speed set-point's rising edge through
/// 100,000 inc/s with 20 % before it. The trigger sample is sample 400 (20 %
/// of 2000), the first at or above the level, the one before it below; the
/// speed actual value integrated over the trace (trapezoids, 1 ms) is the
/// change of the position actual value 6064h within 1 % (plus 2,000 inc);
/// the drive moved (more than a revolution).
#[test]
fn issue35_soem_scope_trace_of_a_move_matches_the_physics() {
    let python = match pysoem_python() {
        Ok(p) => p,
        Err(why) => {
            eprintln!("soem scope test: skipped, {why}");
            return;
        }
    };
    let dir = scratch("soem-scope");
    let csv = dir.join("scope-trace.csv");
    let _ = std::fs::remove_file(&csv);
    let line = Line::new("s", 1, 90, &dir);
    let status = line.run(
        &python,
        "scope.py",
        &[
            "--csv",
            csv.to_str().unwrap(),
            "--samples",
            &SAMPLES.to_string(),
            "--pre",
            &PRE.to_string(),
            "--level",
            &(LEVEL as i64).to_string(),
        ],
    );
    if !status.success() {
        line.fail_with(&format!("scope.py through SOEM failed: {status}"));
    }
    let trace = ScopeTrace::from_csv(&std::fs::read_to_string(&csv).expect("the CSV")).unwrap();
    assert_eq!(trace.t_ms.len(), SAMPLES);
    let set = trace.channel("speed set-point [inc/s]").unwrap();
    let vel = trace.channel("speed actual [inc/s]").unwrap();
    let pos = trace.channel("6064h position actual [inc]").unwrap();
    // the trigger sample: t = 0 at the pre-trigger share, on the edge
    let trig = trace.t_ms.iter().position(|&t| t == 0.0).expect("t = 0");
    assert_eq!(trig, SAMPLES * PRE / 100, "the trigger index");
    assert!(
        set[trig] >= LEVEL && set[trig - 1] < LEVEL,
        "the edge: {} -> {}",
        set[trig - 1],
        set[trig]
    );
    assert!(set[..trig].iter().all(|&v| v < LEVEL), "no earlier crossing");
    let dt = (trace.t_ms[1] - trace.t_ms[0]) * 1e-3;
    assert!((dt - 1e-3).abs() < 1e-9, "1 ms samples: {dt}");
    // velocity integrates to the position's change
    let integral: f64 = vel.windows(2).map(|w| (w[0] + w[1]) / 2.0 * dt).sum();
    let moved = pos[SAMPLES - 1] - pos[0];
    println!(
        "scope trace: trigger at sample {trig} ({} ms), speed set-point {} -> {} inc/s at the edge; \
         integral of the speed actual value {integral:.0} inc, 6064h moved {moved:.0} inc ({:+.3} %)",
        trace.t_ms[trig],
        set[trig - 1],
        set[trig],
        (integral - moved) / moved * 100.0
    );
    assert!(moved > f64::from(1 << 20), "the drive moved: {moved} inc");
    assert!(
        (integral - moved).abs() <= 0.01 * moved.abs() + 2000.0,
        "integral {integral} vs 6064h {moved}"
    );
    let svg = dir.join("scope-trace.svg");
    std::fs::write(
        &svg,
        trace
            .svg("Scope: pv move to 2,000,000 inc/s (SOEM, hil-sim serve)")
            .unwrap(),
    )
    .unwrap();
    match svg_to_png(&svg, &dir.join("scope-trace.png")) {
        Ok(()) => println!(
            "plot: {}, {}",
            svg.display(),
            dir.join("scope-trace.png").display()
        ),
        Err(e) => println!("plot: {} (no PNG: {e})", svg.display()),
    }
}
