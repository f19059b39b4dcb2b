//! A287 DC-Sync optimisation (spec §11.4, §11.8; E-120..E-124).
//!
//! Over ≈ 1000 × A150 the drive records, once per SYNC0 cycle, where the
//! master's frame passed (start and end of frame) and where the aligned
//! cycle read the outputs (Rx) and wrote the inputs (Tx), all relative to
//! SYNC0. Then it checks the stability rule of §11.4: neither Rx nor Tx,
//! each with its jitter, may fall into the frame's window (with its
//! jitter); Rx must follow the end of the frame, Tx must precede the next
//! frame's start. From the measured windows it proposes the A292 range that
//! keeps the drive's block `[Rx_min, Tx_max]` inside the free gap
//! `[EoF_max + guard, SoF_min + T − guard]` (T = SYNC0 cycle).
//!
//! A292 moves the aligned cycle start to SYNC0 − A292, so raising A292 by Δ
//! moves Rx and Tx by −Δ.
//!
//! Result codes (`A287[2]`): 0 idle, 1 running (this implementation's
//! choice: the spec leaves 0 and 1 undescribed), then the spec's 2..8.
//! When the drive block does not fit into the gap the dominant cause is
//! reported, in the spec's order: frame-start jitter above 10 µs peak to
//! peak (the ±5 µs budget of §11.4) → 3; Rx/Tx jitter above 20 µs (the
//! ±10 µs application budget) → 4; otherwise 5 if the drive's Rx→Tx
//! runtime is at least the frame's duration, else 6.

use crate::pll::wrap_signed;

/// Measurement length in drive cycles (§11.8).
pub const MEASURE_CYCLES: u32 = 1000;
/// Frame-start jitter budget, peak to peak, ns (±5 µs, §11.4).
pub const FRAME_JITTER_BUDGET_NS: i64 = 10_000;
/// Drive Rx/Tx jitter budget, peak to peak, ns (±10 µs, §11.4).
pub const DRIVE_JITTER_BUDGET_NS: i64 = 20_000;
/// Tolerance between the measured master cycle and A291, ppm.
pub const CYCLE_MATCH_PPM: u64 = 1000;

/// `A287[2]` result (§11.8).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum OptimizeResult {
    /// 2: not executable (state not Safe-Op/Op, master cycle ≠ A291, DC not used).
    NotExecutable = 2,
    /// 3: cycle too small or master frame-start jitter too large.
    FrameJitter = 3,
    /// 4: cycle too small or drive Rx/Tx jitter too large.
    DriveJitter = 4,
    /// 5: cycle too small or drive application runtime too long.
    Runtime = 5,
    /// 6: cycle too small or frame too long.
    FrameLength = 6,
    /// 7: fault-free, A292 already in the recommended range.
    InRange = 7,
    /// 8: fault-free, but Rx/Tx touches the frame (or Tx lands in the next
    /// frame): A292 can be improved.
    Improvable = 8,
}

impl OptimizeResult {
    /// Success (7 or 8).
    pub const fn is_success(self) -> bool {
        matches!(self, Self::InRange | Self::Improvable)
    }
}

/// What the measurement needs at its start (§11.8 preconditions).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OptimizeRequest {
    /// ESM state is Safe-Op or Op.
    pub safe_op_or_op: bool,
    /// DC-Sync (SYNC0) is in use.
    pub dc_sync: bool,
    /// Master's actual cycle (the PLL's A296), ns.
    pub master_cycle_ns: u32,
    /// A291 set cycle, ns.
    pub a291_ns: u32,
    /// SYNC0 cycle, ns.
    pub sync0_cycle_ns: u32,
    /// A150, ns.
    pub a150_ns: u32,
    /// Current A292, ns.
    pub a292_ns: i32,
    /// Distance kept between the drive's Rx/Tx and the frame, ns.
    pub guard_ns: u32,
}

/// One SYNC0 cycle's timing, all relative to that SYNC0 edge (ns, negative =
/// before SYNC0; [`crate::Pll::relative_to_sync0`] gives them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameSample {
    /// Start of the frame carrying this drive's data.
    pub sof_ns: i64,
    /// End of that frame (≥ start; taken modulo the cycle).
    pub eof_ns: i64,
    /// Start of the aligned local cycle.
    pub cycle_start_ns: i64,
    /// Rx (outputs read) after the cycle start, ns.
    pub rx_after_start_ns: u32,
    /// Tx (inputs written) after the cycle start, ns.
    pub tx_after_start_ns: u32,
}

