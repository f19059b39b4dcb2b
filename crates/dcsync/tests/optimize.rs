//! A287 DC-Sync optimisation (spec §11.8; E-120..E-124).

use dcsync::{FrameSample, OptimizeRequest, OptimizeResult, Optimizer};

const US: i64 = 1_000;

fn request(a292_ns: i32) -> OptimizeRequest {
    OptimizeRequest {
        safe_op_or_op: true,
        dc_sync: true,
        master_cycle_ns: 1_000_050,
        a291_ns: 1_000_000,
        sync0_cycle_ns: 1_000_000,
        a150_ns: 1_000_000,
        a292_ns,
        guard_ns: 1_000,
    }
}

/// Frame −30 µs..−20 µs (±jitter), cycle start at −A292, Rx 5 µs and Tx
/// `tx_us` after the start.
fn feed(opt: &mut Optimizer, n: u32, a292_ns: i32, frame_len: i64, frame_jitter: i64, tx_us: u32) {
    let mut x: u64 = 0x1234_5678;
    for _ in 0..n {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let j = if frame_jitter == 0 {
            0
        } else {
            (x % (2 * frame_jitter as u64 + 1)) as i64 - frame_jitter
        };
        let sof = -30 * US + j - (frame_len - 10 * US);
        opt.record(&FrameSample {
            sof_ns: sof,
            eof_ns: sof + frame_len,
            cycle_start_ns: -i64::from(a292_ns) + (x % 201) as i64 - 100,
            rx_after_start_ns: 5_000,
            tx_after_start_ns: tx_us * 1000,
        });
    }
}

#[test]
fn e121_not_executable_gives_2_and_keeps_a292() {
    for req in [
        OptimizeRequest {
            safe_op_or_op: false,
            ..request(-100_000)
        },
        OptimizeRequest {
            dc_sync: false,
            ..request(-100_000)
        },
        OptimizeRequest {
            master_cycle_ns: 2_000_000,
            ..request(-100_000)
        },
    ] {
        let mut opt = Optimizer::new();
        opt.start(req);
        assert_eq!(opt.result_code(), 2);
        let o = opt.outcome().unwrap();
        assert_eq!(o.result, OptimizeResult::NotExecutable);
        assert_eq!((o.a292_min_ns, o.a292_max_ns), (-100_000, -100_000));
    }
}

#[test]
fn e124_progress_over_1000_drive_cycles() {
    let mut opt = Optimizer::new();
    assert_eq!((opt.progress_percent(), opt.result_code()), (0, 0));
    opt.start(request(-100_000));
    assert!(opt.is_running());
    feed(&mut opt, 500, -100_000, 10 * US, 0, 50);
    assert_eq!((opt.progress_percent(), opt.result_code()), (50, 1));
    feed(&mut opt, 499, -100_000, 10 * US, 0, 50);
    assert_eq!(opt.progress_percent(), 99);
    feed(&mut opt, 1, -100_000, 10 * US, 0, 50);
    assert_eq!(opt.progress_percent(), 100);
    assert!(!opt.is_running());

    // k = 4: 1000 drive cycles are 250 SYNC0 cycles.
    let mut opt = Optimizer::new();
    opt.start(OptimizeRequest {
        sync0_cycle_ns: 2_000_000,
        a150_ns: 500_000,
        master_cycle_ns: 2_000_000,
        a291_ns: 2_000_000,
        ..request(-100_000)
    });
    feed(&mut opt, 125, -100_000, 10 * US, 0, 50);
    assert_eq!(opt.progress_percent(), 50);
    feed(&mut opt, 125, -100_000, 10 * US, 0, 50);
    assert_eq!(opt.progress_percent(), 100);
}

#[test]
fn e120_e123_in_range_gives_7_and_the_a292_range() {
    let mut opt = Optimizer::new();
    opt.start(request(-100_000));
    feed(&mut opt, 1000, -100_000, 10 * US, 0, 50);
    let o = opt.outcome().unwrap();
    assert_eq!(o.result, OptimizeResult::InRange);
    assert_eq!(opt.result_code(), 7);
    // Rx_min = 100 µs − 0.1 µs + 5 µs; EoF_max = −20 µs; Tx_max = 150.1 µs;
    // SoF_min = −30 µs. A292 ≤ Rx_min − (EoF_max + guard) − 100 µs... :
    // upper end puts Rx_min at EoF + 1 µs, lower end puts Tx_max at the
    // next SoF − 1 µs.
    assert!((o.a292_max_ns - 24 * US).abs() <= 200, "{o:?}");
    assert!((o.a292_min_ns + 919 * US).abs() <= 200, "{o:?}");
    assert!(o.a292_min_ns <= -100_000 && -100_000 <= o.a292_max_ns);
    assert_eq!(o.end_of_frame_to_sync_ns, 20 * US);
    assert_eq!(o.frame_duration_ns, 10 * US);
}

#[test]
fn e123_touching_the_frame_gives_8() {
    // Cycle start 25 µs before SYNC0: Rx at −20 µs, on the frame's end.
    let mut opt = Optimizer::new();
    opt.start(request(25_000));
    feed(&mut opt, 1000, 25_000, 10 * US, 0, 50);
    let o = opt.outcome().unwrap();
    assert_eq!(o.result, OptimizeResult::Improvable);
    assert_eq!(opt.result_code(), 8);
    assert!(o.a292_max_ns < 25_000);
    assert!((o.a292_max_ns - 24 * US).abs() <= 200, "{o:?}");
    assert!((o.a292_min_ns + 919 * US).abs() <= 200, "{o:?}");
}

#[test]
fn e122_failures_3_to_6_keep_a292() {
    // Frame 950 µs with ±10 µs start jitter: no room, frame jitter.
    let cases = [
        (950 * US, 10 * US, 50, OptimizeResult::FrameJitter),
        // Frame 400 µs, runtime 600 µs: application runtime.
        (400 * US, 0, 605, OptimizeResult::Runtime),
        // Frame 960 µs, runtime 45 µs: frame length.
        (960 * US, 0, 50, OptimizeResult::FrameLength),
    ];
    for (len, jit, tx, want) in cases {
        let mut opt = Optimizer::new();
        opt.start(request(-100_000));
        feed(&mut opt, 1000, -100_000, len, jit, tx);
        let o = opt.outcome().unwrap();
        assert_eq!(o.result, want, "{o:?}");
        assert!(!o.result.is_success());
        assert_eq!((o.a292_min_ns, o.a292_max_ns), (-100_000, -100_000));
    }
    // Drive jitter: cycle start spread by ±15 µs, frame 950 µs.
    let mut opt = Optimizer::new();
    opt.start(request(-20_000));
    for i in 0..1000i64 {
        opt.record(&FrameSample {
            sof_ns: -960 * US,
            eof_ns: -10 * US,
            cycle_start_ns: 20 * US + (i % 31 - 15) * US,
            rx_after_start_ns: 1_000,
            tx_after_start_ns: 20_000,
        });
    }
    assert_eq!(opt.outcome().unwrap().result, OptimizeResult::DriveJitter);
    assert_eq!(opt.result_code(), 4);
}
