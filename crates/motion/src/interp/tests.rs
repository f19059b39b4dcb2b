use super::*;

fn config(order: InterpolationOrder, n: u32) -> InterpolatorConfig {
    InterpolatorConfig {
        ratio: CycleRatio::new(n * 125_000, 125_000).unwrap(),
        order,
        feedforward: FeedforwardSource::Internal,
        velocity_feedforward_percent: 100.0,
        max_extrapolation: Nanos::from_ms(3),
    }
}

const ORDERS: [InterpolationOrder; 3] = [
    InterpolationOrder::Linear,
    InterpolationOrder::Quadratic,
    InterpolationOrder::Cubic,
];

fn sp(position: i32) -> Option<MasterSetpoint> {
    Some(MasterSetpoint {
        position,
        velocity_offset: 0.0,
    })
}

/// round(x) with x = num/den, half up, as the interpolator rounds.
fn round_div(num: i128, den: i128) -> i128 {
    (2 * num + den).div_euclid(2 * den)
}

/// Runs a constant-velocity ramp of `delta_num/delta_den` increments per
/// master cycle from `start` and checks every control-cycle output
/// against the exact trajectory rounded to whole increments.
fn check_constant_velocity(order: InterpolationOrder, n: u32, start: i32, per_master: i64) {
    let mut ip = FineInterpolator::new(config(order, n)).unwrap();
    ip.start(start);
    let n = i64::from(n);
    // Master positions m·per_master from `start`, exact in i128.
    let mut prev_exact: i128 = 0;
    for m in 1..200i64 {
        let target = i128::from(m * per_master);
        let pos = (i128::from(start) + target) as i64 as i32; // wrap
        for k in 1..=n {
            let out = ip.cycle(if k == 1 { sp(pos) } else { None }).unwrap().position;
            // Exact trajectory between the previous and this set-point.
            let exact_rel = prev_exact * i128::from(n) + (target - prev_exact) * i128::from(k);
            let rounded = round_div(exact_rel, i128::from(n));
            let want = (i128::from(start) + rounded) as i64 as i32;
            // The first segments of quadratic/cubic start from the
            // standstill history; constant velocity holds from m ≥ 4.
            if m >= 4 {
                assert_eq!(out, want, "{order:?} N={n} m={m} k={k}");
            }
            if k == n && m >= 2 {
                assert_eq!(out, pos, "{order:?} ends on the set-point");
            }
        }
        prev_exact = target;
    }
}

#[test]
fn c115_linear_exact_at_constant_velocity() {
    for n in [1, 2, 3, 4, 7, 8, 16] {
        for per_master in [0, 1, 5, 1000, 1_048_576 / 1000, -12_345, 7_777_777] {
            check_constant_velocity(InterpolationOrder::Linear, n, 17, per_master);
        }
    }
}

#[test]
fn c115_quadratic_and_cubic_exact_at_constant_velocity() {
    for order in [InterpolationOrder::Quadratic, InterpolationOrder::Cubic] {
        for n in [1, 3, 4, 8, 13] {
            for per_master in [0, 1, 3, 1049, -99_991, 50_000_000] {
                check_constant_velocity(order, n, -5, per_master);
            }
        }
    }
}

#[test]
fn c115_linear_distributes_remainder_evenly() {
    // 10 increments over N = 4: steps 3,2,3,2 (round half up), never
    // differing by more than one.
    let mut ip = FineInterpolator::new(config(InterpolationOrder::Linear, 4)).unwrap();
    ip.start(0);
    let mut last = 0;
    let mut steps = [0; 4];
    for (k, step) in steps.iter_mut().enumerate() {
        let out = ip.cycle(if k == 0 { sp(10) } else { None }).unwrap();
        *step = out.position - last;
        last = out.position;
    }
    assert_eq!(steps, [3, 2, 3, 2]);
    assert_eq!(last, 10);
}

#[test]
fn c115_wraps_around_i32_max_exactly() {
    for order in ORDERS {
        // Constant velocity through i32::MAX → i32::MIN.
        check_constant_velocity(order, 8, i32::MAX - 50 * 7_777_777, 7_777_777);
        check_constant_velocity(order, 5, i32::MIN + 30 * 1_000_003, -1_000_003);
    }
}

