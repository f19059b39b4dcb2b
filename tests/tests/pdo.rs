//! PDO mapping and assignment through a real master (spec §5, E-048…E-058):
//! remapped in Pre-Op with ethercrab's expedited SDO writes, the new layout
//! runs in Op; refusals with the abort codes of §5.3; an SM2 length that no
//! longer matches the mapping refuses Safe-Op with AL 001Dh.

use drive_tests::al::{ACK, ERR, OP, PREOP, SAFEOP};
use drive_tests::{
    al_status, init, line, map_pdo, request_gives, with_master, with_sdo, with_sdo_set_up, write_sm,
    CoeClient,
};
use ecat::SdoAbort;
use esc::AlStatusCode;

/// Mapping entry: index << 16 | sub << 8 | bit length.
const fn m(index: u16, sub: u8, bits: u8) -> u32 {
    (index as u32) << 16 | (sub as u32) << 8 | bits as u32
}

const CONTROLWORD: u32 = m(0x6040, 0, 16);
const TARGET_VELOCITY: u32 = m(0x60FF, 0, 32);
const STATUSWORD: u32 = m(0x6041, 0, 16);
const VELOCITY_ACTUAL: u32 = m(0x606C, 0, 32);

fn pdo_bytes(sim: &std::cell::RefCell<hil_sim::sim::Simulation>) -> Option<(usize, usize)> {
    use ecat::Dictionary;
    sim.borrow().drives()[0].drive.objects().process_data_bytes()
}

#[test]
fn e048_e049_e054_remap_in_preop_and_run_op_with_the_new_layout() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        // CiA 301 sequence with ethercrab's expedited writes
        sd.sdo_write(0x1600, 0, 0u8).await.expect("1600h:00 = 0");
        sd.sdo_write(0x1600, 1, CONTROLWORD).await.expect("1600h:01");
        sd.sdo_write(0x1600, 2, TARGET_VELOCITY).await.expect("1600h:02");
        sd.sdo_write(0x1600, 0, 2u8).await.expect("1600h:00 = 2");
        sd.sdo_write(0x1A00, 0, 0u8).await.expect("1A00h:00 = 0");
        sd.sdo_write(0x1A00, 1, STATUSWORD).await.expect("1A00h:01");
        sd.sdo_write(0x1A00, 2, VELOCITY_ACTUAL).await.expect("1A00h:02");
        sd.sdo_write(0x1A00, 0, 2u8).await.expect("1A00h:00 = 2");
        assert_eq!(sd.sdo_read::<u32>(0x1600, 2).await.unwrap(), TARGET_VELOCITY);
        assert_eq!(sd.sdo_read::<u8>(0x1A00, 0).await.unwrap(), 2);
        // the A225/A233 mirrors follow
        assert_eq!(sd.sdo_read::<u32>(0x20E1, 2).await.unwrap(), TARGET_VELOCITY);
        assert_eq!(sd.sdo_read::<u8>(0x20E9, 0).await.unwrap(), 2);
        assert_eq!(pdo_bytes(&sim), Some((6, 6)));

        // ethercrab reads 1C12h/1C13h and the mappings and sizes SM2/SM3 from them
        let group = group.into_op(md).await.expect("PRE-OP -> OP with the new layout");
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(al_status(&sd).await, (OP, 0));
        {
            let io = sd.io_raw();
            assert_eq!(io.outputs().len(), 6, "controlword + target velocity");
            assert_eq!(io.inputs().len(), 6, "statusword + velocity actual value");
        }
        let sms = {
            let s = sim.borrow();
            let esc = &s.drives()[0].esc;
            (esc.sync_manager(2).length, esc.sync_manager(3).length)
        };
        assert_eq!(sms, (6, 6), "SM2/SM3 lengths");
        // process data cycles: the drive sees controlword and target velocity
        {
            let mut out = sd.outputs_raw_mut();
            out.copy_from_slice(&[0x0F, 0x00, 0x78, 0x56, 0x34, 0x12]);
        }
        for _ in 0..10 {
            let r = group.tx_rx(md).await.expect("cycle");
            assert_eq!(r.working_counter, 3, "outputs written and inputs read");
        }
        let (received, outputs) = {
            let s = sim.borrow();
            let slave = s.drives()[0].drive.slave();
            (slave.outputs_received(), slave.outputs().to_vec())
        };
        assert!(received > 0, "RxPDO frames reached the drive");
        assert_eq!(
            outputs,
            [0x0F, 0x00, 0x78, 0x56, 0x34, 0x12],
            "the new RxPDO layout"
        );
        assert_eq!(al_status(&sd).await, (OP, 0), "still Op");
    });
}

