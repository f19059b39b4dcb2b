//! net-snmp (Debian package `snmp`) reads and writes the SNMP agent of
//! `hil-sim serve --fieldbus profinet` over a veth pair (spec P-038): the
//! device gets its IP and name by DCP Set (tests/snmp/dcp_set_ip.py, plain
//! sockets), a neighbour sends it an LLDPDU and reads PDPortDataReal
//! (tests/snmp/pn_peer.py), then `snmpwalk` of system, interfaces, LLDP-MIB
//! with the management address tables and the PROFINET (…5.3791) and 802.3
//! (…5.4623) extensions checked against the DCP name, the neighbour's TLVs
//! and PDPortDataReal, `snmpget`, `snmpset`
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
const DEVICE_NAME: &str = "drive-7";

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

/// The controller's own address, which its LLDPDU announces as management address.
const CONTROLLER_ADDR: &str = "192.168.0.10";

/// `snmpwalk` of `oid` with the community "public"; it must succeed.
fn walk_public(line: &PnLine, oid: &str) -> String {
    let (ok, walk) = snmp(line, "snmpwalk", &v2c("public", &[oid]));
    assert!(ok, "{walk}");
    walk
}

/// Each of `rows` ("suffix = value") below the OID `prefix` stands in `walk`.
fn has_rows(walk: &str, prefix: &str, rows: &[&str]) {
    for row in rows {
        has(walk, &format!("{prefix}{row}"));
    }
}

fn has(walk: &str, line: &str) {
    assert!(walk.contains(line), "{line:?} missing:\n{walk}");
}

/// `snmpwalk -v2c -On` of the management address tables and the PROFINET and
/// 802.3 extensions: what the device sends and what the neighbour sent.
fn lldp_extensions(line: &PnLine, mau: &str, peer_station: &str) {
    let ip = DEVICE_IP;
    let walk = walk_public(line, ".1.0.8802.1.1.2.1.3.8");
    // lldpLocManAddrTable: index ipV4(1).4.<address>; length 5, ifIndex(2) 1
    has(&walk, &format!(".1.0.8802.1.1.2.1.3.8.1.3.1.4.{ip} = INTEGER: 5"));
    has(&walk, &format!(".1.0.8802.1.1.2.1.3.8.1.4.1.4.{ip} = INTEGER: 2"));
    has(&walk, &format!(".1.0.8802.1.1.2.1.3.8.1.5.1.4.{ip} = INTEGER: 1"));
    has(&walk, &format!(".1.0.8802.1.1.2.1.3.8.1.6.1.4.{ip} = OID: .0.0"));
    assert_eq!(walk.lines().count(), 4, "{walk}");
    // lldpConfigManAddrTable: both ports send the address (LldpPortList: ports 1, 2)
    let walk = walk_public(line, ".1.0.8802.1.1.2.1.1.7");
    has(
        &walk,
        &format!(".1.0.8802.1.1.2.1.1.7.1.1.1.4.{ip} = Hex-STRING: C0"),
    );
    // lldpRemManAddrTable: the neighbour's address on port 1 (time mark 0, index 1)
    let walk = walk_public(line, ".1.0.8802.1.1.2.1.4.2");
    let c = CONTROLLER_ADDR;
    has(
        &walk,
        &format!(".1.0.8802.1.1.2.1.4.2.1.3.0.1.1.1.4.{c} = INTEGER: 2"),
    );
    has(
        &walk,
        &format!(".1.0.8802.1.1.2.1.4.2.1.4.0.1.1.1.4.{c} = INTEGER: 1"),
    );

    // LLDP-EXT-PNO-MIB: NameOfStation as DCP set it on both ports, RT2/RT3 off;
    // the neighbour's delays, port status and name as its LLDPDU carried them
    let walk = walk_public(line, ".1.0.8802.1.1.2.1.5.3791");
    let loc = ".1.0.8802.1.1.2.1.5.3791.1.2.1.1";
    for port in [1, 2] {
        has(&walk, &format!("{loc}.6.{port} = STRING: \"{DEVICE_NAME}\""));
        has(&walk, &format!("{loc}.4.{port} = INTEGER: 0"));
        has(&walk, &format!("{loc}.5.{port} = INTEGER: 0"));
        has(&walk, &format!("{loc}.1.{port} = Gauge32: 0"));
    }
    let rem = ".1.0.8802.1.1.2.1.5.3791.1.3.1.1";
    has_rows(
        &walk,
        rem,
        &[
            ".1.0.1.1 = Gauge32: 55",
            ".2.0.1.1 = Gauge32: 1123",
            ".3.0.1.1 = Gauge32: 444",
            ".4.0.1.1 = INTEGER: 2",
            &format!(".6.0.1.1 = STRING: \"{peer_station}\""),
        ],
    );
    // 6 columns x 2 local ports + 6 for the one neighbour
    assert_eq!(walk.lines().count(), 18, "{walk}");

    // LLDP-EXT-DOT3-MIB: auto-negotiation on, 10/100 advertised, the MAU type
    // PDPortDataReal reports on port 1; the neighbour's MAC/PHY TLV
    let walk = walk_public(line, ".1.0.8802.1.1.2.1.5.4623");
    let loc = ".1.0.8802.1.1.2.1.5.4623.1.2.1.1";
    has_rows(
        &walk,
        loc,
        &[
            ".1.1 = INTEGER: 1",
            ".2.1 = INTEGER: 1",
            ".3.1 = Hex-STRING: 6C 00",
            &format!(".4.1 = INTEGER: {mau}"),
        ],
    );
    let rem = ".1.0.8802.1.1.2.1.5.4623.1.3.1.1";
    has_rows(
        &walk,
        rem,
        &[
            ".1.0.1.1 = INTEGER: 1",
            ".2.0.1.1 = INTEGER: 2",
            ".4.0.1.1 = INTEGER: 16",
        ],
    );
    assert_eq!(walk.lines().count(), 4 * 2 + 4, "{walk}");
    assert_eq!(
        mau, "16",
        "PDPortDataReal: 100BASE-TX FD while port 1's link is up"
    );
}