#[test]
fn c115_wrap_around_output_is_monotone() {
    for order in ORDERS {
        let mut ip = FineInterpolator::new(config(order, 8)).unwrap();
        let start = i32::MAX - 100_000;
        ip.start(start);
        let mut last = start;
        for m in 1..40i32 {
            let pos = start.wrapping_add(m.wrapping_mul(9_999));
            for k in 0..8 {
                let out = ip.cycle(if k == 0 { sp(pos) } else { None }).unwrap();
                let step = out.position.wrapping_sub(last);
                assert!((0..=9_999).contains(&step), "{order:?} step {step}");
                last = out.position;
            }
            assert_eq!(last, pos);
        }
    }
}

#[test]
fn c116_extrapolates_missing_setpoint_with_last_increment() {
    for order in ORDERS {
        let mut ip = FineInterpolator::new(config(order, 4)).unwrap();
        ip.start(0);
        for m in 1..=6 {
            for k in 0..4 {
                let out = ip.cycle(if k == 0 { sp(m * 400) } else { None }).unwrap();
                assert!(!out.extrapolating);
            }
        }
        // One master cycle without a set-point: continue with 100/step.
        for k in 1..=4 {
            let out = ip.cycle(None).unwrap();
            assert!(out.extrapolating);
            assert_eq!(out.position, 2400 + 100 * k, "{order:?}");
        }
        // The set-point returns: extrapolation ends.
        let out = ip.cycle(sp(3200)).unwrap();
        assert!(!out.extrapolating);
        for _ in 1..4 {
            ip.cycle(None).unwrap();
        }
    }
}

/// C-116 with a master that misses set-points again and again (the soak
/// test's SOEM master on a loaded machine sent one frame every 3–7 ms for a
/// while): each extrapolation continues with the master's own increment per
/// master cycle (between the last two set-points that arrived), not with the
/// step from the last extrapolated point to the set-point that ended it.
/// That step is the correction of the last extrapolation: continuing with it
/// multiplied the error by −(gap − 1) at every gap, and the drive's demand
/// ran away by revolutions into a limit switch.
#[test]
fn c116_repeated_gaps_extrapolate_with_the_masters_increment() {
    for order in ORDERS {
        for n in [1, 4] {
            for gap in [2i64, 3, 4] {
                let mut ip = FineInterpolator::new(config(order, n)).unwrap();
                ip.start(0);
                // an accelerating master trajectory, 5·m² increments at master
                // cycle m (second difference 10); a set-point every cycle for a
                // start, then only every `gap`-th one (the gaps within I423)
                let at = |m: i64| 5 * m * m;
                let mut worst = 0i64;
                for m in 1..=80i64 {
                    let give = m <= 8 || m % gap == 0;
                    for k in 0..n {
                        let setpoint = (give && k == 0).then(|| at(m) as i32);
                        let out = ip.cycle(setpoint.and_then(sp)).unwrap();
                        if m > 8 && k + 1 == n {
                            worst = worst.max((i64::from(out.position) - at(m)).abs());
                        }
                    }
                }
                // extrapolating a gap with the master's increment misses by the
                // acceleration: 10·gap² at most
                assert!(
                    worst <= 10 * gap * gap,
                    "{order:?} N={n} gap {gap}: {worst} increments off the trajectory"
                );
            }
        }
    }
}

#[test]
fn c117_extrapolates_missing_setpoint_then_faults() {
    // I423 = 3 ms, master 1 ms (N = 8): 3 extrapolated master cycles are
    // tolerated, the 4th is longer than I423.
    for order in ORDERS {
        let mut ip = FineInterpolator::new(config(order, 8)).unwrap();
        ip.start(1000);
        for k in 0..8 {
            ip.cycle(if k == 0 { sp(1800) } else { None }).unwrap();
        }
        for _ in 0..3 * 8 {
            assert!(ip.cycle(None).unwrap().extrapolating);
        }
        let err = ip.cycle(None).unwrap_err();
        assert_eq!(err, InterpolationFault::ExtrapolationOverrun);
        assert_eq!(err.event(), Event { number: 78, cause: 3 });
        assert!(ip.is_faulted());
        // Latched: a late set-point does not clear it.
        assert!(ip.cycle(sp(0)).is_err());
        ip.start(0);
        assert!(!ip.is_faulted());
        assert_eq!(ip.cycle(None).unwrap().position, 0);
    }
}

