//! The electrical axis: torque through the current loop.
//!
//! Per axis the shell does what the board's fast task does: once per PWM period
//! (16 kHz) it takes the power stage's sample, runs `foc`'s current loop
//! ([`foc::FocAxis`]) with the iq reference of the axis' torque command
//! (iq = T/kt, id = 0) and loads the compare values into `plant`'s PMSM behind
//! its averaged inverter ([`plant::Plant`]).
//!
//! Mechanics have one source: today's [`Motor`] (inertia, friction with
//! stiction, gravity, end stops, brake, encoder, switches, index). The plant's
//! shaft is driven ([`plant::Shaft::Driven`]) and set to the motor's angle and
//! speed at the start of every PWM period; its electromagnetic torque (the mean
//! of the period's start and end) drives the motor over that period with no
//! further delay ([`Motor::step_applied`]): the current loop's own lag (one
//! period of computation, the PI's bandwidth) replaces the rigid model's
//! one-cycle actuation delay.
//!
//! A control cycle of length dt runs n = round(dt / T_pwm) ≥ 1 PWM periods of the
//! plant; the motor is stepped by dt·(k+1)/n − dt·k/n each, so the motor's time
//! stays the simulation's exactly (under the DC PLL the cycle differs from a
//! whole number of PWM periods by ppm: the plant's periods stretch by as much).
//!
//! The drive core's current seam ([`CurrentControl`]): the simulated drive
//! hands each cycle's [`AxisCommand`] to [`CurrentControl::command`] and puts
//! [`CurrentControl::actual`] (the loop's measured iq and kt·iq, from the last
//! PWM period's sample) into the next cycle's `AxisIo::current`, so 6077h and
//! 6078h show the measurement, as the board's do.
//!
//! A trip of the current loop's protection (over-current, phase sum, DC link,
//! encoder) switches the gates off in its PWM period and reaches the drive
//! core in [`CurrentActual::trip`]: the axis faults with the manual's event
//! (over-current: 33, 2310h). The loop's gains and limits come from the
//! dictionary's motor data ([`ElectricalAxis::set_motor_data`]), the power
//! stage's data and the DC-link window from its A21…A43
//! ([`ElectricalAxis::set_stage_data`]).
//!
//! **The DC link and the brake chopper, per axis.** The plant's DC link is a
//! state (`plant::DcLinkParams`: capacitor, rectifier, brake resistor); each
//! axis' plant has its own, and each axis runs its own brake chopper
//! ([`foc::BrakeChopper`]) on its own link. The SC6 shares one link and one
//! chopper between its two axes; the simulator steps the axes' plants one
//! after the other per control cycle (each over its PWM periods), so a shared
//! link would need the two interleaved period by period. The simplification
//! is exact while one axis brakes and the other's current is zero (what the
//! tests do); with both moving, each axis sees only its own regenerated energy
//! (a real shared link would net motoring against braking). A resistor fault
//! (event 42) is reported by the axis whose chopper saw it.

use crate::motor::{EdgeList, IndexEvent, Motor, MotorOutputs, INC_PER_RAD};
use drive_ecat::axis::{AxisCommand, CurrentActual, CurrentControl, CurrentTrip, DAxisMeans};
use drive_ecat::stage::StageData;
use foc::{BrakeChopper, ChopperParams, FocAxis, LoopParams, MotorData, PowerStage, Protection};
use nanos::Nanos;
use plant::{Plant, PlantParams, Shaft};

/// Which motor model a simulated drive's axes run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PlantModel {
    /// The rigid rotor: the commanded torque acts one control cycle later
    /// ([`Motor::step`]). Cheap: the default.
    #[default]
    Rigid,
    /// The current loop at 16 kHz on the PMSM plant over the same mechanics
    /// ([`ElectricalAxis`]).
    Electrical,
}

/// Current-loop figures of a run, accumulated per PWM period.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CurrentStats {
    /// PWM periods counted.
    pub periods: u64,
    /// PWM periods with the gates on.
    pub enabled_periods: u64,
    /// Sum of the measured iq² over the enabled periods, A².
    pub iq_sq_sum: f64,
    /// Largest |measured iq| with the gates on, A.
    pub iq_max_abs: f64,
    /// Largest |measured id| with the gates on, A.
    pub id_max_abs: f64,
    /// Largest |plant id| (true, without ADC noise) with the gates on, A.
    pub id_true_max_abs: f64,
    /// PWM periods in which the voltage circle limited the controller.
    pub voltage_limited_periods: u64,
}

