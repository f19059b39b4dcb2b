//! E-118 through `hil-sim serve` (issue 14): a DC-aligned master over raw
//! Ethernet keeps the drives in Op while `serve` holds every frame up to 2 ms
//! before processing it. `serve` gives each frame the kernel's receive time,
//! so the drive sees the frame 300 µs before SYNC0, as the master sent it;
//! processed at the time `serve` got to it, frames would look up to 2 ms late,
//! the drive would count them late (A261\[2\], 1C32h:0B) and after five in a
//! row leave Op with AL 0033h.
//!
//! The master is ethercrab's std transport on the other veth end: ethercrab
//! brings the line up (DC start-up, SYNC0 at 1 ms), then a cyclic sender of
//! its own sends one LRW frame per cycle at a fixed instant 300 µs before
//! SYNC0 on the reference clock (with a read of the reference's DC time, so
//! the test can print when the frames reached the drive), without waiting
//! for the previous answer (an answer may take 2 ms), and a monitor reads
//! every drive's AL status and AL status code every 100 ms for 60 s. A
//! sniffer on the master's veth end pairs each cycle's DC-time read as it
//! left (kernel timestamp) with the DC time the drive answered: so the test
//! checks `serve`'s part on its own (half the frames within 100 µs of
//! their departure in the drive's time, and 99 % unless the machine was so
//! busy that the master skipped 5 % of its periods: then the kernel's
//! softirq is held up as well and the 99 % part is reported inconclusive)
//! and tells a late master from a late `serve`. Should the drives leave Op while the master itself sent five
//! frames in a row late (a host too busy for it), the Op part is reported as
//! inconclusive instead of failed. Needs root; skipped otherwise.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::Netns;
use ethercrab::subdevice_group::DcConfiguration;
use ethercrab::{Command, DcSync, MainDevice, MainDeviceConfig, PduStorage, Timeouts};
use futures_lite::future::block_on;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// SYNC0 period and master cycle, ns.
const CYCLE_NS: u64 = 1_000_000;
/// The master's frames leave this long before SYNC0, ns.
const BEFORE_SYNC0_NS: u64 = 300_000;
/// How long the drives must stay in Op.
const HOLD: Duration = Duration::from_secs(60);
/// `serve` holds each frame up to this long.
const DELAY_US: &str = "2000";
/// Drives on the line (the first is the DC reference).
const DRIVES: usize = 2;
/// Threads sending cycles (cycle k by thread k mod SENDERS): an answer may
/// take longer than a cycle, the next cycle must not wait for it.
const SENDERS: u64 = 8;
/// A cycle whose sender wakes later than this is skipped, not sent late, ns.
const MAX_SEND_LATE_NS: u64 = 50_000;

/// SCHED_FIFO priority of the master's threads: above a simulator another
/// test on a shared machine may run, so the master's own cycle stays exact.
const MASTER_PRIORITY: i32 = 80;

/// The most `serve` may move half (99 % on a machine not starved) of the
/// frames in the drive's time against their departure, ns (the drive tolerates 300 µs late; holding frames 2 ms
/// in serve without the receive timestamp moves most by hundreds of µs; the
/// rest of the 1 % is left to a busy host: a virtual CPU taken away between
/// the two timestamps moves a frame too).
const MAX_MISPLACED_NS: i128 = 100_000;

/// AL status register, AL status code register, DC system time.
const AL_STATUS: u16 = 0x0130;
const AL_STATUS_CODE: u16 = 0x0134;
const DC_SYSTEM_TIME: u16 = 0x0910;
/// First FMMU's registers (16 bytes each).
const FMMU0: u16 = 0x0600;

/// `CLOCK_MONOTONIC`, ns (ethercrab's `ethercat_now` and `Instant` read it).
fn mono_ns() -> u64 {
    hil_sim::raw::monotonic().as_ns()
}

/// Sleeps until monotonic `t_ns` (the last 60 µs spinning; a SCHED_FIFO thread has no timer slack).
fn sleep_until(t_ns: u64) {
    let now = mono_ns();
    if t_ns > now + 60_000 {
        std::thread::sleep(Duration::from_nanos(t_ns - now - 60_000));
    }
    while mono_ns() < t_ns {
        std::hint::spin_loop();
    }
}

