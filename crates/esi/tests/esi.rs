//! The generated ESI files: current on disk (CI fails on drift), and, parsed
//! back with a real XML parser (roxmltree), consistent with the SII image
//! and the object dictionary of each subindex template.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;

use drive_ecat::{revision, Template, Variant};
use ecat::sii::{categories, find_category, records, sii_string, sii_word};
use esc::sii::{category, word};
use od::{CommState, DataType, Dictionary};
use roxmltree::{Document, Node};

fn esi_dir() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../esi"))
}

/// A "#x…" hexadecimal or decimal number (ETG.2000 HexDecValue).
fn num(s: &str) -> u64 {
    let s = s.trim();
    match s.strip_prefix("#x") {
        Some(h) => u64::from_str_radix(h, 16).unwrap_or_else(|_| panic!("bad hex {s}")),
        None => s.parse().unwrap_or_else(|_| panic!("bad number {s}")),
    }
}

fn hex_bytes(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
        .collect()
}

fn child<'a, 'i>(n: Node<'a, 'i>, tag: &str) -> Node<'a, 'i> {
    n.children()
        .find(|c| c.has_tag_name(tag))
        .unwrap_or_else(|| panic!("<{}> has no <{tag}>", n.tag_name().name()))
}

fn opt_child<'a, 'i>(n: Node<'a, 'i>, tag: &str) -> Option<Node<'a, 'i>> {
    n.children().find(|c| c.has_tag_name(tag))
}

fn children<'a, 'i>(n: Node<'a, 'i>, tag: &'static str) -> impl Iterator<Item = Node<'a, 'i>> {
    n.children().filter(move |c| c.has_tag_name(tag))
}

fn text<'a>(n: Node<'a, '_>, tag: &str) -> &'a str {
    child(n, tag).text().unwrap_or("")
}

fn device_node<'a, 'i>(doc: &'a Document<'i>) -> Node<'a, 'i> {
    child(
        child(child(doc.root_element(), "Descriptions"), "Devices"),
        "Device",
    )
}

/// The `<Modules>` of the file (E-149).
fn modules<'a, 'i>(doc: &'a Document<'i>) -> Vec<Node<'a, 'i>> {
    children(
        child(child(doc.root_element(), "Descriptions"), "Modules"),
        "Module",
    )
    .collect()
}

/// The ident of a `<Module>`.
fn module_ident(m: Node) -> u32 {
    num(child(m, "Type").attribute("ModuleIdent").unwrap()) as u32
}

/// The `<Slot>`s of the device.
fn slots<'a, 'i>(dev: Node<'a, 'i>) -> Vec<Node<'a, 'i>> {
    children(child(dev, "Slots"), "Slot").collect()
}

/// A PDO's entries as mapping values (index << 16 | sub << 8 | bit length).
fn mapped(pdo: Node) -> Vec<u32> {
    children(pdo, "Entry")
        .map(|e| {
            (num(text(e, "Index")) << 16 | num(text(e, "SubIndex")) << 8 | num(text(e, "BitLen"))) as u32
        })
        .collect()
}

/// The ESI text of `variant` in `template`, as generated (the drift test
/// keeps the files equal).
fn esi(variant: Variant, template: Template) -> String {
    esi::generate(variant, template).unwrap()
}

/// Every (device, template) pair with an ESI.
fn each() -> Vec<(Variant, Template)> {
    esi::VARIANTS
        .iter()
        .flat_map(|&v| esi::TEMPLATES.iter().map(move |&t| (v, t)))
        .collect()
}

#[test]
fn esi_files_are_current() {
    let files = esi::files().unwrap();
    let check = desc_xml::check_current(
        &esi_dir(),
        &files,
        "UPDATE_ESI",
        "cargo test -p esi esi_files_are_current",
    );
    assert_eq!(check, Ok(()));
}

#[test]
fn e150_one_esi_per_template_with_its_own_revision() {
    let files = esi::files().unwrap();
    assert_eq!(files.len(), 4, "two devices, two templates each");
    let names: BTreeSet<&str> = files.iter().map(|f| f.0.as_str()).collect();
    assert_eq!(names.len(), 4);
    for v in esi::VARIANTS {
        let mut revisions = BTreeSet::new();
        for t in esi::TEMPLATES {
            let xml = esi(v, t);
            let doc = Document::parse(&xml).unwrap();
            let dev = device_node(&doc);
            let rev = num(child(dev, "Type").attribute("RevisionNo").unwrap());
            revisions.insert(rev);
            assert!(text_of(dev, "Name").contains(esi::template_name(t)));
            // SDO Information only in "EtherCAT Rx SDO Info" (spec §6.1)
            let coe = child(child(dev, "Mailbox"), "CoE");
            let sdo_info = t == Template::SdoInfo;
            assert_eq!(coe.attribute("SdoInfo"), Some(if sdo_info { "1" } else { "0" }));
            // the template's subindex numbering: A10 (2000h + 10) has sub 0 =
            // element count in SDO Info, sub 0 = element 0 in Rx
            let a10 = drive_ecat::parameter_index(0, 10);
            let dt = data_type(child(dev, "Profile"), &format!("DT{a10:04X}"));
            let sub0 = children(dt, "SubItem").next().unwrap();
            let name = text(sub0, "Name");
            if sdo_info {
                assert_eq!(name, "Highest subindex supported");
            } else {
                assert_eq!(name, "Operating unit");
            }
        }
        assert_eq!(revisions.len(), 2, "each template has its own revision number");
    }
}

fn text_of(n: Node, tag: &str) -> String {
    text(n, tag).to_string()
}

