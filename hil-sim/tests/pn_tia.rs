//! Our own controller on scapy (`tests/profinet/tia.py` with `tia_lib.py`;
//! PyPI `scapy` 2.8, GPL-2.0, a test tool only), not profinet-py, plays TIA
//! Portal's start-up of our GSDML against `hil-sim serve --fieldbus
//! profinet` over a veth pair between two private network namespaces: DCP
//! identify, set name and IP; the implicit read of I&M0 and 0xF000; Connect
//! in advanced startup (RTClass 2, FrameIDs 0x8000–0xBBFF) with the PDev
//! IODWriteMultiple TIA sends, PrmEnd, ApplicationReady; 10 s of cyclic data
//! with DataStatus, IOPS and IOCS checked; the records TIA reads online
//! (the diagnosis records among them); I&M1–4; a 4,068-byte record in RPC
//! fragments; alarm bursts acknowledged late (drive faults through serve's
//! control FIFO, port topology alarms); a second controller refused; a netload run (DCP, ARP, LLDP, RPC,
//! malformed UDP); Release; legacy startup; release/reconnect rounds; the
//! recording through tshark. `scripts/cross qemu-net` runs the same script
//! against the firmware image in QEMU.
//!
//! Needs root and scapy: `SCAPY_PYTHON` names a python that imports it
//! (`.ci/run` sets it to target/scapy-venv/bin/python). Without root or the
//! variable the test prints why and passes without running; a
//! `SCAPY_PYTHON` that cannot import scapy fails it.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::pn_line::{module_args, PnLine};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// A script that has not finished after this long has hung.
const SCRIPT_LIMIT: Duration = Duration::from_secs(300);

/// The python with scapy, or why the test cannot run.
fn scapy_python() -> Result<PathBuf, String> {
    common::peer_python(
        "SCAPY_PYTHON",
        "scapy",
        "import scapy; print(scapy.VERSION)",
        "scapy-venv",
    )
}

/// The steps' lines of the script: `step X: ok|FAIL|expected-fail: …`.
fn step_lines<'a>(lines: &'a [String], step: &str) -> Vec<&'a str> {
    let prefix = format!("step {step}: ");
    lines.iter().filter_map(|l| l.strip_prefix(&prefix)).collect()
}

/// P-002 (class B behaviour under netload), P-007/P-008/P-010 (DCP), P-039 (I&M0 implicit), P-026/P-027 and P-042
/// (Connect in advanced and legacy startup, PrmEnd, ApplicationReady,
/// cyclic data with IOPS/IOCS), P-040 (PDev records), P-041 (4,068-byte
/// records in fragments), P-043 (alarms acknowledged late), P-036 (a second
/// controller refused), netload; every frame of the device dissected by
/// Wireshark.
#[test]
fn p002_p026_p027_p040_p041_p042_p043_scapy_controller_plays_tia_startup() {
    let Some(python) = common::or_skip(scapy_python(), "scapy TIA test") else {
        return;
    };
    let dir = common::scratch("pn-tia");
    let pcap = dir.join("tia.pcap");
    let _ = std::fs::remove_file(&pcap);
    let mut line = PnLine::new("tia", &dir, &[]);
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/profinet/tia.py");
    let words = [
        "--cyclic-seconds",
        "10",
        "--netload-seconds",
        "10",
        "--control",
        line.control.to_str().unwrap(),
        "--pcap",
        pcap.to_str().unwrap(),
    ];
    let args = module_args(&words);
    let (status, lines) = line.run(&python, &script, &args, SCRIPT_LIMIT);
    line.stop_server();
    println!("--- hil-sim serve:\n{}", line.serve_output());
    for step in [
        "a", "b", "c", "d", "e", "f", "g", "h", "i", "j", "k", "l", "m", "n", "o", "w",
    ] {
        let got = step_lines(&lines, step);
        assert!(
            got.iter().any(|l| l.starts_with("ok: ")) && !got.iter().any(|l| l.starts_with("FAIL: ")),
            "step {step} did not pass: {got:?}"
        );
    }
    assert!(status.success(), "tia.py failed");
    let e = step_lines(&lines, "e");
    assert!(
        e.iter()
            .any(|l| l.contains("advanced startup Connect: input FrameID 0x8")),
        "{e:?}"
    );
    let n = step_lines(&lines, "n");
    assert!(
        n.iter()
            .any(|l| l.contains("legacy startup Connect: input FrameID 0xC")),
        "{n:?}"
    );
    let k = step_lines(&lines, "k");
    assert!(k.iter().any(|l| l.contains("0xDB814004")), "{k:?}");
    assert!(pcap.exists(), "no recording");
}
