//! KickCAT (a C++ EtherCAT master; its Python bindings from PyPI,
//! `kickcat==2.5`) as a third real master next to ethercrab and SOEM
//! (issue 33): `hil-sim/tests/soem/kickcat_line.py` drives `hil-sim serve
//! --slaves 2` over a veth pair (the namespaces of `soem.rs`).
//!
//! Needs root and `KICKCAT_PYTHON`, a python that imports kickcat (a
//! throw-away venv: `python3 -m venv target/kickcat-venv &&
//! target/kickcat-venv/bin/pip install kickcat==2.5`); without them the test
//! prints why and passes without running.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::kickcat::{self, INC_PER_REV};
use common::scratch;
use common::soem_line::Line;
use std::path::PathBuf;

/// The python with kickcat, or why the test cannot run.
fn kickcat_python() -> Result<PathBuf, String> {
    common::peer_python("KICKCAT_PYTHON", "kickcat", "import kickcat", "kickcat-venv")
}

/// KickCAT on a line of 2 drives: scan, SDO Info descriptions of 1018h and
/// 6040h (E-080, E-082), complete access of 1A00h against KickCAT's
/// emulated one (E-078), 1018h:01 (E-005), a remap by SDO (E-056), I423
/// raised by SDO (C-117), Safe-Op, Op with process data (E-021), the CiA 402
/// enable in csp (E-034), 10 s of process data in csp with a move of one
/// revolution of axis A on both drives, its set-points computed by the
/// script each cycle, 6064h following within [`TOLERANCE_INC`](kickcat::TOLERANCE_INC) (plus the
/// curve's bend over the master's longest gap) and ending within
/// [`END_TOLERANCE_INC`](kickcat::END_TOLERANCE_INC) of the target (C-116, C-117), Init.
#[test]
fn e080_e082_e078_e056_e021_e034_c116_c117_kickcat_line_of_two_drives_csp_move() {
    let Some(python) = common::or_skip(kickcat_python(), "kickcat test") else {
        return;
    };
    let dir = scratch("kickcat-line");
    let line = Line::new("k", 2, 120, &dir);
    let inc = INC_PER_REV.to_string();
    let args = kickcat::line_args("10", &["--inc-per-rev", &inc, "--move-seconds", "2"]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let status = line.run(&python, "kickcat_line.py", &args);
    if !status.success() {
        line.fail_with(&format!("kickcat_line.py failed: {status}"));
    }
}