#[test]
fn e151_esi_revision_equals_1018_03() {
    for (v, t) in each() {
        let mut od = esi::dictionary(v, t);
        let mut buf = [0u8; 4];
        assert_eq!(od.read(0x1018, 3, &mut buf, CommState::PreOp), Ok(4));
        let od_rev = u32::from_le_bytes(buf);
        assert_eq!(od_rev, revision(t));

        let xml = esi(v, t);
        let doc = Document::parse(&xml).unwrap();
        let dev = device_node(&doc);
        assert_eq!(
            num(child(dev, "Type").attribute("RevisionNo").unwrap()),
            u64::from(od_rev),
            "ESI RevisionNo = 1018h:03 in {t:?}"
        );
        // the SII of that template carries the same revision
        let img = esi::sii(v, t).unwrap();
        let sii_rev = u32::from(sii_word(&img, word::REVISION).unwrap())
            | u32::from(sii_word(&img, word::REVISION + 1).unwrap()) << 16;
        assert_eq!(sii_rev, od_rev);
        // and the ESI dictionary's default of 1018h:03 too
        let ident = object(child(dev, "Profile"), 0x1018);
        let info = children(child(ident, "Info"), "SubItem")
            .find(|s| text(*s, "Name") == "Revision number")
            .unwrap();
        let default = hex_bytes(text(child(info, "Info"), "DefaultData"));
        assert_eq!(default, od_rev.to_le_bytes());
    }
    // the default template's SII is the one the drive carries (drive_ecat::device)
    for v in esi::VARIANTS {
        assert_eq!(esi::device(v, Template::SdoInfo), *drive_ecat::device(v));
    }
}

#[test]
fn e108_dc_sync0_is_the_default_op_mode() {
    for (v, t) in each() {
        let xml = esi(v, t);
        let doc = Document::parse(&xml).unwrap();
        let dc = child(device_node(&doc), "Dc");
        let modes: Vec<Node> = children(dc, "OpMode").collect();
        let first = modes[0];
        assert_eq!(
            num(text(first, "AssignActivate")),
            0x0300,
            "SYNC0 first = default"
        );
        assert!(text(first, "Desc").contains("SYNC0"));
        assert_eq!(child(first, "CycleTimeSync0").attribute("Factor"), Some("1"));
        assert_eq!(num(text(first, "CycleTimeSync0")), 0, "the master's cycle");
        let names: Vec<&str> = modes.iter().map(|m| text(*m, "Name")).collect();
        assert!(
            names.contains(&"SM-Synchron") && names.contains(&"FreeRun"),
            "{names:?}"
        );
        for m in &modes[1..] {
            assert_eq!(num(text(*m, "AssignActivate")), 0);
        }
    }
    // the SII's DC category follows the declaration order: SYNC0 first there too
    let first = drive_ecat::DEVICE
        .dc_modes
        .first()
        .map(|m| (m.assign_activate, m.sync0_cycle_factor));
    assert_eq!(first, Some((0x0300, 1)), "SII lists DC SYNC0 first");
}

