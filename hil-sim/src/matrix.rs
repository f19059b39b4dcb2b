//! The fault matrix (issue 19, `docs/fault-matrix.md`): a test that checks
//! a fault case ends it with [`fault_row!`](crate::fault_row), which asserts that what the
//! test saw is what the case expects and leaves the row in
//! `target/tmp/fault-matrix/`; `scripts/fault-matrix` prints the rows as a
//! table (CI) and checks the table in the docs against them.
//!
//! A row is the case (what happened), the spec items it checks, the
//! expected end (state, AL status code, EMCY, 603Fh, diagnosis, what must
//! not be lost) and the end the test saw, written in the same words from
//! the values the test read, so a different end is a different text.

use std::path::Path;

/// One row of the fault matrix.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Row<'a> {
    /// Position in the table (rows sort by it).
    pub order: &'a str,
    /// The fault case.
    pub case: &'a str,
    /// The spec items checked.
    pub spec: &'a str,
    /// The peer that ran it (e.g. "ethercrab").
    pub peer: &'a str,
    /// The specified end.
    pub expected: &'a str,
}

/// Asserts `seen == row.expected` and writes the row (tab-separated, with
/// the test's name) to `dir/<order>.tsv`.
pub fn record(dir: &str, test: &str, row: &Row<'_>, seen: &str) {
    assert_eq!(
        seen, row.expected,
        "fault matrix {} ({}): {}",
        row.order, row.spec, row.case
    );
    let dir = Path::new(dir).join("fault-matrix");
    std::fs::create_dir_all(&dir).expect("fault-matrix dir");
    let clean = |s: &str| s.replace(['\t', '\n'], " ");
    let text = [row.order, row.case, row.spec, row.peer, row.expected, seen, test]
        .map(clean)
        .join("\t");
    std::fs::write(dir.join(format!("{}.tsv", row.order)), text + "\n").expect("write row");
}

/// `fault_row!(row, seen)`: [`record`] from an integration test (its
/// `CARGO_TARGET_TMPDIR` and the calling function's name).
#[macro_export]
macro_rules! fault_row {
    ($row:expr, $seen:expr) => {{
        fn here() {}
        let name = ::core::any::type_name_of_val(&here);
        let name = name.strip_suffix("::here").unwrap_or(name);
        let name = name.rsplit("::").next().unwrap_or(name);
        $crate::matrix::record(env!("CARGO_TARGET_TMPDIR"), name, &$row, &$seen)
    }};
}

/// "Op", "Safe-Op + ERR" … of an AL status (0x0130) value.
pub fn al_state(status: u16) -> String {
    let state = match status & 0x0F {
        1 => "Init",
        2 => "Pre-Op",
        3 => "Bootstrap",
        4 => "Safe-Op",
        8 => "Op",
        _ => "?",
    };
    if status & 0x10 != 0 {
        format!("{state} + ERR")
    } else {
        state.to_string()
    }
}

/// "Op, AL 0000h" from (AL status, AL status code).
pub fn al(status: (u16, u16)) -> String {
    format!("{}, AL {:04X}h", al_state(status.0), status.1)
}

/// The CiA 402 state name of a statusword ([`cia402::State::name`]);
/// "Not ready" for Not ready to switch on and a statusword of no state.
pub fn cia402_state(sw: u16) -> &'static str {
    match cia402::State::from_statusword(sw) {
        None | Some(cia402::State::NotReadyToSwitchOn) => "Not ready",
        Some(s) => s.name(),
    }
}

/// "EMCY 7500h/10h event 52 cause 6" for each EMCY (8 bytes), "no EMCY"
/// for none.
pub fn emcys(list: &[Vec<u8>]) -> String {
    if list.is_empty() {
        return "no EMCY".into();
    }
    let one = |e: &Vec<u8>| match e.as_slice() {
        [c0, c1, reg, ev, cause, ..] => format!(
            "EMCY {:04X}h/{reg:02X}h event {ev} cause {cause}",
            u16::from_le_bytes([*c0, *c1])
        ),
        _ => format!("EMCY {e:02x?}"),
    };
    list.iter().map(one).collect::<Vec<_>>().join(" + ")
}
