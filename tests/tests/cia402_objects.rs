//! CiA 402 communication items through a real master (features-cia402.md
//! C-130 … C-151, spec cia402.md §5, §7): the standard PDO layout as the
//! master exchanges it, mapping limits and directions, sub 0 constants,
//! manufacturer parameter addressing, the PDO timeout A258, hidden
//! parameters, native fieldbus scaling, synchronisation, saving, the mapping
//! after a restart and the station alias.

use drive_ecat::{parameter_index, Template};
use drive_tests::al::{ERR, OP, SAFEOP};
use drive_tests::step::{advance, op_via_safe_op};
use drive_tests::{
    al_status, init, line, map_layout, motor_rev_s, sdo_is, variant, with_master, with_preop, with_sdo,
    Cyclic, REV,
};
use ecat::SdoAbort;
use esc::AlStatusCode;
use hil_sim::sim::Simulation;
use std::cell::RefCell;

/// Mapping entry: index << 16 | sub << 8 | bit length.
const fn m(index: u16, sub: u8, bits: u8) -> u32 {
    (index as u32) << 16 | (sub as u32) << 8 | bits as u32
}

/// Offsets of a byte-packed mapping.
fn offsets(entries: &[u32]) -> (Vec<usize>, usize) {
    let mut at = 0;
    let mut out = Vec::new();
    for e in entries {
        out.push(at);
        at += (e & 0xFF) as usize / 8;
    }
    (out, at)
}

// ---------------------------------------------------------------------------
// C-130 … C-133, C-138, C-139 PDO layout and mapping
// ---------------------------------------------------------------------------

#[test]
fn c130_c131_c132_standard_pdo_layout_byte_packed_through_the_master() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        // the mapping objects as the master reads them
        let read_map = async |pdo: u16| {
            let n: u8 = sd.sdo_read(pdo, 0).await.unwrap();
            let mut v = Vec::new();
            for s in 1..=n {
                v.push(sd.sdo_read::<u32>(pdo, s).await.unwrap());
            }
            v
        };
        let rx = read_map(0x1600).await;
        let tx = read_map(0x1A00).await;
        let rx_expected = [
            m(0x6040, 0, 16),
            m(0x6060, 0, 8),
            m(0x607A, 0, 32),
            m(0x60FF, 0, 32),
            m(0x60B1, 0, 32),
            m(0x60B2, 0, 16),
            m(0x6071, 0, 16),
            m(0x60FE, 1, 32),
        ];
        let tx_expected = [
            m(0x6041, 0, 16),
            m(0x6061, 0, 8),
            m(0x6064, 0, 32),
            m(0x606C, 0, 32),
            m(0x6077, 0, 16),
            m(0x60F4, 0, 32),
            m(0x60FD, 0, 32),
            m(0x60E4, 1, 32),
            m(parameter_index(4, 201), 0, 16),
            m(parameter_index(0, 67), 0, 16),
        ];
        assert_eq!(rx, rx_expected, "1600h (Tab. 30)");
        assert_eq!(tx, tx_expected, "1A00h (Tab. 32)");
        // byte-packed: 6060h (1 byte) at 2 puts 607Ah at the odd offset 3 (C-132)
        let (rx_at, rx_len) = offsets(&rx);
        let (tx_at, tx_len) = offsets(&tx);
        assert_eq!(rx_at, [0, 2, 3, 7, 11, 15, 17, 19]);
        assert_eq!(rx_len, 23, "RxPDO 23 bytes");
        assert_eq!(tx_at, [0, 2, 3, 7, 11, 13, 17, 21, 25, 27]);
        assert_eq!(tx_len, 29, "TxPDO 29 bytes");

        // the exchanged image has exactly these sizes and offsets
        let group = group.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).unwrap();
        // A67 bit 0 from 6041h bit 6 (switch on disabled), so byte 27 carries a known bit
        sd.sdo_write(parameter_index(0, 66), 1, 0x6041_0006u32)
            .await
            .unwrap();
        let mut c = Cyclic::new(md, &group, &sim, 0);
        c.set_mode(0);
        c.set_target_position(0x0102_0304);
        c.set_target_velocity(-0x0A0B_0C0D);
        c.set_velocity_offset(0x1122_3344);
        c.set_torque_offset(-1234);
        c.set_target_torque(777);
        c.out[19..23].copy_from_slice(&0x8000_0005u32.to_le_bytes());
        let t = c.run(5).await;
        sdo_is(&sd, 0x607A, 0, 0x0102_0304i32, "607Ah @3").await;
        sdo_is(&sd, 0x60FF, 0, -0x0A0B_0C0Di32, "60FFh @7").await;
        sdo_is(&sd, 0x60B1, 0, 0x1122_3344i32, "60B1h @11").await;
        sdo_is(&sd, 0x60B2, 0, -1234i16, "60B2h @15").await;
        sdo_is(&sd, 0x6071, 0, 777i16, "6071h @17").await;
        sdo_is(&sd, 0x60FE, 1, 0x8000_0005u32, "60FEh:01 @19").await;
        sdo_is(&sd, 0x6041, 0, t.statusword, "6041h @0").await;
        sdo_is(&sd, 0x6061, 0, t.mode_display, "6061h @2").await;
        sdo_is(&sd, 0x6064, 0, t.position, "6064h @3").await;
        sdo_is(&sd, 0x60E4, 1, t.additional_position, "60E4h:01 @21").await;
        assert_eq!(t.state(), drive_tests::sw::SOD);
        assert_eq!(t.a67 & 1, 1, "A67 @27 carries 6041h bit 6: {:#06x}", t.a67);
    });
}

