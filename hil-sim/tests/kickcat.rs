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

use common::soem_line::Line;
use ecat::Dictionary;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The python with kickcat, or why the test cannot run.
fn kickcat_python() -> Result<PathBuf, String> {
    if !common::is_root() {
        return Err("needs root for network namespaces and raw sockets".into());
    }
    let py = std::env::var_os("KICKCAT_PYTHON").ok_or("KICKCAT_PYTHON is not set")?;
    let out = Command::new(&py)
        .args(["-c", "import kickcat"])
        .output()
        .unwrap_or_else(|e| panic!("KICKCAT_PYTHON={}: {e}", Path::new(&py).display()));
    assert!(
        out.status.success(),
        "KICKCAT_PYTHON={} cannot import kickcat: {}",
        Path::new(&py).display(),
        String::from_utf8_lossy(&out.stderr).trim()
    );
    Ok(PathBuf::from(py))
}

/// KickCAT on a line of 2 drives: scan, SDO Info descriptions of 1018h and
/// 6040h (E-080, E-082), complete access of 1A00h against KickCAT's
/// emulated one (E-078), 1018h:01 (E-005), a remap by SDO (E-056),
/// Safe-Op, Op with process data (E-021), the CiA 402 enable in csp and 10 s
/// of process data (E-034), Init.
#[test]
fn e080_e082_e078_e056_e021_e034_kickcat_line_of_two_drives() {
    let python = match kickcat_python() {
        Ok(p) => p,
        Err(why) => {
            eprintln!("kickcat test: skipped, {why}");
            return;
        }
    };
    let od = drive_ecat::DriveObjects::default();
    let name = |index: u16| od.object(index).expect("declared").name.to_string();
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("kickcat-line");
    std::fs::create_dir_all(&dir).expect("scratch dir");
    let line = Line::new("k", 2, 120, &dir);
    let (n1018, n6040) = (name(0x1018), name(0x6040));
    let status = line.run(
        &python,
        "kickcat_line.py",
        &[
            "--slaves",
            "2",
            "--seconds",
            "10",
            "--name-1018",
            &n1018,
            "--name-6040",
            &n6040,
        ],
    );
    if !status.success() {
        let serve = line.serve_output();
        let tail: Vec<&str> = serve.lines().rev().take(40).collect();
        let tail: Vec<&str> = tail.into_iter().rev().collect();
        panic!(
            "kickcat_line.py failed: {status}\n--- hil-sim serve ({}), last lines:\n{}",
            line.serve_log.display(),
            tail.join("\n")
        );
    }
}
