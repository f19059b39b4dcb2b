//! The object-dictionary reference, generated from the declaration
//! (`docs/object-dictionary.md`; the test `od_doc_is_current` keeps the file
//! current, `UPDATE_OD_DOC=1 cargo test -p drive-core` rewrites it).

use crate::objects::{Object, Value, OBJECTS};
use crate::{AXIS_B_CIA402, AXIS_B_MANUFACTURER};
use core::fmt::{self, Write};
use od::{DataType, EntryInfo, ObjectCode};

/// Writes the reference as Markdown.
pub fn write_reference(w: &mut impl Write) -> fmt::Result {
    w.write_str(HEADER)?;
    section(w, "Communication area 1000h–1FFFh", 0x1000..0x2000)?;
    section(
        w,
        "Manufacturer parameters, axis A and global, 2000h–5FFFh",
        0x2000..0x6000,
    )?;
    section(w, "CiA 402, axis A, 6000h–65FFh", 0x6000..0x6600)?;
    copies(w, "CiA 402, axis B, 6800h–6DFFh", 0x6800..0x6E00, AXIS_B_CIA402)?;
    copies(
        w,
        "Manufacturer parameters, axis B, A000h–DFFFh",
        0xA000..0xE000,
        AXIS_B_MANUFACTURER,
    )?;
    section(w, "Modular device profile, F000h–FFFEh", 0xF000..0xFFFF)?;
    single_axis(w)?;
    scaling(w)
}

/// The single-axis device ([`crate::Variant::Single`]): what it leaves out
/// and what it declares differently ([`crate::objects::single`]).
fn single_axis(w: &mut impl Write) -> fmt::Result {
    w.write_str(
        "\n## The single-axis device (SI6A061)\n\n\
         The single-axis device (`Variant::Single`, `DriveObjects::for_variant`) has every object \
         above except axis B's, 6800h–6FFFh and A000h–DFFFh (0602 0000h, \
         not in the SDO Info lists, not mappable: 0604 0041h), and declares these entries differently \
         (`crates/drive-core/src/objects/single.rs`); its RAM image has the same layout.\n\n\
         | Index | Sub | Name | Double-axis device | Single-axis device | Notes |\n|---|---|---|---|---|---|\n",
    )?;
    for r in crate::Variant::Single.redeclared() {
        let Some((_, o)) = crate::objects::find(r.info.index) else {
            continue;
        };
        let notes = Notes(r);
        if let (Value::Text(a), Value::Text(b)) = (o.value, r.value) {
            writeln!(
                w,
                "| {:04X}h | 00h | {} | \"{a}\" | \"{b}\" | {notes} |",
                r.info.index, r.info.name
            )?;
        }
        // the entries whose defaults differ, one row per object
        let differ = || {
            o.info
                .entries
                .iter()
                .zip(r.info.entries.iter())
                .filter(|(a, b)| a.default != b.default)
        };
        let (Some((_, first)), Some((_, last))) = (differ().next(), differ().next_back()) else {
            continue;
        };
        write!(w, "| {:04X}h | {:02X}h", r.info.index, first.sub)?;
        if last.sub != first.sub {
            write!(w, "–{:02X}h", last.sub)?;
        }
        write!(w, " | {}", first.name)?;
        if last.sub != first.sub {
            write!(w, " … {}", last.name)?;
        }
        for single in [false, true] {
            w.write_str(" | ")?;
            for (k, (a, b)) in differ().enumerate() {
                let e = if single { b } else { a };
                let sep = if k == 0 { "" } else { ", " };
                write!(w, "{sep}{}", Num(&e, e.default))?;
            }
        }
        writeln!(w, " | {notes} |")?;
    }
    Ok(())
}

