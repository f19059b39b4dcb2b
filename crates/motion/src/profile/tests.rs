use super::*;

const DT: u32 = 250_000; // 250 µs

/// 3000 rpm, 1e9 inc/s² acceleration, 5e8 deceleration, 1e11 jerk.
fn limits() -> ProfileLimits {
    ProfileLimits {
        velocity: 52_428_800.0,
        acceleration: 1.0e9,
        deceleration: 5.0e8,
        jerk: 1.0e11,
    }
}

/// Steps until done (at most `max` steps) and returns the samples'
/// count; checks each sample with `check(prev, sample)`.
fn run(
    g: &mut ProfileGenerator,
    dt: u32,
    max: usize,
    mut check: impl FnMut(&ProfileSample, &ProfileSample),
) -> (usize, ProfileSample) {
    let mut prev = ProfileSample {
        position: g.current().0,
        velocity: g.current().2 as f32,
        acceleration: g.current().3 as f32,
        done: false,
    };
    for i in 0..max {
        let s = g.step(dt);
        assert!(s.velocity.is_finite() && s.acceleration.is_finite());
        check(&prev, &s);
        prev = s;
        if s.done {
            return (i + 1, s);
        }
    }
    panic!("not done after {max} steps");
}

/// Checks v, a (speed-up vs. slow-down) and jerk against the limits.
fn limit_checker(l: ProfileLimits, dt: u32) -> impl FnMut(&ProfileSample, &ProfileSample) {
    let dt_s = f64::from(dt) * 1e-9;
    move |p, s| {
        let tol = 1.0 + 1e-6;
        let v = f64::from(s.velocity);
        let a = f64::from(s.acceleration);
        assert!(v.abs() <= f64::from(l.velocity) * tol, "v {v}");
        let amax = if a * v > 0.0 {
            l.acceleration
        } else {
            l.acceleration.max(l.deceleration)
        };
        assert!(a.abs() <= f64::from(amax) * tol + 1.0, "a {a} at v {v}");
        if a * v < -1.0 && v.abs() > 1.0 && f64::from(p.velocity) * v > 0.0 {
            assert!(a.abs() <= f64::from(l.deceleration) * tol + 1.0, "dec {a}");
        }
        let jerk = (a - f64::from(p.acceleration)).abs() / dt_s;
        assert!(jerk <= f64::from(l.jerk) * (1.0 + 1e-3), "jerk {jerk}");
        // Position and velocity agree: Δx ≈ mean velocity · dt.
        let dx = f64::from(s.position.wrapping_sub(p.position));
        let vm = 0.5 * (v + f64::from(p.velocity));
        assert!(
            (dx - vm * dt_s).abs() <= 1.0 + f64::from(l.jerk) * dt_s * dt_s * dt_s,
            "dx {dx} vs {}",
            vm * dt_s
        );
    }
}

#[test]
fn c049_pp_profile_reaches_target_exactly() {
    let starts = [0, -12_345, i32::MAX - 1_000_000, i32::MIN + 3];
    let distances = [
        1,
        2,
        7,
        1000,
        1 << 20,
        10 << 20,
        1 << 30,
        -1,
        -(3 << 20),
        -(1 << 30),
    ];
    for &start in &starts {
        for &d in &distances {
            let mut g = ProfileGenerator::new(start);
            let target = start.wrapping_add(d);
            assert_eq!(
                g.move_to(PositionTarget::Absolute(target), limits(), SetMode::Immediate),
                Ok(true)
            );
            let sign = d.signum();
            let (_, last) = run(&mut g, DT, 200_000, |p, s| {
                // Never beyond the target, never backwards.
                let rest = i64::from(target.wrapping_sub(s.position));
                assert!(rest * i64::from(sign) >= 0, "overshoot {rest} (d {d})");
                let step = i64::from(s.position.wrapping_sub(p.position));
                assert!(step * i64::from(sign) >= 0, "backwards {step}");
            });
            assert_eq!(last.position, target, "start {start} d {d}");
            assert_eq!(last.velocity, 0.0);
            assert!(g.is_standstill());
            assert_eq!(g.step(DT).position, target);
        }
    }
}

