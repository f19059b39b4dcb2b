//! The drive's cycle against SYNC0 through the master: the A287 optimisation and its failures,
//! A149's order of Rx, application and Tx, SYNC0 a multiple of A150, A292 limited to one cycle
//! (E-109, E-111, E-112, E-120..E-124).

use super::*;

const A149: u16 = drive_ecat::parameter_index(0, 149);
const A150: u16 = drive_ecat::parameter_index(0, 150);
const A287: u16 = drive_ecat::parameter_index(0, 287);

/// E-120, E-121, E-123, E-124 (spec §11.8): A287[0] = 1 (sub 1) in Pre-Op
/// fails at once with 2 ("not executable"); in Op with DC SYNC0 it runs over
/// ≥ 1000 × A150, A287[1] (progress) rises by SDO, then A287[2] is 7 or 8
/// with a proposed A292 range min ≤ max (A287[3], [4]) around the A292 in
/// force, and A287[0] is back to 0.
#[test]
fn e120_e123_e124_a287_optimisation_through_the_master() {
    let sim = line();
    let pre_op = async |sd: &Sd<'_>| {
        sd.sdo_write(A287, 1, 1u8).await.expect("A287[0] in Pre-Op");
        let mut result = 0u8;
        for _ in 0..10 {
            result = sd.sdo_read(A287, 3).await.expect("A287[2]");
            if result != 0 {
                break;
            }
        }
        let start: u8 = sd.sdo_read(A287, 1).await.expect("A287[0]");
        println!("A287 in Pre-Op: result {result}, start {start}");
        assert_eq!(result, 2, "E-121: not executable in Pre-Op");
        assert_eq!(start, 0, "A287[0] back to 0");
    };
    let (progress, seen) = dc_op(&sim, SYNC0_NS, pre_op, 150, async |md, group| {
        for sd in group.iter(md) {
            sd.sdo_write(A287, 1, 1u8).await.expect("A287[0] = 1");
        }
        let mut progress: Vec<u8> = Vec::new();
        let mut done = false;
        for _ in 0..30 {
            dc_cycles(md, group, &sim, 50, |_, _, _| {}).await;
            let sd = group.subdevice(md, 0).expect("drive");
            let p: u8 = sd.sdo_read(A287, 2).await.expect("A287[1]");
            progress.push(p);
            let r: u8 = sd.sdo_read(A287, 3).await.expect("A287[2]");
            if r >= 2 {
                done = true;
                break;
            }
        }
        assert!(done, "finished: progress {progress:?}");
        let mut seen = Vec::new();
        for i in 0..2 {
            let sd = group.subdevice(md, i).expect("drive");
            let mut v = [0i64; 8];
            for (k, slot) in v.iter_mut().enumerate() {
                *slot = match k {
                    0..=2 => i64::from(sd.sdo_read::<u8>(A287, k as u8 + 1).await.expect("A287")),
                    _ => i64::from(sd.sdo_read::<i32>(A287, k as u8 + 1).await.expect("A287")),
                };
            }
            seen.push(v);
        }
        (progress, seen)
    });
    println!("A287[1] progress of drive 0 by SDO: {progress:?}");
    assert!(
        progress.iter().any(|&p| p > 0 && p < 100),
        "E-124: progress during the measurement"
    );
    assert!(progress.windows(2).all(|w| w[0] <= w[1]), "progress never falls");
    let s = sim.borrow();
    for (i, v) in seen.iter().enumerate() {
        println!(
            "drive {i}: A287 = {v:?} ([0] start, [1] %, [2] result, [3]/[4] A292 min/max µs, [5] EoF→SYNC0, \
             [6] frame, [7] SYNC0→Rx)"
        );
        assert_eq!(v[0], 0, "drive {i}: A287[0] back to 0");
        assert_eq!(v[1], 100, "drive {i}: progress 100 %");
        assert!(matches!(v[2], 7 | 8), "E-123: drive {i}: result {}", v[2]);
        assert!(v[3] <= v[4], "drive {i}: min ≤ max");
        if v[2] == 7 {
            assert!(
                (v[3]..=v[4]).contains(&i64::from(A292_US)),
                "drive {i}: 7 = A292 in range"
            );
        }
        assert!((-1000..1000).contains(&v[3]) && (-1000..1000).contains(&v[4]));
        let out = s.drives()[i].drive.optimizer().outcome().expect("outcome");
        assert!(out.result.is_success());
        // frames ≈ 100 µs before SYNC0; the SDO reads in between delay some
        assert!((-500..=110).contains(&v[5]), "drive {i}: EoF → SYNC0 {} µs", v[5]);
        assert!((0..500).contains(&v[6]), "drive {i}: frame window {} µs", v[6]);
    }
}

