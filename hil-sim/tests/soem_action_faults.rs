//! SOEM (through pysoem) against `hil-sim serve --plant electrical
//! --plant-fault FAULT`: the motor actions (A75/A69 in the process data,
//! issue 35, E-140, E-141) fail with their result code on a plant with the
//! fault each checks, and nothing else changes (`action_faults.py`; fault
//! matrix rows 65–70). One `serve` per fault, a few seconds each, one at a
//! time. Needs root and `PYSOEM_PYTHON` (`.ci/run` sets it to
//! target/pysoem-venv/bin/python); skipped otherwise, like `soem.rs`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::scratch;
use common::soem_line::{pysoem_turn, soem_row, Line, SCRIPT_LIMIT};
use std::path::Path;

/// What every case ends with besides the action's own words: no fault, no
/// diagnosis message, the motor data and the commutation offset as before,
/// A69 idle once Execute is low, and the axis enables again.
const UNCHANGED: &str = "603Fh 0000h; history: no new message; B05, B52, B53, B62 unchanged; \
                         Execute low: A69 idle; the enable: Operation enabled";

/// Starts `serve --plant electrical --plant-fault fault` (namespaces named
/// after `tag`), runs `action_faults.py --fault fault` against it and
/// returns the end it printed for the fault matrix (`ROW <order> <seen>`).
fn seen_with(python: &Path, tag: &str, fault: &str, order: &str) -> String {
    let dir = scratch(&format!("soem-action-faults-{fault}"));
    let line = Line::with_serve_args(
        tag,
        1,
        60,
        &dir,
        &["--plant", "electrical", "--plant-fault", fault],
    );
    let (child, script) = line.spawn(python, "action_faults.py", &["--fault", fault]);
    let (status, lines) = common::watch_script(child, &script, SCRIPT_LIMIT);
    if !status.success() {
        line.fail_with(&format!(
            "action_faults.py --fault {fault} through SOEM failed: {status}"
        ));
    }
    let prefix = format!("ROW {order} ");
    lines
        .iter()
        .find_map(|l| l.strip_prefix(&prefix))
        .map(str::to_string)
        .unwrap_or_else(|| line.fail_with(&format!("action_faults.py printed no row {order}")))
}

/// E-140, E-141 (B40 test phase) through SOEM, fault matrix rows 65 and 66:
/// on a plant with motor phases V and W swapped (`--plant-fault
/// swapped-phases`) the turning field turns the rotor backwards, and on one
/// whose encoder counts the other way (`reversed-encoder`) the rotor turns
/// forwards but the count goes down by 2^20/4 (4 pole pairs): both times
/// B40 fails with 7, A69 "failed" with the selector shown, and nothing else
/// changed.
#[test]
fn e140_b40_soem_swapped_phases_and_a_reversed_encoder_fail_test_phase_with_7() {
    let Some((python, _one)) = pysoem_turn("soem B40 plant faults") else {
        return;
    };
    let expected = format!("B40: A69 failed (the selector shown), B40[0] 7; the count negative; {UNCHANGED}");
    let swapped = soem_row(
        "65",
        "electrical plant: motor phases V and W swapped (`serve --plant-fault swapped-phases`); \
         B40 test phase started by A75 in Ready to switch on, then the enable (cst)",
        "E-140, E-141",
        &expected,
    );
    hil_sim::fault_row!(swapped, seen_with(&python, "fp", "swapped-phases", "65"));
    let expected = format!("B40: A69 failed (the selector shown), B40[0] 7; the count -2^20/4; {UNCHANGED}");
    let reversed = soem_row(
        "66",
        "electrical plant: the encoder counts the other way (`serve --plant-fault \
         reversed-encoder`); B40 test phase as row 65",
        "E-140, E-141",
        &expected,
    );
    hil_sim::fault_row!(reversed, seen_with(&python, "fe", "reversed-encoder", "66"));
}