/// E-061: A250 (= 10F3h:04, BOOL) maps into the TxPDO: one bit beside the
/// statusword, padded to the byte with a gap entry. It is 0 in Op until a
/// diagnosis message arrives (here: a refused state request, E-144), then
/// the master sees 1 cyclically without reading 10F3h; acknowledging the
/// message clears it. A250 in the RxPDO is refused (0604 0041h).
#[test]
fn e061_a250_new_messages_flag_in_the_txpdo() {
    let sim = line(1);
    let a250 = drive_ecat::parameter_index(0, 250);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        sd.sdo_write(0x1A00, 0, 0u8).await.expect("1A00h:00 = 0");
        sd.sdo_write(0x1A00, 1, STATUSWORD).await.expect("1A00h:01");
        sd.sdo_write(0x1A00, 2, m(a250, 0, 1))
            .await
            .expect("1A00h:02 = A250, 1 bit");
        sd.sdo_write(0x1A00, 3, m(0, 0, 7))
            .await
            .expect("1A00h:03 = 7-bit gap");
        sd.sdo_write(0x1A00, 0, 3u8).await.expect("1A00h:00 = 3");
        assert!(
            sd.sdo_write(0x1600, 2, m(a250, 0, 1)).await.is_err(),
            "not RxPDO-mappable"
        );
        let (_, tx) = pdo_bytes(&sim).unwrap();
        assert_eq!(tx, 3, "statusword + one byte");
        let group = group.into_op(md).await.expect("PRE-OP -> OP");
        let sd = group.subdevice(md, 0).unwrap();
        let flag = async || {
            for _ in 0..5 {
                group.tx_rx(md).await.expect("cycle");
            }
            sd.io_raw().inputs()[2]
        };
        assert_eq!(flag().await, 0, "no new message");
        // a refused request (Bootstrap from Op, 0011h) is a new message
        drive_tests::request(&sd, drive_tests::al::BOOT).await;
        for _ in 0..20 {
            group.tx_rx(md).await.expect("cycle");
        }
        assert_eq!(flag().await, 1, "new message, seen in the process data");
        let newest: u8 = sd.sdo_read(0x10F3, 2).await.expect("10F3h:02");
        sd.sdo_write(0x10F3, 3, newest).await.expect("acknowledge");
        assert_eq!(flag().await, 0, "acknowledged");
    });
}