/// Runs one A287 measurement on both drives of `group`,
/// calling `each` with the cycle number and the simulation after every
/// cycle; returns drive 0's A287[2], [3], [4] (result, A292 min/max µs) as
/// the dictionary holds them.
async fn a287_measurement<'a>(
    md: &'a MainDevice<'a>,
    group: &DcOpGroup,
    sim: &RefCell<Simulation>,
    mut each: impl FnMut(usize, &mut Simulation),
) -> (i64, i64, i64) {
    // started in the dictionary, not by SDO: mailbox traffic would delay the
    // next frames and look like master jitter (the SDO start is tested above)
    for d in sim.borrow_mut().drives_mut() {
        d.drive.objects_mut().set(A287, 1, 1).expect("A287[0] = 1");
    }
    for k in 0..1500 {
        dc_cycles(md, group, sim, 1, |_, _, _| {}).await;
        let mut s = sim.borrow_mut();
        each(k, &mut s);
        if s.drives()[0].drive.objects().get(A287, 3).unwrap() >= 2 {
            break;
        }
    }
    let s = sim.borrow();
    let get = |sub| s.drives()[0].drive.objects().get(A287, sub).unwrap();
    (get(3), get(4), get(5))
}

/// E-121, E-122, E-123 (spec §11.8) through the master, with the drive's
/// measured Rx/Tx offsets ([`drive_ecat::runtime::Drive::set_step_offsets`]) and
/// the frame jitter injected: Rx…Tx over 995 µs of the 1 ms cycle leaves no
/// room for the frame (5: application runtime); Rx/Tx moving by 30 µs from
/// cycle to cycle (4: drive jitter); ±20 µs frame jitter (3: master jitter);
/// each failure proposes min = max = the A292 in force. A291 ≠ the master
/// cycle (60C2h = 2 ms) and SM-Sync (no DC) give 2 at once.
#[test]
fn e121_e122_e123_a287_failures_through_the_master() {
    let sim = line();
    let results = dc_op(
        &sim,
        SYNC0_NS,
        async |_| {},
        150,
        async |md, group| {
            let offsets = |s: &mut Simulation, rx: u32, tx: u32| {
                for d in s.drives_mut() {
                    d.drive.set_step_offsets(rx, tx);
                }
            };
            let runtime = a287_measurement(md, group, &sim, |_, s| offsets(s, 0, 995_000)).await;
            let jitter = a287_measurement(md, group, &sim, |k, s| {
                let j = if k % 2 == 0 { 0 } else { 30_000 };
                offsets(s, j, 960_000 + j);
            })
            .await;
            let master = a287_measurement(md, group, &sim, |k, s| {
                if k == 0 {
                    s.set_frame_jitter(nanos::Nanos::from_ns(20_000), 0xE122);
                }
                offsets(s, 0, 985_000);
            })
            .await;
            sim.borrow_mut().set_frame_jitter(nanos::Nanos::from_ns(0), 0);
            // A291 ≠ the master cycle: 60C2h = 2 ms is copied into A291
            let sd = group.subdevice(md, 0).expect("drive");
            sd.sdo_write(0x60C2, 1, 2u8).await.expect("60C2h:01");
            sd.sdo_write(0x60C2, 2, -3i8).await.expect("60C2h:02");
            dc_cycles(md, group, &sim, 3, |_, _, _| {}).await;
            let a291 = a287_measurement(md, group, &sim, |_, _| {}).await;
            [runtime, jitter, master, a291]
        },
    );
    println!(
        "A287 (result, min, max): runtime {:?}, drive jitter {:?}, frame jitter {:?}, A291 {:?}",
        results[0], results[1], results[2], results[3]
    );
    let a292 = i64::from(A292_US);
    for (r, want) in results.iter().zip([5, 4, 3, 2]) {
        assert_eq!(*r, (want, a292, a292), "result {want}: min = max = A292");
    }

    // SM-Sync (no DC): not executable
    let sim = RefCell::new(Simulation::new(1));
    let result: u8 = run_in_process(&sim, async |md, clock| {
        let group = init(md, clock).await.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).expect("drive");
        sd.sdo_write(A287, 1, 1u8).await.expect("A287[0]");
        sd.sdo_read(A287, 3).await.expect("A287[2]")
    });
    assert_eq!(result, 2, "E-121: DC not used");
}

