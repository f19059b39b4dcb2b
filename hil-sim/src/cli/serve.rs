//! `hil-sim serve`: the simulated line answers EtherCAT frames on a raw
//! Ethernet interface, paced by the wall clock.
//!
//! # Timing
//!
//! Simulated time is `CLOCK_MONOTONIC` since the start. Each received frame
//! carries the kernel's receive timestamp; the simulation runs to that instant
//! ([`Simulation::catch_up`]: SYNC0 edges and control cycles in between one
//! by one, one firmware poll) and only then processes the frame, so the
//! drive sees the frame when it arrived, however long `serve` took to get to it (a wait, a
//! busy machine, `--delay-us`). While no frame waits, the simulation is kept
//! at the wall clock (less [`IDLE_LAG`]) every [`IDLE_WAIT`] (or
//! continuously with `--busy-poll`), so an arriving frame finds little left
//! to simulate and is answered at once. Frames that queued up are processed
//! in order, each at its own receive time; one whose time the simulation has
//! already passed (it arrived while the simulation was being caught up) is
//! processed at once, and counted in the summary when that was more than
//! [`LATE_NOTE`] late.

use super::args::{Fieldbus, Plant, PlantFault, ServeArgs};

/// Seed of the electrical plant's ADC noise under `serve --plant electrical`.
pub(super) const PLANT_SEED: u64 = 0x5E12_0034;
use super::print_new_changes;
use super::serve_stats::{describe, thread_cpu, Answer, Stats};
use hil_sim::electrical::ElectricalAxis;
use hil_sim::plants::PlantDrive;
use hil_sim::raw::{monotonic, RawSocket};
use hil_sim::sim::{SimDrive, Simulation};
use nanos::Nanos;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// Set by SIGINT or SIGTERM: `serve` ends its loop, flushes the recording
/// and prints its summary.
pub(super) static STOP: AtomicBool = AtomicBool::new(false);

extern "C" fn on_stop_signal(_: libc::c_int) {
    STOP.store(true, Ordering::Relaxed);
}

/// Ctrl-C and `kill` end `serve` in order (the recording complete).
pub(super) fn stop_on_signals() {
    let handler = on_stop_signal as extern "C" fn(libc::c_int) as libc::sighandler_t;
    for sig in [libc::SIGINT, libc::SIGTERM] {
        // SAFETY: the handler only stores to an atomic (async-signal-safe).
        #[allow(unsafe_code)]
        unsafe {
            libc::signal(sig, handler);
        }
    }
}

/// Longest sleep on the socket while no frame waits: the simulation is caught
/// up with the wall clock at least this often.
pub const IDLE_WAIT: Duration = Duration::from_micros(100);

/// Between frames the simulation stays this far behind the wall clock: a
/// frame the kernel stamped but had not queued yet when the socket was read
/// (its softirq still to run on a busy machine) is then still in the
/// simulation's future. Costs nothing: an arriving frame catches up anyway.
const IDLE_LAG: Nanos = Nanos::from_us(50);

/// A frame the simulation reaches later than this after its receive time is
/// counted in the summary (less is the wire time of the frame before).
const LATE_NOTE: Nanos = Nanos::from_us(20);

/// How often the pcap recording is flushed (a write error then ends `serve`).
const FLUSH_EVERY: Nanos = Nanos::from_secs(1);

/// `--plant-r`/`--plant-l`/`--plant-offset`: the plant's motor on every
/// electrical axis.
fn set_plant_motor(sim: &mut Simulation, args: &ServeArgs) -> Result<(), String> {
    let Some(apply) = plant_motor(args)? else {
        return Ok(());
    };
    for d in sim.drives_mut() {
        apply_plant_motor(d, &apply);
    }
    Ok(())
}

/// `apply` ([`plant_motor`]'s change) on each electrical axis of `d`.
pub(super) fn apply_plant_motor(d: &mut impl PlantDrive, apply: &impl Fn(&mut ElectricalAxis)) {
    for axis in 0..2 {
        if let Some(el) = d.plants_mut().get_mut(axis) {
            apply(el);
        }
    }
}

