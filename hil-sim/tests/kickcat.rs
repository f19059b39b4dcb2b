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

/// The python with kickcat, or why the test cannot run.
fn kickcat_python() -> Result<PathBuf, String> {
    common::peer_python("KICKCAT_PYTHON", "kickcat", "import kickcat", "kickcat-venv")
}

/// Increments per revolution of the drive's position (6064h, 607Ah) with
/// the default scaling (`hil-sim/tests/soem/line.py` moves by the same).
const INC_PER_REV: u32 = 1 << 20;

/// I423 as KickCAT sets it by SDO before Op: the longest the drive
/// extrapolates a missing csp set-point (C-117). The default 10 ms is shorter
/// than the stalls of a Python master on a loaded machine (gaps of 20 to
/// 170 ms seen with a load of 12 on 2 cores: the drive faulted, rightly),
/// so the master sets what its own jitter needs.
const I423_MS: u16 = 500;

/// How far 6064h may be from the csp set-point sent in the same cycle during
/// the move (1/16 rev): the position loop's lag at the move's 0.79 rev/s and
/// the set-point's advance over one cycle of the master (the inputs of a
/// frame are read as its outputs are written). The script adds twice what
/// the drive's linear extrapolation (C-116) over the longest gap between the
/// master's cycles (g) misses of the curve, a/2 · g² with the curve's
/// largest acceleration a = π²/(2 T²) rev/s² (T = 2 s: 1/160 rev for
/// g = 100 ms).
const TOLERANCE_INC: u32 = INC_PER_REV / 16;

/// How far 6064h may end from the target once the move is over: the
/// drive's default position window I22 (1/360 rev, the window of "target
/// reached"), as `tests/tests/motion.rs` checks. At rest the axis hunts: the
/// velocity PI's integral part winds the torque up at a following error
/// until it passes the motor's breakaway friction (0.03 N·m), the rotor
/// slides against the lower Coulomb friction (0.02 N·m) past the target and
/// sticks on the other side, a stick-slip limit cycle whose steps scale as
/// (0.03 − 0.02) N·m over the cascade's stiffness Kp·Kv at the 1 ms cycle
/// (0.015 N·m·s/rad × 50 /s: 13 mrad, 2200 inc). `demo`'s 1 ms csp held 4 s
/// at its target sticks at +73, −1220, +441, −954, +608 inc on the rigid
/// model and at +76, −619, +391, −577, +472 inc on the electrical one. The
/// rigid model's run here ends 4 inc from the target only because it is
/// free of noise: it sticks that close after the move, and at 4 inc the
/// integral needs tens of seconds to break the rotor away; with the current
/// loop's ADC noise it sticks a few hundred inc off and hunts within the 8 s
/// (+472/−450, −613/+430 inc seen). 200 inc held only for that lucky run.
const END_TOLERANCE_INC: u32 = INC_PER_REV / 360;

/// KickCAT on a line of 2 drives: scan, SDO Info descriptions of 1018h and
/// 6040h (E-080, E-082), complete access of 1A00h against KickCAT's
/// emulated one (E-078), 1018h:01 (E-005), a remap by SDO (E-056), I423
/// raised by SDO (C-117), Safe-Op, Op with process data (E-021), the CiA 402
/// enable in csp (E-034), 10 s of process data in csp with a move of one
/// revolution of axis A on both drives, its set-points computed by the
/// script each cycle, 6064h following within [`TOLERANCE_INC`] (plus the
/// curve's bend over the master's longest gap) and ending within
/// [`END_TOLERANCE_INC`] of the target (C-116, C-117), Init.
#[test]
fn e080_e082_e078_e056_e021_e034_c116_c117_kickcat_line_of_two_drives_csp_move() {
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
    let i423 = format!("{:#06x}", drive_ecat::params::I423);
    let (i423_ms, inc, tol, end_tol) = (
        I423_MS.to_string(),
        INC_PER_REV.to_string(),
        TOLERANCE_INC.to_string(),
        END_TOLERANCE_INC.to_string(),
    );
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
            "--i423-index",
            &i423,
            "--i423-ms",
            &i423_ms,
            "--inc-per-rev",
            &inc,
            "--move-seconds",
            "2",
            "--tolerance",
            &tol,
            "--end-tolerance",
            &end_tol,
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
