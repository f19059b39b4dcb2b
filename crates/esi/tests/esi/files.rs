//! The files themselves: current on disk, one per template with its own revision equal to
//! 1018h:03 (E-150, E-151), DC SYNC0 the default op mode (E-108), the single-axis device's ESI
//! without axis B (E-005, E-084, E-150) and explicit device identification in 0134h (E-026).

use super::*;

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
