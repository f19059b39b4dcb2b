//! One axis' current loop: sample in, compare values out, once per PWM period.

use crate::fmath;
use crate::params::{Gains, LoopParams, MotorData, ParamError};
use crate::pi::CurrentPi;
use crate::protect::{CurrentDeviation, DcLink, I2t, I2tState, OverCurrent, PhaseSum, Trip};
use crate::seam::{PwmOut, Sample, Scaling, Shunts};
use crate::svm::{compare_values, compensate_dead_time, svm, PwmCounts};
use crate::transform::{clarke, inverse_park, park, Abc, AlphaBeta, Dq};
use crate::trig::{sin_cos, Angle};

/// PWM periods per step of the i²t model (16 ms at 16 kHz).
pub const I2T_DECIMATION: u32 = 256;

/// The power stage's i²t level below which a limit reached at 100 % is
/// lifted again.
pub const STAGE_I2T_RELEASE: f32 = 0.95;

/// Protection thresholds of one axis (the drive's own limits).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Protection {
    /// Software over-current trip.
    pub over_current: OverCurrent,
    /// Plausibility of the three measured currents (three shunts only).
    pub phase_sum: PhaseSum,
    /// DC-link window.
    pub dc_link: DcLink,
    /// The current following its reference (an open phase).
    pub deviation: CurrentDeviation,
    /// The power stage's current limit (its maximum current), A.
    pub stage_current_a: f32,
    /// The power stage's rated (continuous) current, A: its i²t model's
    /// 100 %, to which the current is limited at 100 % (below
    /// `stage_current_a`).
    pub stage_rated_a: f32,
    /// The power stage's thermal time constant (its i²t model), s.
    pub stage_tau_s: f32,
    /// The loop's own i²t model limits the current to the rated current at
    /// 100 %. Off where the control cycle above owns the motor protection
    /// (the drive core's i²t with U10/U11 limits through the torque it
    /// commands): the loop's model is then only the fault backstop at
    /// [`I2t::fault_level`](crate::protect::I2t::fault_level).
    pub i2t_limits: bool,
}

impl Protection {
    /// Trip at 9 A, phase sum within 0.3 A, DC link 400…800 V (400 V mains,
    /// 565 V nominal), the current error's mean square within a quarter of
    /// the reference's + (0.1 A)² per i²t window, power stage 8 A maximum and
    /// 4 A rated with a thermal time constant of 5 s, the motor's i²t model
    /// limiting: the declared defaults of the drive's dictionary (A35, A40,
    /// A41…A43, `drive_core::stage`), for a loop without one; where the
    /// dictionary exists its values are applied with
    /// [`FocAxis::set_protection`].
    pub const fn default_stage() -> Self {
        Self {
            over_current: OverCurrent { threshold_a: 9.0 },
            phase_sum: PhaseSum { tolerance_a: 0.3 },
            dc_link: DcLink {
                min_v: 400.0,
                max_v: 800.0,
            },
            deviation: CurrentDeviation {
                share: 0.25,
                floor_a: 0.1,
            },
            stage_current_a: 8.0,
            stage_rated_a: 4.0,
            stage_tau_s: 5.0,
            i2t_limits: true,
        }
    }
}

/// What the last step measured and commanded (the actual torque 6077h and current
/// 6078h/PNU 1102 come from `current.q`), with the limits in force and the i²t
/// models' verdicts, which the axis shows from its making on and updates where
/// they change.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Measured {
    /// Phase currents, A.
    pub phases: Abc,
    /// dq currents, A.
    pub current: Dq,
    /// DC-link voltage, V.
    pub vdc: f32,
    /// Electrical angle of the sample.
    pub angle: Angle,
    /// Electrical speed, rad/s (angle difference over one period).
    pub omega_e: f32,
    /// dq voltage commanded, V.
    pub voltage: Dq,
    /// The voltage circle limited the last step.
    pub voltage_limited: bool,
    /// The current limit in force, A.
    pub current_limit_a: f32,
    /// The i²t model's verdict.
    pub i2t: Option<I2tState>,
    /// The power stage's i²t model's verdict.
    pub stage_i2t: Option<I2tState>,
    /// The power stage's own current limit in force, A: its maximum
    /// current, its rated current from its i²t model's 100 % until it falls
    /// below [`STAGE_I2T_RELEASE`].
    pub stage_limit_a: f32,
}

