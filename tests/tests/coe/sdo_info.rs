//! SDO Information (§7) and what CoE shows: the lists and descriptions against the dictionary
//! (E-080 … E-084), A268's selection of the listed objects (E-083), the manufacturer array in
//! both templates without SDO Info in the Rx template (E-012, E-013, E-079), and the access
//! level A10[2] (E-016, E-017, E-084).

use super::*;

/// The object's data type as SDO Info reports it (ETG.1000.6): the entry type
/// of a VAR, the element type of an ARRAY, the standard structure of a RECORD.
fn object_type(o: &Object) -> u16 {
    match o.info.code.code() {
        7 => o.info.entries.get(0).unwrap().data_type.code(),
        8 => o
            .info
            .entries
            .iter()
            .find(|e| e.sub >= 1)
            .unwrap()
            .data_type
            .code(),
        _ => match o.info.index {
            0x1018 => 0x0023,
            0x1600..=0x17FF | 0x1A00..=0x1BFF => 0x0021,
            0x1C32 | 0x1C33 => 0x0029,
            _ => 0x002A,
        },
    }
}

/// The bytes of each default/min/max value in an entry description.
fn value_size(t: DataType) -> usize {
    match t {
        DataType::Bool | DataType::F32 => 0,
        t if t.is_string() => 0,
        t => t.bytes(),
    }
}

#[test]
fn e080_e081_e082_e084_sdo_info_lists_and_descriptions_match_the_dictionary() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let mut c = CoeClient::new();
        let shown: Vec<&Object> = device_objects().filter(|o| visible(o)).collect();
        let all: Vec<u16> = shown.iter().map(|o| o.info.index).collect();
        let mappable = |rx: bool| -> Vec<u16> {
            shown
                .iter()
                .filter(|o| {
                    o.info.entries.iter().any(|e| {
                        if rx {
                            e.access.rx_mappable()
                        } else {
                            e.access.tx_mappable()
                        }
                    })
                })
                .map(|o| o.info.index)
                .collect()
        };
        assert!(
            all.len() < device_objects().count(),
            "some objects are hidden at level {LEVEL}"
        );
        // E-080: all, RxPDO- and TxPDO-mappable (fragmented: the lists are long)
        assert_eq!(c.od_list(&sd, 1).await, all, "OD list: all visible objects");
        let rx = c.od_list(&sd, 2).await;
        assert_eq!(rx, mappable(true), "RxPDO-mappable objects");
        assert!(rx.contains(&0x6040) && !rx.contains(&0x6041) && !rx.contains(&0x1000));
        let tx = c.od_list(&sd, 3).await;
        assert_eq!(tx, mappable(false), "TxPDO-mappable objects");
        assert!(tx.contains(&0x6041) && tx.contains(&0x10F3) && !tx.contains(&0x1000));
        // E-081: backup and settings lists are empty
        assert_eq!(c.od_list(&sd, 4).await, Vec::<u16>::new());
        assert_eq!(c.od_list(&sd, 5).await, Vec::<u16>::new());
        // list type 0: the five lengths
        let (op, d) = c.info(&sd, 1, &0u16.to_le_bytes()).await;
        assert_eq!(op, 2);
        let lengths: Vec<u16> = d.chunks(2).map(|b| u16::from_le_bytes([b[0], b[1]])).collect();
        assert_eq!(
            lengths,
            [0, all.len() as u16, rx.len() as u16, tx.len() as u16, 0, 0]
        );

        // E-082: every visible object's description and every entry's
        for o in &shown {
            let index = o.info.index;
            let d = c.object_desc(&sd, index).await.unwrap();
            assert_eq!(d.name, o.info.name, "{index:04X}h name");
            assert_eq!(d.code, o.info.code.code(), "{index:04X}h object code");
            assert_eq!(d.data_type, object_type(o), "{index:04X}h data type");
            assert_eq!(d.max_sub, o.info.max_sub(), "{index:04X}h max subindex");
            for e in o.info.entries {
                let at = format!("{index:04X}h:{:02X}h", e.sub);
                let d = c
                    .entry_desc(&sd, index, e.sub, 0x77, value_size(e.data_type))
                    .await
                    .unwrap();
                assert_eq!(d.name, e.name, "{at} name");
                assert_eq!(d.data_type, e.data_type.code(), "{at} data type");
                assert_eq!(d.bit_len, e.data_type.bits(), "{at} bit length");
                assert_eq!(d.access, e.access.0, "{at} access, mapping, backup bits");
                let mut expected = Vec::new();
                if value_size(e.data_type) > 0 {
                    let n = value_size(e.data_type);
                    expected.push(e.default.to_le_bytes()[..n].to_vec());
                    for v in [e.min, e.max].into_iter().flatten() {
                        expected.push(v.to_le_bytes()[..n].to_vec());
                    }
                }
                assert_eq!(d.values, expected, "{at} default, min, max");
                assert_eq!(d.value_info & 0x07, 0x07, "{at} value info");
            }
        }

        // a sample, spelled out
        let d = c.object_desc(&sd, 0x1018).await.unwrap();
        assert_eq!((d.data_type, d.max_sub, d.code), (0x0023, 4, 9));
        assert_eq!(d.name, "Identity object");
        let d = c.object_desc(&sd, 0x1600).await.unwrap();
        assert_eq!((d.data_type, d.max_sub, d.code), (0x0021, 24, 9));
        let d = c.entry_desc(&sd, 0x1600, 1, 0x17, 4).await.unwrap();
        assert_eq!((d.data_type, d.bit_len, d.access), (0x0007, 32, 0x000F));
        assert_eq!(
            d.values,
            [0x6040_0010u32.to_le_bytes().to_vec()],
            "default mapping"
        );
        let d = c.object_desc(&sd, 0x6040).await.unwrap();
        assert_eq!(
            (d.data_type, d.max_sub, d.code, d.name.as_str()),
            (6, 0, 7, "Controlword")
        );
        let d = c.entry_desc(&sd, 0x6040, 0, 0x07, 2).await.unwrap();
        assert_eq!(
            (d.data_type, d.bit_len, d.access),
            (6, 16, 0x00FF),
            "rw, Rx and Tx"
        );
        let d = c.entry_desc(&sd, 0x6041, 0, 0x07, 2).await.unwrap();
        assert_eq!((d.data_type, d.bit_len, d.access), (6, 16, 0x0087), "ro, Tx");
        // A10 access level: an array, element e at subindex e + 1 (E-013)
        let a10 = drive_ecat::parameter_index(0, 10);
        let d = c.object_desc(&sd, a10).await.unwrap();
        assert_eq!(
            (d.data_type, d.max_sub, d.code, d.name.as_str()),
            (5, 4, 8, "Access level")
        );
        let d = c.entry_desc(&sd, a10, 3, 0x77, 1).await.unwrap();
        assert_eq!(d.name, "CANopen and EtherCAT");
        assert_eq!(d.values, [vec![2], vec![0], vec![3]], "default 2, range 0..3");
        assert_eq!(d.access, 0x003F, "rw in every state, not mappable");

        // errors: unknown and hidden objects, unknown subindex
        assert_eq!(c.object_desc(&sd, 0x5000).await, Err(NO_OBJECT));
        let hidden = device_objects().find(|o| !visible(o)).unwrap().info.index;
        assert_eq!(c.object_desc(&sd, hidden).await, Err(NO_OBJECT), "E-084");
        assert_eq!(c.entry_desc(&sd, 0x1018, 9, 0, 0).await, Err(NO_SUBINDEX));

        // E-085: SDO Info in Safe-Op and Op too. The number of requests above
        // grows with the dictionary, so this client's last counter is any of
        // 1..7: hand the mailbox over, or ethercrab's next request is dropped
        // as a repeat whenever its counter happens to be the same.
        c.hand_over(&sd).await;
        let group = group.into_op(md).await.expect("PRE-OP -> OP");
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(c.od_list(&sd, 3).await, tx);
        assert_eq!(c.object_desc(&sd, 0x6041).await.unwrap().name, "Statusword");
    });
}

