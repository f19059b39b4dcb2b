//! The Example Function block's scenarios P-219…P-227 (and P-206, the
//! standard parameter record 0xB02E on the running AR) through profinet-py
//! (PyPI, 0.6.6), an IO controller written by others, against `hil-sim
//! serve --fieldbus profinet --control FIFO` (one drive with its motors)
//! over a veth pair between two private network namespaces.
//!
//! `tests/profinet/fb.py` models the function block (spec profidrive.md
//! §13: its inputs build the 36-byte receive telegrams 0xE0/0xE1/0xE2 of
//! §4.5 each cycle, the response telegram gives its outputs, PKW with the
//! toggle rule) on profinet-py's cyclic exchange, runs the scenarios and
//! prints one line for each: `scenario P-2xx: ok|FAIL|expected-fail: …`.
//! The test fails on a FAIL line, on a scenario without its line and on
//! the script's failure; the expected failures (the drive's known gaps,
//! with the observed and the specified behaviour) are printed and listed.
//! The script's `figure:` lines (time per scenario, positions commanded
//! and reached, largest following error) are appended to
//! `target/tmp/profinet-py/figures.txt`, which `.ci/run` prints.
//!
//! Needs root and `PROFINET_PY_PYTHON` as `tests/profinet.rs`; without
//! either the test prints why and passes without running.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::pn_line::{module_args, PnLine};
use std::path::Path;
use std::time::Duration;

/// A script that has not finished after this long has hung.
const SCRIPT_LIMIT: Duration = Duration::from_secs(150);
/// The figure lines of this test (fb.py prints them so).
const FIGURE: &str = "figure: P-2";
/// The scenarios, each reported once.
const SCENARIOS: [&str; 10] = [
    "P-219", "P-220", "P-221", "P-222", "P-223", "P-224", "P-225", "P-226", "P-206", "P-227",
];

/// The result word of a scenario line: `ok`, `FAIL` or `expected-fail`.
fn verdict(line: &str) -> Option<(&str, &str, &str)> {
    let rest = line.strip_prefix("scenario ")?;
    let (item, rest) = rest.split_once(": ")?;
    let (word, text) = rest.split_once(": ")?;
    Some((item, word, text))
}

/// P-219…P-227: the Example Function block's scenarios (enable, operating
/// modes, homing, positioning with appended records, relative, change
/// immediately, intermediate stop and hold, speed and torque control, jog,
/// PKW with a unit change (P-208), the parameter record (P-206), fault and
/// its reset, the position error limit PNU 1273 (P-160)) through profinet-py
/// against serve.
#[test]
fn p160_p206_p208_p219_p220_p221_p222_p223_p224_p225_p226_p227_the_example_function_block_through_profinet_py(
) {
    let Some(python) = common::or_skip(common::profinet_py_python(), "profinet-py FB test") else {
        return;
    };
    let dir = common::scratch("profinet-py");
    let mut line = PnLine::new("fb", &dir, &[]);
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/profinet/fb.py");
    let args = module_args(&["--control".as_ref(), line.control.as_os_str()]);
    let (status, lines) = line.run(&python, &script, &args, SCRIPT_LIMIT);
    line.stop_server();
    println!(
        "--- hil-sim serve ({}):\n{}",
        line.serve_log.display(),
        line.serve_output()
    );

    // appended to the profinet-py test's figures (which cargo runs first and
    // which rewrites the file); this test's own lines of an earlier run go
    let path = dir.join("figures.txt");
    let mut text: String = std::fs::read_to_string(&path)
        .unwrap_or_default()
        .lines()
        .filter(|l| !l.starts_with(FIGURE))
        .map(|l| format!("{l}\n"))
        .collect();
    for l in lines.iter().filter(|l| l.starts_with(FIGURE)) {
        text.push_str(l);
        text.push('\n');
    }
    std::fs::write(&path, text).expect("figures.txt");

    let mut failed = Vec::new();
    let mut expected = Vec::new();
    for item in SCENARIOS {
        let got: Vec<_> = lines
            .iter()
            .filter_map(|l| verdict(l))
            .filter(|(i, _, _)| *i == item)
            .collect();
        assert_eq!(got.len(), 1, "scenario {item}: one line expected, got {got:?}");
        let (_, word, text) = got[0];
        match word {
            "ok" => {}
            "expected-fail" => expected.push(format!("{item}: {text}")),
            _ => failed.push(format!("{item}: {word}: {text}")),
        }
    }
    println!("--- expected failures ({}):", expected.len());
    for e in &expected {
        println!("  {e}");
    }
    assert!(failed.is_empty(), "scenarios failed:\n{}", failed.join("\n"));
    assert!(status.success(), "fb.py failed ({status})");
}
