//! Fieldbus scaling A213 through a real master (E-059, E-143, E-086; spec
//! `ethercat.md` §5.4, §15): the representation set in Pre-Op, scaled
//! process data in Op, the parameter channel's own representation, and the
//! refusals. The dictionary side: `crates/drive-core/src/tests_scaling.rs`.

use drive_ecat::parameter_index;
use drive_tests::{init, line, motor_rev_s, with_master, with_sdo, CoeClient, Cyclic, REV};
use ecat::SdoAbort;
use hil_sim::sim::Simulation;
use std::cell::RefCell;

const A213: u16 = parameter_index(0, 213);
const A310: u16 = parameter_index(0, 310);
const A311: u16 = parameter_index(0, 311);

/// 606Ch's place in the standard TxPDO (after 6041h, 6061h, 6064h).
const VELOCITY_AT: usize = 7;

/// The value the drive keeps in `index`:`sub` (the process data's
/// representation).
fn kept(sim: &RefCell<Simulation>, index: u16, sub: u8) -> i64 {
    sim.borrow().drives()[0].drive.objects().get(index, sub).unwrap()
}

/// A213[0] = 0 with A310 = 2, A311 = 3 set in Pre-Op (bad values refused
/// first); in Op the csv set-point 60FFh and the actual velocity 606Ch
/// travel in 0.01 inc/s, little-endian; A213[0], A310 and A311 are refused
/// in Op; the parameter channel shows 60FFh in inc/s with A213[1] = 1 and
/// in the process data's 0.01 inc/s with A213[1] = 0 (changeable in Op).
#[test]
fn e059_e143_integer_process_data_in_op_and_the_parameter_channel() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let mut c = CoeClient::new();
        // bad input: nothing changes
        for (index, sub, data, abort) in [
            (A213, 1, &[0u8, 0][..], SdoAbort::LENGTH_TOO_HIGH),
            (A213, 1, &[2], SdoAbort::VALUE_TOO_HIGH),
            (A213, 3, &[0], SdoAbort::NO_SUBINDEX),
            (A310, 0, &[10], SdoAbort::VALUE_TOO_HIGH),
            (A311, 0, &[1, 0], SdoAbort::LENGTH_TOO_HIGH),
        ] {
            assert_eq!(
                c.download(&sd, index, sub, data).await,
                Err(abort.0),
                "{index:04X}h:{sub} {data:?}"
            );
        }
        assert_eq!(c.upload(&sd, A213, 1).await, Ok(vec![1]), "native");
        assert_eq!(c.upload(&sd, A310, 0).await, Ok(vec![0]));
        // the master's start-up list: integer process data, 2 and 3 decimals
        c.download(&sd, A213, 1, &[0]).await.unwrap();
        c.download(&sd, A310, 0, &[2]).await.unwrap();
        c.download(&sd, A311, 0, &[3]).await.unwrap();
        c.hand_over(&sd).await;

        let group = group.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).unwrap();
        // the representation of running process data stays
        for (index, sub, data) in [(A213, 1, 1u8), (A310, 0, 0), (A311, 0, 0)] {
            assert_eq!(
                c.download(&sd, index, sub, &[data]).await,
                Err(SdoAbort::DEVICE_STATE.0),
                "{index:04X}h:{sub} in Op"
            );
        }
        assert_eq!(c.upload(&sd, A213, 1).await, Ok(vec![0]));
        assert_eq!(c.upload(&sd, A310, 0).await, Ok(vec![2]));
        c.hand_over(&sd).await;

        let mut cy = Cyclic::new(md, &group, &sim, 0);
        cy.enable_in(9).await;
        // 0.5 rev/s in 0.01 inc/s
        let v = REV * 50;
        cy.set_target_velocity(v);
        assert_eq!(
            &cy.out[7..11],
            &v.to_le_bytes(),
            "60FFh little-endian in the RxPDO"
        );
        let t = cy.run(600).await;
        let motor = motor_rev_s(&sim, 0);
        println!(
            "A310 = 2: 60FFh {v}, 606Ch {}, plant {motor:.4} rev/s",
            t.velocity
        );
        assert!((motor - 0.5).abs() < 0.01, "the plant turns 0.5 rev/s: {motor}");
        assert!(
            (t.velocity - v).abs() < v / 100,
            "606Ch in 0.01 inc/s: {}",
            t.velocity
        );
        let inputs = sd.io_raw().inputs().to_vec();
        assert_eq!(
            &inputs[VELOCITY_AT..VELOCITY_AT + 4],
            &t.velocity.to_le_bytes(),
            "606Ch little-endian in the TxPDO"
        );
        assert_eq!(
            kept(&sim, 0x60FF, 0),
            i64::from(v),
            "the dictionary keeps the PDO value"
        );

        // the parameter channel: native (A213[1] = 1, the default) shows inc/s
        let mut c = CoeClient::new();
        let up = |r: Result<Vec<u8>, u32>| i32::from_le_bytes(r.unwrap().try_into().unwrap());
        assert_eq!(up(c.upload(&sd, 0x60FF, 0).await), REV / 2, "60FFh in inc/s");
        let shown = up(c.upload(&sd, 0x606C, 0).await);
        assert!((shown - REV / 2).abs() < REV / 100, "606Ch in inc/s: {shown}");
        // A213[1] may change in Op: now the channel carries the 0.01 inc/s too
        c.download(&sd, A213, 2, &[0]).await.unwrap();
        assert_eq!(up(c.upload(&sd, 0x60FF, 0).await), v, "60FFh in 0.01 inc/s");
        c.hand_over(&sd).await;
        // and the process data ran on unchanged
        let t = cy.run(100).await;
        assert!((t.velocity - v).abs() < v / 100, "606Ch: {}", t.velocity);
        assert!((motor_rev_s(&sim, 0) - 0.5).abs() < 0.01);
    });
}

/// E-086: the master's CoE-Online view edits values in the unit the ESI and
/// SDO Info declare (6081h: inc/s). With A213[1] = 1 (native) an edit means
/// that unit whatever the process data carry and reads back as typed; with
/// A213[1] = 0 the same number is taken in the process data's 0.01 inc/s,
/// a hundredth of what the editor showed.
#[test]
fn e086_coe_online_edit_lands_in_the_declared_unit_only_with_native() {
    let sim = line(1);
    with_sdo(&sim, async |sd, c| {
        c.download(sd, A213, 1, &[0]).await.unwrap();
        c.download(sd, A310, 0, &[2]).await.unwrap();
        let edit = 5000u32.to_le_bytes();
        // native parameter channel
        c.download(sd, 0x6081, 0, &edit).await.unwrap();
        assert_eq!(c.upload(sd, 0x6081, 0).await, Ok(edit.to_vec()), "as typed");
        assert_eq!(
            kept(&sim, 0x6081, 0),
            500_000,
            "5000 inc/s = 500 000 × 0.01 inc/s"
        );
        // integer parameter channel: the same edit
        c.download(sd, A213, 2, &[0]).await.unwrap();
        c.download(sd, 0x6081, 0, &edit).await.unwrap();
        assert_eq!(c.upload(sd, 0x6081, 0).await, Ok(edit.to_vec()));
        assert_eq!(kept(&sim, 0x6081, 0), 5000, "50 inc/s, not 5000");
        c.download(sd, A213, 2, &[1]).await.unwrap();
        assert_eq!(
            c.upload(sd, 0x6081, 0).await,
            Ok(50u32.to_le_bytes().to_vec()),
            "what the native view shows of it"
        );
    });
}
