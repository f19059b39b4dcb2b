//! Distributed clocks (ESC datasheet, DC chapter): the ESC's local clock,
//! receive-time latching, system time, the drift-control loop and the cyclic
//! unit (SYNC0/SYNC1).
//!
//! # Model
//!
//! - **Local clock.** Every ESC has its own oscillator:
//!   `local(t) = offset + t · (1 + drift + correction)` for simulation time `t`
//!   (ns), with the drift from [`EscConfig::clock_drift_ppb`](super::EscConfig)
//!   and the offset from [`EscConfig::clock_offset_ns`](super::EscConfig). The
//!   clock is piecewise linear: a change of speed re-anchors it, so it never
//!   jumps. Integer arithmetic (parts per trillion), deterministic.
//! - **Position in the line.** The line tells each ESC when a frame reaches it
//!   ([`LineTiming`]): port 0 at `arrival` after the frame entered the line,
//!   port 1 (the frame coming back from the rest of the line) `loop_time` later.
//!   A write to 0x0900 latches `local` at these instants into 0x0900 (port 0),
//!   0x0904 (port 1) and 0x0918 (processing unit, 64 bit), so a master's
//!   topology and propagation-delay calculation works.
//! - **System time** (0x0910, computed on read) = `local + offset (0x0920)`,
//!   taken at the frame's arrival for ECAT reads and at the ESC's time for PDI
//!   reads.
//! - **Drift control.** An ARMW/FRMW that *writes* 0x0910 (at every slave but
//!   the one that reads it, the reference) compares, at the frame's arrival,
//!   `Δ = system time − (written value + system time delay 0x0928)` over the
//!   bytes written (32 or 64 bit). 0x092C shows the mean of Δ (sign bit 31 set
//!   when the local copy is behind, magnitude in ns; exponential mean over
//!   `2^depth` samples, depth = 0x0934 bits 0..3). The loop is a PI controller
//!   on the clock speed (P ≈ 600 /s, I ≈ 90 000 /s², gains sized for sample
//!   intervals up to 1 ms and reduced for longer ones), clamped to
//!   ±[`MAX_CORRECTION_PPT`]; it corrects by changing the speed only, never by a
//!   jump, like the ET1100's speed counter. 0x0932 shows the frequency part of
//!   the correction in units of 0.1 ppm (i16). A write to 0x0930 resets the
//!   loop (filters, integral, correction), as on the ET1100.
//! - **Cyclic unit.** Writing 0x0981 with bit 0 (cyclic operation) and bit 1
//!   (SYNC0) starts SYNC0 at the start time 0x0990 (system time), then every
//!   0x09A0 ns of system time (0 = a single pulse). Bit 2 adds SYNC1 at
//!   `start + c1` (c1 = 0x09A4), repeated every `max(1, c1 / c0) · c0`:
//!   c1 = 0 → with SYNC0, c1 < c0 → SYNC0 shifted by c1, c1 = n·c0 (+ s) →
//!   every n-th SYNC0 (shifted by s). Each pulse sets 0x098E (0x098F) bit 0
//!   and, when the AL event mask has it, AL event request bit 2 (3); a PDI read
//!   of 0x098E (0x098F) clears both. While active, 0x0990 reads the next SYNC0
//!   time and 0x0998 the next SYNC1 time. A start time already in the past at
//!   activation starts at the next cycle boundary after it (a real ESC would
//!   wait for its system time to wrap). Pulse length (0x0982), the PDI-owned
//!   cyclic unit (0x0980), activation status (0x0984) and the latch units are
//!   not modelled.

use ::esc::regs::{self, al_event, dc};

use super::Esc;
use nanos::Nanos;

