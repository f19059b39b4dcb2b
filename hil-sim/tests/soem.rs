//! SOEM, the most used open-source EtherCAT master (C), as a second real
//! master next to ethercrab: pysoem (PyPI; it builds SOEM's sources) drives
//! `hil-sim serve` over a veth pair between two private network namespaces.
//!
//! - the master's namespace holds one end of the veth pair and runs the
//!   Python scripts in `hil-sim/tests/soem/` with the venv's python;
//! - the simulator's namespace holds the other end and runs
//!   `hil-sim serve --iface … --slaves 3`.
//!
//! The expected values come from the drive's own declarations: the SII image
//! `ecat::build_sii(&drive::DEVICE, …)` and the objects a fresh dictionary
//! shows, written to files the scripts compare SOEM's readings with.
//!
//! Needs root (network namespaces, raw sockets) and pysoem: `PYSOEM_PYTHON`
//! names a python that imports it (`.ci/run` installs it into
//! `target/pysoem-venv` and sets the variable). Without root or without the
//! variable the tests print why and pass without running; a `PYSOEM_PYTHON`
//! that cannot import pysoem fails them.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::ip;
use ecat::Dictionary;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::Mutex;
use std::time::Duration;

/// One SOEM run at a time: each needs the cores for its 1 ms cycle.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// Drives on the line.
const SLAVES: usize = 3;
/// Process data in Op, s (at least 10 s of 1 ms cycles).
const OP_SECONDS: u32 = 12;
/// A script that has not finished after this long has hung.
const SCRIPT_LIMIT: Duration = Duration::from_secs(240);

/// The python with pysoem, or why the test cannot run (not root, or
/// `PYSOEM_PYTHON` not set). A `PYSOEM_PYTHON` that cannot import pysoem is
/// a failure, not a skip: whoever set it wants the test to run.
fn pysoem_python() -> Result<PathBuf, String> {
    if !common::is_root() {
        return Err("needs root for network namespaces and raw sockets".into());
    }
    let py = std::env::var_os("PYSOEM_PYTHON").ok_or(
        "PYSOEM_PYTHON is not set (`.ci/run` installs pysoem into target/pysoem-venv and sets it to \
         target/pysoem-venv/bin/python)",
    )?;
    let out = Command::new(&py)
        .args(["-c", "import pysoem; print(pysoem.__version__)"])
        .output()
        .unwrap_or_else(|e| panic!("PYSOEM_PYTHON={}: {e}", Path::new(&py).display()));
    assert!(
        out.status.success(),
        "PYSOEM_PYTHON={} cannot import pysoem: {}",
        Path::new(&py).display(),
        String::from_utf8_lossy(&out.stderr).trim()
    );
    println!(
        "pysoem {} ({})",
        String::from_utf8_lossy(&out.stdout).trim(),
        Path::new(&py).display()
    );
    Ok(PathBuf::from(py))
}

/// SCHED_FIFO priority of `serve`: the simulated drives stand for hardware
/// (an ESC and an MCU of their own), so `serve` gets the CPU before the
/// compile jobs of a shared machine do (a descheduled `serve` still sees
/// each frame at its kernel receive time, but answers it late). The master
/// runs at SCHED_FIFO 40 as SOEM's samples do (the script sets it).
const SERVE_PRIORITY: &str = "50";

/// Two private namespaces joined by a veth pair, `hil-sim serve` in one.
struct Line {
    master_ns: String,
    sim_ns: String,
    master_if: String,
    server: Option<Child>,
    serve_log: PathBuf,
}

impl Line {
    fn new(tag: &str, slaves: usize, seconds: u32, dir: &Path) -> Self {
        let id = std::process::id() % 100_000;
        let master_ns = format!("soem{tag}{id}m");
        let sim_ns = format!("soem{tag}{id}s");
        let master_if = format!("so{tag}{id}m");
        let sim_if = format!("so{tag}{id}s");
        for ns in [&master_ns, &sim_ns] {
            let _ = Command::new("ip")
                .args(["netns", "del", ns])
                .stderr(Stdio::null())
                .status();
            ip(&["netns", "add", ns]);
            ip(&["-n", ns, "link", "set", "lo", "up"]);
        }
        ip(&[
            "link", "add", &master_if, "netns", &master_ns, "type", "veth", "peer", "name", &sim_if, "netns",
            &sim_ns,
        ]);
        ip(&["-n", &master_ns, "link", "set", &master_if, "up"]);
        ip(&["-n", &sim_ns, "link", "set", &sim_if, "up"]);
        let serve_log = dir.join(format!("serve-{tag}.log"));
        // SOEM_PCAP=1: serve records every frame (for a failure's evidence)
        let pcap = std::env::var_os("SOEM_PCAP").map(|_| dir.join(format!("serve-{tag}.pcap")));
        let log = std::fs::File::create(&serve_log).expect("serve log");
        let server = Command::new("ip")
            .args(["netns", "exec", &sim_ns, env!("CARGO_BIN_EXE_hil-sim"), "serve"])
            .args(["--fifo-priority", SERVE_PRIORITY])
            .args(["--iface", &sim_if, "--slaves", &slaves.to_string()])
            .args(["--seconds", &seconds.to_string()])
            .args(
                pcap.iter()
                    .flat_map(|p| [std::ffi::OsStr::new("--pcap"), p.as_os_str()]),
            )
            .stdout(log.try_clone().expect("log"))
            .stderr(log)
            .spawn()
            .expect("spawn hil-sim serve");
        // serve opens its socket at once; the script's scan retries as well
        std::thread::sleep(Duration::from_millis(300));
        Self {
            master_ns,
            sim_ns,
            master_if,
            server: Some(server),
            serve_log,
        }
    }