#[test]
fn e058_e075_mapping_refusals_0604_0041_0604_0042_0604_0043() {
    let sim = line(1);
    with_sdo(&sim, async |sd, c| {
        let put = |v: u32| v.to_le_bytes();
        c.download(sd, 0x1600, 0, &[0]).await.unwrap();
        // not RxPDO-mappable: statusword (Tx only), device type, unknown, hidden (A293)
        for bad in [
            STATUSWORD,
            m(0x1000, 0, 32),
            m(0x5555, 0, 16),
            m(drive_ecat::parameter_index(0, 293), 0, 16),
        ] {
            assert_eq!(
                c.download(sd, 0x1600, 1, &put(bad)).await,
                Err(SdoAbort::NOT_MAPPABLE.0),
                "{bad:08X}h in an RxPDO"
            );
        }
        // not TxPDO-mappable: quick stop option code (Rx only)
        c.download(sd, 0x1A00, 0, &[0]).await.unwrap();
        assert_eq!(
            c.download(sd, 0x1A00, 1, &put(m(0x605A, 0, 16))).await,
            Err(SdoAbort::NOT_MAPPABLE.0)
        );
        // mappable, but with the wrong bit length
        assert_eq!(
            c.download(sd, 0x1600, 1, &put(m(0x6040, 0, 8))).await,
            Err(SdoAbort::PARAMETER_INCOMPATIBLE.0)
        );
        assert_eq!(
            c.upload(sd, 0x1600, 1).await,
            Ok(put(CONTROLWORD).to_vec()),
            "unchanged"
        );
        // too many entries: sub 0 above 24
        assert_eq!(
            c.download(sd, 0x1600, 0, &[25]).await,
            Err(SdoAbort::PDO_LENGTH.0)
        );
        // too long: 24 × 32 bits is the limit, gaps of 255 bits exceed it
        for s in 1..=24u8 {
            c.download(sd, 0x1600, s, &put(TARGET_VELOCITY)).await.unwrap();
        }
        c.download(sd, 0x1600, 0, &[24]).await.expect("24 × 32 bits fit");
        c.download(sd, 0x1600, 0, &[0]).await.unwrap();
        for s in 1..=4u8 {
            c.download(sd, 0x1600, s, &put(0x0000_00FF)).await.unwrap();
        }
        assert_eq!(
            c.download(sd, 0x1600, 0, &[4]).await,
            Err(SdoAbort::PDO_LENGTH.0),
            "4 × 255 bits > 768"
        );
        assert_eq!(c.upload(sd, 0x1600, 0).await, Ok(vec![0]), "sub 0 unchanged");
        // an entry while sub 0 != 0 (CiA 301 step b)
        c.download(sd, 0x1600, 1, &put(CONTROLWORD)).await.unwrap();
        c.download(sd, 0x1600, 0, &[1]).await.unwrap();
        assert_eq!(
            c.download(sd, 0x1600, 2, &put(TARGET_VELOCITY)).await,
            Err(SdoAbort::DEVICE_STATE.0)
        );
        // E-052: the FSoE channel is not configurable
        assert_eq!(c.download(sd, 0x1603, 0, &[0]).await, Err(SdoAbort::READ_ONLY.0));
        assert_eq!(
            c.download(sd, 0x1A03, 1, &put(STATUSWORD)).await,
            Err(SdoAbort::READ_ONLY.0)
        );
        // assignment: only the direction's PDOs, no duplicates
        c.download(sd, 0x1C12, 0, &[0]).await.unwrap();
        assert_eq!(
            c.download(sd, 0x1C12, 1, &0x1A00u16.to_le_bytes()).await,
            Err(SdoAbort::PARAMETER_INCOMPATIBLE.0)
        );
        c.download(sd, 0x1C12, 1, &0x1600u16.to_le_bytes()).await.unwrap();
        c.download(sd, 0x1C12, 2, &0x1600u16.to_le_bytes()).await.unwrap();
        assert_eq!(
            c.download(sd, 0x1C12, 0, &[2]).await,
            Err(SdoAbort::PARAMETER_INCOMPATIBLE.0),
            "1600h assigned twice"
        );
        c.download(sd, 0x1C12, 0, &[1]).await.unwrap();
        assert_eq!(
            pdo_bytes(&sim),
            Some((2, 0)),
            "1600h = controlword, 1A00h emptied"
        );
    });
}

#[test]
fn e048_e054_mapping_and_assignment_refused_in_safeop_with_0800_0022() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let group = group.into_safe_op(md).await.expect("PRE-OP -> SAFE-OP");
        let sd = group.subdevice(md, 0).unwrap();
        let mut c = CoeClient::new();
        for (index, sub, data) in [
            (0x1600u16, 0u8, vec![0u8]),
            (0x1600, 1, CONTROLWORD.to_le_bytes().to_vec()),
            (0x1A00, 0, vec![0]),
            (0x1A01, 3, STATUSWORD.to_le_bytes().to_vec()),
            (0x1C12, 0, vec![0]),
            (0x1C13, 1, 0x1A01u16.to_le_bytes().to_vec()),
            (0x20E1, 0, vec![0]), // A225 = 1600h
        ] {
            let before = c.upload(&sd, index, sub).await.unwrap();
            assert_eq!(
                c.download(&sd, index, sub, &data).await,
                Err(SdoAbort::DEVICE_STATE.0),
                "{index:04X}h:{sub:02X}h in Safe-Op"
            );
            assert_eq!(c.upload(&sd, index, sub).await, Ok(before), "unchanged");
        }
        // ethercrab's write gets the same refusal
        assert!(sd.sdo_write(0x1600, 0, 0u8).await.is_err());
        assert_eq!(pdo_bytes(&sim), Some((23, 29)));
        assert_eq!(al_status(&sd).await, (SAFEOP, 0));
    });
}

