//! Segmented transfers and complete access: segmented download and upload with their toggle
//! errors (E-065 … E-068), complete access to 1018h, 1600h and 1C12h in CiA 301 order, and
//! ethercrab's complete access from subindex 1 (E-078).

use super::*;

/// E72 "User configuration identification": a writable VISIBLE_STRING(16).
const E72: u16 = drive_ecat::parameter_index(4, 72);

#[test]
fn e065_e067_e068_segmented_download_byte_for_byte_and_toggle_error() {
    let sim = line(1);
    let [i0, i1] = E72.to_le_bytes();
    with_sdo(&sim, async |sd, c| {
        // the manual's example: 16 bytes 01h…10h in three 7-byte segments
        let data: Vec<u8> = (1..=16).collect();
        let replies = c.download_segmented(sd, E72, 0, &data, false).await.unwrap();
        assert_eq!(
            replies,
            [
                vec![0x60, i0, i1, 0, 0, 0, 0, 0],
                vec![0x20, 0, 0, 0, 0, 0, 0, 0],
                vec![0x30, 0, 0, 0, 0, 0, 0, 0],
                vec![0x20, 0, 0, 0, 0, 0, 0, 0],
            ],
            "S §9.3.2.3 download example"
        );
        // read back: the whole value fits the mailbox, so a normal upload
        let r = c.sdo(sd, &[0x40, i0, i1, 0, 0, 0, 0, 0]).await.unwrap();
        let mut expected = vec![0x41, i0, i1, 0, 16, 0, 0, 0];
        expected.extend_from_slice(&data);
        assert_eq!(r, expected, "normal upload response, size 16");

        // a shorter string through segments: read back without padding
        c.download_segmented(sd, E72, 0, b"axis cfg 7", false)
            .await
            .unwrap();
        assert_eq!(c.upload(sd, E72, 0).await, Ok(b"axis cfg 7".to_vec()));
        // too long for STRING(16), in segments: 0607 0012h, value kept
        let long = [b'y'; 17];
        assert_eq!(
            c.download_segmented(sd, E72, 0, &long, false).await,
            Err(LENGTH_TOO_HIGH)
        );
        assert_eq!(c.upload(sd, E72, 0).await, Ok(b"axis cfg 7".to_vec()));

        // E-068: the second segment repeats toggle 0
        let r = c.sdo(sd, &[0x21, i0, i1, 0, 16, 0, 0, 0]).await.unwrap();
        assert_eq!(r[0], 0x60);
        let r = c
            .sdo(sd, &[0x00, b'a', b'b', b'c', b'd', b'e', b'f', b'g'])
            .await
            .unwrap();
        assert_eq!(r[0], 0x20);
        let r = c.sdo(sd, &[0x00, b'h', b'i', b'j', b'k', b'l', b'm', b'n']).await;
        assert_eq!(r, Err(TOGGLE_BIT));
        assert_eq!(
            c.upload(sd, E72, 0).await,
            Ok(b"axis cfg 7".to_vec()),
            "nothing written"
        );
        // the transfer ended with the abort: a further segment is unknown (0504 0001h)
        let r = c.sdo(sd, &[0x10, b'o', b'p', 0, 0, 0, 0, 0]).await;
        assert_eq!(r, Err(SdoAbort::INVALID_COMMAND.0));

        // a segment longer than 7 bytes (ETG.1000.6): as long as the mailbox data says
        let r = c.sdo(sd, &[0x21, i0, i1, 0, 12, 0, 0, 0]).await.unwrap();
        assert_eq!(r[0], 0x60);
        let mut seg = vec![0x01];
        seg.extend_from_slice(b"twelve bytes");
        let r = c.sdo(sd, &seg).await.unwrap();
        assert_eq!(r[0], 0x20, "last segment acknowledged");
        assert_eq!(c.upload(sd, E72, 0).await, Ok(b"twelve bytes".to_vec()));
        c.download_segmented(sd, E72, 0, b"axis cfg 7", false)
            .await
            .unwrap();

        // E-069: a segmented download left idle for more than 1 s times out
        let r = c.sdo(sd, &[0x21, i0, i1, 0, 16, 0, 0, 0]).await.unwrap();
        assert_eq!(r[0], 0x60);
        {
            let mut s = sim.borrow_mut();
            let t = s.now().as_ns() + ecat::coe::SDO_TIMEOUT.as_ns() + 1_000_000;
            s.advance_to(nanos::Nanos::from_ns(t));
        }
        let r = c.sdo(sd, &[0x00, b'a', b'b', b'c', b'd', b'e', b'f', b'g']).await;
        assert_eq!(r, Err(SdoAbort::TIMEOUT.0));
        assert_eq!(c.upload(sd, E72, 0).await, Ok(b"axis cfg 7".to_vec()));
    });
}

