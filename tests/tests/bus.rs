//! The bus through a real master: ethercrab drives the simulated ESC in-process
//! (no root, no network), the slave stack runs its real code in simulated time.

use drive_tests::al::{ACK, BOOT, ERR, INIT, OP, PREOP, SAFEOP};
use drive_tests::{al_status, init, line, request, with_master, with_sdo, write_sm};
use ecat::sii;
use esc::{AlState, AlStatusCode};

fn changes(sim: &hil_sim::sim::Simulation, i: usize) -> Vec<(AlState, AlState, u16)> {
    sim.drives()[i]
        .state_log
        .iter()
        .map(|(_, c)| (c.from, c.to, c.code.0))
        .collect()
}

#[test]
fn e021_master_walks_init_preop_safeop_op_and_back() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        assert_eq!(group.len(), 1);
        let group = group.into_op(md).await.expect("PRE-OP -> OP");
        assert_eq!(al_status(&group.subdevice(md, 0).unwrap()).await, (OP, 0));
        for _ in 0..10 {
            group.tx_rx(md).await.expect("cycle");
        }
        let group = group.into_safe_op(md).await.expect("OP -> SAFE-OP");
        let group = group.into_pre_op(md).await.expect("SAFE-OP -> PRE-OP");
        group.into_init(md).await.expect("PRE-OP -> INIT");
    });
    assert_eq!(sim.borrow().drives()[0].esc.al_status(), INIT);
    use AlState::*;
    assert_eq!(
        changes(&sim.borrow(), 0),
        [
            (Init, PreOp, 0),
            (PreOp, SafeOp, 0),
            (SafeOp, Op, 0),
            (Op, SafeOp, 0),
            (SafeOp, PreOp, 0),
            (PreOp, Init, 0)
        ]
    );
}

#[test]
fn e005_slave_count_addresses_identity_and_name_from_sii() {
    let sim = line(2);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        assert_eq!(group.len(), 2, "BRD counts both slaves");
        let addrs: Vec<u16> = group.iter(md).map(|s| s.configured_address()).collect();
        assert_eq!(addrs, [0x1000, 0x1001]);
        for sd in group.iter(md) {
            let id = sd.identity();
            assert_eq!(id.vendor_id, 0xB9, "E-005 vendor ID");
            assert_eq!(id.product_id, drive_tests::variant().product_code());
            assert_eq!(id.revision, drive_ecat::SOFTWARE_BUILD);
            assert_eq!(id.serial, drive_ecat::SERIAL);
            assert_eq!(sd.name(), drive_tests::device().order_code);
        }
        // the configured addresses really are in the ESCs
        for i in 0..2 {
            let sd = group.subdevice(md, i).unwrap();
            let a: u16 = sd.register_read(esc::regs::STATION_ADDRESS).await.unwrap();
            assert_eq!(a, 0x1000 + i as u16);
        }
    });
}

#[test]
fn e003_sii_read_by_master_has_syncmanagers_and_protocols() {
    let sim = line(1);
    let image = with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.iter(md).next().unwrap();
        let size = sd.eeprom_size(md).await.expect("eeprom size");
        let mut buf = vec![0u8; size];
        let n = sd.eeprom_read_raw(md, 0, &mut buf).await.expect("eeprom read");
        buf.truncate(n);
        buf
    });
    assert_eq!(sii::sii_word(&image, esc::sii::word::VENDOR_ID), Some(0xB9));
    let protocols = sii::sii_word(&image, esc::sii::word::MAILBOX_PROTOCOL).unwrap();
    assert_eq!(
        protocols,
        esc::sii::mailbox_protocol::COE | esc::sii::mailbox_protocol::EOE | esc::sii::mailbox_protocol::FOE,
        "E-003: CoE and EoE, and FoE for the firmware download (issue 8)"
    );
    let sms = sii::find_category(&image, esc::sii::category::SYNC_MANAGER).expect("SM category");
    let sms: Vec<&[u8]> = sii::records(sms, 8).collect();
    assert_eq!(sms.len(), 4);
    let start = |r: &[u8]| u16::from_le_bytes([r[0], r[1]]);
    for (sm, (want, what)) in sms.iter().zip([
        ((0x1000, 0x26, 1), "SM0 mailbox out"),
        ((0x1100, 0x22, 2), "SM1 mailbox in"),
        ((0x1200, 0x64, 3), "SM2 outputs"),
        ((0x1A00, 0x20, 4), "SM3 inputs"),
    ]) {
        assert_eq!((start(sm), sm[4], sm[7]), want, "{what}");
    }
    // the master read the same image the ESC was loaded with
    assert_eq!(&image[..], &sim.borrow().drives()[0].esc.sii()[..image.len()]);
}