#[test]
fn c049_pp_profile_respects_v_a_j_limits() {
    for (d, l) in [
        (10 << 20, limits()),
        (1 << 30, limits()),
        (-(1 << 22), limits()),
        (
            5000,
            ProfileLimits {
                velocity: 1.0e6,
                acceleration: 2.0e7,
                deceleration: 4.0e7,
                jerk: 1.0e9,
            },
        ),
    ] {
        let mut g = ProfileGenerator::new(100);
        g.move_to(
            PositionTarget::Relative {
                distance: d,
                actual: 100,
            },
            l,
            SetMode::Immediate,
        )
        .unwrap();
        let dt = 100_000;
        let mut vmax = 0.0f32;
        let mut check = limit_checker(l, dt);
        let (_, last) = run(&mut g, dt, 1_000_000, |p, s| {
            vmax = vmax.max(s.velocity.abs());
            check(p, s);
        });
        assert_eq!(last.position, 100i32.wrapping_add(d));
        if d.abs() >= 1 << 30 {
            // Long moves reach the velocity limit.
            assert!(vmax >= l.velocity * 0.999, "vmax {vmax}");
        }
    }
}

#[test]
fn c049_pp_move_time_close_to_minimum() {
    // 1e7 inc with v = 1e7 inc/s, a = d = 1e8 inc/s², j = 1e10 inc/s³:
    // the plan reaches v and cruises (time-optimal for these limits).
    let l = ProfileLimits {
        velocity: 1.0e7,
        acceleration: 1.0e8,
        deceleration: 1.0e8,
        jerk: 1.0e10,
    };
    let mut g = ProfileGenerator::new(0);
    g.move_to(PositionTarget::Absolute(10_000_000), l, SetMode::Immediate)
        .unwrap();
    // Ramp: 0.01 s jerk + 0.09 s const + 0.01 s jerk = 0.11 s, distance
    // 0.55e6 each; cruise 8.9e6 / 1e7 = 0.89 s: total 1.11 s.
    let (steps, _) = run(&mut g, 1_000_000, 10_000, |_, _| {});
    assert!((1110..=1112).contains(&steps), "{steps}");
}

#[test]
fn c044_change_set_immediately_replans_mid_move() {
    let l = limits();
    for (first, second) in [
        (10 << 20, 20 << 20),
        (10 << 20, 3 << 20),
        (10 << 20, -(5 << 20)),
        (1 << 20, 0),
    ] {
        let mut g = ProfileGenerator::new(0);
        g.move_to(PositionTarget::Absolute(first), l, SetMode::Immediate)
            .unwrap();
        let mut check = limit_checker(l, DT);
        for _ in 0..100 {
            let s = g.step(DT);
            assert!(!s.done);
        }
        assert_eq!(
            g.move_to(PositionTarget::Absolute(second), l, SetMode::Immediate),
            Ok(true)
        );
        assert_eq!(g.target(), second);
        let (_, last) = run(&mut g, DT, 400_000, &mut check);
        assert_eq!(last.position, second, "{first} → {second}");
    }
}

#[test]
fn c044_same_target_again_while_decelerating_does_not_reverse() {
    let l = limits();
    let mut g = ProfileGenerator::new(0);
    g.move_to(PositionTarget::Absolute(1 << 20), l, SetMode::Immediate)
        .unwrap();
    let mut n = 0;
    loop {
        let s = g.step(DT);
        n += 1;
        if n % 7 == 0 {
            g.move_to(PositionTarget::Absolute(1 << 20), l, SetMode::Immediate)
                .unwrap();
        }
        assert!(s.position <= 1 << 20);
        if s.done {
            assert_eq!(s.position, 1 << 20);
            break;
        }
        assert!(n < 100_000);
    }
}

#[test]
fn c043_new_target_refused_while_moving_without_bit5() {
    let l = limits();
    let mut g = ProfileGenerator::new(0);
    assert_eq!(
        g.move_to(PositionTarget::Absolute(1 << 20), l, SetMode::WhenStandstill),
        Ok(true)
    );
    g.step(DT);
    assert_eq!(
        g.move_to(PositionTarget::Absolute(5 << 20), l, SetMode::WhenStandstill),
        Ok(false)
    );
    assert_eq!(g.target(), 1 << 20);
    let (_, last) = run(&mut g, DT, 100_000, |_, _| {});
    assert_eq!(last.position, 1 << 20);
    assert_eq!(
        g.move_to(PositionTarget::Absolute(5 << 20), l, SetMode::WhenStandstill),
        Ok(true)
    );
    let (_, last) = run(&mut g, DT, 100_000, |_, _| {});
    assert_eq!(last.position, 5 << 20);
}

