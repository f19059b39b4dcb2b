//! Fine interpolation of cyclic set-points (spec §10; C-114 – C-120).
//!
//! [`FineInterpolator`] (ip, csp) takes one position set-point per master
//! cycle and gives one position set-point per control cycle, N = master /
//! control steps per set-point difference, plus velocity and acceleration
//! feedforward. [`VelocityInterpolator`] (csv) does the same for a velocity
//! set-point.
//!
//! # Timing
//!
//! The set-point consumed at a master-cycle boundary is reached after exactly
//! N control cycles: the first control cycle after its arrival adds the first
//! single step (C-115), the N-th ends on it. The output therefore follows the
//! master's trajectory with a delay of one master cycle minus one control
//! cycle ([`FineInterpolator::delay_ns`]), the same for every order.
//!
//! # Arithmetic
//!
//! Every order evaluates the Newton polynomial through the last 2, 3 or 4
//! set-points p₋₃ … p₀ (backward differences ∇¹ = p₀ − p₋₁, ∇², ∇³) on the
//! last interval, t = k/N, k = 1 … N:
//!
//! x(t) = p₋₁ + t·∇¹ + t(t−1)/2·∇² + (t+1)t(t−1)/6·∇³
//!
//! exactly, as one integer fraction over 6N³ rounded to the nearest increment
//! (`i64`, no floating point on the position path). At constant velocity ∇² =
//! ∇³ = 0, so every order gives round(p₋₁ + k·∇¹/N): the exact trajectory
//! rounded to whole increments, zero increments of error, the remainder of
//! ∇¹/N distributed evenly, and exactly p₀ at k = N. Differences are taken
//! with wrap-around (`wrapping_sub`), so crossing `i32::MAX` changes nothing.

use crate::cycle::CycleRatio;
use crate::float;
use crate::Event;
use nanos::Nanos;

/// Order of the position interpolation polynomial (I425, spec §10.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InterpolationOrder {
    /// Straight line between the last two set-points.
    Linear,
    /// Parabola through the last three set-points.
    Quadratic,
    /// Cubic through the last four set-points.
    Cubic,
}

/// Source of the velocity feedforward (I425, spec §10.2, C-118, C-119).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FeedforwardSource {
    /// Derived by the drive from the interpolation polynomial (I425 = 0, 4, 5).
    Internal,
    /// The master's velocity offset 60B1h (A592), linearly interpolated
    /// between master cycles (I425 = 1, 3).
    External,
}

/// Why an interpolator configuration is refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConfigError {
    /// I425 value that the spec does not describe (2, or above 5).
    UnknownI425(u8),
    /// I25 outside 0 … 100 % or not finite.
    FeedforwardWeight,
}

/// Maps I425 "Speed feed forward – interpolation" to order and source
/// (spec §10.2 table): 0 internal linear, 1 external linear, 3 external
/// quadratic, 4 internal quadratic, 5 internal cubic; 2 is undescribed and
/// refused.
pub fn from_i425(i425: u8) -> Result<(InterpolationOrder, FeedforwardSource), ConfigError> {
    match i425 {
        0 => Ok((InterpolationOrder::Linear, FeedforwardSource::Internal)),
        1 => Ok((InterpolationOrder::Linear, FeedforwardSource::External)),
        3 => Ok((InterpolationOrder::Quadratic, FeedforwardSource::External)),
        4 => Ok((InterpolationOrder::Quadratic, FeedforwardSource::Internal)),
        5 => Ok((InterpolationOrder::Cubic, FeedforwardSource::Internal)),
        other => Err(ConfigError::UnknownI425(other)),
    }
}

/// Configuration of a [`FineInterpolator`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InterpolatorConfig {
    /// Master cycle A291 over control cycle A150 (validated).
    pub ratio: CycleRatio,
    /// Polynomial order (I425).
    pub order: InterpolationOrder,
    /// Feedforward source (I425).
    pub feedforward: FeedforwardSource,
    /// I25 speed feedforward weight in % (0 … 100; 0 disables, C-120).
    pub velocity_feedforward_percent: f32,
    /// I423 maximum extrapolation period (C-117).
    pub max_extrapolation: Nanos,
}