/// The outcome: `A287[2]` and the proposed A292 range (and the figures the
/// wizard shows).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OptimizeOutcome {
    /// `A287[2]`.
    pub result: OptimizeResult,
    /// Proposed minimum A292, ns (= current A292 on failure).
    pub a292_min_ns: i64,
    /// Proposed maximum A292, ns (= current A292 on failure).
    pub a292_max_ns: i64,
    /// End of frame (latest) → SYNC0, ns (positive = frame ends before SYNC0).
    pub end_of_frame_to_sync_ns: i64,
    /// Frame window including jitter (latest end − earliest start), ns.
    pub frame_duration_ns: i64,
    /// SYNC0 → earliest Rx, ns.
    pub sync_to_rx_ns: i64,
}

/// Min/max of a cyclic quantity, unwrapped around its first sample.
#[derive(Debug, Clone, Copy, Default)]
struct Span {
    first: i64,
    min: i64,
    max: i64,
    n: u32,
}

impl Span {
    fn add(&mut self, v: i64, period: i64) -> i64 {
        let u = if self.n == 0 {
            self.first = v;
            self.min = v;
            self.max = v;
            v
        } else {
            self.first + wrap_signed(v.saturating_sub(self.first), period)
        };
        self.min = self.min.min(u);
        self.max = self.max.max(u);
        self.n = self.n.saturating_add(1);
        u
    }

    fn spread(&self) -> i64 {
        self.max - self.min
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Idle,
    Running,
    Done(OptimizeOutcome),
}

/// The A287 measurement. Idle until [`Optimizer::start`].
#[derive(Debug, Clone)]
pub struct Optimizer {
    req: Option<OptimizeRequest>,
    phase: Phase,
    samples: u32,
    needed: u32,
    sof: Span,
    eof_max: i64,
    start: Span,
    rx: Span,
    tx: Span,
    frame_len_max: i64,
    runtime_max: i64,
}

impl Default for Optimizer {
    fn default() -> Self {
        Self::new()
    }
}

impl Optimizer {
    /// Idle.
    pub const fn new() -> Self {
        Self {
            req: None,
            phase: Phase::Idle,
            samples: 0,
            needed: 0,
            sof: Span {
                first: 0,
                min: 0,
                max: 0,
                n: 0,
            },
            eof_max: 0,
            start: Span {
                first: 0,
                min: 0,
                max: 0,
                n: 0,
            },
            rx: Span {
                first: 0,
                min: 0,
                max: 0,
                n: 0,
            },
            tx: Span {
                first: 0,
                min: 0,
                max: 0,
                n: 0,
            },
            frame_len_max: 0,
            runtime_max: 0,
        }
    }

    /// `A287[0]`: starts a measurement. Fails at once with result 2 when a
    /// precondition does not hold (E-121).
    pub fn start(&mut self, req: OptimizeRequest) {
        *self = Self::new();
        self.req = Some(req);
        let a291 = u64::from(req.a291_ns);
        let diff = u64::from(req.master_cycle_ns.abs_diff(req.a291_ns));
        let cycle_ok = a291 > 0 && diff * 1_000_000 <= a291 * CYCLE_MATCH_PPM;
        if !req.safe_op_or_op || !req.dc_sync || !cycle_ok || req.a150_ns == 0 || req.sync0_cycle_ns == 0 {
            self.phase = Phase::Done(Self::failure(&req, OptimizeResult::NotExecutable));
            return;
        }
        let k = (req.sync0_cycle_ns / req.a150_ns).max(1);
        self.needed = MEASURE_CYCLES.div_ceil(k);
        self.phase = Phase::Running;
    }

    fn failure(req: &OptimizeRequest, result: OptimizeResult) -> OptimizeOutcome {
        OptimizeOutcome {
            result,
            a292_min_ns: i64::from(req.a292_ns),
            a292_max_ns: i64::from(req.a292_ns),
            end_of_frame_to_sync_ns: 0,
            frame_duration_ns: 0,
            sync_to_rx_ns: 0,
        }
    }

    /// Whether a measurement is running.
    pub fn is_running(&self) -> bool {
        self.phase == Phase::Running
    }