#[test]
fn c041_zero_distance_move_is_done_at_once() {
    let mut g = ProfileGenerator::new(42);
    g.move_to(PositionTarget::Absolute(42), limits(), SetMode::Immediate)
        .unwrap();
    assert!(g.is_standstill());
    let s = g.step(DT);
    assert!(s.done);
    assert_eq!(s.position, 42);
}

#[test]
fn c046_additive_moves_from_last_target() {
    let l = limits();
    let mut g = ProfileGenerator::new(1000);
    g.move_to(PositionTarget::Absolute(2000), l, SetMode::Immediate)
        .unwrap();
    // Interrupted after a few cycles: the next additive move still counts
    // from the last target 2000.
    g.step(DT);
    g.move_to(PositionTarget::Additive(500), l, SetMode::Immediate)
        .unwrap();
    assert_eq!(g.target(), 2500);
    let (_, last) = run(&mut g, DT, 100_000, |_, _| {});
    assert_eq!(last.position, 2500);
    for _ in 0..10 {
        g.move_to(PositionTarget::Additive(-3), l, SetMode::WhenStandstill)
            .unwrap();
        run(&mut g, DT, 100_000, |_, _| {});
    }
    assert_eq!(g.step(DT).position, 2470);
}

#[test]
fn c047_relative_moves_from_actual_position() {
    let l = limits();
    let mut g = ProfileGenerator::new(1000);
    g.move_to(
        PositionTarget::Relative {
            distance: -700,
            actual: 995,
        },
        l,
        SetMode::Immediate,
    )
    .unwrap();
    assert_eq!(g.target(), 295);
    let (_, last) = run(&mut g, DT, 100_000, |_, _| {});
    assert_eq!(last.position, 295);
}

#[test]
fn c055_pv_reaches_target_velocity_within_limits() {
    let l = limits();
    let mut g = ProfileGenerator::new(i32::MAX - 10);
    let mut check = limit_checker(l, DT);
    let mut prev = g.step(DT);
    for (vt, want) in [
        (1.0e7f32, 1.0e7f32),
        (-5.0e6, -5.0e6),
        (1.0e9, l.velocity), // capped at the limit
        (0.0, 0.0),
    ] {
        g.run_velocity(vt, l).unwrap();
        let mut reached = 0;
        for _ in 0..40_000 {
            let s = g.step(DT);
            check(&prev, &s);
            prev = s;
            if s.velocity == want {
                reached += 1;
                if reached > 10 {
                    break;
                }
            }
        }
        assert_eq!(prev.velocity, want);
        assert_eq!(prev.acceleration, 0.0);
    }
    assert!(g.is_standstill());
    assert!(g.step(DT).done);
}

#[test]
fn c055_pv_cruise_position_keeps_exact_pace() {
    // 1000.5 inc/s for 2000 s of 1 ms steps: 2 001 000 increments.
    let l = ProfileLimits {
        velocity: 1.0e6,
        acceleration: 1.0e12,
        deceleration: 1.0e12,
        jerk: f32::INFINITY,
    };
    let mut g = ProfileGenerator::new(0);
    g.take_over(0, 1000.5);
    g.run_velocity(1000.5, l).unwrap();
    let mut last = 0;
    for _ in 0..2_000_000 {
        last = g.step(1_000_000).position;
    }
    assert_eq!(last, 2_001_000);
}

#[test]
fn c010_quick_stop_brakes_on_its_own_deceleration() {
    let l = limits();
    let mut g = ProfileGenerator::new(0);
    g.move_to(PositionTarget::Absolute(1 << 30), l, SetMode::Immediate)
        .unwrap();
    let mut s = g.step(DT);
    for _ in 0..8000 {
        s = g.step(DT);
    }
    let v0 = f64::from(s.velocity);
    assert!((v0 - f64::from(l.velocity)).abs() < 1.0, "cruising {v0}");
    // Quick stop 6085h = 2e9 inc/s², no jerk limit.
    let qs = 2.0e9f32;
    g.stop(qs, f32::INFINITY).unwrap();
    let mut steps = 0;
    let start = s.position;
    let (n, last) = run(&mut g, DT, 100_000, |p, s| {
        steps += 1;
        assert!(f64::from(s.acceleration).abs() <= f64::from(qs) * 1.000_001);
        assert!(s.position >= p.position);
    });
    // t = v/d = 26.2 ms = 105 cycles; distance v²/2d.
    let t = v0 / f64::from(qs);
    assert!((n as f64 - t / 250e-6).abs() <= 2.0, "{n}");
    let dist = v0 * v0 / (2.0 * f64::from(qs));
    assert!((f64::from(last.position - start) - dist).abs() < v0 * 250e-6 + 1.0);
    assert!(g.is_standstill());
    assert_eq!(g.target(), 1 << 30);
}

