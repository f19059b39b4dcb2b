//! The mailbox: SDO through SM0/SM1, counters, error replies, repeat, SDO Info fragments, and the
//! mailbox served by its own task (E-027, E-037, E-079, E-080).

use super::*;

#[test]
fn e027_sdo_upload_and_download_through_mailbox() {
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    let resp = r.upload(0x1008, 0, 1).unwrap();
    assert_eq!(resp.len(), 128);
    // header: length 10, CoE, counter 1
    assert_eq!(&resp[..6], &[10, 0, 0, 0, 0, 0x13]);
    assert_eq!(
        &resp[6..16],
        &[0x00, 0x30, 0x43, 0x08, 0x10, 0x00, b'T', b'e', b's', b't']
    );
    assert!(resp[16..].iter().all(|&b| b == 0));
    // expedited download 2 bytes
    r.esc.mbx_write(&[
        10, 0, 0, 0, 0, 0x23, 0x00, 0x20, 0x2B, 0x00, 0x20, 0x00, 0x34, 0x12, 0, 0,
    ]);
    r.poll();
    let resp = r.esc.mbx_read().unwrap();
    assert_eq!(
        &resp[..16],
        &[10, 0, 0, 0, 0, 0x23, 0x00, 0x30, 0x60, 0x00, 0x20, 0x00, 0, 0, 0, 0]
    );
    assert_eq!(r.app.value, 0x1234);
}

#[test]
fn e037_no_mailbox_in_init() {
    let mut r = Rig::new();
    assert!(r.upload(0x1008, 0, 1).is_none());
    assert_ne!(r.esc.events() & al_event::sm(0), 0, "SM0 not read in Init");
    // P->I drops the mailbox again
    r.goto(AlState::PreOp);
    assert!(r.upload(0x1008, 0, 2).is_some());
    assert_eq!(r.req(1), (1, 0));
    assert!(r.upload(0x1008, 0, 3).is_none());
}

#[test]
fn mailbox_counter_cycles_and_duplicates_are_dropped() {
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    let mut counters = Vec::new();
    for i in 0..9u8 {
        let resp = r.upload(0x1008, 0, i % 7 + 1).unwrap();
        counters.push(resp[5] >> 4);
    }
    assert_eq!(counters, [1, 2, 3, 4, 5, 6, 7, 1, 2]);
    // same counter again (request repeated by the master): no reply
    assert!(r.upload(0x1008, 0, 2).is_none());
    // counter 0 is never a duplicate
    assert!(r.upload(0x1008, 0, 0).is_some());
    assert!(r.upload(0x1008, 0, 0).is_some());
}

#[test]
fn mailbox_error_replies() {
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    // SoE is not handled: unsupported protocol
    r.esc.mbx_write(&[4, 0, 0, 0, 0, 0x15, 0, 0, 0, 0]);
    r.poll();
    let resp = r.esc.mbx_read().unwrap();
    assert_eq!(&resp[..10], &[4, 0, 0, 0, 0, 0x10, 0x01, 0x00, 0x02, 0x00]);
    // length beyond the mailbox: invalid size
    r.esc.mbx_write(&[200, 0, 0, 0, 0, 0x23, 0, 0, 0, 0]);
    r.poll();
    let resp = r.esc.mbx_read().unwrap();
    assert_eq!(&resp[..10], &[4, 0, 0, 0, 0, 0x20, 0x01, 0x00, 0x08, 0x00]);
    // CoE frame too short for an SDO: size too short
    r.esc.mbx_write(&[4, 0, 0, 0, 0, 0x33, 0x00, 0x20, 0x40, 0x00]);
    r.poll();
    let resp = r.esc.mbx_read().unwrap();
    assert_eq!(&resp[6..10], &[0x01, 0x00, 0x06, 0x00]);
}

#[test]
fn mailbox_waits_for_sm1_empty_and_holds_next_request() {
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    r.esc.mbx_write(&[
        10, 0, 0, 0, 0, 0x13, 0x00, 0x20, 0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0,
    ]);
    r.poll();
    assert!(r.esc.sm1_full());
    // the master has not read SM1 yet: the next response stays pending
    r.esc.mbx_write(&[
        10, 0, 0, 0, 0, 0x23, 0x00, 0x20, 0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0,
    ]);
    r.poll();
    let first = r.esc.mbx_read().unwrap();
    assert_eq!(first[5] >> 4, 1);
    assert_eq!(&first[9..11], &[0x00, 0x20]);
    r.poll();
    let second = r.esc.mbx_read().unwrap();
    assert_eq!(second[5] >> 4, 2);
    assert_eq!(&second[9..11], &[0x08, 0x10]);
    // a third request held back while a response is pending is served later
    r.esc.mbx_write(&[
        10, 0, 0, 0, 0, 0x33, 0x00, 0x20, 0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0,
    ]);
    r.esc.mem[regs::sm(1) as usize + 5] |= status::MAILBOX_FULL;
    r.poll(); // response pending, SM1 "full"
    r.esc.mbx_write(&[
        10, 0, 0, 0, 0, 0x43, 0x00, 0x20, 0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0,
    ]);
    r.poll();
    assert_ne!(
        r.esc.events() & al_event::sm(0),
        0,
        "SM0 left full while a response is pending"
    );
    assert_eq!(r.esc.mbx_read().unwrap()[5] >> 4, 2, "stale content");
    r.poll();
    assert_eq!(r.esc.mbx_read().unwrap()[5] >> 4, 3);
    r.poll();
    assert_eq!(r.esc.mbx_read().unwrap()[5] >> 4, 4);
}

