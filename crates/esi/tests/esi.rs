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

use drive::{revision, Template, Variant};
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
    let check = generated::check_current(
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
            let a10 = drive::parameter_index(0, 10);
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
    // the default template's SII is the one the drive carries (drive::device)
    for v in esi::VARIANTS {
        assert_eq!(esi::device(v, Template::SdoInfo), *drive::device(v));
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
    let first = drive::DEVICE
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
        let declared = drive::device(v);
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
        assert_eq!(
            num(sms[0].attribute("StartAddress").unwrap()),
            w(word::STD_RX_MAILBOX_OFFSET)
        );
        assert_eq!(
            num(sms[0].attribute("DefaultSize").unwrap()),
            w(word::STD_RX_MAILBOX_SIZE)
        );
        assert_eq!(
            num(sms[1].attribute("StartAddress").unwrap()),
            w(word::STD_TX_MAILBOX_OFFSET)
        );
        assert_eq!(
            num(sms[1].attribute("DefaultSize").unwrap()),
            w(word::STD_TX_MAILBOX_SIZE)
        );
        assert_eq!(
            sms.iter().map(|s| s.text().unwrap()).collect::<Vec<_>>(),
            ["MBoxOut", "MBoxIn", "Outputs", "Inputs"]
        );
        assert_eq!(
            num(sms[2].attribute("DefaultSize").unwrap()),
            declared.output_bytes() as u64
        );
        assert_eq!(
            num(sms[3].attribute("DefaultSize").unwrap()),
            declared.input_bytes() as u64
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
            u64::from(drive::device(v).device_type & 0xFFFF)
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

#[test]
fn esi_pdo_entries_are_mappable_objects() {
    for (v, t) in each() {
        let od = esi::dictionary(v, t);
        let xml = esi(v, t);
        let doc = Document::parse(&xml).unwrap();
        let dev = device_node(&doc);
        for (tag, rx) in [("RxPdo", true), ("TxPdo", false)] {
            for pdo in children(dev, tag) {
                let index = num(text(pdo, "Index")) as u16;
                let declared = drive::device(v).pdo(index).unwrap();
                let entries: Vec<Node> = children(pdo, "Entry").collect();
                assert_eq!(entries.len(), declared.entries.len());
                for (node, d) in entries.iter().zip(declared.entries) {
                    let (i, s) = (
                        num(text(*node, "Index")) as u16,
                        num(text(*node, "SubIndex")) as u8,
                    );
                    assert_eq!((i, s), (d.index, d.sub));
                    assert_eq!(text(*node, "DataType"), expected_type(d.data_type));
                    let e = od
                        .object(i)
                        .and_then(|o| o.entry(s))
                        .unwrap_or_else(|| panic!("{tag} {index:04X}h: {i:04X}h:{s} not in the OD"));
                    assert_eq!(num(text(*node, "BitLen")), u64::from(e.bit_len()), "{i:04X}h:{s}");
                    let mappable = if rx {
                        e.access.rx_mappable()
                    } else {
                        e.access.tx_mappable()
                    };
                    assert!(mappable, "{tag} {index:04X}h: {i:04X}h:{s} not mappable");
                }
            }
        }
    }
}

/// The numeric defaults of object `index` in the ESI dictionary, in entry order.
fn defaults(profile: Node, index: u16) -> Vec<u64> {
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
    let (rx_a, tx_a) = drive::PdoLayout::Standard.entries();
    for (v, t) in each() {
        assert_eq!(drive::device(v).pdo(0x1600).unwrap().entries, rx_a);
        assert_eq!(drive::device(v).pdo(0x1A00).unwrap().entries, tx_a);
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
                let d = defaults(profile, index);
                assert_eq!(d[0], mapped.len() as u64, "{index:04X}h:00");
                assert_eq!(&d[1..=mapped.len()], &mapped[..], "{index:04X}h");
            }
            let d = defaults(profile, assign);
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
        let entries: Vec<u64> = children(dev, "RxPdo")
            .chain(children(dev, "TxPdo"))
            .flat_map(|p| children(p, "Entry").map(|e| num(text(e, "Index"))))
            .collect();
        match v {
            Variant::Single => {
                assert_eq!(
                    num(ty.attribute("ProductCode").unwrap()),
                    u64::from(drive::PRODUCT_CODE_SINGLE)
                );
                assert_eq!(ty.text(), Some("SI6A061"));
                assert!(text(dev, "Name").starts_with("SI6 SI6A061"), "{t:?}");
                assert!(!objects.iter().any(|&i| axis_b(i)), "{t:?}: an axis-B object");
                assert!(!entries.iter().any(|&i| axis_b(i)), "{t:?}: an axis-B PDO entry");
                assert_eq!((pdos("RxPdo"), pdos("TxPdo")), (vec![0x1600], vec![0x1A00]));
                // channel 2 is there, free and empty
                for pdo in [0x1601, 0x1A01] {
                    assert!(defaults(profile, pdo).iter().all(|&d| d == 0), "{pdo:04X}h");
                }
                assert_eq!(
                    defaults(profile, 0xF050),
                    [
                        2,
                        u64::from(drive::module_ident(drive::PdoLayout::Standard, 0)),
                        0
                    ]
                );
                let name = children(child(object(profile, 0x1008), "Info"), "DefaultString").next();
                assert_eq!(name.and_then(|n| n.text()), Some("SI6"));
            }
            Variant::Double => {
                assert_eq!(
                    num(ty.attribute("ProductCode").unwrap()),
                    u64::from(drive::PRODUCT_CODE)
                );
                assert!(objects.iter().any(|&i| (0x6800..=0x6FFF).contains(&i)));
                assert!(objects.iter().any(|&i| (0xA000..=0xDFFF).contains(&i)));
                assert_eq!(
                    (pdos("RxPdo"), pdos("TxPdo")),
                    (vec![0x1600, 0x1601], vec![0x1A00, 0x1A01])
                );
            }
        }
    }
}
