//! The mailbox data-link layer through a real master's frames: error replies
//! for unsupported protocols and bad headers, the repeat request.

use drive_tests::{line, with_sdo, RawMailbox, MAILBOX_LEN};
use ecat::mailbox::MailboxError;

/// Mailbox error reply (type 0): service 0001h, then the detail code.
fn mailbox_error(resp: &(u8, Vec<u8>)) -> u16 {
    assert_eq!(resp.0, 0, "mailbox type ERR");
    assert_eq!(
        u16::from_le_bytes([resp.1[0], resp.1[1]]),
        0x0001,
        "service: mailbox error"
    );
    u16::from_le_bytes([resp.1[2], resp.1[3]])
}

#[test]
fn e003_unsupported_protocol_gets_mailbox_error_0002() {
    let sim = line(1);
    with_sdo(&sim, async |sd, _| {
        let mut mbx = RawMailbox::new();
        // FoE (4) is supported since issue 8 (firmware download)
        for soe_foe_voe in [5u8, 15] {
            let resp = mbx
                .exchange(sd, soe_foe_voe, &[1, 2, 3, 4])
                .await
                .expect("a reply");
            assert_eq!(
                mailbox_error(&resp),
                MailboxError::UNSUPPORTED_PROTOCOL.0,
                "type {soe_foe_voe}"
            );
        }
        // the mailbox still works afterwards: 1000h through CoE
        let resp = mbx.sdo(sd, &[0x40, 0x00, 0x10, 0, 0, 0, 0, 0]).await;
        assert_eq!(resp[2], 0x43, "expedited upload response, 4 bytes");
        assert_eq!(
            u32::from_le_bytes(resp[6..10].try_into().unwrap()),
            drive_ecat::DEVICE_TYPE
        );
    });
}

#[test]
fn mailbox_length_beyond_buffer_gets_invalid_size() {
    let sim = line(1);
    with_sdo(&sim, async |sd, _| {
        let mut mbx = RawMailbox::new();
        let mut frame = [0u8; MAILBOX_LEN];
        frame[0..2].copy_from_slice(&(MAILBOX_LEN as u16).to_le_bytes()); // 6 bytes too long
        frame[5] = 0x13; // CoE, counter 1
        mbx.send_raw(sd, frame).await;
        let resp = mbx.receive(sd).await.expect("a reply");
        assert_eq!(mailbox_error(&resp), MailboxError::INVALID_SIZE.0);
    });
}

#[test]
fn mailbox_repeat_request_returns_the_last_reply_again() {
    let sim = line(1);
    with_sdo(&sim, async |sd, _| {
        let mut mbx = RawMailbox::new();
        let first = mbx.sdo(sd, &[0x40, 0x18, 0x10, 1, 0, 0, 0, 0]).await; // 1018h:01 vendor
                                                                           // the master lost the frame: toggle SM1's repeat bit (activate byte bit 1)
        let act: u8 = sd.register_read(esc::regs::sm(1) + 6).await.unwrap();
        sd.register_write(esc::regs::sm(1) + 6, act ^ esc::sm::activate::REPEAT)
            .await
            .unwrap();
        let again = mbx.receive(sd).await.expect("repeated reply");
        assert_eq!(again.0, 3);
        assert_eq!(again.1, first, "same reply again");
        let ack: u8 = sd.register_read(esc::regs::sm(1) + 7).await.unwrap();
        assert_eq!(
            ack & esc::sm::pdi_control::REPEAT_ACK != 0,
            (act ^ esc::sm::activate::REPEAT) & esc::sm::activate::REPEAT != 0,
            "repeat acknowledged"
        );
    });
}