/// One in parts per trillion.
const PPT: i128 = 1_000_000_000_000;
/// Largest clock-speed correction of the drift-control loop, parts per
/// trillion (±1000 ppm).
pub const MAX_CORRECTION_PPT: i64 = 1_000_000_000;
/// Largest configurable oscillator drift, ppb (±10 %).
pub const MAX_DRIFT_PPB: i32 = 100_000_000;
/// Proportional gain of the drift-control loop, 1/s.
const LOOP_KP: i128 = 600;
/// Integral gain of the drift-control loop, 1/s².
const LOOP_KI: i128 = 90_000;
/// Longest sample interval the loop gains are sized for, ns; longer intervals
/// get proportionally smaller gains (the loop stays stable, only slower).
const LOOP_TMAX_NS: i128 = 1_000_000;
/// Largest time difference the loop takes in, ns (larger ones are clamped).
const MAX_DIFF_NS: i64 = 1_000_000_000_000;
/// Fraction bits of the time-difference mean.
const MEAN_FRAC: u32 = 8;
/// Unit of the speed counter difference register 0x0932: 0.1 ppm in ppt.
const SPEED_DIFF_UNIT_PPT: i64 = 100_000;

/// Where an ESC sits in the line, in time: when a frame reaches it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LineTiming {
    /// From the frame entering the line to its start at this ESC's port 0.
    pub arrival: Nanos,
    /// From the frame leaving port 1 to its return at port 1 (the round trip
    /// through the rest of the line); zero for the last ESC.
    pub loop_time: Nanos,
}

/// SYNC pulses since the last [`Esc::take_sync0_events`] call.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SyncPulses {
    /// Number of pulses.
    pub count: u32,
    /// Simulation time of the last pulse (valid when `count > 0`).
    pub last_now: Nanos,
    /// System time of the last pulse (exactly `start + k · cycle`), ns.
    pub last_system_ns: u64,
}

/// A piecewise-linear local clock:
/// `local(t) = anchor_local + (anchor_frac + (t − anchor_now) · (1 + rate)) / 1e12`.
/// The fraction of a nanosecond at the anchor is kept, so re-anchoring (a
/// change of speed) never loses time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct LocalClock {
    /// Simulation time of the anchor.
    anchor_now: Nanos,
    anchor_local: u64,
    /// Sub-nanosecond part of the local time at the anchor, 1e-12 ns (0..1e12).
    anchor_frac: i64,
    /// Speed deviation from nominal, parts per trillion.
    rate_ppt: i64,
}

impl LocalClock {
    /// A clock reading `offset_ns` at time 0 and running `rate_ppt` fast.
    pub(super) fn new(offset_ns: u64, rate_ppt: i64) -> Self {
        Self {
            anchor_now: Nanos::ZERO,
            anchor_local: offset_ns,
            anchor_frac: 0,
            rate_ppt,
        }
    }

    /// Local time since the anchor at `t`, in 1e-12 ns (fraction included).
    fn elapsed_fine(&self, t: Nanos) -> i128 {
        let dt = i128::from(t.as_ns()) - i128::from(self.anchor_now.as_ns());
        dt * (PPT + i128::from(self.rate_ppt)) + i128::from(self.anchor_frac)
    }

    /// Local time at simulation time `t` (rounded down), wrapping like a 64-bit counter.
    pub(super) fn local_at(&self, t: Nanos) -> u64 {
        // whole ns since the anchor: ⌊(dt·(1e12 + rate) + frac) / 1e12⌋ =
        // dt + ⌊(dt·rate + frac) / 1e12⌋, in 64 bits where it fits
        let whole = i64::try_from(i128::from(t.as_ns()) - i128::from(self.anchor_now.as_ns()))
            .ok()
            .and_then(|dt| {
                let fine = dt.checked_mul(self.rate_ppt)?.checked_add(self.anchor_frac)?;
                dt.checked_add(fine.div_euclid(PPT as i64))
            });
        match whole {
            Some(w) => self.anchor_local.wrapping_add(w as u64),
            None => self.local_at_wide(t),
        }
    }