#[test]
fn c010_halt_with_jerk_limited_ramp() {
    let l = limits();
    let mut g = ProfileGenerator::new(0);
    g.run_velocity(-3.0e7, l).unwrap();
    for _ in 0..2000 {
        g.step(DT);
    }
    // Stop while still accelerating or at speed, with 6084h and jerk.
    g.stop(l.deceleration, l.jerk).unwrap();
    let mut check = limit_checker(l, DT);
    let (_, last) = run(&mut g, DT, 100_000, |p, s| {
        check(p, s);
        assert!(s.position <= p.position);
    });
    assert_eq!(last.velocity, 0.0);
    // Stop at standstill is a no-op.
    g.stop(1.0, 1.0).unwrap();
    assert!(g.step(DT).done);
}

#[test]
fn c049_invalid_limits_refused() {
    let mut g = ProfileGenerator::new(0);
    let t = PositionTarget::Absolute(1);
    let base = limits();
    for (l, e) in [
        (
            ProfileLimits {
                velocity: 0.0,
                ..base
            },
            ProfileError::Velocity,
        ),
        (
            ProfileLimits {
                velocity: -1.0,
                ..base
            },
            ProfileError::Velocity,
        ),
        (
            ProfileLimits {
                velocity: f32::INFINITY,
                ..base
            },
            ProfileError::Velocity,
        ),
        (
            ProfileLimits {
                acceleration: 0.0,
                ..base
            },
            ProfileError::Acceleration,
        ),
        (
            ProfileLimits {
                acceleration: f32::NAN,
                ..base
            },
            ProfileError::Acceleration,
        ),
        (
            ProfileLimits {
                deceleration: -5.0,
                ..base
            },
            ProfileError::Deceleration,
        ),
        (ProfileLimits { jerk: 0.0, ..base }, ProfileError::Jerk),
        (
            ProfileLimits {
                jerk: f32::NAN,
                ..base
            },
            ProfileError::Jerk,
        ),
    ] {
        assert_eq!(g.move_to(t, l, SetMode::Immediate), Err(e));
        assert_eq!(g.run_velocity(1.0, l), Err(e));
    }
    assert_eq!(g.run_velocity(f32::NAN, base), Err(ProfileError::TargetVelocity));
    assert_eq!(g.stop(0.0, 1.0), Err(ProfileError::Deceleration));
    assert_eq!(g.stop(1.0, -1.0), Err(ProfileError::Jerk));
    assert!(g.is_standstill());
}

#[test]
fn c049_random_commands_always_end_exactly() {
    // A small LCG drives random targets, limits and interruptions.
    let mut seed = 0x1234_5678_9abc_def0u64;
    let mut rnd = move || {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (seed >> 33) as u32
    };
    let mut g = ProfileGenerator::new(0);
    for _ in 0..300 {
        let l = ProfileLimits {
            velocity: 1.0e3 + (rnd() % 50_000_000) as f32,
            acceleration: 1.0e4 + (rnd() % 1_000_000_000) as f32,
            deceleration: 1.0e4 + (rnd() % 1_000_000_000) as f32,
            jerk: if rnd() % 5 == 0 {
                f32::INFINITY
            } else {
                1.0e6 + (rnd() % 2_000_000_000) as f32 * 50.0
            },
        };
        let target = rnd().wrapping_mul(rnd()) as i32 >> (rnd() % 24);
        g.move_to(PositionTarget::Absolute(target), l, SetMode::Immediate)
            .unwrap();
        let interrupt = rnd() % 3 == 0;
        let n = rnd() % 2000;
        let mut done = false;
        for _ in 0..n {
            let s = g.step(DT);
            assert!(s.velocity.is_finite() && s.acceleration.is_finite());
            if s.done {
                assert_eq!(s.position, target);
                done = true;
                break;
            }
        }
        if interrupt && !done {
            if rnd() % 2 == 0 {
                g.stop(l.deceleration, l.jerk).unwrap();
            } else {
                g.run_velocity((rnd() % 1000) as f32 - 500.0, l).unwrap();
            }
            for _ in 0..50 {
                g.step(DT);
            }
        }
    }
    // Finally: a move from wherever it is ends exactly.
    let l = limits();
    g.move_to(PositionTarget::Absolute(-77), l, SetMode::Immediate)
        .unwrap();
    let (_, last) = run(&mut g, DT, 10_000_000, |_, _| {});
    assert_eq!(last.position, -77);
}

