//! net-snmp (Debian package `snmp`) reads and writes the SNMP agent of
//! `hil-sim serve --fieldbus profinet` over a veth pair (spec P-038): the
//! device gets its IP by DCP Set (tests/snmp/dcp_set_ip.py, plain sockets),
//! then `snmpwalk` of system, interfaces and LLDP-MIB, `snmpget`, `snmpset`
//! of sysName/sysContact/sysLocation that are still there after the device
//! restarts (serve's `restart` command: powered on again over the same
//! parameter flash), and a set with the read community that is refused.
//! Numeric OIDs only (`-m ''`: no MIB files needed).
//!
//! Needs root (namespaces, raw sockets) and net-snmp's tools; without them
//! the test prints why and passes without running.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::pn_line::PnLine;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

const DEVICE_IP: &str = "192.168.0.50";

/// A net-snmp tool run in the controller's namespace: (success, stdout + stderr).
fn snmp(line: &PnLine, tool: &str, args: &[&str]) -> (bool, String) {
    let out = Command::new("ip")
        .args(["netns", "exec", &line.ctl_ns, tool])
        .args(["-m", "", "-On", "-t", "1", "-r", "1"])
        .args(args)
        .output()
        .expect("run net-snmp");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.success(), text)
}

fn v2c<'a>(community: &'a str, rest: &[&'a str]) -> Vec<&'a str> {
    let mut v = vec!["-v2c", "-c", community, DEVICE_IP];
    v.extend_from_slice(rest);
    v
}

/// Writes one command into serve's control FIFO and waits for `expect` in its output.
fn control(line: &PnLine, command: &str, expect: &str) {
    std::fs::write(&line.control, format!("{command}\n")).expect("control FIFO");
    let until = Instant::now() + Duration::from_secs(5);
    while !line.serve_output().contains(expect) {
        assert!(
            Instant::now() < until,
            "serve did not {command}:\n{}",
            line.serve_output()
        );
        std::thread::sleep(Duration::from_millis(50));
    }
}

#[test]
fn p038_net_snmp_walks_gets_and_sets_the_agent_and_the_settings_survive_a_restart() {
    if !common::is_root() {
        eprintln!("snmp test: skipped, needs root");
        return;
    }
    if Command::new("snmpget").arg("--version").output().is_err() {
        eprintln!("snmp test: skipped, net-snmp's tools are missing (apt-get install snmp)");
        return;
    }
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("snmp");
    std::fs::create_dir_all(&dir).expect("scratch dir");
    let line = PnLine::new("sn", &dir, &[]);
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/snmp/dcp_set_ip.py");
    let dcp = Command::new("ip")
        .args(["netns", "exec", &line.ctl_ns, "python3"])
        .arg(&script)
        .args([&line.ctl_if, &line.device_mac, DEVICE_IP])
        .output()
        .expect("python3");
    assert!(
        dcp.status.success(),
        "DCP Set IP: {}",
        String::from_utf8_lossy(&dcp.stdout)
    );

    // system: sysDescr … sysServices, sysUpTime as Timeticks
    let (ok, walk) = snmp(&line, "snmpwalk", &v2c("public", &[".1.3.6.1.2.1.1"]));
    assert!(ok, "{walk}");
    for o in 1..=7 {
        assert!(
            walk.contains(&format!(".1.3.6.1.2.1.1.{o}.0 = ")),
            "sysObject {o} missing:\n{walk}"
        );
    }
    assert!(walk.contains(".1.3.6.1.2.1.1.3.0 = Timeticks:"), "{walk}");
    // interfaces: ifNumber 3, ifDescr of the interface and both ports
    let (ok, walk) = snmp(&line, "snmpwalk", &v2c("public", &[".1.3.6.1.2.1.2"]));
    assert!(ok, "{walk}");
    assert!(walk.contains(".1.3.6.1.2.1.2.1.0 = INTEGER: 3"), "{walk}");
    for (i, d) in [(1, "PROFINET interface"), (2, "port-001"), (3, "port-002")] {
        assert!(
            walk.contains(&format!(".1.3.6.1.2.1.2.2.1.2.{i} = STRING: \"{d}\"")),
            "{walk}"
        );
    }
    // LLDP-MIB: chassis ID is the interface MAC, the local port table names both ports
    let (ok, walk) = snmp(&line, "snmpwalk", &v2c("public", &[".1.0.8802.1.1.2"]));
    assert!(ok, "{walk}");
    assert!(walk.contains(".1.0.8802.1.1.2.1.3.1.0 = INTEGER: 4"), "{walk}");
    let mac_hex = line.device_mac.replace(':', " ").to_uppercase();
    assert!(walk.contains(&mac_hex), "lldpLocChassisId {mac_hex}:\n{walk}");
    assert!(
        walk.contains(".1.0.8802.1.1.2.1.3.7.1.3.2 = STRING: \"port-002\""),
        "{walk}"
    );

    // set the three writable strings with the write community
    let (ok, out) = snmp(
        &line,
        "snmpset",
        &v2c(
            "private",
            &[
                ".1.3.6.1.2.1.1.4.0",
                "s",
                "ops@plant",
                ".1.3.6.1.2.1.1.5.0",
                "s",
                "axis-7",
                ".1.3.6.1.2.1.1.6.0",
                "s",
                "hall 3",
            ],
        ),
    );
    assert!(ok, "{out}");
    // read-only object: notWritable, nothing changes
    let (ok, out) = snmp(
        &line,
        "snmpset",
        &v2c("private", &[".1.3.6.1.2.1.1.1.0", "s", "x"]),
    );
    assert!(!ok && out.contains("notWritable"), "{out}");
    // the read community cannot set: no answer
    let (ok, out) = snmp(
        &line,
        "snmpset",
        &v2c("public", &[".1.3.6.1.2.1.1.5.0", "s", "evil"]),
    );
    assert!(!ok && out.contains("Timeout"), "{out}");
    // unknown community: no answer to a get either
    let (ok, out) = snmp(&line, "snmpget", &v2c("nobody", &[".1.3.6.1.2.1.1.5.0"]));
    assert!(!ok && out.contains("Timeout"), "{out}");

    control(&line, "restart", "restarted");
    let (ok, out) = snmp(
        &line,
        "snmpget",
        &v2c(
            "public",
            &[".1.3.6.1.2.1.1.4.0", ".1.3.6.1.2.1.1.5.0", ".1.3.6.1.2.1.1.6.0"],
        ),
    );
    assert!(ok, "{out}");
    for (o, v) in [(4, "ops@plant"), (5, "axis-7"), (6, "hall 3")] {
        assert!(
            out.contains(&format!(".1.3.6.1.2.1.1.{o}.0 = STRING: \"{v}\"")),
            "{out}"
        );
    }
    // v1 get of a missing object: noSuchName
    let (ok, out) = snmp(
        &line,
        "snmpget",
        &["-v1", "-c", "public", DEVICE_IP, ".1.3.6.1.2.1.1.9.0"],
    );
    assert!(!ok && out.contains("noSuchName"), "{out}");
}
