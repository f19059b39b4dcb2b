extern crate std;
use super::*;
use crate::esc::EscConfig;
use crate::frame::testutil::{phys, pos, xfer, xfer1};
use crate::frame::Command;
use ::esc::Pdi;
use std::vec::Vec;

fn esc_with_clock(drift_ppb: i32, offset_ns: u64) -> Esc {
    Esc::new(
        EscConfig {
            clock_drift_ppb: drift_ppb,
            clock_offset_ns: offset_ns,
            ..EscConfig::default()
        },
        &[],
    )
}

fn u64_of(d: &[u8]) -> u64 {
    u64::from_le_bytes(d[..8].try_into().unwrap())
}

fn u32_of(d: &[u8]) -> u32 {
    u32::from_le_bytes(d[..4].try_into().unwrap())
}

/// How far `a`'s system time is ahead of `b`'s at `t` (ns).
fn sync_offset(a: &Esc, b: &Esc, t: u64) -> i64 {
    a.system_time_ns(Nanos::from_ns(t))
        .wrapping_sub(b.system_time_ns(Nanos::from_ns(t))) as i64
}

/// Station addresses 0x1000 and 0x1001 for `a` and `b` (APWR) at `t`.
fn address_pair(a: &mut Esc, b: &mut Esc, t: u64) {
    for (p, addr) in [(0u16, 0x1000u16), (1, 0x1001)] {
        xfer(
            &mut [&mut *a, &mut *b],
            Command::Apwr,
            phys(pos(p), ::esc::regs::STATION_ADDRESS),
            &addr.to_le_bytes(),
            t,
        );
    }
}

/// The line timing of the two-ESC tests: `a` first (loop time 500 ns),
/// `b` 250 ns after it.
fn on_a_line(a: &mut Esc, b: &mut Esc) {
    a.set_line_timing(LineTiming {
        arrival: Nanos::from_ns(0),
        loop_time: Nanos::from_ns(500),
    });
    b.set_line_timing(LineTiming {
        arrival: Nanos::from_ns(250),
        loop_time: Nanos::from_ns(0),
    });
}

/// The signed value of the system time difference register (sign bit 31).
fn difference(e: &Esc) -> i64 {
    let mut b = [0u8; 4];
    e.read_reg(dc::SYSTEM_TIME_DIFFERENCE, &mut b);
    let v = u32::from_le_bytes(b);
    let mag = i64::from(v & 0x7FFF_FFFF);
    if v & 1 << 31 != 0 {
        -mag
    } else {
        mag
    }
}

#[test]
fn local_clock_runs_with_drift_and_offset_and_inverts_exactly() {
    let c = LocalClock::new(5_000, 100_000_000); // +100 ppm
    assert_eq!(c.local_at(Nanos::from_ns(0)), 5_000);
    assert_eq!(
        c.local_at(Nanos::from_ns(1_000_000_000)),
        5_000 + 1_000_000_000 + 100_000
    );
    let slow = LocalClock::new(0, -80_000_000); // -80 ppm
    assert_eq!(
        slow.local_at(Nanos::from_ns(1_000_000_000)),
        1_000_000_000 - 80_000
    );
    for clock in [c, slow, LocalClock::new(u64::MAX - 10, 3_456_789)] {
        for target in [0u64, 1, 999, 123_456_789, 1_000_000_007, 98_765_432_123] {
            let target = clock.local_at(Nanos::from_ns(0)).wrapping_add(target);
            let t = clock.now_for_local(target);
            assert!(clock.local_at(t).wrapping_sub(target) as i64 >= 0);
            if t > Nanos::ZERO {
                assert!(
                    (clock.local_at(t - Nanos::from_ns(1)).wrapping_sub(target) as i64) < 0,
                    "earliest"
                );
            }
        }
    }
    // a change of speed keeps the time continuous
    let mut c = c;
    let before = c.local_at(Nanos::from_ns(2_000_000));
    c.set_rate(Nanos::from_ns(2_000_000), -50_000_000);
    assert_eq!(c.local_at(Nanos::from_ns(2_000_000)), before);
    assert_eq!(c.local_at(Nanos::from_ns(3_000_000)), before + 1_000_000 - 50);
}