impl CurrentStats {
    /// Mean square of the measured iq over the enabled periods, A² (its square
    /// root is the rms).
    pub fn iq_mean_square(&self) -> f64 {
        if self.enabled_periods == 0 {
            0.0
        } else {
            self.iq_sq_sum / self.enabled_periods as f64
        }
    }

    fn take(&mut self, foc: &FocAxis, plant: &Plant, gates: bool) {
        self.periods += 1;
        if !gates {
            return;
        }
        let m = foc.measured();
        let (id, iq) = (f64::from(m.current.d), f64::from(m.current.q));
        self.enabled_periods += 1;
        self.iq_sq_sum += iq * iq;
        self.iq_max_abs = self.iq_max_abs.max(abs(iq));
        self.id_max_abs = self.id_max_abs.max(abs(id));
        self.id_true_max_abs = self.id_true_max_abs.max(abs(plant.id()));
        if m.voltage_limited {
            self.voltage_limited_periods += 1;
        }
    }
}

/// The last PWM period of a control cycle, for traces.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CurrentSnapshot {
    /// Measured d and q currents (the current loop's view), A.
    pub id_a: f64,
    /// Measured q current, A.
    pub iq_a: f64,
    /// The iq reference, A.
    pub iq_ref_a: f64,
    /// The motor's phase currents a, b, c (the plant's, without noise), A.
    pub phases_a: [f64; 3],
    /// Electromagnetic torque of the plant, N·m.
    pub torque_nm: f64,
}

/// One axis' current loop and PMSM; the mechanics are the [`Motor`] passed to
/// [`ElectricalAxis::step`].
#[derive(Debug, Clone)]
pub struct ElectricalAxis {
    plant: Plant,
    foc: FocAxis,
    period: Nanos,
    stats: CurrentStats,
    last: CurrentSnapshot,
    command: AxisCommand,
    /// Mean of the measured iq over the last control cycle's PWM periods, A.
    iq_cycle_mean: f32,
    /// The d axis over the last control cycle (voltage and current means).
    d_cycle: Option<DAxisMeans>,
    /// The d voltage of the last PWM period, V (it acts until the next sample).
    prev_ud: f32,
    /// The motor data and loop parameters the loop runs with.
    motor: MotorData,
    params: LoopParams,
    /// The brake chopper on this axis' DC link.
    chopper: BrakeChopper,
    /// The stage's data last applied.
    stage: StageData,
}

impl CurrentControl for ElectricalAxis {
    /// A latched trip clears once the axis commands the power stage off (it
    /// saw the trip in the cycle before and coasts in Fault): a cause that
    /// shows with the gates off (an encoder loss, an over-voltage) trips again
    /// in the next PWM period and keeps the axis in Fault; one that needs the
    /// gates (a short, an over-current, an under-voltage) shows again when
    /// they go on, as a board's latched trip acknowledged with the fault.
    fn command(&mut self, command: &AxisCommand) {
        if !command.power_stage {
            self.foc.reset_trip();
            self.chopper.reset_fault();
        }
        self.command = *command;
    }

    /// The loop's measured iq (with the ADC's quantisation and noise), its
    /// mean over the last control cycle's PWM periods (what a board's fast
    /// task accumulates for the control cycle: one sample's noise, ~7 mA, is
    /// above 2 % of a 10 % current), and the torque it makes by the loop's kt.
    fn actual(&self) -> Option<CurrentActual> {
        let iq = self.iq_cycle_mean;
        let m = self.foc.measured();
        // the loop's record shows its limits from the loop's making on
        let stage = m.stage_limit_a;
        let warning = matches!(m.stage_i2t, Some(s) if s != foc::I2tState::Normal) || self.chopper.warning();
        Some(CurrentActual {
            torque_nm: self.foc.gains().kt_nm_per_a * iq,
            current_a: iq,
            stage_limit_a: stage,
            stage_warning: warning,
            d_axis: self.d_cycle,
            trip: self
                .foc
                .trip()
                .or(self.chopper.fault().then_some(CurrentTrip::BrakeResistor)),
        })
    }
}