    /// [`LocalClock::local_at`] in 128-bit arithmetic throughout.
    pub(super) fn local_at_wide(&self, t: Nanos) -> u64 {
        let whole = self.elapsed_fine(t).div_euclid(PPT);
        self.anchor_local.wrapping_add(whole as u64)
    }

    /// The earliest simulation time at which the local time reaches `local`
    /// (wrapping comparison), saturated at zero and [`Nanos::MAX`].
    pub(super) fn now_for_local(&self, local: u64) -> Nanos {
        let dl = local.wrapping_sub(self.anchor_local) as i64;
        // ⌈(dl·1e12 − frac) / den⌉ with den = 1e12 + rate (> 0) is
        // dl + ⌈(−dl·rate − frac) / den⌉, in 64 bits where it fits
        let den = PPT as i64 + self.rate_ppt;
        let dt = Some(dl)
            .filter(|_| den > 0)
            .and_then(|dl| dl.checked_mul(self.rate_ppt))
            .and_then(i64::checked_neg)
            .and_then(|y| y.checked_sub(self.anchor_frac)?.checked_add(den - 1))
            .and_then(|y| dl.checked_add(y.div_euclid(den)));
        let dt = match dt {
            Some(dt) => i128::from(dt),
            None => self.first_now_wide(dl),
        };
        self.settle(local, clamp_u64(i128::from(self.anchor_now.as_ns()) + dt))
    }

    /// [`LocalClock::now_for_local`]'s estimate (simulation time since the
    /// anchor) in 128-bit arithmetic throughout.
    pub(super) fn first_now_wide(&self, dl: i64) -> i128 {
        let dl = i128::from(dl);
        let den = PPT + i128::from(self.rate_ppt);
        (dl * PPT - i128::from(self.anchor_frac) + den - 1).div_euclid(den)
    }

    /// [`LocalClock::now_for_local`] in 128-bit arithmetic throughout (the
    /// tests compare the two).
    #[cfg(test)]
    pub(super) fn now_for_local_wide(&self, local: u64) -> Nanos {
        let dl = local.wrapping_sub(self.anchor_local) as i64;
        let t = clamp_u64(i128::from(self.anchor_now.as_ns()) + self.first_now_wide(dl));
        self.settle_by(local, t, Self::local_at_wide)
    }

    /// The earliest time at or near `t` at which the local time reaches `local`.
    fn settle(&self, local: u64, t: u64) -> Nanos {
        self.settle_by(local, t, Self::local_at)
    }

    /// [`Self::settle`] with the local time `local_at` gives.
    fn settle_by(&self, local: u64, mut t: u64, local_at: impl Fn(&Self, Nanos) -> u64) -> Nanos {
        let reached = |c: &Self, t: u64| local_at(c, Nanos::from_ns(t)).wrapping_sub(local) as i64 >= 0;
        for _ in 0..4 {
            if reached(self, t) {
                break;
            }
            t = t.saturating_add(1);
        }
        for _ in 0..4 {
            if t > 0 && reached(self, t - 1) {
                t -= 1;
            } else {
                break;
            }
        }
        Nanos::from_ns(t)
    }

    /// Changes the speed from `t` on (the local time is continuous at `t`).
    pub(super) fn set_rate(&mut self, t: Nanos, rate_ppt: i64) {
        if rate_ppt == self.rate_ppt {
            return;
        }
        let fine = self.elapsed_fine(t);
        self.anchor_local = self.anchor_local.wrapping_add(fine.div_euclid(PPT) as u64);
        self.anchor_frac = fine.rem_euclid(PPT) as i64;
        self.anchor_now = t;
        self.rate_ppt = rate_ppt;
    }

    /// Current speed deviation, ppt.
    pub(super) fn rate_ppt(&self) -> i64 {
        self.rate_ppt
    }
}

/// Saturating i128 → u64.
fn clamp_u64(v: i128) -> u64 {
    if v <= 0 {
        0
    } else {
        u64::try_from(v).unwrap_or(u64::MAX)
    }
}

