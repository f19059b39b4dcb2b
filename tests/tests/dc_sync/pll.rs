//! The PLL on drifting drives: lock to SYNC0 − A292, frame jitter, loss of SYNC0, late frames,
//! a SYNC0 cycle it cannot run, and A298's status bits (E-107, E-109, E-113..E-119).

use super::*;

/// What to do to the line during the DC cycles.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Inject {
    Nothing,
    /// Deactivate SYNC0 (0x0981 = 0) on both drives before this cycle.
    StopSync0(usize),
    /// Send this cycle's frame 200 µs late (100 µs after SYNC0).
    LateFrame(usize),
}

/// Per-drive snapshot taken through the bus (SDO) after the cycles.
#[derive(Debug, Clone, Copy)]
struct Seen {
    a298: u16,
    a261_late: u32,
    a296_us: u32,
    /// 1C32h:0B / 1C33h:0B SM-event missed counters, A264[7] (their mirror).
    sm_missed: [u16; 3],
    /// 1C32h:20 sync error, A264[9].
    sync_error: [u8; 2],
}

/// Configures A292 by SDO, DC with SYNC0 every [`SYNC0_NS`], requests OP and
/// runs `cycles` `tx_rx_dc` cycles; calls `probe` with the cycle number and
/// the simulation after each cycle; reads A298, A261[2], A296 by SDO at the end.
fn run(
    sim: &RefCell<Simulation>,
    cycles: usize,
    inject: Inject,
    mut probe: impl FnMut(usize, &Simulation),
) -> [Seen; 2] {
    run_in_process(sim, async |md, clock| {
        let group = dc_requested_op_after(md, clock, SYNC0_NS, async |sd| {
            sd.sdo_write(A292, 0, A292_US).await.expect("A292");
        })
        .await;
        let mut op = false;
        for i in 0..cycles {
            if inject == Inject::StopSync0(i) {
                for sd in group.iter(md) {
                    sd.register_write(esc::regs::dc::ACTIVATION, 0u8)
                        .await
                        .expect("0x0981");
                }
            }
            let r = group.tx_rx_dc(md).await.expect("DC cycle");
            op |= r.all_op();
            probe(i, &sim.borrow());
            let mut wait = r.extra.next_cycle_wait.as_nanos() as u64;
            if inject == Inject::LateFrame(i + 1) {
                wait += 2 * FRAME_LEAD_NS;
            }
            let mut s = sim.borrow_mut();
            let t = s.now().as_ns() + wait;
            s.advance_to(nanos::Nanos::from_ns(t));
        }
        assert!(op, "the group reached OP");
        let mut seen = [Seen {
            a298: 0,
            a261_late: 0,
            a296_us: 0,
            sm_missed: [0; 3],
            sync_error: [0; 2],
        }; 2];
        for (i, s) in seen.iter_mut().enumerate() {
            let sd = group.subdevice(md, i).expect("drive");
            s.a298 = sd.sdo_read(A298, 0).await.expect("A298");
            s.a261_late = sd.sdo_read(A261, 3).await.expect("A261[2]");
            s.a296_us = sd.sdo_read(A296, 0).await.expect("A296");
            s.sm_missed = [
                sd.sdo_read(0x1C32, 0x0B).await.expect("1C32h:0B"),
                sd.sdo_read(0x1C33, 0x0B).await.expect("1C33h:0B"),
                sd.sdo_read(A264, 8).await.expect("A264[7]"),
            ];
            s.sync_error = [
                sd.sdo_read(0x1C32, 0x20).await.expect("1C32h:20"),
                sd.sdo_read(A264, 10).await.expect("A264[9]"),
            ];
        }
        seen
    })
}

/// Phase error of each aligned, locked cycle start in DC system time against
/// SYNC0 − A292 (SYNC0 on the system-time grid of [`SYNC0_NS`]), ns.
fn phase_errors(sim: &Simulation, drive: usize) -> Vec<i64> {
    let target = -i64::from(A292_US) * 1000;
    let p = SYNC0_NS as i64;
    sim.drives()[drive]
        .cycle_log
        .iter()
        .filter(|c| c.index == 0 && c.locked)
        .map(|c| {
            let e = (c.system_ns as i64 - target).rem_euclid(p);
            if e >= p / 2 {
                e - p
            } else {
                e
            }
        })
        .collect()
}