#[test]
fn esi_matches_sii_image() {
    for (v, t) in each() {
        let img = esi::sii(v, t).unwrap();
        let w = |n: u16| u64::from(sii_word(&img, n).unwrap());
        let w32 = |n: u16| w(n) | w(n + 1) << 16;
        let xml = esi(v, t);
        let declared = drive_ecat::device(v);
        let doc = Document::parse(&xml).unwrap();
        let root = doc.root_element();
        let dev = device_node(&doc);

        // identity
        assert_eq!(num(text(child(root, "Vendor"), "Id")), w32(word::VENDOR_ID));
        let ty = child(dev, "Type");
        assert_eq!(num(ty.attribute("ProductCode").unwrap()), w32(word::PRODUCT_CODE));
        assert_eq!(num(ty.attribute("RevisionNo").unwrap()), w32(word::REVISION));
        let strings = find_category(&img, category::STRINGS).unwrap();
        let general = find_category(&img, category::GENERAL).unwrap();
        let s = |i: u8| std::str::from_utf8(sii_string(strings, i).unwrap()).unwrap();
        assert_eq!(ty.text(), Some(s(general[2])), "order code");
        assert_eq!(text(dev, "GroupType"), s(general[0]));
        assert!(text(dev, "Name").starts_with(s(general[3])));

        // SyncManagers: mailbox addresses and sizes, control bytes, start addresses
        let sms: Vec<Node> = children(dev, "Sm").collect();
        assert_eq!(sms.len(), 4);
        let sm_cat = find_category(&img, category::SYNC_MANAGER).unwrap();
        for (i, (sm, rec)) in sms.iter().zip(records(sm_cat, 8)).enumerate() {
            let start = u64::from(u16::from_le_bytes([rec[0], rec[1]]));
            let len = u64::from(u16::from_le_bytes([rec[2], rec[3]]));
            assert_eq!(num(sm.attribute("StartAddress").unwrap()), start, "SM{i}");
            assert_eq!(
                num(sm.attribute("ControlByte").unwrap()),
                u64::from(rec[4]),
                "SM{i}"
            );
            assert_eq!(sm.attribute("Enable"), Some("1"));
            if i < 2 {
                assert_eq!(num(sm.attribute("DefaultSize").unwrap()), len, "SM{i}");
            }
        }
        for (i, name, want) in [
            (0, "StartAddress", w(word::STD_RX_MAILBOX_OFFSET)),
            (0, "DefaultSize", w(word::STD_RX_MAILBOX_SIZE)),
            (1, "StartAddress", w(word::STD_TX_MAILBOX_OFFSET)),
            (1, "DefaultSize", w(word::STD_TX_MAILBOX_SIZE)),
            (2, "DefaultSize", declared.output_bytes() as u64),
            (3, "DefaultSize", declared.input_bytes() as u64),
        ] {
            assert_eq!(num(sms[i].attribute(name).unwrap()), want, "SM{i} {name}");
        }
        assert_eq!(
            sms.iter().map(|s| s.text().unwrap()).collect::<Vec<_>>(),
            ["MBoxOut", "MBoxIn", "Outputs", "Inputs"]
        );

        // FMMUs
        let fmmu_cat = find_category(&img, category::FMMU).unwrap();
        let fmmus: Vec<u8> = children(dev, "Fmmu")
            .map(|f| match f.text().unwrap_or("") {
                "Outputs" => 1,
                "Inputs" => 2,
                "MBoxState" => 3,
                _ => 0,
            })
            .collect();
        assert_eq!(&fmmus[..], &fmmu_cat[..fmmus.len()]);
        assert!(
            fmmu_cat[fmmus.len()..].iter().all(|&f| f == 0),
            "only unused FMMUs left out"
        );

        // EEPROM: size, ConfigData = the SII's first words, bootstrap mailbox
        let ee = child(dev, "Eeprom");
        assert_eq!(num(text(ee, "ByteSize")), (w(word::EEPROM_SIZE) + 1) * 128);
        let config = hex_bytes(text(ee, "ConfigData"));
        assert_eq!(config.len(), esi::CONFIG_DATA_BYTES);
        assert_eq!(&config[..], &img[..esi::CONFIG_DATA_BYTES]);
        let boot = hex_bytes(text(ee, "BootStrap"));
        let at = usize::from(word::BOOT_RX_MAILBOX_OFFSET) * 2;
        assert_eq!(&boot[..], &img[at..at + 8]);

        // mailbox protocols (SII word 1Ch) and CoE details (GENERAL byte 5)
        let mbx = child(dev, "Mailbox");
        let protocols = w(word::MAILBOX_PROTOCOL) as u16;
        for (tag, bit) in [("AoE", 1), ("EoE", 2), ("CoE", 4), ("FoE", 8), ("SoE", 16)] {
            assert_eq!(opt_child(mbx, tag).is_some(), protocols & bit != 0, "{tag}");
        }
        let coe = child(mbx, "CoE");
        let details = general[5];
        for (attr, bit) in [
            ("SdoInfo", 1 << 1),
            ("PdoAssign", 1 << 2),
            ("PdoConfig", 1 << 3),
            ("PdoUpload", 1 << 4),
            ("CompleteAccess", 1 << 5),
        ] {
            assert_eq!(coe.attribute(attr) == Some("1"), details & bit != 0, "CoE {attr}");
        }
        assert_eq!(general[6] != 0, opt_child(mbx, "FoE").is_some(), "FoE details");
        assert_eq!(general[7] != 0, opt_child(mbx, "EoE").is_some(), "EoE details");

        // PDOs: the SII's RXPDO/TXPDO categories
        for (tag, kind) in [("RxPdo", category::RXPDO), ("TxPdo", category::TXPDO)] {
            let cat = find_category(&img, kind).unwrap();
            let mut pos = 0;
            for pdo in children(dev, tag) {
                let head = &cat[pos..pos + 8];
                assert_eq!(
                    num(text(pdo, "Index")),
                    u64::from(u16::from_le_bytes([head[0], head[1]]))
                );
                let entries: Vec<Node> = children(pdo, "Entry").collect();
                assert_eq!(entries.len(), usize::from(head[2]));
                match pdo.attribute("Sm") {
                    Some(sm) => assert_eq!(num(sm), u64::from(head[3])),
                    None => assert_eq!(head[3], 0xFF),
                }
                assert_eq!(text(pdo, "Name"), s(head[5]));
                pos += 8;
                for e in entries {
                    let r = &cat[pos..pos + 8];
                    assert_eq!(num(text(e, "Index")), u64::from(u16::from_le_bytes([r[0], r[1]])));
                    assert_eq!(num(text(e, "SubIndex")), u64::from(r[2]));
                    assert_eq!(text(e, "Name"), s(r[3]));
                    assert_eq!(num(text(e, "BitLen")), u64::from(r[5]));
                    pos += 8;
                }
            }
            assert_eq!(pos, cat.len(), "{tag}: every SII PDO in the ESI");
        }

        // DC op modes: the same set as the SII's DC category
        let dc_cat = find_category(&img, category::DC).unwrap();
        let mut sii_modes: Vec<(String, u64)> = records(dc_cat, 24)
            .map(|r| {
                (
                    s(r[18]).to_string(),
                    u64::from(u16::from_le_bytes([r[14], r[15]])),
                )
            })
            .collect();
        let mut esi_modes: Vec<(String, u64)> = children(child(dev, "Dc"), "OpMode")
            .map(|m| (text(m, "Name").to_string(), num(text(m, "AssignActivate"))))
            .collect();
        sii_modes.sort();
        esi_modes.sort();
        assert_eq!(esi_modes, sii_modes);
        assert!(categories(&img).count() >= 6);
    }
}

fn data_type<'a, 'i>(profile: Node<'a, 'i>, name: &str) -> Node<'a, 'i> {
    children(child(child(profile, "Dictionary"), "DataTypes"), "DataType")
        .find(|d| text(*d, "Name") == name)
        .unwrap_or_else(|| panic!("no DataType {name}"))
}

