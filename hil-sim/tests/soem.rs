//! SOEM, the most used open-source EtherCAT master (C), as a second real
//! master next to ethercrab: pysoem (PyPI; it builds SOEM's sources) drives
//! `hil-sim serve` over a veth pair between two private network namespaces.
//!
//! - the master's namespace holds one end of the veth pair and runs the
//!   Python scripts in `hil-sim/tests/soem/` with the venv's python;
//! - the simulator's namespace holds the other end and runs
//!   `hil-sim serve --iface … --slaves 3`.
//!
//! The fault cases (`faults.py`, rows 6x of the fault matrix,
//! docs/fault-matrix.md) print the end SOEM read as `ROW <order> <seen>`
//! lines; each test compares them with its rows' expected ends
//! (`hil_sim::fault_row!`, which also leaves the rows for
//! `scripts/fault-matrix`).
//!
//! The expected values come from the drive's own declarations: the SII image
//! `ecat::build_sii(&drive_ecat::DEVICE, …)` and the objects a fresh dictionary
//! shows, written to files the scripts compare SOEM's readings with.
//!
//! Needs root (network namespaces, raw sockets) and pysoem: `PYSOEM_PYTHON`
//! names a python that imports it (`.ci/run` installs it into
//! `target/pysoem-venv` and sets the variable). Without root or without the
//! variable the tests print why and pass without running; a `PYSOEM_PYTHON`
//! that cannot import pysoem fails them.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::scratch;
use common::soem_line::{pysoem_turn, soem_row, Line, SCRIPT_LIMIT};
use ecat::Dictionary;
use std::fmt::Write as _;
use std::path::Path;

/// Drives on the line.
const SLAVES: usize = 3;
/// Process data in Op, s (at least 10 s of 1 ms cycles).
const OP_SECONDS: u32 = 12;
/// The SII image the simulated drives carry.
fn sii_image() -> Vec<u8> {
    let mut sii = vec![0u8; ecat::sii::EEPROM_BYTES];
    ecat::build_sii(&drive_ecat::DEVICE, &mut sii).expect("SII");
    sii
}

