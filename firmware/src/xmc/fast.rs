//! The current-loop fast task of the board images (issue 34): both axes'
//! `foc::FocAxis` once per PWM period, on the VADC's "conversions done"
//! interrupt (VADC0_G0_0, raised by the DC-link result, the last of the five
//! conversions CCU80 triggers at the PWM centre).
//!
//! Per axis and period ([`FastLoop::period`]): the phase currents U and V
//! (W = −U − V, two shunts) and the DC link from the ADC, the encoder
//! position and phase-error flag from POSIF, the CCU8's trap flag; the
//! current loop's step with the iq reference the control cycle set (or a
//! motor action's d voltage, whose d-axis means go back with the
//! measurement: B41 "calibrate motor" phases the encoder on the board as in
//! the simulator); the compare values to the CCU8's shadow registers (transferred at the period
//! boundary). An axis runs (pins to the CCU8, gate enable high) only while
//! the control cycle commands it on and neither the loop nor the trap has
//! tripped; otherwise its pins are held low (`power-pins`) and the gate
//! enable is low once no axis runs: within the period that saw the trip.
//!
//! The control cycle and this task meet in [`Link`] (one per axis, an RTIC
//! resource the control cycle locks for a few instructions): the control
//! cycle hands in its command ([`Link::command`]: iq = torque/kt, id = 0,
//! the power stage) and takes the measurement for its next cycle
//! ([`Link::io`]: the position, the mean iq since the last cycle, the
//! trip), as the simulator's `CurrentControl` seam does (hil-sim
//! `electrical`). A trip (the loop's, or the trap as over-current) keeps the
//! axis off until it is commanded on again, which the drive does only after
//! the fault was acknowledged; a cause still present trips again in the
//! first period. The control cycle is told of a trip once (the axis latches
//! the fault itself): a trip still reported after the fault reset would
//! fault the axis again at once (the drive core's monitor raises it on
//! every cycle that carries it), and the axis could never be enabled again.
//!
//! The motor is the dictionary's (group B, 6073h/6075h: the drive core's
//! `MotorData`, converted once by `MotorData::current_loop`): the control
//! cycle hands it over with its command, and the fast task applies a changed
//! set before its next step (gains by pole-zero cancellation, the commutation
//! offset B05, the torque constant the command divides by). The power
//! stage's data (A35 under-voltage limit, A40 over-voltage trip, A41/A42/A43
//! its currents and thermal time constant: `drive_ecat::stage::StageData`)
//! reach the loops the same way when the dictionary's configuration moved.
//! The board's scaling and the rest of the protection are the constants of
//! [`board`]: all assumptions until a power board is at hand
//! (docs/hardware.md; the brake chopper's output is not wired).

use super::motor::{Motor, DEAD_NS, PWM_HZ};
use drive_ecat::axis::{AxisCommand, AxisIo, CurrentActual, CurrentTrip, DAxisMeans, Injection, MotorData};
use drive_ecat::stage::StageData;
use foc::{Dq, FocAxis, Sample};
use xmc_motor::pwm::Duty;

/// The board's constants of the current loop, declared once. None is
/// checked against a power board (docs/hardware.md, "Power stage").
pub mod board {
    use foc::{LoopParams, MotorData, Protection, Scaling, Shunts};