fn object<'a, 'i>(profile: Node<'a, 'i>, index: u16) -> Node<'a, 'i> {
    children(child(child(profile, "Dictionary"), "Objects"), "Object")
        .find(|o| num(text(*o, "Index")) == u64::from(index))
        .unwrap_or_else(|| panic!("no Object {index:04X}h"))
}

/// The ESI type name of `t`, written out independently of the generator.
fn expected_type(t: DataType) -> String {
    match t {
        DataType::Bool => "BOOL".into(),
        DataType::I8 => "SINT".into(),
        DataType::I16 => "INT".into(),
        DataType::I32 => "DINT".into(),
        DataType::I64 => "LINT".into(),
        DataType::U8 => "USINT".into(),
        DataType::U16 => "UINT".into(),
        DataType::U32 => "UDINT".into(),
        DataType::U64 => "ULINT".into(),
        DataType::F32 => "REAL".into(),
        DataType::VisibleString(n) => format!("STRING({n})"),
        DataType::OctetString(n) => format!("ARRAY [0..{}] OF BYTE", n - 1),
    }
}

/// Checks an ESI `Flags` element against access rights `a`.
fn check_flags(flags: Node, a: od::Access, persistent: bool, what: &str) {
    let backup = opt_child(flags, "Backup").and_then(|b| b.text()) == Some("1");
    assert_eq!(backup, persistent, "{what}: backup");
    let access = child(flags, "Access");
    let expected = match (a.readable(), a.writable()) {
        (true, false) => "ro",
        (false, _) => "wo",
        (true, true) => "rw",
    };
    assert_eq!(access.text(), Some(expected), "{what}: access");
    let preop_only = a.readable() && a.writable_in(0) && !a.writable_in(1) && !a.writable_in(2);
    assert_eq!(
        access.attribute("WriteRestrictions") == Some("PreOP"),
        preop_only,
        "{what}: PreOp"
    );
    let mapping = opt_child(flags, "PdoMapping")
        .and_then(|m| m.text())
        .unwrap_or("");
    assert_eq!(mapping.contains('R'), a.rx_mappable(), "{what}: RxPDO mapping");
    assert_eq!(mapping.contains('T'), a.tx_mappable(), "{what}: TxPDO mapping");
}

#[test]
fn esi_dictionary_matches_od() {
    for (v, t) in each() {
        let od = esi::dictionary(v, t);
        let xml = esi(v, t);
        let doc = Document::parse(&xml).unwrap();
        let dev = device_node(&doc);
        let profile = child(dev, "Profile");
        assert_eq!(
            num(text(profile, "ProfileNo")),
            u64::from(drive_ecat::device(v).device_type & 0xFFFF)
        );
        let dict = child(profile, "Dictionary");
        let types: BTreeMap<&str, Node> = children(child(dict, "DataTypes"), "DataType")
            .map(|d| (text(d, "Name"), d))
            .collect();
        let listed: Vec<Node> = children(child(dict, "Objects"), "Object").collect();

        // every visible object, in order, and nothing else
        let mut visible = Vec::new();
        let mut after = None;
        while let Some(o) = od.next_object(after) {
            visible.push(o);
            after = Some(o.index);
        }
        assert_eq!(listed.len(), visible.len(), "{t:?}: object count");
        assert!(visible.len() > 100);

        for (node, o) in listed.iter().zip(&visible) {
            let what = format!("{v:?} {t:?} {:04X}h", o.index);
            assert_eq!(num(text(*node, "Index")), u64::from(o.index), "{what}");
            assert_eq!(text(*node, "Name"), o.name, "{what}");
            let ty = text(*node, "Type");
            let var =
                o.code == od::ObjectCode::Var && o.entries.len() == 1 && o.entries.get(0).unwrap().sub == 0;
            if var {
                let e = &o.entries.get(0).unwrap();
                assert_eq!(ty, expected_type(e.data_type), "{what}");
                assert_eq!(num(text(*node, "BitSize")), u64::from(e.bit_len()), "{what}");
                assert!(types.contains_key(ty), "{what}: type {ty} declared");
                check_flags(child(*node, "Flags"), e.access, e.persistent, &what);
                continue;
            }
            let dt = types
                .get(ty)
                .unwrap_or_else(|| panic!("{what}: no DataType {ty}"));
            assert_eq!(text(*dt, "BitSize"), text(*node, "BitSize"), "{what}");
            let subs: Vec<Node> = children(*dt, "SubItem").collect();
            assert_eq!(subs.len(), o.entries.len(), "{what}: entries");
            let infos: Vec<Node> = children(child(*node, "Info"), "SubItem").collect();
            assert_eq!(infos.len(), o.entries.len(), "{what}: defaults");
            let mut end = 0;
            for ((s, e), info) in subs.iter().zip(o.entries).zip(&infos) {
                let what = format!("{what}:{:02X}h", e.sub);
                assert_eq!(num(text(*s, "SubIdx")), u64::from(e.sub), "{what}");
                assert_eq!(text(*s, "Name"), e.name, "{what}");
                assert_eq!(text(*info, "Name"), e.name, "{what}");
                let sty = text(*s, "Type");
                assert_eq!(sty, expected_type(e.data_type), "{what}");
                assert!(types.contains_key(sty), "{what}: type {sty} declared");
                assert_eq!(num(text(*s, "BitSize")), u64::from(e.bit_len()), "{what}");
                let offs = num(text(*s, "BitOffs"));
                assert!(offs >= end, "{what}: overlapping bit offsets");
                end = offs + u64::from(e.bit_len());
                check_flags(child(*s, "Flags"), e.access, e.persistent, &what);
                // numeric defaults: the declared default (1018h:03: the revision)
                if !e.data_type.is_string() {
                    let data = hex_bytes(text(child(*info, "Info"), "DefaultData"));
                    assert_eq!(data.len(), e.data_type.bytes(), "{what}");
                    let v = e.data_type.decode(&data).unwrap();
                    let expected = if o.index == 0x1018 && e.sub == 3 {
                        i64::from(revision(t))
                    } else {
                        e.default
                    };
                    let mask = if e.data_type.bits() >= 64 {
                        u64::MAX
                    } else {
                        (1 << e.data_type.bits().max(8)) - 1
                    };
                    assert_eq!(v as u64 & mask, expected as u64 & mask, "{what}: default");
                }
            }
            assert!(end <= num(text(*node, "BitSize")), "{what}: size");
        }
    }
}