    /// Runs `python script args` in the master's namespace; its output is
    /// printed as it comes, the exit status returned (killed after
    /// [`SCRIPT_LIMIT`]).
    fn run(&self, python: &Path, script: &str, args: &[&str]) -> ExitStatus {
        let script = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/soem")
            .join(script);
        let child = Command::new("ip")
            .args(["netns", "exec", &self.master_ns])
            .arg(python)
            .arg("-u")
            .arg(&script)
            .args(["--iface", &self.master_if])
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("run the script");
        // print line by line (println! goes through the test harness's capture)
        common::watch_script(child, &script, SCRIPT_LIMIT).0
    }

    /// What `serve` printed (state changes of every drive, with AL codes).
    fn serve_output(&self) -> String {
        std::fs::read_to_string(&self.serve_log).unwrap_or_default()
    }
}

impl Drop for Line {
    fn drop(&mut self) {
        if let Some(s) = self.server.take() {
            common::stop_server(s, Duration::from_secs(2));
        }
        // deleting the namespaces deletes the veth pair
        for ns in [&self.master_ns, &self.sim_ns] {
            let _ = Command::new("ip").args(["netns", "del", ns]).status();
        }
    }
}

/// The SII image the simulated drives carry.
fn sii_image() -> Vec<u8> {
    let mut sii = vec![0u8; ecat::sii::EEPROM_BYTES];
    ecat::build_sii(&drive::DEVICE, &mut sii).expect("SII");
    sii
}

/// The objects a fresh drive shows through SDO Info (the "EtherCAT Rx SDO
/// Info" template, the default access level), one line per object and entry:
/// `obj index code max_sub data_type|- name` and `ent index sub data_type
/// bits access default name`, tab-separated, numbers in hex except code,
/// max_sub, bits and default. The object's data type is given for VAR and
/// ARRAY objects (the type of their entries).
fn od_listing() -> String {
    let dict = drive::DriveObjects::default();
    let mut out = String::new();
    let mut after = None;
    while let Some(o) = dict.next_object(after) {
        after = Some(o.index);
        let dtype = match o.code.code() {
            7 => o.entry(0).map(|e| format!("{:04x}", e.data_type.code())),
            8 => o
                .entries
                .iter()
                .find(|e| e.sub >= 1)
                .map(|e| format!("{:04x}", e.data_type.code())),
            _ => None,
        };
        let dtype = dtype.unwrap_or_else(|| "-".into());
        writeln!(
            out,
            "obj\t{:04x}\t{}\t{}\t{dtype}\t{}",
            o.index,
            o.code.code(),
            o.max_sub(),
            o.name
        )
        .unwrap();
        for e in o.entries {
            writeln!(
                out,
                "ent\t{:04x}\t{:02x}\t{:04x}\t{}\t{:04x}\t{}\t{}",
                o.index,
                e.sub,
                e.data_type.code(),
                e.bit_len(),
                e.access.0,
                e.default,
                e.name
            )
            .unwrap();
        }
    }
    out
}