    /// Amperes per ADC count of a phase current: a 12-bit conversion over
    /// ±10 A (4.88 mA per count; the current-sense amplifier's gain and the
    /// shunt decide it). Positive: current into the motor (the amplifier's
    /// polarity is assumed so).
    pub const AMPS_PER_COUNT: f32 = 20.0 / 4096.0;
    /// ADC count of zero current: mid-scale (no offset calibration yet).
    pub const ZERO_COUNT: f32 = 2048.0;
    /// Volts per DC-link ADC count: 0.25 V (1023 V full scale: the divider
    /// of a 400 V-mains stage).
    pub const VOLTS_PER_COUNT: f32 = 0.25;
    /// Encoder lines per revolution (four counts per line): 4096, a power of
    /// two so the position scales to 2^20 increments per turn exactly.
    pub const ENCODER_LINES: u32 = 4096;
    /// Increments (2^20 per revolution) per encoder count.
    pub const INC_PER_COUNT: i32 = ((1u32 << 20) / (4 * ENCODER_LINES)) as i32;
    const _: () = assert!(INC_PER_COUNT as u32 * 4 * ENCODER_LINES == 1 << 20);
    /// Encoder increments of the d axis (the commutation offset) until the
    /// dictionary's B05 arrives with the first control cycle: 0, i.e. the
    /// rotor assumed aligned with phase U at power-on. An incremental
    /// encoder needs B41 "calibrate motor" after each power-on before the
    /// loop can commutate (docs/hardware.md).
    pub const COMMUTATION_OFFSET_INC: u32 = 0;
    /// Compare value of a full PWM period as the loop computes it: 2^15, so
    /// the CCU8's Q16 duty is twice the loop's compare value (the CCU8
    /// itself resolves 1/4500 of the period at 16 kHz).
    pub const LOOP_PERIOD_COUNTS: u16 = 1 << 15;
    /// The loop's scaling of the board's integers.
    pub const SCALING: Scaling = Scaling {
        amps_per_count: AMPS_PER_COUNT,
        zero_counts: [ZERO_COUNT; 3],
        volts_per_count: VOLTS_PER_COUNT,
        pwm_period_counts: LOOP_PERIOD_COUNTS,
        shunts: Shunts::Two,
        commutation_offset_inc: COMMUTATION_OFFSET_INC,
    };
    /// The motor until the dictionary's data arrive with the first control
    /// cycle ([`super::Link::command`]): the simulator's default servo
    /// (`foc::MotorData::default_servo`: 3.6 Ω, 12 mH, 4 pole pairs, kt
    /// 0.65 N·m/A, 2 A rated, 6 A max), which is also what the dictionary
    /// declares by default.
    pub const MOTOR: MotorData = MotorData::default_servo();
    /// The loop at the image's PWM rate with ω_c = 2π·1 kHz, dead time as
    /// the CCU8's.
    pub const LOOP: LoopParams = LoopParams {
        pwm_hz: super::PWM_HZ as f32,
        dead_time_s: super::DEAD_NS as f32 * 1.0e-9,
        ..LoopParams::default_16k()
    };
    /// The stage's protection (`foc::Protection::default_stage`: trip at
    /// 9 A, DC link 400…800 V, stage 8 A); the loop's i²t only as the
    /// backstop: the drive core's i²t limits the torque it commands.
    pub const PROTECTION: Protection = Protection {
        i2t_limits: false,
        ..Protection::default_stage()
    };
}

/// One axis between the control cycle and the fast task.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Link {
    /// Torque constant of the loop, N·m/A (the motor data's B17 once the
    /// fast task applied them).
    kt: f32,
    /// Control → fast: the motor data last handed over.
    motor: Option<MotorData>,
    /// `motor` changed and the fast task has not applied it yet.
    motor_new: bool,
    /// Control → fast: the power stage's data last handed over, not yet
    /// applied when `Some`.
    stage: Option<StageData>,
    /// Fast → control: the DC link at the last period, V.
    vdc_v: f32,
    /// Control → fast: power stage commanded on.
    on: bool,
    /// Control → fast: iq reference, A.
    iq_ref_a: f32,
    /// Control → fast: a motor action's d voltage instead of the current
    /// controllers (B41 calibrate, B42 optimise, …; only with the power
    /// stage on).
    injection: Option<Injection>,
    /// Fast → control: sums of the applied d voltage and the measured d
    /// current over the periods in `periods` (the actions' measurement).
    ud_sum_v: f32,
    id_sum_a: f32,
    /// The d voltage of the last period: the current sampled at this
    /// period's centre pairs with it.
    prev_ud_v: f32,
    /// Fast → control: sum of the measured iq since the last [`Link::io`], A.
    iq_sum_a: f32,
    /// PWM periods in `iq_sum_a`.
    periods: u32,
    /// The last period's measured iq, A.
    iq_last_a: f32,
    /// Encoder position, increments.
    position_inc: i32,
    /// POSIF reported no phase error since the last [`Link::io`].
    encoder_ok: bool,
    /// The DC link within the stage's window at the last period.
    supply_ok: bool,
    /// The latched trip (cleared when the axis is commanded on again).
    trip: Option<CurrentTrip>,
    /// `trip` was handed to the control cycle.
    trip_reported: bool,
    /// The power stage's current limit in force at the last period, A
    /// (infinite while the loop models no stage i²t).
    stage_limit_a: f32,
    /// The power stage's i²t at or above its warning level.
    stage_warning: bool,
}

impl Link {
    /// An axis commanded off with nothing measured yet (supply missing
    /// until the first period says otherwise).
    pub const fn new(kt: f32) -> Link {
        Link {
            kt,
            motor: None,
            motor_new: false,
            stage: None,
            vdc_v: 0.0,
            on: false,
            iq_ref_a: 0.0,
            injection: None,
            ud_sum_v: 0.0,
            id_sum_a: 0.0,
            prev_ud_v: 0.0,
            iq_sum_a: 0.0,
            periods: 0,
            iq_last_a: 0.0,
            position_inc: 0,
            encoder_ok: true,
            supply_ok: false,
            trip: None,
            trip_reported: false,
            stage_limit_a: f32::INFINITY,
            stage_warning: false,
        }
    }

