//! `hil-sim demo --fieldbus profinet`'s sequence (the Example Function
//! block against the simulated PROFINET drive, in-process, simulated time):
//! each phase's outcome. One run serves every test (it is deterministic;
//! one test runs it a second time and compares).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use hil_sim::electrical::PlantModel;
use hil_sim::fb::pkw::Outcome;
use hil_sim::fb::sequence::{self, milli_rev_to_inc, Observer, Phase, Report, Sample, CHAIN, SPEED_RPM};
use nanos::Nanos;
use std::sync::OnceLock;

/// Every end position within one PROFINET position unit (1/1000 rev =
/// 1049 increments): the finest target a controller can command through
/// PNU 1001.0, and nearly 3 times tighter than the target window that
/// `target_reached` alone guarantees (PNU 1271 = I22, this drive's 1° =
/// 2 913 inc; the manual's default is 10°, docs/conformance.md P-158).
const END_POSITION_TOLERANCE_INC: i64 = 1049;

#[derive(Default)]
struct Collect {
    lines: Vec<String>,
    phases: Vec<Phase>,
    samples: usize,
}

impl Observer for Collect {
    fn line(&mut self, _t: Nanos, text: &str) {
        self.lines.push(text.to_string());
    }
    fn phase(&mut self, _t: Nanos, phase: Phase) {
        self.phases.push(phase);
    }
    fn sample(&mut self, _s: &Sample) {
        self.samples += 1;
    }
}

/// The demo's run: the current loop on the electrical plant (its default).
fn run() -> (Report, Collect) {
    let mut c = Collect::default();
    let (report, _) = sequence::run(&mut c, None, PlantModel::Electrical).expect("the exchange runs");
    (report, c)
}

fn shared() -> &'static (Report, Collect) {
    static RUN: OnceLock<(Report, Collect)> = OnceLock::new();
    RUN.get_or_init(run)
}

#[test]
fn every_phase_runs_in_order_and_the_run_is_deterministic() {
    let (r, c) = shared();
    assert_eq!(c.phases, Phase::ALL);
    let ran: Vec<Phase> = r.phases.iter().map(|p| p.phase).collect();
    assert_eq!(ran, Phase::ALL);
    assert_eq!(c.samples as u64, r.cycles, "one sample per controller cycle");
    assert_eq!(r.frames.0, r.cycles, "one output frame per 1 ms cycle");
    assert!(
        r.frames.1 + 20 >= r.cycles,
        "an input frame every cycle: {:?}",
        r.frames
    );
    let (again, c2) = run();
    assert_eq!(&again, r, "the same run twice");
    assert_eq!(c2.lines, c.lines);
}

#[test]
fn p219_the_fb_enables_the_drive_through_soi_rtso_so_op() {
    let (r, c) = shared();
    assert!(r.enabled);
    assert_eq!(r.enable_states, [0x40, 0x01, 0x03, 0x07]);
    for step in [
        "CW1 0x0430 -> 0x0436",
        "CW1 0x0436 -> 0x0437",
        "CW1 0x0437 -> 0x043f",
    ] {
        assert!(c.lines.iter().any(|l| l == step), "{step} printed");
    }
    assert!(c
        .lines
        .iter()
        .any(|l| l.contains("state SO -> OP, drive_is_enabled 0->1")));
}

#[test]
fn p222_homing_on_the_index_pulse_sets_home_valid() {
    let (r, _) = shared();
    assert!(r.home_valid);
    // method 33 makes the index pulse zero; the axis stops just past it
    assert!(r.home_position_inc.abs() < 1 << 14, "{}", r.home_position_inc);
}

#[test]
fn p221_the_appended_chain_and_the_relative_move_end_on_their_targets() {
    let (r, _) = shared();
    assert!(
        !r.early_target_reached,
        "P-105: target_reached only at the chain's end"
    );
    assert_eq!(r.passing_rpm.len(), 2, "both intermediate targets passed");
    for ((rpm, end), (_, _, want)) in r.passing_rpm.iter().zip(CHAIN.iter()) {
        assert_eq!(end, want);
        assert!(
            (rpm - end).abs() * 10 <= *end,
            "passed at {rpm} rpm, end velocity {end}"
        );
    }
    assert_eq!(r.targets.len(), 2);
    assert_eq!(r.targets[0].commanded_inc, milli_rev_to_inc(8000));
    assert_eq!(
        r.targets[1].commanded_inc,
        milli_rev_to_inc(6000),
        "relative to the set-point"
    );
    for t in &r.targets {
        assert!(t.error_inc().abs() <= END_POSITION_TOLERANCE_INC, "{t:?}");
    }
}

