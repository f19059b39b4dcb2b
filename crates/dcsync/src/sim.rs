//! A deterministic host model around a [`Pll`] for the tests and the
//! benchmark (not used by the firmware).
//!
//! - DC time is the reference ("true" time, ns from 0). SYNC0 edges are at
//!   `first_sync0 + n × SYNC0 cycle` exactly: the ESC generates them in
//!   hardware from DC time, so frame jitter does not move them.
//! - The local counter runs at `(1 + drift_ppb·10⁻⁹)` × DC rate from
//!   `local_offset`; the cycle timer counts ticks of `timer_hz` of that
//!   local time. The firmware reads local ns as whole ticks converted to ns.
//! - The SYNC0 interrupt runs `sync0_latency_ns ± latency_jitter_ns`
//!   (uniform) after the edge and timestamps the local counter then; the PLL
//!   is told the constant part.
//! - The master's frame for SYNC0 n arrives at `SYNC0 − frame_lead_ns ±
//!   frame_jitter_ns` (uniform) and is timestamped without latency; it only
//!   feeds the late-frame statistics.
//! - Jitter comes from a seeded xorshift: the same seed gives the same run.
//! - The true phase error of each aligned cycle is its DC start time minus
//!   (nearest SYNC0 edge − A292).

use crate::pll::{wrap_signed, Config, CycleCommand, FrameTiming, Pll};
use crate::validate::SyncError;
use nanos::Nanos;

/// xorshift64 (Marsaglia); a zero seed is replaced.
#[derive(Debug, Clone)]
pub struct XorShift64(u64);

impl XorShift64 {
    /// Seeded generator.
    pub const fn new(seed: u64) -> Self {
        Self(if seed == 0 { 0x9E37_79B9_7F4A_7C15 } else { seed })
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.0 = x;
        x
    }

    /// Uniform in [−a, a].
    pub fn symmetric(&mut self, a: u32) -> i64 {
        if a == 0 {
            return 0;
        }
        let span = 2 * u64::from(a) + 1;
        (self.next_u64() % span) as i64 - i64::from(a)
    }
}

/// The simulated world.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Scenario {
    /// Local oscillator against DC, ppb (positive = local clock fast).
    pub drift_ppb: i64,
    /// Constant SYNC0 interrupt latency, DC ns (the PLL is told it).
    pub sync0_latency_ns: u32,
    /// Uniform SYNC0 interrupt latency jitter, ± DC ns.
    pub latency_jitter_ns: u32,
    /// Frame arrival before SYNC0, DC ns (negative = after).
    pub frame_lead_ns: i64,
    /// Uniform frame arrival jitter, ± DC ns.
    pub frame_jitter_ns: u32,
    /// DC time of the first SYNC0 edge.
    pub first_sync0: Nanos,
    /// Local counter value at DC time 0.
    pub local_offset: Nanos,
    /// DC time window `[from, to)` without SYNC0 pulses and frames.
    pub sync0_gap: Option<(Nanos, Nanos)>,
    /// Random seed.
    pub seed: u64,
}

impl Default for Scenario {
    /// No drift, 300 ns ± 100 ns SYNC0 latency, frames 20 µs before SYNC0
    /// without jitter, odd start offsets, seed 1.
    fn default() -> Self {
        Self {
            drift_ppb: 0,
            sync0_latency_ns: 300,
            latency_jitter_ns: 100,
            frame_lead_ns: 20_000,
            frame_jitter_ns: 0,
            first_sync0: Nanos::from_ns(1_234_567),
            local_offset: Nanos::from_ns(987_654_321),
            sync0_gap: None,
            seed: 1,
        }
    }
}

/// What happened in one [`Simulator::step`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SimEvent {
    /// SYNC0 interrupt at DC time `dc`.
    Sync0 {
        /// DC time of the interrupt.
        dc: Nanos,
    },
    /// Frame arrival.
    Frame {
        /// DC time.
        dc: Nanos,
        /// What the PLL made of it.
        timing: Option<FrameTiming>,
    },
    /// Local cycle start.
    Cycle {
        /// DC time of the start.
        dc: Nanos,
        /// The PLL's answer.
        cmd: CycleCommand,
        /// True phase error of an aligned cycle (DC ns, positive = late).
        error_ns: Option<i64>,
    },
}

const GIGA: i128 = 1_000_000_000;

/// Runs a [`Pll`] against a [`Scenario`].
#[derive(Debug, Clone)]
pub struct Simulator {
    sc: Scenario,
    pll: Pll,
    rng: XorShift64,
    cycle_ns: i128,
    hz: i128,
    next_sync0: u64,
    sync0_isr: i128,
    next_frame: u64,
    frame_at: i128,
    tick: i128,
    tick_at: i128,
}