    /// The control cycle's command: iq = torque/kt (id = 0), the power
    /// stage; no current with the power stage off. `motor`: the axis'
    /// motor data in force (the dictionary's); a change is applied by the
    /// fast task before its next step (a set the loop refuses leaves it as
    /// it was; the dictionary refuses such values where they are written).
    /// `stage`: the power stage's data when the dictionary's configuration
    /// moved (`None`: unchanged).
    #[inline]
    pub fn command(&mut self, c: &AxisCommand, motor: &MotorData, stage: Option<&StageData>) {
        if let Some(st) = stage {
            self.stage = Some(*st);
        }
        if self.motor.as_ref() != Some(motor) {
            self.motor = Some(*motor);
            self.motor_new = true;
        }
        self.on = c.power_stage;
        self.iq_ref_a = if c.power_stage { c.torque_nm / self.kt } else { 0.0 };
        self.injection = c.injection.filter(|_| c.power_stage);
    }

    /// The DC link at the last PWM period, mV (6079h).
    #[inline]
    pub fn dc_link_mv(&self) -> u32 {
        (self.vdc_v * 1000.0) as u32
    }

    /// The control cycle's inputs: the encoder position, its and the DC
    /// link's state, the mean measured iq since the last call (the last
    /// period's when none ran) and the torque kt·iq, a new trip (once).
    ///
    /// No PWM period since the last call (the ADC's interrupt stopped: a
    /// control cycle spans at least two, four at 16 kHz) reads as the supply missing: the
    /// DC link is no longer measured ([`guard`] then cuts the gate enable,
    /// and an enabled axis faults).
    #[inline]
    pub fn io(&mut self) -> AxisIo {
        let fresh = self.periods > 0;
        let iq = if fresh {
            self.iq_sum_a / self.periods as f32
        } else {
            self.iq_last_a
        };
        let encoder_ok = self.encoder_ok;
        let trip = if self.trip_reported { None } else { self.trip };
        self.trip_reported = self.trip.is_some();
        let n = self.periods as f32;
        let d_axis = fresh.then(|| DAxisMeans {
            voltage_v: self.ud_sum_v / n,
            current_a: self.id_sum_a / n,
            interval_s: n / PWM_HZ as f32,
        });
        self.ud_sum_v = 0.0;
        self.id_sum_a = 0.0;
        self.iq_sum_a = 0.0;
        self.periods = 0;
        self.encoder_ok = true;
        AxisIo {
            encoder_ok,
            supply_ok: self.supply_ok && fresh,
            current: Some(CurrentActual {
                trip,
                stage_limit_a: self.stage_limit_a,
                stage_warning: self.stage_warning,
                d_axis,
                ..CurrentActual::measured(self.kt * iq, iq)
            }),
            ..AxisIo::ready(self.position_inc)
        }
    }
}

/// The power stage's data when the dictionary's configuration generation
/// moved since `seen` (updated), else `None`: read once per change, not per
/// cycle.
pub fn stage_if_moved(objects: &drive_ecat::DriveObjects, seen: &mut u32) -> Option<StageData> {
    let generation = objects.config_generation();
    (generation != *seen).then(|| {
        *seen = generation;
        StageData::read(objects)
    })
}

/// The control cycle's hand-over to the fast task: each axis' command with
/// its motor data (and the stage's data when they moved); the DC link the
/// fast task last measured, mV (for 6079h).
pub fn hand_over(
    links: &mut [Link; 2],
    commands: &[AxisCommand; 2],
    axes: &[drive_ecat::axis::Axis; 2],
    stage: Option<&StageData>,
) -> u32 {
    for ((l, c), a) in links.iter_mut().zip(commands).zip(axes) {
        l.command(c, a.motor(), stage);
    }
    let [a, _] = links;
    a.dc_link_mv()
}

/// The control cycle's guard of the fast task: with either axis' supply
/// missing ([`Link::io`]: the DC link out of its window, or no PWM period
/// since the last cycle) the gate enable goes low. Where the fast task
/// runs it has switched such an axis off already (its loop trips on the
/// DC link); where it stopped, nothing else would.
#[inline]
pub fn guard(io: &[AxisIo; 2]) {
    if io.iter().any(|a| !a.supply_ok) {
        super::power::set(false);
    }
}

/// The fast task's state: the power stage and both current loops.
pub struct FastLoop {
    motor: Motor,
    foc: [FocAxis; 2],
    /// The command of the last period (a rising edge clears the trips).
    was_on: [bool; 2],
    /// Interrupts without a complete set of conversions (none stepped).
    missed: u32,
}