/// Saturating i128 → i64.
fn clamp_i64(v: i128) -> i64 {
    i64::try_from(v).unwrap_or(if v < 0 { i64::MIN } else { i64::MAX })
}

/// One periodic pulse generator of the cyclic unit, in system time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
struct Pulse {
    /// System time of the next pulse; `None` when inactive.
    next: Option<u64>,
    /// Pulses since the last take.
    pending: SyncPulses,
    /// Pulses since power-on.
    total: u64,
}

/// Distributed-clock state of one ESC (everything that is not a register).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct DcState {
    pub(super) clock: LocalClock,
    drift_ppt: i64,
    /// Integral (frequency) part of the loop's correction, ppt.
    integral_ppt: i64,
    /// Mean time difference, ns · 2^MEAN_FRAC.
    mean: i64,
    /// Time of the previous drift-control sample.
    last_sample: Option<Nanos>,
    pub(super) line: LineTiming,
    /// Time of the ECAT access in progress at this ESC (frame arrival).
    pub(super) ecat_time: Nanos,
    sync0: Pulse,
    sync1: Pulse,
    /// SYNC1 period, ns of system time (0 = single pulse).
    sync1_period: u64,
}

impl DcState {
    /// Power-on state for a clock with `drift_ppb` and `offset_ns`.
    pub(super) fn new(drift_ppb: i32, offset_ns: u64) -> Self {
        let drift_ppt = i64::from(drift_ppb.clamp(-MAX_DRIFT_PPB, MAX_DRIFT_PPB)) * 1000;
        Self {
            clock: LocalClock::new(offset_ns, drift_ppt),
            drift_ppt,
            integral_ppt: 0,
            mean: 0,
            last_sample: None,
            line: LineTiming::default(),
            ecat_time: Nanos::ZERO,
            sync0: Pulse::default(),
            sync1: Pulse::default(),
            sync1_period: 0,
        }
    }
}

impl Esc {
    // ------------------------------------------------------------ public API

    /// Sets this ESC's position in the line (the line's owner calls it before
    /// each frame; the default is 0/0: every port sees the frame at once).
    pub fn set_line_timing(&mut self, timing: LineTiming) {
        self.dc.line = timing;
    }

    /// Replaces the oscillator: `local(t) = offset_ns + t · (1 + drift_ppb · 1e-9)`
    /// from simulation time 0 on (as if configured through [`EscConfig`](super::EscConfig);
    /// drift clamped to ±[`MAX_DRIFT_PPB`]). The drift-control loop restarts.
    /// Meant for before the first frame: the local time jumps otherwise.
    pub fn set_clock(&mut self, drift_ppb: i32, offset_ns: u64) {
        self.config.clock_drift_ppb = drift_ppb.clamp(-MAX_DRIFT_PPB, MAX_DRIFT_PPB);
        self.config.clock_offset_ns = offset_ns;
        let fresh = DcState::new(drift_ppb, offset_ns);
        self.dc.clock = fresh.clock;
        self.dc.drift_ppt = fresh.drift_ppt;
        self.dc.integral_ppt = 0;
        self.dc.mean = 0;
        self.dc.last_sample = None;
    }

    /// The ESC's local time (register value, ns) at simulation time `now`.
    pub fn local_ns(&self, now: Nanos) -> u64 {
        self.dc.clock.local_at(now)
    }

    /// The ESC's system time (local time + 0x0920; register value, ns) at
    /// simulation time `now`.
    pub fn system_time_ns(&self, now: Nanos) -> u64 {
        self.local_ns(now)
            .wrapping_add(self.get_u64(dc::SYSTEM_TIME_OFFSET))
    }

    /// Current clock speed relative to nominal (drift + correction), ppb.
    pub fn clock_rate_ppb(&self) -> i64 {
        self.dc.clock.rate_ppt() / 1000
    }