/// The entries fieldbus scaling acts on ([`crate::objects::scaling`]).
fn scaling(w: &mut impl Write) -> fmt::Result {
    w.write_str(
        "\n## Fieldbus scaling (A213)\n\n\
         With A213 = 1 \"native\" (the default) these entries count in the user units of their axis \
         (6091h/6092h; the unit column names the default, increments); with A213 = 0 \"integer with \
         decimal places\" in user units / 10^A310 (velocities) or / 10^A311 (accelerations, \
         decelerations, jerk) of their axis. A213[0] is the representation of the process data and \
         of the values the dictionary keeps (the axis converts them); A213[1] that of the parameter \
         channel (SDO, UDP parameter service), converted from the kept value when the two differ. \
         Axis B's entries are at +800h (CiA 402) and +8000h (group J). Every other entry has a fixed \
         unit; positions take decimal places through the feed constant 6092h.\n\n\
         | Index | Sub | Name | Decimal places |\n|---|---|---|---|\n",
    )?;
    for (index, sub, q) in crate::objects::scaling::SCALED {
        let name = crate::objects::find(index)
            .and_then(|(_, o)| o.info.entry(sub))
            .map_or("", |e| e.name);
        let decimals = match q {
            crate::objects::scaling::Quantity::Velocity => "A310",
            crate::objects::scaling::Quantity::Acceleration => "A311",
        };
        writeln!(w, "| {index:04X}h | {sub:02X}h | {name} | {decimals} |")?;
    }
    Ok(())
}

const HEADER: &str = "# Object dictionary

Generated from the declaration in `crates/drive-core/src/objects/` by the test `od_doc_is_current`
(`UPDATE_OD_DOC=1 cargo test -p drive-core od_doc_is_current` rewrites this file). Do not edit by hand.

- **Sub**: subindex in the default template \"EtherCAT Rx SDO Info\". In the template \"EtherCAT Rx\"
  the elements of manufacturer arrays and records are at subindex = element number (one lower)
  and sub 0 is element 0 (spec §2.6).
- **Access**: ro, rw, wo; \"rw PreOp\" = written in Pre-Operational only (0800 0022h otherwise).
- **PDO**: Rx = RxPDO-mappable, Tx = TxPDO-mappable.
- **Saved**: saved by 1010h / A00 and restored by 1011h (defaults).
- **Value**: const = declared constant; RAM = RAM image; live = owned by another part of the
  firmware (fed through `DriveObjects::set` or a `LiveValues` provider); command = write-only
  action; = X = the same value as object X.
- **Level**: access level A10[2] needed to see the object (hidden objects: 0602 0000h).
";

fn section(w: &mut impl Write, title: &str, range: core::ops::Range<u16>) -> fmt::Result {
    write!(w, "\n## {title}\n\n")?;
    w.write_str("| Index | Sub | Name | Type | Access | PDO | Range | Default | Unit | Saved | Value, level, notes |\n")?;
    w.write_str("|---|---|---|---|---|---|---|---|---|---|---|\n")?;
    for o in OBJECTS.iter().filter(|o| range.contains(&o.info.index)) {
        object(w, o)?;
    }
    Ok(())
}

fn copies(w: &mut impl Write, title: &str, range: core::ops::Range<u16>, by: u16) -> fmt::Result {
    write!(
        w,
        "\n## {title}\n\nEvery object below repeats the axis-A object at index − {by:X}h with the same entries, \
         types, access, PDO mapping, ranges and defaults, and its own values.\n\n"
    )?;
    w.write_str("| Index | Axis A | Name |\n|---|---|---|\n")?;
    for o in OBJECTS.iter().filter(|o| range.contains(&o.info.index)) {
        writeln!(
            w,
            "| {:04X}h | {:04X}h | {} |",
            o.info.index,
            o.info.index - by,
            o.info.name
        )?;
    }
    Ok(())
}

fn object(w: &mut impl Write, o: &Object) -> fmt::Result {
    let notes = Notes(o);
    match (o.info.code, o.info.entries.get(0)) {
        (ObjectCode::Var, Some(e)) if o.info.entries.len() == 1 => {
            write!(w, "| {:04X}h ", o.info.index)?;
            entry(w, o, &e, &notes)
        }
        (code, _) => {
            let code = match code {
                ObjectCode::Var => "VAR",
                ObjectCode::Array => "ARRAY",
                ObjectCode::Record => "RECORD",
            };
            writeln!(
                w,
                "| {:04X}h | | **{}** | {code} | | | | | | | {notes} |",
                o.info.index, o.info.name
            )?;
            for e in o.info.entries {
                w.write_str("| ")?;
                entry(w, o, &e, &"")?;
            }
            Ok(())
        }
    }
}

