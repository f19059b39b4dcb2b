//! Axis parameters through the PROFIdrive parameter access, saved and
//! restored across a restart, with profinet-py (PyPI, 0.6.6) as the
//! engineering tool against `hil-sim serve --fieldbus profinet --control
//! FIFO` over a veth pair between two private network namespaces (issue
//! 40): `tests/profinet/params.py` changes the torque-mode speed limit
//! G472 and the velocity controller's Kp C31 through record 0xB02E on a
//! device-access AR (PNU = the object's index, docs/pnu.md), saves with
//! PNU 971 = 1, changes C31 once more without saving, has serve restart
//! the device over the same parameter flash, and reads both back.
//!
//! Needs root and `PROFINET_PY_PYTHON` as `tests/profinet.rs`; without
//! either the test prints why and passes without running.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::pn_line::PnLine;
use std::ffi::OsStr;
use std::path::Path;
use std::time::Duration;

/// A script that has not finished after this long has hung.
const SCRIPT_LIMIT: Duration = Duration::from_secs(90);

/// P-199 (PNU 971 = 1 saves the parameters) and P-206 (record 0xB02E):
/// G472 and C31 changed by the record, saved, the device restarted, the
/// saved values read back (not the change made after the save, not the
/// defaults).
#[test]
fn p199_p206_profinet_py_changes_g472_and_the_speed_kp_saves_and_reads_them_after_a_restart() {
    let Some(python) = common::or_skip(common::profinet_py_python(), "profinet-py parameter test") else {
        return;
    };
    let dir = common::scratch("profinet-py");
    let mut line = PnLine::new("pp", &dir, &[]);
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/profinet/params.py");
    let args: [&OsStr; 2] = ["--control".as_ref(), line.control.as_os_str()];
    let (status, lines) = line.run(&python, &script, &args, SCRIPT_LIMIT);
    line.stop_server();
    let serve = line.serve_output();
    println!("--- hil-sim serve ({}):\n{serve}", line.serve_log.display());
    let verdict: Vec<&String> = lines
        .iter()
        .filter(|l| l.starts_with("scenario P-199: "))
        .collect();
    assert_eq!(verdict.len(), 1, "one scenario line expected: {lines:?}");
    assert!(verdict[0].starts_with("scenario P-199: ok: "), "{}", verdict[0]);
    assert!(
        serve.contains("restarted over the same parameter flash"),
        "serve did not restart"
    );
    assert!(status.success(), "params.py failed ({status})");
}