#[test]
fn p220_p223_the_speed_segment_runs_at_300_rpm_and_stops() {
    let (r, _) = shared();
    assert_eq!(
        r.speed_mode_actual, 0x08,
        "P-220: telegram E1 selects speed control"
    );
    assert!((r.speed_rpm - SPEED_RPM).abs() <= 3, "{} rpm", r.speed_rpm);
    assert!(r.velo_zero);
    // ZSW1 bit 8 in speed mode is open in the drive (docs/conformance.md
    // P-223): either it comes or the demo reports its absence
    assert!(
        r.velo_reached.is_some() || r.deviations.iter().any(|d| d.starts_with("P-223/P-102")),
        "{:?}",
        r.deviations
    );
}

#[test]
fn p225_jog_moves_each_way() {
    let (r, _) = shared();
    let [pos, neg] = r.jog_inc;
    // 200 rpm for 0.5 s with 1000 rpm/s ramps: well over a revolution
    assert!(pos > 1 << 20, "{pos}");
    assert!(neg < -(1 << 20), "{neg}");
}

#[test]
fn p226_pkw_reads_a_pnu_and_reads_and_writes_a_canopen_object() {
    let (r, _) = shared();
    let get = |label: &str| {
        r.pkw
            .iter()
            .filter(|(l, _)| l == label)
            .map(|(_, o)| *o)
            .collect::<Vec<_>>()
    };
    assert_eq!(get("write 6065h.0"), [Outcome::Done(20_000)]);
    let reads = get("read 6065h.0");
    assert_eq!(reads.len(), 2);
    assert_eq!(reads[1], Outcome::Done(20_000), "read back");
    assert!(matches!(get("read 964.0")[..], [Outcome::Done(_)]));
    assert!(matches!(get("read 1100.0")[..], [Outcome::Done(_)]));
    assert!(matches!(
        get("read 999.0 (no such PNU)")[..],
        [Outcome::Refused(_)]
    ));
    assert!(
        !r.deviations.iter().any(|d| d.starts_with("P-226")),
        "{:?}",
        r.deviations
    );
}

#[test]
fn p215_p227_a_provoked_fault_is_seen_acknowledged_and_the_drive_enables_again() {
    let (r, c) = shared();
    assert!(r.fault_seen, "ZSW1 bit 3");
    assert!(r.disabled_by_fault);
    assert!(r.fault_cleared, "fault_reset (CW1 bit 7 rising edge)");
    assert!(r.re_enabled, "the FB's enable sequence again");
    assert!(c.lines.iter().any(|l| l.contains("state OP -> fault")));
    assert!(c.lines.iter().any(|l| l.contains("state fault -> SOI")));
}

/// The FB against the drive without the demo's script: enable and home
/// (method 34), then the positioning inputs the demo sequence leaves out.
struct Bench {
    ctl: hil_sim::fb::controller::PnController,
    fb: hil_sim::fb::ExampleFb,
    i: hil_sim::fb::FbInputs,
}

impl Bench {
    fn enabled() -> Bench {
        use hil_sim::fb::controller::PnController;
        let ctl = PnController::connect(PnController::drive(), Nanos::from_ms(10), None).unwrap();
        let mut b = Bench {
            ctl,
            fb: hil_sim::fb::ExampleFb::new(),
            i: hil_sim::fb::FbInputs {
                drive_enable: true,
                ..Default::default()
            },
        };
        assert!(b.until(500, |o| o.drive_is_enabled), "enabled");
        // absolute targets need a reference (C-050): method 34, the
        // current position, without a move
        b.i.start_homing = true;
        assert!(b.until(1_000, |o| o.home_valid), "homed");
        b.i.start_homing = false;
        b.run(10);
        b
    }

    fn cycle(&mut self) {
        let t = self.fb.receive_telegram(&self.i);
        let r = self.ctl.exchange(&t).unwrap().map(<[u8]>::to_vec);
        if let (Some(r), true) = (r, self.ctl.fresh()) {
            let _ = self.fb.response(&r, self.i.drive_enable);
        }
    }

    fn until(&mut self, ms: u64, done: impl Fn(&hil_sim::fb::FbOutputs) -> bool) -> bool {
        for _ in 0..ms {
            self.cycle();
            if done(self.fb.outputs()) {
                return true;
            }
        }
        false
    }

    fn run(&mut self, ms: u64) {
        for _ in 0..ms {
            self.cycle();
        }
    }

    fn position(&self) -> i32 {
        self.fb.outputs().position_actual_value
    }

    /// Starts a task to `target` (1/1000 rev) at 1000 rpm.
    fn start(&mut self, target: i32, immediately: bool) {
        self.i.target_position = target;
        self.i.change_immediatly = immediately;
        if !immediately {
            assert!(self.until(5_000, |o| !o.pos_task_ack), "a task can be taken");
        }
        self.i.start_pos = true;
        assert!(self.until(100, |o| o.pos_task_ack), "the start is acknowledged");
        self.i.start_pos = false;
        self.cycle();
    }
}