#[test]
fn esc_local_and_system_time_follow_the_configured_clock() {
    let mut e = esc_with_clock(50_000, 1_000); // +50 ppm
    assert_eq!(
        e.local_ns(Nanos::from_ns(2_000_000_000)),
        1_000 + 2_000_000_000 + 100_000
    );
    xfer1(
        &mut e,
        Command::Apwr,
        phys(0, dc::SYSTEM_TIME_OFFSET),
        &7_000u64.to_le_bytes(),
        0,
    );
    let (d, _) = xfer1(
        &mut e,
        Command::Aprd,
        phys(0, dc::SYSTEM_TIME),
        &[0; 8],
        1_000_000_000,
    );
    assert_eq!(u64_of(&d), 1_000 + 1_000_000_000 + 50_000 + 7_000);
    // the PDI reads it at the ESC's time
    let mut b = [0u8; 8];
    e.read(dc::SYSTEM_TIME, &mut b).unwrap();
    assert_eq!(
        u64::from_le_bytes(b),
        e.system_time_ns(Nanos::from_ns(1_000_000_000))
    );
}

#[test]
fn receive_times_per_port_follow_the_line() {
    let mut a = esc_with_clock(0, 0);
    let mut b = esc_with_clock(20_000, 1_000_000); // +20 ppm, another phase
    on_a_line(&mut a, &mut b);
    let t = 10_000_000u64;
    let (_, wkc) = xfer(
        &mut [&mut a, &mut b],
        Command::Bwr,
        phys(0, dc::RECEIVE_TIME_PORT0),
        &[0; 4],
        t,
    );
    assert_eq!(wkc, 2);
    let ports = |e: &mut Esc| {
        let (d, _) = xfer1(
            e,
            Command::Aprd,
            phys(0, dc::RECEIVE_TIME_PORT0),
            &[0; 8],
            t + 1000,
        );
        let (pu, _) = xfer1(e, Command::Aprd, phys(0, dc::RECEIVE_TIME_PU), &[0; 8], t + 1000);
        (u32_of(&d), u32_of(&d[4..]), u64_of(&pu))
    };
    let (p0, p1, pu) = ports(&mut a);
    assert_eq!(
        (u64::from(p0), p1 - p0, pu),
        (t, 500, t),
        "round trip through the rest of the line"
    );
    let (p0, p1, pu) = ports(&mut b);
    assert_eq!(
        pu,
        b.local_ns(Nanos::from_ns(t + 250)),
        "port 0 at its arrival, local clock"
    );
    assert_eq!((p0, p1), (pu as u32, pu as u32), "last slave: port 1 closed");
}

#[test]
fn ecat_system_time_is_taken_at_the_frames_arrival() {
    let mut e = esc_with_clock(0, 0);
    e.set_line_timing(LineTiming {
        arrival: Nanos::from_ns(750),
        loop_time: Nanos::from_ns(0),
    });
    let (d, _) = xfer1(&mut e, Command::Aprd, phys(0, dc::SYSTEM_TIME), &[0; 8], 5_000);
    assert_eq!(u64_of(&d), 5_750);
}