/// Position actual value 6064h of axis A: the drive's object and its bytes in
/// the TxPDO image the drive's Tx step wrote (what the next frame carries).
fn actual_and_txpdo(d: &mut hil_sim::sim::SimDrive) -> (i64, i64) {
    let obj = d.drive.objects().get(0x6064, 0).expect("6064h");
    let at = txpdo_6064_at(d);
    let img = d.drive.slave_mut().inputs_mut();
    let tx = i32::from_le_bytes(img[at..at + 4].try_into().unwrap());
    (obj, i64::from(tx))
}

/// The byte offset of 6064h (axis A) in the drive's TxPDO image.
fn txpdo_6064_at(d: &hil_sim::sim::SimDrive) -> usize {
    let e = d
        .drive
        .pdo_image()
        .tx()
        .entries()
        .iter()
        .find(|e| e.index == 0x6064)
        .expect("6064h mapped");
    usize::from(e.bit_offset / 8)
}

/// E-111 (spec §11.5): the motor of axis A moves by a new position every
/// cycle. With A149 = 0 (Rx → app → Tx) the TxPDO written by a cycle carries
/// the actual position the application computed in that same cycle; with
/// A149 = 1 (Rx → Tx → app) it carries the previous cycle's.
#[test]
fn e111_a149_orders_rx_app_tx() {
    for a149 in [0u8, 1] {
        let sim = line();
        let pre_op = async |sd: &Sd<'_>| {
            sd.sdo_write(A149, 0, a149).await.expect("A149");
        };
        let (same, differ, master_lag) = dc_op(&sim, SYNC0_NS, pre_op, 150, async |md, group| {
            let (mut same, mut differ) = (0, 0);
            let mut images = Vec::new();
            let mut master = Vec::new();
            for i in 0..40i64 {
                sim.borrow_mut().drives_mut()[0].motors[0].set_position_inc(100_000 * (i + 1));
                dc_cycles(md, group, &sim, 1, |_, _, _| {}).await;
                let (obj, tx) = actual_and_txpdo(&mut sim.borrow_mut().drives_mut()[0]);
                if i >= 5 {
                    if obj == tx {
                        same += 1;
                    } else {
                        differ += 1;
                    }
                }
                images.push(tx);
                let sd = group.subdevice(md, 0).expect("drive");
                let inputs = sd.inputs_raw();
                let at = txpdo_6064_at(&sim.borrow().drives()[0]);
                master.push(i64::from(i32::from_le_bytes(
                    inputs[at..at + 4].try_into().unwrap(),
                )));
            }
            // the frame after a probe carries the image seen at the probe
            let lag = (0..3usize).find(|&l| (10..39).all(|i| master[i + l] == images[i]));
            (same, differ, lag)
        });
        println!(
            "A149 = {a149}: TxPDO = this cycle's 6064h in {same} cycles, another in {differ}; \
             master sees the image {master_lag:?} frame(s) later"
        );
        if a149 == 0 {
            assert_eq!(differ, 0, "A149 = 0: Tx after the application");
        } else {
            assert_eq!(same, 0, "A149 = 1: Tx before the application");
        }
        assert!(master_lag.is_some(), "the image written by Tx goes on the bus");
    }
}