#[test]
fn e107_e109_e114_pll_locks_control_cycle_to_sync0_minus_a292_on_drifting_drives() {
    let sim = line();
    // simulation time of the first SYNC0 and of the first cycle with both drives locked
    let (mut first_sync0, mut all_locked) = (None, None);
    let seen = run(&sim, 400, Inject::Nothing, |_, s| {
        let d = &s.drives()[0];
        if first_sync0.is_none() {
            first_sync0 = d.sync0_log.front().map(|p| p.now.as_ns());
        }
        let locked = s
            .drives()
            .iter()
            .all(|d| d.drive.pll().is_some_and(|p| p.is_locked()));
        if all_locked.is_none() && locked {
            all_locked = Some(s.now().as_ns());
        }
    });
    let lock_ms = all_locked.zip(first_sync0).map(|(l, f)| (l - f) as f64 / 1e6);
    println!("both drives phase locked {lock_ms:?} ms after the first SYNC0");
    assert!(lock_ms.is_some_and(|t| t <= 100.0), "lock within 100 ms");
    let s = sim.borrow();
    for (i, seen) in seen.iter().enumerate() {
        let d = &s.drives()[i];
        let pll = d.drive.pll().expect("PLL running");
        let errors = phase_errors(&s, i);
        let worst = errors.iter().map(|e| e.abs()).max().unwrap_or(i64::MAX);
        let mean = errors.iter().sum::<i64>() as f64 / errors.len().max(1) as f64;
        let first_lock = d.cycle_log.iter().find(|c| c.locked).map(|c| c.now.as_ns());
        println!(
            "drive {i} ({:+} ppm): A298 {:#06x} (SDO), A296 {} µs, A261 {:?}, PLL phase error {:?} ns, \
             {} locked aligned cycles in the log: mean {mean:.1} ns, worst |error| {worst} ns; first locked \
             cycle in the log at {:?} ns; late frames {}",
            DRIFTS[i],
            seen.a298,
            seen.a296_us,
            pll.diagnostics().elements(),
            pll.phase_error_ns(),
            errors.len(),
            first_lock,
            seen.a261_late,
        );
        assert!(pll.is_locked(), "drive {i} locked");
        let st = PllStatus(seen.a298);
        assert!(
            st.contains(PllStatus::PHASE_LOCKED | PllStatus::FREQUENCY_LOCKED | PllStatus::SYNC0_PRESENT),
            "drive {i}: A298 {:#06x}",
            seen.a298
        );
        assert_eq!(seen.a298 & PllStatus::DEACTIVATED, 0);
        assert_eq!(
            pll.phase_offset_ns(),
            i64::from(A292_US) * 1000,
            "A292 from the SDO"
        );
        assert!(
            errors.len() >= 100,
            "drive {i}: {} locked aligned cycles",
            errors.len()
        );
        assert!(
            worst <= 1_000,
            "drive {i}: cycle start within ±1 µs of SYNC0 − A292: {worst} ns"
        );
        assert_eq!(seen.a296_us, 1000, "A296: the measured SYNC0 cycle, µs");
        // frames 100 µs before SYNC0: A261[1] ≈ +100 µs (data before SYNC0)
        let data_us = pll.diagnostics().data_to_sync0_us;
        assert!((80..=100).contains(&data_us), "drive {i}: A261[1] = {data_us} µs");
    }
    // every cycle (k = 1) is an aligned one, 1 ms apart in system time
    for d in s.drives() {
        for w in d.cycle_log.iter().collect::<Vec<_>>().windows(2) {
            let dt = w[1].system_ns - w[0].system_ns;
            assert!(dt.abs_diff(SYNC0_NS) <= 1_000, "cycle length {dt} ns");
        }
    }
}

#[test]
fn e113_pll_stays_locked_with_5us_frame_jitter() {
    let sim = line();
    sim.borrow_mut()
        .set_frame_jitter(nanos::Nanos::from_ns(5_000), 0xE113);
    run(&sim, 400, Inject::Nothing, |_, _| {});
    let s = sim.borrow();
    for i in 0..2 {
        let worst = phase_errors(&s, i)
            .iter()
            .map(|e| e.abs())
            .max()
            .unwrap_or(i64::MAX);
        println!("drive {i} with ±5 µs frame jitter: worst |phase error| {worst} ns");
        assert!(s.drives()[i].drive.pll().is_some_and(|p| p.is_locked()));
        assert!(worst <= 1_000, "drive {i}: {worst} ns");
    }
}

