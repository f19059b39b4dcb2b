//! The single-axis device (SI6A061, issue 20) through a real master
//! (ethercrab, in-process): its own identity from the SII, an object
//! dictionary without axis B (no 68xxh, no A000h…DFFFh objects: SDO Info
//! does not list them, an SDO gets 0602 0000h, a mapping 0604 0041h), only
//! channel 1 assigned, and Op with axis A's standard process data: enable
//! and a csp move, axis B's motor unpowered.

use drive_ecat::Variant;
use drive_tests::{init, sw, with_cyclic, with_master, with_sdo, CoeClient, REV, REV_F};
use hil_sim::sim::{SimDrive, Simulation};
use std::cell::RefCell;

/// 0602 0000h: the object does not exist in the object dictionary.
const NO_OBJECT: u32 = 0x0602_0000;
/// 0604 0041h: the object cannot be mapped into the PDO.
const NOT_MAPPABLE: u32 = 0x0604_0041;

/// A line of `n` single-axis drives.
fn single_axis_line(n: usize) -> RefCell<Simulation> {
    RefCell::new(Simulation::of(Variant::Single, n))
}

/// One of axis B's objects: CiA 402 at +800h, manufacturer at +8000h.
fn axis_b(index: u16) -> bool {
    (0x6800..=0x6FFF).contains(&index) || (0xA000..=0xDFFF).contains(&index)
}

#[test]
fn e005_e006_the_single_axis_identity_from_the_sii_and_1018h() {
    // a mixed line: the master tells the two devices apart by product code
    let sim = RefCell::new(Simulation::with_nodes(vec![
        SimDrive::new(),
        SimDrive::single_axis(),
    ]));
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let ids: Vec<_> = group.iter(md).map(|sd| sd.identity()).collect();
        assert_eq!(ids.len(), 2);
        assert_eq!((ids[0].vendor_id, ids[1].vendor_id), (0xB9, 0xB9));
        assert_eq!(ids[0].product_id, drive_ecat::PRODUCT_CODE);
        assert_eq!(ids[1].product_id, drive_ecat::PRODUCT_CODE_SINGLE);
        assert_eq!(ids[1].revision, drive_ecat::SOFTWARE_BUILD);
        let names: Vec<String> = group.iter(md).map(|sd| sd.name().to_string()).collect();
        assert!(names[1].contains("SI6"), "SII name {names:?}");
        assert!(names[0].contains("SC6"), "SII name {names:?}");
        // the dictionary says the same (E-005, E-006)
        let sd = group.subdevice(md, 1).unwrap();
        let code: u32 = sd.sdo_read(0x1018, 2).await.expect("1018h:02");
        assert_eq!(code, drive_ecat::PRODUCT_CODE_SINGLE);
        let mut c = CoeClient::new();
        assert_eq!(c.upload(&sd, 0x1008, 0).await, Ok(b"SI6".to_vec()));
    });
}

#[test]
fn e080_e084_the_single_axis_od_lists_have_no_axis_b_object() {
    let sim = single_axis_line(1);
    with_sdo(&sim, async |sd, c| {
        let all = c.od_list(sd, 1).await;
        let rx = c.od_list(sd, 2).await;
        let tx = c.od_list(sd, 3).await;
        for (what, list) in [("all", &all), ("RxPDO", &rx), ("TxPDO", &tx)] {
            let b: Vec<String> = list
                .iter()
                .filter(|&&i| axis_b(i))
                .map(|i| format!("{i:04X}h"))
                .collect();
            assert!(b.is_empty(), "{what}: axis-B objects listed: {b:?}");
        }
        // axis A and the communication area are all there, channel 2 too
        for index in [
            0x1018, 0x1600, 0x1601, 0x1A01, 0x1C12, 0x6040, 0x6041, 0x28C8, 0xF050,
        ] {
            assert!(all.contains(&index), "{index:04X}h listed");
        }
        assert!(rx.contains(&0x6040) && tx.contains(&0x6041));
        // the same list as the double-axis device's without axis B
        let expected: Vec<u16> = {
            let d = drive_ecat::DriveObjects::for_variant(Variant::Single);
            let mut out = Vec::new();
            let mut after = None;
            while let Some(o) = od::Dictionary::next_object(&d, after) {
                out.push(o.index);
                after = Some(o.index);
            }
            out
        };
        assert_eq!(all, expected);
        // an object description of an axis-B object is refused too
        let (op, data) = c.info(sd, 3, &0x6841u16.to_le_bytes()).await;
        assert_eq!(op, 7, "SDO Info error for 6841h: {data:02x?}");
        assert_eq!(u32::from_le_bytes(data[..4].try_into().unwrap()), NO_OBJECT);
    });
}