/// The objects a fresh drive shows through SDO Info (the "EtherCAT Rx SDO
/// Info" template, the default access level), one line per object and entry:
/// `obj index code max_sub data_type|- name` and `ent index sub data_type
/// bits access default name`, tab-separated, numbers in hex except code,
/// max_sub, bits and default. The object's data type is given for VAR and
/// ARRAY objects (the type of their entries).
fn od_listing() -> String {
    let dict = drive_ecat::DriveObjects::default();
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
    let Some((python, _one)) = pysoem_turn("soem line test") else {
        return;
    };
    let dir = scratch("soem-line");
    let sii = dir.join("sii.bin");
    let od = dir.join("od.tsv");
    std::fs::write(&sii, sii_image()).unwrap();
    std::fs::write(&od, od_listing()).unwrap();
    let line = Line::new("l", SLAVES, 200, &dir);
    line.run_passes(
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
    let Some((python, _one)) = pysoem_turn("soem EoE test") else {
        return;
    };
    let dir = scratch("soem-eoe");
    // A166 "IP address reference" as a fresh drive declares it (the UDP read's answer)
    let a166 = drive_ecat::DriveObjects::default()
        .object(drive_ecat::parameter_index(0, 166))
        .and_then(|o| o.entry(0))
        .expect("A166")
        .default;
    let line = Line::new("e", SLAVES, 200, &dir);
    line.run_passes(
        &python,
        "eoe.py",
        &["--slaves", &SLAVES.to_string(), "--a166", &a166.to_string()],
    );
}

/// The firmware update as SOEM's `firm_update` sample does it (Init, the
/// bootstrap mailbox from the SII, Bootstrap, `ecx_FOEwrite`, Init) with the
/// update files `foe-image make` writes by default, one per slot and named
/// for it (`firmware-slot-a.sc6f`, `firmware-slot-b.sc6f`, issue 33;
/// docs/flashing.md): the master reads the drive's update slot E54 by SDO
/// and sends that slot's file, the other slot's file is refused (the drive:
/// 8004h; SOEM reports an FoE error answer as −5), a bit-flipped and a
/// truncated file too, a name that does not start with `firmware` gets 8001h
/// (−10), the right file is taken, `serve` prints that the download was
/// verified and stored in that slot, and the drive returns to Pre-Op. The
/// new image starts only at the next power-on (E-019; the power cycle and the
/// boot from the new slot are checked in-process, where the slots can be
/// seen: `tools/foe-image/tests/round_trip.rs`).
#[test]
fn e019_foe_file_for_the_update_slot_through_soem_firm_update() {
    let Some((python, _one)) = pysoem_turn("soem FoE test") else {
        return;
    };
    let dir = scratch("soem-foe");
    let body = hil_sim::sim::firmware_body(64 * 1024, 0);
    // the image linked for each slot of `serve`'s drive, signed with the
    // development key (issue 18), written under the tool's default name
    let seed = drive_ecat::boot::parse_key_hex(include_str!("../../keys/dev-ed25519.key")).unwrap();
    let slots = hil_sim::sim::FirmwareSlots::new(hil_sim::sim::FirmwareFlash::new());
    let mut good = Vec::new();
    for slot in [drive_ecat::boot::Slot::A, drive_ecat::boot::Slot::B] {
        let info = foe_image::ImageInfo {
            version: 2,
            load_address: slots.load_address(slot),
            security_counter: 1,
        };
        let file = foe_image::update_file(&body, info, &seed).unwrap();
        let name = foe_image::default_file_name(info.load_address);
        assert_eq!(name, foe_image::slot_file_name(slot.index()));
        std::fs::write(dir.join(&name), &file).unwrap();
        good.push(file);
    }
    // a flipped and a truncated copy of the file for slot A, the update slot
    // of `serve`'s empty drives (foe.py checks the drive says so in E54)
    let mut flipped = good[0].clone();
    flipped[drive_ecat::boot::IMAGE_HEADER_LEN + 20_000] ^= 0x04;
    let truncated = good[0][..good[0].len() - 100].to_vec();
    let path = |name: &str| dir.join(name);
    for (name, data) in [("flipped", &flipped), ("truncated", &truncated)] {
        std::fs::write(path(name), data).unwrap();
    }
    let line = Line::new("f", 1, 120, &dir);
    let arg = |name: &str| path(name).to_str().unwrap().to_string();
    let (d, f, t) = (
        dir.to_str().unwrap().to_string(),
        arg("flipped"),
        arg("truncated"),
    );
    let e54 = format!("{:#06x}", drive_ecat::params::E54);
    let (status, printed) = line.run_lines(
        &python,
        "foe.py",
        &["--files", &d, "--e54", &e54, "--flipped", &f, "--truncated", &t],
    );
    if !status.success() {
        line.fail_with(&format!("foe.py through SOEM failed: {status}"));
    }
    // a retry of the good file after SOEM lost the frame of its last
    // packet sends it again: the drive had stored it already and stores it
    // once more (each time the same file, slot A)
    let retries = printed
        .iter()
        .filter(|l| l.starts_with("RETRY the update slot's file"))
        .count();
    let serve = line.serve_output();
    let stored: Vec<&str> = serve
        .lines()
        .filter(|l| l.contains("FoE download verified"))
        .collect();
    if stored.is_empty()
        || stored.len() > 1 + retries
        || !stored.iter().all(|l| l.contains("stored in slot A (version 2)"))
    {
        line.fail_with(&format!(
            "serve should print one stored download (one more per retry of the good file, {retries}), in slot A (version 2): {stored:?}"
        ));
    }
}

/// Drives on the line of the fault cases.
const FAULT_SLAVES: usize = 2;

/// Runs `faults.py --case <case>` on a line of [`FAULT_SLAVES`] drives
/// (`tag`: one letter for the namespaces); the rows it printed (`ROW
/// <order> <seen>`), or the test fails with serve's log.
fn fault_rows(python: &Path, tag: &str, case: &[&str]) -> Vec<(String, String)> {
    let dir = scratch(&format!("soem-faults-{}", case[0]));
    let line = Line::new(tag, FAULT_SLAVES, 120, &dir);
    let slaves = FAULT_SLAVES.to_string();
    let mut args = vec!["--slaves", &slaves, "--case"];
    args.extend_from_slice(case);
    let (child, script) = line.spawn(python, "faults.py", &args);
    let (status, lines) = common::watch_script(child, &script, SCRIPT_LIMIT);
    if !status.success() {
        line.fail_with(&format!("faults.py {case:?} through SOEM failed: {status}"));
    }
    lines
        .iter()
        .filter_map(|l| l.strip_prefix("ROW "))
        .filter_map(|r| r.split_once(' '))
        .map(|(order, seen)| (order.to_string(), seen.to_string()))
        .collect()
}

/// The end faults.py printed for row `order`.
fn seen_in<'a>(rows: &'a [(String, String)], order: &str) -> &'a str {
    rows.iter()
        .find(|(o, _)| o == order)
        .map(|(_, seen)| seen.as_str())
        .unwrap_or_else(|| panic!("faults.py printed no row {order}: {rows:?}"))
}