impl FastLoop {
    /// Both loops with [`board`]'s constants, disabled; `None` when `foc`
    /// refuses them (it does not: its tests check the defaults).
    pub fn new(motor: Motor) -> Option<FastLoop> {
        let foc = FocAxis::new(board::MOTOR, board::LOOP, board::SCALING, board::PROTECTION).ok()?;
        Some(FastLoop {
            motor,
            foc: [foc; 2],
            was_on: [false; 2],
            missed: 0,
        })
    }

    /// The loops' torque constant, N·m/A (for [`Link::new`]).
    pub fn kt(&self) -> f32 {
        let [a, _] = &self.foc;
        a.gains().kt_nm_per_a
    }

    /// Interrupts that found the conversions incomplete.
    pub fn missed(&self) -> u32 {
        self.missed
    }

    /// One PWM period of both axes (the body of the fast task).
    pub fn period(&mut self, links: &mut [Link; 2]) {
        let Some(s) = self.motor.samples() else {
            self.missed = self.missed.wrapping_add(1);
            return;
        };
        let mut any_on = false;
        let axes = self
            .foc
            .iter_mut()
            .zip(links.iter_mut())
            .zip(self.was_on.iter_mut());
        for (i, ((foc, link), was_on)) in axes.enumerate() {
            let on = link.on;
            if on && !*was_on {
                // commanded on again (after the fault was acknowledged)
                foc.reset_trip();
                self.motor.clear_trap(i);
                link.trip = None;
                link.trip_reported = false;
            }
            *was_on = on;
            if let Some(st) = link.stage.take() {
                // the DC-link window and the stage's currents; the trip
                // threshold and the rest of `board::PROTECTION` stay
                foc.set_protection(st.protection(*foc.protection()));
            }
            if link.motor_new {
                link.motor_new = false;
                if let Some(m) = &link.motor {
                    // gains by pole-zero cancellation, kt, the currents
                    if foc
                        .set_params(m.current_loop(), m.loop_params(board::LOOP))
                        .is_ok()
                    {
                        link.kt = m.torque_constant_nm_per_a;
                    }
                    foc.set_commutation_offset(m.commutation_offset_inc);
                }
            }
            let trapped = self.motor.trapped(i);
            let (counts, phase_error) = self.motor.encoder(i);
            let position_inc = counts.wrapping_mul(board::INC_PER_COUNT);
            let (iu, iv) = (
                s.iu.get(i).copied().unwrap_or(0),
                s.iv.get(i).copied().unwrap_or(0),
            );
            let sample = Sample {
                phase_counts: [iu, iv, 0],
                dc_link_count: s.udc,
                position_inc: position_inc as u32,
                encoder_ok: !phase_error,
            };
            foc.enable(on && !trapped && link.trip.is_none());
            let out = match &link.injection {
                Some(j) => j.step(foc, &sample),
                None => foc.step(
                    &sample,
                    Dq {
                        d: 0.0,
                        q: link.iq_ref_a,
                    },
                ),
            };
            if on {
                if link.trip.is_none() {
                    link.trip = if trapped {
                        Some(CurrentTrip::OverCurrent)
                    } else {
                        foc.trip()
                    };
                }
            } else {
                // gates off: a DC link out of its window is "supply
                // missing", not a fault; nothing else can trip
                foc.reset_trip();
            }
            let run = on && link.trip.is_none() && out.gate_enable;
            // the pins first (switching on writes 50 % to the shadow
            // registers), then this step's duties over them for the next period
            self.motor.set_on(i, run);
            if run {
                self.motor.set_duties(i, out.compare.map(duty));
            }
            any_on |= run;
            let m = foc.measured();
            link.ud_sum_v += link.prev_ud_v;
            link.id_sum_a += m.current.d;
            link.prev_ud_v = m.voltage.d;
            link.iq_last_a = m.current.q;
            link.iq_sum_a += m.current.q;
            link.periods = link.periods.saturating_add(1);
            link.position_inc = position_inc;
            link.encoder_ok &= !phase_error;
            let dc = foc.protection().dc_link;
            link.supply_ok = m.vdc >= dc.min_v && m.vdc <= dc.max_v;
            link.vdc_v = m.vdc;
            link.stage_limit_a = m.stage_i2t.map_or(f32::INFINITY, |_| m.stage_limit_a);
            link.stage_warning = matches!(m.stage_i2t, Some(st) if st != foc::I2tState::Normal);
        }
        super::power::set(any_on);
    }
}

/// The CCU8's Q16 duty of a loop compare value (0 ..= [`board::LOOP_PERIOD_COUNTS`]).
#[inline]
fn duty(compare: u16) -> Duty {
    (u32::from(compare) << 1).min(u32::from(Duty::MAX)) as Duty
}