/// What a PWM period applies: the current controllers' output for a current
/// reference, or a voltage open loop.
#[derive(Debug, Clone, Copy)]
enum Command {
    Current(Dq),
    Voltage(Dq, Option<Angle>),
}

/// The current loop of one axis with its protection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FocAxis {
    gains: Gains,
    counts: PwmCounts,
    motor: MotorData,
    scaling: Scaling,
    protection: Protection,
    pi: CurrentPi,
    i2t: I2t,
    i2t_alpha: f64,
    i2t_sum: f32,
    i2t_count: u32,
    i2t_state: I2tState,
    stage_i2t: I2t,
    stage_i2t_alpha: f64,
    stage_i2t_state: I2tState,
    /// The stage's i²t limits: from 100 % until it falls below
    /// [`STAGE_I2T_RELEASE`] (without the hysteresis the limit would toggle
    /// around 100 % every model step).
    stage_limiting: bool,
    last_angle: Option<Angle>,
    trip: Option<Trip>,
    enabled: bool,
    external_limit_a: f32,
    /// The lowest of the limits, A: recomputed where one of them changes
    /// ([`FocAxis::refresh_limits`]), not per step.
    limit_a: f32,
    /// The power stage's own limit in force, A.
    stage_limit_a: f32,
    /// The trip the i²t model step judges: the current deviation (an open
    /// motor connection) first, then the motor's i²t model, then the
    /// stage's (one test in the step instead of three).
    slow_trip: Option<Trip>,
    /// The current error's and the reference's squares summed over the
    /// i²t window's periods with the current loop closed below half the
    /// back-EMF's speed limit, the squares of the reference's steps in the
    /// window, and the periods counted ([`CurrentDeviation`]).
    deviation_sums: (f32, f32, f32, u32),
    /// The reference of the last closed-loop period (zero with the gates
    /// off or open loop): its step to the next is [`Self::step_allowance`]'s.
    deviation_last: Dq,
    /// A healthy loop's error after a reference step Δ, ∑e² over the
    /// periods of its transient, per |Δ|², twice over
    /// ([`step_allowance`]): a step's transient is no deviation, however
    /// small the window's reference (a step late in a window, a pulse).
    step_allowance: f32,
    /// The last window's current deviated.
    deviation_trip: bool,
    /// The reference's mean square of the last window judged (A²): a
    /// window is judged against the larger of its own and this one, so a
    /// reference that fell to zero at a window's start (a torque step to
    /// nothing) leaves the decay of the current it had as the error against
    /// the reference that current followed.
    deviation_last_ref: f32,
    /// Windows left unjudged after an open-loop (voltage-commanded) period:
    /// the current a motor action's injection left decays against the
    /// closed loop's reference (the window of the change and the next).
    deviation_hold: u8,
    measured: Measured,
}

impl FocAxis {
    /// An axis with these parameters, disabled (gates off), or the first parameter
    /// that is refused.
    pub fn new(
        motor: MotorData,
        params: LoopParams,
        scaling: Scaling,
        protection: Protection,
    ) -> Result<Self, ParamError> {
        let gains = Gains::from_motor(&motor, &params)?;
        let i2t = I2t::new(motor.rated_current_a, motor.thermal_time_constant_s);
        let stage_i2t = I2t::new(
            fmath::max(protection.stage_rated_a, 1e-3),
            fmath::max(protection.stage_tau_s, 1e-3),
        );
        Ok(Self {
            gains,
            counts: PwmCounts::new(
                scaling.pwm_period_counts,
                gains.dead_time_duty,
                gains.inv_dead_time_band,
            ),
            motor,
            scaling,
            protection,
            pi: CurrentPi::new(),
            i2t_alpha: i2t.alpha(gains.ts_s * I2T_DECIMATION as f32),
            i2t,
            i2t_sum: 0.0,
            i2t_count: 0,
            i2t_state: I2tState::Normal,
            stage_i2t_alpha: stage_i2t.alpha(gains.ts_s * I2T_DECIMATION as f32),
            stage_i2t,
            stage_i2t_state: I2tState::Normal,
            stage_limiting: false,
            last_angle: None,
            trip: None,
            enabled: false,
            external_limit_a: f32::INFINITY,
            limit_a: 0.0,
            stage_limit_a: 0.0,
            slow_trip: None,
            deviation_sums: (0.0, 0.0, 0.0, 0),
            deviation_last: Dq::default(),
            step_allowance: step_allowance(&gains),
            deviation_trip: false,
            deviation_last_ref: 0.0,
            deviation_hold: 0,
            measured: Measured::default(),
        })
        .map(|mut axis| {
            axis.refresh_limits();
            axis
        })
    }