impl Simulator {
    /// A simulator; `cfg.sync0_latency_ns` is set from the scenario.
    pub fn new(sc: Scenario, cfg: Config) -> Result<Self, SyncError> {
        let mut cfg = cfg;
        cfg.sync0_latency_ns = sc.sync0_latency_ns;
        let pll = Pll::new(cfg)?;
        let mut sim = Self {
            sc,
            pll,
            rng: XorShift64::new(sc.seed),
            cycle_ns: i128::from(cfg.sync0_cycle_ns),
            hz: i128::from(cfg.timer_hz.max(1)),
            next_sync0: 0,
            sync0_isr: 0,
            next_frame: 0,
            frame_at: 0,
            tick: 0,
            tick_at: 0,
        };
        sim.tick = sim.tick_of_local(sim.local_ns(0)) + 1;
        sim.tick_at = sim.dc_of_tick(sim.tick);
        sim.schedule_sync0();
        sim.schedule_frame();
        Ok(sim)
    }

    /// The PLL.
    pub fn pll(&self) -> &Pll {
        &self.pll
    }

    /// The PLL, to change its parameters on the fly.
    pub fn pll_mut(&mut self) -> &mut Pll {
        &mut self.pll
    }

    /// The scenario (may be changed on the fly, e.g. a SYNC0 gap).
    pub fn scenario_mut(&mut self) -> &mut Scenario {
        &mut self.sc
    }

    /// DC time of SYNC0 edge `n`.
    pub fn sync0_dc(&self, n: u64) -> Nanos {
        self.sc.first_sync0 + Nanos::from_ns(self.cycle_ns as u64).saturating_mul(n)
    }

    fn local_ns(&self, dc: i128) -> i128 {
        i128::from(self.sc.local_offset.as_ns())
            + (dc * (GIGA + i128::from(self.sc.drift_ppb))).div_euclid(GIGA)
    }

    fn tick_of_local(&self, local: i128) -> i128 {
        (local * self.hz).div_euclid(GIGA)
    }

    fn local_of_tick(&self, tick: i128) -> Nanos {
        Nanos::from_ns((tick * GIGA).div_euclid(self.hz) as u64)
    }

    fn dc_of_tick(&self, tick: i128) -> i128 {
        let num = (tick * GIGA - i128::from(self.sc.local_offset.as_ns()) * self.hz) * GIGA;
        let den = self.hz * (GIGA + i128::from(self.sc.drift_ppb));
        -((-num).div_euclid(den))
    }

    fn read_counter(&self, dc: i128) -> Nanos {
        self.local_of_tick(self.tick_of_local(self.local_ns(dc)))
    }

    fn in_gap(&self, n: u64) -> bool {
        let s = self.sync0_dc(n);
        self.sc.sync0_gap.is_some_and(|(a, b)| s >= a && s < b)
    }

    fn schedule_sync0(&mut self) {
        while self.in_gap(self.next_sync0) {
            self.next_sync0 += 1;
        }
        let lat = i64::from(self.sc.sync0_latency_ns) + self.rng.symmetric(self.sc.latency_jitter_ns);
        self.sync0_isr = i128::from(self.sync0_dc(self.next_sync0).as_ns()) + i128::from(lat);
    }

    fn schedule_frame(&mut self) {
        loop {
            while self.in_gap(self.next_frame) {
                self.next_frame += 1;
            }
            let j = self.rng.symmetric(self.sc.frame_jitter_ns);
            self.frame_at = i128::from(self.sync0_dc(self.next_frame).as_ns())
                - i128::from(self.sc.frame_lead_ns)
                + i128::from(j);
            if self.frame_at >= 0 {
                return;
            }
            self.next_frame += 1;
        }
    }

    /// Processes the next event in DC-time order.
    pub fn step(&mut self) -> SimEvent {
        if self.tick_at <= self.sync0_isr && self.tick_at <= self.frame_at {
            let dc = self.tick_at;
            let cmd = self.pll.on_cycle_start(self.local_of_tick(self.tick));
            let error_ns = (cmd.index == 0).then(|| {
                let x = dc + i128::from(self.pll.phase_offset_ns()) - i128::from(self.sc.first_sync0.as_ns());
                wrap_signed(x as i64, self.cycle_ns as i64)
            });
            self.tick += i128::from(cmd.period_ticks.max(1));
            self.tick_at = self.dc_of_tick(self.tick);
            SimEvent::Cycle {
                dc: Nanos::from_ns(dc as u64),
                cmd,
                error_ns,
            }
        } else if self.sync0_isr <= self.frame_at {
            let dc = self.sync0_isr;
            self.pll.on_sync0(self.read_counter(dc));
            self.next_sync0 += 1;
            self.schedule_sync0();
            SimEvent::Sync0 {
                dc: Nanos::from_ns(dc as u64),
            }
        } else {
            let dc = self.frame_at;
            let timing = self.pll.on_frame(self.read_counter(dc));
            self.next_frame += 1;
            self.schedule_frame();
            SimEvent::Frame {
                dc: Nanos::from_ns(dc as u64),
                timing,
            }
        }
    }

    /// Steps until DC time `until`, calling `f` for every event.
    pub fn run_until(&mut self, until: Nanos, mut f: impl FnMut(&Pll, &SimEvent)) {
        loop {
            let next = self.tick_at.min(self.sync0_isr).min(self.frame_at);
            if next >= i128::from(until.as_ns()) {
                return;
            }
            let ev = self.step();
            f(&self.pll, &ev);
        }
    }
}
