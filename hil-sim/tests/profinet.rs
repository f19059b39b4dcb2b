//! profinet-py (PyPI, 0.6.6), an independent PROFINET IO controller, drives
//! `hil-sim serve --fieldbus profinet` over a veth pair between two private
//! network namespaces (controller and device both bind UDP 34964):
//!
//! - the device's namespace holds one end and runs `serve --fieldbus
//!   profinet --pcap …`;
//! - the controller's namespace holds the other end (192.168.0.10/24) and
//!   runs `tests/profinet/controller.py`: DCP Identify All (the unnamed
//!   drive by its MAC), DCP Set name and IP (permanent), Identify by name,
//!   I&M0 through an RPC read, Connect with the GSDML's DAP and the manual's
//!   example modules, PrmEnd, ApplicationReady, Release, a Connect with a wrong
//!   module (ModuleDiff), ≥ 10 s of cyclic data at 1 ms through the PROFIdrive
//!   profile (telegram 1: the enable sequence in CW1/ZSW1, 100 rpm, a PKW
//!   read), a drive fault (raised through serve's control channel) as
//!   a diagnosis alarm that profinet-py acknowledges and that disappears
//!   after the fault reset, and the AR's abort when the controller stops
//!   sending. The figure "DCP identify to first valid cyclic data" goes to
//!   `target/tmp/profinet-py/figures.txt` (`.ci/run` prints it).
//!
//! The test asserts on the script's step lines and on the events `serve`
//! prints, then dissects `serve`'s recording with tshark: no malformed
//! frame and no expert warning from the device, and the protocol histogram.
//!
//! Needs root (namespaces, raw sockets) and profinet-py: `PROFINET_PY_PYTHON`
//! names a python that imports it (`.ci/run` sets it to
//! target/profinet-venv/bin/python). Without root or without the variable
//! the test prints why and passes without running; a `PROFINET_PY_PYTHON`
//! that cannot import profinet fails it.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::ip;
use profinet::model::{self, DataModule, Direction};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A script that has not finished after this long has hung.
const SCRIPT_LIMIT: Duration = Duration::from_secs(240);
/// Seconds of cyclic data exchange (at least 10).
const CYCLIC_SECONDS: &str = "12";
/// The controller's address (in its own namespace only).
const CONTROLLER_IP: &str = "192.168.0.10/24";
/// The name and IP the controller gives the device.
const NAME: &str = "drive-1";
/// Drives serve runs on the line (the controller talks to the first, finds
/// them all).
const DRIVES: u16 = 2;
/// The drive fault of step (i): event 44 "External fault 1", cause 1.
const FAULT_EVENT: u8 = 44;
const FAULT_CAUSE: u8 = 1;
const DEVICE_IP: &str = "192.168.0.50";

/// The python with profinet-py, or why the test cannot run.
fn profinet_py_python() -> Result<PathBuf, String> {
    if !common::is_root() {
        return Err("needs root for network namespaces and raw sockets".into());
    }
    let py = std::env::var_os("PROFINET_PY_PYTHON").ok_or(
        "PROFINET_PY_PYTHON is not set (`.ci/run` installs profinet-py into target/profinet-venv and sets \
         it to target/profinet-venv/bin/python; locally e.g. /tmp/pnvenv/bin/python)",
    )?;
    let show = Path::new(&py).display().to_string();
    let out = Command::new(&py)
        .args(["-c", "import profinet; print(profinet.__version__)"])
        .output()
        .unwrap_or_else(|e| panic!("PROFINET_PY_PYTHON={show}: {e}"));
    assert!(
        out.status.success(),
        "PROFINET_PY_PYTHON={show} cannot import profinet: {}",
        String::from_utf8_lossy(&out.stderr).trim()
    );
    println!(
        "profinet-py {} ({show})",
        String::from_utf8_lossy(&out.stdout).trim()
    );
    Ok(PathBuf::from(py))
}