/// One set-point from the master, delivered once per master cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MasterSetpoint {
    /// Position set-point 60C1h:01 (A601, ip) or 607Ah (A567, csp), increments.
    pub position: i32,
    /// Velocity offset 60B1h (A592) in increments/s; used only with
    /// [`FeedforwardSource::External`]. A non-finite value counts as 0.
    pub velocity_offset: f32,
}

/// One control cycle's output of the [`FineInterpolator`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InterpolatorOutput {
    /// Position set-point for the position controller, increments.
    pub position: i32,
    /// Velocity feedforward, increments/s, already weighted by I25.
    pub velocity_feedforward: f32,
    /// Acceleration feedforward, increments/s² (not weighted by I25).
    pub acceleration_feedforward: f32,
    /// The current master cycle is extrapolated (no set-point arrived).
    pub extrapolating: bool,
}

/// The interpolator's fault.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InterpolationFault {
    /// Extrapolation lasted longer than I423: event 78 cause 3 (C-117).
    ExtrapolationOverrun,
}

impl InterpolationFault {
    /// The drive event this fault raises.
    pub const fn event(&self) -> Event {
        match self {
            InterpolationFault::ExtrapolationOverrun => Event::EXTRAPOLATION_OVERRUN,
        }
    }
}

/// Counts extrapolated time against I423 (shared by both interpolators).
#[derive(Debug, Clone, Copy)]
struct ExtrapolationMonitor {
    /// I423.
    limit: Nanos,
    /// Time extrapolated since the last real set-point.
    extrapolated: Nanos,
    /// A set-point has arrived since `start`; before that nothing is counted.
    armed: bool,
    /// Latched fault, cleared only by `start`.
    faulted: bool,
}

impl ExtrapolationMonitor {
    const fn new(limit: Nanos) -> Self {
        Self {
            limit,
            extrapolated: Nanos::ZERO,
            armed: false,
            faulted: false,
        }
    }

    fn received(&mut self) {
        self.extrapolated = Nanos::ZERO;
        self.armed = true;
    }

    /// One master cycle of `master_ns` is extrapolated.
    fn missed(&mut self, master_ns: u32) -> Result<(), InterpolationFault> {
        if self.armed {
            self.extrapolated = self
                .extrapolated
                .saturating_add(Nanos::from_ns(u64::from(master_ns)));
            if self.extrapolated > self.limit {
                self.faulted = true;
                return Err(InterpolationFault::ExtrapolationOverrun);
            }
        }
        Ok(())
    }
}

/// Fine interpolator of ip and csp (spec §10.1, §10.2).
///
/// Call [`start`](Self::start) when the mode becomes active, then
/// [`cycle`](Self::cycle) once per control cycle.
#[derive(Debug, Clone)]
pub struct FineInterpolator {
    config: InterpolatorConfig,
    /// Set-points p₋₃, p₋₂, p₋₁, p₀ (increments), p₀ the newest.
    p3: i32,
    p2: i32,
    p1: i32,
    p0: i32,
    /// External velocity at p₋₁ and p₀, increments/s.
    v1: f32,
    v0: f32,
    /// Backward differences of the current segment, increments (∇¹ < 2³¹,
    /// |∇²| < 2³², |∇³| < 2³³); zero above the order.
    d1: i64,
    d2: i64,
    d3: i64,
    /// Single steps done in the current segment, 1 … N; N means a boundary
    /// is due at the next call.
    k: u32,
    /// Latest set-point offered since the last boundary.
    pending: Option<MasterSetpoint>,
    monitor: ExtrapolationMonitor,
    extrapolating: bool,
    /// The last set-point that arrived (not extrapolated), increments.
    last_real: i32,
    /// Master cycles extrapolated since `last_real`.
    since_real: u32,
    /// The master's last increment per master cycle (between the last two
    /// set-points that arrived, spread over the cycles between them): what a
    /// missing set-point is extrapolated with (C-116).
    step: i32,
}