/// A master's DC start-up on a two-slave line (as ethercrab does it):
/// latch, offsets from the receive times, delay of the second slave; then
/// FRMW of the reference's system time, first every `static_ns` for
/// `static_n` frames, then every `cycle_ns` for `cycles` frames. Returns
/// the line and the time of the last frame.
fn drift_run(
    drift_a: i32,
    drift_b: i32,
    static_n: usize,
    static_ns: u64,
    cycles: usize,
    cycle_ns: u64,
    mut trace: impl FnMut(&Esc, &Esc, u64),
) -> (Esc, Esc, u64) {
    let mut a = esc_with_clock(drift_a, 3_000_000);
    let mut b = esc_with_clock(drift_b, 987_654_321);
    on_a_line(&mut a, &mut b);
    let mut t = 1_000_000u64;
    address_pair(&mut a, &mut b, t);
    // ethercrab's reset of the loop parameters
    xfer(
        &mut [&mut a, &mut b],
        Command::Bwr,
        phys(0, dc::FILTER_DEPTH_TIME),
        &0x0C00u16.to_le_bytes(),
        t,
    );
    xfer(
        &mut [&mut a, &mut b],
        Command::Bwr,
        phys(0, dc::SPEED_COUNTER_START),
        &0x1000u16.to_le_bytes(),
        t,
    );
    xfer(
        &mut [&mut a, &mut b],
        Command::Bwr,
        phys(0, dc::RECEIVE_TIME_PORT0),
        &[0; 4],
        t,
    );
    let master_now = t + 50_000;
    let pu_a = a.get_u64(dc::RECEIVE_TIME_PU);
    let pu_b = b.get_u64(dc::RECEIVE_TIME_PU);
    let (p0, p1) = (
        a.get_u32(dc::RECEIVE_TIME_PORT0),
        a.get_u32(dc::RECEIVE_TIME_PORT1),
    );
    let delay_b = (p1 - p0) / 2;
    for (adr, pu, delay) in [(0x1000u16, pu_a, 0u32), (0x1001, pu_b, delay_b)] {
        let off = master_now.wrapping_sub(pu);
        xfer(
            &mut [&mut a, &mut b],
            Command::Fpwr,
            phys(adr, dc::SYSTEM_TIME_OFFSET),
            &off.to_le_bytes(),
            t,
        );
        xfer(
            &mut [&mut a, &mut b],
            Command::Fpwr,
            phys(adr, dc::SYSTEM_TIME_DELAY),
            &delay.to_le_bytes(),
            t,
        );
    }
    let plan = core::iter::repeat_n(static_ns, static_n).chain(core::iter::repeat_n(cycle_ns, cycles));
    for step in plan {
        t += step;
        let (_, wkc) = xfer(
            &mut [&mut a, &mut b],
            Command::Frmw,
            phys(0x1000, dc::SYSTEM_TIME),
            &[0; 8],
            t,
        );
        assert_eq!(wkc, 2);
        trace(&a, &b, t);
    }
    (a, b, t)
}

#[test]
fn drift_control_converges_for_plus_minus_100_ppm() {
    for (da, db) in [
        (100_000, -100_000),
        (-100_000, 100_000),
        (0, 100_000),
        (-30_000, 0),
    ] {
        let mut worst_late = 0i64;
        let (a, b, t) = drift_run(da, db, 10_000, 8_000, 1_000, 1_000_000, |a, b, t| {
            if t > 500_000_000 {
                let d = sync_offset(a, b, t);
                worst_late = worst_late.max(d.abs());
            }
        });
        let d = difference(&b);
        let sync = sync_offset(&a, &b, t);
        std::println!(
            "drifts {da}/{db} ppb: 0x092C {d} ns, true offset {sync} ns, worst after 0.5 s {worst_late} ns, rate a {} b {} ppb",
            a.clock_rate_ppb(),
            b.clock_rate_ppb()
        );
        assert!(d.abs() <= 2, "difference register {d}");
        assert!(sync.abs() <= 2, "system times {sync}");
        assert!(worst_late <= 3, "stays in sync {worst_late}");
        // the frequency part of the correction (0x0932, 0.1 ppm) matches the drift
        // difference; the quantised (1 ns) loop dithers it by a few tenths of a ppm
        let speed = i32::from(b.get_u16(dc::SPEED_COUNTER_DIFF) as i16);
        assert!((speed - (da - db) / 100).abs() <= 3, "speed counter diff {speed}");
        assert!(
            (a.clock_rate_ppb() - b.clock_rate_ppb()).abs() <= 100,
            "same speed"
        );
        assert_eq!(a.clock_correction_ppb(), 0, "the reference is not adjusted");
    }
}