/// Runs `cmd`, returning its stdout; fails the test if it fails.
fn output(cmd: &mut Command) -> String {
    let out = cmd.output().unwrap_or_else(|e| panic!("{cmd:?}: {e}"));
    assert!(
        out.status.success(),
        "{cmd:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Two private namespaces joined by a veth pair, `serve --fieldbus profinet`
/// in one. Everything is removed on drop (also when the test fails).
struct Line {
    ctl_ns: String,
    dev_ns: String,
    ctl_if: String,
    device_mac: String,
    server: Option<Child>,
    serve_log: PathBuf,
    /// serve's control FIFO (`--control`).
    control: PathBuf,
}

impl Line {
    fn new(dir: &Path, pcap: &Path) -> Self {
        let id = std::process::id() % 100_000;
        let ctl_ns = format!("pnctl{id}");
        let dev_ns = format!("pndev{id}");
        let ctl_if = format!("pn{id}c");
        let dev_if = format!("pn{id}d");
        for ns in [&ctl_ns, &dev_ns] {
            let _ = Command::new("ip")
                .args(["netns", "del", ns])
                .stderr(Stdio::null())
                .status();
        }
        // from here on Drop cleans up whatever was made
        let mut line = Self {
            ctl_ns,
            dev_ns,
            ctl_if,
            device_mac: String::new(),
            server: None,
            serve_log: dir.join("serve.log"),
            control: dir.join("control"),
        };
        let (c, d) = (line.ctl_ns.clone(), line.dev_ns.clone());
        for ns in [&c, &d] {
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
        // no IPv6 chatter from either kernel in the recording
        for (ns, ifc) in [(&c, &line.ctl_if), (&d, &dev_if)] {
            let _ = Command::new("ip")
                .args(["netns", "exec", ns, "sysctl", "-qw"])
                .arg(format!("net.ipv6.conf.{ifc}.disable_ipv6=1"))
                .status();
        }
        ip(&["-n", &c, "link", "set", &line.ctl_if, "up"]);
        ip(&["-n", &d, "link", "set", &dev_if, "up"]);
        ip(&["-n", &c, "addr", "add", CONTROLLER_IP, "dev", &line.ctl_if]);
        line.device_mac = output(
            Command::new("ip")
                .args(["netns", "exec", &d, "cat"])
                .arg(format!("/sys/class/net/{dev_if}/address")),
        )
        .trim()
        .to_string();
        let log = std::fs::File::create(&line.serve_log).expect("serve log");
        line.server = Some(
            Command::new("ip")
                .args(["netns", "exec", &d, env!("CARGO_BIN_EXE_hil-sim"), "serve"])
                .args(["--fieldbus", "profinet", "--iface", &dev_if])
                .args(["--slaves", &DRIVES.to_string()])
                .arg("--pcap")
                .arg(pcap)
                .arg("--control")
                .arg(&line.control)
                .stdout(log.try_clone().expect("log"))
                .stderr(log)
                .spawn()
                .expect("spawn hil-sim serve"),
        );
        // serve prints its first line once its socket is open
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

    /// Runs the controller script in the controller's namespace; its lines
    /// are printed as they come and returned with the exit status.
    fn run(&self, python: &Path, args: &[&str]) -> (bool, Vec<String>) {
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/profinet/controller.py");
        let child = Command::new("ip")
            .args(["netns", "exec", &self.ctl_ns])
            .arg(python)
            .arg("-u")
            .arg(&script)
            .args(["--iface", &self.ctl_if, "--device-mac", &self.device_mac])
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("run the script");
        let (status, lines) = common::watch_script(child, &script, SCRIPT_LIMIT);
        (status.success(), lines)
    }

    /// Stops serve (SIGTERM: it flushes the recording and prints its
    /// summary).
    fn stop_server(&mut self) {
        if let Some(s) = self.server.take() {
            common::stop_server(s, Duration::from_secs(5));
        }
    }

    fn serve_output(&self) -> String {
        std::fs::read_to_string(&self.serve_log).unwrap_or_default()
    }
}

impl Drop for Line {
    fn drop(&mut self) {
        self.stop_server();
        // deleting the namespaces deletes the veth pair and the address
        for ns in [&self.ctl_ns, &self.dev_ns] {
            let _ = Command::new("ip")
                .args(["netns", "del", ns])
                .stderr(Stdio::null())
                .status();
        }
    }
}

/// tshark on `pcap` with `args`; its stdout (the "running as root" note on
/// stderr is dropped).
fn tshark(pcap: &Path, args: &[&str]) -> String {
    let out = Command::new("tshark")
        .arg("-r")
        .arg(pcap)
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("tshark (apt tshark) is needed to dissect the recording: {e}"));
    assert!(
        out.status.success(),
        "tshark {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The steps' lines of the script: `step X: ok|FAIL|expected-fail: …`.
fn step_lines<'a>(lines: &'a [String], step: &str) -> Vec<&'a str> {
    let prefix = format!("step {step}: ");
    lines.iter().filter_map(|l| l.strip_prefix(&prefix)).collect()
}

/// P-008 (Identify), P-007/P-010 (DCP Set name and IP), P-039 (I&M0), P-027
/// (Connect, PrmEnd, ApplicationReady, Release), P-029 (ModuleDiff), P-042
/// (cyclic data), P-110…P-114 and P-223 (the profile's telegram 1: the
/// enable sequence answered in ZSW1, a speed set-point seen in PNU 1101),
/// P-191 (a PKW read), P-030/P-035/P-085 (a drive fault as a diagnosis
/// alarm, acknowledged by CW1 bit 7), P-036 and Q-07 (the AR aborted when the
/// controller goes silent), all with profinet-py as the controller; every
/// frame of the device dissected by Wireshark without a warning.
#[test]
fn p008_p027_p029_p030_p035_p036_p042_p085_p110_p191_p223_profinet_py_names_connects_drives_and_loses_the_drive(
) {
    let python = match profinet_py_python() {
        Ok(p) => p,
        Err(why) => {
            eprintln!("profinet-py test: skipped, {why}");
            return;
        }
    };
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("profinet-py");
    std::fs::create_dir_all(&dir).expect("scratch dir");
    let pcap = dir.join("serve.pcap");
    let mut line = Line::new(&dir, &pcap);
    let gsdml = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../gsdml")
        .join(gsdml::file_name());
    let module = |direction, words| gsdml::module_id(DataModule { direction, words });
    // the manual's example: slot 1 "18 Word Output Data", slot 2 "18 Word Input Data"
    let (out18, in18) = (module(Direction::FromDrive, 18), module(Direction::ToDrive, 18));
    let vendor = format!("{:#06x}", model::VENDOR_ID);
    let (ok, lines) = line.run(
        &python,
        &[
            "--gsdml",
            gsdml.to_str().unwrap(),
            "--out-module",
            &out18,
            "--in-module",
            &in18,
            "--vendor-id",
            &vendor,
            "--order",
            model::ORDER_NUMBER,
            "--name",
            NAME,
            "--ip",
            DEVICE_IP,
            "--cyclic-seconds",
            CYCLIC_SECONDS,
            "--control",
            line.control.to_str().unwrap(),
            "--drives",
            &DRIVES.to_string(),
            "--motor",
            "--fault-event",
            &FAULT_EVENT.to_string(),
            "--fault-cause",
            &FAULT_CAUSE.to_string(),
        ],
    );
    line.stop_server();
    let serve = line.serve_output();
    println!("--- hil-sim serve ({}):\n{serve}", line.serve_log.display());
    for step in ["a", "b", "c", "d", "e", "f", "g", "h", "i", "j"] {
        let got = step_lines(&lines, step);
        assert!(
            got.iter().any(|l| l.starts_with("ok: ")) && !got.iter().any(|l| l.starts_with("FAIL: ")),
            "step {step} did not pass: {got:?}"
        );
    }
    assert!(ok, "controller.py failed");
    // the figures, for .ci/run to print after the tests
    let figures: Vec<&str> = lines.iter().filter_map(|l| l.strip_prefix("figure: ")).collect();
    assert!(!figures.is_empty(), "controller.py printed no figure");
    let text: String = figures.iter().map(|f| format!("figure: {f}\n")).collect();
    std::fs::write(dir.join("figures.txt"), &text).expect("figures.txt");
    print!("{text}");
    let a = step_lines(&lines, "a");
    assert!(
        a.iter()
            .any(|l| l.contains(&line.device_mac) && l.contains("name ''") && l.contains("ip 0.0.0.0")),
        "{a:?}"
    );
    let d = step_lines(&lines, "d");
    assert!(
        d.iter()
            .any(|l| l.contains(&format!("vendor 0x{:04X}", model::VENDOR_ID))
                && l.contains(&format!("order '{}'", model::ORDER_NUMBER))),
        "{d:?}"
    );
    for want in [
        format!("DCP name of station \"{NAME}\" (permanent)"),
        format!("DCP IP {DEVICE_IP} mask 255.255.255.0 gateway 0.0.0.0 (permanent)"),
        ": connected".into(),
        ": PrmEnd".into(),
        ": ready (ApplicationReady confirmed)".into(),
        ": released".into(),
        ": cyclic data exchanged".into(),
        ": lost (cyclic watchdog or alarm channel)".into(),
        ": aborted (Local)".into(),
        format!("axis A: event {FAULT_EVENT} cause {FAULT_CAUSE} raised"),
        "diagnosis appears: axis A Fault".into(),
        "diagnosis disappears:".into(),
        "alarms: 2 sent, 2 acknowledged".into(),
        "device counters:".into(),
    ] {
        assert!(serve.contains(&want), "serve did not print `{want}`");
    }

    // Wireshark's view of the recording
    let filter = format!(
        "eth.src == {} && (_ws.malformed || _ws.expert.severity >= warning)",
        line.device_mac
    );
    let device_warnings = tshark(&pcap, &["-Y", &filter]);
    let all_warnings = tshark(&pcap, &["-Y", "_ws.malformed || _ws.expert.severity >= warning"]);
    println!("--- tshark: malformed or warnings, all sources:\n{all_warnings}");
    assert!(
        device_warnings.trim().is_empty(),
        "frames from the device that Wireshark flags:\n{device_warnings}"
    );
    // every captured frame, the controller's too, dissects without a malformed packet
    let malformed = tshark(&pcap, &["-Y", "_ws.malformed"]);
    assert!(
        malformed.trim().is_empty(),
        "malformed frames in the recording:\n{malformed}"
    );
    let protocols = tshark(&pcap, &["-T", "fields", "-e", "frame.protocols"]);
    let mut histogram = std::collections::BTreeMap::<&str, usize>::new();
    for p in protocols.lines() {
        *histogram.entry(p).or_default() += 1;
    }
    println!("--- tshark: protocol histogram of {}:", pcap.display());
    for (p, n) in &histogram {
        println!("{n:>7} {p}");
    }
    for want in ["pn_dcp", "dcerpc", "pn_io", "lldp", "pn_rt"] {
        assert!(
            histogram.keys().any(|p| p.split(':').any(|x| x == want)),
            "no {want} frame in the recording"
        );
    }
}