/// Every PDO the ESI describes, at device level and in every module (E-149):
/// its entries are the declared ones (the device's PDO, or the module's
/// layout on its axis) and exist in the dictionary with the same bit length,
/// mappable in the PDO's direction.
#[test]
fn esi_pdo_entries_are_mappable_objects() {
    for (v, t) in each() {
        let od = esi::dictionary(v, t);
        let xml = esi(v, t);
        let doc = Document::parse(&xml).unwrap();
        let dev = device_node(&doc);
        // (PDO node, the declared entries, where)
        let mut pdos: Vec<(Node, &[od::PdoEntry], String)> = Vec::new();
        for tag in ["RxPdo", "TxPdo"] {
            for pdo in children(dev, tag) {
                let index = num(text(pdo, "Index")) as u16;
                let declared = drive_ecat::device(v).pdo(index).unwrap();
                pdos.push((pdo, declared.entries, format!("device {index:04X}h")));
            }
        }
        let system: Vec<(u32, u16, drive_ecat::PdoLayout)> = (0..v.axes() as u16)
            .flat_map(|axis| drive_ecat::PdoLayout::ALL.map(|l| (drive_ecat::module_ident(l, axis), axis, l)))
            .collect();
        let mut in_modules = 0;
        for m in modules(&doc) {
            let ident = module_ident(m);
            let &(_, axis, layout) = system
                .iter()
                .find(|s| s.0 == ident)
                .unwrap_or_else(|| panic!("{v:?} {t:?}: module {ident:08X}h is no system module"));
            let (rx, tx) = layout.axis_entries(axis);
            for (tag, declared) in [("RxPdo", rx), ("TxPdo", tx)] {
                for pdo in children(m, tag) {
                    pdos.push((pdo, declared, format!("module {ident:08X}h")));
                    in_modules += 1;
                }
            }
        }
        assert_eq!(in_modules, 2 * system.len(), "an RxPDO and a TxPDO per module");
        for (pdo, declared, what) in pdos {
            let rx = pdo.has_tag_name("RxPdo");
            let index = num(text(pdo, "Index")) as u16;
            assert_eq!(rx, (0x1600..0x1A00).contains(&index), "{what}: direction");
            let entries: Vec<Node> = children(pdo, "Entry").collect();
            assert_eq!(entries.len(), declared.len(), "{what}");
            for (node, d) in entries.iter().zip(declared) {
                let (i, s) = (
                    num(text(*node, "Index")) as u16,
                    num(text(*node, "SubIndex")) as u8,
                );
                assert_eq!((i, s), (d.index, d.sub), "{what}");
                assert_eq!(text(*node, "DataType"), expected_type(d.data_type), "{what}");
                let e = od
                    .object(i)
                    .and_then(|o| o.entry(s))
                    .unwrap_or_else(|| panic!("{what} {index:04X}h: {i:04X}h:{s} not in the OD"));
                assert_eq!(
                    num(text(*node, "BitLen")),
                    u64::from(e.bit_len()),
                    "{what} {i:04X}h:{s}"
                );
                let mappable = if rx {
                    e.access.rx_mappable()
                } else {
                    e.access.tx_mappable()
                };
                assert!(mappable, "{what} {index:04X}h: {i:04X}h:{s} not mappable");
            }
        }
    }
}

/// The numeric defaults of object `index` in the ESI dictionary, in entry order.
fn defaults_of(profile: Node, index: u16) -> Vec<u64> {
    let info = child(object(profile, index), "Info");
    children(info, "SubItem")
        .map(|s| {
            let data = hex_bytes(text(child(s, "Info"), "DefaultData"));
            data.iter().rev().fold(0u64, |v, b| v << 8 | u64::from(*b))
        })
        .collect()
}

#[test]
fn esi_pdos_match_mapping_and_assignment_objects() {
    // the standard layout of axis A is what 1600h/1A00h carry (PdoLayout::Standard)
    let (rx_a, tx_a) = drive_ecat::PdoLayout::Standard.entries();
    for (v, t) in each() {
        assert_eq!(drive_ecat::device(v).pdo(0x1600).unwrap().entries, rx_a);
        assert_eq!(drive_ecat::device(v).pdo(0x1A00).unwrap().entries, tx_a);
        let xml = esi(v, t);
        let doc = Document::parse(&xml).unwrap();
        let dev = device_node(&doc);
        let profile = child(dev, "Profile");
        for (tag, assign) in [("RxPdo", 0x1C12), ("TxPdo", 0x1C13)] {
            let mut assigned = Vec::new();
            for pdo in children(dev, tag) {
                let index = num(text(pdo, "Index")) as u16;
                if pdo.attribute("Sm").is_some() {
                    assigned.push(u64::from(index));
                }
                // 16xxh/1Axxh sub n default = index << 16 | sub << 8 | bit length of entry n
                let mapped: Vec<u64> = children(pdo, "Entry")
                    .map(|e| {
                        num(text(e, "Index")) << 16 | num(text(e, "SubIndex")) << 8 | num(text(e, "BitLen"))
                    })
                    .collect();
                let d = defaults_of(profile, index);
                assert_eq!(d[0], mapped.len() as u64, "{index:04X}h:00");
                assert_eq!(&d[1..=mapped.len()], &mapped[..], "{index:04X}h");
            }
            let d = defaults_of(profile, assign);
            assert_eq!(d[0], assigned.len() as u64, "{assign:04X}h:00");
            assert_eq!(&d[1..=assigned.len()], &assigned[..], "{assign:04X}h");
        }
    }
}