impl ElectricalAxis {
    /// The default servo (`foc::MotorData::default_servo`, the plant's
    /// 16 kHz inverter and ADCs, 2 RK4 sub-steps per half period), current loop
    /// at ω_c = 2π·1 kHz. `seed` seeds the ADC noise (one per axis and drive
    /// keeps runs reproducible and axes independent). The defaults are valid
    /// (`foc`'s tests check them); a refusal is returned, never a panic.
    pub fn default_servo(seed: u64) -> Result<Self, foc::ParamError> {
        Self::default_servo_at(seed, 16_000.0)
    }

    /// [`Self::default_servo`] with the inverter and the loop at `pwm_hz`
    /// (8 kHz: the other rate the board offers, feature `pwm-8k`).
    pub fn default_servo_at(seed: u64, pwm_hz: f32) -> Result<Self, foc::ParamError> {
        let mut p = PlantParams::default_servo();
        p.inverter.pwm_hz = f64::from(pwm_hz);
        p.mech.shaft = Shaft::Driven { speed_rad_s: 0.0 };
        // τ = L/R = 3.3 ms, ω_e·h ≤ 0.04 at 3000 rpm: two RK4 steps per half
        // period are exact to well below the ADC's count (4 cost twice as
        // much); one would not do: the plant's gates-off decay (τ = T_pwm/8)
        // needs h ≤ 2.7·τ for RK4 to stay stable
        p.substeps_per_half = 2;
        p.seed = seed;
        let params = LoopParams {
            pwm_hz,
            ..LoopParams::default_16k()
        };
        Self::new(p, MotorData::default_servo(), params)
    }

    /// An axis of this plant and current loop, or the loop parameter refused.
    pub fn new(p: PlantParams, motor: MotorData, params: LoopParams) -> Result<Self, foc::ParamError> {
        // the drive core owns the motor protection (its i²t with U10/U11
        // limits the torque it commands): the loop's own i²t is the backstop
        let stage = Protection {
            i2t_limits: false,
            ..Protection::default_stage()
        };
        let foc = FocAxis::new(motor, params, p.scaling(), stage)?;
        let chopper = BrakeChopper::new(ChopperParams::default_stage(), p.period_s() as f32);
        let (motor_data, loop_params) = (motor, params);
        let period = Nanos::from_ns((1.0e9 / p.inverter.pwm_hz + 0.5) as u64);
        Ok(Self {
            plant: Plant::new(p),
            foc,
            period,
            stats: CurrentStats::default(),
            last: CurrentSnapshot::default(),
            command: AxisCommand::OFF,
            iq_cycle_mean: 0.0,
            d_cycle: None,
            prev_ud: 0.0,
            motor: motor_data,
            params: loop_params,
            chopper,
            stage: StageData::default(),
        })
    }

    /// The motor data of the drive's dictionary (issue 34) for the current
    /// loop: its gains by pole-zero cancellation (Kp = ω_c·L, Ki = ω_c·R with
    /// ω_c = 2π·B64), kt, the rated and the maximum current and the thermal
    /// time constant of its own i²t backstop, and the commutation offset
    /// (B05). Applied when they changed; a set
    /// the loop refuses (ω_c above a fifth of the PWM rate) leaves the loop as
    /// it was. The plant (the motor itself) keeps its own data: motor data
    /// that do not match it detune the loop, as on a real drive.
    pub fn set_motor_data(&mut self, m: &drive_ecat::axis::MotorData) -> Result<(), foc::ParamError> {
        let motor = m.current_loop();
        let params = m.loop_params(self.params);
        // B05: the encoder position of the d axis along phase a
        self.foc.set_commutation_offset(m.commutation_offset_inc);
        if motor == self.motor && params == self.params {
            return Ok(());
        }
        self.foc.set_params(motor, params)?;
        self.motor = motor;
        self.params = params;
        Ok(())
    }

    /// The power stage's data and the DC-link window of the drive's
    /// dictionary (A21…A43, `drive_core::stage`) for the current loop (its
    /// window: A35 under-voltage, A40 over-voltage; the stage's current
    /// A41/A42 and τ A43) and the brake chopper (A21 R, A22 rated power, A23
    /// τ, A38 threshold); the plant's brake resistor is the one A21 names
    /// (0: none fitted). Applied when they changed; the stage's and the
    /// resistor's heat stay.
    pub fn set_stage_data(&mut self, s: &StageData) {
        if *s == self.stage {
            return;
        }
        self.foc.set_protection(s.protection(*self.foc.protection()));
        self.chopper.set_params(s.chopper());
        self.plant.set_brake_resistor(f64::from(s.brake_resistor_ohm));
        self.stage = *s;
    }

