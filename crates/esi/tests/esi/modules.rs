//! The modular ESI (E-149): one slot per axis with a module per layout (E-056), F050h reporting
//! the ident of the module (E-148), and the default modules equal to the default mapping and
//! the SII.

use super::*;

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
