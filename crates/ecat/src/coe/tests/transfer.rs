//! SDO transfers: expedited, normal and segmented (spec §6.1–6.4), and their aborts (E-062..E-073, E-077).

use super::*;

// ---------------------------------------------------------------- expedited

#[test]
fn e063_expedited_upload_with_size() {
    let mut t = T::new(64);
    let r = t.sdo(&upload_req(0x2000, 0));
    assert_eq!(resp(&r), &[0x4B, 0x00, 0x20, 0x00, 0x34, 0x12, 0, 0]);
    let r = t.sdo(&upload_req(0x2002, 3));
    assert_eq!(resp(&r), &[0x4F, 0x02, 0x20, 0x03, 0x33, 0, 0, 0]);
    let r = t.sdo(&upload_req(0x2004, 0));
    assert_eq!(resp(&r), &[0x43, 0x04, 0x20, 0x00, 0xEF, 0xBE, 0xAD, 0xDE]);
}

#[test]
fn e063_expedited_download_sizes() {
    let mut t = T::new(64);
    // 2Fh: 1 byte, 2Bh: 2 bytes, 23h: 4 bytes, 22h: size not indicated (cut to the entry)
    for (cmd, index, sub, value) in [
        (0x2F, 0x2002, 3, &[0xA1][..]),
        (0x2B, 0x2000, 0, &[0x01, 0x02][..]),
        (0x23, 0x2002, 2, &[0x04, 0x03, 0x02, 0x01][..]),
        (0x22, 0x2000, 0, &[0x0A, 0x0B][..]),
    ] {
        let [i0, i1] = u16::to_le_bytes(index);
        let mut req = [cmd, i0, i1, sub, 0, 0, 0, 0];
        req[4..4 + value.len()].copy_from_slice(value);
        if cmd == 0x22 {
            req[6] = 0xFF; // the unused bytes of a size-less request
        }
        let r = t.sdo(&req);
        assert_eq!(resp(&r), &[0x60, i0, i1, sub, 0, 0, 0, 0]);
        assert_eq!(t.dict.writes.last().unwrap(), &(index, sub, value.to_vec()));
    }
    assert_eq!(t.dict.writes.len(), 4);
}

#[test]
fn e073_expedited_length_mismatch_aborts_0607_0012() {
    let mut t = T::new(64);
    // 27h: 3 bytes to a UINT16
    let r = t.sdo(&[0x27, 0x00, 0x20, 0x00, 1, 2, 3, 0]);
    assert_eq!(abort(&r, 0x2000, 0), 0x0607_0012);
    let r = t.sdo(&[0x2F, 0x02, 0x20, 0x02, 1, 0, 0, 0]);
    assert_eq!(abort(&r, 0x2002, 2), 0x0607_0013);
    assert!(t.dict.writes.is_empty());
}

// ---------------------------------------------------------------- normal

#[test]
fn e064_normal_upload_carries_size_and_data() {
    let mut t = T::new(64);
    let r = t.sdo(&upload_req(0x2001, 0));
    assert_eq!(r.len(), 26);
    let mut expect = vec![0x41, 0x01, 0x20, 0x00, 16, 0, 0, 0];
    expect.extend(1..=16u8);
    assert_eq!(resp(&r), &expect[..]);
    assert!(!t.srv.transfer_in_progress());
    assert_eq!(t.dict.reads, 1);
}

#[test]
fn e064_normal_download_with_data_in_initiate() {
    let mut t = T::new(64);
    let mut req = vec![0x21, 0x01, 0x20, 0x00, 16, 0, 0, 0];
    req.extend((0..16u8).map(|b| b ^ 0xFF));
    let r = t.sdo(&req);
    assert_eq!(resp(&r), &[0x60, 0x01, 0x20, 0x00, 0, 0, 0, 0]);
    assert_eq!(t.dict.writes, vec![(0x2001, 0, req[8..].to_vec())]);
    assert!(!t.srv.transfer_in_progress());
}