/// SCHED_FIFO for the calling thread, as a real-time master would run (best effort).
fn fifo(priority: i32) {
    let p = libc::sched_param {
        sched_priority: priority,
    };
    // SAFETY: p is a valid sched_param; 0 is the calling thread.
    #[allow(unsafe_code)]
    unsafe {
        libc::sched_setscheduler(0, libc::SCHED_FIFO, &p);
    }
}

/// The logical span of the process image: the union of every drive's
/// active FMMUs (start address, length).
async fn process_image(md: &MainDevice<'_>, addrs: &[u16]) -> (u32, u16) {
    let (mut lo, mut hi) = (u32::MAX, 0u32);
    for &a in addrs {
        for k in 0..3u16 {
            let f: [u8; 16] = Command::fprd(a, FMMU0 + 16 * k).receive(md).await.expect("FMMU");
            if f[12] & 1 == 0 {
                continue;
            }
            let start = u32::from_le_bytes([f[0], f[1], f[2], f[3]]);
            let len = u32::from(u16::from_le_bytes([f[4], f[5]]));
            lo = lo.min(start);
            hi = hi.max(start + len);
        }
    }
    assert!(lo < hi, "the drives have active FMMUs");
    (lo, u16::try_from(hi - lo).unwrap())
}

/// The reference clock's system time minus this host's monotonic clock, ns:
/// the smallest difference over `n` reads (the read that left soonest).
async fn dc_offset(md: &MainDevice<'_>, reference: u16, n: usize) -> i128 {
    let mut best = i128::MAX;
    for _ in 0..n {
        let t0 = mono_ns();
        let dc: u64 = Command::frmw(reference, DC_SYSTEM_TIME)
            .ignore_wkc()
            .receive(md)
            .await
            .expect("DC time");
        best = best.min(i128::from(dc) - i128::from(t0));
    }
    best
}

/// DC time `dc` relative to the nearest SYNC0 edge (negative: before it), ns.
fn rel_sync0(dc: u64, sync0_start: u64) -> i64 {
    let phase = (dc.wrapping_sub(sync0_start) % CYCLE_NS) as i64;
    let cycle = CYCLE_NS as i64;
    if phase >= cycle / 2 {
        phase - cycle
    } else {
        phase
    }
}

/// Late by the drive's rule (E-118): after SYNC0, or more than half a cycle before it.
fn is_late(rel_ns: i64) -> bool {
    rel_ns >= 0 || rel_ns < -((CYCLE_NS / 2) as i64)
}

/// One cycle's DC-time read as the wire showed it: when the master's frame
/// left (kernel timestamp of the outgoing frame, monotonic ns) and the
/// reference's DC time in the answer (when the drive processed the frame).
#[derive(Clone, Copy)]
struct WireSample {
    tx_ns: u64,
    dc_ns: u64,
}

/// The index and data of an FPRD of [`DC_SYSTEM_TIME`] at `reference` (an
/// EtherCAT frame whose first datagram it is).
fn dc_read(f: &[u8], reference: u16) -> Option<(usize, u64)> {
    if f.get(12..14)? != hil_sim::raw::ETHERTYPE_ECAT.to_be_bytes() {
        return None;
    }
    // Ethernet 14, EtherCAT header 2; datagram: cmd, idx, ADP, ADO, length, IRQ, data, WKC
    let d = f.get(16..)?;
    let word = |k: usize| Some(u16::from_le_bytes([*d.get(k)?, *d.get(k + 1)?]));
    let fprd = *d.first()? == 0x04;
    if !fprd || word(2)? != reference || word(4)? != DC_SYSTEM_TIME || word(6)? & 0x7FF != 8 {
        return None;
    }
    Some((
        usize::from(*d.get(1)?),
        u64::from_le_bytes(d.get(10..18)?.try_into().ok()?),
    ))
}