#[test]
fn c117_jitter_within_i423_recovers() {
    let mut ip = FineInterpolator::new(config(InterpolationOrder::Linear, 4)).unwrap();
    ip.start(0);
    // Set-points every master cycle, every third one missing.
    for m in 1..=30 {
        for k in 0..4 {
            let give = k == 0 && m % 3 != 0;
            ip.cycle(if give { sp(m * 40) } else { None }).unwrap();
        }
    }
}

#[test]
fn c117_no_fault_before_first_setpoint() {
    let mut ip = FineInterpolator::new(config(InterpolationOrder::Cubic, 4)).unwrap();
    ip.start(77);
    for _ in 0..1000 {
        let out = ip.cycle(None).unwrap();
        assert_eq!(out.position, 77);
        assert!(!out.extrapolating);
    }
}

#[test]
fn c117_i423_zero_faults_on_first_missing() {
    let mut cfg = config(InterpolationOrder::Linear, 2);
    cfg.max_extrapolation = Nanos::ZERO;
    let mut ip = FineInterpolator::new(cfg).unwrap();
    ip.start(0);
    ip.cycle(sp(10)).unwrap();
    ip.cycle(None).unwrap();
    assert!(ip.cycle(None).is_err());
}

#[test]
fn c119_internal_feedforward_from_setpoints() {
    for order in ORDERS {
        let mut ip = FineInterpolator::new(config(order, 8)).unwrap();
        ip.start(0);
        // 1000 increments per 1 ms master cycle = 1e6 inc/s.
        let mut out = None;
        for m in 1..=10 {
            for k in 0..8 {
                out = Some(ip.cycle(if k == 0 { sp(m * 1000) } else { None }).unwrap());
            }
        }
        let out = out.unwrap();
        assert!((out.velocity_feedforward - 1.0e6).abs() < 1.0, "{order:?}");
        assert!(out.acceleration_feedforward.abs() < 1.0);
    }
}

/// The feedforward of the general polynomial (the path before the
/// straight-segment shortcut), from the interpolator's differences.
fn general_feedforward(ip: &FineInterpolator) -> (f32, f32) {
    let master_s = ip.config.ratio.master_ns() as f32 * 1e-9;
    let t = ip.k as f32 / ip.config.ratio.n() as f32;
    let d1 = float::from_i64(ip.d1);
    let d2 = float::from_i64(ip.d2);
    let d3 = float::from_i64(ip.d3);
    let v = d1 + (2.0 * t - 1.0) * 0.5 * d2 + (3.0 * t * t - 1.0) / 6.0 * d3;
    let a = d2 + t * d3;
    (
        v / master_s * (ip.config.velocity_feedforward_percent * 0.01),
        a / (master_s * master_s),
    )
}

#[test]
fn c119_internal_feedforward_unchanged_on_straight_segment() {
    // constant velocity (straight segments) and then a ramp (not straight),
    // every order, N = 1, 3, 8, I25 = 100 % and 40 %: the output equals
    // the general polynomial's bit for bit
    for order in ORDERS {
        for n in [1, 3, 8] {
            for weight in [100.0, 40.0] {
                let mut c = config(order, n);
                c.velocity_feedforward_percent = weight;
                let mut ip = FineInterpolator::new(c).unwrap();
                ip.start(-5_000);
                let (mut pos, mut straight) = (-5_000i32, 0);
                for m in 1..=40i32 {
                    pos += if m <= 20 { 1_234 } else { 1_234 + 50 * (m - 20) };
                    for k in 0..n {
                        let out = ip.cycle(if k == 0 { sp(pos) } else { None }).unwrap();
                        let (v, a) = general_feedforward(&ip);
                        assert_eq!(
                            out.velocity_feedforward.to_bits(),
                            v.to_bits(),
                            "{order:?} N={n} m={m}"
                        );
                        assert_eq!(
                            out.acceleration_feedforward.to_bits(),
                            a.to_bits(),
                            "{order:?} N={n} m={m}"
                        );
                        if ip.d2 == 0 && ip.d3 == 0 {
                            straight += 1;
                        }
                    }
                }
                // both paths ran (linear: only straight segments)
                let linear = order == InterpolationOrder::Linear;
                assert!(straight > 0 && (linear || straight < 40 * n), "{order:?} N={n}");
            }
        }
    }
}