    /// One step of both i²t models with the mean square current of the last
    /// I2T_DECIMATION periods (out of line: once per 256 steps).
    #[inline(never)]
    fn i2t_model_step(&mut self) {
        let mean_sq = self.i2t_sum * (1.0 / I2T_DECIMATION as f32);
        self.i2t_state = self.i2t.step_alpha(mean_sq, self.i2t_alpha);
        self.stage_i2t_state = self.stage_i2t.step_alpha(mean_sq, self.stage_i2t_alpha);
        if matches!(self.stage_i2t_state, I2tState::Limiting | I2tState::Fault) {
            self.stage_limiting = true;
        } else if self.stage_i2t.level() < STAGE_I2T_RELEASE {
            self.stage_limiting = false;
        }
        self.i2t_sum = 0.0;
        self.i2t_count = 0;
        // the current's plausibility: judged when at least half the window
        // counted (a window mostly at the voltage limit or open loop is not)
        // (not the windows of and after open-loop periods, and each against
        // the larger reference of its own and the last judged window's)
        let (e, r, steps, n) = self.deviation_sums;
        let k = 1.0 / fmath::max(n as f32, 1.0);
        // the reference's steps' healthy transients are no deviation
        let e = fmath::max(e - self.step_allowance * steps, 0.0);
        if self.deviation_hold > 0 {
            self.deviation_hold -= 1;
            self.deviation_last_ref = 0.0;
        } else if n >= I2T_DECIMATION / 2 {
            let reference = fmath::max(r * k, self.deviation_last_ref);
            self.deviation_trip = self.protection.deviation.deviates(e * k, reference);
            self.deviation_last_ref = r * k;
        } else {
            self.deviation_last_ref = r * k;
        }
        self.deviation_sums = (0.0, 0.0, 0.0, 0);
        self.refresh_limits();
    }

    /// The current limit in force and the i²t models' trip, from the limits and
    /// the models' states: after each i²t model step, new motor data and a new
    /// external limit (the step only reads them).
    fn refresh_limits(&mut self) {
        let i2t = self.i2t_state;
        let i2t_limit = if !self.protection.i2t_limits || i2t == I2tState::Normal || i2t == I2tState::Warning
        {
            f32::INFINITY
        } else {
            self.motor.rated_current_a
        };
        // the power stage: its maximum, its rated current while its i²t
        // model is at or above 100 %
        let stage_limit = if self.stage_limiting {
            fmath::min(self.protection.stage_rated_a, self.protection.stage_current_a)
        } else {
            self.protection.stage_current_a
        };
        // the lowest of the limits (`protect::current_limit`, unrolled: all are
        // validated positive, the external one sanitised where it is set)
        self.limit_a = fmath::min(
            fmath::min(self.motor.max_current_a, stage_limit),
            fmath::min(self.external_limit_a, i2t_limit),
        );
        self.stage_limit_a = stage_limit;
        self.slow_trip = if self.deviation_trip {
            Some(Trip::MotorConnection)
        } else if i2t == I2tState::Fault {
            Some(Trip::MotorI2t)
        } else if self.stage_i2t_state == I2tState::Fault {
            Some(Trip::StageI2t)
        } else {
            None
        };
        self.show_limits();
    }

    /// The limits in force and the i²t models' verdicts into the record of
    /// the last step ([`Measured`]).
    fn show_limits(&mut self) {
        let m = &mut self.measured;
        m.current_limit_a = self.limit_a;
        m.i2t = Some(self.i2t_state);
        m.stage_i2t = Some(self.stage_i2t_state);
        m.stage_limit_a = self.stage_limit_a;
    }

    /// The simulated servo's loop (`MotorData::default_servo`,
    /// `LoopParams::default_16k`, `Protection::default_stage`) on `scaling`,
    /// disabled.
    pub fn default_servo(scaling: Scaling) -> Result<Self, ParamError> {
        Self::new(
            MotorData::default_servo(),
            LoopParams::default_16k(),
            scaling,
            Protection::default_stage(),
        )
    }

