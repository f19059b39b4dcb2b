//! The checked-in GSDML as a real controller's GSDML parser reads it:
//! profinet-py (`profinet.gsdml.load_gsdml`, tested with 0.6.6) must see the
//! identity, the DAP with its subslots and the 36 modules with their lengths,
//! and build the IO slots of the manual's example configuration (slot 1 =
//! "18 Word Output Data", slot 2 = "18 Word Input Data").
//!
//! `PROFINET_PY_PYTHON` names a python that imports `profinet` (e.g.
//! `pip install profinet-py==0.6.6` into a venv). Without the variable the
//! tests print why and pass without running; a `PROFINET_PY_PYTHON` that
//! cannot import profinet fails them.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use profinet::model::{self, DataModule, Direction};

/// Prints what profinet-py parsed, one fact a line:
/// `identity VENDOR DEVICE`, `dap ID MODULE_IDENT`, `dapsub IDENT IN OUT`,
/// `sys SUBSLOT IDENT`, `useable TARGET ALLOWED_SLOTS…`,
/// `module ID IDENT`, `sub MODULE_ID IDENT IN OUT`,
/// `slot SLOT SUBSLOT IN OUT MODULE_IDENT SUBMODULE_IDENT` (the example).
const SNIPPET: &str = r#"
import sys
from profinet.gsdml import load_gsdml
d = load_gsdml(sys.argv[1])
print("identity", d.vendor_id, d.device_id)
for dap in d.daps:
    print("dap", dap.id, dap.module_ident)
    for s in dap.submodules:
        print("dapsub", s.submodule_ident, s.input_length, s.output_length)
    for s in dap.system_submodules:
        print("sys", s.subslot_number, s.submodule_ident)
    for t in dap.useable_modules:
        print("useable", t, *dap.allowed_slots.get(t, []))
for m in d.modules.values():
    print("module", m.id, m.module_ident)
    for s in m.submodules:
        print("sub", m.id, s.submodule_ident, s.input_length, s.output_length)
for s in d.build_io_slots(slot_assignment={1: sys.argv[2], 2: sys.argv[3]}):
    print("slot", s.slot, s.subslot, s.input_length, s.output_length, s.module_ident, s.submodule_ident)
"#;

fn gsdml_path() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../gsdml")).join(gsdml::file_name())
}

/// One printed line: its keyword and fields.
type Line = (String, Vec<String>);

/// profinet-py's reading of the checked-in file, or why it cannot run.
fn parsed() -> &'static Result<Vec<Line>, String> {
    static PARSED: OnceLock<Result<Vec<Line>, String>> = OnceLock::new();
    PARSED.get_or_init(|| {
        let py = std::env::var_os("PROFINET_PY_PYTHON").ok_or(
            "PROFINET_PY_PYTHON is not set (a python with profinet-py, e.g. \
             PROFINET_PY_PYTHON=/tmp/pnvenv/bin/python)",
        )?;
        let show = Path::new(&py).display().to_string();
        let version = Command::new(&py)
            .args(["-c", "import profinet; print(profinet.__version__)"])
            .output()
            .unwrap_or_else(|e| panic!("PROFINET_PY_PYTHON={show}: {e}"));
        assert!(
            version.status.success(),
            "PROFINET_PY_PYTHON={show} cannot import profinet: {}",
            String::from_utf8_lossy(&version.stderr).trim()
        );
        println!(
            "profinet-py {} ({show})",
            String::from_utf8_lossy(&version.stdout).trim()
        );
        let example = |direction, words| gsdml::module_id(DataModule { direction, words });
        let out = Command::new(&py)
            .arg("-c")
            .arg(SNIPPET)
            .arg(gsdml_path())
            .arg(example(Direction::FromDrive, 18))
            .arg(example(Direction::ToDrive, 18))
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "profinet-py could not load the GSDML: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        );
        Ok(String::from_utf8(out.stdout)
            .unwrap()
            .lines()
            .map(|l| {
                let mut f = l.split_whitespace().map(str::to_string);
                (f.next().unwrap_or_default(), f.collect())
            })
            .collect())
    })
}

/// The lines with keyword `key`, or `None` (after saying why) when
/// profinet-py is not available.
fn lines(key: &str) -> Option<Vec<Vec<String>>> {
    match parsed() {
        Ok(all) => Some(
            all.iter()
                .filter(|(k, _)| k == key)
                .map(|(_, f)| f.clone())
                .collect(),
        ),
        Err(why) => {
            println!("skipped: {why}");
            None
        }
    }
}