#[test]
fn drift_control_after_static_sync_alone_and_with_slow_cycles() {
    // after the static drift compensation alone
    let (a, b, t) = drift_run(50_000, -80_000, 10_000, 8_000, 0, 0, |_, _, _| {});
    let sync = sync_offset(&a, &b, t);
    assert!(sync.abs() <= 2 && difference(&b).abs() <= 2, "{sync}");
    // 10 ms cycles only (gains reduced): still converges
    let (a, b, t) = drift_run(50_000, -80_000, 0, 0, 1_000, 10_000_000, |_, _, _| {});
    let sync = sync_offset(&a, &b, t);
    assert!(sync.abs() <= 5, "{sync}");
}

#[test]
fn drift_control_with_time_filter_depth_stays_stable() {
    let mut a = esc_with_clock(0, 0);
    let mut b = esc_with_clock(100_000, 0);
    address_pair(&mut a, &mut b, 0);
    // power-on filter depth 4
    let mut t = 0;
    for _ in 0..2_000 {
        t += 1_000_000;
        xfer(
            &mut [&mut a, &mut b],
            Command::Frmw,
            phys(0x1000, dc::SYSTEM_TIME),
            &[0; 8],
            t,
        );
    }
    let sync = sync_offset(&a, &b, t);
    assert!(sync.abs() <= 2, "{sync}");
    assert!(difference(&b).abs() <= 2);
    // speed counter difference shows the frequency correction (-100 ppm, 0.1 ppm units)
    let speed = b.get_u16(dc::SPEED_COUNTER_DIFF) as i16;
    assert!((speed + 1000).abs() <= 3, "{speed}");
    // a write of the speed counter start resets the loop
    xfer(
        &mut [&mut a, &mut b],
        Command::Bwr,
        phys(0, dc::SPEED_COUNTER_START),
        &0x1000u16.to_le_bytes(),
        t,
    );
    assert_eq!(b.clock_correction_ppb(), 0);
    assert_eq!(b.get_u16(dc::SPEED_COUNTER_DIFF), 0);
}

#[test]
fn only_armw_frmw_writes_feed_the_loop_and_32_bit_writes_compare_32_bits() {
    let mut a = esc_with_clock(0, 0);
    let mut b = esc_with_clock(0, 0);
    xfer(
        &mut [&mut a, &mut b],
        Command::Apwr,
        phys(pos(0), ::esc::regs::STATION_ADDRESS),
        &0x1000u16.to_le_bytes(),
        0,
    );
    // a broadcast write of 0 (a master's reset) is no drift sample
    xfer(
        &mut [&mut a, &mut b],
        Command::Bwr,
        phys(0, dc::SYSTEM_TIME),
        &[0; 8],
        1_000_000_000,
    );
    assert_eq!((difference(&b), b.clock_correction_ppb()), (0, 0));
    // a 32-bit FRMW: local copy 2^32 + 1000 ahead in 64 bit, 1000 in 32 bit
    b.set_clock(0, (1 << 32) + 1000);
    let (_, wkc) = xfer(
        &mut [&mut a, &mut b],
        Command::Frmw,
        phys(0x1000, dc::SYSTEM_TIME),
        &[0; 4],
        2_000_000_000,
    );
    assert_eq!(wkc, 2);
    assert_eq!(difference(&b), 1000);
    assert!(b.clock_correction_ppb() < 0, "slowed down");
    // the reference reads only
    assert_eq!(difference(&a), 0);
}

/// Sets up and starts the cyclic unit with ECAT writes.
fn start_sync(e: &mut Esc, start: u64, c0: u32, c1: u32, act: u8, now: u64) {
    xfer1(
        e,
        Command::Apwr,
        phys(0, dc::START_TIME),
        &start.to_le_bytes(),
        now,
    );
    xfer1(e, Command::Apwr, phys(0, dc::SYNC0_CYCLE), &c0.to_le_bytes(), now);
    xfer1(e, Command::Apwr, phys(0, dc::SYNC1_CYCLE), &c1.to_le_bytes(), now);
    xfer1(e, Command::Apwr, phys(0, dc::ACTIVATION), &[act], now);
}