/// E-140, E-141 (B43 test winding, B40) through SOEM, fault matrix rows 67
/// and 68: with motor phase W open (`--plant-fault open-phase`) B43, which
/// runs in Ready to switch on without the enable, finds no current (2) and
/// so does B40 after the enable (2); with phase V's resistance 10 % high
/// (`unbalanced-winding`) B43 fails with 6, its resistances along U, V, W
/// those of the closed form (R_x + R_y‖R_z)/1.5 within 1 % of R. Each time
/// A69 "failed", nothing else changed.
#[test]
fn e140_b43_soem_an_open_phase_and_an_unbalanced_winding_fail_with_their_codes() {
    let Some((python, _one)) = pysoem_turn("soem B43 plant faults") else {
        return;
    };
    let expected = format!(
        "B43: A69 failed (the selector shown), B43[0] 2, E48 2 throughout; {UNCHANGED}; \
             B40: A69 failed (the selector shown), B40[0] 2; {UNCHANGED}"
    );
    let open = soem_row(
        "67",
        "electrical plant: motor phase W open (`serve --plant-fault open-phase`); B43 test \
         winding started by A75 in Ready to switch on (no enable), then B40 test phase as row 65",
        "E-140, E-141",
        &expected,
    );
    hil_sim::fault_row!(open, seen_with(&python, "fo", "open-phase", "67"));
    let expected = format!(
        "B43: A69 failed (the selector shown), B43[0] 6, E48 2 throughout; \
             U, V, W 1.016 R, 1.067 R, 1.016 R; {UNCHANGED}"
    );
    let unbalanced = soem_row(
        "68",
        "electrical plant: phase V's resistance 10 % high (`serve --plant-fault \
         unbalanced-winding`); B43 test winding as row 67",
        "E-140, E-141",
        &expected,
    );
    hil_sim::fault_row!(unbalanced, seen_with(&python, "fu", "unbalanced-winding", "68"));
}

/// E-140, E-141 (B300 test brake) through SOEM, fault matrix row 69: the
/// plant's holding brake worn to 1.0 N·m (`--plant-fault slipping-brake`),
/// below the rated torque 6076h (1.3 N·m) B300 applies against it: the
/// shaft slips beyond 1/360 rev, B300 fails with 9, the axis is back under
/// its own control (E48 = 4), nothing else changed.
#[test]
fn e140_b300_soem_a_slipping_brake_fails_test_brake_with_9() {
    let Some((python, _one)) = pysoem_turn("soem B300 plant fault") else {
        return;
    };
    let expected = format!(
        "B300: A69 failed (the selector shown), B300[0] 9, moved beyond 1/360 rev, E48 4; {UNCHANGED}"
    );
    let slipping = soem_row(
        "69",
        "the holding brake worn to 1.0 N·m, below the rated torque (`serve --plant-fault \
         slipping-brake`); B300 test brake started by A75 in Ready to switch on, then the enable",
        "E-140, E-141",
        &expected,
    );
    hil_sim::fault_row!(slipping, seen_with(&python, "fs", "slipping-brake", "69"));
}

/// E-140, E-141 (B301 grind brake) through SOEM, fault matrix row 70: the
/// plant's brake stays closed whatever is commanded (`--plant-fault
/// stuck-brake`): B301 grinds it (each grind phase turns the shaft at least
/// 0.8 of 2^19 inc) but the first released phase does not turn it (below a
/// tenth of 2^18 inc): B301 fails with 11, nothing else changed.
#[test]
fn e140_b301_soem_a_stuck_brake_fails_grind_brake_with_11() {
    let Some((python, _one)) = pysoem_turn("soem B301 plant fault") else {
        return;
    };
    let expected =
        format!("B301: A69 failed (the selector shown), B301[0] 11, ground, not released; {UNCHANGED}");
    let stuck = soem_row(
        "70",
        "the holding brake stays closed whatever is commanded (`serve --plant-fault stuck-brake`); \
         B301 grind brake started by A75 in Ready to switch on, then the enable (cst)",
        "E-140, E-141",
        &expected,
    );
    hil_sim::fault_row!(stuck, seen_with(&python, "fk", "stuck-brake", "70"));
}
