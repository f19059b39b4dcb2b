//! The ESI dictionary against the object dictionary: types, flags and defaults of every entry,
//! PDO entries that are mappable objects, and the PDOs against the mapping and assignment
//! objects.

use super::*;

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