/// The motor model of drive `k` (from 0) of either fieldbus as `--plant`
/// and `--pwm-khz` choose it, seeded with [`PLANT_SEED`] + 2k (axis B with
/// one more, so runs are reproducible and axes independent), and
/// `--plant-fault` on its axis A.
pub(super) fn set_up_plant(d: &mut impl PlantDrive, k: u64, args: &ServeArgs) -> Result<(), String> {
    d.plants_mut()
        .set(
            args.plant.into(),
            PLANT_SEED.wrapping_add(2 * k),
            args.pwm_khz.hz(),
        )
        .map_err(|e| format!("the electrical plant's parameters: {e:?}"))?;
    if let Some(f) = args.plant_fault {
        f.apply(
            d.plants_mut()
                .get_mut(0)
                .ok_or("--plant-fault needs --plant electrical")?,
        );
        if let Some(m) = d.motor_mut(0) {
            f.apply_to_motor(m.params_mut());
        }
    }
    Ok(())
}

/// The change `--plant-r`/`--plant-l`/`--plant-offset` make to an
/// electrical axis' plant (both fieldbuses); `None` without them.
pub(super) fn plant_motor(
    args: &ServeArgs,
) -> Result<Option<impl Fn(&mut hil_sim::electrical::ElectricalAxis) + '_>, String> {
    if args.plant_r.is_none() && args.plant_l.is_none() && args.plant_offset.is_none() {
        return Ok(None);
    }
    if args.plant != Plant::Electrical {
        return Err("--plant-r/--plant-l/--plant-offset need --plant electrical".into());
    }
    if args.plant_offset.is_some_and(|o| !o.is_finite()) {
        return Err("--plant-offset must be a finite angle".into());
    }
    let positive = |x: Option<f64>| x.is_none_or(|v| v.is_finite() && v > 0.0);
    if !positive(args.plant_r) || !positive(args.plant_l) {
        return Err("--plant-r and --plant-l must be positive".into());
    }
    Ok(Some(move |el: &mut hil_sim::electrical::ElectricalAxis| {
        let plant = el.plant_mut();
        let mut m = plant.params().motor;
        m.r_ohm = args.plant_r.unwrap_or(m.r_ohm);
        if let Some(l) = args.plant_l {
            (m.ld_h, m.lq_h) = (l, l);
        }
        m.commutation_offset_rad = args.plant_offset.unwrap_or(m.commutation_offset_rad);
        plant.set_motor(m);
    }))
}