/// The single-axis device's ESIs (issue 20): its own product code and type,
/// no axis-B object (6800h…6FFFh, A000h…DFFFh) and only axis A's PDOs,
/// channel 2 an empty free channel; the double-axis ESIs keep axis B.
#[test]
fn e005_e084_e150_the_single_axis_esi_has_no_axis_b() {
    let axis_b = |i: u64| (0x6800..=0x6FFF).contains(&i) || (0xA000..=0xDFFF).contains(&i);
    for (v, t) in each() {
        let xml = esi(v, t);
        let doc = Document::parse(&xml).unwrap();
        let dev = device_node(&doc);
        let ty = child(dev, "Type");
        let profile = child(dev, "Profile");
        let objects: Vec<u64> = children(child(child(profile, "Dictionary"), "Objects"), "Object")
            .map(|o| num(text(o, "Index")))
            .collect();
        let pdos = |tag| -> Vec<u64> { children(dev, tag).map(|p| num(text(p, "Index"))).collect() };
        let module_pdos: Vec<Node> = modules(&doc)
            .into_iter()
            .flat_map(|m| children(m, "RxPdo").chain(children(m, "TxPdo")))
            .collect();
        let module_indexes: BTreeSet<u64> = module_pdos.iter().map(|p| num(text(*p, "Index"))).collect();
        let entries: Vec<u64> = children(dev, "RxPdo")
            .chain(children(dev, "TxPdo"))
            .chain(module_pdos.iter().copied())
            .flat_map(|p| children(p, "Entry").map(|e| num(text(e, "Index"))))
            .collect();
        match v {
            Variant::Single => {
                assert_eq!(
                    num(ty.attribute("ProductCode").unwrap()),
                    u64::from(drive_ecat::PRODUCT_CODE_SINGLE)
                );
                assert_eq!(ty.text(), Some("SI6A061"));
                assert!(text(dev, "Name").starts_with("SI6 SI6A061"), "{t:?}");
                assert!(!objects.iter().any(|&i| axis_b(i)), "{t:?}: an axis-B object");
                assert!(!entries.iter().any(|&i| axis_b(i)), "{t:?}: an axis-B PDO entry");
                assert_eq!((pdos("RxPdo"), pdos("TxPdo")), (vec![0x1600], vec![0x1A00]));
                assert_eq!(module_indexes, BTreeSet::from([0x1600, 0x1A00]), "{t:?}: modules");
                assert_eq!(slots(dev).len(), 1, "{t:?}: one slot, axis A");
                // channel 2 is there, free and empty
                for pdo in [0x1601, 0x1A01] {
                    assert!(defaults_of(profile, pdo).iter().all(|&d| d == 0), "{pdo:04X}h");
                }
                assert_eq!(
                    defaults_of(profile, 0xF050),
                    [
                        2,
                        u64::from(drive_ecat::module_ident(drive_ecat::PdoLayout::Standard, 0)),
                        0
                    ]
                );
                let name = children(child(object(profile, 0x1008), "Info"), "DefaultString").next();
                assert_eq!(name.and_then(|n| n.text()), Some("SI6"));
            }
            Variant::Double => {
                assert_eq!(
                    num(ty.attribute("ProductCode").unwrap()),
                    u64::from(drive_ecat::PRODUCT_CODE)
                );
                assert!(objects.iter().any(|&i| (0x6800..=0x6FFF).contains(&i)));
                assert!(objects.iter().any(|&i| (0xA000..=0xDFFF).contains(&i)));
                assert_eq!(
                    (pdos("RxPdo"), pdos("TxPdo")),
                    (vec![0x1600, 0x1601], vec![0x1A00, 0x1A01])
                );
                assert_eq!(
                    module_indexes,
                    BTreeSet::from([0x1600, 0x1601, 0x1A00, 0x1A01]),
                    "{t:?}: modules"
                );
                assert!(entries.iter().any(|&i| (0x6800..=0x6FFF).contains(&i)));
                assert_eq!(slots(dev).len(), 2, "{t:?}: axes A and B");
            }
        }
    }
}