#[test]
fn e114_e119_loss_of_sync0_loses_the_lock_and_reports_a_pll_fault() {
    let sim = line();
    let mut locked_before = [false; 2];
    let seen = run(&sim, 330, Inject::StopSync0(300), |i, s| {
        if i != 299 {
            return;
        }
        for (i, d) in s.drives().iter().enumerate() {
            locked_before[i] = d.drive.pll().is_some_and(|p| p.is_locked());
        }
    });
    let s = sim.borrow();
    for (i, seen) in seen.iter().enumerate() {
        let d = &s.drives()[i];
        let pll = d.drive.pll().expect("PLL kept (hold-over)");
        println!(
            "drive {i}: locked before {}, after: A298 {:#06x}, fault {:?} (AL {:#06x})",
            locked_before[i],
            seen.a298,
            pll.fault(),
            pll.fault().map_or(0, |f| f.al_status_code())
        );
        assert!(locked_before[i], "drive {i} locked before SYNC0 stopped");
        assert!(!pll.is_locked());
        assert_eq!(pll.fault(), Some(SyncFault::Sync0Timeout));
        assert_eq!(seen.sync_error, [1, 1], "E-119: 1C32h:20 and A264[9]");
        let st = PllStatus(seen.a298);
        assert!(
            st.contains(PllStatus::ERROR),
            "A298 error bit: {:#06x}",
            seen.a298
        );
        assert_eq!(
            seen.a298 & (PllStatus::PHASE_LOCKED | PllStatus::SYNC0_PRESENT),
            0
        );
        // the control cycle keeps running at the last frequency
        let last: Vec<_> = d.cycle_log.iter().rev().take(20).collect();
        for w in last.windows(2) {
            let dt = w[0].system_ns - w[1].system_ns;
            assert!(dt.abs_diff(SYNC0_NS) <= 1_000, "hold-over cycle {dt} ns");
        }
    }
}

#[test]
fn e117_e118_e119_a_late_frame_counts_in_a261_and_1c32h() {
    let sim = line();
    let mut before = [(0u32, None); 2];
    let seen = run(&sim, 330, Inject::LateFrame(300), |i, s| {
        if i != 299 {
            return;
        }
        for (i, d) in s.drives().iter().enumerate() {
            let pll = d.drive.pll().expect("PLL");
            before[i] = (pll.diagnostics().late_frames, pll.fault());
        }
    });
    let s = sim.borrow();
    for (i, seen) in seen.iter().enumerate() {
        let pll = s.drives()[i].drive.pll().expect("PLL");
        println!(
            "drive {i}: A261[2] {} before, {} after one late frame (SDO); fault {:?}",
            before[i].0,
            seen.a261_late,
            pll.fault()
        );
        assert_eq!(seen.a261_late, before[i].0 + 1, "drive {i}: one late frame");
        // E-119: 1C32h/1C33h:0B count it too, A264[7] mirrors 1C32h:0B
        let late = seen.a261_late as u16;
        assert_eq!(seen.sm_missed, [late; 3], "drive {i}: SM-event missed");
        assert_eq!(seen.sync_error, [0, 0], "drive {i}: no sync error");
        assert!(pll.is_locked(), "SYNC0 is not moved by a frame");
        assert_eq!(pll.fault(), before[i].1, "one late frame is no sync I/O fault");
    }
}

#[test]
fn e116_a_sync0_cycle_the_pll_cannot_run_is_refused() {
    // the PLL's configuration check (the P→S check is the slave stack's)
    let bad = dcsync::Config::new(1_100_000, 1_000_000, drive_ecat::runtime::TIMER_HZ);
    assert!(dcsync::Pll::new(bad).is_err());
    let sim = line();
    let a261_0: u8 = run_in_process(&sim, async |md, clock| {
        let dc = DcConfiguration {
            start_delay: Duration::from_millis(5),
            sync0_period: Duration::from_nanos(1_100_000),
            sync0_shift: Duration::ZERO,
        };
        let group = into_dc_sync0(md, init(md, clock).await, dc, async |_| {})
            .await
            .expect("SYNC0, PRE-OP with PDI, DC configuration");
        {
            let mut s = sim.borrow_mut();
            let t = s.now().as_ns() + 20_000_000;
            s.advance_to(nanos::Nanos::from_ns(t));
        }
        let sd = group.subdevice(md, 0).expect("drive");
        let a298: u16 = sd.sdo_read(A298, 0).await.expect("A298");
        assert_ne!(a298 & PllStatus::ERROR, 0, "A298 {a298:#06x}");
        sd.sdo_read(A261, 1).await.expect("A261[0]")
    });
    let s = sim.borrow();
    let d = &s.drives()[0];
    assert!(d.sync0_log.len() > 5, "SYNC0 runs");
    assert!(d.drive.pll().is_none(), "no PLL for a 1.1 ms SYNC0 cycle");
    println!("1.1 ms SYNC0: {:?}, A261[0] = {a261_0}", d.drive.sync_error());
    assert_eq!(
        d.drive.sync_error().map(|e| e.diag_code()),
        Some(dcsync::DiagCode::CycleNotOnGrid)
    );
    assert_eq!(a261_0, 3, "A261[0] = 3: not a multiple of 250 µs");
    assert!(d.cycle_log.is_empty(), "the control cycle stays free-running");
}