/// Steps to every SYNC0 edge up to `until` and returns (sim time, system time) of each pulse.
fn sync0_edges(e: &mut Esc, until: u64) -> Vec<(u64, u64)> {
    let mut out = Vec::new();
    while let Some(t) = e.next_sync0_at().filter(|&t| t <= Nanos::from_ns(until)) {
        let p = e.take_sync0_events(t);
        assert_eq!((p.count, p.last_now), (1, t));
        out.push((t.as_ns(), p.last_system_ns));
    }
    out
}

#[test]
fn sync0_pulses_are_exact_in_system_time() {
    let mut e = esc_with_clock(-37_000, 555_555); // -37 ppm
    xfer1(
        &mut e,
        Command::Apwr,
        phys(0, dc::SYSTEM_TIME_OFFSET),
        &1_000_000_000u64.to_le_bytes(),
        0,
    );
    let start = 1_020_000_000u64; // system time
    start_sync(&mut e, start, 1_000_000, 0, 0x03, 1_000);
    assert_eq!(e.take_sync0_events(Nanos::from_ns(1_000)).count, 0);
    let edges = sync0_edges(&mut e, 200_000_000);
    assert!(edges.len() > 150);
    for (k, &(t, sys)) in edges.iter().enumerate() {
        assert_eq!(sys, start + k as u64 * 1_000_000);
        assert!(
            e.system_time_ns(Nanos::from_ns(t)) >= sys && e.system_time_ns(Nanos::from_ns(t - 1)) < sys,
            "edge exact"
        );
    }
    // in simulation time the period is 1 ms / (1 - 37 ppm)
    let (t0, _) = edges[0];
    let (t100, _) = edges[100];
    assert!(((t100 - t0) as i64 - 100_003_701).abs() <= 1, "{}", t100 - t0);
    // 0x0990 reads the next pulse
    let now = e.now().as_ns();
    let (d, _) = xfer1(&mut e, Command::Aprd, phys(0, dc::START_TIME), &[0; 8], now);
    assert_eq!(u64_of(&d), edges.last().unwrap().1 + 1_000_000);
    // deactivation stops it
    xfer1(&mut e, Command::Apwr, phys(0, dc::ACTIVATION), &[0], now);
    assert_eq!(e.next_sync0_at(), None);
}

#[test]
fn sync0_status_and_al_event_clear_on_pdi_read() {
    let mut e = esc_with_clock(0, 0);
    start_sync(&mut e, 100_000, 50_000, 0, 0x03, 0);
    e.tick(Nanos::from_ns(99_999));
    assert_eq!(e.get_u8(dc::SYNC0_STATUS), 0);
    e.tick(Nanos::from_ns(100_000));
    assert_eq!(e.get_u8(dc::SYNC0_STATUS) & 1, 1);
    assert_ne!(Pdi::al_event(&mut e).unwrap() & al_event::SYNC0, 0);
    // an ECAT read does not acknowledge
    xfer1(&mut e, Command::Aprd, phys(0, dc::SYNC0_STATUS), &[0], 100_000);
    assert_eq!(e.get_u8(dc::SYNC0_STATUS) & 1, 1);
    let mut s = [0u8];
    e.read(dc::SYNC0_STATUS, &mut s).unwrap();
    assert_eq!(s[0] & 1, 1, "read value shows the pulse");
    assert_eq!(e.get_u8(dc::SYNC0_STATUS) & 1, 0, "cleared by reading");
    assert_eq!(Pdi::al_event(&mut e).unwrap() & al_event::SYNC0, 0);
    // several pulses missed: counted, the last one's time is reported
    let p = e.take_sync0_events(Nanos::from_ns(330_000));
    assert_eq!((p.count, p.last_system_ns), (5, 300_000));
    assert_eq!(e.next_sync0_at(), Some(Nanos::from_ns(350_000)));
    // masked out: no AL event, the status still shows it
    e.write(::esc::regs::AL_EVENT_MASK, &(!al_event::SYNC0).to_le_bytes())
        .unwrap();
    e.read(dc::SYNC0_STATUS, &mut s).unwrap();
    e.tick(Nanos::from_ns(350_000));
    assert_eq!(e.al_event_request() & al_event::SYNC0, 0);
    assert_eq!(e.get_u8(dc::SYNC0_STATUS) & 1, 1);
    // the master cannot write the status
    xfer1(&mut e, Command::Apwr, phys(0, dc::SYNC0_STATUS), &[0], 350_000);
    assert_eq!(e.get_u8(dc::SYNC0_STATUS) & 1, 1);
}