    /// The brake chopper on this axis' DC link.
    pub fn chopper(&self) -> &BrakeChopper {
        &self.chopper
    }

    /// The DC link as the loop measured it last, mV (6079h).
    pub fn dc_link_mv(&self) -> u32 {
        (self.foc.measured().vdc * 1000.0 + 0.5) as u32
    }

    /// The plant.
    pub fn plant(&self) -> &Plant {
        &self.plant
    }

    /// The plant, for its settings ([`Plant::set_faults`],
    /// [`Plant::set_dc_link`]): what a test does to the motor, its wiring or
    /// the DC link, never to the drive.
    pub fn plant_mut(&mut self) -> &mut Plant {
        &mut self.plant
    }

    /// The current loop.
    pub fn foc(&self) -> &FocAxis {
        &self.foc
    }

    /// Figures so far.
    pub fn stats(&self) -> &CurrentStats {
        &self.stats
    }

    /// The last PWM period.
    pub fn last(&self) -> &CurrentSnapshot {
        &self.last
    }

    /// One control cycle of length `dt` under the command last given
    /// ([`CurrentControl::command`]): [`ElectricalAxis::step`] with its torque
    /// (none with the power stage off), power stage and brake. With the
    /// plant's `encoder_reversed` fault the position and velocity the drive
    /// reads count the other way too (as the current loop's sample does; the
    /// switch and probe edges keep the rotor's own positions).
    pub fn run(&mut self, motor: &mut Motor, dt: Nanos) -> MotorOutputs {
        let c = self.command;
        let torque = if c.power_stage {
            f64::from(c.torque_nm)
        } else {
            0.0
        };
        let mut out = self.step(motor, torque, c.power_stage, !c.brake_release, dt);
        if self.plant.params().faults.encoder_reversed {
            out.position_inc = out.position_inc.wrapping_neg();
            out.velocity_inc_per_s = -out.velocity_inc_per_s;
        }
        out
    }

    /// One control cycle of length `dt`: the current loop runs with iq =
    /// `torque_nm`/kt (gates on while `power_stage`), the motor moves under the
    /// plant's torque and `brake`. Returns the motor's outputs over the whole
    /// cycle, as [`Motor::step`] does.
    pub fn step(
        &mut self,
        motor: &mut Motor,
        torque_nm: f64,
        power_stage: bool,
        brake: bool,
        dt: Nanos,
    ) -> MotorOutputs {
        self.foc.enable(power_stage);
        // the shortcut only while the link needs no chopper either (its
        // resistor discharges the link period by period)
        let chopping = self.chopper.params().resistor_ohm > 0.0
            && (self.chopper.is_on() || self.foc.measured().vdc >= self.chopper.params().on_v);
        if !power_stage && !chopping && abs(self.plant.id()) + abs(self.plant.iq()) < IDLE_A {
            return self.idle(motor, brake, dt);
        }
        let reference = self.foc.current_reference(torque_nm as f32);
        let pwm = self.period.as_ns().max(1);
        let n = ((dt.as_ns() + pwm / 2) / pwm).max(1);
        let mut merged: Option<MotorOutputs> = None;
        let mut t_prev = 0u64;
        let mut iq_sum = 0.0f32;
        let (mut ud_sum, mut id_sum) = (0.0f32, 0.0f32);
        let injection = self.command.injection.filter(|_| power_stage);
        for k in 1..=n {
            let t_next = (u128::from(dt.as_ns()) * u128::from(k) / u128::from(n)) as u64;
            let h = Nanos::from_ns(t_next - t_prev);
            let sample = self.plant.sample();
            let out = match injection {
                Some(j) => j.step(&mut self.foc, &sample),
                None => self.foc.step(&sample, reference),
            };
            // the sample at this period's start is the centre of the last
            // period: its current pairs with the last period's voltage
            let m = self.foc.measured();
            ud_sum += self.prev_ud;
            id_sum += m.current.d;
            self.prev_ud = m.voltage.d;
            self.plant.apply(&out);
            self.plant.set_chopper(self.chopper.step(m.vdc));
            self.plant
                .set_rotor(motor.position_inc_f64() / INC_PER_RAD, motor.velocity_rad_s());
            let t0 = self.plant.torque_nm();
            self.plant.advance();
            let te = 0.5 * (t0 + self.plant.torque_nm());
            self.stats.take(&self.foc, &self.plant, out.gate_enable);
            iq_sum += self.foc.measured().current.q;
            let o = motor.step_applied(te, brake, h);
            merged = Some(match merged {
                None => o,
                Some(m) => merge(m, &o, Nanos::from_ns(t_prev)),
            });
            t_prev = t_next;
            if k == n {
                let m = self.foc.measured();
                self.last = CurrentSnapshot {
                    id_a: f64::from(m.current.d),
                    iq_a: f64::from(m.current.q),
                    iq_ref_a: f64::from(reference.q),
                    phases_a: self.plant.phase_currents(),
                    torque_nm: self.plant.torque_nm(),
                };
            }
        }
        self.iq_cycle_mean = iq_sum / n as f32;
        self.d_cycle = Some(DAxisMeans {
            voltage_v: ud_sum / n as f32,
            current_a: id_sum / n as f32,
            interval_s: dt.as_ns() as f32 * 1e-9,
        });
        // n ≥ 1: the loop ran; the fallback only satisfies the types
        merged.unwrap_or_else(|| motor.step_applied(0.0, brake, dt))
    }
}