/// E-115 (spec §11.6) through the master: bits 0/1 when the PLL uses at
/// least half of its ±500 ppm range (drive 0 is the DC reference at 0 ppm;
/// drive 1 at +300 ppm lengthens its cycle, drive 2 at −300 ppm shortens
/// it), bit 2 while it stretches cycles to align, bit 4 when A296 > A291
/// (60C2h = 500 µs is copied into A291), bit 5 when A290 ≠ 1.
#[test]
fn e115_a298_bits_through_the_master() {
    let mut line3 = Simulation::new(3);
    for (d, drift) in line3.drives_mut().iter_mut().zip([0.0, 300.0, -300.0]) {
        d.set_clock(drift, 1_234_567);
    }
    let sim = RefCell::new(line3);
    let mut ever = [0u16; 3];
    run(&sim, 600, Inject::Nothing, |_, s| {
        for (i, d) in s.drives().iter().enumerate() {
            ever[i] |= d.drive.objects().get(A298, 0).unwrap() as u16;
        }
    });
    let s = sim.borrow();
    let a298: Vec<u16> = s
        .drives()
        .iter()
        .map(|d| d.drive.objects().get(A298, 0).unwrap() as u16)
        .collect();
    println!("A298 at 0 / +300 / −300 ppm: {a298:04x?}, seen {ever:04x?}");
    let locked = PllStatus::PHASE_LOCKED | PllStatus::SYNC0_PRESENT;
    let engaged = PllStatus::ENGAGED_SLOWER | PllStatus::ENGAGED_FASTER;
    assert!(PllStatus(a298[0]).contains(locked));
    assert_eq!(a298[0] & engaged, 0, "the reference sees no drift");
    assert!(PllStatus(a298[1]).contains(locked | PllStatus::ENGAGED_SLOWER));
    assert!(PllStatus(a298[2]).contains(locked | PllStatus::ENGAGED_FASTER));
    for (i, a) in a298.iter().enumerate() {
        let not = PllStatus::MAX_RANGE | PllStatus::SYNC_CYCLE_TOO_LONG | PllStatus::DEACTIVATED;
        assert_eq!(a & not, 0, "drive {i}: {a:#06x}");
        assert_ne!(
            ever[i] & PllStatus::CYCLE_EXTENDED,
            0,
            "drive {i}: stretched while aligning"
        );
    }
    drop(s);

    // 60C2h = 5 × 10⁻⁴ s: A291 = 500 µs < A296 = 1000 µs; then A290 = 0
    let sim = line();
    let pre_op = async |sd: &Sd<'_>| {
        sd.sdo_write(0x60C2, 1, 5u8).await.expect("60C2h:01");
        sd.sdo_write(0x60C2, 2, -4i8).await.expect("60C2h:02");
    };
    let (bit4, bit5): (u16, u16) = dc_op(&sim, SYNC0_NS, pre_op, 200, async |md, group| {
        let sd = group.subdevice(md, 0).expect("drive");
        let a291: u32 = sd
            .sdo_read(drive_ecat::parameter_index(0, 291), 0)
            .await
            .expect("A291");
        assert_eq!(a291, 500, "60C2h copied into A291");
        let bit4 = sd.sdo_read(A298, 0).await.expect("A298");
        sd.sdo_write(drive_ecat::parameter_index(0, 290), 0, 0u8)
            .await
            .expect("A290");
        dc_cycles(md, group, &sim, 5, |_, _, _| {}).await;
        (bit4, sd.sdo_read(A298, 0).await.expect("A298"))
    });
    println!("A298 with A291 = 500 µs: {bit4:#06x}; then A290 = 0: {bit5:#06x}");
    assert!(PllStatus(bit4).contains(PllStatus::SYNC_CYCLE_TOO_LONG | PllStatus::PHASE_LOCKED));
    assert_eq!(bit4 & PllStatus::DEACTIVATED, 0);
    assert!(PllStatus(bit5).contains(PllStatus::DEACTIVATED));
}