/// E-149: the ESI is modular. One slot per axis (axis A; axis B only on
/// the double-axis device), each with exactly one module per application
/// layout (`PdoLayout::ALL`) of that axis, the standard layout the default;
/// every module in `<Modules>` once, in one slot, with its own ident (axis
/// B's differ from axis A's), its RxPDO and TxPDO in the axis's channel
/// (1600h/1A00h + axis, assigned to SM2/SM3 when in the slot) named after
/// the layout. The device-level PDOs stay (the SII's default configuration),
/// each described once, and those a module describes again are marked
/// `OverwrittenByModule`, so no PDO index is described twice in a way a
/// master would reject.
#[test]
fn e056_e149_one_slot_per_axis_with_a_module_per_layout() {
    for (v, t) in each() {
        let what = format!("{v:?} {t:?}");
        let xml = esi(v, t);
        let doc = Document::parse(&xml).unwrap();
        let dev = device_node(&doc);
        let slots = slots(dev);
        assert_eq!(slots.len(), v.axes(), "{what}: a slot per axis");
        let modules = modules(&doc);
        assert_eq!(
            modules.len(),
            drive_ecat::PdoLayout::ALL.len() * v.axes(),
            "{what}"
        );
        let by_ident: BTreeMap<u32, Node> = modules.iter().map(|m| (module_ident(*m), *m)).collect();
        assert_eq!(by_ident.len(), modules.len(), "{what}: idents unique");
        let mut slotted = BTreeSet::new();
        let mut module_pdos = BTreeSet::new();
        for (axis, slot) in (0u16..).zip(&slots) {
            let letter = ["A", "B"][usize::from(axis)];
            assert_eq!(text(*slot, "Name"), format!("Axis {letter}"), "{what}");
            assert_eq!(num(slot.attribute("MinInstances").unwrap()), 1, "{what}");
            assert_eq!(num(slot.attribute("MaxInstances").unwrap()), 1, "{what}");
            let idents: Vec<Node> = children(*slot, "ModuleIdent").collect();
            let listed: Vec<u32> = idents.iter().map(|i| num(i.text().unwrap()) as u32).collect();
            let layouts = drive_ecat::PdoLayout::ALL.map(|l| drive_ecat::module_ident(l, axis));
            assert_eq!(listed, layouts, "{what}: axis {letter}");
            let defaults: Vec<u32> = idents
                .iter()
                .filter(|i| i.attribute("Default").is_some_and(|d| num(d) == 1))
                .map(|i| num(i.text().unwrap()) as u32)
                .collect();
            assert_eq!(
                defaults,
                [drive_ecat::module_ident(drive_ecat::PdoLayout::Standard, axis)],
                "{what}: axis {letter} defaults to the standard layout"
            );
            for (layout, ident) in drive_ecat::PdoLayout::ALL.iter().zip(listed) {
                assert!(slotted.insert(ident), "{what}: {ident:08X}h in one slot only");
                let m = by_ident
                    .get(&ident)
                    .unwrap_or_else(|| panic!("{what}: no module {ident:08X}h"));
                assert_eq!(ident & drive_ecat::AXIS_B_MODULE != 0, axis == 1, "{what}");
                assert_eq!(
                    text(*m, "Name"),
                    format!("Axis {letter}: {}", layout.name()),
                    "{what}"
                );
                let rx: Vec<Node> = children(*m, "RxPdo").collect();
                let tx: Vec<Node> = children(*m, "TxPdo").collect();
                assert_eq!((rx.len(), tx.len()), (1, 1), "{what}: {ident:08X}h");
                for (pdo, index, sm) in [(rx[0], 0x1600 + axis, 2), (tx[0], 0x1A00 + axis, 3)] {
                    assert_eq!(num(text(pdo, "Index")), u64::from(index), "{what}: {ident:08X}h");
                    assert_eq!(pdo.attribute("Sm").map(num), Some(sm), "{what}: {ident:08X}h");
                    // the device has PDO configuration: no module PDO is fixed
                    assert_eq!(pdo.attribute("Fixed"), None, "{what}: {ident:08X}h");
                    assert!(!mapped(pdo).is_empty(), "{what}: {ident:08X}h");
                    module_pdos.insert(index);
                }
            }
        }
        assert_eq!(slotted.len(), modules.len(), "{what}: every module in a slot");
        // device level: each PDO once; those a module describes are overwritten by it
        for tag in ["RxPdo", "TxPdo"] {
            let mut seen = BTreeSet::new();
            for pdo in children(dev, tag) {
                let index = num(text(pdo, "Index")) as u16;
                assert!(seen.insert(index), "{what}: {index:04X}h twice at device level");
                assert_eq!(
                    pdo.attribute("OverwrittenByModule") == Some("1"),
                    module_pdos.contains(&index),
                    "{what}: {index:04X}h"
                );
            }
        }
        for index in &module_pdos {
            assert!(
                drive_ecat::device(v).pdo(*index).is_some(),
                "{what}: {index:04X}h has a device-level default"
            );
        }
    }
}

