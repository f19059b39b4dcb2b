//! SOEM (through pysoem) against `hil-sim serve --plant electrical`: the
//! torque modes on the current loop and the PMSM plant (issue 34). Needs root
//! and `PYSOEM_PYTHON` (`.ci/run` sets it to target/pysoem-venv/bin/python);
//! skipped otherwise, like `soem.rs`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::soem_line::{pysoem_python, scratch, Line};

/// C-038, P-187 through SOEM on the electrical plant (`cst_electrical.py`):
/// 6071h steps of ±10 %, ±50 %, ±100 % of the rated torque in cst give a
/// 6077h (kt times the measured iq, averaged over the control cycle) within
/// 2 % of 6071h in every frame from the fourth after the step while the free
/// rotor is below half the speed limit (G472/G475 = 100 % of I10).
#[test]
fn c038_p187_soem_cst_steps_on_the_electrical_plant_give_6077h_within_2_percent() {
    let python = match pysoem_python() {
        Ok(p) => p,
        Err(why) => {
            eprintln!("soem electrical test: skipped, {why}");
            return;
        }
    };
    let dir = scratch("soem-cst-electrical");
    let i10 = drive_ecat::DriveObjects::new()
        .get(drive_ecat::params::I10, 0)
        .expect("I10 declared");
    let line = Line::with_serve_args("e", 1, 120, &dir, &["--plant", "electrical"]);
    let status = line.run(&python, "cst_electrical.py", &["--i10", &i10.to_string()]);
    if !status.success() {
        line.fail_with(&format!("cst_electrical.py through SOEM failed: {status}"));
    }
}