#[test]
fn c133_up_to_24_entries_per_pdo() {
    let sim = line(1);
    with_sdo(&sim, async |sd, c| {
        for (pdo, entry) in [(0x1600u16, m(0x6060, 0, 8)), (0x1A00, m(0x6061, 0, 8))] {
            c.download(sd, pdo, 0, &[0]).await.unwrap();
            for s in 1..=24u8 {
                c.download(sd, pdo, s, &entry.to_le_bytes()).await.unwrap();
            }
            c.download(sd, pdo, 0, &[24])
                .await
                .expect("24 entries are accepted");
            assert_eq!(c.upload(sd, pdo, 0).await, Ok(vec![24]));
            c.download(sd, pdo, 0, &[0]).await.unwrap();
            assert_eq!(
                c.download(sd, pdo, 0, &[25]).await,
                Err(SdoAbort::PDO_LENGTH.0),
                "{pdo:04X}h: 25 entries refused"
            );
            assert!(
                c.download(sd, pdo, 25, &entry.to_le_bytes()).await.is_err(),
                "{pdo:04X}h: there is no 25th entry"
            );
        }
    });
}

#[test]
fn c138_only_mappable_objects_in_their_direction() {
    let sim = line(1);
    with_sdo(&sim, async |sd, c| {
        c.download(sd, 0x1600, 0, &[0]).await.unwrap();
        c.download(sd, 0x1A00, 0, &[0]).await.unwrap();
        let not = Err(SdoAbort::NOT_MAPPABLE.0);
        // (PDO, subindex, entry, taken): in the order written
        for (pdo, sub, entry, taken) in [
            // 6098h: not mappable at all
            (0x1600, 1, m(0x6098, 0, 8), false),
            (0x1A00, 1, m(0x6098, 0, 8), false),
            // 605Ah: Rx only
            (0x1A00, 1, m(0x605A, 0, 16), false),
            (0x1600, 1, m(0x605A, 0, 16), true),
            // 6041h: Tx only
            (0x1600, 2, m(0x6041, 0, 16), false),
            (0x1A00, 1, m(0x6041, 0, 16), true),
        ] {
            let r = c.download(sd, pdo, sub, &entry.to_le_bytes()).await;
            let want = if taken { Ok(()) } else { not };
            assert_eq!(r, want, "{entry:08X}h into {pdo:04X}h:{sub}");
        }
        // the axis-B window follows the same flags
        c.download(sd, 0x1601, 0, &[0]).await.unwrap();
        assert_eq!(
            c.download(sd, 0x1601, 1, &m(0x6898, 0, 8).to_le_bytes()).await,
            not
        );
        let axis_b = c.download(sd, 0x1601, 1, &m(0x6840, 0, 16).to_le_bytes()).await;
        if variant().axes() == 2 {
            axis_b.expect("6840h in an RxPDO");
        } else {
            assert_eq!(axis_b, not, "the single-axis device has no 6840h");
        }
    });
}

