//! SDO Information service: OD lists, object and entry descriptions, fragmentation (spec §7, E-079..E-085).

use super::*;

// ---------------------------------------------------------------- SDO Info

/// Checks the SDO Info header of `r`: (opcode incl. incomplete bit, fragments left, data).
fn info_parts(r: &[u8]) -> (u8, u16, &[u8]) {
    assert_eq!(&r[..2], &[0x00, 0x80], "SDO Info header");
    assert_eq!(r[3], 0);
    (r[2], u16::from_le_bytes([r[4], r[5]]), &r[6..])
}

fn u16s(b: &[u8]) -> Vec<u16> {
    b.chunks(2).map(|c| u16::from_le_bytes([c[0], c[1]])).collect()
}

#[test]
fn e079_sdo_info_only_when_configured() {
    let mut t = T::new(64);
    t.srv = CoeServer::new(CoeConfig::from_details(crate::desc::coe_details::SDO));
    assert_eq!(
        t.raw(&[0x00, 0x80, 0x01, 0, 0, 0, 0x01, 0x00]),
        Err(MailboxError::SERVICE_NOT_SUPPORTED)
    );
    assert_eq!(
        CoeConfig::from_details(crate::desc::coe_details::SDO_INFO | crate::desc::coe_details::SDO),
        CoeConfig {
            sdo_info: true,
            complete_access: false
        }
    );
}

#[test]
fn e080_sdo_info_od_list_all_rx_tx() {
    let mut t = T::new(128);
    let r = t.info(opcode::OD_LIST_REQ, &[1, 0]);
    let (op, left, data) = info_parts(&r);
    assert_eq!((op, left), (0x02, 0));
    assert_eq!(
        u16s(data),
        [1, 0x1C12, 0x2000, 0x2001, 0x2002, 0x2003, 0x2004, 0x2005, 0x2006]
    );
    let r = t.info(opcode::OD_LIST_REQ, &[2, 0]);
    assert_eq!(u16s(info_parts(&r).2), [2, 0x2000]);
    let r = t.info(opcode::OD_LIST_REQ, &[3, 0]);
    assert_eq!(u16s(info_parts(&r).2), [3, 0x2002, 0x2004]);
    // lengths: all, rx, tx, backup, settings
    let r = t.info(opcode::OD_LIST_REQ, &[0, 0]);
    assert_eq!(u16s(info_parts(&r).2), [0, 8, 1, 2, 0, 0]);
}

#[test]
fn e081_backup_and_settings_lists_are_empty() {
    let mut t = T::new(128);
    for lt in [4u8, 5] {
        let r = t.info(opcode::OD_LIST_REQ, &[lt, 0]);
        assert_eq!(info_parts(&r), (0x02, 0, &[lt, 0][..]));
    }
    // an unknown list type: SDO Info error
    let r = t.info(opcode::OD_LIST_REQ, &[9, 0]);
    assert_eq!(info_parts(&r), (0x07, 0, &0x0800_0000u32.to_le_bytes()[..]));
}

#[test]
fn e080_sdo_info_fragmentation() {
    // 40 data bytes: 34 bytes (17 words) of list per fragment
    let mut t = T::new(40);
    t.dict.many = true;
    let r = t.info(opcode::OD_LIST_REQ, &[1, 0]);
    // 2 + 2 * 108 = 218 bytes → 7 fragments
    let (op, left, data) = info_parts(&r);
    assert_eq!((op, left, data.len()), (0x82, 6, 34));
    assert_eq!(u16s(data)[0], 1);
    let mut all = u16s(data)[1..].to_vec();
    assert!(t.srv.has_fragments());
    let mut expect_left = 5u16;
    while let Some(r) = t.fragment() {
        let (op, left, data) = info_parts(&r);
        assert_eq!(left, expect_left);
        assert_eq!(op, if left > 0 { 0x82 } else { 0x02 });
        all.extend(u16s(data));
        expect_left = expect_left.wrapping_sub(1);
    }
    assert_eq!(expect_left, u16::MAX, "the last one had 0 left");
    let mut expect: Vec<u16> = OBJECTS.iter().map(|o| o.index).collect();
    expect.extend((0..MANY_N as u16).map(|i| 0x3000 + i));
    assert_eq!(all, expect);
    // a new request ends a list in progress
    t.info(opcode::OD_LIST_REQ, &[1, 0]);
    assert!(t.srv.has_fragments());
    t.sdo(&upload_req(0x2000, 0));
    assert!(!t.srv.has_fragments());
    assert!(t.fragment().is_none());
}