/// The master's increment per master cycle after a gap: `moved` over the
/// `missed` + 1 cycles since the last set-point that arrived, rounded half
/// up (checked: no panic path). Out of line: it runs after a gap only, and
/// its 64-bit division would weigh on the cycle's common path.
#[cold]
#[inline(never)]
fn step_after_gap(moved: i32, missed: u32) -> i32 {
    let cycles = i64::from(missed) + 1;
    let step = (2 * i64::from(moved) + cycles).checked_div_euclid(2 * cycles);
    step.and_then(|s| i32::try_from(s).ok()).unwrap_or(0)
}

impl FineInterpolator {
    /// A new interpolator at standstill at position 0; validates I25.
    pub fn new(config: InterpolatorConfig) -> Result<Self, ConfigError> {
        let w = config.velocity_feedforward_percent;
        if !w.is_finite() || !(0.0..=100.0).contains(&w) {
            return Err(ConfigError::FeedforwardWeight);
        }
        let mut s = Self {
            config,
            p3: 0,
            p2: 0,
            p1: 0,
            p0: 0,
            v1: 0.0,
            v0: 0.0,
            d1: 0,
            d2: 0,
            d3: 0,
            k: 0,
            pending: None,
            monitor: ExtrapolationMonitor::new(config.max_extrapolation),
            extrapolating: false,
            last_real: 0,
            since_real: 0,
            step: 0,
        };
        s.start(0);
        Ok(s)
    }

    /// The configuration.
    pub const fn config(&self) -> &InterpolatorConfig {
        &self.config
    }

    /// (Re)starts at standstill at `position` (increments, normally the
    /// actual position when ip/csp becomes active); clears a latched fault.
    /// The next [`cycle`](Self::cycle) is a master-cycle boundary. The
    /// extrapolation monitor counts only after the first set-point arrived.
    pub fn start(&mut self, position: i32) {
        self.p3 = position;
        self.p2 = position;
        self.p1 = position;
        self.p0 = position;
        self.v1 = 0.0;
        self.v0 = 0.0;
        self.d1 = 0;
        self.d2 = 0;
        self.d3 = 0;
        self.k = self.config.ratio.n();
        self.pending = None;
        self.monitor = ExtrapolationMonitor::new(self.config.max_extrapolation);
        self.extrapolating = false;
        self.last_real = position;
        self.since_real = 0;
        self.step = 0;
    }

    /// Delay of the output behind the master's trajectory: one master cycle
    /// minus one control cycle, ns.
    pub const fn delay_ns(&self) -> u32 {
        self.config.ratio.master_ns() - self.config.ratio.control_ns()
    }

    /// The fault is latched (until [`start`](Self::start)).
    pub const fn is_faulted(&self) -> bool {
        self.monitor.faulted
    }

    /// One control cycle. `setpoint` is `Some` in the control cycle in which a
    /// new master set-point arrived (PDO received); it is taken at the next
    /// master-cycle boundary (the latest one wins). A boundary without a new
    /// set-point extrapolates with the last increment (C-116); extrapolating
    /// longer than I423 returns the fault (event 78 cause 3, C-117), which
    /// stays latched.
    pub fn cycle(
        &mut self,
        setpoint: Option<MasterSetpoint>,
    ) -> Result<InterpolatorOutput, InterpolationFault> {
        if self.monitor.faulted {
            return Err(InterpolationFault::ExtrapolationOverrun);
        }
        if setpoint.is_some() {
            self.pending = setpoint;
        }
        let n = self.config.ratio.n();
        if self.k >= n {
            self.boundary()?;
        }
        self.k = self.k.saturating_add(1).min(n);
        Ok(self.evaluate())
    }

