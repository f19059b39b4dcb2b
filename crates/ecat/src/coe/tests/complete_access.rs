//! SDO complete access: upload and download of a whole object (E-078).

use super::*;

// ---------------------------------------------------------------- complete access

#[test]
fn e078_complete_access_upload_from_sub0_and_sub1() {
    let mut t = T::new(64);
    // record: sub 0 as 16 bits, then 2 + 4 + 1 bytes
    let r = t.sdo(&[0x50, 0x02, 0x20, 0x00, 0, 0, 0, 0]);
    assert_eq!(
        resp(&r),
        &[0x41, 0x02, 0x20, 0x00, 9, 0, 0, 0, 3, 0, 0x11, 0x11, 0x22, 0x22, 0x22, 0x22, 0x33]
    );
    let r = t.sdo(&[0x50, 0x02, 0x20, 0x01, 0, 0, 0, 0]);
    assert_eq!(
        resp(&r),
        &[0x41, 0x02, 0x20, 0x01, 7, 0, 0, 0, 0x11, 0x11, 0x22, 0x22, 0x22, 0x22, 0x33]
    );
    // array with a template entry: the present count (2), expedited (≤ 4 bytes from sub 1)
    let r = t.sdo(&[0x50, 0x12, 0x1C, 0x00, 0, 0, 0, 0]);
    assert_eq!(
        resp(&r),
        &[0x41, 0x12, 0x1C, 0x00, 6, 0, 0, 0, 2, 0, 0x00, 0x16, 0x01, 0x16]
    );
    let r = t.sdo(&[0x50, 0x12, 0x1C, 0x01, 0, 0, 0, 0]);
    assert_eq!(resp(&r), &[0x43, 0x12, 0x1C, 0x01, 0x00, 0x16, 0x01, 0x16]);
    // only sub 0 or 1
    let r = t.sdo(&[0x50, 0x02, 0x20, 0x02, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0x2002, 2), 0x0601_0000);
}

#[test]
fn e078_complete_access_download_writes_sub0_zero_entries_then_count() {
    let mut t = T::new(64);
    let r = t.sdo(&[
        0x31, 0x12, 0x1C, 0x00, 8, 0, 0, 0, 3, 0, 0x00, 0x16, 0x02, 0x16, 0x03, 0x16,
    ]);
    assert_eq!(resp(&r), &[0x60, 0x12, 0x1C, 0x00, 0, 0, 0, 0]);
    assert_eq!(
        t.dict.writes,
        vec![
            (0x1C12, 0, vec![0]),
            (0x1C12, 1, vec![0x00, 0x16]),
            (0x1C12, 2, vec![0x02, 0x16]),
            (0x1C12, 3, vec![0x03, 0x16]),
            (0x1C12, 0, vec![3]),
        ]
    );
    // expedited complete access from sub 1 (as ethercrab sends it): the same
    // order, sub 0 = the number of entries in the data (the drive's dictionary
    // refuses entries while sub 0 != 0)
    t.dict.writes.clear();
    let r = t.sdo(&[0x33, 0x12, 0x1C, 0x01, 0x10, 0x1A, 0x11, 0x1A]);
    assert_eq!(resp(&r)[0], 0x60);
    assert_eq!(
        t.dict.writes,
        vec![
            (0x1C12, 0, vec![0]),
            (0x1C12, 1, vec![0x10, 0x1A]),
            (0x1C12, 2, vec![0x11, 0x1A]),
            (0x1C12, 0, vec![2]),
        ]
    );
}

#[test]
fn e078_complete_access_download_segmented_record() {
    let mut t = T::new(64);
    t.sdo(&[0x31, 0x02, 0x20, 0x00, 9, 0, 0, 0]);
    t.sdo(&[0x00, 3, 0, 0xAA, 0xAA, 0x05, 0x00, 0x00]);
    // t = 1, n = 5, c = 1
    let r = t.sdo(&[0x1B, 0x00, 0xBB, 0, 0, 0, 0, 0]);
    assert_eq!(resp(&r)[0], 0x30);
    assert_eq!(
        t.dict.writes,
        vec![
            (0x2002, 0, vec![0]),
            (0x2002, 1, vec![0xAA, 0xAA]),
            (0x2002, 2, vec![5, 0, 0, 0]),
            (0x2002, 3, vec![0xBB]),
            (0x2002, 0, vec![3]),
        ]
    );
}