#[test]
fn c139_subindex_0_constants() {
    let sim = line(1);
    with_sdo(&sim, async |sd, _| {
        for (index, n) in [
            (0x6046u16, 2u8),
            (0x60A4, 1),
            (0x60E3, 0x14),
            // the manual prints 5 but lists subs 1–6: the standard's 6 (decisions table)
            (0x60C4, 6),
            (0x6099, 2),
            (0x607D, 2),
            (0x60C2, 2),
            (0x6846, 2),
            (0x68E3, 0x14),
        ] {
            if !variant().has_object(index) {
                let missing = sd.sdo_read::<u8>(index, 0).await;
                assert!(missing.is_err(), "{index:04X}h on the single-axis device");
                continue;
            }
            let v: u8 = sd.sdo_read(index, 0).await.unwrap();
            assert_eq!(v, n, "{index:04X}h:00");
            assert!(
                sd.sdo_write(index, 0, n + 1).await.is_err(),
                "{index:04X}h:00 is constant"
            );
            let v: u8 = sd.sdo_read(index, 0).await.unwrap();
            assert_eq!(v, n, "{index:04X}h:00 unchanged");
        }
    });
}

// ---------------------------------------------------------------------------
// C-135 … C-137 manufacturer parameter addressing, C-141 hidden parameters
// ---------------------------------------------------------------------------

#[test]
fn c135_c136_c137_manufacturer_parameter_addresses_and_templates() {
    let sim = line(1);
    let a340 = 0x2000 + 340; // group A (0) × 200h + line 340
    let e200 = 0x2000 + 4 * 0x200 + 200;
    assert_eq!((a340, e200), (0x2154, 0x28C8));
    with_sdo(&sim, async |sd, c| {
        // C-135/C-136: A340 of axis A at 2154h, of axis B at A154h, independent
        let axis_b = variant().axes() == 2;
        sd.sdo_write(a340, 0, 70u16).await.unwrap();
        let b_write = sd.sdo_write(a340 + 0x8000, 0, 30u16).await;
        assert_eq!(sd.sdo_read::<u16>(a340, 0).await.unwrap(), 70);
        let objects = |sim: &RefCell<Simulation>, i: u16| sim.borrow().drives()[0].drive.objects().get(i, 0);
        if axis_b {
            b_write.unwrap();
            assert_eq!(sd.sdo_read::<u16>(a340 + 0x8000, 0).await.unwrap(), 30);
            assert_eq!(objects(&sim, 0xA154), Ok(30), "the axis-B parameter");
        } else {
            assert!(b_write.is_err(), "no A154h on the single-axis device");
            assert_eq!(
                c.upload(sd, a340 + 0x8000, 0).await,
                Err(SdoAbort::NO_OBJECT.0),
                "no A154h on the single-axis device"
            );
        }
        // C-137, "SDO Info" template (default): E200[0] at sub 1, sub 0 = element count
        assert_eq!(
            c.upload(sd, e200, 0).await,
            Ok(vec![2]),
            "E200 sub 0 = 2 elements"
        );
        assert!(c.upload(sd, e200, 1).await.is_ok(), "E200[0] at sub 1");
        assert_eq!(
            c.upload(sd, e200 + 0x8000, 1).await.is_ok(),
            axis_b,
            "axis B E200[0] at A8C8h:01"
        );
        assert!(c.upload(sd, e200, 3).await.is_err(), "no element 2");
        // "EtherCAT Rx" template: element = subindex
        sim.borrow_mut().drives_mut()[0]
            .drive
            .objects_mut()
            .set_template(Template::Rx);
        assert_eq!(
            c.upload(sd, e200, 0).await.map(|v| v.len()),
            Ok(2),
            "E200[0] (WORD) at sub 0"
        );
        assert!(c.upload(sd, e200, 1).await.is_ok(), "E200[1] at sub 1");
        assert!(c.upload(sd, e200, 2).await.is_err(), "no element 2");
        // A66 (per-axis array of UDINT): element 3 written in the Rx template is element 3 + 1 in SDO Info
        c.download(sd, parameter_index(0, 66), 3, &0x6041_0002u32.to_le_bytes())
            .await
            .unwrap();
        sim.borrow_mut().drives_mut()[0]
            .drive
            .objects_mut()
            .set_template(Template::SdoInfo);
        assert_eq!(
            c.upload(sd, parameter_index(0, 66), 4).await,
            Ok(0x6041_0002u32.to_le_bytes().to_vec())
        );
    });
}