#[test]
fn e082_object_description() {
    let mut t = T::new(128);
    let r = t.info(opcode::OBJECT_DESC_REQ, &[0x02, 0x20]);
    let (op, left, data) = info_parts(&r);
    assert_eq!((op, left), (0x04, 0));
    // index, data type (RECORD), max subindex, object code, name
    assert_eq!(&data[..6], &[0x02, 0x20, 0x2A, 0x00, 3, 9]);
    assert_eq!(&data[6..], b"Record");
    let r = t.info(opcode::OBJECT_DESC_REQ, &[0x12, 0x1C]);
    // array of UINT16 with capacity 4 (sub 0 max)
    assert_eq!(&info_parts(&r).2[..6], &[0x12, 0x1C, 0x06, 0x00, 4, 8]);
    let r = t.info(opcode::OBJECT_DESC_REQ, &[0x01, 0x20]);
    assert_eq!(&info_parts(&r).2[..6], &[0x01, 0x20, 0x0A, 0x00, 0, 7]);
    // unknown object
    let r = t.info(opcode::OBJECT_DESC_REQ, &[0x00, 0x70]);
    assert_eq!(info_parts(&r), (0x07, 0, &0x0602_0000u32.to_le_bytes()[..]));
    // a long name is cut to the mailbox
    let mut t = T::new(16);
    let r = t.info(opcode::OBJECT_DESC_REQ, &[0x12, 0x1C]);
    assert_eq!(r.len(), 16);
    assert_eq!(&r[12..], b"RxPD");
}

#[test]
fn e082_entry_description() {
    let mut t = T::new(128);
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x02, 0x20, 0x01, 0x00]);
    let (op, left, data) = info_parts(&r);
    assert_eq!((op, left), (0x06, 0));
    // index, sub, value info, data type, bit length, access (RW + TxPDO), name
    assert_eq!(
        &data[..10],
        &[0x02, 0x20, 0x01, 0x00, 0x06, 0x00, 16, 0, 0xBF, 0x00]
    );
    assert_eq!(&data[10..], b"First");
    // default, minimum, maximum on request
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x02, 0x20, 0x02, 0x77]);
    let data = info_parts(&r).2;
    assert_eq!(
        &data[..10],
        &[0x02, 0x20, 0x02, 0x77, 0x07, 0x00, 32, 0, 0x3F, 0x00]
    );
    assert_eq!(&data[10..22], &[7, 0, 0, 0, 0, 0, 0, 0, 0xE8, 0x03, 0, 0]);
    assert_eq!(&data[22..], b"Second");
    // minimum requested but not limited: not supplied
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x02, 0x20, 0x01, 0x20]);
    assert_eq!(info_parts(&r).2[3], 0x00);
    // signed minimum of a UINT16 entry is sent in the entry's size
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x00, 0x20, 0x00, 0x20]);
    let data = info_parts(&r).2;
    assert_eq!(&data[3..12], &[0x20, 0x06, 0x00, 16, 0, 0x7F, 0, 0xFB, 0xFF]);
    // array element through the template; RxPDO/TxPDO bits and write-only access
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x12, 0x1C, 0x03, 0x00]);
    assert_eq!(&info_parts(&r).2[10..], b"PDO");
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x03, 0x20, 0x00, 0x00]);
    assert_eq!(&info_parts(&r).2[8..10], &[0x38, 0x00]);
    // errors
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x02, 0x20, 0x04, 0x00]);
    assert_eq!(info_parts(&r), (0x07, 0, &0x0609_0011u32.to_le_bytes()[..]));
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x12, 0x1C, 0x05, 0x00]);
    assert_eq!(info_parts(&r).2, &0x0609_0011u32.to_le_bytes()[..]);
    let r = t.info(opcode::ENTRY_DESC_REQ, &[0x00, 0x70, 0x00, 0x00]);
    assert_eq!(info_parts(&r).2, &0x0602_0000u32.to_le_bytes()[..]);
    // unknown opcode
    let r = t.info(0x09, &[0, 0]);
    assert_eq!(info_parts(&r), (0x07, 0, &0x0504_0001u32.to_le_bytes()[..]));
}

#[test]
fn e085_sdo_info_in_preop_safeop_op() {
    for state in [AlState::PreOp, AlState::SafeOp, AlState::Op] {
        let mut t = T::new(128);
        t.state = state;
        let r = t.info(opcode::OD_LIST_REQ, &[1, 0]);
        assert_eq!(info_parts(&r).0, 0x02);
    }
}