    /// The drift-control loop's current correction of the clock speed, ppb.
    pub fn clock_correction_ppb(&self) -> i64 {
        (self.dc.clock.rate_ppt() - self.dc.drift_ppt) / 1000
    }

    /// Simulation time of the next SYNC0 pulse (inverting the local clock at
    /// its current speed), `None` when SYNC0 is not active. A time loop that
    /// stops exactly there and calls [`Esc::tick`] sees the pulse.
    pub fn next_sync0_at(&self) -> Option<Nanos> {
        self.dc.sync0.next.map(|s| self.now_for_system(s))
    }

    /// The SYNC0 cycle time register (0x09A0), ns (0: single shot).
    pub fn sync0_cycle_ns(&self) -> u32 {
        self.get_u32(dc::SYNC0_CYCLE)
    }

    /// Simulation time of the next SYNC1 pulse, `None` when SYNC1 is not active.
    pub fn next_sync1_at(&self) -> Option<Nanos> {
        self.dc.sync1.next.map(|s| self.now_for_system(s))
    }

    /// Advances to `now` and returns the SYNC0 pulses since the last call
    /// (count, time of the last one); the count restarts at 0.
    pub fn take_sync0_events(&mut self, now: Nanos) -> SyncPulses {
        self.tick(now);
        core::mem::take(&mut self.dc.sync0.pending)
    }

    /// Advances to `now` and returns the SYNC1 pulses since the last call.
    pub fn take_sync1_events(&mut self, now: Nanos) -> SyncPulses {
        self.tick(now);
        core::mem::take(&mut self.dc.sync1.pending)
    }

    /// SYNC0 pulses since power-on (never reset; lets a time loop see progress).
    pub fn sync0_total(&self) -> u64 {
        self.dc.sync0.total
    }

    // -------------------------------------------------------------- internal

    /// Simulation time at which the system time reaches `system`.
    fn now_for_system(&self, system: u64) -> Nanos {
        let local = system.wrapping_sub(self.get_u64(dc::SYSTEM_TIME_OFFSET));
        self.dc.clock.now_for_local(local)
    }

    /// The byte `a` of the computed DC registers at time `t` (system time 0x0910).
    pub(super) fn dc_computed(&self, a: u32, t: Nanos) -> Option<u8> {
        let st = u32::from(dc::SYSTEM_TIME);
        if self.config.dc_supported && (st..st + 8).contains(&a) {
            let bytes = self.system_time_ns(t).to_le_bytes();
            return bytes.get((a - st) as usize).copied();
        }
        None
    }

    /// A write to receive time port 0 latches the local time of the frame at
    /// each port and at the processing unit.
    pub(super) fn dc_latch_receive_times(&mut self) {
        if !self.config.dc_supported {
            return;
        }
        let t0 = self.dc.ecat_time;
        let p0 = self.dc.clock.local_at(t0);
        let p1 = self.dc.clock.local_at(t0.saturating_add(self.dc.line.loop_time));
        self.set_u32(dc::RECEIVE_TIME_PORT0, p0 as u32);
        self.set_u32(dc::RECEIVE_TIME_PORT1, p1 as u32);
        self.set_u64(dc::RECEIVE_TIME_PU, p0);
    }