#[test]
fn e066_e068_e078_segmented_complete_upload_of_10f3h_and_toggle_error() {
    let sim = line(1);
    with_sdo(&sim, async |sd, c| {
        // 10F3h from sub 0: 2 + 6 + 20 × 28 bytes, more than one mailbox
        let (data, kind) = c.upload_kind(sd, 0x10F3, 0, true).await.unwrap();
        assert_eq!(kind, UploadKind::Segmented);
        let mut expected = vec![25, 0];
        for sub in 1..=25u8 {
            let mut v = local_read(&sim, 0x10F3, sub);
            let e = drive_ecat::objects::find(0x10F3)
                .unwrap()
                .1
                .info
                .entry(sub)
                .unwrap();
            v.resize(e.data_type.bytes(), 0);
            expected.extend_from_slice(&v);
        }
        assert_eq!(data.len(), 568);
        assert_eq!(
            data, expected,
            "complete access layout: sub 0 as 16 bits, then each entry"
        );

        // E-068: an upload segment with the wrong toggle bit
        let r = c.sdo(sd, &[0x50, 0xF3, 0x10, 0, 0, 0, 0, 0]).await.unwrap();
        assert_eq!(r[..8], [0x41, 0xF3, 0x10, 0, 0x38, 0x02, 0, 0], "size only, 568");
        let r = c.sdo(sd, &[0x60, 0, 0, 0, 0, 0, 0, 0]).await.unwrap();
        assert_eq!(r[0] & 0xF0, 0x00, "first segment, toggle 0");
        let r = c.sdo(sd, &[0x60, 0, 0, 0, 0, 0, 0, 0]).await;
        assert_eq!(r, Err(TOGGLE_BIT));
        // the abort ended it: a new upload starts cleanly
        assert_eq!(c.upload_kind(sd, 0x10F3, 0, true).await.unwrap().0, expected);
    });
}