    /// Master-cycle boundary: take the new set-point or extrapolate one.
    ///
    /// A missing set-point is extrapolated with the master's last increment
    /// per master cycle (`step`): after a gap it is the
    /// increment from the set-point before the gap to the one after it,
    /// spread over the cycles between, not the step from the last
    /// extrapolated point to the new set-point. That step is the correction
    /// of the extrapolation's error, and extrapolating with it again at the
    /// next gap multiplies the error by −(gap − 1): a master missing every
    /// third set-point for a while sent the demand away by revolutions.
    fn boundary(&mut self) -> Result<(), InterpolationFault> {
        self.k = 0;
        let next = match self.pending.take() {
            Some(sp) => {
                self.monitor.received();
                self.extrapolating = false;
                let moved = sp.position.wrapping_sub(self.last_real);
                self.step = if self.since_real == 0 {
                    // no gap (every cycle but after one): no 64-bit division
                    moved
                } else {
                    step_after_gap(moved, self.since_real)
                };
                self.last_real = sp.position;
                self.since_real = 0;
                let v = if sp.velocity_offset.is_finite() {
                    sp.velocity_offset
                } else {
                    0.0
                };
                MasterSetpoint {
                    position: sp.position,
                    velocity_offset: v,
                }
            }
            None => {
                self.monitor.missed(self.config.ratio.master_ns())?;
                self.extrapolating = self.monitor.armed;
                if self.monitor.armed {
                    self.since_real = self.since_real.saturating_add(1);
                }
                MasterSetpoint {
                    position: self.p0.wrapping_add(self.step),
                    velocity_offset: self.v0,
                }
            }
        };
        self.p3 = self.p2;
        self.p2 = self.p1;
        self.p1 = self.p0;
        self.p0 = next.position;
        self.v1 = self.v0;
        self.v0 = next.velocity_offset;
        // Increments between consecutive set-points (wrap-around).
        let e0 = i64::from(self.p0.wrapping_sub(self.p1));
        let e1 = i64::from(self.p1.wrapping_sub(self.p2));
        let e2 = i64::from(self.p2.wrapping_sub(self.p3));
        self.d1 = e0;
        self.d2 = 0;
        self.d3 = 0;
        match self.config.order {
            InterpolationOrder::Linear => {}
            InterpolationOrder::Quadratic => self.d2 = e0 - e1,
            InterpolationOrder::Cubic => {
                self.d2 = e0 - e1;
                self.d3 = e0 - 2 * e1 + e2;
            }
        }
        Ok(())
    }

    /// Output at step k of N.
    fn evaluate(&self) -> InterpolatorOutput {
        let (n_steps, k_steps) = (self.config.ratio.n(), self.k);
        let offset = if k_steps >= n_steps {
            // the segment's end (every cycle when N = 1): x = p₀ = p₋₁ + ∇¹
            // exactly, without the 64-bit division below
            self.d1
        } else {
            let n = i64::from(n_steps);
            let k = i64::from(k_steps);
            // 6N³·(x − p₋₁) = 6N²k∇¹ + 3Nk(k−N)∇² + (k+N)k(k−N)∇³; with N ≤ 512
            // and the difference bounds every term stays below 2⁵⁸.
            let num =
                6 * n * n * k * self.d1 + 3 * n * k * (k - n) * self.d2 + (k + n) * k * (k - n) * self.d3;
            let den = 6 * n * n * n;
            // Round half up: floor((2·num + den) / (2·den)).
            // (den ≥ 6: N ≥ 1 by construction; checked so no panic path remains)
            (2 * num + den).checked_div_euclid(2 * den).unwrap_or(0)
        };
        // Truncation to i32 is the wrap-around of the position counter.
        let position = self.p1.wrapping_add(offset as i32);

        let master_s = self.config.ratio.master_ns() as f32 * 1e-9;
        let t = k_steps as f32 / n_steps as f32;
        let (velocity, acceleration) = match self.config.feedforward {
            // a straight segment (constant velocity, ∇² = ∇³ = 0): the
            // polynomial's derivative is ∇¹ and its second derivative 0
            // exactly (what the general path gives, master_s > 0), without
            // its float conversions and products
            FeedforwardSource::Internal if self.d2 == 0 && self.d3 == 0 => {
                (float::from_i64(self.d1) / master_s, 0.0)
            }
            FeedforwardSource::Internal => {
                // dx/dt in increments per master cycle, then per second.
                let d1 = float::from_i64(self.d1);
                let d2 = float::from_i64(self.d2);
                let d3 = float::from_i64(self.d3);
                let v = d1 + (2.0 * t - 1.0) * 0.5 * d2 + (3.0 * t * t - 1.0) / 6.0 * d3;
                let a = d2 + t * d3;
                (v / master_s, a / (master_s * master_s))
            }
            FeedforwardSource::External => {
                let v = self.v1 + t * (self.v0 - self.v1);
                (v, (self.v0 - self.v1) / master_s)
            }
        };
        InterpolatorOutput {
            position,
            velocity_feedforward: velocity * (self.config.velocity_feedforward_percent * 0.01),
            acceleration_feedforward: acceleration,
            extrapolating: self.extrapolating,
        }
    }
}