#[test]
fn c141_hidden_parameters_are_not_reachable() {
    let sim = line(1);
    let a10 = parameter_index(0, 10);
    let i46 = parameter_index(8, 46); // level 1
    with_sdo(&sim, async |sd, c| {
        assert_eq!(c.upload(sd, i46, 0).await, Ok(vec![0]), "visible at A10[2] = 2");
        // A10[2] = 0: level-1 parameters are hidden for read and write
        c.download(sd, a10, 3, &[0]).await.unwrap();
        let hidden = SdoAbort::NO_OBJECT.0;
        assert_eq!(c.upload(sd, i46, 0).await, Err(hidden));
        assert_eq!(c.download(sd, i46, 0, &[5]).await, Err(hidden));
        assert_eq!(c.upload(sd, i46 + 0x8000, 0).await, Err(hidden), "axis B too");
        // CiA 402 objects stay reachable
        assert!(c.upload(sd, 0x6041, 0).await.is_ok());
        c.download(sd, a10, 3, &[2]).await.unwrap();
        assert_eq!(
            c.upload(sd, i46, 0).await,
            Ok(vec![0]),
            "the write did not happen"
        );
    });
}

// ---------------------------------------------------------------------------
// C-140 PDO timeout A258
// ---------------------------------------------------------------------------

/// Op with RxPDO every 1 ms, then a gap of `gap_ms` without frames:
/// `true` if the drive left Op with the PDO timeout.
fn pdo_gap_times_out(a258: u16, gap_ms: u64) -> bool {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        group
            .subdevice(md, 0)
            .unwrap()
            .sdo_write(parameter_index(0, 258), 0, a258)
            .await
            .unwrap();
        let group = op_via_safe_op(md, group, &sim).await;
        let sd = group.subdevice(md, 0).unwrap();
        for _ in 0..20 {
            advance(&sim, 1_000_000);
            group.tx_rx(md).await.unwrap();
        }
        assert_eq!(al_status(&sd).await, (OP, 0));
        advance(&sim, gap_ms * 1_000_000);
        match al_status(&sd).await {
            (OP, 0) => false,
            (s, code) => {
                assert_eq!(
                    (s, code),
                    (SAFEOP | ERR, AlStatusCode::SM_WATCHDOG.0),
                    "A258 = {a258}: PDO timeout"
                );
                true
            }
        }
    })
}

#[test]
fn c140_pdo_timeout_a258_values() {
    // 0 and 65535: off
    assert!(!pdo_gap_times_out(0, 500), "A258 = 0 off");
    assert!(!pdo_gap_times_out(65535, 500), "A258 = 65535 off");
    // 1 … 65531: that many ms
    assert!(!pdo_gap_times_out(30, 25), "30 ms: a 25 ms gap is within");
    assert!(pdo_gap_times_out(30, 40), "30 ms: a 40 ms gap times out");
    // 65532: one lost frame tolerated, two not
    assert!(!pdo_gap_times_out(65532, 2), "one frame lost");
    assert!(pdo_gap_times_out(65532, 3), "two frames lost");
    // 65533: three consecutive lost frames tolerated, four not
    assert!(!pdo_gap_times_out(65533, 4), "three frames lost");
    assert!(pdo_gap_times_out(65533, 5), "four frames lost");
}

// ---------------------------------------------------------------------------
// C-142 native scaling, C-145 synchronisation
// ---------------------------------------------------------------------------

/// csv at 60FFh = `v` after the Pre-Op writes `setup` (index, sub, value):
/// 60FFh as the parameter channel shows it, 606Ch in the TxPDO, the plant's
/// velocity in rev/s.
fn csv_at(setup: &[(u16, u8, u8)], v: i32) -> (i32, i32, f64) {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let a213: u8 = sd.sdo_read(parameter_index(0, 213), 1).await.unwrap();
        assert_eq!(a213, 1, "A213[0] = 1 native by default");
        for &(index, sub, value) in setup {
            sd.sdo_write(index, sub, value).await.unwrap();
        }
        let group = group.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).unwrap();
        let mut c = Cyclic::new(md, &group, &sim, 0);
        c.enable_in(9).await;
        c.set_target_velocity(v);
        let t = c.run(600).await;
        let shown = sd.sdo_read::<i32>(0x60FF, 0).await.unwrap();
        let motor = motor_rev_s(&sim, 0);
        println!(
            "{setup:?}: 60FFh {v} (SDO {shown}), 606Ch {}, plant {motor:.4} rev/s",
            t.velocity
        );
        (shown, t.velocity, motor)
    })
}