/// Fault matrix rows 61 and 62 through SOEM: two drives in Op under DC
/// SYNC0 1 ms with A258 = 100 ms (E-126: a time, not a count of frames, so
/// the Python master's own jitter does not decide), axis A of each enabled
/// in pv at standstill (no cyclic set-point: I423's extrapolation limit,
/// C-117, does not apply), axis B disabled. The master sends no frame for
/// 20 ms: nothing happens. For 500 ms: the PDO timeout (E-044, E-128),
/// event 52 cause 6 with its EMCY and both axes in Fault (E-129), SOEM
/// acknowledges, requests Op and resets the faults (C-017); 6065h and A258
/// as written before. A stall of the master that the drives' clock shows
/// at least as long as A258 repeats a case (faults.py).
#[test]
fn e126_e044_e128_e129_soem_frame_pauses_under_dc_with_a258_100_ms() {
    let Some((python, _one)) = pysoem_turn("soem fault matrix (frame pauses)") else {
        return;
    };
    let rows = fault_rows(&python, "p", &["pause"]);
    let short = soem_row(
        "61",
        "SOEM in Op under DC SYNC0 1 ms (axis A of both drives enabled in pv at standstill), A258 = 100 ms: \
               no frame from the master for 20 ms",
        "E-126",
        "drives 1, 2: Op, AL 0000h; axis A Operation enabled, axis B Switch on disabled; no EMCY; \
                   603Fh 0000h, 683Fh 0000h; history: no new message",
    );
    hil_sim::fault_row!(short, seen_in(&rows, "61"));
    let long = soem_row(
        "62",
        "the same, no frame for 500 ms; then SOEM acknowledges, requests Op and resets the faults",
        "E-126, E-044, E-128, E-129, C-017",
        "drives 1, 2: Safe-Op + ERR, AL 001Bh; axis A Fault, axis B Fault; EMCY 7500h/10h event 52 \
                   cause 6; 603Fh 7500h, 683Fh 7500h; history: error AL 001Bh; the master acknowledges and \
                   requests Op: drives 1, 2: Op, AL 0000h; a fault reset: axis A Switch on disabled, axis B \
                   Switch on disabled; 6065h 123456, A258 100",
    );
    hil_sim::fault_row!(long, seen_in(&rows, "62"));
}