/// P-137: a passing move reaches its target at the end velocity without a
/// stop (monotonic velocity never below the end velocity near the target,
/// jerk-limited), then goes on at it; a follow-up move from that state
/// continues gap-free to the second target and stops there.
#[test]
fn p137_move_through_passes_the_target_at_the_end_velocity() {
    let mut g = ProfileGenerator::new(0);
    let l = limits();
    let ve = 20_000_000.0f32;
    g.move_through(3_000_000, ve, l).unwrap();
    assert!(!g.passed());
    let mut last = g.step(DT);
    let mut steps = 0;
    while !g.passed() {
        let s = g.step(DT);
        assert!(s.velocity > 0.0, "no stop on the way: {s:?}");
        assert!(s.position >= last.position);
        last = s;
        steps += 1;
        assert!(steps < 100_000);
    }
    // passed within one cycle's travel at the end velocity
    let step = (ve as f64 * DT as f64 * 1e-9) as i32 + 2;
    assert!(
        last.position >= 3_000_000 - step && last.position <= 3_000_000 + step,
        "{last:?}"
    );
    assert!((last.velocity - ve).abs() < 1.0, "{last:?}");
    let cruise = g.step(DT);
    assert_eq!(cruise.velocity, ve);
    assert!(!cruise.done);
    // the follow-up: from the cruising state to the second target, no gap
    g.move_to(PositionTarget::Absolute(6_000_000), l, SetMode::Immediate)
        .unwrap();
    assert!(!g.passed(), "a new command clears passed");
    let (_, end) = run(&mut g, DT, 100_000, |p, s| {
        assert!(s.position >= p.position, "no reversal: {p:?} → {s:?}");
    });
    assert_eq!(end.position, 6_000_000);
}

/// P-137: an end velocity that cannot be reached within the distance, or
/// an end velocity of 0, gives an ordinary move that stops on the target.
#[test]
fn p137_unreachable_or_zero_end_velocity_stops_on_the_target() {
    for (target, ve) in [(1_000, 50_000_000.0f32), (2_000_000, 0.0)] {
        let mut g = ProfileGenerator::new(0);
        let l = ProfileLimits {
            acceleration: 1.0e6,
            ..limits()
        };
        g.move_through(target, ve, l).unwrap();
        let (_, end) = run(&mut g, DT, 1_000_000, |_, _| {});
        assert_eq!(end.position, target);
        assert!(!g.passed());
    }
}

#[test]
fn reset_mid_move_behaves_as_a_new_generator() {
    // `reset` keeps the old plan's memory (issue 36) but nothing of it may
    // show: from a reset mid-move, mid-stop or mid-cruise every command and
    // step gives what a new generator at the same position gives
    let l = limits();
    let starts: [fn(&mut ProfileGenerator); 3] = [
        |g| {
            g.move_to(PositionTarget::Absolute(900_000), limits(), SetMode::Immediate)
                .unwrap();
        },
        |g| {
            g.run_velocity(-2.0e6, limits()).unwrap();
        },
        |g| {
            g.move_to(PositionTarget::Absolute(-400_000), limits(), SetMode::Immediate)
                .unwrap();
            for _ in 0..40 {
                g.step(DT);
            }
            g.stop(5.0e8, 1.0e11).unwrap();
        },
    ];
    for start in starts {
        let mut g = ProfileGenerator::new(1000);
        start(&mut g);
        for _ in 0..25 {
            g.step(DT);
        }
        g.reset(-7777);
        let mut fresh = ProfileGenerator::new(-7777);
        assert!(g.is_standstill());
        assert_eq!(g.target(), fresh.target());
        assert_eq!(g.current(), fresh.current());
        assert_eq!(g.step(DT), fresh.step(DT));
        g.move_to(PositionTarget::Additive(3000), l, SetMode::Immediate)
            .unwrap();
        fresh
            .move_to(PositionTarget::Additive(3000), l, SetMode::Immediate)
            .unwrap();
        for _ in 0..2000 {
            let (a, b) = (g.step(DT), fresh.step(DT));
            assert_eq!(a, b);
            if a.done {
                break;
            }
        }
    }
}