#[test]
fn c142_native_scaling_passes_values_unchanged_and_a310_sets_decimals() {
    // native: 60FFh in inc/s as sent, 1 234 567 inc/s reaches the object and the axis unchanged
    let v = 1_234_567;
    let (shown, velocity, motor) = csv_at(&[], v);
    assert_eq!(shown, v, "60FFh as sent");
    assert!(
        (velocity - v).abs() < v / 100,
        "606Ch in the same unit: {velocity}"
    );
    let motor = motor * f64::from(REV);
    assert!(
        (motor - f64::from(v)).abs() < f64::from(v) / 100.0,
        "the plant turns {motor}"
    );
    // A213[0] = 0 with A310 = 2 (Pre-Op, C-142/E-143): velocities count in 0.01 units/s
    let a213 = parameter_index(0, 213);
    let a310 = parameter_index(0, 310);
    let (shown, velocity, motor) = csv_at(&[(a213, 1, 0), (a310, 0, 2)], REV * 50);
    assert!((motor - 0.5).abs() < 0.01, "0.5 rev/s: {motor}");
    assert!(
        (velocity - REV * 50).abs() < REV / 2,
        "606Ch in 0.01 inc/s: {velocity}"
    );
    assert_eq!(shown, REV / 2, "the native parameter channel shows inc/s");
}

#[test]
fn c145_sm_sync_and_dc_sync_selectable() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        // 1C32h:04 supported synchronisation types: free run, SM-Sync, DC SYNC0
        let supported: u16 = sd.sdo_read(0x1C32, 4).await.unwrap();
        assert_eq!(supported & 0x0007, 0x0007, "1C32h:04 {supported:#06x}");
        // no SYNC0, 1C32h:01 = 1 from the master's start-up list: SM-Sync in Op
        sd.sdo_write(0x1C32, 1, 1u16).await.expect("SM-Sync selectable");
        let group = group.into_op(md).await.expect("OP in SM-Sync");
        let sd = group.subdevice(md, 0).unwrap();
        let t: u16 = sd.sdo_read(0x1C32, 1).await.unwrap();
        assert_eq!(t, 1, "1C32h:01 = 1 SM-Sync");
    });
    // DC: the dc_sync tests run Op under SYNC0; here the P→S decision with 0981h
    assert_eq!(
        ecat::esm::sync_mode(ecat::esm::DC_ACTIVATION_SYNC0, Some(1)),
        Ok(ecat::esm::SyncMode::DcSync0),
        "SYNC0 activated by the master wins"
    );
    assert_eq!(ecat::esm::SyncMode::DcSync0.sync_type(), 2);
}

// ---------------------------------------------------------------------------
// C-146 saving, C-147 mapping after a restart, C-151 station alias
// ---------------------------------------------------------------------------

const A00: u16 = parameter_index(0, 0);
const I46: u16 = parameter_index(8, 46);

fn power_cycle(sim: &RefCell<Simulation>) {
    sim.borrow_mut().drives_mut()[0].power_cycle();
}

#[test]
fn c146_changes_are_volatile_until_a00_saves_them() {
    let sim = line(1);
    let read =
        |sim: &RefCell<Simulation>| with_preop(sim, async |sd| sd.sdo_read::<u8>(I46, 0).await.unwrap());
    with_sdo(&sim, async |sd, _| {
        sd.sdo_write(I46, 0, 5u8).await.unwrap();
    });
    assert_eq!(read(&sim), 5, "in RAM");
    power_cycle(&sim);
    assert_eq!(read(&sim), 0, "not saved: the default after power-off");
    let (progress, result) = with_sdo(&sim, async |sd, _| {
        sd.sdo_write(I46, 0, 5u8).await.unwrap();
        let before: u8 = sd.sdo_read(A00, 2).await.unwrap();
        assert_ne!(before, 100, "no save done yet: A00[1] {before}");
        sd.sdo_write(A00, 1, 1u8).await.unwrap();
        let mut done = None;
        for _ in 0..100 {
            advance(&sim, 1_000_000);
            let p: u8 = sd.sdo_read(A00, 2).await.unwrap();
            if p == 100 {
                done = Some((p, sd.sdo_read::<u8>(A00, 3).await.unwrap()));
                break;
            }
        }
        done.expect("A00[1] reaches 100 %")
    });
    println!("A00: progress {progress} %, result {result}");
    assert_eq!(
        i64::from(result),
        drive_ecat::runtime::save_result::OK,
        "A00[2] ok"
    );
    power_cycle(&sim);
    assert_eq!(read(&sim), 5, "saved: kept over power-off");
}