/// One control cycle's output of the [`VelocityInterpolator`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VelocityOutput {
    /// Velocity set-point, increments/s.
    pub velocity: f32,
    /// Acceleration (slope of the interpolation), increments/s².
    pub acceleration: f32,
    /// The current master cycle is extrapolated (no set-point arrived).
    pub extrapolating: bool,
}

/// Fine interpolator of csv (spec §6.5.3, §10.1): linear between the master's
/// velocity set-points 60FFh, reached after N control cycles; a missing
/// set-point holds the last velocity (its "last increment" is zero
/// acceleration) and counts against I423 like the position interpolator.
#[derive(Debug, Clone)]
pub struct VelocityInterpolator {
    ratio: CycleRatio,
    /// Velocity set-points v₋₁ and v₀, increments/s.
    v1: f32,
    v0: f32,
    k: u32,
    pending: Option<f32>,
    monitor: ExtrapolationMonitor,
    extrapolating: bool,
    max_extrapolation: Nanos,
}

impl VelocityInterpolator {
    /// A new interpolator at velocity 0; `max_extrapolation` is I423.
    pub const fn new(ratio: CycleRatio, max_extrapolation: Nanos) -> Self {
        Self {
            ratio,
            v1: 0.0,
            v0: 0.0,
            k: ratio.n(),
            pending: None,
            monitor: ExtrapolationMonitor::new(max_extrapolation),
            extrapolating: false,
            max_extrapolation,
        }
    }

    /// (Re)starts at `velocity` (increments/s; non-finite counts as 0) and
    /// clears a latched fault.
    pub fn start(&mut self, velocity: f32) {
        let v = if velocity.is_finite() { velocity } else { 0.0 };
        self.v1 = v;
        self.v0 = v;
        self.k = self.ratio.n();
        self.pending = None;
        self.monitor = ExtrapolationMonitor::new(self.max_extrapolation);
        self.extrapolating = false;
    }

    /// One control cycle; `setpoint` (increments/s) is `Some` in the cycle a
    /// new 60FFh value arrived. Same boundary, extrapolation and fault rules
    /// as [`FineInterpolator::cycle`].
    pub fn cycle(&mut self, setpoint: Option<f32>) -> Result<VelocityOutput, InterpolationFault> {
        if self.monitor.faulted {
            return Err(InterpolationFault::ExtrapolationOverrun);
        }
        if let Some(v) = setpoint {
            self.pending = Some(if v.is_finite() { v } else { 0.0 });
        }
        let n = self.ratio.n();
        if self.k >= n {
            self.k = 0;
            let next = match self.pending.take() {
                Some(v) => {
                    self.monitor.received();
                    self.extrapolating = false;
                    v
                }
                None => {
                    self.monitor.missed(self.ratio.master_ns())?;
                    self.extrapolating = self.monitor.armed;
                    self.v0
                }
            };
            self.v1 = self.v0;
            self.v0 = next;
        }
        self.k = self.k.saturating_add(1).min(n);
        let t = self.k as f32 / n as f32;
        let master_s = self.ratio.master_ns() as f32 * 1e-9;
        let velocity = if self.k == n {
            self.v0
        } else {
            self.v1 + t * (self.v0 - self.v1)
        };
        Ok(VelocityOutput {
            velocity,
            acceleration: (self.v0 - self.v1) / master_s,
            extrapolating: self.extrapolating,
        })
    }
}

#[cfg(test)]
mod tests;
