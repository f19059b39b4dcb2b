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
    /// I423 maximum extrapolation period in ns (C-117).
    pub max_extrapolation_ns: u64,
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
    /// I423 in ns.
    limit_ns: u64,
    /// Time extrapolated since the last real set-point, ns.
    extrapolated_ns: u64,
    /// A set-point has arrived since `start`; before that nothing is counted.
    armed: bool,
    /// Latched fault, cleared only by `start`.
    faulted: bool,
}

impl ExtrapolationMonitor {
    const fn new(limit_ns: u64) -> Self {
        Self {
            limit_ns,
            extrapolated_ns: 0,
            armed: false,
            faulted: false,
        }
    }

    fn received(&mut self) {
        self.extrapolated_ns = 0;
        self.armed = true;
    }

    /// One master cycle of `master_ns` is extrapolated.
    fn missed(&mut self, master_ns: u32) -> Result<(), InterpolationFault> {
        if self.armed {
            self.extrapolated_ns = self.extrapolated_ns.saturating_add(u64::from(master_ns));
            if self.extrapolated_ns > self.limit_ns {
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
            monitor: ExtrapolationMonitor::new(config.max_extrapolation_ns),
            extrapolating: false,
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
        self.monitor = ExtrapolationMonitor::new(self.config.max_extrapolation_ns);
        self.extrapolating = false;
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
    fn boundary(&mut self) -> Result<(), InterpolationFault> {
        self.k = 0;
        let next = match self.pending.take() {
            Some(sp) => {
                self.monitor.received();
                self.extrapolating = false;
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
                MasterSetpoint {
                    position: self.p0.wrapping_add(self.p0.wrapping_sub(self.p1)),
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
    max_extrapolation_ns: u64,
}

impl VelocityInterpolator {
    /// A new interpolator at velocity 0; `max_extrapolation_ns` is I423.
    pub const fn new(ratio: CycleRatio, max_extrapolation_ns: u64) -> Self {
        Self {
            ratio,
            v1: 0.0,
            v0: 0.0,
            k: ratio.n(),
            pending: None,
            monitor: ExtrapolationMonitor::new(max_extrapolation_ns),
            extrapolating: false,
            max_extrapolation_ns,
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
        self.monitor = ExtrapolationMonitor::new(self.max_extrapolation_ns);
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
mod tests {
    use super::*;

    fn config(order: InterpolationOrder, n: u32) -> InterpolatorConfig {
        InterpolatorConfig {
            ratio: CycleRatio::new(n * 125_000, 125_000).unwrap(),
            order,
            feedforward: FeedforwardSource::Internal,
            velocity_feedforward_percent: 100.0,
            max_extrapolation_ns: 3_000_000,
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
        cfg.max_extrapolation_ns = 0;
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
        assert_eq!(
            from_i425(1),
            Ok((InterpolationOrder::Linear, FeedforwardSource::External))
        );
        assert_eq!(
            from_i425(3),
            Ok((InterpolationOrder::Quadratic, FeedforwardSource::External))
        );
    }

    #[test]
    fn c119_i425_maps_internal_orders() {
        assert_eq!(
            from_i425(0),
            Ok((InterpolationOrder::Linear, FeedforwardSource::Internal))
        );
        assert_eq!(
            from_i425(4),
            Ok((InterpolationOrder::Quadratic, FeedforwardSource::Internal))
        );
        assert_eq!(
            from_i425(5),
            Ok((InterpolationOrder::Cubic, FeedforwardSource::Internal))
        );
        assert_eq!(from_i425(2), Err(ConfigError::UnknownI425(2)));
        assert_eq!(from_i425(6), Err(ConfigError::UnknownI425(6)));
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
        let mut vi = VelocityInterpolator::new(ratio, 2_000_000);
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
}
