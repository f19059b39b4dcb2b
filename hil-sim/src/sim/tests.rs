use super::*;
use crate::frame::testutil::{build, phys, pos};
use crate::frame::Command;
use ::esc::regs::dc;

/// Sends one datagram through the simulation.
fn send(sim: &mut Simulation, cmd: Command, addr: u32, data: &[u8]) {
    let mut f = build(&[(cmd, addr, data)]);
    sim.exchange(&mut f);
}

/// Starts SYNC0 at every slave at system time `start` with `cycle`.
fn start_sync0(sim: &mut Simulation, start: u64, cycle: u32) {
    let n = sim.drives().len() as u16;
    for p in 0..n {
        send(
            sim,
            Command::Apwr,
            phys(pos(p), dc::START_TIME),
            &start.to_le_bytes(),
        );
        send(
            sim,
            Command::Apwr,
            phys(pos(p), dc::SYNC0_CYCLE),
            &cycle.to_le_bytes(),
        );
        send(sim, Command::Apwr, phys(pos(p), dc::ACTIVATION), &[0x03]);
    }
}

#[test]
fn frame_jitter_is_seeded_deterministic_and_bounded() {
    let run = |max: u64, seed: u64| {
        let mut sim = Simulation::with_nodes(Vec::<SimDrive>::new());
        sim.set_frame_jitter(Nanos::from_ns(max), seed);
        let mut times = Vec::new();
        for _ in 0..200 {
            let t0 = sim.now().as_ns();
            send(&mut sim, Command::Brd, phys(0, 0), &[0; 2]);
            times.push(sim.now().as_ns() - t0);
        }
        times
    };
    let a = run(5_000, 42);
    assert_eq!(a, run(5_000, 42), "same seed, same jitter");
    assert_ne!(a, run(5_000, 43), "another seed");
    let wire = run(0, 42)[0];
    assert!(run(0, 7).iter().all(|&t| t == wire), "no jitter by default");
    assert!(
        a.iter().all(|&t| (wire..=wire + 10_000).contains(&t)),
        "±5 µs around 5 µs"
    );
    let spread = a.iter().max().unwrap() - a.iter().min().unwrap();
    assert!(spread > 8_000, "uses the range: {spread}");
}

#[test]
fn sync0_is_delivered_at_each_edge_in_time_order() {
    let mut sim = Simulation::new(2);
    sim.drives_mut()[0].set_clock(50.0, 1_000);
    sim.drives_mut()[1].set_clock(-80.0, 7_777_777);
    start_sync0(&mut sim, 2_000_000, 250_000);
    // the second drive's system time is ahead (its local clock is): no offsets written
    sim.advance_to(Nanos::from_ns(20_000_000));
    for (i, d) in sim.drives().iter().enumerate() {
        let log: Vec<_> = d.sync0_log.iter().copied().collect();
        assert!(log.len() >= 40, "drive {i}: {} pulses", log.len());
        for w in log.windows(2) {
            assert_eq!(w[1].system_ns - w[0].system_ns, 250_000, "exact in system time");
            assert_eq!(w[1].pulses, 1, "each edge delivered");
        }
        for s in &log {
            assert!(d.esc.system_time_ns(s.now) >= s.system_ns);
            assert!(
                d.esc.system_time_ns(s.now - Nanos::from_ns(1)) < s.system_ns,
                "at the edge"
            );
            assert_eq!(s.local_ns, d.esc.local_ns(s.now));
        }
        assert_eq!(
            d.esc.al_event_request() & ::esc::regs::al_event::SYNC0,
            0,
            "acknowledged"
        );
    }
    // with frames in between: still every edge, never late
    let before = sim.drives()[0].sync0_log.back().copied().unwrap();
    let t0 = sim.now().as_ns();
    for _ in 0..100 {
        send(&mut sim, Command::Brd, phys(0, 0), &[0; 64]);
    }
    sim.advance_to(Nanos::from_ns(sim.now().as_ns() + 1_000_000));
    let log = &sim.drives()[0].sync0_log;
    let after: Vec<_> = log.iter().filter(|s| s.system_ns > before.system_ns).collect();
    let expected = (sim.now().as_ns() - t0) / 250_000;
    assert!(
        after.len() as u64 >= expected,
        "{} pulses in {} ns",
        after.len(),
        sim.now().as_ns() - t0
    );
    assert!(after.iter().all(|s| s.pulses == 1));
    assert_eq!(after[0].system_ns, before.system_ns + 250_000);
}

#[test]
fn power_cycle_keeps_the_oscillator() {
    let mut d = SimDrive::new();
    d.set_clock(-25.0, 42);
    d.power_cycle();
    assert_eq!(d.esc.config().clock_drift_ppb, -25_000);
    assert_eq!(
        d.esc.local_ns(Nanos::from_ns(1_000_000_000)),
        42 + 1_000_000_000 - 25_000
    );
}

/// The MCU clock's 64-bit paths (`mcu_local`, `mcu_now_for`, `tick_local`)
/// give what the 128-bit arithmetic they replaced gives, for drifts up to
/// the ESC's limit, offsets and times up to 2^62 ns (146 years).
#[test]
fn mcu_clock_64_bit_paths_equal_the_128_bit_arithmetic() {
    fn local_wide(offset: u64, ppb: i32, now: u64) -> u64 {
        let now = i128::from(now);
        let t = i128::from(offset) + now + now * i128::from(ppb) / 1_000_000_000;
        u64::try_from(t.max(0)).unwrap_or(u64::MAX)
    }
    fn first_wide(offset: u64, ppb: i32, local: u64) -> Option<u64> {
        let rel = i128::from(local) - i128::from(offset);
        let den = (1_000_000_000 + i128::from(ppb)).max(1);
        (rel > 0).then(|| u64::try_from(rel * 1_000_000_000 / den).unwrap_or(u64::MAX))
    }
    let mut x = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let mut d = SimDrive::new();
    for _ in 0..20_000 {
        let ppb = match next() % 3 {
            0 => 0,
            1 => (next() % 200_001) as i32 - 100_000,
            _ => (next() % 200_000_001) as i32 - 100_000_000,
        };
        let offset = next() >> (2 + next() % 62);
        d.esc.set_clock(ppb, offset);
        let now = next() >> (2 + next() % 62);
        assert_eq!(
            d.mcu_local(Nanos::from_ns(now)).as_ns(),
            local_wide(offset, ppb, now),
            "{ppb} ppb, offset {offset}, at {now}"
        );
        let local = next() >> (2 + next() % 62);
        let t = d.mcu_now_for(Nanos::from_ns(local)).as_ns();
        // the first time the clock reaches `local`, found from the same estimate
        let mut want = first_wide(offset, ppb, local).unwrap_or(0);
        if local > offset {
            while local_wide(offset, ppb, want) < local {
                want = want.saturating_add(1);
            }
            while want > 0 && local_wide(offset, ppb, want - 1) >= local {
                want -= 1;
            }
        }
        assert_eq!(t, want, "{ppb} ppb, offset {offset}, reaching {local}");
        let tick = next() >> (next() % 64);
        let wide = (u128::from(tick) * NS_PER_S).div_ceil(u128::from(TIMER_HZ));
        assert_eq!(
            SimDrive::tick_local(tick).as_ns(),
            u64::try_from(wide).unwrap_or(u64::MAX),
            "tick {tick}"
        );
    }
}
