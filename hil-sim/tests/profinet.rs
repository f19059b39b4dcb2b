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
//!   sending; the cyclic AR in advanced startup (RTClass 2 IOCRs, FrameIDs
//!   0x8000–0xBBFF, as an S7-1500 connects; profinet-py's block builders
//!   wrapped for it), and one more Connect, PrmEnd, ApplicationReady,
//!   Release in advanced startup, in which a 4,068-byte record goes in
//!   DCE/RPC fragments (answered for its index) and a 4,069-byte one gets
//!   "write length error", and the PDev records TIA uses (PDPortDataCheck
//!   written and read back, PDRealData, PDPortStatistic) and an
//!   IODWriteMultiple with a bad sub-write answered with an error. The figure "DCP identify to first valid cyclic data" goes to
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

use common::pn_line::{module_args, PnLine};
use profinet::model;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// A script that has not finished after this long has hung.
const SCRIPT_LIMIT: Duration = Duration::from_secs(240);
/// Seconds of cyclic data exchange (at least 10).
const CYCLIC_SECONDS: &str = "12";
/// The name and IP the controller gives the device.
const NAME: &str = "drive-1";
/// Drives serve runs on the line (the controller talks to the first, finds
/// them all).
const DRIVES: u16 = 2;
/// The drive fault of step (i): event 44 "External fault 1", cause 1.
const FAULT_EVENT: u8 = 44;
const FAULT_CAUSE: u8 = 1;
const DEVICE_IP: &str = "192.168.0.50";

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
/// (cyclic data; legacy and advanced startup), P-110…P-114 and P-223 (the profile's telegram 1: the
/// enable sequence answered in ZSW1, a speed set-point seen in PNU 1101),
/// P-191 (a PKW read), P-030/P-035/P-085 (a drive fault as a diagnosis
/// alarm, acknowledged by CW1 bit 7), P-036 and Q-07 (the AR aborted when the
/// controller goes silent), all with profinet-py as the controller; every
/// frame of the device dissected by Wireshark without a warning.
#[test]
fn p008_p027_p029_p030_p035_p036_p040_p041_p042_p085_p110_p191_p223_profinet_py_names_connects_drives_and_loses_the_drive(
) {
    let Some(python) = common::or_skip(common::profinet_py_python(), "profinet-py test") else {
        return;
    };
    let dir = common::scratch("profinet-py");
    let pcap = dir.join("serve.pcap");
    let drives = DRIVES.to_string();
    let mut line = PnLine::new(
        "pn",
        &dir,
        &[
            "--slaves".as_ref(),
            drives.as_ref(),
            "--pcap".as_ref(),
            pcap.as_os_str(),
        ],
    );
    let vendor = format!("{:#06x}", model::VENDOR_ID);
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/profinet/controller.py");
    let (fault_event, fault_cause) = (FAULT_EVENT.to_string(), FAULT_CAUSE.to_string());
    let words = [
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
        &drives,
        "--motor",
        "--fault-event",
        &fault_event,
        "--fault-cause",
        &fault_cause,
        "--startup",
        "advanced",
    ];
    let args = module_args(&words);
    let (status, lines) = line.run(&python, &script, &args, SCRIPT_LIMIT);
    let ok = status.success();
    line.stop_server();
    let serve = line.serve_output();
    println!("--- hil-sim serve ({}):\n{serve}", line.serve_log.display());
    for step in ["a", "b", "c", "d", "e", "f", "g", "h", "i", "j", "k", "l", "m"] {
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
    // P-042: legacy startup (step e) and advanced startup (step k and the
    // cyclic AR of step h) both connect, with FrameIDs of their RTClass
    let e = step_lines(&lines, "e");
    assert!(e.iter().any(|l| l.contains("input FrameID 0xC")), "{e:?}");
    let k = step_lines(&lines, "k");
    assert!(
        k.iter()
            .any(|l| l.contains("output FrameID 0x81") && l.contains(&format!("station b'{NAME}'"))),
        "{k:?}"
    );
    assert!(
        lines
            .iter()
            .any(|l| l.contains("advanced startup: input FrameID 0x80")),
        "step h did not connect in advanced startup"
    );
    // P-041: records of MaxSupportedRecordSize in fragments
    let l = step_lines(&lines, "l");
    assert!(
        l.iter().any(|x| x.starts_with("ok: 4068-byte")) && l.iter().any(|x| x.starts_with("ok: 4069-byte")),
        "{l:?}"
    );
    // P-040, P-041: the PDev records and IODWriteMultiple's outer status (issue 32)
    let m = step_lines(&lines, "m");
    assert_eq!(m.iter().filter(|x| x.starts_with("ok: ")).count(), 4, "{m:?}");
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
