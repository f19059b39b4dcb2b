//! Checks in the style of the ETG conformance test tool, written on SOEM's
//! low-level register access (pysoem's `_fprd`/`_fpwr`), against `hil-sim
//! serve` over a veth pair (issue 33): `hil-sim/tests/soem/conformance.py`,
//! one case per test, on a line of one drive.
//!
//! Needs root and pysoem (`PYSOEM_PYTHON`, as `soem.rs`); without them the
//! tests print why and pass without running.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::scratch;
use common::soem_line::{pysoem_turn, Line};

/// Runs `conformance.py --case <case>` on a line of one drive (`tag`: one
/// letter for the namespaces); fails with serve's log.
fn run_case(tag: &str, case: &str) {
    let Some((python, _one)) = pysoem_turn(&format!("soem conformance case {case}")) else {
        return;
    };
    let dir = scratch(&format!("soem-conformance-{case}"));
    let line = Line::new(tag, 1, 90, &dir);
    let status = line.run(&python, "conformance.py", &["--case", case]);
    if !status.success() {
        line.fail_with(&format!(
            "conformance.py --case {case} through SOEM failed: {status}"
        ));
    }
}

/// E-033, E-047: Safe-Op → Op that cannot succeed (A258 = 100 ms, no
/// process data) is refused with 002Bh 200 ms after the request whether
/// SOEM writes AL control once, every 5 ms (as libethercat does) or every
/// 1 ms: a repeated identical request does not restart the wait.
#[test]
fn e033_e047_soem_repeated_op_request_refused_on_time() {
    run_case("o", "op-repeat");
}

/// E-025, E-045, E-038: SOEM switches a SyncManager off with an FPWR of its
/// activate register (0x0806 + 8n bit 0 = 0): SM0 or SM1 in Pre-Op, Safe-Op
/// or Op gives Init + ERR 0016h, SM2 in Safe-Op/Op Pre-Op + ERR 001Dh, SM3
/// 001Eh; SM2/SM3 in Pre-Op nothing; SOEM's next scan brings the drive back.
#[test]
fn e025_e045_e038_soem_sm_switched_off_by_register_write() {
    run_case("m", "sm-off");
}

/// E-027: mailbox requests of reserved types (6, 14) and of protocols the
/// drive does not speak (AoE, SoE), written into SM0 with SOEM's FPWR, are
/// answered with the mailbox error 0002h (unsupported protocol), not 0001h;
/// SOEM's SDO read works afterwards.
#[test]
fn e027_soem_reserved_mailbox_type_unsupported_protocol() {
    run_case("t", "mbx-type");
}

/// E-026, explicit device identification (ETG.1000.6): SOEM writes an
/// alias into the SII (word 4 and the CRC of words 0–7), the ESC reloads it
/// into 0x0012; AL control with the ID request bit (Init, Pre-Op) gives AL
/// status bit 5 and the alias in 0x0134; a request without the bit clears
/// them; a refused request shows its error code, not the ID.
#[test]
fn e026_soem_explicit_device_identification_through_registers() {
    run_case("i", "id-request");
}

/// E-002 (issue 33.3): frames as libethercat sends them (EtherCAT header
/// length 16 bytes larger than the datagrams, unpadded on veth), a shorter
/// header length, a trailer: `serve` answers each datagram as an ESC does;
/// a frame ending inside its datagram is dropped.
#[test]
fn e002_soem_libethercat_style_frames_answered_by_serve() {
    run_case("f", "frames");
}