#[test]
fn c119_internal_quadratic_feedforward_tracks_acceleration() {
    // x = a/2·t² sampled every 1 ms with a = 2e9 inc/s² (x = 1000·m²):
    // at the end of segment m the output is on x(m ms) with velocity
    // a·m·1 ms.
    let mut ip = FineInterpolator::new(config(InterpolationOrder::Quadratic, 8)).unwrap();
    ip.start(0);
    let mut out = None;
    for m in 1..=20i32 {
        for k in 0..8 {
            out = Some(ip.cycle(if k == 0 { sp(m * m * 1000) } else { None }).unwrap());
        }
    }
    let out = out.unwrap();
    assert_eq!(out.position, 400_000);
    assert!((out.velocity_feedforward - 2.0e9 * 0.020).abs() < 100.0);
    assert!((out.acceleration_feedforward - 2.0e9).abs() < 1.0e4);
}

#[test]
fn c118_external_feedforward_uses_60b1_weighted_by_i25() {
    let mut cfg = config(InterpolationOrder::Linear, 4);
    cfg.feedforward = FeedforwardSource::External;
    cfg.velocity_feedforward_percent = 80.0;
    let mut ip = FineInterpolator::new(cfg).unwrap();
    ip.start(0);
    let mut out = None;
    for m in 1..=5 {
        for k in 0..4 {
            let s = MasterSetpoint {
                position: m * 10,
                velocity_offset: 5000.0,
            };
            out = Some(ip.cycle(if k == 0 { Some(s) } else { None }).unwrap());
        }
    }
    let out = out.unwrap();
    assert!((out.velocity_feedforward - 4000.0).abs() < 1e-3);
    assert_eq!(out.position, 50);
    i425_maps(&[
        (1, Ok((InterpolationOrder::Linear, FeedforwardSource::External))),
        (
            3,
            Ok((InterpolationOrder::Quadratic, FeedforwardSource::External)),
        ),
    ]);
}

#[test]
fn c119_i425_maps_internal_orders() {
    i425_maps(&[
        (0, Ok((InterpolationOrder::Linear, FeedforwardSource::Internal))),
        (
            4,
            Ok((InterpolationOrder::Quadratic, FeedforwardSource::Internal)),
        ),
        (5, Ok((InterpolationOrder::Cubic, FeedforwardSource::Internal))),
        (2, Err(ConfigError::UnknownI425(2))),
        (6, Err(ConfigError::UnknownI425(6))),
    ]);
}

/// What I425 selects: the interpolation order and the feed-forward source.
type I425 = Result<(InterpolationOrder, FeedforwardSource), ConfigError>;

/// I425 → interpolation order and feed-forward source (or the refusal), each case.
fn i425_maps(cases: &[(u8, I425)]) {
    for &(i425, want) in cases {
        assert_eq!(from_i425(i425), want, "I425 = {i425}");
    }
}

#[test]
fn c120_i25_zero_disables_velocity_feedforward() {
    let mut cfg = config(InterpolationOrder::Cubic, 4);
    cfg.velocity_feedforward_percent = 0.0;
    let mut ip = FineInterpolator::new(cfg).unwrap();
    ip.start(0);
    for m in 1..=5 {
        for k in 0..4 {
            let out = ip.cycle(if k == 0 { sp(m * 1000) } else { None }).unwrap();
            assert_eq!(out.velocity_feedforward, 0.0);
        }
    }
    cfg.velocity_feedforward_percent = 101.0;
    assert!(FineInterpolator::new(cfg).is_err());
    cfg.velocity_feedforward_percent = f32::NAN;
    assert!(FineInterpolator::new(cfg).is_err());
}

#[test]
fn c115_csv_velocity_interpolated_linearly() {
    let ratio = CycleRatio::new(1_000_000, 250_000).unwrap();
    let mut vi = VelocityInterpolator::new(ratio, Nanos::from_ms(2));
    vi.start(0.0);
    let out: [f32; 4] = core::array::from_fn(|k| {
        vi.cycle(if k == 0 { Some(1000.0) } else { None })
            .unwrap()
            .velocity
    });
    assert_eq!(out, [250.0, 500.0, 750.0, 1000.0]);
    // Missing: hold, then fault after I423 = 2 ms.
    for _ in 0..8 {
        let o = vi.cycle(None).unwrap();
        assert_eq!(o.velocity, 1000.0);
        assert!(o.extrapolating);
    }
    assert_eq!(vi.cycle(None), Err(InterpolationFault::ExtrapolationOverrun));
}