/// A scratch directory for one test's files.
fn scratch(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(test);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

fn fail_with(line: &Line, what: &str) -> ! {
    let serve = line.serve_output();
    let tail: Vec<&str> = serve.lines().rev().take(60).collect();
    let tail: Vec<&str> = tail.into_iter().rev().collect();
    panic!(
        "{what}\n--- hil-sim serve ({}), last lines:\n{}\n(SOEM_PCAP=1 records serve's frames next to its log)",
        line.serve_log.display(),
        tail.join("\n")
    );
}

/// SOEM on a line of 3 drives: scan, identity (1000h, 1018h, the SII's
/// identity and name) and the SII read back through SOEM byte for byte
/// (E-002, E-004, E-005, E-151); the object list and every object and entry
/// description through SDO Info (E-080, E-082); the default PDO assignment
/// and mappings (E-048, E-049, E-054); refused SDOs with their abort codes
/// (E-071, E-072); a different mapping and assignment written in Pre-Op and
/// taken over by SOEM's config_map (a part of E-056); the Pre-Op → Safe-Op refusals
/// 001Dh/001Eh (E-045, E-057, with EMCY A000h, E-028) and 0035h/0036h for
/// SYNC0 cycles off the 250 µs grid or not k × A150 (E-029); DC SYNC0 at 1 ms
/// with the master aligned to the reference clock (E-107), Safe-Op, Op
/// (E-021); per drive axis A and axis B (E-015) through the CiA 402 enable
/// sequence, a one-revolution csp move and a disable (E-034); 12 s of process
/// data in Op, the cycles with a wrong working counter printed.
#[test]
fn e002_e005_e080_e082_e045_e029_e015_soem_line_scan_sdo_info_pdo_dc_cia402() {
    let python = match pysoem_python() {
        Ok(p) => p,
        Err(why) => {
            eprintln!("soem line test: skipped, {why}");
            return;
        }
    };
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let dir = scratch("soem-line");
    let sii = dir.join("sii.bin");
    let od = dir.join("od.tsv");
    std::fs::write(&sii, sii_image()).unwrap();
    std::fs::write(&od, od_listing()).unwrap();
    let line = Line::new("l", SLAVES, 200, &dir);
    let status = line.run(
        &python,
        "line.py",
        &[
            "--slaves",
            &SLAVES.to_string(),
            "--sii",
            sii.to_str().unwrap(),
            "--od",
            od.to_str().unwrap(),
            "--seconds",
            &OP_SECONDS.to_string(),
        ],
    );
    if !status.success() {
        fail_with(&line, &format!("line.py through SOEM failed: {status}"));
    }
}

/// EoE through SOEM as a user would (pysoem has no EoE call; the script uses
/// its register access for SOEM's mailbox and EoE functions): on a line of 3
/// drives nothing is in the send mailbox before the master used EoE (E-098);
/// SOEM's exact set-IP request bytes (packed, addresses as little-endian
/// UINT32) answered with result 0 (E-096); a Linux TAP in the master's
/// namespace bridged to the drives' EoE with SOEM's fragmentation, and from
/// that namespace `ping` (also 1200-byte pings, fragmented both ways) and
/// the UDP parameter service (port 5011) of every drive (E-095).
#[test]
fn e096_e095_e098_soem_set_ip_ping_and_udp_through_a_tap_bridge() {
    let python = match pysoem_python() {
        Ok(p) => p,
        Err(why) => {
            eprintln!("soem EoE test: skipped, {why}");
            return;
        }
    };
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let dir = scratch("soem-eoe");
    // A166 "IP address reference" as a fresh drive declares it (the UDP read's answer)
    let a166 = drive::DriveObjects::default()
        .object(drive::parameter_index(0, 166))
        .and_then(|o| o.entry(0))
        .expect("A166")
        .default;
    let line = Line::new("e", SLAVES, 200, &dir);
    let status = line.run(
        &python,
        "eoe.py",
        &["--slaves", &SLAVES.to_string(), "--a166", &a166.to_string()],
    );
    if !status.success() {
        fail_with(&line, &format!("eoe.py through SOEM failed: {status}"));
    }
}

/// The firmware update as SOEM's `firm_update` sample does it (Init, the
/// bootstrap mailbox from the SII, Bootstrap, `ecx_FOEwrite`, Init) with the
/// update file of `tools/foe-image` (docs/flashing.md): a bit-flipped and a
/// truncated file are refused (SOEM reports the FoE error answer as −5), a
/// name that does not start with `firmware` gets 8001h (−10), the tool's
/// file is taken, and the drive returns to Pre-Op. (That the file lands in
/// the inactive slot and boots is checked in-process, where the slots can be
/// seen: `tools/foe-image/tests/round_trip.rs`.)
#[test]
fn foe_image_through_soem_firm_update() {
    let python = match pysoem_python() {
        Ok(p) => p,
        Err(why) => {
            eprintln!("soem FoE test: skipped, {why}");
            return;
        }
    };
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let dir = scratch("soem-foe");
    let body: Vec<u8> = (0..64 * 1024u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 24) as u8)
        .collect();
    // signed with the development key for slot A, where `serve`'s empty
    // drive downloads to (issue 18)
    let seed = drive::boot::parse_key_hex(include_str!("../../keys/dev-ed25519.key")).unwrap();
    let info = foe_image::ImageInfo {
        version: 2,
        load_address: hil_sim::sim::FirmwareSlots::new(hil_sim::sim::FirmwareFlash::new())
            .load_address(drive::boot::Slot::A),
        security_counter: 1,
    };
    let good = foe_image::update_file(&body, info, &seed).unwrap();
    let mut flipped = good.clone();
    flipped[drive::boot::IMAGE_HEADER_LEN + 20_000] ^= 0x04;
    let truncated = good[..good.len() - 100].to_vec();
    let path = |name: &str| dir.join(name);
    for (name, data) in [("good", &good), ("flipped", &flipped), ("truncated", &truncated)] {
        std::fs::write(path(name), data).unwrap();
    }
    let line = Line::new("f", 1, 120, &dir);
    let arg = |name: &str| path(name).to_str().unwrap().to_string();
    let (g, f, t) = (arg("good"), arg("flipped"), arg("truncated"));
    let status = line.run(
        &python,
        "foe.py",
        &["--good", &g, "--flipped", &f, "--truncated", &t],
    );
    if !status.success() {
        fail_with(&line, &format!("foe.py through SOEM failed: {status}"));
    }
}