#[test]
fn mailbox_repeat_rewrites_last_response() {
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    let first = r.upload(0x1008, 0, 1).unwrap();
    // the master lost it and toggles the repeat bit
    r.esc.mem[regs::sm(1) as usize + 6] ^= activate::REPEAT;
    r.poll();
    assert_eq!(r.esc.mbx_read().unwrap(), first);
    assert_ne!(r.esc.mem[regs::sm(1) as usize + 7] & pdi_control::REPEAT_ACK, 0);
    // no further repeat: nothing new
    r.poll();
    assert!(r.esc.mbx_read().is_none());
    // toggling back is a second repeat request
    r.esc.mem[regs::sm(1) as usize + 6] ^= activate::REPEAT;
    r.poll();
    assert_eq!(r.esc.mbx_read().unwrap(), first);
    assert_eq!(r.esc.mem[regs::sm(1) as usize + 7] & pdi_control::REPEAT_ACK, 0);
}

#[test]
fn e080_od_list_fragments_through_the_mailbox() {
    let mut r = Rig::with(&DEV_INFO);
    r.goto(AlState::PreOp);
    // Get OD List, all objects: 2 + 2 * 150 bytes, 116 per fragment (SM1 128) -> 3 fragments
    r.esc.mbx_write(&[
        8, 0, 0, 0, 0, 0x13, 0x00, 0x80, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00,
    ]);
    r.poll();
    let mut indices = Vec::new();
    let mut frames = Vec::new();
    for _ in 0..3 {
        let resp = r.esc.mbx_read().expect("a fragment");
        // the master has not read yet: nothing new is written
        frames.push(resp);
        r.poll();
    }
    for (i, f) in frames.iter().enumerate() {
        let len = u16::from_le_bytes([f[0], f[1]]) as usize;
        assert_eq!(f[5], 0x03 | ((i as u8 + 1) << 4), "CoE, counters 1, 2, 3");
        assert_eq!(&f[6..8], &[0x00, 0x80]);
        let left = 2 - i as u16;
        assert_eq!(f[8], if left > 0 { 0x82 } else { 0x02 });
        assert_eq!(u16::from_le_bytes([f[10], f[11]]), left);
        let data = &f[12..6 + len];
        let data = if i == 0 {
            assert_eq!(&data[..2], &[1, 0]);
            &data[2..]
        } else {
            data
        };
        indices.extend(data.chunks(2).map(|c| u16::from_le_bytes([c[0], c[1]])));
    }
    assert_eq!(
        indices,
        (0..MANY_N as u16).map(|i| 0x3000 + i).collect::<Vec<_>>()
    );
    assert!(r.esc.mbx_read().is_none(), "no fourth fragment");
    // the next request is served normally
    let resp = r.upload(0x1008, 0, 2).unwrap();
    assert_eq!(&resp[6..9], &[0x00, 0x30, 0x43]);
}

#[test]
fn e079_no_sdo_info_without_the_coe_detail() {
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    r.esc.mbx_write(&[
        8, 0, 0, 0, 0, 0x13, 0x00, 0x80, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00,
    ]);
    r.poll();
    let resp = r.esc.mbx_read().unwrap();
    // mailbox error: service not supported
    assert_eq!(&resp[..10], &[4, 0, 0, 0, 0, 0x10, 0x01, 0x00, 0x04, 0x00]);
}

/// E-027/E-037 with the stack split over two tasks: `poll_esc` (AL control,
/// process data) never touches the mailbox, `poll_mailbox_only` serves it,
/// and together they answer like `poll`.
#[test]
fn e027_e037_mailbox_served_by_its_own_task() {
    let mut r = Rig::new();
    let split = |r: &mut Rig, mailbox: bool| {
        r.t += Nanos::from_ms(1);
        let Ok(c) = r.slave.poll_esc(&mut r.esc, &mut r.app, r.t);
        if mailbox {
            let Ok(()) = r.slave.poll_mailbox_only(
                &mut r.esc,
                &mut r.app,
                &mut crate::foe::NoFiles,
                &mut crate::eoe::NoEthernet,
                r.t,
            );
        }
        c
    };
    // AL control through the ESC part alone
    r.esc.request(2);
    let c = split(&mut r, false);
    assert_eq!(c.map(|c| c.to), Some(AlState::PreOp));
    assert_eq!(r.esc.status(), 2);
    // a request waits in SM0 while only the ESC part runs
    r.esc
        .mbx_write(&[10, 0, 0, 0, 0, 0x13, 0x00, 0x20, 0x40, 0x08, 0x10, 0, 0, 0, 0, 0]);
    for _ in 0..3 {
        split(&mut r, false);
        assert!(r.esc.mbx_read().is_none());
        assert_ne!(r.esc.events() & al_event::sm(0), 0, "SM0 read by the ESC part");
    }
    // the mailbox part answers it
    split(&mut r, true);
    let resp = r.esc.mbx_read().unwrap();
    assert_eq!(&resp[6..12], &[0x00, 0x30, 0x43, 0x08, 0x10, 0x00]);
    // back in Init the mailbox part serves nothing (E-037)
    r.esc.request(1);
    split(&mut r, true);
    r.esc
        .mbx_write(&[10, 0, 0, 0, 0, 0x23, 0x00, 0x20, 0x40, 0x08, 0x10, 0, 0, 0, 0, 0]);
    split(&mut r, true);
    assert!(r.esc.mbx_read().is_none());
}