/// Runs `serve` until `--seconds` have passed (or forever).
pub fn serve(args: &ServeArgs) -> Result<(), String> {
    if args.fieldbus == Fieldbus::Profinet {
        if args.plant_fault.is_some() && args.plant != Plant::Electrical {
            return Err("--plant-fault needs --plant electrical".into());
        }
        if args.flywheel.is_some() {
            return Err("--flywheel is EtherCAT-only".into());
        }
        return super::serve_pn::serve(args);
    }
    if args.name.is_some() {
        return Err("--name is PROFINET-only (--fieldbus profinet)".into());
    }
    if args.control.is_some() {
        return Err("--control is PROFINET-only (--fieldbus profinet)".into());
    }
    let slaves = usize::from(args.slaves);
    let variant = match args.axes {
        Some(1) => drive_ecat::Variant::Single,
        _ => drive_ecat::Variant::Double,
    };
    // drives with firmware slots: an FoE download in Bootstrap is accepted
    let mut sim = Simulation::with_nodes(
        (0..slaves)
            .map(|_| SimDrive::with_firmware_slots_for(variant))
            .collect(),
    );
    for (k, d) in (0u64..).zip(sim.drives_mut()) {
        set_up_plant(d, k, args)?;
    }
    set_plant_motor(&mut sim, args)?;
    if let Some(j) = args.flywheel {
        if !(j.is_finite() && j > 0.0) {
            return Err("--flywheel must be a positive inertia".into());
        }
        if args.plant_fault.is_some_and(PlantFault::is_brake) {
            return Err("--flywheel has no holding brake: no brake fault with it".into());
        }
        for d in sim.drives_mut() {
            d.motors[0].params_mut().set_flywheel(j);
        }
    }
    // the recording first: an unwritable path fails before anything else
    if let Some(p) = &args.pcap {
        sim.record_pcap(p)
            .map_err(|e| format!("cannot write the pcap file {}: {e}", p.display()))?;
    }
    let iface = &args.iface;
    let sock = RawSocket::open(iface).map_err(|e| format!("{iface}: {e}"))?;
    // every drive answers ping and the UDP parameter service on its EoE
    // interface once the master set its IP address (docs/eoe.md); drive k
    // (from 1) has the MAC 02:00:00:00:hi(k):lo(k)
    for (k, d) in (1u16..).zip(sim.drives_mut()) {
        let [hi, lo] = k.to_be_bytes();
        d.bind_net([0x02, 0x00, 0x00, 0x00, hi, lo], u64::from(k), Nanos::ZERO);
    }
    let device = drive_ecat::device(variant);
    let kind = match variant {
        drive_ecat::Variant::Double => "double-axis",
        drive_ecat::Variant::Single => "single-axis",
    };
    println!(
        "hil-sim serve: {slaves} simulated {kind} drive(s) {} (product code {}) on {iface}",
        device.order_code, device.identity.product_code
    );
    if args.plant == Plant::Electrical {
        println!(
            "plant: current loop ({} kHz) -> simulated PMSM and inverter on every axis",
            args.pwm_khz.hz() / 1000.0
        );
        if let Some(f) = args.plant_fault {
            println!("plant fault on axis A of every drive: {f:?}");
        }
    }
    println!(
        "EoE: ping and the UDP parameter service (port {}) answer at the IP address the master sets",
        net::param::PARAM_PORT
    );
    if let Some(p) = &args.pcap {
        println!("recording frames to {}", p.display());
    }
    println!("{}", super::realtime::apply_for_serve(args));
    if let Some(max) = args.delay_us {
        println!(
            "test: every frame held 0..={max} µs after its arrival (seed {})",
            args.delay_seed
        );
    }
    stop_on_signals();
    let stats = run(&mut sim, &sock, args)?;
    flush_recording(&mut sim, args)?;
    print_lock_summary(&sim);
    println!(
        "{} frames served; {} without a kernel timestamp; {} reached the simulation more than {} µs after \
         their receive time (worst by {:.1} µs)",
        sim.frames(),
        stats.unstamped,
        stats.late,
        LATE_NOTE.as_us(),
        stats.worst_late.as_ns() as f64 / 1e3
    );
    if sim.frames() > 0 {
        println!(
            "answer sent after the kernel's receive: {}; of that simulating: {}",
            stats.answer.summary(),
            stats.work.summary()
        );
        println!(
            "CPU time of serve's thread: per frame (catch-up and frame) {}; per idle step {} \
             (wall {})",
            stats.work_cpu.summary(),
            stats.idle_cpu.summary(),
            stats.idle_wall.summary()
        );
        println!("slowest answers:");
        for l in stats.slowest.lines() {
            println!("{l}");
        }
    }
    Ok(())
}