#[test]
fn c147_changed_mapping_kept_over_a_restart_only_when_saved() {
    let sim = line(1);
    let map_ip = |sim: &RefCell<Simulation>, save: bool| {
        with_preop(sim, async |sd| {
            map_layout(&sd, drive_ecat::PdoLayout::Ip).await;
            if save {
                sd.sdo_write(A00, 1, 1u8).await.unwrap();
                for _ in 0..100 {
                    advance(sim, 1_000_000);
                    if sd.sdo_read::<u8>(A00, 2).await.unwrap() == 100 {
                        break;
                    }
                }
            }
        })
    };
    let rx_len = |sim: &RefCell<Simulation>| {
        with_preop(sim, async |sd| {
            let n: u8 = sd.sdo_read(0x1600, 0).await.unwrap();
            let mut bits = 0u32;
            for s in 1..=n {
                bits += sd.sdo_read::<u32>(0x1600, s).await.unwrap() & 0xFF;
            }
            bits / 8
        })
    };
    assert_eq!(rx_len(&sim), 23, "standard map");
    map_ip(&sim, false);
    assert_eq!(rx_len(&sim), 7, "ip map in RAM");
    power_cycle(&sim);
    assert_eq!(rx_len(&sim), 23, "not saved: the standard map after a restart");
    map_ip(&sim, true);
    power_cycle(&sim);
    assert_eq!(rx_len(&sim), 7, "saved: the ip map after a restart");
    // and the restarted drive runs Op with it (7-byte RxPDO)
    with_master(&sim, async |md, clock| {
        let group = init(md, clock)
            .await
            .into_op(md)
            .await
            .expect("OP with the saved map");
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(sd.io_raw().outputs().len(), 7);
    });
}

#[test]
fn c151_station_alias_kept_in_the_eeprom_and_shown_in_a254() {
    use esc::regs;
    use esc::sii::control;
    let sim = line(1);
    let alias = 0x0A51u16;
    with_sdo(&sim, async |sd, _| {
        let before: u16 = sd.sdo_read(parameter_index(0, 254), 0).await.unwrap();
        assert_ne!(before, alias);
        // the master writes word 4 (alias) and word 7 (checksum) of the SII, then reloads
        let mut head = sim.borrow().drives()[0].esc.sii()[..14].to_vec();
        head[8..10].copy_from_slice(&alias.to_le_bytes());
        let crc = esc::sii::config_checksum(&head);
        for (word, value) in [(4u32, alias), (7, u16::from(crc))] {
            sd.register_write(regs::SII_DATA, value).await.unwrap();
            sd.register_write(regs::SII_ADDRESS, word).await.unwrap();
            sd.register_write(regs::SII_CONTROL, control::CMD_WRITE | control::WRITE_ENABLE)
                .await
                .unwrap();
            advance(&sim, 1_000_000);
        }
        sd.register_write(regs::SII_CONTROL, control::CMD_RELOAD)
            .await
            .unwrap();
        advance(&sim, 1_000_000);
    });
    // the next start-up (Init → Pre-Op) shows it in A254
    with_sdo(&sim, async |sd, _| {
        let a254: u16 = sd.sdo_read(parameter_index(0, 254), 0).await.unwrap();
        println!("A254 {a254:#06x}");
        assert_eq!(a254, alias, "A254 shows the alias from the EEPROM");
    });
    assert_eq!(
        &sim.borrow().drives()[0].esc.sii()[8..10],
        &alias.to_le_bytes(),
        "in the SII image"
    );
}
