//! The spec-name walk (issue 40): every manufacturer parameter the spec's
//! parameter glossary names (`shared/spec/cia402.md` §16:
//! `| A44 | 0x202C | … |`) is declared at that index, which
//! is the manual's coordinate `parameter_index(group, line)`, or it is listed
//! in `docs/conformance.md` ("Spec parameters not declared") with a reason.

use crate::objects;
use crate::parameter_index;
use std::path::PathBuf;
use std::string::String;
use std::vec::Vec;

/// The spec: `DRIVE_SPEC_DIR`, else `../shared/spec` beside the workspace
/// (as CI lays it out).
fn spec_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("DRIVE_SPEC_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/spec")));
    dir.join("cia402.md").is_file().then_some(dir)
}

/// `A44` → (group 0, line 44).
fn coordinate(name: &str) -> Option<(u16, u16)> {
    let mut chars = name.chars();
    let g = chars.next()?;
    let line: u16 = chars.as_str().parse().ok()?;
    let group = u16::try_from(u32::from(g).checked_sub(u32::from('A'))?).ok()?;
    (group < 26).then_some((group, line))
}

/// The rows of the glossary (§16): (parameter, index, spec line number);
/// parameters at line ≥ 512 ("–", no CoE index) are left out.
fn rows(text: &str) -> Vec<(String, u16, usize)> {
    let mut out = Vec::new();
    let mut inside = false;
    for (n, line) in text.lines().enumerate() {
        if line.starts_with("## ") {
            inside = line.contains("Parameter glossary");
            continue;
        }
        if !inside {
            continue;
        }
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let [_, names, indices, ..] = cells.as_slice() else {
            continue;
        };
        if !indices.starts_with("0x") {
            continue;
        }
        let names: Vec<&str> = names.split('/').map(str::trim).collect();
        let indices: Vec<&str> = indices.split('/').map(str::trim).collect();
        assert_eq!(names.len(), indices.len(), "cia402.md:{}: {line}", n + 1);
        for (p, i) in names.iter().zip(indices) {
            let index = u16::from_str_radix(i.trim_start_matches("0x"), 16)
                .unwrap_or_else(|_| panic!("cia402.md:{}: index {i}", n + 1));
            out.push((String::from(*p), index, n + 1));
        }
    }
    out
}

/// The parameters docs/conformance.md lists as not declared: lines
/// "- `B26` …" under the heading "Spec parameters not declared".
fn listed_as_not_declared() -> Vec<String> {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/conformance.md"))
        .expect("docs/conformance.md");
    let Some(start) = text.find("### Spec parameters not declared") else {
        return Vec::new();
    };
    text[start..]
        .lines()
        .skip(1)
        .take_while(|l| !l.starts_with('#'))
        .filter_map(|l| {
            let rest = l.strip_prefix("- `")?;
            let (name, reason) = rest.split_once('`')?;
            // a reason is required
            (reason.trim_start_matches(':').trim().len() > 10).then(|| String::from(name))
        })
        .collect()
}

#[test]
fn spec_parameter_table_is_declared_or_listed() {
    let Some(dir) = spec_dir() else {
        std::println!("skipped: no spec (set DRIVE_SPEC_DIR or lay ../shared beside the workspace)");
        return;
    };
    let text = std::fs::read_to_string(dir.join("cia402.md")).expect("cia402.md");
    let rows = rows(&text);
    assert!(rows.len() > 60, "the table was found: {} parameters", rows.len());
    let listed = listed_as_not_declared();
    let mut missing = Vec::new();
    for (name, index, line) in &rows {
        let (group, l) = coordinate(name).unwrap_or_else(|| panic!("cia402.md:{line}: {name}"));
        assert_eq!(
            parameter_index(group, l),
            *index,
            "cia402.md:{line}: {name} is not at 2000h + group·200h + line"
        );
        let declared = objects::find(*index).is_some_and(|(_, o)| !o.info.name.is_empty());
        let is_listed = listed.iter().any(|n| n == name);
        assert!(
            !(declared && is_listed),
            "{name} is declared and still listed in docs/conformance.md as not declared"
        );
        if !declared && !is_listed {
            missing.push(std::format!("{name} ({index:#06x}, cia402.md:{line})"));
        }
    }
    assert!(missing.is_empty(), "neither declared nor listed: {missing:?}");
}