/// Watches the master's veth end until `stop`: every DC-time read that left
/// and its answer.
fn sniff(iface: &str, reference: u16, stop: &AtomicBool) -> Vec<WireSample> {
    let sock = hil_sim::raw::RawSocket::open_sniffer(iface).expect("sniffer on the veth end");
    let mut left = [None; 256];
    let mut out = Vec::new();
    let mut buf = [0u8; 2048];
    while !stop.load(Ordering::Relaxed) {
        if !sock.wait(Duration::from_millis(10)).expect("wait") {
            continue;
        }
        while let Some(rx) = sock.try_recv(&mut buf).expect("sniff") {
            let (Some(t), Some((idx, dc))) =
                (rx.rx.map(nanos::Nanos::as_ns), dc_read(&buf[..rx.len], reference))
            else {
                continue;
            };
            if rx.outgoing {
                left[idx] = Some(t);
            } else if let Some(tx_ns) = left[idx].take() {
                out.push(WireSample { tx_ns, dc_ns: dc });
            }
        }
    }
    out
}

/// What the wire showed, ns: how far the drive's view of the frames lay
/// behind their departure (beyond the 0.1 % quantile of that lag): p50,
/// p90, p99, p99.9 and worst; the frames
/// late for the drive and their longest run, as it saw them and as the master
/// sent them; the range of the drive's arrival times before SYNC0.
#[derive(Debug)]
struct WireFigures {
    misplaced_q_ns: [i128; 4],
    worst_misplaced_ns: i128,
    late_seen: usize,
    run_seen: usize,
    late_sent: usize,
    run_sent: usize,
    closest_ns: i64,
    farthest_ns: i64,
}

fn wire_figures(samples: &[WireSample], sync0_start: u64) -> WireFigures {
    // DC time minus departure: a constant (the clocks' offset) plus how late
    // the drive saw the frame; the constant is the 0.1 % quantile (robust
    // against a departure stamp taken late, which makes a lag look small)
    let lag = |s: &WireSample| i128::from(s.dc_ns) - i128::from(s.tx_ns);
    let mut lags: Vec<i128> = samples.iter().map(lag).collect();
    lags.sort_unstable();
    let q = |p: f64| {
        lags.get(((lags.len().max(1) - 1) as f64 * p) as usize)
            .copied()
            .unwrap_or(0)
    };
    let base = q(0.001);
    let misplaced_q_ns = [q(0.5) - base, q(0.9) - base, q(0.99) - base, q(0.999) - base];
    let worst_misplaced_ns = lags.last().copied().unwrap_or(0) - base;
    let runs = |rel: &dyn Fn(&WireSample) -> i64| {
        let (mut late, mut run, mut worst) = (0, 0, 0);
        for s in samples {
            if is_late(rel(s)) {
                late += 1;
                run += 1;
                worst = worst.max(run);
            } else {
                run = 0;
            }
        }
        (late, worst)
    };
    let seen = |s: &WireSample| rel_sync0(s.dc_ns, sync0_start);
    // departure on the DC time base, with the smallest lag
    let sent = |s: &WireSample| {
        rel_sync0(
            u64::try_from(i128::from(s.tx_ns) + base).unwrap_or(0),
            sync0_start,
        )
    };
    let (late_seen, run_seen) = runs(&seen);
    let (late_sent, mut run_sent) = runs(&sent);
    // periods in which the master sent no frame at all (its sender woke too
    // late and skipped them) count as late for the drive's rule as well:
    // the longest run of periods without a frame sent in time
    let departure = |s: &WireSample| i128::from(s.tx_ns) + base;
    let (mut run, mut prev) = (0usize, None::<i128>);
    for s in samples {
        let t = departure(s);
        if let Some(p) = prev {
            let cycle = i128::from(CYCLE_NS);
            let missing = usize::try_from(((t - p) + cycle / 2) / cycle - 1).unwrap_or(0);
            run += missing;
        }
        if is_late(sent(s)) {
            run += 1;
        } else {
            run_sent = run_sent.max(run);
            run = 0;
        }
        run_sent = run_sent.max(run);
        prev = Some(t);
    }
    WireFigures {
        misplaced_q_ns,
        worst_misplaced_ns,
        late_seen,
        run_seen,
        late_sent,
        run_sent,
        closest_ns: -samples.iter().map(seen).max().unwrap_or(0),
        farthest_ns: -samples.iter().map(seen).min().unwrap_or(0),
    }
}

