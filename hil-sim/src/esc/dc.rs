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
//!   ([`LineTiming`]): port 0 at `arrival_ns` after the frame entered the line,
//!   port 1 (the frame coming back from the rest of the line) `loop_ns` later.
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
    /// From the frame entering the line to its start at this ESC's port 0, ns.
    pub arrival_ns: u64,
    /// From the frame leaving port 1 to its return at port 1 (the round trip
    /// through the rest of the line), ns; 0 for the last ESC.
    pub loop_ns: u64,
}

/// SYNC pulses since the last [`Esc::take_sync0_events`] call.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SyncPulses {
    /// Number of pulses.
    pub count: u32,
    /// Simulation time of the last pulse, ns (valid when `count > 0`).
    pub last_now_ns: u64,
    /// System time of the last pulse (exactly `start + k · cycle`), ns.
    pub last_system_ns: u64,
}

/// A piecewise-linear local clock:
/// `local(t) = anchor_local + (anchor_frac + (t − anchor_now) · (1 + rate)) / 1e12`.
/// The fraction of a nanosecond at the anchor is kept, so re-anchoring (a
/// change of speed) never loses time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct LocalClock {
    anchor_now: u64,
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
            anchor_now: 0,
            anchor_local: offset_ns,
            anchor_frac: 0,
            rate_ppt,
        }
    }

    /// Local time since the anchor at `t`, in 1e-12 ns (fraction included).
    fn elapsed_fine(&self, t: u64) -> i128 {
        let dt = i128::from(t) - i128::from(self.anchor_now);
        dt * (PPT + i128::from(self.rate_ppt)) + i128::from(self.anchor_frac)
    }

    /// Local time at simulation time `t` (rounded down), wrapping like a 64-bit counter.
    pub(super) fn local_at(&self, t: u64) -> u64 {
        let whole = self.elapsed_fine(t).div_euclid(PPT);
        self.anchor_local.wrapping_add(whole as u64)
    }

    /// The earliest simulation time at which the local time reaches `local`
    /// (wrapping comparison), saturated at 0 and `u64::MAX`.
    pub(super) fn now_for_local(&self, local: u64) -> u64 {
        let dl = i128::from(local.wrapping_sub(self.anchor_local) as i64);
        let den = PPT + i128::from(self.rate_ppt);
        let dt = (dl * PPT - i128::from(self.anchor_frac) + den - 1).div_euclid(den);
        let mut t = clamp_u64(i128::from(self.anchor_now) + dt);
        let reached = |c: &Self, t: u64| c.local_at(t).wrapping_sub(local) as i64 >= 0;
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
        t
    }

    /// Changes the speed from `t` on (the local time is continuous at `t`).
    pub(super) fn set_rate(&mut self, t: u64, rate_ppt: i64) {
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
    last_sample: Option<u64>,
    pub(super) line: LineTiming,
    /// Time of the ECAT access in progress at this ESC (frame arrival).
    pub(super) ecat_time: u64,
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
            ecat_time: 0,
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

    /// The ESC's local time at simulation time `now_ns`.
    pub fn local_ns(&self, now_ns: u64) -> u64 {
        self.dc.clock.local_at(now_ns)
    }

    /// The ESC's system time (local time + 0x0920) at simulation time `now_ns`.
    pub fn system_time_ns(&self, now_ns: u64) -> u64 {
        self.local_ns(now_ns)
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
    pub fn next_sync0_at(&self) -> Option<u64> {
        self.dc.sync0.next.map(|s| self.now_for_system(s))
    }

    /// Simulation time of the next SYNC1 pulse, `None` when SYNC1 is not active.
    pub fn next_sync1_at(&self) -> Option<u64> {
        self.dc.sync1.next.map(|s| self.now_for_system(s))
    }

    /// Advances to `now_ns` and returns the SYNC0 pulses since the last call
    /// (count, time of the last one); the count restarts at 0.
    pub fn take_sync0_events(&mut self, now_ns: u64) -> SyncPulses {
        self.tick(now_ns);
        core::mem::take(&mut self.dc.sync0.pending)
    }

    /// Advances to `now_ns` and returns the SYNC1 pulses since the last call.
    pub fn take_sync1_events(&mut self, now_ns: u64) -> SyncPulses {
        self.tick(now_ns);
        core::mem::take(&mut self.dc.sync1.pending)
    }

    /// SYNC0 pulses since power-on (never reset; lets a time loop see progress).
    pub fn sync0_total(&self) -> u64 {
        self.dc.sync0.total
    }

    // -------------------------------------------------------------- internal

    /// Simulation time at which the system time reaches `system`.
    fn now_for_system(&self, system: u64) -> u64 {
        let local = system.wrapping_sub(self.get_u64(dc::SYSTEM_TIME_OFFSET));
        self.dc.clock.now_for_local(local)
    }

    /// The byte `a` of the computed DC registers at time `t` (system time 0x0910).
    pub(super) fn dc_computed(&self, a: u32, t: u64) -> Option<u8> {
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
        let p1 = self.dc.clock.local_at(t0.saturating_add(self.dc.line.loop_ns));
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
        let dt = self.dc.last_sample.map(|l| i128::from(t.saturating_sub(l)));
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
    pub(super) fn dc_tick(&mut self, now: u64) {
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
            last_now_ns: last_now,
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
mod tests {
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
        assert_eq!(c.local_at(0), 5_000);
        assert_eq!(c.local_at(1_000_000_000), 5_000 + 1_000_000_000 + 100_000);
        let slow = LocalClock::new(0, -80_000_000); // -80 ppm
        assert_eq!(slow.local_at(1_000_000_000), 1_000_000_000 - 80_000);
        for clock in [c, slow, LocalClock::new(u64::MAX - 10, 3_456_789)] {
            for target in [0u64, 1, 999, 123_456_789, 1_000_000_007, 98_765_432_123] {
                let target = clock.local_at(0).wrapping_add(target);
                let t = clock.now_for_local(target);
                assert!(clock.local_at(t).wrapping_sub(target) as i64 >= 0);
                if t > 0 {
                    assert!(
                        (clock.local_at(t - 1).wrapping_sub(target) as i64) < 0,
                        "earliest"
                    );
                }
            }
        }
        // a change of speed keeps the time continuous
        let mut c = c;
        let before = c.local_at(2_000_000);
        c.set_rate(2_000_000, -50_000_000);
        assert_eq!(c.local_at(2_000_000), before);
        assert_eq!(c.local_at(3_000_000), before + 1_000_000 - 50);
    }

    #[test]
    fn esc_local_and_system_time_follow_the_configured_clock() {
        let mut e = esc_with_clock(50_000, 1_000); // +50 ppm
        assert_eq!(e.local_ns(2_000_000_000), 1_000 + 2_000_000_000 + 100_000);
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
        assert_eq!(u64::from_le_bytes(b), e.system_time_ns(1_000_000_000));
    }

    #[test]
    fn receive_times_per_port_follow_the_line() {
        let mut a = esc_with_clock(0, 0);
        let mut b = esc_with_clock(20_000, 1_000_000); // +20 ppm, another phase
        a.set_line_timing(LineTiming {
            arrival_ns: 0,
            loop_ns: 500,
        });
        b.set_line_timing(LineTiming {
            arrival_ns: 250,
            loop_ns: 0,
        });
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
        assert_eq!(pu, b.local_ns(t + 250), "port 0 at its arrival, local clock");
        assert_eq!((p0, p1), (pu as u32, pu as u32), "last slave: port 1 closed");
    }

    #[test]
    fn ecat_system_time_is_taken_at_the_frames_arrival() {
        let mut e = esc_with_clock(0, 0);
        e.set_line_timing(LineTiming {
            arrival_ns: 750,
            loop_ns: 0,
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
        a.set_line_timing(LineTiming {
            arrival_ns: 0,
            loop_ns: 500,
        });
        b.set_line_timing(LineTiming {
            arrival_ns: 250,
            loop_ns: 0,
        });
        let mut t = 1_000_000u64;
        for (p, addr) in [(0u16, 0x1000u16), (1, 0x1001)] {
            xfer(
                &mut [&mut a, &mut b],
                Command::Apwr,
                phys(pos(p), ::esc::regs::STATION_ADDRESS),
                &addr.to_le_bytes(),
                t,
            );
        }
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
                    let d = a.system_time_ns(t).wrapping_sub(b.system_time_ns(t)) as i64;
                    worst_late = worst_late.max(d.abs());
                }
            });
            let d = difference(&b);
            let sync = a.system_time_ns(t).wrapping_sub(b.system_time_ns(t)) as i64;
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
        let sync = a.system_time_ns(t).wrapping_sub(b.system_time_ns(t)) as i64;
        assert!(sync.abs() <= 2 && difference(&b).abs() <= 2, "{sync}");
        // 10 ms cycles only (gains reduced): still converges
        let (a, b, t) = drift_run(50_000, -80_000, 0, 0, 1_000, 10_000_000, |_, _, _| {});
        let sync = a.system_time_ns(t).wrapping_sub(b.system_time_ns(t)) as i64;
        assert!(sync.abs() <= 5, "{sync}");
    }

    #[test]
    fn drift_control_with_time_filter_depth_stays_stable() {
        let mut a = esc_with_clock(0, 0);
        let mut b = esc_with_clock(100_000, 0);
        for (p, addr) in [(0u16, 0x1000u16), (1, 0x1001)] {
            xfer(
                &mut [&mut a, &mut b],
                Command::Apwr,
                phys(pos(p), ::esc::regs::STATION_ADDRESS),
                &addr.to_le_bytes(),
                0,
            );
        }
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
        let sync = a.system_time_ns(t).wrapping_sub(b.system_time_ns(t)) as i64;
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
        while let Some(t) = e.next_sync0_at().filter(|&t| t <= until) {
            let p = e.take_sync0_events(t);
            assert_eq!((p.count, p.last_now_ns), (1, t));
            out.push((t, p.last_system_ns));
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
        assert_eq!(e.take_sync0_events(1_000).count, 0);
        let edges = sync0_edges(&mut e, 200_000_000);
        assert!(edges.len() > 150);
        for (k, &(t, sys)) in edges.iter().enumerate() {
            assert_eq!(sys, start + k as u64 * 1_000_000);
            assert!(
                e.system_time_ns(t) >= sys && e.system_time_ns(t - 1) < sys,
                "edge exact"
            );
        }
        // in simulation time the period is 1 ms / (1 - 37 ppm)
        let (t0, _) = edges[0];
        let (t100, _) = edges[100];
        assert!(((t100 - t0) as i64 - 100_003_701).abs() <= 1, "{}", t100 - t0);
        // 0x0990 reads the next pulse
        let now = e.now_ns();
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
        e.tick(99_999);
        assert_eq!(e.get_u8(dc::SYNC0_STATUS), 0);
        e.tick(100_000);
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
        let p = e.take_sync0_events(330_000);
        assert_eq!((p.count, p.last_system_ns), (5, 300_000));
        assert_eq!(e.next_sync0_at(), Some(350_000));
        // masked out: no AL event, the status still shows it
        e.write(::esc::regs::AL_EVENT_MASK, &(!al_event::SYNC0).to_le_bytes())
            .unwrap();
        e.read(dc::SYNC0_STATUS, &mut s).unwrap();
        e.tick(350_000);
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
            while let Some(t) = e.next_sync1_at().filter(|&t| t < 2_000_000) {
                e.take_sync1_events(t);
                times.push(t);
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
        assert_eq!(e.next_sync0_at(), Some(1_000_000));
        let mut e = esc_with_clock(0, 0);
        start_sync(&mut e, 100_000, 300_000, 0, 0x03, 1_000_001);
        assert_eq!(e.next_sync0_at(), Some(1_300_000));
    }
}