/// The serve loop (see the module's Timing section).
fn run(sim: &mut Simulation, sock: &RawSocket, args: &ServeArgs) -> Result<Stats, String> {
    let start = monotonic();
    let end = args
        .seconds
        .map(|s| start.saturating_add(Nanos::from_ns((s.max(0.0) * 1e9) as u64)));
    let mut delay = args.delay_us.map(|max| Delay::new(max, args.delay_seed));
    let mut stats = Stats::default();
    let mut printed = Vec::new();
    let mut locks = Vec::new();
    let mut buf = [0u8; 1600];
    // the last idle step's wall and CPU time
    let mut last_idle = (Nanos::ZERO, Nanos::ZERO);
    let mut next_flush = start + FLUSH_EVERY;
    loop {
        // the clock is read before the socket: a frame not there yet arrives later
        let now = monotonic();
        if let Some(rx) = sock.try_recv(&mut buf).map_err(|e| format!("receive: {e}"))? {
            let rx_time = rx.rx.unwrap_or_else(|| {
                stats.unstamped += 1;
                now
            });
            let picked = monotonic();
            let held = match delay.as_mut() {
                Some(d) => d.hold(rx_time),
                None => Nanos::ZERO,
            };
            let begin = picked + held;
            let t = rx_time.saturating_sub(start);
            let behind = sim.now().saturating_sub(t);
            if behind > LATE_NOTE {
                stats.late += 1;
            }
            stats.worst_late = stats.worst_late.max(behind);
            let cpu0 = thread_cpu();
            sim.catch_up(t);
            let cpu1 = thread_cpu();
            let frame = buf.get_mut(..rx.len).unwrap_or_default();
            // the datagram headers before the drives change them (APxx addresses count up)
            let mut head = [0u8; 256];
            let head_len = frame.len().min(head.len());
            if let (Some(h), Some(f)) = (head.get_mut(..head_len), frame.get(..head_len)) {
                h.copy_from_slice(f);
            }
            sim.exchange(frame);
            sock.send(frame).map_err(|e| format!("send: {e}"))?;
            let sent = monotonic();
            let cpu2 = thread_cpu();
            stats.work.add(sent.saturating_sub(begin));
            stats.work_cpu.add(cpu2.saturating_sub(cpu0));
            let answer = sent.saturating_sub(rx_time).saturating_sub(held);
            stats.answer.add(answer);
            if stats.slowest.wants(answer) {
                stats.slowest.add(Answer {
                    n: sim.frames(),
                    at: t,
                    answer,
                    waited: picked.saturating_sub(rx_time),
                    catch_up_cpu: cpu1.saturating_sub(cpu0),
                    exchange_cpu: cpu2.saturating_sub(cpu1),
                    idle_before: last_idle,
                    frame: describe(head.get(..head_len).unwrap_or_default()),
                });
            }
            if let Some(e) = sim.recording_error() {
                return Err(format!("the pcap recording failed: {e}"));
            }
            // drain what queued up before simulating further
            continue;
        }
        let cpu0 = thread_cpu();
        sim.catch_up(now.saturating_sub(start + IDLE_LAG));
        print_new_changes(sim, &mut printed);
        print_firmware_stored(sim);
        // printed is done with: serve keeps no log, its memory stays the
        // same however long it runs (the soak benchmark checks it)
        for d in sim.drives_mut() {
            d.state_log.clear();
        }
        printed.fill(0);
        print_lock_changes(sim, &mut locks);
        if now >= next_flush {
            next_flush = now + FLUSH_EVERY;
            flush_recording(sim, args)?;
        }
        // the idle step (catch-up, printing, flushing): a frame that
        // arrives meanwhile waits for it
        last_idle = (monotonic().saturating_sub(now), thread_cpu().saturating_sub(cpu0));
        stats.idle_cpu.add(last_idle.1);
        stats.idle_wall.add(last_idle.0);
        if end.is_some_and(|e| now >= e) || STOP.load(Ordering::Relaxed) {
            return Ok(stats);
        }
        if !args.busy_poll {
            sock.wait(IDLE_WAIT).map_err(|e| format!("wait: {e}"))?;
        }
    }
}

/// Milliseconds of a simulation time, for the log.
fn ms(t: Nanos) -> f64 {
    t.as_ns() as f64 / 1e6
}