    /// New motor data and loop parameters; on a refusal nothing changes. The
    /// integrators restart from zero on success.
    pub fn set_params(&mut self, motor: MotorData, params: LoopParams) -> Result<(), ParamError> {
        let gains = Gains::from_motor(&motor, &params)?;
        // keep the winding's heat: the new model starts at the present level
        let x = self.i2t.level();
        self.gains = gains;
        self.counts = PwmCounts::new(
            self.scaling.pwm_period_counts,
            gains.dead_time_duty,
            gains.inv_dead_time_band,
        );
        self.motor = motor;
        self.i2t = I2t::new(motor.rated_current_a, motor.thermal_time_constant_s);
        self.i2t.set_level(x);
        self.i2t_alpha = self.i2t.alpha(gains.ts_s * I2T_DECIMATION as f32);
        self.stage_i2t_alpha = self.stage_i2t.alpha(gains.ts_s * I2T_DECIMATION as f32);
        self.step_allowance = step_allowance(&gains);
        self.pi.reset();
        self.refresh_limits();
        Ok(())
    }

    /// New protection thresholds from now on (the power stage's data and the
    /// DC-link window of the dictionary: its maximum and rated current,
    /// thermal time constant, over-voltage trip and under-voltage limit). The
    /// stage's heat (its i²t level) stays; a latched trip stays. Applied only
    /// when they changed (cheap to call every control cycle).
    pub fn set_protection(&mut self, protection: Protection) {
        if protection == self.protection {
            return;
        }
        let x = self.stage_i2t.level();
        self.stage_i2t = I2t::new(
            fmath::max(protection.stage_rated_a, 1e-3),
            fmath::max(protection.stage_tau_s, 1e-3),
        );
        self.stage_i2t.set_level(x);
        self.stage_i2t_alpha = self.stage_i2t.alpha(self.gains.ts_s * I2T_DECIMATION as f32);
        self.protection = protection;
        self.refresh_limits();
    }

    /// The protection thresholds in force.
    pub fn protection(&self) -> &Protection {
        &self.protection
    }

    /// The gains in force.
    pub fn gains(&self) -> &Gains {
        &self.gains
    }

    /// Gates on (true) or off. Enabling clears the integrators.
    pub fn enable(&mut self, on: bool) {
        if on && !self.enabled {
            self.pi.reset();
        }
        self.enabled = on;
    }

    /// A further current limit, A (2415h in speed mode, P-133); infinity = none.
    pub fn set_external_limit(&mut self, limit_a: f32) {
        // a NaN limit is no licence: 0 A; negative likewise
        self.external_limit_a = if limit_a >= 0.0 { limit_a } else { 0.0 };
        self.refresh_limits();
    }

    /// The latched trip, if any.
    pub fn trip(&self) -> Option<Trip> {
        self.trip
    }

    /// Fault reset: clears the latched trip (a cause still present trips again in
    /// the next step).
    pub fn reset_trip(&mut self) {
        self.trip = None;
        self.deviation_trip = false;
        self.deviation_sums = (0.0, 0.0, 0.0, 0);
        self.refresh_limits();
    }

    /// What the last step measured, and the limits in force.
    pub fn measured(&self) -> &Measured {
        &self.measured
    }

    /// The i²t model.
    pub fn i2t(&self) -> &I2t {
        &self.i2t
    }

    /// The power stage's i²t model.
    pub fn stage_i2t(&self) -> &I2t {
        &self.stage_i2t
    }

    /// The current reference of a torque command: iq = torque / kt, id = 0 (no field
    /// weakening yet: the speed range ends where the back-EMF meets the voltage
    /// circle; a negative id reference there is future work).
    pub fn current_reference(&self, torque_nm: f32) -> Dq {
        Dq {
            d: 0.0,
            q: torque_nm / self.gains.kt_nm_per_a,
        }
    }

    /// One PWM period: the sample of this period's centre in, the compare values of
    /// the next period out. Trips latch and switch the gates off in the same step.
    pub fn step(&mut self, s: &Sample, reference: Dq) -> PwmOut {
        self.step_with(s, Command::Current(reference))
    }

    /// One PWM period with `voltage` applied open loop (dq, V; clamped to the
    /// voltage circle) instead of the current controllers' output: the motor
    /// actions' measurement (identifying R and L). Measurement, protection and
    /// modulation as in [`FocAxis::step`]; the integrators stay reset.
    pub fn step_voltage(&mut self, s: &Sample, voltage: Dq) -> PwmOut {
        self.step_with(s, Command::Voltage(voltage, None))
    }