/// Fault matrix row 63 through SOEM: a master process killed (SIGKILL) in
/// Op with process data (two drives in free run, A258 = 100 ms and 6065h
/// written by it, axis A enabled in pv): 500 ms later the drives are in
/// Safe-Op + ERR with AL 001Bh (E-126, E-044; the AL status read by one
/// raw APRD frame, since SOEM's scan resets every drive to Init first). A
/// new master process scans (Init, Pre-Op: the unread EMCY went with the
/// mailbox, E-037; 603Fh and the history keep the fault), finds A258 and
/// 6065h as the first master wrote them, maps, Safe-Op, Op (E-021), resets
/// the faults and enables axis A. Free run: under DC the new master's first
/// Op request would depend on how soon after the Init its scan deactivates
/// SYNC0 (docs/fault-matrix.md, the SYNC0 loss in Init).
#[test]
fn e126_e044_e037_e021_soem_master_killed_in_op_and_a_new_master() {
    let Some((python, _one)) = pysoem_turn("soem fault matrix (master killed)") else {
        return;
    };
    let rows = fault_rows(&python, "r", &["restart"]);
    let killed = soem_row(
        "63",
        "the SOEM master process is killed (SIGKILL) in Op (free run, axis A enabled in pv; it wrote A258 = \
               100 ms and 6065h); 500 ms later a new SOEM master process scans and brings the line to Op",
        "E-126, E-044, E-037, E-021",
        "500 ms after the kill (AL status by a raw APRD frame): drives 1, 2: Safe-Op + ERR, AL 001Bh; \
                   the new master's scan: drives 1, 2: Pre-Op, AL 0000h; axis A Fault, axis B Fault; no EMCY; \
                   603Fh 7500h, 683Fh 7500h; history: error AL 001Bh; 6065h 654321, A258 100; its maps, \
                   Safe-Op, Op, a fault reset and the enable: drives 1, 2: Op, AL 0000h; axis A Operation \
                   enabled, axis B Switch on disabled",
    );
    hil_sim::fault_row!(killed, seen_in(&rows, "63"));
}

/// Fault matrix row 64 through SOEM: a master stops as SOEM's samples do
/// (Op, Safe-Op, Init, the socket closed, SYNC0 left running: the drives'
/// PLLs lock again in Init), and a new master process scans (its start-up
/// switches SYNC0 off: a SYNC0 timeout latches below Safe-Op, where the
/// drive shows no error) and brings the line to Op under DC: Op at the
/// first request (E-046; it was refused with 0034h until Pre-Op → Safe-Op
/// cleared a PLL fault latched below Safe-Op).
#[test]
fn e046_e021_soem_a_master_stopped_in_init_and_a_new_master_under_dc() {
    let Some((python, _one)) = pysoem_turn("soem fault matrix (stop and restart under DC)") else {
        return;
    };
    let rows = fault_rows(&python, "s", &["stop-restart"]);
    let row = soem_row(
        "64",
        "a SOEM master stops as SOEM's samples do (Op, Safe-Op, Init, socket closed, SYNC0 left running); \
               300 ms later a new SOEM master process scans and brings the line to Op under DC SYNC0",
        "E-046, E-021",
        "the new master's scan, maps, DC, Safe-Op and Op request: drives 1, 2: Op, AL 0000h; the \
                   enable: drives 1, 2: axis A Operation enabled; 6065h 654321, A258 100",
    );
    hil_sim::fault_row!(row, seen_in(&rows, "64"));
}

/// C-039 through SOEM (issue 40): the velocity limits of the torque modes
/// G472/G475 (2DD8h/2DDBh) default to 0 % and keep the axis still in cst
/// (statusword bit 11); a value beyond 100 % is refused with 0609 0031h;
/// raised by SDO in Op to 40 % of I10, 6071h = 10 % of the rated torque
/// moves the axis in cst forward and in pt back, 6077h follows 6071h while
/// it accelerates (within 2 %: `serve`'s default electrical plant shows kt
/// times the measured iq), and the speed settles at ±40 % of I10
/// (`torque.py`).
#[test]
fn c039_soem_raises_g472_g475_by_sdo_and_cst_pt_move_the_axis() {
    let Some((python, _one)) = pysoem_turn("soem torque-mode test") else {
        return;
    };
    let dir = scratch("soem-torque");
    // I10, the reference of G472/G475's percentages, as a fresh drive has it
    let i10 = drive_ecat::DriveObjects::new()
        .get(drive_ecat::params::I10, 0)
        .expect("I10 declared");
    let line = Line::new("t", 1, 120, &dir);
    line.run_passes(
        &python,
        "torque.py",
        &["--limit", "400", "--i10", &i10.to_string()],
    );
}