#[test]
/// The drive declares FoE (issue 8), so Bootstrap exists, but only through
/// Init: from Pre-Op it is an invalid change (0011h). Devices without FoE keep
/// refusing it with 0013h (E-022, `e021_e022_e023_transition_matrix`).
fn e022_bootstrap_from_preop_refused_with_0011_and_acknowledged() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        request(&group.subdevice(md, 0).unwrap(), BOOT).await;
        assert_eq!(
            al_status(&group.subdevice(md, 0).unwrap()).await,
            (PREOP | ERR, 0x0011)
        );
        // a request without acknowledge is ignored while the error is shown
        request(&group.subdevice(md, 0).unwrap(), INIT).await;
        assert_eq!(
            al_status(&group.subdevice(md, 0).unwrap()).await,
            (PREOP | ERR, 0x0011)
        );
        // acknowledge clears the indication and the request is carried out
        request(&group.subdevice(md, 0).unwrap(), PREOP | ACK).await;
        assert_eq!(al_status(&group.subdevice(md, 0).unwrap()).await, (PREOP, 0));
    });
}

#[test]
fn e023_impossible_transition_0011_and_unknown_state_0012() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        request(&group.subdevice(md, 0).unwrap(), OP).await; // PRE-OP -> OP skips SAFE-OP
        assert_eq!(
            al_status(&group.subdevice(md, 0).unwrap()).await,
            (PREOP | ERR, 0x0011)
        );
        request(&group.subdevice(md, 0).unwrap(), 5 | ACK).await;
        assert_eq!(
            al_status(&group.subdevice(md, 0).unwrap()).await,
            (PREOP | ERR, 0x0012)
        );
        request(&group.subdevice(md, 0).unwrap(), INIT | ACK).await;
        assert_eq!(al_status(&group.subdevice(md, 0).unwrap()).await, (INIT, 0));
        request(&group.subdevice(md, 0).unwrap(), SAFEOP).await; // INIT -> SAFE-OP
        assert_eq!(
            al_status(&group.subdevice(md, 0).unwrap()).await,
            (INIT | ERR, 0x0011)
        );
    });
}

#[test]
fn e025_invalid_mailbox_sm_stays_init_with_0016() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        request(&group.subdevice(md, 0).unwrap(), INIT).await;
        assert_eq!(al_status(&group.subdevice(md, 0).unwrap()).await, (INIT, 0));
        let sd = group.subdevice(md, 0).unwrap();
        // SM0 moved away from the SII's start address
        sd.register_write(esc::regs::sm(0), 0x1800u16).await.unwrap();
        request(&group.subdevice(md, 0).unwrap(), PREOP).await;
        assert_eq!(
            al_status(&group.subdevice(md, 0).unwrap()).await,
            (INIT | ERR, AlStatusCode::INVALID_MAILBOX_CONFIG.0)
        );
        // repaired and acknowledged: the mailbox starts
        sd.register_write(esc::regs::sm(0), 0x1000u16).await.unwrap();
        request(&group.subdevice(md, 0).unwrap(), PREOP | ACK).await;
        assert_eq!(al_status(&group.subdevice(md, 0).unwrap()).await, (PREOP, 0));
    });
}

#[test]
fn e028_e045_sm2_sm3_length_checked_on_preop_to_safeop() {
    let rx = drive_ecat::DEVICE.output_bytes() as u16;
    let tx = drive_ecat::DEVICE.input_bytes() as u16;
    assert_eq!(
        (rx, tx),
        (23, 29),
        "standard maps: RxPDO 23 bytes, TxPDO 29 bytes"
    );
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        // SM2 one byte short: invalid output configuration
        write_sm(&group.subdevice(md, 0).unwrap(), 2, 0x1200, rx - 1, 0x64).await;
        write_sm(&group.subdevice(md, 0).unwrap(), 3, 0x1A00, tx, 0x20).await;
        request(&group.subdevice(md, 0).unwrap(), SAFEOP).await;
        assert_eq!(
            al_status(&group.subdevice(md, 0).unwrap()).await,
            (PREOP | ERR, AlStatusCode::INVALID_OUTPUT_CONFIG.0)
        );
        // SM2 right, SM3 one byte long: invalid input configuration
        write_sm(&group.subdevice(md, 0).unwrap(), 2, 0x1200, rx, 0x64).await;
        write_sm(&group.subdevice(md, 0).unwrap(), 3, 0x1A00, tx + 1, 0x20).await;
        request(&group.subdevice(md, 0).unwrap(), SAFEOP | ACK).await;
        assert_eq!(
            al_status(&group.subdevice(md, 0).unwrap()).await,
            (PREOP | ERR, AlStatusCode::INVALID_INPUT_CONFIG.0)
        );
        // both right: SAFE-OP
        write_sm(&group.subdevice(md, 0).unwrap(), 3, 0x1A00, tx, 0x20).await;
        request(&group.subdevice(md, 0).unwrap(), SAFEOP | ACK).await;
        assert_eq!(al_status(&group.subdevice(md, 0).unwrap()).await, (SAFEOP, 0));
    });
}