fn entry(w: &mut impl Write, o: &Object, e: &EntryInfo, notes: &dyn fmt::Display) -> fmt::Result {
    let a = e.access;
    let access = match (a.readable(), a.writable(), a.writable_in(1)) {
        (true, false, _) => "ro",
        (false, _, _) => "wo",
        (true, true, true) => "rw",
        (true, true, false) => "rw PreOp",
    };
    let pdo = match (a.rx_mappable(), a.tx_mappable()) {
        (true, true) => "Rx/Tx",
        (true, false) => "Rx",
        (false, true) => "Tx",
        (false, false) => "",
    };
    write!(
        w,
        "| {:02X}h | {} | {} | {access} | {pdo} | ",
        e.sub,
        e.name,
        TypeName(e.data_type)
    )?;
    match (e.min, e.max) {
        (Some(min), Some(max)) => write!(w, "{}…{}", Num(e, min), Num(e, max))?,
        (Some(min), None) => write!(w, "≥ {}", Num(e, min))?,
        (None, Some(max)) => write!(w, "≤ {}", Num(e, max))?,
        (None, None) => {}
    }
    match o.value {
        Value::Text(s) => write!(w, " | \"{s}\"")?,
        _ if e.data_type.is_string() => w.write_str(" | ")?,
        _ => write!(w, " | {}", Num(e, e.default))?,
    }
    let saved = if e.persistent { "yes" } else { "" };
    writeln!(w, " | {} | {saved} | {notes} |", e.unit)
}

/// The object-level notes: value kind, level, reference note.
struct Notes<'a>(&'a Object);

impl fmt::Display for Notes<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let o = self.0;
        match o.value {
            Value::Const | Value::Text(_) => f.write_str("const")?,
            Value::Identity => f.write_str("const")?,
            Value::Ram => f.write_str("RAM")?,
            Value::Live => f.write_str("live")?,
            Value::Provided => f.write_str("runtime")?,
            Value::Command => f.write_str("command")?,
            Value::Mirror { index, .. } => write!(f, "= {index:04X}h")?,
            Value::Alias(list) => {
                f.write_str("=")?;
                for (i, (index, sub)) in list.iter().filter(|(i, _)| *i != 0).enumerate() {
                    let sep = if i == 0 { " " } else { ", " };
                    write!(f, "{sep}{index:04X}h:{sub:02X}h")?;
                }
            }
        }
        if o.level > 0 {
            write!(f, "; level {}", o.level)?;
        }
        if !o.note.is_empty() {
            f.write_str("; ")?;
            for part in o.note.split('|') {
                if !core::ptr::eq(part.as_ptr(), o.note.as_ptr()) {
                    f.write_str("\\|")?;
                }
                f.write_str(part)?;
            }
        }
        Ok(())
    }
}

/// A value of entry `e`: hexadecimal for unsigned values ≥ 100h without a
/// unit (bit fields, mapping entries), decimal otherwise.
struct Num<'a>(&'a EntryInfo, i64);

impl fmt::Display for Num<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Num(e, v) = *self;
        if !e.data_type.signed() && e.unit.is_empty() && v >= 0x100 {
            write!(f, "{v:X}h")
        } else {
            write!(f, "{v}")
        }
    }
}

struct TypeName(DataType);

impl fmt::Display for TypeName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            DataType::Bool => f.write_str("BOOL"),
            DataType::I8 => f.write_str("INT8"),
            DataType::I16 => f.write_str("INT16"),
            DataType::I32 => f.write_str("INT32"),
            DataType::I64 => f.write_str("INT64"),
            DataType::U8 => f.write_str("UINT8"),
            DataType::U16 => f.write_str("UINT16"),
            DataType::U32 => f.write_str("UINT32"),
            DataType::U64 => f.write_str("UINT64"),
            DataType::F32 => f.write_str("REAL32"),
            DataType::VisibleString(n) => write!(f, "STRING({n})"),
            DataType::OctetString(n) => write!(f, "OCTET_STRING({n})"),
        }
    }
}