#[test]
fn p221_intermediate_stop_pauses_and_resumes_the_task() {
    let mut b = Bench::enabled();
    b.start(20_000, false);
    b.run(500);
    assert!(!b.fb.outputs().velo_zero, "moving");
    b.i.intermediate_stop = true;
    assert!(b.until(2_000, |o| o.velo_zero), "stopped (ZSW1 bit 13)");
    let held = b.position();
    b.run(300);
    assert!(
        (b.position() - held).abs() <= 2,
        "held: {held} -> {}",
        b.position()
    );
    assert!(!b.fb.outputs().target_reached);
    b.i.intermediate_stop = false;
    assert!(b.until(20_000, |o| o.target_reached), "the task continues");
    b.run(200);
    assert!((b.position() - 20_000).abs() <= 1, "{}", b.position());
}

#[test]
fn p221_hold_cancels_the_task_without_target_reached() {
    let mut b = Bench::enabled();
    b.start(20_000, false);
    b.run(500);
    b.i.hold = true;
    assert!(b.until(2_000, |o| o.velo_zero), "braked to a stop");
    b.run(300);
    let stopped = b.position();
    assert!(
        stopped < 20_000 - 1_000,
        "cancelled well before the target: {stopped}"
    );
    assert!(!b.fb.outputs().target_reached, "not target reached");
    // releasing hold does nothing (§13.1)
    b.i.hold = false;
    b.run(500);
    assert!(
        (b.position() - stopped).abs() <= 2,
        "{stopped} -> {}",
        b.position()
    );
    assert!(!b.fb.outputs().target_reached);
}

#[test]
fn p221_change_immediately_replaces_the_running_task() {
    let mut b = Bench::enabled();
    b.start(20_000, false);
    b.run(500);
    let at = b.position();
    assert!(at > 0 && at < 20_000, "{at}");
    b.start(2_000, true);
    assert!(b.until(20_000, |o| o.target_reached));
    b.run(200);
    assert!(
        (b.position() - 2_000).abs() <= 1,
        "the new target: {}",
        b.position()
    );
    assert!(b.fb.outputs().target_reached);
}

/// The demo's sequence on a plant the drive does not know (5× the servo's
/// inertia, 3× its friction), without and with its self-tuning phase.
fn mechanics_run(self_tune: bool) -> Report {
    let mut c = Collect::default();
    let options = sequence::Options {
        self_tune,
        mechanics: (5.0, 3.0),
        ..PlantModel::Electrical.into()
    };
    let (report, _) = sequence::run_with(&mut c, None, options).expect("the exchange runs");
    report
}

/// Issue 35 on PROFINET: B44 started and read through the telegram's PKW
/// channel (A75 = 1Fh in ready to switch on, A69 polled, B45…B47 read;
/// E-140/E-141) identifies the unknown plant, and the positioning moves
/// after it follow far closer than with the hand-set defaults: issue 35's
/// goal, at most 500 inc per move (the figures, `cargo bench -p hil-sim
/// --bench selftune`: 403 / 406 inc at B48's 60 Hz), against about 76,000 /
/// 86,000 inc untuned.
#[test]
fn e140_b44_through_pkw_before_the_positioning_moves_cuts_their_following_error() {
    let untuned = mechanics_run(false);
    let tuned = mechanics_run(true);
    assert!(untuned.self_tune.is_none());
    let t = tuned.self_tune.expect("the self-tuning phase ran");
    assert_eq!(t.a69, 0b1111 << 8 | 2 << 12 | 100, "A69 done, 100 %: {t:?}");
    assert_eq!(t.code, 0, "B44[0] = 0: identified and written");
    let j = f64::from(t.inertia) * 1e-7;
    assert!((j / 5e-4 - 1.0).abs() < 0.05, "J {j} within 5 % of 5e-4");
    let fc = f64::from(t.coulomb) * 1e-6;
    assert!((fc / 0.06 - 1.0).abs() < 0.10, "Fc {fc} within 10 % of 0.06");
    let ran: Vec<Phase> = tuned.phases.iter().map(|p| p.phase).collect();
    assert_eq!(ran, Phase::of_run(true));
    assert_eq!(untuned.moves.len(), 2);
    assert_eq!(tuned.moves.len(), 2);
    for (before, after) in untuned.moves.iter().zip(&tuned.moves) {
        assert!(after.max_inc <= 500, "{after:?} (untuned {before:?})");
        assert!(
            after.max_inc * 20 < before.max_inc,
            "{after:?} against {before:?}"
        );
        assert!(
            after.rms_inc * 20.0 < before.rms_inc,
            "{after:?} against {before:?}"
        );
    }
    for t in &tuned.targets {
        assert!(t.error_inc().abs() <= END_POSITION_TOLERANCE_INC, "{t:?}");
    }
}