/// E-083: A268 selects what the OD lists show: [0] index area (0 the
/// standard area, 1 the manufacturer area 2000h…5FFFh and axis B's
/// A000h…DFFFh, 2 all), [1] a bit per manufacturer group A…Z. Objects left
/// out keep their descriptions; a value beyond the range is refused and
/// changes nothing.
#[test]
fn e083_a268_selects_the_listed_objects() {
    let sim = line(1);
    let a268 = drive_ecat::parameter_index(0, 268);
    with_sdo(&sim, async |sd, c| {
        let manufacturer = |i: &u16| matches!(i & 0x7FFF, 0x2000..=0x5FFF);
        let all = c.od_list(sd, 1).await;
        assert!(all.iter().any(manufacturer) && all.iter().any(|i| !manufacturer(i)));
        // standard area only
        c.download(sd, a268, 1, &[0]).await.unwrap();
        let standard = c.od_list(sd, 1).await;
        assert_eq!(
            standard,
            all.iter()
                .copied()
                .filter(|i| !manufacturer(i))
                .collect::<Vec<_>>()
        );
        let tx = c.od_list(sd, 3).await;
        assert!(
            tx.contains(&0x6041) && !tx.iter().any(manufacturer),
            "TxPDO list too"
        );
        let (_, d) = c.info(sd, 1, &0u16.to_le_bytes()).await;
        assert_eq!(
            u16::from_le_bytes([d[2], d[3]]) as usize,
            standard.len(),
            "list lengths follow"
        );
        assert_eq!(
            c.object_desc(sd, a268).await.unwrap().name,
            "SDO Info object selection",
            "a left-out object keeps its description"
        );
        // manufacturer area, groups A (bit 0) and I (bit 8) only
        c.download(sd, a268, 1, &[1]).await.unwrap();
        c.download(sd, a268, 2, &0x0101u32.to_le_bytes()).await.unwrap();
        let chosen = c.od_list(sd, 1).await;
        let in_a_or_i = |i: &u16| manufacturer(i) && matches!(((i & 0x7FFF) - 0x2000) >> 9, 0 | 8);
        assert_eq!(chosen, all.iter().copied().filter(in_a_or_i).collect::<Vec<_>>());
        assert!(chosen.contains(&a268) && chosen.contains(&drive_ecat::parameter_index(8, 22)));
        // all, groups as chosen: the standard area again beside A and I
        c.download(sd, a268, 1, &[2]).await.unwrap();
        let mixed = c.od_list(sd, 1).await;
        let want: Vec<u16> = all
            .iter()
            .copied()
            .filter(|i| !manufacturer(i) || in_a_or_i(i))
            .collect();
        assert_eq!(mixed, want);
        // out of range: refused, the selection unchanged
        assert_eq!(
            c.download(sd, a268, 1, &[3]).await,
            Err(0x0609_0031),
            "value too high"
        );
        assert_eq!(c.od_list(sd, 1).await, want);
        c.download(sd, a268, 2, &0x03FF_FFFFu32.to_le_bytes())
            .await
            .unwrap();
        assert_eq!(c.od_list(sd, 1).await, all, "the defaults list everything");
    });
}