#[test]
fn e016_e072_an_sdo_to_axis_b_gets_0602_0000_and_changes_nothing() {
    let sim = single_axis_line(1);
    with_sdo(&sim, async |sd, c| {
        for (index, sub) in [(0x6841, 0), (0x6840, 0), (0x6864, 0), (0xA8C8, 1), (0xA000, 1)] {
            assert_eq!(
                c.upload(sd, index, sub).await,
                Err(NO_OBJECT),
                "{index:04X}h:{sub}"
            );
        }
        let before = sim.borrow().drives()[0].drive.objects().clone();
        assert_eq!(c.download(sd, 0x6840, 0, &[0x0F, 0]).await, Err(NO_OBJECT));
        assert_eq!(c.download(sd, 0x6860, 0, &[8]).await, Err(NO_OBJECT));
        assert_eq!(
            sim.borrow().drives()[0].drive.objects(),
            &before,
            "refused downloads change nothing"
        );
        // ethercrab's own SDO read of 6841h fails as well
        c.hand_over(sd).await;
        let r: Result<u16, _> = sd.sdo_read(0x6841, 0).await;
        assert!(r.is_err(), "6841h: {r:?}");
        // axis A answers
        let sw: u16 = sd.sdo_read(0x6041, 0).await.expect("6041h");
        assert_eq!(sw & 0x6F, sw::SOD);
    });
}

#[test]
fn e051_e054_only_channel_1_is_assigned_and_channel_2_is_empty() {
    let sim = single_axis_line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        for (assign, pdo) in [(0x1C12u16, 0x1600u16), (0x1C13, 0x1A00)] {
            let n: u8 = sd.sdo_read(assign, 0).await.expect("sub 0");
            assert_eq!(n, 1, "{assign:04X}h:00");
            let first: u16 = sd.sdo_read(assign, 1).await.expect("sub 1");
            assert_eq!(first, pdo, "{assign:04X}h:01");
        }
        for pdo in [0x1601u16, 0x1A01] {
            let n: u8 = sd.sdo_read(pdo, 0).await.expect("sub 0");
            assert_eq!(n, 0, "{pdo:04X}h is empty");
            let e: u32 = sd.sdo_read(pdo, 1).await.expect("sub 1");
            assert_eq!(e, 0, "{pdo:04X}h:01");
        }
        let f050: u32 = sd.sdo_read(0xF050, 2).await.expect("F050h:02");
        assert_eq!(f050, 0, "no module on axis B (E-148)");
        // ethercrab sized the process data from the assignment: 23 + 29 bytes
        let group = group.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(
            (sd.io_raw().outputs().len(), sd.io_raw().inputs().len()),
            (23, 29)
        );
    });
}

#[test]
fn e058_mapping_an_axis_b_object_gets_0604_0041_and_changes_nothing() {
    let sim = single_axis_line(1);
    with_sdo(&sim, async |sd, c| {
        for pdo in [0x1600u16, 0x1601] {
            c.download(sd, pdo, 0, &[0]).await.expect("sub 0 = 0");
            let before = sim.borrow().drives()[0].drive.objects().clone();
            for m in [0x6840_0010u32, 0x687A_0020, 0xA043_0010] {
                assert_eq!(
                    c.download(sd, pdo, 1, &m.to_le_bytes()).await,
                    Err(NOT_MAPPABLE),
                    "{pdo:04X}h:01 = {m:08X}h"
                );
            }
            assert_eq!(sim.borrow().drives()[0].drive.objects(), &before);
        }
        let tx = 0x6841_0010u32;
        c.download(sd, 0x1A01, 0, &[0]).await.expect("sub 0 = 0");
        assert_eq!(
            c.download(sd, 0x1A01, 1, &tx.to_le_bytes()).await,
            Err(NOT_MAPPABLE)
        );
        // axis A's objects map into channel 2; the standard map goes back
        c.download(sd, 0x1601, 1, &0x6040_0010u32.to_le_bytes())
            .await
            .expect("6040h into channel 2");
        c.download(sd, 0x1600, 0, &[8]).await.expect("1600h back");
        assert_eq!(
            c.upload(sd, 0x1600, 1).await,
            Ok(0x6040_0010u32.to_le_bytes().to_vec())
        );
    });
}

#[test]
fn e034_op_with_axis_a_standard_pdo_enable_and_a_csp_move() {
    let sim = single_axis_line(1);
    with_cyclic(&sim, async |m, _| {
        m.set_mode(8);
        let tx = m.run(3).await;
        assert_eq!(tx.state(), sw::SOD);
        let start = tx.position;
        m.set_target_position(start);
        let tx = m.enable().await;
        assert!(tx.bit(12), "csp: drive follows, {:#06x}", tx.statusword);
        // one revolution in 500 ms (linear set-points), then hold
        let n = 500;
        for k in 1..=n + 300 {
            let target = start + (f64::from(REV) * f64::from(k.min(n)) / f64::from(n)) as i32;
            m.set_target_position(target);
            let tx = m.cycle().await;
            assert_eq!(tx.state(), sw::OE, "cycle {k}: {:#06x}", tx.statusword);
        }
        let end = start + REV;
        let err = f64::from(end - m.tx.position).abs() / REV_F;
        assert!(
            err < 0.01,
            "axis A reached the target: {} of {end}",
            m.tx.position
        );
        // axis B: no power, no motion
        let sim = sim.borrow();
        let d = &sim.drives()[0];
        let b = d.motor_outputs(1).expect("a cycle ran");
        assert_eq!(b.torque_applied_nm, 0.0);
        assert!(b.brake_applied);
        assert!(d.motors[1].velocity_rad_s().abs() < 1e-9);
        assert!(!d.motor_outputs(0).unwrap().brake_applied);
    });
}