/// The counter in `walk`'s line starting with `oid = ` (`Counter32: n`, `Gauge32: n`).
fn counter(walk: &str, oid: &str) -> u64 {
    let l = walk
        .lines()
        .find(|l| l.starts_with(&format!("{oid} = ")))
        .unwrap_or_else(|| panic!("{oid} missing:\n{walk}"));
    l.rsplit(' ')
        .next()
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{l}"))
}

/// `snmpwalk -v2c -On` of lldpConfiguration and lldpStatistics: the timing the
/// transmitter uses, and counters that saw the neighbour's LLDPDU on port 1.
fn lldp_config_and_statistics(line: &PnLine) {
    let walk = walk_public(line, ".1.0.8802.1.1.2.1.1");
    let interval = profinet::lldp::TX_INTERVAL.as_secs();
    let c = ".1.0.8802.1.1.2.1.1";
    has(&walk, &format!("{c}.1.0 = INTEGER: {interval}"));
    // TTL sent = interval x hold multiplier
    let hold = u64::from(profinet::lldp::TTL_SECS) / interval;
    has(&walk, &format!("{c}.2.0 = INTEGER: {hold}"));
    for port in [1, 2] {
        // txAndRx, no notifications, no optional basic TLV (an empty BITS octet)
        has(&walk, &format!("{c}.6.1.2.{port} = INTEGER: 3"));
        has(&walk, &format!("{c}.6.1.3.{port} = INTEGER: 2"));
        has(&walk, &format!("{c}.6.1.4.{port} = Hex-STRING: 00"));
    }
    // 5 scalars, 3 x 2 port config cells, the management address row
    assert_eq!(walk.lines().count(), 5 + 6 + 1, "{walk}");
    // read-only: the device cannot change its interval
    let (ok, out) = snmp(
        line,
        "snmpset",
        &v2c("private", &[&format!("{c}.1.0"), "i", "30"]),
    );
    assert!(!ok && out.contains("notWritable"), "{out}");

    let walk = walk_public(line, ".1.0.8802.1.1.2.1.2");
    let s = ".1.0.8802.1.1.2.1.2";
    assert!(walk.contains(&format!("{s}.1.0 = Timeticks:")), "{walk}");
    assert!(counter(&walk, &format!("{s}.2.0")) >= 1, "inserts:\n{walk}");
    assert!(counter(&walk, &format!("{s}.6.1.2.1")) >= 1, "tx port 1:\n{walk}");
    assert!(
        counter(&walk, &format!("{s}.7.1.4.1")) >= 1,
        "rx frames port 1:\n{walk}"
    );
    assert_eq!(counter(&walk, &format!("{s}.7.1.2.1")), 0, "{walk}");
    // 5 scalars, 2 tx cells, 6 x 2 rx cells
    assert_eq!(walk.lines().count(), 5 + 2 + 12, "{walk}");
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
    let dir = common::scratch("snmp");
    let line = PnLine::new("sn", &dir, &[]);
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/snmp/dcp_set_ip.py");
    let dcp = Command::new("ip")
        .args(["netns", "exec", &line.ctl_ns, "python3"])
        .arg(&script)
        .args([&line.ctl_if, &line.device_mac, DEVICE_IP, DEVICE_NAME])
        .output()
        .expect("python3");
    assert!(
        dcp.status.success(),
        "DCP Set IP and name: {}",
        String::from_utf8_lossy(&dcp.stdout)
    );
    // the neighbour: its LLDPDU, then what PDPortDataReal of port 1 reports
    let peer = Command::new("ip")
        .args(["netns", "exec", &line.ctl_ns, "python3"])
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/snmp/pn_peer.py"))
        .args([&line.ctl_if, DEVICE_IP, CONTROLLER_ADDR])
        .output()
        .expect("python3");
    let peer_out = String::from_utf8_lossy(&peer.stdout).into_owned();
    assert!(peer.status.success(), "pn_peer.py: {peer_out}");
    let real = peer_out
        .lines()
        .find_map(|l| l.strip_prefix("pdportdatareal: "))
        .unwrap_or_else(|| panic!("no PDPortDataReal: {peer_out}"));
    let field = |k: &str| -> String {
        real.split(' ')
            .find_map(|kv| kv.strip_prefix(&format!("{k}=")))
            .unwrap_or_else(|| panic!("{k} in {real}"))
            .to_string()
    };
    let (mau, peer_station) = (field("mau"), field("peer_station"));
    assert_eq!(
        peer_station, "plc-1",
        "PDPortDataReal names the neighbour: {real}"
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
    // LLDP-MIB: the chassis ID is what the LLDPDU sends, the NameOfStation
    // (local, 7) once named; the local port table names both ports
    let (ok, walk) = snmp(&line, "snmpwalk", &v2c("public", &[".1.0.8802.1.1.2"]));
    assert!(ok, "{walk}");
    assert!(walk.contains(".1.0.8802.1.1.2.1.3.1.0 = INTEGER: 7"), "{walk}");
    assert!(
        walk.contains(&format!(".1.0.8802.1.1.2.1.3.2.0 = STRING: \"{DEVICE_NAME}\"")),
        "lldpLocChassisId {DEVICE_NAME}:\n{walk}"
    );
    assert!(
        walk.contains(".1.0.8802.1.1.2.1.3.7.1.3.2 = STRING: \"port-002\""),
        "{walk}"
    );
    // the whole LLDP-MIB walk ends and never repeats (snmpwalk checks the order itself)
    assert!(!walk.contains("not increasing"), "{walk}");
    lldp_extensions(&line, &mau, &peer_station);
    lldp_config_and_statistics(&line);

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