#[test]
fn e064_e065_partial_initiate_data_then_long_segment() {
    let mut t = T::new(64);
    // initiate carries 5 of 16 bytes, one 11-byte segment (longer than 7) ends it
    let r = t.sdo(&[0x21, 0x01, 0x20, 0x00, 16, 0, 0, 0, 1, 2, 3, 4, 5]);
    assert_eq!(resp(&r), &[0x60, 0x01, 0x20, 0x00, 0, 0, 0, 0]);
    assert!(t.dict.writes.is_empty());
    let r = t.sdo(&[0x01, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16]);
    assert_eq!(resp(&r), &[0x20, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(t.dict.writes, vec![(0x2001, 0, (1..=16).collect())]);
}

// ---------------------------------------------------------------- segmented (§6.4)

#[test]
fn e065_e067_segmented_download_worked_example() {
    let mut t = T::new(64);
    let exchange: [(&[u8], &[u8]); 4] = [
        (
            &[0x21, 0x01, 0x20, 0x00, 0x10, 0x00, 0x00, 0x00],
            &[0x60, 0x01, 0x20, 0x00, 0x00, 0x00, 0x00, 0x00],
        ),
        (
            &[0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07],
            &[0x20, 0, 0, 0, 0, 0, 0, 0],
        ),
        (
            &[0x10, 0x08, 0x09, 0x0A, 0x0B, 0x0C, 0x0D, 0x0E],
            &[0x30, 0, 0, 0, 0, 0, 0, 0],
        ),
        (
            &[0x0B, 0x0F, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00],
            &[0x20, 0, 0, 0, 0, 0, 0, 0],
        ),
    ];
    for (i, (c, s)) in exchange.iter().enumerate() {
        let r = t.sdo(c);
        assert_eq!(resp(&r), *s, "step {i}");
        // one write, at the end
        assert_eq!(t.dict.writes.len(), usize::from(i == 3), "step {i}");
    }
    assert_eq!(t.dict.writes, vec![(0x2001, 0, (1..=16).collect())]);
}

#[test]
fn e066_e067_segmented_upload_worked_example() {
    // a 16-byte mailbox (10 data bytes): 7-byte segments as in S §9.3.2.3
    let mut t = T::new(10);
    let exchange: [(&[u8], &[u8]); 4] = [
        (
            &[0x40, 0x01, 0x20, 0x00, 0, 0, 0, 0],
            &[0x41, 0x01, 0x20, 0x00, 0x10, 0x00, 0x00, 0x00],
        ),
        (
            &[0x60, 0, 0, 0, 0, 0, 0, 0],
            &[0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07],
        ),
        (
            &[0x70, 0, 0, 0, 0, 0, 0, 0],
            &[0x10, 0x08, 0x09, 0x0A, 0x0B, 0x0C, 0x0D, 0x0E],
        ),
        (
            &[0x60, 0, 0, 0, 0, 0, 0, 0],
            &[0x0B, 0x0F, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00],
        ),
    ];
    for (i, (c, s)) in exchange.iter().enumerate() {
        let r = t.sdo(c);
        assert_eq!(resp(&r), *s, "step {i}");
    }
    assert_eq!(t.dict.reads, 1, "read once at the initiate");
    assert!(!t.srv.transfer_in_progress());
    // the transfer is over: another segment request is unknown
    let r = t.sdo(&[0x70, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0, 0), 0x0504_0001);
}

#[test]
fn e066_segmented_upload_uses_the_mailbox_size() {
    // 20 data bytes: the value (16) does not fit the initiate (10 + 16), one
    // 16-byte segment (segment data = mailbox data − 3) with c = 1, n = 0
    let mut t = T::new(20);
    let r = t.sdo(&upload_req(0x2001, 0));
    assert_eq!(resp(&r), &[0x41, 0x01, 0x20, 0x00, 16, 0, 0, 0]);
    let r = t.sdo(&[0x60, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(r.len(), 19);
    assert_eq!(resp(&r)[0], 0x01);
    assert_eq!(&resp(&r)[1..], &(1..=16).collect::<Vec<u8>>()[..]);
    // a 120-byte value in a 40-byte mailbox: 37-byte segments, last has 9 + padding
    let mut t = T::new(40);
    t.dict.values.insert((0x2005, 0), (0..120).collect());
    let r = t.sdo(&upload_req(0x2005, 0));
    assert_eq!(resp(&r), &[0x41, 0x05, 0x20, 0x00, 120, 0, 0, 0]);
    let mut got = Vec::new();
    let mut toggle = 0;
    loop {
        let r = t.sdo(&[0x60 | toggle, 0, 0, 0, 0, 0, 0, 0]);
        let s = resp(&r);
        assert_eq!(s[0] & 0x10, toggle, "toggle echoed");
        let n = if s.len() == 8 {
            7 - usize::from((s[0] >> 1) & 7)
        } else {
            s.len() - 1
        };
        got.extend_from_slice(&s[1..1 + n]);
        if s[0] & 1 != 0 {
            break;
        }
        toggle ^= 0x10;
    }
    assert_eq!(got, (0..120).collect::<Vec<u8>>());
}

// ---------------------------------------------------------------- aborts

#[test]
fn e068_toggle_error_aborts_0503_0000() {
    let mut t = T::new(64);
    t.sdo(&[0x21, 0x01, 0x20, 0x00, 16, 0, 0, 0]);
    t.sdo(&[0x00, 1, 2, 3, 4, 5, 6, 7]);
    // the second segment must carry t = 1
    let r = t.sdo(&[0x00, 8, 9, 10, 11, 12, 13, 14]);
    assert_eq!(abort(&r, 0x2001, 0), 0x0503_0000);
    assert!(t.dict.writes.is_empty());
    assert!(!t.srv.transfer_in_progress());
    // upload: first segment request with t = 1
    let mut t = T::new(10);
    t.sdo(&upload_req(0x2001, 0));
    let r = t.sdo(&[0x70, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0x2001, 0), 0x0503_0000);
}

#[test]
fn e069_segment_without_transfer_and_unknown_command_abort_0504_0001() {
    let mut t = T::new(64);
    let r = t.sdo(&[0x00, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(abort(&r, 0, 0), 0x0504_0001);
    let r = t.sdo(&[0x60, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0, 0), 0x0504_0001);
    // block download / block upload / ccs 7
    for cmd in [0xC6, 0xA4, 0xE0] {
        let r = t.sdo(&[cmd, 0x00, 0x20, 0x00, 0, 0, 0, 0]);
        assert_eq!(abort(&r, 0x2000, 0), 0x0504_0001, "cmd {cmd:#x}");
    }
    // an upload segment request during a download
    t.sdo(&[0x21, 0x01, 0x20, 0x00, 16, 0, 0, 0]);
    let r = t.sdo(&[0x60, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0x2001, 0), 0x0504_0001);
    assert!(!t.srv.transfer_in_progress());
}

#[test]
fn e069_protocol_timeout_aborts_0504_0000() {
    let mut t = T::new(64);
    t.sdo(&[0x21, 0x01, 0x20, 0x00, 16, 0, 0, 0]);
    t.now += Nanos::from_ms(900); // within the timeout
    let r = t.sdo(&[0x00, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(resp(&r)[0], 0x20);
    t.now += SDO_TIMEOUT + Nanos::from_ns(1);
    t.srv.tick(t.now);
    assert!(!t.srv.transfer_in_progress());
    // the next segment learns about it
    let r = t.sdo(&[0x10, 8, 9, 10, 11, 12, 13, 14]);
    assert_eq!(abort(&r, 0x2001, 0), 0x0504_0000);
    let r = t.sdo(&[0x0B, 15, 16, 0, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0, 0), 0x0504_0001);
    assert!(t.dict.writes.is_empty());
    // upload: timeout seen by handle itself
    let mut t = T::new(10);
    t.sdo(&upload_req(0x2001, 0));
    t.now += 2 * SDO_TIMEOUT;
    let r = t.sdo(&[0x60, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0x2001, 0), 0x0504_0000);
}

#[test]
fn e070_out_of_memory_aborts_0504_0005_before_any_write() {
    let mut t = T::new(64);
    // announced 5000 bytes > 4 KiB
    let r = t.sdo(&[0x21, 0x05, 0x20, 0x00, 0x88, 0x13, 0, 0]);
    assert_eq!(abort(&r, 0x2005, 0), 0x0504_0005);
    assert!(!t.srv.transfer_in_progress());
    // size-less normal download growing past 4 KiB
    t.sdo(&[0x20, 0x05, 0x20, 0x00, 0, 0, 0, 0]);
    let mut toggle = 0u8;
    let mut last = None;
    for _ in 0..(MAX_TRANSFER / 50 + 2) {
        let mut seg = vec![toggle];
        seg.extend([0x77; 50]);
        let r = t.sdo(&seg);
        if r[2] == 0x80 {
            last = Some(r);
            break;
        }
        toggle ^= 0x10;
    }
    assert_eq!(abort(&last.unwrap(), 0x2005, 0), 0x0504_0005);
    // upload of a 5000-byte value: the dictionary cannot fill the 4 KiB buffer
    let r = t.sdo(&upload_req(0x2005, 0));
    assert_eq!(abort(&r, 0x2005, 0), 0x0504_0005);
    assert!(t.dict.writes.is_empty());
}

#[test]
fn e071_access_aborts() {
    let mut t = T::new(64);
    let r = t.sdo(&upload_req(0x2003, 0));
    assert_eq!(abort(&r, 0x2003, 0), 0x0601_0001);
    let r = t.sdo(&[0x23, 0x04, 0x20, 0x00, 1, 2, 3, 4]);
    assert_eq!(abort(&r, 0x2004, 0), 0x0601_0002);
    // complete access to a VAR
    let r = t.sdo(&[0x50, 0x00, 0x20, 0x00, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0x2000, 0), 0x0601_0000);
    // write-only value can be written
    let r = t.sdo(&[0x23, 0x03, 0x20, 0x00, 1, 2, 3, 4]);
    assert_eq!(resp(&r)[0], 0x60);
}

#[test]
fn e072_unknown_object_and_subindex() {
    let mut t = T::new(64);
    let r = t.sdo(&upload_req(0x6000, 0));
    assert_eq!(abort(&r, 0x6000, 0), 0x0602_0000);
    let r = t.sdo(&upload_req(0x2002, 9));
    assert_eq!(abort(&r, 0x2002, 9), 0x0609_0011);
}

#[test]
fn e073_announced_size_mismatch_aborts_0607_0010() {
    let mut t = T::new(64);
    // fewer bytes than announced
    t.sdo(&[0x21, 0x01, 0x20, 0x00, 16, 0, 0, 0]);
    t.sdo(&[0x00, 1, 2, 3, 4, 5, 6, 7]);
    let r = t.sdo(&[0x13, 8, 9, 10, 11, 12, 13, 14]);
    assert_eq!(abort(&r, 0x2001, 0), 0x0607_0010);
    // more bytes than announced
    t.sdo(&[0x21, 0x01, 0x20, 0x00, 10, 0, 0, 0]);
    t.sdo(&[0x00, 1, 2, 3, 4, 5, 6, 7]);
    let r = t.sdo(&[0x11, 8, 9, 10, 11, 12, 13, 14]);
    assert_eq!(abort(&r, 0x2001, 0), 0x0607_0010);
    assert!(t.dict.writes.is_empty());
}

#[test]
fn e077_abort_frame_layout() {
    let mut t = T::new(64);
    let r = t.sdo(&upload_req(0x2003, 0));
    // service 2, 80h, index, subindex, additional code (LSB, MSB), error code, class
    assert_eq!(r, [0x00, 0x20, 0x80, 0x03, 0x20, 0x00, 0x01, 0x00, 0x01, 0x06]);
}

#[test]
fn abort_from_master_cancels_the_transfer_without_reply() {
    let mut t = T::new(64);
    t.sdo(&[0x21, 0x01, 0x20, 0x00, 16, 0, 0, 0]);
    t.sdo(&[0x00, 1, 2, 3, 4, 5, 6, 7]);
    let r = t.raw(&[0x00, 0x20, 0x80, 0x01, 0x20, 0x00, 0, 0, 0x04, 0x05]);
    assert_eq!(r, Ok(None));
    assert!(!t.srv.transfer_in_progress());
    let r = t.sdo(&[0x1B, 8, 9, 0, 0, 0, 0, 0]);
    assert_eq!(abort(&r, 0, 0), 0x0504_0001);
    assert!(t.dict.writes.is_empty());
}

#[test]
fn new_initiate_replaces_the_transfer_in_progress() {
    let mut t = T::new(64);
    t.sdo(&[0x21, 0x01, 0x20, 0x00, 16, 0, 0, 0]);
    t.sdo(&[0x00, 1, 2, 3, 4, 5, 6, 7]);
    let r = t.sdo(&upload_req(0x2000, 0));
    assert_eq!(resp(&r)[0], 0x4B);
    let r = t.sdo(&[0x10, 8, 9, 10, 11, 12, 13, 14]);
    assert_eq!(abort(&r, 0, 0), 0x0504_0001);
}

#[test]
fn short_frames_and_unknown_services_are_mailbox_errors() {
    let mut t = T::new(64);
    assert_eq!(
        t.raw(&[0x00, 0x20, 0x40, 0x00, 0x20]),
        Err(MailboxError::SIZE_TOO_SHORT)
    );
    assert_eq!(t.raw(&[0x00]), Err(MailboxError::SIZE_TOO_SHORT));
    assert_eq!(
        t.raw(&[0x00, 0x30, 0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0]),
        Err(MailboxError::SERVICE_NOT_SUPPORTED)
    );
    assert_eq!(
        t.raw(&[0x00, 0x80, 0x01, 0x00]),
        Err(MailboxError::SIZE_TOO_SHORT)
    );
}

#[test]
fn e062_sdo_in_preop_safeop_op() {
    for state in [AlState::PreOp, AlState::SafeOp, AlState::Op] {
        let mut t = T::new(64);
        t.state = state;
        let r = t.sdo(&upload_req(0x2000, 0));
        assert_eq!(resp(&r)[0], 0x4B);
        let r = t.sdo(&[0x2B, 0x06, 0x20, 0x00, 1, 0, 0, 0]);
        if state == AlState::PreOp {
            assert_eq!(resp(&r)[0], 0x60);
        } else {
            // the dictionary's state rule comes through unchanged
            assert_eq!(abort(&r, 0x2006, 0), 0x0800_0022);
        }
    }
}