    /// ARMW/FRMW write of the system time (`written`: the bytes from 0x0910 on,
    /// at most 8): one sample of the drift-control loop.
    pub(super) fn dc_system_time_written(&mut self, written: &[u8]) {
        let n = written.len().min(8);
        if !self.config.dc_supported || n == 0 {
            return;
        }
        let t = self.dc.ecat_time;
        let mut w = [0u8; 8];
        for (d, s) in w.iter_mut().zip(written) {
            *d = *s;
        }
        let received = u64::from_le_bytes(w);
        let delay = u64::from(self.get_u32(dc::SYSTEM_TIME_DELAY));
        let raw = self.system_time_ns(t).wrapping_sub(received.wrapping_add(delay));
        // compare over the bytes written, sign-extended
        let bits = 8 * n as u32;
        let diff = if bits >= 64 {
            raw as i64
        } else {
            let shift = 64 - bits;
            ((raw << shift) as i64) >> shift
        };
        let diff = diff.clamp(-MAX_DIFF_NS, MAX_DIFF_NS);

        // mean for 0x092C
        let depth = u32::from(self.get_u8(dc::FILTER_DEPTH_TIME) & 0x0F);
        let x = diff.saturating_mul(1 << MEAN_FRAC);
        let mean = if self.dc.last_sample.is_none() || depth == 0 {
            x
        } else {
            self.dc
                .mean
                .saturating_add((x.saturating_sub(self.dc.mean)) >> depth)
        };
        self.dc.mean = mean;
        let m = mean >> MEAN_FRAC;
        let mag = u32::try_from(m.unsigned_abs())
            .unwrap_or(u32::MAX)
            .min(0x7FFF_FFFF);
        let sign = if m < 0 { 1u32 << 31 } else { 0 };
        self.set_u32(dc::SYSTEM_TIME_DIFFERENCE, sign | mag);

        // PI on the clock speed
        let e = i128::from(diff);
        let dt = self.dc.last_sample.map(|l| i128::from(t.since(l).as_ns()));
        let (p_scale_num, p_scale_den) = match dt {
            Some(dt) if dt > LOOP_TMAX_NS => (LOOP_TMAX_NS, dt),
            _ => (1, 1),
        };
        let p = LOOP_KP * e * 1000 * p_scale_num / p_scale_den;
        if let Some(dt) = dt.filter(|&d| d > 0) {
            let tau = dt.min(LOOP_TMAX_NS);
            let di = LOOP_KI * e * tau * tau / dt / 1_000_000;
            self.dc.integral_ppt = clamp_i64(i128::from(self.dc.integral_ppt) + di)
                .clamp(-MAX_CORRECTION_PPT, MAX_CORRECTION_PPT);
        }
        self.dc.last_sample = Some(t);
        let corr =
            clamp_i64(-(p + i128::from(self.dc.integral_ppt))).clamp(-MAX_CORRECTION_PPT, MAX_CORRECTION_PPT);
        self.dc.clock.set_rate(t, self.dc.drift_ppt + corr);
        let speed = (-self.dc.integral_ppt / SPEED_DIFF_UNIT_PPT)
            .clamp(i64::from(i16::MIN), i64::from(i16::MAX)) as i16;
        self.set_u16(dc::SPEED_COUNTER_DIFF, speed as u16);
    }

    /// A write to the speed counter start (0x0930) resets the loop.
    pub(super) fn dc_loop_reset(&mut self) {
        let t = self.dc.ecat_time;
        self.dc.integral_ppt = 0;
        self.dc.mean = 0;
        self.dc.last_sample = None;
        self.dc.clock.set_rate(t, self.dc.drift_ppt);
        self.set_u16(dc::SPEED_COUNTER_DIFF, 0);
        self.set_u32(dc::SYSTEM_TIME_DIFFERENCE, 0);
    }