/// E-112 (spec §11.3, §11.4): SYNC0 = 2 ms with A150 = 1 ms (k = 2): P→S
/// accepted, the PLL locks, two control cycles per SYNC0 of which only one
/// (index 0, at SYNC0 − A292) is aligned and runs Rx/Tx.
#[test]
fn e112_sync0_twice_a150() {
    const SYNC0_2MS: u64 = 2_000_000;
    let sim = line();
    let pre_op = async |sd: &Sd<'_>| {
        sd.sdo_write(A150, 0, 1000u16).await.expect("A150");
    };
    let a296 = dc_op(&sim, SYNC0_2MS, pre_op, 200, async |md, group| {
        let sd = group.subdevice(md, 0).expect("drive");
        let v: u32 = sd.sdo_read(A296, 0).await.expect("A296");
        v
    });
    assert_eq!(a296, 2000, "A296: the 2 ms SYNC0 cycle");
    let s = sim.borrow();
    for (i, d) in s.drives().iter().enumerate() {
        let pll = d.drive.pll().expect("PLL");
        assert_eq!(pll.k(), 2, "drive {i}: k = 2");
        assert!(pll.is_locked(), "drive {i} locked");
        assert_eq!(d.drive.slave().state(), esc::AlState::Op);
        let log: Vec<_> = d.cycle_log.iter().filter(|c| c.locked).collect();
        assert!(log.len() >= 100, "drive {i}: {} locked cycles", log.len());
        for w in log.windows(2) {
            let dt = w[1].system_ns - w[0].system_ns;
            assert!(dt.abs_diff(1_000_000) <= 1_000, "drive {i}: cycle {dt} ns");
            assert_ne!(w[0].index, w[1].index, "indices alternate");
        }
        for c in &log {
            assert_eq!((c.rx, c.tx), (c.index == 0, c.index == 0), "Rx/Tx only aligned");
            if c.index == 0 {
                let target = -i64::from(A292_US) * 1000;
                let p = SYNC0_2MS as i64;
                let e = (c.system_ns as i64 - target).rem_euclid(p);
                let e = if e >= p / 2 { e - p } else { e };
                assert!(e.abs() <= 1_000, "drive {i}: aligned at SYNC0 − A292: {e} ns");
            }
        }
        let aligned = log.iter().filter(|c| c.index == 0).count();
        println!(
            "drive {i}: k = 2, {} locked cycles in the log, {aligned} aligned",
            log.len()
        );
    }
}

/// E-109 (spec §11.3): A292 = −1500 µs written by the master with A150 =
/// 1 ms is limited to one drive cycle: the aligned cycle starts just under
/// one A150 after SYNC0 and the PLL locks there.
#[test]
fn e109_a292_beyond_one_a150_is_limited_to_one_cycle_through_the_master() {
    let sim = line();
    let pre_op = async |sd: &Sd<'_>| {
        sd.sdo_write(A292, 0, -1500i32).await.expect("A292");
    };
    dc_op(&sim, SYNC0_NS, pre_op, 400, async |_, _| {});
    let s = sim.borrow();
    for (i, d) in s.drives().iter().enumerate() {
        let pll = d.drive.pll().expect("PLL");
        assert_eq!(
            d.drive.objects().get(A292, 0),
            Ok(-1500),
            "the object keeps the value"
        );
        assert_eq!(pll.phase_offset_ns(), -999_999, "drive {i}: limited to one A150");
        assert!(pll.is_locked(), "drive {i} locked");
        let target = 999_999i64;
        let p = SYNC0_NS as i64;
        let errors: Vec<i64> = d
            .cycle_log
            .iter()
            .filter(|c| c.locked)
            .map(|c| {
                let e = (c.system_ns as i64 - target).rem_euclid(p);
                if e >= p / 2 {
                    e - p
                } else {
                    e
                }
            })
            .collect();
        let worst = errors.iter().map(|e| e.abs()).max().unwrap_or(i64::MAX);
        println!(
            "drive {i}: A292 −1500 µs → {} ns, worst {worst} ns",
            pll.phase_offset_ns()
        );
        assert!(errors.len() >= 100 && worst <= 1_000, "drive {i}: {worst} ns");
    }
}