#[test]
fn e057_remap_behind_the_masters_back_refuses_safeop_with_001d_and_001e() {
    let sim = line(1);
    with_sdo_set_up(&sim, async |sd, c| {
        // the master configures SM2/SM3 for the default layout (23/29 bytes)
        // someone else shortens the RxPDO to the controlword
        c.download(sd, 0x1600, 0, &[0]).await.unwrap();
        c.download(sd, 0x1600, 1, &CONTROLWORD.to_le_bytes())
            .await
            .unwrap();
        c.download(sd, 0x1600, 0, &[1]).await.unwrap();
        write_sm(sd, 2, 0x1200, 23, 0x64).await;
        write_sm(sd, 3, 0x1A00, 29, 0x20).await;
        request_gives(
            sd,
            SAFEOP,
            (PREOP | ERR, AlStatusCode::INVALID_OUTPUT_CONFIG.0),
            "SM2 23 bytes, mapping 2 bytes",
        )
        .await;
        // EMCY A000h, diag code SM2 "PDO length not correct" (4·2 + 2 = Ah)
        let r = c.sdo(sd, &[0x40, 0x00, 0x10, 0, 0, 0, 0, 0]).await.unwrap();
        assert_eq!(r[0], 0x43, "1000h still readable");
        let emcy = c.emergencies.first().expect("an EMCY before the reply");
        assert_eq!((u16::from_le_bytes([emcy[0], emcy[1]]), emcy[3]), (0xA000, 0x0A));

        // SM2 matched to the new mapping: the TxPDO shrinks behind its back too
        write_sm(sd, 2, 0x1200, 2, 0x64).await;
        c.download(sd, 0x1A00, 0, &[1]).await.unwrap(); // statusword only
        request_gives(
            sd,
            SAFEOP | ACK,
            (PREOP | ERR, AlStatusCode::INVALID_INPUT_CONFIG.0),
            "SM3 29 bytes, mapping 2 bytes",
        )
        .await;
        write_sm(sd, 3, 0x1A00, 2, 0x20).await;
        request_gives(sd, SAFEOP | ACK, (SAFEOP, 0), "both lengths match").await;
    });
}

/// The slave's process images follow the mapping of the P→S transition.
#[test]
fn e048_e049_slave_process_image_follows_a_remapped_layout() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        map_pdo(&sd, 0x1600, &[CONTROLWORD]).await;
        sd.sdo_write(0x1A00, 0, 1u8).await.unwrap();
        let group = group.into_op(md).await.unwrap();
        group.tx_rx(md).await.unwrap();
        let mut s = sim.borrow_mut();
        let slave = s.drives_mut()[0].drive.slave_mut();
        assert_eq!(slave.outputs().len(), 2, "RxPDO: controlword");
        assert_eq!(slave.inputs_mut().len(), 2, "TxPDO: statusword");
    });
}

/// The mode-specific maps (cia402.md §6.5.1 ip, §6.5.6 vl) written by a master's
/// startup list in Pre-Op, then OP with the new process image.
#[test]
fn e048_e049_ip_and_vl_maps_from_a_startup_list_reach_op() {
    for (layout, bytes) in [
        (drive_ecat::PdoLayout::Ip, 7usize),
        (drive_ecat::PdoLayout::Vl, 5),
    ] {
        let sim = drive_tests::line(1);
        drive_tests::with_master(&sim, async |md, clock| {
            let group = drive_tests::init(md, clock).await;
            let sd = group.subdevice(md, 0).unwrap();
            drive_tests::map_layout(&sd, layout).await;
            let group = group.into_op(md).await.expect("OP with the mode map");
            let sd = group.subdevice(md, 0).unwrap();
            assert_eq!(sd.io_raw().outputs().len(), bytes, "{layout:?} RxPDO");
            assert_eq!(sd.io_raw().inputs().len(), bytes, "{layout:?} TxPDO");
            for _ in 0..5 {
                group.tx_rx(md).await.expect("cycle");
            }
        });
        // the drive side computes the same layout from its own declaration
        let mut objects = drive_ecat::DriveObjects::new();
        objects.apply_map(layout).expect("apply_map");
        use od::Dictionary as _;
        assert_eq!(objects.process_data_bytes(), Some((bytes, bytes)));
    }
}
