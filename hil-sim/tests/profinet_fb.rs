//! The Example Function block's scenarios P-219…P-227 through profinet-py
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

use common::ip;
use profinet::model::{DataModule, Direction};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A script that has not finished after this long has hung.
const SCRIPT_LIMIT: Duration = Duration::from_secs(150);
/// The controller's address (in its own namespace only).
const CONTROLLER_IP: &str = "192.168.0.10/24";
/// The figure lines of this test (fb.py prints them so).
const FIGURE: &str = "figure: P-2";
/// The scenarios, each reported once.
const SCENARIOS: [&str; 9] = [
    "P-219", "P-220", "P-221", "P-222", "P-223", "P-224", "P-225", "P-226", "P-227",
];

/// Two private namespaces joined by a veth pair, `serve --fieldbus
/// profinet --control FIFO` in one; removed on drop.
struct Line {
    ctl_ns: String,
    dev_ns: String,
    ctl_if: String,
    device_mac: String,
    server: Option<Child>,
    serve_log: PathBuf,
    control: PathBuf,
}

impl Line {
    fn new(dir: &Path) -> Self {
        let id = std::process::id() % 100_000;
        let mut line = Self {
            ctl_ns: format!("fbctl{id}"),
            dev_ns: format!("fbdev{id}"),
            ctl_if: format!("fb{id}c"),
            device_mac: String::new(),
            server: None,
            serve_log: dir.join("serve-fb.log"),
            control: dir.join("control-fb"),
        };
        let dev_if = format!("fb{id}d");
        let (c, d) = (line.ctl_ns.clone(), line.dev_ns.clone());
        for ns in [&c, &d] {
            let _ = Command::new("ip")
                .args(["netns", "del", ns])
                .stderr(Stdio::null())
                .status();
            ip(&["netns", "add", ns]);
            ip(&["-n", ns, "link", "set", "lo", "up"]);
        }
        ip(&[
            "link",
            "add",
            &line.ctl_if,
            "netns",
            &c,
            "type",
            "veth",
            "peer",
            "name",
            &dev_if,
            "netns",
            &d,
        ]);
        for (ns, ifc) in [(&c, &line.ctl_if), (&d, &dev_if)] {
            let _ = Command::new("ip")
                .args(["netns", "exec", ns, "sysctl", "-qw"])
                .arg(format!("net.ipv6.conf.{ifc}.disable_ipv6=1"))
                .status();
        }
        ip(&["-n", &c, "link", "set", &line.ctl_if, "up"]);
        ip(&["-n", &d, "link", "set", &dev_if, "up"]);
        ip(&["-n", &c, "addr", "add", CONTROLLER_IP, "dev", &line.ctl_if]);
        let mac = Command::new("ip")
            .args(["netns", "exec", &d, "cat"])
            .arg(format!("/sys/class/net/{dev_if}/address"))
            .output()
            .expect("read the device's MAC");
        line.device_mac = String::from_utf8_lossy(&mac.stdout).trim().to_string();
        let log = std::fs::File::create(&line.serve_log).expect("serve log");
        line.server = Some(
            Command::new("ip")
                .args(["netns", "exec", &d, env!("CARGO_BIN_EXE_hil-sim"), "serve"])
                .args(["--fieldbus", "profinet", "--iface", &dev_if])
                .arg("--control")
                .arg(&line.control)
                .stdout(log.try_clone().expect("log"))
                .stderr(log)
                .spawn()
                .expect("spawn hil-sim serve"),
        );
        let until = Instant::now() + Duration::from_secs(10);
        while !line.serve_output().contains("hil-sim serve:") {
            assert!(
                Instant::now() < until,
                "serve did not start:\n{}",
                line.serve_output()
            );
            std::thread::sleep(Duration::from_millis(50));
        }
        line
    }

    fn serve_output(&self) -> String {
        std::fs::read_to_string(&self.serve_log).unwrap_or_default()
    }

    fn stop_server(&mut self) {
        if let Some(s) = self.server.take() {
            common::stop_server(s, Duration::from_secs(5));
        }
    }
}

impl Drop for Line {
    fn drop(&mut self) {
        self.stop_server();
        for ns in [&self.ctl_ns, &self.dev_ns] {
            let _ = Command::new("ip")
                .args(["netns", "del", ns])
                .stderr(Stdio::null())
                .status();
        }
    }
}

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
/// PKW, fault and its reset) through profinet-py against serve.
#[test]
fn p219_p220_p221_p222_p223_p224_p225_p226_p227_the_example_function_block_through_profinet_py() {
    let python = match common::profinet_py_python() {
        Ok(p) => p,
        Err(why) => {
            eprintln!("profinet-py FB test: skipped, {why}");
            return;
        }
    };
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("profinet-py");
    std::fs::create_dir_all(&dir).expect("scratch dir");
    let mut line = Line::new(&dir);
    let gsdml = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../gsdml")
        .join(gsdml::file_name());
    let module = |direction, words| gsdml::module_id(DataModule { direction, words });
    let (out18, in18) = (module(Direction::FromDrive, 18), module(Direction::ToDrive, 18));
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/profinet/fb.py");
    let child = Command::new("ip")
        .args(["netns", "exec", &line.ctl_ns])
        .arg(&python)
        .arg("-u")
        .arg(&script)
        .args(["--iface", &line.ctl_if, "--device-mac", &line.device_mac])
        .arg("--gsdml")
        .arg(&gsdml)
        .args(["--out-module", &out18, "--in-module", &in18])
        .arg("--control")
        .arg(&line.control)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run fb.py");
    let (status, lines) = common::watch_script(child, &script, SCRIPT_LIMIT);
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
