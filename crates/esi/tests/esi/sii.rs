//! The ESI against the SII image of each device and template.

use super::*;

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