#[test]
fn e037_back_to_init_stops_mailbox() {
    let sim = line(1);
    with_sdo(&sim, async |sd, _| {
        let dt: u32 = sd.sdo_read(0x1000, 0).await.expect("1000h in PRE-OP");
        assert_eq!(dt, drive_ecat::DEVICE_TYPE, "E-004");
        request(sd, INIT).await;
        assert_eq!(al_status(sd).await, (INIT, 0));
        assert!(sd.sdo_read::<u32>(0x1000, 0).await.is_err(), "no mailbox in INIT");
    });
}

#[test]
fn e028_e092_failed_preop_to_safeop_sends_emcy_a000_with_diag_code() {
    let sim = line(1);
    with_sdo(&sim, async |sd, _| {
        // SM3 one byte short: PDO length not correct on SM3 -> diag code 4*3 + 2 = Eh
        write_sm(sd, 2, 0x1200, 23, 0x64).await;
        write_sm(sd, 3, 0x1A00, 28, 0x20).await;
        request(sd, SAFEOP).await;
        assert_eq!(
            al_status(sd).await,
            (PREOP | ERR, AlStatusCode::INVALID_INPUT_CONFIG.0)
        );
        let mut mbx = drive_tests::RawMailbox::new();
        let (kind, data) = mbx.receive(sd).await.expect("an EMCY in the mailbox");
        assert_eq!(kind, 3, "CoE");
        assert_eq!(
            u16::from_le_bytes([data[0], data[1]]) >> 12,
            1,
            "CoE service 1: emergency"
        );
        let emcy = &data[2..10];
        assert_eq!(u16::from_le_bytes([emcy[0], emcy[1]]), 0xA000, "error code A000h");
        assert_eq!(emcy[2], 2, "error register = ESM state Pre-Op");
        assert_eq!(emcy[3], 0x0E, "diag code: SM3, PDO length not correct");
    });
}

#[test]
fn e144_e146_refused_transition_lands_in_the_diagnosis_history() {
    let sim = line(1);
    with_sdo(&sim, async |sd, _| {
        let fresh: u8 = sd.sdo_read(0x10F3, 4).await.expect("10F3h:04");
        assert_eq!(fresh, 0, "no new messages after power-on (E-145)");
        request(sd, BOOT).await; // refused with 0011h (Bootstrap only from Init)
        assert_eq!(al_status(sd).await, (PREOP | ERR, 0x0011));
        let new: u8 = sd.sdo_read(0x10F3, 4).await.expect("10F3h:04");
        assert_eq!(new, 1, "new message available");
        let newest: u8 = sd.sdo_read(0x10F3, 2).await.expect("10F3h:02");
        assert_eq!(newest, 6, "the first message sits at subindex 6");
        let mut coe = drive_tests::CoeClient::new();
        let msg = coe.upload(sd, 0x10F3, 6).await.expect("10F3h:06");
        let code = u32::from_le_bytes(msg[0..4].try_into().unwrap());
        assert_eq!(
            code,
            drive_ecat::runtime::DIAG_AL_STATUS | 0x0011,
            "diag code carries the AL status code"
        );
        assert_eq!(u16::from_le_bytes([msg[4], msg[5]]) & 0x0F, 2, "type: error");
        // acknowledging it clears the new-message flag (E-146)
        sd.sdo_write(0x10F3, 3, 6u8).await.expect("acknowledge");
        let after: u8 = sd.sdo_read(0x10F3, 4).await.expect("10F3h:04");
        assert_eq!(after, 0);
    });
}
