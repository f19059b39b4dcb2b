//! The book's PNU reference (`docs/pnu.md`), generated from [`CATALOGUE`]:
//! the test `pnu_doc_is_current` keeps the file equal to what the catalogue
//! gives (`UPDATE_PNU_DOC=1 cargo test -p drive-pn pnu_doc_is_current`
//! rewrites it).

use super::pnu::{Jog, Source, Unit, CATALOGUE};
use core::fmt::Write;
use std::string::String;

fn unit(u: Unit) -> &'static str {
    match u {
        Unit::None => "",
        Unit::Position => "position (user units)",
        Unit::Velocity => "velocity (user units/s)",
        Unit::Acceleration => "acceleration (user units/s²)",
        Unit::Rpm => "rpm",
        Unit::RpmPerSecond => "rpm/s",
    }
}

fn source(s: Source, out: &mut String) -> core::fmt::Result {
    match s {
        Source::Object { index, sub } => write!(out, "object {index:04X}h:{sub:02X}h"),
        Source::SelectedRecord(f) => write!(out, "the selected positioning record: {f:?}"),
        Source::JogRecord(j, f) => {
            let j = match j {
                Jog::Both => "both",
                Jog::Positive => "positive",
                Jog::Negative => "negative",
            };
            write!(out, "jog record ({j}): {f:?}")
        }
        other => write!(out, "{other:?}"),
    }
}

/// The Markdown of `docs/pnu.md`.
pub fn render() -> Result<String, core::fmt::Error> {
    let mut out = String::new();
    writeln!(out, "# PROFINET parameter numbers (PNUs)\n")?;
    writeln!(
        out,
        "Generated from `CATALOGUE` in `crates/drive-pn/src/profile/pnu.rs` by the test \
         `pnu_doc_is_current` (`UPDATE_PNU_DOC=1 cargo test -p drive-pn pnu_doc_is_current` \
         rewrites this file). Do not edit by hand.\n"
    )?;
    writeln!(
        out,
        "A PNU is read and written by PKW in the cyclic channel and by the base mode parameter \
         access (record 0xB02E). The PNUs below are the profile's own; every object of the \
         [object dictionary](object-dictionary.md) is reached as well, under its CANopen index \
         (PNU = index, subindex = subindex), with the errors of [the codes chapter](codes.md). \
         **Source** says where a PNU's value lives: an object of the dictionary (one value, two \
         names), a field of a positioning or jog record, or the profile itself.\n"
    )?;
    writeln!(out, "| PNU | Sub | Name | Type | Access | Unit | Source |")?;
    writeln!(out, "|---|---|---|---|---|---|---|")?;
    for p in CATALOGUE {
        let access = match (p.readable, p.writable) {
            (true, true) => "rw",
            (true, false) => "ro",
            (false, true) => "wo",
            (false, false) => "-",
        };
        let mut src = String::new();
        source(p.source, &mut src)?;
        writeln!(
            out,
            "| {} | {} | {} | {:?} | {} | {} | {} |",
            p.addr.index,
            p.addr.sub,
            p.name,
            p.data_type,
            access,
            unit(p.unit),
            src
        )?;
    }
    Ok(out)
}

#[test]
fn pnu_doc_is_current() {
    let text = render().unwrap();
    let docs = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs"));
    let cmd = "cargo test -p drive-pn pnu_doc_is_current";
    let check = desc_xml::check_file_current(docs, "pnu.md", &text, "UPDATE_PNU_DOC", cmd);
    assert_eq!(check, Ok(()));
}