/// E-148 with E-149: F050h reports for each axis exactly the ident of the
/// ESI module that describes the axis's mapping. Each module's PDOs, written
/// into a fresh dictionary as a master's startup list would (Pre-Op, sub 0 =
/// 0, the entries, sub 0 = n: the mapping checks accept every entry), make
/// F050h:(slot + 1) read the module's ident; the default configuration reads
/// the slots' default idents (0 for the single-axis device's axis B), as the
/// ESI dictionary's F050h defaults say.
#[test]
fn e148_e149_f050_reports_the_ident_of_the_esi_module() {
    for (v, t) in each() {
        let what = format!("{v:?} {t:?}");
        let xml = esi(v, t);
        let doc = Document::parse(&xml).unwrap();
        let dev = device_node(&doc);
        let read_f050 = |od: &mut drive_ecat::DriveObjects, sub: u8| {
            let mut buf = [0u8; 4];
            assert_eq!(od.read(0xF050, sub, &mut buf, CommState::PreOp), Ok(4));
            u32::from_le_bytes(buf)
        };
        // the default configuration
        let defaults: Vec<u32> = slots(dev)
            .iter()
            .map(|s| {
                let d = children(*s, "ModuleIdent")
                    .find(|i| i.attribute("Default") == Some("1"))
                    .unwrap();
                num(d.text().unwrap()) as u32
            })
            .collect();
        let mut od = esi::dictionary(v, t);
        let mut f050 = vec![read_f050(&mut od, 1), read_f050(&mut od, 2)];
        if v == Variant::Single {
            assert_eq!(f050.pop(), Some(0), "{what}: no module on axis B");
        }
        assert_eq!(f050, defaults, "{what}: F050h = the slots' defaults");
        let esi_f050 = defaults_of(child(dev, "Profile"), 0xF050);
        assert_eq!(esi_f050[0], 2, "{what}");
        assert_eq!(
            &esi_f050[1..=f050.len()],
            &f050.iter().map(|&i| u64::from(i)).collect::<Vec<_>>()[..]
        );
        // every module, written into its axis's channel
        for (axis, slot) in (0u8..).zip(slots(dev)) {
            for ident in children(slot, "ModuleIdent").map(|i| num(i.text().unwrap()) as u32) {
                let m = modules(&doc)
                    .into_iter()
                    .find(|m| module_ident(*m) == ident)
                    .unwrap();
                let mut od = esi::dictionary(v, t);
                let other = (v == Variant::Double).then(|| read_f050(&mut od, 2 - axis));
                for pdo in children(m, "RxPdo").chain(children(m, "TxPdo")) {
                    let index = num(text(pdo, "Index")) as u16;
                    let entries = mapped(pdo);
                    od.write(index, 0, &[0], CommState::PreOp).unwrap();
                    for (sub, e) in (1u8..).zip(&entries) {
                        let r = od.write(index, sub, &e.to_le_bytes(), CommState::PreOp);
                        assert_eq!(r, Ok(()), "{what}: {ident:08X}h {index:04X}h:{sub} = {e:08X}h");
                    }
                    od.write(index, 0, &[entries.len() as u8], CommState::PreOp)
                        .unwrap_or_else(|e| panic!("{what}: {ident:08X}h {index:04X}h: {e:?}"));
                }
                assert_eq!(
                    read_f050(&mut od, axis + 1),
                    ident,
                    "{what}: F050h:{:02X} after module {ident:08X}h",
                    axis + 1
                );
                if let Some(other) = other {
                    assert_eq!(read_f050(&mut od, 2 - axis), other, "{what}: the other axis");
                }
            }
        }
    }
}

/// E-149 with the SII: the default module of each slot is the default
/// mapping of its channel. Its PDOs' entries equal the dictionary's mapping
/// (16xxh/1Axxh at start, read through the dictionary and as the ESI
/// dictionary's defaults), the device-level PDO of the same index and the
/// SII's RXPDO/TXPDO record of it (what SOEM and ethercrab read).
#[test]
fn e149_default_modules_equal_the_default_mapping_and_the_sii() {
    for (v, t) in each() {
        let what = format!("{v:?} {t:?}");
        let xml = esi(v, t);
        let doc = Document::parse(&xml).unwrap();
        let dev = device_node(&doc);
        let profile = child(dev, "Profile");
        let od = esi::dictionary(v, t);
        let img = esi::sii(v, t).unwrap();
        let sii_pdo = |kind: u16, index: u16| -> Vec<u32> {
            let cat = find_category(&img, kind).unwrap();
            let mut pos = 0;
            while pos < cat.len() {
                let head = &cat[pos..pos + 8];
                let n = usize::from(head[2]);
                let entries = (0..n).map(|k| {
                    let r = &cat[pos + 8 + 8 * k..pos + 16 + 8 * k];
                    u32::from(u16::from_le_bytes([r[0], r[1]])) << 16 | u32::from(r[2]) << 8 | u32::from(r[5])
                });
                if u16::from_le_bytes([head[0], head[1]]) == index {
                    return entries.collect();
                }
                pos += 8 + 8 * n;
            }
            panic!("{what}: {index:04X}h not in the SII");
        };
        for slot in slots(dev) {
            let default = children(slot, "ModuleIdent")
                .find(|i| i.attribute("Default") == Some("1"))
                .map(|i| num(i.text().unwrap()) as u32)
                .unwrap();
            let m = modules(&doc)
                .into_iter()
                .find(|m| module_ident(*m) == default)
                .unwrap();
            for (tag, kind) in [("RxPdo", category::RXPDO), ("TxPdo", category::TXPDO)] {
                let pdo = child(m, tag);
                let index = num(text(pdo, "Index")) as u16;
                let entries = mapped(pdo);
                assert_eq!(
                    od.mapping(index).collect::<Vec<_>>(),
                    entries,
                    "{what}: {index:04X}h"
                );
                let d = defaults_of(profile, index);
                assert_eq!(d[0], entries.len() as u64, "{what}: {index:04X}h:00");
                let listed: Vec<u32> = d[1..=entries.len()].iter().map(|&x| x as u32).collect();
                assert_eq!(listed, entries, "{what}: {index:04X}h defaults");
                let device = children(dev, tag)
                    .find(|p| num(text(*p, "Index")) == u64::from(index))
                    .unwrap();
                assert_eq!(mapped(device), entries, "{what}: device-level {index:04X}h");
                assert_eq!(sii_pdo(kind, index), entries, "{what}: SII {index:04X}h");
            }
        }
    }
}

/// Explicit device identification (issue 33): every ESI declares the ID in
/// register 0x0134 (ETG.2000 `Info/IdentificationReg134`), which the drive
/// answers an AL control ID request with (the station alias).
#[test]
fn e026_esi_declares_explicit_device_identification_in_0134() {
    for (v, t) in each() {
        let xml = esi(v, t);
        let doc = roxmltree::Document::parse(&xml).unwrap();
        let dev = device_node(&doc);
        let info = child(dev, "Info");
        assert_eq!(text(info, "IdentificationReg134"), "true", "{v:?} {t:?}");
    }
}