impl ElectricalAxis {
    /// A cycle with the gates off, no current left and the DC link below the
    /// chopper's threshold: no torque, so the motor alone; one PWM period of
    /// the plant and the (disabled) loop at its end keep the sample and the
    /// loop's last angle fresh for the next enable (the link changes only
    /// through the chopper, which is off and stays off).
    fn idle(&mut self, motor: &mut Motor, brake: bool, dt: Nanos) -> MotorOutputs {
        let out = motor.step_applied(0.0, brake, dt);
        let pwm = self.period.as_ns().max(1);
        self.stats.periods += (dt.as_ns() + pwm / 2) / pwm;
        self.plant
            .set_rotor(motor.position_inc_f64() / INC_PER_RAD, motor.velocity_rad_s());
        self.plant.advance();
        let sample = self.plant.sample();
        let pwm_out = self.foc.step(&sample, foc::Dq::default());
        self.plant.apply(&pwm_out);
        let vdc = self.foc.measured().vdc;
        self.plant.set_chopper(self.chopper.step(vdc));
        let m = self.foc.measured();
        self.iq_cycle_mean = m.current.q;
        self.d_cycle = None;
        self.prev_ud = 0.0;
        self.last = CurrentSnapshot {
            id_a: f64::from(m.current.d),
            iq_a: f64::from(m.current.q),
            iq_ref_a: 0.0,
            phases_a: self.plant.phase_currents(),
            torque_nm: self.plant.torque_nm(),
        };
        out
    }
}

/// Below this |id| + |iq| with the gates off an axis is idle (the currents
/// decay with a time constant of an eighth of a PWM period once the gates
/// are off, so a cycle takes them below it): [`ElectricalAxis::step`] then
/// steps only the motor.
const IDLE_A: f64 = 1.0e-9;

/// `later` (a sub-step starting `offset` after `first`'s start) merged into
/// `first`: the state at its end (the torque of its last PWM period), the
/// events of both.
fn merge(first: MotorOutputs, later: &MotorOutputs, offset: Nanos) -> MotorOutputs {
    let mut edges: EdgeList = first.edges;
    edges.append_shifted(&later.edges, offset);
    let index = first.index.or(later.index.map(|i| IndexEvent {
        time_offset: i.time_offset.saturating_add(offset),
        ..i
    }));
    MotorOutputs {
        position_inc: later.position_inc,
        velocity_inc_per_s: later.velocity_inc_per_s,
        torque_applied_nm: later.torque_applied_nm,
        brake_applied: later.brake_applied,
        index,
        index_count: first.index_count.saturating_add(later.index_count),
        inputs: later.inputs,
        edges,
        step_start: first.step_start,
        at_end_stop: later.at_end_stop,
    }
}

fn abs(x: f64) -> f64 {
    if x < 0.0 {
        -x
    } else {
        x
    }
}

#[cfg(test)]
mod tests;