#[test]
fn sync1_follows_the_cycle_rules() {
    let sync1 = |c1: u32| {
        let mut e = esc_with_clock(0, 0);
        start_sync(&mut e, 1_000_000, 100_000, c1, 0x07, 0);
        let mut times = Vec::new();
        while let Some(t) = e.next_sync1_at().filter(|&t| t < Nanos::from_ms(2)) {
            e.take_sync1_events(t);
            times.push(t.as_ns());
        }
        times.truncate(3);
        times
    };
    assert_eq!(sync1(0), [1_000_000, 1_100_000, 1_200_000], "with SYNC0");
    assert_eq!(sync1(30_000), [1_030_000, 1_130_000, 1_230_000], "shifted");
    assert_eq!(
        sync1(300_000),
        [1_300_000, 1_600_000, 1_900_000],
        "every 3rd SYNC0"
    );
    assert_eq!(
        sync1(310_000),
        [1_310_000, 1_610_000, 1_910_000],
        "every 3rd, shifted"
    );
    // SYNC0 single shot (cycle 0)
    let mut e = esc_with_clock(0, 0);
    start_sync(&mut e, 500, 0, 0, 0x03, 0);
    assert_eq!(sync0_edges(&mut e, 10_000_000), [(500, 500)]);
    assert_eq!(e.next_sync0_at(), None);
}

#[test]
fn start_time_in_the_past_starts_at_the_next_cycle_boundary() {
    let mut e = esc_with_clock(0, 0);
    start_sync(&mut e, 100_000, 300_000, 0, 0x03, 1_000_000);
    assert_eq!(e.next_sync0_at(), Some(Nanos::from_ns(1_000_000)));
    let mut e = esc_with_clock(0, 0);
    start_sync(&mut e, 100_000, 300_000, 0, 0x03, 1_000_001);
    assert_eq!(e.next_sync0_at(), Some(Nanos::from_ns(1_300_000)));
}

/// The local clock's 64-bit fast paths give what the 128-bit arithmetic
/// gives: random speeds (drift and correction at their limits and small),
/// fractions left by re-anchoring, times before and long after the anchor.
#[test]
fn local_clock_64_bit_paths_equal_the_128_bit_arithmetic() {
    let mut x = 0x2545_F491_4F6C_DD1Du64;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let limit = i64::from(MAX_DRIFT_PPB) * 1000 + MAX_CORRECTION_PPT;
    for round in 0..2_000u64 {
        let rate = |r: u64| match r % 4 {
            0 => 0,
            1 => (r >> 8) as i64 % 100_000_000 - 50_000_000,
            _ => (r >> 8) as i64 % (2 * limit + 1) - limit,
        };
        let mut c = LocalClock::new(next(), rate(next()));
        let mut t = next() % 1_000_000_000_000;
        for _ in 0..(round % 5) {
            t += next() % 10_000_000_000;
            c.set_rate(Nanos::from_ns(t), rate(next()));
        }
        for _ in 0..20 {
            let r = next();
            let probe = match r % 4 {
                0 => t.saturating_sub(r >> 40),
                1 => t + (r >> 40),
                2 => t + (r >> 16),
                _ => r,
            };
            let p = Nanos::from_ns(probe);
            assert_eq!(c.local_at(p), c.local_at_wide(p), "{c:?} at {probe}");
            let local = match next() % 3 {
                0 => c.local_at(p),
                1 => c.local_at(p).wrapping_add(next() >> 20),
                _ => next(),
            };
            assert_eq!(
                c.now_for_local(local),
                c.now_for_local_wide(local),
                "{c:?} reaching {local}"
            );
        }
    }
}