/// What the cyclic sender saw.
#[derive(Default)]
struct CycleStats {
    sent: AtomicU64,
    answered: AtomicU64,
    /// No answer, or a wrong working counter.
    failed: AtomicU64,
    /// Cycles not sent: the sender woke too late ([`MAX_SEND_LATE_NS`]).
    skipped: AtomicU64,
    /// Worst lateness of a send against its instant, ns.
    worst_send_late_ns: AtomicU64,
}

#[test]
fn e118_dc_aligned_master_keeps_op_while_serve_is_delayed_2ms() {
    if !common::is_root() {
        eprintln!("e118 (serve delayed 2 ms): skipped, needs root for network namespaces and raw sockets");
        return;
    }
    let seconds = (HOLD.as_secs() + 60).to_string();
    let drives = DRIVES.to_string();
    let net = Netns::new(
        env!("CARGO_BIN_EXE_hil-sim"),
        'd',
        &[
            "--slaves",
            &drives,
            "--delay-us",
            DELAY_US,
            "--delay-seed",
            "118",
            "--seconds",
            &seconds,
        ],
    );
    let storage: &'static PduStorage<32, { PduStorage::element_size(1100) }> =
        Box::leak(Box::new(PduStorage::new()));
    let (tx, rx, pdu_loop) = storage.try_split().expect("split");
    let task = ethercrab::std::tx_rx_task(&net.host_if, tx, rx).expect("raw socket on the veth end");
    std::thread::spawn(move || {
        // above the senders: a queued frame leaves at once
        fifo(MASTER_PRIORITY + 2);
        futures_lite::future::block_on(task)
    });
    // every answer may come 2 ms late, and the simulator is a debug build
    let timeouts = Timeouts {
        pdu: Duration::from_millis(200),
        eeprom: Duration::from_millis(200),
        state_transition: Duration::from_secs(20),
        mailbox_echo: Duration::from_millis(500),
        mailbox_response: Duration::from_secs(2),
        ..Timeouts::default()
    };
    let config = MainDeviceConfig {
        dc_static_sync_iterations: 1000,
        ..MainDeviceConfig::default()
    };
    let md = MainDevice::new(pdu_loop, timeouts, config);

    // bring-up: DC start-up, SYNC0 every cycle, PRE-OP -> SAFE-OP, OP requested
    let mut group =
        block_on(md.init_single_group::<4, 256>(ethercrab::std::ethercat_now)).expect("init over veth");
    assert_eq!(group.len(), DRIVES);
    for mut sd in group.iter_mut(&md) {
        sd.set_dc_sync(DcSync::Sync0);
    }
    let addrs: Vec<u16> = group.iter(&md).map(|sd| sd.configured_address()).collect();
    let group = block_on(async {
        group
            .into_pre_op_pdi(&md)
            .await
            .expect("PRE-OP with PDI")
            .configure_dc_sync(
                &md,
                DcConfiguration {
                    start_delay: Duration::from_millis(100),
                    sync0_period: Duration::from_nanos(CYCLE_NS),
                    sync0_shift: Duration::from_nanos(CYCLE_NS - BEFORE_SYNC0_NS),
                },
            )
            .await
            .expect("DC configuration")
            .request_into_op(&md)
            .await
            .expect("request OP")
    });
    let (image_start, image_len) = block_on(process_image(&md, &addrs));
    let offset = block_on(dc_offset(&md, addrs[0], 50));
    let sync0_start: u64 = block_on(Command::fprd(addrs[0], 0x0990).receive(&md)).expect("SYNC0 start time");
    let phase_ns = (sync0_start % CYCLE_NS + CYCLE_NS - BEFORE_SYNC0_NS) % CYCLE_NS;
    // the first send instant: monotonic time whose DC time is at `phase_ns` of a cycle
    let now_dc = u64::try_from(i128::from(mono_ns() + 20_000_000) + offset).unwrap();
    let first_dc = (now_dc / CYCLE_NS + 1) * CYCLE_NS + phase_ns;
    let first = u64::try_from(i128::from(first_dc) - offset).unwrap();
    println!(
        "process image {image_len} bytes at {image_start:#x}; DC time - monotonic {offset} ns; \
         frames at DC phase {phase_ns} ns ({BEFORE_SYNC0_NS} ns before SYNC0)"
    );

    let stop = AtomicBool::new(false);
    let stats = CycleStats::default();
    let wkc = u16::try_from(3 * DRIVES).unwrap();
    let (reached_op, samples, bad, late_frames, wire) = std::thread::scope(|s| {
        let sniffer = {
            let (iface, stop, reference) = (net.host_if.as_str(), &stop, addrs[0]);
            s.spawn(move || sniff(iface, reference, stop))
        };
        for j in 0..SENDERS {
            let (md, stop, stats) = (&md, &stop, &stats);
            let reference = addrs[0];
            s.spawn(move || {
                fifo(MASTER_PRIORITY);
                let outputs = vec![0u8; usize::from(image_len)];
                let mut k = j;
                while !stop.load(Ordering::Relaxed) {
                    let t = first + k * CYCLE_NS;
                    k += SENDERS;
                    sleep_until(t);
                    // a master sends on time or not at all
                    let late = mono_ns().saturating_sub(t);
                    stats.worst_send_late_ns.fetch_max(late, Ordering::Relaxed);
                    if late > MAX_SEND_LATE_NS {
                        stats.skipped.fetch_add(1, Ordering::Relaxed);
                        continue;
                    }
                    stats.sent.fetch_add(1, Ordering::Relaxed);
                    // the reference's DC time as the cycle's frames pass it (the
                    // drive's view of when they arrived), then the process data
                    // (the sniffer pairs the DC-time read with its answer)
                    let (_, r) = block_on(futures_lite::future::zip(
                        Command::fprd(reference, DC_SYSTEM_TIME).receive::<u64>(md),
                        Command::lrw(image_start)
                            .with_wkc(wkc)
                            .send_receive_slice(md, outputs.as_slice()),
                    ));
                    match r {
                        Ok(_) => stats.answered.fetch_add(1, Ordering::Relaxed),
                        Err(_) => stats.failed.fetch_add(1, Ordering::Relaxed),
                    };
                }
            });
        }
        // wait for OP, then watch AL status and code for HOLD
        let al = |a: u16| -> (u16, u16) {
            let st: u16 = block_on(Command::fprd(a, AL_STATUS).receive(&md)).unwrap_or(0xFFFF);
            let code: u16 = block_on(Command::fprd(a, AL_STATUS_CODE).receive(&md)).unwrap_or(0xFFFF);
            (st, code)
        };
        let t_op = Instant::now();
        let mut reached_op = false;
        while t_op.elapsed() < Duration::from_secs(20) {
            if addrs.iter().all(|&a| al(a) == (0x08, 0)) {
                reached_op = true;
                break;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        println!("OP after {:.2} s: {reached_op}", t_op.elapsed().as_secs_f64());
        let mut bad = Vec::new();
        let mut samples = 0u32;
        let t_hold = Instant::now();
        while reached_op && t_hold.elapsed() < HOLD && bad.len() < 10 {
            for (i, &a) in addrs.iter().enumerate() {
                let (st, code) = al(a);
                if (st, code) != (0x08, 0) {
                    bad.push((t_hold.elapsed().as_secs_f64(), i, st, code));
                }
            }
            samples += 1;
            std::thread::sleep(Duration::from_millis(100));
        }
        // 1C32h:0B, the late frames each drive counted (E-118, E-119)
        let late: Vec<Option<u16>> = (0..addrs.len())
            .map(|i| {
                let sd = group.subdevice(&md, i).ok()?;
                block_on(sd.sdo_read::<u16>(0x1C32, 0x0B)).ok()
            })
            .collect();
        stop.store(true, Ordering::Relaxed);
        (reached_op, samples, bad, late, sniffer.join().expect("sniffer"))
    });
    let (sent, answered, failed, skipped) = (
        stats.sent.load(Ordering::Relaxed),
        stats.answered.load(Ordering::Relaxed),
        stats.failed.load(Ordering::Relaxed),
        stats.skipped.load(Ordering::Relaxed),
    );
    println!(
        "cycles: {sent} sent, {answered} answered, {failed} without an answer or with a wrong working counter, \
         {skipped} skipped (sender woke late); worst wake-up {:.1} µs after its instant; {samples} AL samples per drive, not Op/0: {bad:?}; \
         late frames counted by the drives (1C32h:0B): {late_frames:?}",
        stats.worst_send_late_ns.load(Ordering::Relaxed) as f64 / 1e3
    );
    let w = wire_figures(&wire, sync0_start);
    println!(
        "on the wire: {} cycles; the drive saw them {:.1}..{:.1} µs before SYNC0, off their departure by \
         p50 {:.1}, p90 {:.1}, p99 {:.1}, p99.9 {:.1}, max {:.1} µs; late by the drive's rule: {} as seen (at most {} in \
         a row), {} as sent by the master (at most {} periods in a row without a frame sent in time)",
        wire.len(),
        w.closest_ns as f64 / 1e3,
        w.farthest_ns as f64 / 1e3,
        w.misplaced_q_ns[0] as f64 / 1e3,
        w.misplaced_q_ns[1] as f64 / 1e3,
        w.misplaced_q_ns[2] as f64 / 1e3,
        w.misplaced_q_ns[3] as f64 / 1e3,
        w.worst_misplaced_ns as f64 / 1e3,
        w.late_seen,
        w.run_seen,
        w.late_sent,
        w.run_sent
    );
    drop(group);
    drop(net);
    // serve's part, whatever the machine does: each frame at its departure
    assert!(
        wire.len() as u64 >= sent * 9 / 10,
        "the sniffer saw most cycles: {} of {sent}",
        wire.len()
    );
    // without the receive timestamp half the frames would move by more than
    // 1 ms (held 0..2 ms): the median within the bound holds on any machine
    assert!(
        w.misplaced_q_ns[0] <= MAX_MISPLACED_NS,
        "serve moved half the frames more than {} µs in the drive's time (p50 {:.1} µs)",
        MAX_MISPLACED_NS / 1000,
        w.misplaced_q_ns[0] as f64 / 1e3
    );
    // 99 %: only on a machine that leaves the processes their CPU (the
    // master's sender skipped under 5 % of its periods for waking late);
    // on one that does not, the kernel's softirq and serve are held up alike
    let starved = skipped * 20 > sent + skipped;
    if starved {
        println!(
            "e118 (serve delayed 2 ms): the 99 % placement is inconclusive, the machine was too busy \
             ({skipped} of {} periods skipped by the master for waking late); p99 {:.1} µs",
            sent + skipped,
            w.misplaced_q_ns[2] as f64 / 1e3
        );
    } else {
        assert!(
            w.misplaced_q_ns[2] <= MAX_MISPLACED_NS,
            "serve moved 1 % of the frames more than {} µs in the drive's time (p99 {:.1} µs)",
            MAX_MISPLACED_NS / 1000,
            w.misplaced_q_ns[2] as f64 / 1e3
        );
    }
    let op_kept = reached_op && bad.is_empty();
    if !op_kept && w.run_sent >= 5 {
        // the master itself sent no frame in time for five periods in a row
        // (late or skipped): the drive rightly leaves Op, whatever serve does
        println!(
            "e118 (serve delayed 2 ms): the Op part is inconclusive, the machine was too busy for the master \
             ({} periods in a row without a frame sent in time); serve's placement of the frames was checked",
            w.run_sent
        );
        return;
    }
    assert!(reached_op, "the drives reached OP with serve delayed");
    assert!(
        bad.is_empty(),
        "left OP or raised an AL status code (s, drive, 0x0130, 0x0134): {bad:?}"
    );
    assert!(
        samples as u64 >= HOLD.as_secs() * 5,
        "watched the whole time: {samples} samples"
    );
}