/// Prints every drive's gains and losses of the SYNC0 lock (the PLL's phase
/// lock, [`hil_sim::sim::PllLock`]) since the last call; `seen` keeps the
/// counts printed so far. A loss names the drive's AL state and the time
/// since the last frame then (a loss while frames flowed is a defect; one
/// after the master stopped may be SYNC0 going with it).
fn print_lock_changes(sim: &Simulation, seen: &mut Vec<(u32, u32)>) {
    seen.resize(sim.drives().len(), (0, 0));
    for (i, (d, s)) in sim.drives().iter().zip(seen.iter_mut()).enumerate() {
        let l = &d.pll_lock;
        if (l.gained, l.lost) == *s {
            continue;
        }
        if let (true, Some(loss)) = (l.lost != s.1, l.last_loss) {
            let frame = loss.since_frame.map_or_else(
                || "no frame before".to_string(),
                |g| format!("the last frame {:.1} ms before", ms(g)),
            );
            let more = l.lost - s.1;
            let more = if more > 1 {
                format!(" (lost {more} times since the last line)")
            } else {
                String::new()
            };
            println!(
                "  [{:>10.3} ms] slave {i}: SYNC0 lock (PLL) lost in {:?}, {frame}{more}",
                ms(loss.at),
                loss.state
            );
        }
        if l.gained != s.0 && l.locked {
            println!(
                "  [{:>10.3} ms] slave {i}: SYNC0 lock (PLL) gained",
                ms(l.changed)
            );
        }
        *s = (l.gained, l.lost);
    }
}

/// The end summary of the SYNC0 lock: drives locked at the end, losses in
/// all, and a line for every drive that lost it or is not locked.
fn print_lock_summary(sim: &Simulation) {
    let drives = sim.drives();
    let locked = drives.iter().filter(|d| d.pll_lock.locked).count();
    let lost: u64 = drives.iter().map(|d| u64::from(d.pll_lock.lost)).sum();
    let gained: u64 = drives.iter().map(|d| u64::from(d.pll_lock.gained)).sum();
    println!(
        "SYNC0 lock (PLL): {locked} of {} drive(s) locked at the end; gained {gained}, lost {lost} time(s) in all",
        drives.len()
    );
    for (i, d) in drives.iter().enumerate() {
        let l = &d.pll_lock;
        if l.lost == 0 && (l.locked || l.gained == 0) {
            continue;
        }
        let last = l.last_loss.map_or_else(String::new, |loss| {
            format!(", the last at {:.3} ms in {:?}", ms(loss.at), loss.state)
        });
        println!(
            "  slave {i}: gained {}, lost {} time(s){last}; locked at the end: {}",
            l.gained,
            l.lost,
            if l.locked { "yes" } else { "no" }
        );
    }
}

/// Flushes the pcap recording: a write error ends `serve` with a message.
fn flush_recording(sim: &mut Simulation, args: &ServeArgs) -> Result<(), String> {
    match (&args.pcap, sim.flush()) {
        (Some(p), Err(e)) => Err(format!("the pcap file {} is incomplete: {e}", p.display())),
        _ => Ok(()),
    }
}

/// `--delay-us`: holds each frame a seeded random time after its arrival
/// (xorshift64, uniform in 0..=max µs), as a loaded machine would.
struct Delay {
    max: Nanos,
    state: u64,
}

impl Delay {
    fn new(max_us: u64, seed: u64) -> Self {
        Self {
            max: Nanos::from_us(max_us),
            // a fixed mix of the seed, never state 0
            state: (seed.wrapping_add(0x9E37_79B9_7F4A_7C15) ^ 0xBF58_476D_1CE4_E5B9).max(1),
        }
    }

    /// Sleeps until `arrival` (monotonic) plus the next random delay;
    /// returns how long it slept.
    fn hold(&mut self, arrival: Nanos) -> Nanos {
        let mut x = self.state;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.state = x;
        let until = arrival.saturating_add(Nanos::from_ns(x % self.max.as_ns().saturating_add(1)));
        let now = monotonic();
        if until > now {
            std::thread::sleep(Duration::from_nanos((until - now).as_ns()));
        }
        monotonic().saturating_sub(now)
    }
}

/// Prints each FoE download a drive verified and stored since the last call
/// (issue 33: the user sees the image landed, and in which slot).
fn print_firmware_stored(sim: &mut Simulation) {
    for (i, d) in sim.drives_mut().iter_mut().enumerate() {
        if let Some(s) = d.drive.take_firmware_stored() {
            println!(
                "slave {i}: FoE download verified and stored in slot {:?} (version {}); \
                 it starts at the next power-on",
                s.slot, s.version
            );
        }
    }
}