#[test]
fn e012_e013_e079_manufacturer_array_in_both_templates() {
    let sim = line(1);
    let a10 = drive_ecat::parameter_index(0, 10);
    with_sdo(&sim, async |sd, c| {
        // "EtherCAT Rx SDO Info": A10[2] at subindex 3, sub 0 = element count
        assert_eq!(c.upload(sd, a10, 0).await, Ok(vec![4]));
        c.download(sd, a10, 2, &[1]).await.unwrap(); // A10[1] (DS6)
        assert_eq!(c.upload(sd, a10, 2).await, Ok(vec![1]));
        assert_eq!(c.upload(sd, a10, 3).await, Ok(vec![2]));
        assert_eq!(c.upload(sd, a10, 4).await, Ok(vec![2]));
        assert_eq!(
            c.upload(sd, 0x1018, 3).await,
            Ok(revision(Template::SdoInfo).to_le_bytes().to_vec())
        );
        assert_eq!(c.entry_desc(sd, a10, 2, 0, 1).await.unwrap().name, "DS6");

        // "EtherCAT Rx": element = subindex, no SDO Info, revision bit 0 clear
        sim.borrow_mut().drives_mut()[0]
            .drive
            .objects_mut()
            .set_template(Template::Rx);
        assert_eq!(c.upload(sd, a10, 1).await, Ok(vec![1]), "A10[1] at subindex 1");
        assert_eq!(c.upload(sd, a10, 2).await, Ok(vec![2]), "A10[2] at subindex 2");
        assert_eq!(c.upload(sd, a10, 0).await, Ok(vec![2]), "sub 0 = element 0");
        assert_eq!(c.upload(sd, a10, 4).await, Err(NO_SUBINDEX));
        c.download(sd, a10, 1, &[2]).await.unwrap();
        assert_eq!(objects(&sim).get(a10, 2), Ok(2), "same value, SDO-Info numbering");
        assert_eq!(
            c.upload(sd, 0x1018, 3).await,
            Ok(revision(Template::Rx).to_le_bytes().to_vec())
        );
        // simple parameters and CiA 402 objects keep subindex 0 (E-011)
        assert_eq!(c.upload(sd, 0x6060, 0).await, Ok(vec![8]));
        let reply = c.try_request(sd, &[0x00, 0x80, 3, 0, 0, 0, 0x18, 0x10]).await;
        let (kind, data) = reply.expect_err("E-079: no SDO Info in the Rx template");
        assert_eq!(kind, 0, "mailbox error reply");
        assert_eq!(
            u16::from_le_bytes([data[2], data[3]]),
            ecat::mailbox::MailboxError::SERVICE_NOT_SUPPORTED.0
        );
    });
}

#[test]
fn e016_e017_e084_access_level_a10_2_decides_what_coe_sees() {
    let sim = line(1);
    let a10 = drive_ecat::parameter_index(0, 10);
    let a293 = drive_ecat::parameter_index(0, 293); // PLL gain, level 3
    let a150 = drive_ecat::parameter_index(0, 150); // cycle time, level 1
    with_sdo(&sim, async |sd, c| {
        for level in [0u8, 1, 3, 2] {
            c.download(sd, a10, 3, &[level]).await.unwrap();
            let expected: Vec<u16> = device_objects()
                .filter(|o| o.level <= level)
                .map(|o| o.info.index)
                .collect();
            assert_eq!(c.od_list(sd, 1).await, expected, "E-084 at level {level}");
            let a150_read = c.upload(sd, a150, 0).await;
            let a293_write = c.download(sd, a293, 0, &[0, 0]).await;
            if level >= 1 {
                assert_eq!(a150_read, Ok(1000u16.to_le_bytes().to_vec()));
            } else {
                assert_eq!(a150_read, Err(NO_OBJECT), "E-016 hidden at level 0");
            }
            if level >= 3 {
                assert_eq!(a293_write, Ok(()));
            } else {
                assert_eq!(a293_write, Err(NO_OBJECT), "E-016 hidden at level {level}");
            }
        }
    });
}