    /// [`FocAxis::step_voltage`] in a frame at the fixed electrical angle
    /// `frame` instead of the encoder's (a current vector the rotor aligns to,
    /// a voltage along one phase's axis): the measured dq current and the
    /// voltage are in that frame for this period.
    pub fn step_voltage_at(&mut self, s: &Sample, voltage: Dq, frame: Angle) -> PwmOut {
        self.step_with(s, Command::Voltage(voltage, Some(frame)))
    }

    /// The commutation offset (encoder increments at which the rotor's d axis
    /// points along phase a) from now on.
    pub fn set_commutation_offset(&mut self, offset_inc: u32) {
        self.scaling.commutation_offset_inc = offset_inc;
    }

    fn step_with(&mut self, s: &Sample, command: Command) -> PwmOut {
        let sc = &self.scaling;
        let g = &self.gains;
        let [ca, cb, cc] = s.phase_counts;
        let [za, zb, zc] = sc.zero_counts;
        let a = (f32::from(ca) - za) * sc.amps_per_count;
        let b = (f32::from(cb) - zb) * sc.amps_per_count;
        let phases = match sc.shunts {
            Shunts::Three => Abc {
                a,
                b,
                c: (f32::from(cc) - zc) * sc.amps_per_count,
            },
            Shunts::Two => Abc { a, b, c: -a - b },
        };
        let vdc = f32::from(s.dc_link_count) * sc.volts_per_count;

        let angle: Angle = s
            .position_inc
            .wrapping_sub(sc.commutation_offset_inc)
            .wrapping_mul(g.pole_pairs)
            << 12;
        let omega_e = match self.last_angle {
            Some(last) => (angle.wrapping_sub(last) as i32) as f32 * g.omega_per_angle,
            None => 0.0,
        };
        self.last_angle = Some(angle);
        let frame = match command {
            Command::Voltage(_, Some(f)) => f,
            _ => angle,
        };
        let (sin, cos) = sin_cos(frame);
        let current = park(clarke(phases), sin, cos);

        // i²t: the mean square current of I2T_DECIMATION periods, one model step
        self.i2t_sum += current.d * current.d + current.q * current.q;
        self.i2t_count += 1;
        if self.i2t_count >= I2T_DECIMATION {
            self.i2t_model_step();
        }
        let (sc, g) = (&self.scaling, &self.gains);
        if self.trip.is_none() {
            let p = &self.protection;
            // the DC link inside its window (the ordinary case) asks no more
            let dc = if vdc >= p.dc_link.min_v && vdc <= p.dc_link.max_v {
                None
            } else {
                // a low DC link with the gates off is no fault: the stage
                // is only not ready (it trips when they go on)
                p.dc_link
                    .check(vdc)
                    .filter(|&t| self.enabled || t != Trip::DcUnderVoltage)
            };
            // (the phase sum needs no test of the shunts: with two,
            // c = −a − b makes it exactly 0, never implausible)
            self.trip = if p.over_current.tripped(phases) {
                Some(Trip::OverCurrent)
            } else if p.phase_sum.implausible(phases) {
                Some(Trip::PhaseSum)
            } else if dc.is_some() {
                dc
            } else if !s.encoder_ok {
                Some(Trip::EncoderLost)
            } else {
                self.slow_trip
            };
        }
        let limit = self.limit_a;
        // the step's own values; the limits and the models' verdicts are
        // written where they change (`show_limits`, from the axis' making
        // on: issue 34's budget)
        let m = &mut self.measured;
        (m.phases, m.current, m.vdc, m.angle, m.omega_e) = (phases, current, vdc, angle, omega_e);
        let half = sc.pwm_period_counts / 2;
        if self.trip.is_some() || !self.enabled {
            self.measured.voltage = Dq::default();
            self.measured.voltage_limited = false;
            self.pi.reset();
            self.deviation_last = Dq::default();
            return PwmOut {
                compare: [half; 3],
                gate_enable: false,
            };
        }

        let v_max = g.v_limit_per_vdc * vdc;
        let (v, cut) = match command {
            Command::Current(reference) => {
                let (d, q) = fmath::clamp_sym2(reference.d, reference.q, limit);
                let out = self.pi.step(g, Dq { d, q }, current, omega_e, v_max);
                // the reference's step (none mostly: it changes once per
                // control cycle at most; computed anyway, a constant cost)
                let (sd, sq) = (d - self.deviation_last.d, q - self.deviation_last.q);
                self.deviation_last = Dq { d, q };
                self.deviation_sums.2 += sd * sd + sq * sq;
                // judged below half the speed at which the back-EMF takes
                // the whole voltage: there a healthy winding always takes the
                // current (R·I ≪ the voltage), even with the voltage at its
                // limit, which is where an open phase drives the integrators
                if omega_e.abs() * self.motor.psi_vs < 0.5 * v_max {
                    let (ed, eq) = (d - current.d, q - current.q);
                    let (e, r, _, n) = &mut self.deviation_sums;
                    *e += ed * ed + eq * eq;
                    *r += d * d + q * q;
                    *n += 1;
                }
                out
            }
            Command::Voltage(v, _) => {
                self.pi.reset();
                self.deviation_hold = 2;
                self.deviation_last = Dq::default();
                let clamp = |x: f32| fmath::clamp(x, -v_max, v_max);
                let cut = v.d.abs() > v_max || v.q.abs() > v_max;
                (
                    Dq {
                        d: clamp(v.d),
                        q: clamp(v.q),
                    },
                    cut,
                )
            }
        };
        self.measured.voltage = v;
        self.measured.voltage_limited = cut;

        // the voltage acts over the next period, centred one period after the sample
        // rotating (sin, cos) by δ = ω·Ts to second order (|δ| ≤ 0.08 rad at
        // 3000 rpm and 16 kHz: error δ³/6 < 10⁻⁴) instead of a second table lookup
        // (a fixed frame does not turn)
        let delta = match command {
            Command::Voltage(_, Some(_)) => 0.0,
            _ => omega_e * g.ts_s,
        };
        let k = 1.0 - 0.5 * delta * delta;
        let (so, co) = (sin * k + cos * delta, cos * k - sin * delta);
        let v_ab: AlphaBeta = inverse_park(v, so, co);
        let compare = match command {
            // the current loop: modulator, dead-time compensation and counts fused
            Command::Current(_) => compare_values(v_ab, vdc, phases, &self.counts),
            // a motor action's voltage: the separate blocks, and the voltage
            // the compare values realise (their rounding to counts is up to
            // 60 mV per leg at 565 V: a constant voltage's rounding would
            // bias a measurement), less the dead time's share
            Command::Voltage(..) => {
                let (duty, _) = svm(v_ab, vdc, 1.0 / fmath::max(vdc, 1.0));
                let comp = compensate_dead_time(duty, phases, g.dead_time_duty, g.inv_dead_time_band);
                let period = f32::from(sc.pwm_period_counts);
                let cmp = |d: f32| (d * period + 0.5) as u16;
                let compare = [cmp(comp.a), cmp(comp.b), cmp(comp.c)];
                let realised =
                    |c: u16, with: f32, without: f32| (f32::from(c) / period - with + without) * vdc;
                let [ca, cb, cc] = compare;
                let v_abc = Abc {
                    a: realised(ca, comp.a, duty.a),
                    b: realised(cb, comp.b, duty.b),
                    c: realised(cc, comp.c, duty.c),
                };
                self.measured.voltage = park(clarke(v_abc), so, co);
                compare
            }
        };
        PwmOut {
            compare,
            gate_enable: true,
        }
    }
}

/// A healthy loop's error after a step Δ of its reference, ∑e² over the
/// transient per |Δ|², twice over: the loop is first order with ω_c behind
/// one period's delay (pole-zero cancellation, [`Gains::from_motor`]), so the
/// error is Δ in the period of the step and the next, then Δ·aᵏ with
/// a = e^(−ω_c·Ts): ∑e² = Δ²·(1 + 1/(1 − a²)) (2.26·Δ² at 1 kHz and
/// 16 kHz). The factor 2 covers the decoupling's transient on the other
/// axis and the voltage's limit below half the back-EMF's speed, where the
/// check counts.
fn step_allowance(g: &Gains) -> f32 {
    let omega_c = g.kp_q / g.lq_h;
    let a2 = libm::expf(-2.0 * omega_c * g.ts_s);
    2.0 * (1.0 + 1.0 / fmath::max(1.0 - a2, 1e-6))
}