    /// ECAT write of the activation register 0x0981: starts or stops SYNC0/SYNC1.
    pub(super) fn dc_activation_written(&mut self) {
        let act = self.get_u8(dc::ACTIVATION);
        let cyclic = act & 0x01 != 0;
        if !cyclic || act & 0x02 == 0 {
            self.dc.sync0.next = None;
        }
        if !cyclic || act & 0x04 == 0 {
            self.dc.sync1.next = None;
        }
        if !cyclic || !self.config.dc_supported {
            return;
        }
        let now_sys = self.system_time_ns(self.dc.ecat_time);
        let c0 = u64::from(self.get_u32(dc::SYNC0_CYCLE));
        let mut start = self.get_u64(dc::START_TIME);
        let behind = now_sys.wrapping_sub(start) as i64;
        if behind > 0 && c0 > 0 {
            start = start.wrapping_add((behind as u64).div_ceil(c0).saturating_mul(c0));
        }
        if act & 0x02 != 0 && self.dc.sync0.next.is_none() {
            self.dc.sync0.next = Some(start);
            self.set_u64(dc::START_TIME, start);
        }
        if act & 0x04 != 0 && self.dc.sync1.next.is_none() {
            let c1 = u64::from(self.get_u32(dc::SYNC1_CYCLE));
            self.dc.sync1_period = c1.checked_div(c0).map_or(0, |n| n.max(1) * c0);
            let first = start.wrapping_add(c1);
            self.dc.sync1.next = Some(first);
            self.set_u64(dc::NEXT_SYNC1, first);
        }
    }

    /// PDI read side effects: reading a SYNC status acknowledges the pulse.
    pub(super) fn dc_pdi_read(&mut self, touches: impl Fn(u16) -> bool) {
        if touches(dc::SYNC0_STATUS) {
            let s = self.get_u8(dc::SYNC0_STATUS) & !1;
            self.set_u8(dc::SYNC0_STATUS, s);
            self.clear_al_event(al_event::SYNC0);
        }
        if touches(dc::SYNC1_STATUS) {
            let s = self.get_u8(dc::SYNC1_STATUS) & !1;
            self.set_u8(dc::SYNC1_STATUS, s);
            self.clear_al_event(al_event::SYNC1);
        }
    }

    /// Generates the SYNC pulses due at `now` (called by [`Esc::tick`]).
    pub(super) fn dc_tick(&mut self, now: Nanos) {
        if self.dc.sync0.next.is_none() && self.dc.sync1.next.is_none() {
            return;
        }
        let sys = self.system_time_ns(now);
        let c0 = u64::from(self.get_u32(dc::SYNC0_CYCLE));
        if let Some(next) = self.fire(true, sys, c0) {
            self.set_u64(dc::START_TIME, next);
        }
        let c1 = self.dc.sync1_period;
        if let Some(next) = self.fire(false, sys, c1) {
            self.set_u64(dc::NEXT_SYNC1, next);
        }
    }

    /// Fires the pulses of SYNC0 (`zero`) or SYNC1 due by system time `sys`;
    /// returns the next pulse time when it moved.
    fn fire(&mut self, zero: bool, sys: u64, period: u64) -> Option<u64> {
        let pulse = if zero { &self.dc.sync0 } else { &self.dc.sync1 };
        let next = pulse.next?;
        let late = sys.wrapping_sub(next) as i64;
        if late < 0 {
            return None;
        }
        let (count, last) = match (late as u64).checked_div(period) {
            Some(k) => (k.saturating_add(1), next.wrapping_add(k.saturating_mul(period))),
            None => (1, next),
        };
        let following = (period > 0).then(|| last.wrapping_add(period));
        let last_now = self.now_for_system(last);
        let pulse = if zero {
            &mut self.dc.sync0
        } else {
            &mut self.dc.sync1
        };
        pulse.next = following;
        pulse.total = pulse.total.saturating_add(count);
        pulse.pending = SyncPulses {
            count: pulse
                .pending
                .count
                .saturating_add(u32::try_from(count).unwrap_or(u32::MAX)),
            last_now,
            last_system_ns: last,
        };
        let (status, event) = if zero {
            (dc::SYNC0_STATUS, al_event::SYNC0)
        } else {
            (dc::SYNC1_STATUS, al_event::SYNC1)
        };
        let s = self.get_u8(status) | 1;
        self.set_u8(status, s);
        if self.get_u32(regs::AL_EVENT_MASK) & event != 0 {
            self.set_al_event(event);
        }
        // None: a single shot is done, the unit stays activated but idle
        following
    }
}

#[cfg(test)]
mod tests;