#[test]
fn e078_complete_access_download_checks_before_writing() {
    let mut t = T::new(64);
    // sub 2 above its maximum (1000)
    let r = t.sdo(&[
        0x31, 0x02, 0x20, 0x00, 9, 0, 0, 0, 3, 0, 1, 1, 0xD0, 0x07, 0, 0, 1,
    ]);
    assert_eq!(abort(&r, 0x2002, 0), 0x0609_0031);
    // one byte short / long
    let r = t.sdo(&[0x31, 0x02, 0x20, 0x00, 8, 0, 0, 0, 3, 0, 1, 1, 5, 0, 0, 0]);
    assert_eq!(abort(&r, 0x2002, 0), 0x0607_0013);
    let r = t.sdo(&[0x31, 0x02, 0x20, 0x00, 10, 0, 0, 0, 3, 0, 1, 1, 5, 0, 0, 0, 1, 9]);
    assert_eq!(abort(&r, 0x2002, 0), 0x0607_0012);
    // more entries than the array holds
    let r = t.sdo(&[0x31, 0x12, 0x1C, 0x00, 4, 0, 0, 0, 5, 0, 0, 0]);
    assert_eq!(abort(&r, 0x1C12, 0), 0x0609_0031);
    // sub 3 is writable in PreOp only
    t.state = AlState::SafeOp;
    let r = t.sdo(&[0x31, 0x02, 0x20, 0x00, 9, 0, 0, 0, 3, 0, 1, 1, 5, 0, 0, 0, 1]);
    assert_eq!(abort(&r, 0x2002, 0), 0x0800_0022);
    assert!(t.dict.writes.is_empty());
    // in PreOp the same value goes through
    t.state = AlState::PreOp;
    let r = t.sdo(&[0x31, 0x02, 0x20, 0x00, 9, 0, 0, 0, 3, 0, 1, 1, 5, 0, 0, 0, 1]);
    assert_eq!(resp(&r)[0], 0x60);
    assert_eq!(t.dict.writes.len(), 5);
}

/// A refusal part-way (the dictionary's consistency check on entry 2)
/// aborts with its code and puts entry 1 and sub 0 back: the object reads
/// as before (found by the mailbox fuzz target's oracle: a complete
/// download of 1600h:01 aborted 0604 0041h and left the mapping empty).
#[test]
fn e078_complete_access_refused_entry_puts_the_old_values_back() {
    let mut t = T::new(64);
    t.dict.values.insert((0x1C12, 0), vec![1]);
    t.dict.values.insert((0x1C12, 1), vec![0x01, 0x16]);
    t.dict.values.insert((0x1C12, 2), vec![0x00, 0x00]);
    t.dict.refuse = Some((0x1C12, 2, SdoAbort::PARAMETER_INCOMPATIBLE));
    let r = t.sdo(&[0x31, 0x12, 0x1C, 0x00, 6, 0, 0, 0, 2, 0, 0x00, 0x16, 0x05, 0x16]);
    assert_eq!(abort(&r, 0x1C12, 0), 0x0604_0043);
    assert_eq!(
        t.dict.writes,
        vec![
            (0x1C12, 0, vec![0]),
            (0x1C12, 1, vec![0x00, 0x16]),
            (0x1C12, 1, vec![0x01, 0x16]),
            (0x1C12, 0, vec![1]),
        ]
    );
    assert_eq!(t.dict.values[&(0x1C12, 0)], vec![1]);
    assert_eq!(t.dict.values[&(0x1C12, 1)], vec![0x01, 0x16]);
    // the final sub 0 refused (e.g. 0604 0042h, too long): every entry back
    let mut t = T::new(64);
    t.dict.values.insert((0x1C12, 0), vec![1]);
    t.dict.values.insert((0x1C12, 1), vec![0x01, 0x16]);
    t.dict.refuse_value = Some((0x1C12, 0, vec![2], SdoAbort::PDO_LENGTH));
    let r = t.sdo(&[0x31, 0x12, 0x1C, 0x00, 6, 0, 0, 0, 2, 0, 0x00, 0x16, 0x05, 0x16]);
    assert_eq!(abort(&r, 0x1C12, 0), 0x0604_0042);
    assert_eq!(t.dict.values[&(0x1C12, 0)], vec![1]);
    assert_eq!(t.dict.values[&(0x1C12, 1)], vec![0x01, 0x16]);
}

#[test]
fn e078_complete_access_off_or_without_metadata_aborts_0601_0000() {
    let mut t = T::new(64);
    t.srv = CoeServer::new(CoeConfig {
        sdo_info: true,
        complete_access: false,
    });
    let r = t.sdo(&[0x50, 0x12, 0x1C, 0x00, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0x1C12, 0), 0x0601_0000);
    let mut t = T::new(64);
    let r = t.sdo(&[0x50, 0x00, 0x70, 0x00, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0x7000, 0), 0x0601_0000);
}