#[test]
fn e078_complete_access_upload_1018h_1600h_and_download_1c12h_in_cia301_order() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let mut c = CoeClient::new();
        // 1018h from sub 0 and from sub 1
        let mut identity = vec![4, 0];
        for v in [
            drive_ecat::VENDOR_ID,
            variant().product_code(),
            revision(Template::SdoInfo),
            drive_ecat::SERIAL,
        ] {
            identity.extend_from_slice(&v.to_le_bytes());
        }
        assert_eq!(
            c.upload_kind(&sd, 0x1018, 0, true).await,
            Ok((identity.clone(), UploadKind::Normal))
        );
        assert_eq!(
            c.upload_kind(&sd, 0x1018, 1, true).await.unwrap().0,
            identity[2..]
        );
        // 1600h: the 8 entries of the default RxPDO
        let rx_default: Vec<u32> = vec![
            0x6040_0010,
            0x6060_0008,
            0x607A_0020,
            0x60FF_0020,
            0x60B1_0020,
            0x60B2_0010,
            0x6071_0010,
            0x60FE_0120,
        ];
        let mut map = vec![8, 0];
        rx_default
            .iter()
            .for_each(|m| map.extend_from_slice(&m.to_le_bytes()));
        assert_eq!(c.upload_kind(&sd, 0x1600, 0, true).await.unwrap().0, map);
        // complete access needs an ARRAY or RECORD from sub 0 or 1
        assert_eq!(c.upload_kind(&sd, 0x6040, 0, true).await, Err(UNSUPPORTED_ACCESS));
        assert_eq!(c.upload_kind(&sd, 0x1018, 2, true).await, Err(UNSUPPORTED_ACCESS));

        // 1C12h: two RxPDOs (the entries are written while sub 0 = 0, CiA 301)
        let assign = [2, 0, 0x00, 0x16, 0x02, 0x16];
        c.download_normal(&sd, 0x1C12, 0, &assign, true).await.unwrap();
        assert_eq!(c.upload_kind(&sd, 0x1C12, 0, true).await.unwrap().0, assign);
        assert_eq!(c.upload(&sd, 0x1C12, 2).await, Ok(vec![0x02, 0x16]));
        // refused before anything is written: count above 4, data too short
        let before = settled(&sim);
        let five = [5, 0, 0, 0x16, 1, 0x16, 2, 0x16, 3, 0x16, 0, 0x16];
        assert_eq!(
            c.download_normal(&sd, 0x1C12, 0, &five, true).await,
            Err(VALUE_TOO_HIGH)
        );
        assert_eq!(
            c.download_normal(&sd, 0x1C12, 0, &[2, 0, 0, 0x16], true).await,
            Err(LENGTH_TOO_LOW)
        );
        assert_eq!(settled(&sim), before, "nothing written");
        // a TxPDO in the RxPDO assignment: refused by the entry write, after
        // sub 0 = 0; the old assignment comes back, nothing changed
        assert_eq!(
            c.download_normal(&sd, 0x1C12, 0, &[1, 0, 0x00, 0x1A], true).await,
            Err(PARAMETER_INCOMPATIBLE)
        );
        assert_eq!(c.upload_kind(&sd, 0x1C12, 0, true).await.unwrap().0, assign);
        assert_eq!(settled(&sim), before, "the refused assignment changed nothing");
        // the mailbox fuzz target's finding: an expedited complete download
        // of 1600h:01 (size not indicated: four bytes 6Eh, entry 6E6Eh:6Eh)
        // was refused with 0604 0041h after sub 0 = 0, and the default
        // mapping was gone
        assert_eq!(
            c.download_normal(&sd, 0x1600, 1, &[0x6E; 4], true).await,
            Err(SdoAbort::NOT_MAPPABLE.0)
        );
        assert_eq!(c.upload_kind(&sd, 0x1600, 0, true).await.unwrap().0, map);
        assert_eq!(settled(&sim), before, "the refused mapping changed nothing");
        // back to the default
        c.download_normal(&sd, 0x1C12, 0, &[1, 0, 0x00, 0x16], true)
            .await
            .unwrap();
        assert_eq!(
            c.upload_kind(&sd, 0x1C12, 0, true).await.unwrap().0,
            [1, 0, 0x00, 0x16]
        );

        // 1600h in segments with complete access: a new mapping and back
        let mut short = vec![2, 0];
        short.extend_from_slice(&0x6040_0010u32.to_le_bytes());
        short.extend_from_slice(&0x60FF_0020u32.to_le_bytes());
        c.download_segmented(&sd, 0x1600, 0, &short, true).await.unwrap();
        assert_eq!(c.upload_kind(&sd, 0x1600, 0, true).await.unwrap().0, short);
        assert_eq!(objects(&sim).process_data_bytes(), Some((6, 29)));
        c.download_segmented(&sd, 0x1600, 0, &map, true).await.unwrap();
        assert_eq!(c.upload_kind(&sd, 0x1600, 0, true).await.unwrap().0, map);
        assert_eq!(objects(&sim).process_data_bytes(), Some((23, 29)));

        // not in Safe-Op: 0800 0022h, nothing written
        let group = group.into_safe_op(md).await.expect("PRE-OP -> SAFE-OP");
        let sd = group.subdevice(md, 0).unwrap();
        let before = settled(&sim);
        assert_eq!(
            c.download_normal(&sd, 0x1C12, 0, &[1, 0, 0x01, 0x16], true).await,
            Err(DEVICE_STATE)
        );
        assert_eq!(settled(&sim), before);
    });
}

#[test]
fn e078_ethercrab_complete_access_from_subindex_1_to_assignment_and_mapping() {
    // ethercrab's `SubIndex::Complete` is complete access from subindex 1
    // (sub 0 not in the data): the entries, then sub 0 = their number
    use ethercrab::SubIndex::Complete;
    let sim = line(1);
    with_sdo(&sim, async |sd, c| {
        let assign: [u8; 2] = sd.sdo_read(0x1C12, Complete).await.expect("CA upload from sub 1");
        assert_eq!(assign, [0x00, 0x16]);
        sd.sdo_write(0x1C12, Complete, 0x1602u16)
            .await
            .expect("CA download from sub 1 of 1C12h");
        assert_eq!(
            c.upload_kind(sd, 0x1C12, 0, true).await.unwrap().0,
            [1, 0, 0x02, 0x16]
        );
        sd.sdo_write(0x1C12, Complete, 0x1600u16).await.unwrap();
        // a one-entry RxPDO: controlword only
        sd.sdo_write(0x1600, Complete, 0x6040_0010u32)
            .await
            .expect("CA download from sub 1 of 1600h");
        assert_eq!(c.upload(sd, 0x1600, 0).await, Ok(vec![1]));
        assert_eq!(objects(&sim).process_data_bytes(), Some((2, 29)));
        // a refused entry puts the mapping back, as from sub 0
        assert_eq!(
            c.download_normal(sd, 0x1600, 1, &0x6041_0010u32.to_le_bytes(), true)
                .await,
            Err(SdoAbort::NOT_MAPPABLE.0)
        );
        assert_eq!(c.upload(sd, 0x1600, 0).await, Ok(vec![1]));
        assert_eq!(
            c.upload(sd, 0x1600, 1).await,
            Ok(0x6040_0010u32.to_le_bytes().to_vec())
        );
    });
}