    /// One SYNC0 cycle's sample (ignored unless running).
    pub fn record(&mut self, s: &FrameSample) {
        let Some(req) = self.req else { return };
        if self.phase != Phase::Running {
            return;
        }
        let t = i64::from(req.sync0_cycle_ns);
        let sof = self.sof.add(s.sof_ns, t);
        let len = (s.eof_ns.saturating_sub(s.sof_ns)).rem_euclid(t.max(1));
        self.frame_len_max = self.frame_len_max.max(len);
        self.eof_max = if self.samples == 0 {
            sof + len
        } else {
            self.eof_max.max(sof + len)
        };
        let cs = self.start.add(s.cycle_start_ns, t);
        // Rx/Tx follow the unwrapped cycle start, so they stay consistent.
        let rx = cs + i64::from(s.rx_after_start_ns);
        let tx = cs + i64::from(s.tx_after_start_ns);
        for (span, v) in [(&mut self.rx, rx), (&mut self.tx, tx)] {
            if span.n == 0 {
                span.first = v;
                span.min = v;
                span.max = v;
            }
            span.min = span.min.min(v);
            span.max = span.max.max(v);
            span.n = span.n.saturating_add(1);
        }
        self.runtime_max = self
            .runtime_max
            .max(i64::from(s.tx_after_start_ns) - i64::from(s.rx_after_start_ns));
        self.samples = self.samples.saturating_add(1);
        if self.samples >= self.needed {
            self.phase = Phase::Done(self.evaluate(&req));
        }
    }

    /// `A287[1]`: progress, 0..=100 %.
    pub fn progress_percent(&self) -> u8 {
        match self.phase {
            Phase::Idle => 0,
            Phase::Done(_) => 100,
            Phase::Running => {
                let p = u64::from(self.samples) * 100 / u64::from(self.needed.max(1));
                u8::try_from(p.min(99)).unwrap_or(99)
            }
        }
    }

    /// `A287[2]` as a number: 0 idle, 1 running, 2..8 per the spec.
    pub fn result_code(&self) -> u8 {
        match self.phase {
            Phase::Idle => 0,
            Phase::Running => 1,
            Phase::Done(o) => o.result as u8,
        }
    }

    /// The outcome once finished.
    pub fn outcome(&self) -> Option<OptimizeOutcome> {
        match self.phase {
            Phase::Done(o) => Some(o),
            _ => None,
        }
    }

    fn evaluate(&self, req: &OptimizeRequest) -> OptimizeOutcome {
        let t = i64::from(req.sync0_cycle_ns);
        let guard = i64::from(req.guard_ns);
        let a292 = i64::from(req.a292_ns);
        let frame = self.eof_max - self.sof.min;
        let block = self.tx.max - self.rx.min;
        let slack = t - frame - block - 2 * guard;
        let figures = OptimizeOutcome {
            result: OptimizeResult::InRange,
            a292_min_ns: a292,
            a292_max_ns: a292,
            end_of_frame_to_sync_ns: -self.eof_max,
            frame_duration_ns: frame,
            sync_to_rx_ns: wrap_signed(self.rx.min, t),
        };
        let fail = |result| OptimizeOutcome { result, ..figures };
        if slack < 0 {
            return fail(self.cause());
        }
        // How far Rx_min lies after the earliest allowed position.
        let delta = (self.rx.min - (self.eof_max + guard)).rem_euclid(t.max(1));
        let in_range = delta <= slack;
        let (mut lo, mut hi) = (a292 + delta - slack, a292 + delta);
        if !in_range {
            // Same window one cycle away: take the one nearest to 0.
            let centre = a292 + delta - slack / 2;
            let m = (centre + t / 2).div_euclid(t.max(1));
            lo -= m * t;
            hi -= m * t;
        }
        let lim = i64::from(req.a150_ns) - 1;
        let (lo, hi) = (lo.max(-lim), hi.min(lim));
        if lo > hi {
            return fail(self.cause());
        }
        OptimizeOutcome {
            result: if in_range {
                OptimizeResult::InRange
            } else {
                OptimizeResult::Improvable
            },
            a292_min_ns: lo,
            a292_max_ns: hi,
            ..figures
        }
    }

    fn cause(&self) -> OptimizeResult {
        if self.sof.spread() > FRAME_JITTER_BUDGET_NS {
            OptimizeResult::FrameJitter
        } else if self.rx.spread().max(self.tx.spread()) > DRIVE_JITTER_BUDGET_NS {
            OptimizeResult::DriveJitter
        } else if self.runtime_max >= self.frame_len_max {
            OptimizeResult::Runtime
        } else {
            OptimizeResult::FrameLength
        }
    }
}