fn n(s: &str) -> u64 {
    s.parse().unwrap_or_else(|_| panic!("not a number: {s}"))
}

#[test]
fn p025_profinet_py_loads_the_dap_and_identity() {
    let Some(identity) = lines("identity") else {
        return;
    };
    assert_eq!(
        identity,
        [vec![model::VENDOR_ID.to_string(), model::DEVICE_ID.to_string()]]
    );
    let daps = lines("dap").unwrap();
    assert_eq!(
        daps,
        [vec!["DAP_1".to_string(), model::DAP_MODULE_IDENT.to_string()]]
    );
    let subs = lines("dapsub").unwrap();
    assert_eq!(
        subs,
        [vec![
            model::DAP_SUBMODULE_IDENT.to_string(),
            "0".into(),
            "0".into()
        ]]
    );
    let sys: Vec<(u64, u64)> = lines("sys")
        .unwrap()
        .iter()
        .map(|f| (n(&f[0]), n(&f[1])))
        .collect();
    let want = [
        (0x8000, u64::from(model::INTERFACE_SUBMODULE_IDENT)),
        (0x8001, u64::from(model::port_submodule_ident(1))),
        (0x8002, u64::from(model::port_submodule_ident(2))),
    ];
    assert_eq!(sys, want);
}

#[test]
fn p026_profinet_py_sees_the_36_modules_with_their_lengths() {
    let Some(modules) = lines("module") else {
        return;
    };
    let idents: BTreeMap<String, u64> = modules.iter().map(|f| (f[0].clone(), n(&f[1]))).collect();
    let subs: BTreeMap<String, (u64, u64, u64)> = lines("sub")
        .unwrap()
        .iter()
        .map(|f| (f[0].clone(), (n(&f[1]), n(&f[2]), n(&f[3]))))
        .collect();
    let useable: BTreeMap<String, Vec<u64>> = lines("useable")
        .unwrap()
        .iter()
        .map(|f| (f[0].clone(), f[1..].iter().map(|s| n(s)).collect()))
        .collect();
    assert_eq!(idents.len(), 36);
    assert_eq!(subs.len(), 36);
    assert_eq!(useable.len(), 36);
    let slots: Vec<u64> = model::DATA_SLOTS.map(u64::from).collect();
    for m in DataModule::catalogue() {
        let id = gsdml::module_id(m);
        assert_eq!(idents[&id], u64::from(m.ident()), "{id}");
        let bytes = m.bytes() as u64;
        // profinet-py's input = device -> controller, output = controller -> device
        let (input, output) = match m.direction {
            Direction::FromDrive => (bytes, 0),
            Direction::ToDrive => (0, bytes),
        };
        assert_eq!(
            subs[&id],
            (u64::from(model::DATA_SUBMODULE_IDENT), input, output),
            "{id}"
        );
        assert_eq!(useable[&id], slots, "{id}");
    }
}

#[test]
fn p026_profinet_py_builds_the_manuals_example_slots() {
    let Some(slots) = lines("slot") else {
        return;
    };
    let got: Vec<Vec<u64>> = slots.iter().map(|f| f.iter().map(|s| n(s)).collect()).collect();
    let dap = u64::from(model::DAP_MODULE_IDENT);
    let out18 = DataModule {
        direction: Direction::FromDrive,
        words: 18,
    };
    let in18 = DataModule {
        direction: Direction::ToDrive,
        words: 18,
    };
    let data = u64::from(model::DATA_SUBMODULE_IDENT);
    let want: Vec<Vec<u64>> = vec![
        vec![0, 1, 0, 0, dap, u64::from(model::DAP_SUBMODULE_IDENT)],
        vec![0, 0x8000, 0, 0, dap, u64::from(model::INTERFACE_SUBMODULE_IDENT)],
        vec![0, 0x8001, 0, 0, dap, 0x8001],
        vec![0, 0x8002, 0, 0, dap, u64::from(model::port_submodule_ident(2))],
        // slot 1: "18 Word Output Data" at PLC inputs I 0…35
        vec![1, 1, 36, 0, u64::from(out18.ident()), data],
        // slot 2: "18 Word Input Data" at PLC outputs Q 0…35
        vec![2, 1, 0, 36, u64::from(in18.ident()), data],
    ];
    assert_eq!(got, want);
}
