//! The electrical plant of the simulator: a permanent-magnet synchronous motor in
//! dq coordinates behind an averaged two-level inverter, sampled like a power
//! board's ADC and encoder, over a rotor's mechanics.
//!
//! # Model
//!
//! ```text
//! Ld·did/dt = vd − R·id + ω·Lq·iq          Te = 1.5·p·(ψ·iq + (Ld − Lq)·id·iq)
//! Lq·diq/dt = vq − R·iq − ω·Ld·id − ω·ψ    J·dωm/dt = Te − b·ωm − Tc·sign(ωm) − Tbrake·sign(ωm) + Tg (− Tshaft)
//! ```
//!
//! - DC link ([`DcLinkParams`], optional): a capacitor fed by a diode rectifier
//!   (current only into the link, through the source's resistance), discharged
//!   by the inverter's averaged power Σ v_x·i_x and by the brake resistor while
//!   the chopper conducts ([`Plant::set_chopper`]): regenerative braking raises
//!   the voltage. `None`: a stiff source.
//! - Inverter (averaged over a PWM period): leg x puts `d_x·Vdc` on its terminal,
//!   less `Vdc·t_dead/Ts·sign(i_x)` (linear within ±`dead_time_band_a`); the star
//!   point floats, so only the phase voltages' differential part (Clarke) acts.
//!   Gates off: the phase currents are zero (valid while the back-EMF's line
//!   voltage stays below the DC link, so the diode bridge blocks).
//! - Timing: [`Plant::apply`] sets the compare values of the next period;
//!   [`Plant::advance`] integrates one period with them and takes the sample at
//!   its centre, as a board's ADC triggered by the PWM timer. Integration: RK4 in
//!   `substeps_per_half` sub-steps per half period, in f64.
//! - Sampling: phase (leg) currents quantised to the ADC's counts with seeded,
//!   approximately normal noise ([`rng`]); the DC link likewise; the encoder as
//!   2^20 increments per revolution (floor).
//! - Mechanics: inertia, viscous and Coulomb friction with stick (a rotor that
//!   reaches zero speed stays until the drive torque exceeds friction plus brake),
//!   constant gravity torque, rigid end stops, a brake, an optional two-mass load
//!   ([`TwoMass`]: motor inertia, shaft spring and damper, load inertia; gravity
//!   and the end stops act on the load); a shaft can be locked or driven at a speed.
//! - Faults ([`FaultOptions`]): an open phase (its current held at zero: the
//!   current vector's derivative loses its component along that phase's axis;
//!   exact for Ld = Lq), phases b and c swapped at the inverter, an unbalanced
//!   winding (per-phase resistance), an encoder loss, a leg shorted to the DC
//!   link's negative rail behind its current sensor (a short or an earth fault:
//!   the sensor reads the fault's current too), a broken current sensor.
//!
//! The default motor is `foc::MotorData::default_servo` (hil-sim's servo with
//! electrical data, the numbers' source written there) over hil-sim's mechanics.
#![no_std]
#![deny(missing_docs)]

pub mod closed_loop;
pub mod params;
pub mod rng;

pub use params::{
    AdcParams, DcLinkParams, FaultOptions, InverterParams, MechParams, Phase, PlantParams, PmsmParams, Shaft,
    TwoMass,
};

use core::f64::consts::TAU;
use foc::{PowerStage, PwmOut, Sample};
use rng::XorShift64Star;

/// Encoder increments per revolution.
pub const INC_PER_REV: i64 = 1 << 20;

const SQRT_3_2: f64 = 0.866_025_403_784_438_6;
const FRAC_1_SQRT_3: f64 = 0.577_350_269_189_625_8;

/// The integrated state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct State {
    id: f64,
    iq: f64,
    theta_m: f64,
    omega_m: f64,
    theta_l: f64,
    omega_l: f64,
    /// DC-link voltage, V.
    vdc: f64,
    /// Energy the rectifier fed into the link, J.
    e_mains: f64,
    /// Energy the brake resistor dissipated, J.
    e_brake: f64,
}

impl State {
    fn add(&self, k: &State, h: f64) -> State {
        State {
            id: self.id + k.id * h,
            iq: self.iq + k.iq * h,
            theta_m: self.theta_m + k.theta_m * h,
            omega_m: self.omega_m + k.omega_m * h,
            theta_l: self.theta_l + k.theta_l * h,
            omega_l: self.omega_l + k.omega_l * h,
            vdc: self.vdc + k.vdc * h,
            e_mains: self.e_mains + k.e_mains * h,
            e_brake: self.e_brake + k.e_brake * h,
        }
    }
}

/// The motor, inverter, sensors and load of one axis.
#[derive(Debug, Clone)]
pub struct Plant {
    p: PlantParams,
    x: State,
    pwm: PwmOut,
    sample: Sample,
    rng: XorShift64Star,
    periods: u64,
    brake_engaged: bool,
    held_position: u32,
    chopper_on: bool,
}

impl Plant {
    /// A plant at rest, currents zero, gates off, brake released.
    pub fn new(p: PlantParams) -> Self {
        let mut x = State {
            theta_m: p.mech.initial_angle_rad,
            theta_l: p.mech.initial_angle_rad,
            vdc: p.inverter.vdc_v,
            ..State::default()
        };
        if let Shaft::Driven { speed_rad_s } = p.mech.shaft {
            x.omega_m = speed_rad_s;
            x.omega_l = speed_rad_s;
        }
        let mut plant = Self {
            p,
            x,
            pwm: PwmOut {
                compare: [p.inverter.pwm_period_counts / 2; 3],
                gate_enable: false,
            },
            sample: Sample::default(),
            rng: XorShift64Star::new(p.seed),
            periods: 0,
            brake_engaged: false,
            held_position: 0,
            chopper_on: false,
        };
        plant.held_position = plant.encoder_count();
        plant.sample = plant.take_sample();
        plant
    }

    /// The parameters.
    pub fn params(&self) -> &PlantParams {
        &self.p
    }

    /// Sets the motor's electrical data from now on (a test's motor that the
    /// drive does not know: R, L, ψ, pole pairs, commutation offset); the
    /// currents keep their values.
    pub fn set_motor(&mut self, m: PmsmParams) {
        self.p.motor = m;
    }

    /// Sets faults from now on (an open phase takes effect with the currents'
    /// next derivative; the phase's current is forced to zero at once).
    pub fn set_faults(&mut self, f: FaultOptions) {
        self.p.faults = f;
        if let Some(ph) = f.open_phase {
            let (s, c) = self.sin_cos_e(self.x.theta_m);
            let (a, b) = (c * self.x.id - s * self.x.iq, s * self.x.id + c * self.x.iq);
            let (na, nb) = phase_axis(ph);
            let k = a * na + b * nb;
            let (a, b) = (a - k * na, b - k * nb);
            self.x.id = c * a + s * b;
            self.x.iq = -s * a + c * b;
        }
    }

    /// Changes the DC-link voltage at once (a mains drop or surge), V: the
    /// capacitor's voltage and, with the DC link a state, the mains' peak
    /// from now on (so the link stays there at rest).
    pub fn set_dc_link(&mut self, vdc_v: f64) {
        self.p.inverter.vdc_v = vdc_v;
        self.x.vdc = vdc_v;
        if let Some(dc) = self.p.dc_link.as_mut() {
            dc.mains_peak_v = vdc_v;
        }
    }

    /// The brake chopper's gate from the next period on (true = the brake
    /// resistor across the link): the chopper block's output
    /// (`foc::BrakeChopper`). Without a resistor in [`PlantParams::dc_link`]
    /// it changes nothing.
    pub fn set_chopper(&mut self, on: bool) {
        self.chopper_on = on;
    }

    /// The chopper's gate in force.
    pub fn chopper_on(&self) -> bool {
        self.chopper_on
    }

    /// Sets the brake resistor fitted on the chopper, Ω (0 = none).
    pub fn set_brake_resistor(&mut self, ohm: f64) {
        if let Some(dc) = self.p.dc_link.as_mut() {
            dc.brake_resistor_ohm = ohm;
        }
    }

    /// The DC link's voltage, V (without ADC noise).
    pub fn dc_link_v(&self) -> f64 {
        self.x.vdc
    }

    /// Energy the rectifier fed into the link since start, J.
    pub fn mains_energy_j(&self) -> f64 {
        self.x.e_mains
    }

    /// Energy the brake resistor dissipated since start, J.
    pub fn brake_energy_j(&self) -> f64 {
        self.x.e_brake
    }

    /// Engages (true) or releases the brake.
    pub fn set_brake(&mut self, engaged: bool) {
        self.brake_engaged = engaged;
    }

    /// Changes what holds the shaft (e.g. locks it after spinning up).
    pub fn set_shaft(&mut self, shaft: Shaft) {
        self.p.mech.shaft = shaft;
        match shaft {
            Shaft::Locked => {
                self.x.omega_m = 0.0;
                self.x.omega_l = 0.0;
            }
            Shaft::Driven { speed_rad_s } => {
                self.x.omega_m = speed_rad_s;
                self.x.omega_l = speed_rad_s;
            }
            Shaft::Free => {}
        }
    }

    /// Puts the motor shaft at `angle_rad` turning at `speed_rad_s` (mechanical),
    /// currents kept: for a co-simulation whose mechanics live elsewhere (hil-sim's
    /// motor with [`Shaft::Driven`]: this plant then contributes the currents and
    /// the torque, the other model the motion).
    pub fn set_rotor(&mut self, angle_rad: f64, speed_rad_s: f64) {
        self.x.theta_m = angle_rad;
        self.x.omega_m = speed_rad_s;
        if self.p.mech.two_mass.is_none() {
            self.x.theta_l = angle_rad;
            self.x.omega_l = speed_rad_s;
        }
        if let Shaft::Driven { .. } = self.p.mech.shaft {
            self.p.mech.shaft = Shaft::Driven { speed_rad_s };
        }
    }

    /// Time since start, s.
    pub fn time_s(&self) -> f64 {
        self.periods as f64 * self.p.period_s()
    }

    /// d-axis current, A.
    pub fn id(&self) -> f64 {
        self.x.id
    }

    /// q-axis current, A.
    pub fn iq(&self) -> f64 {
        self.x.iq
    }

    /// Electromagnetic torque 1.5·p·(ψ·iq + (Ld − Lq)·id·iq), N·m.
    pub fn torque_nm(&self) -> f64 {
        let m = &self.p.motor;
        1.5 * f64::from(m.pole_pairs) * (m.psi_vs * self.x.iq + (m.ld_h - m.lq_h) * self.x.id * self.x.iq)
    }

    /// Motor shaft angle, rad (unwrapped).
    pub fn angle_rad(&self) -> f64 {
        self.x.theta_m
    }

    /// Motor shaft speed, rad/s.
    pub fn speed_rad_s(&self) -> f64 {
        self.x.omega_m
    }

    /// Load angle, rad (the motor's without a two-mass load).
    pub fn load_angle_rad(&self) -> f64 {
        if self.p.mech.two_mass.is_some() {
            self.x.theta_l
        } else {
            self.x.theta_m
        }
    }

    /// Load speed, rad/s.
    pub fn load_speed_rad_s(&self) -> f64 {
        if self.p.mech.two_mass.is_some() {
            self.x.omega_l
        } else {
            self.x.omega_m
        }
    }

    /// The motor's phase currents (a, b, c), A, without noise.
    pub fn phase_currents(&self) -> [f64; 3] {
        let (s, c) = self.sin_cos_e(self.x.theta_m);
        let (al, be) = (c * self.x.id - s * self.x.iq, s * self.x.id + c * self.x.iq);
        [al, -0.5 * al + SQRT_3_2 * be, -0.5 * al - SQRT_3_2 * be]
    }

    fn sin_cos_e(&self, theta_m: f64) -> (f64, f64) {
        let m = &self.p.motor;
        let th = f64::from(m.pole_pairs) * (theta_m - m.commutation_offset_rad);
        (libm::sin(th), libm::cos(th))
    }

    fn encoder_count(&self) -> u32 {
        (libm::floor(self.x.theta_m / TAU * INC_PER_REV as f64) as i64) as u32
    }

    /// One PWM period with the compare values last applied; the sample at its
    /// centre is what [`PowerStage::sample`] returns next.
    pub fn advance(&mut self) {
        let n = self.p.substeps_per_half.max(1);
        let h = self.p.period_s() / (2.0 * f64::from(n));
        let period = f64::from(self.p.inverter.pwm_period_counts.max(1));
        let duty = self.pwm.compare.map(|c| (f64::from(c) / period).clamp(0.0, 1.0));
        let gate = self.pwm.gate_enable;
        for half in 0..2 {
            for _ in 0..n {
                self.substep(h, duty, gate);
            }
            if half == 0 {
                self.sample = self.take_sample();
            }
        }
        self.periods += 1;
    }

    fn substep(&mut self, h: f64, duty: [f64; 3], gate: bool) {
        let x0 = self.x;
        let k1 = self.deriv(&x0, duty, gate);
        let k2 = self.deriv(&x0.add(&k1, 0.5 * h), duty, gate);
        let k3 = self.deriv(&x0.add(&k2, 0.5 * h), duty, gate);
        let k4 = self.deriv(&x0.add(&k3, h), duty, gate);
        // x0 + h/6·(k1 + 2·k2 + 2·k3 + k4)
        let mut x = x0
            .add(&k1, h / 6.0)
            .add(&k2, h / 3.0)
            .add(&k3, h / 3.0)
            .add(&k4, h / 6.0);
        if self.p.mech.shaft == Shaft::Free {
            // stick: a rotor whose speed crosses zero stops there; the next
            // derivative decides whether the drive torque breaks it loose
            if x0.omega_m != 0.0 && x0.omega_m * x.omega_m <= 0.0 {
                x.omega_m = 0.0;
            }
            let (lo, hi) = self
                .p
                .mech
                .end_stops_rad
                .unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
            let two = self.p.mech.two_mass.is_some();
            let (th, om) = if two {
                (&mut x.theta_l, &mut x.omega_l)
            } else {
                (&mut x.theta_m, &mut x.omega_m)
            };
            if *th < lo {
                *th = lo;
                *om = om.max(0.0);
            } else if *th > hi {
                *th = hi;
                *om = om.min(0.0);
            }
        }
        self.x = x;
    }

    fn deriv(&self, x: &State, duty: [f64; 3], gate: bool) -> State {
        let m = &self.p.motor;
        let inv = &self.p.inverter;
        let f = &self.p.faults;
        let pp = f64::from(m.pole_pairs);
        let we = pp * x.omega_m;
        let (did, diq, p_inv) = if gate {
            let (s, c) = self.sin_cos_e(x.theta_m);
            let (ia, ib) = (c * x.id - s * x.iq, s * x.id + c * x.iq);
            let i_abc = [ia, -0.5 * ia + SQRT_3_2 * ib, -0.5 * ia - SQRT_3_2 * ib];
            // motor phase b sits on leg c and vice versa when swapped
            let leg_of = if f.swapped_bc {
                [0usize, 2, 1]
            } else {
                [0usize, 1, 2]
            };
            let dt = inv.dead_time_s * inv.pwm_hz;
            let mut v = [0.0f64; 3];
            for (k, vk) in v.iter_mut().enumerate() {
                let leg = leg_of.get(k).copied().unwrap_or(k);
                let d = duty.get(leg).copied().unwrap_or(0.5);
                let i = i_abc.get(k).copied().unwrap_or(0.0);
                *vk = x.vdc * (d - dt * (i / inv.dead_time_band_a).clamp(-1.0, 1.0));
            }
            // the power the inverter draws from the link (the star point
            // floats: Σi = 0, so the common mode of v carries none)
            let p_inv: f64 = v.iter().zip(i_abc).map(|(v, i)| v * i).sum();
            let drop: [f64; 3] = core::array::from_fn(|k| {
                m.r_ohm * f.r_scale.get(k).copied().unwrap_or(1.0) * i_abc.get(k).copied().unwrap_or(0.0)
            });
            let u = [v[0] - drop[0], v[1] - drop[1], v[2] - drop[2]];
            let ua = (2.0 * u[0] - u[1] - u[2]) / 3.0;
            let ub = (u[1] - u[2]) * FRAC_1_SQRT_3;
            let ud = c * ua + s * ub;
            let uq = -s * ua + c * ub;
            let mut did = (ud + we * m.lq_h * x.iq) / m.ld_h;
            let mut diq = (uq - we * m.ld_h * x.id - we * m.psi_vs) / m.lq_h;
            if let Some(ph) = f.open_phase {
                // d(i_αβ)/dt = R(θ)·(di_dq/dt + ω·J·i_dq), projected, and back
                let (w, wq) = (did - we * x.iq, diq + we * x.id);
                let (da, db) = (c * w - s * wq, s * w + c * wq);
                let (na, nb) = phase_axis(ph);
                let k = da * na + db * nb;
                let (da, db) = (da - k * na, db - k * nb);
                did = c * da + s * db + we * x.iq;
                diq = -s * da + c * db - we * x.id;
            }
            (did, diq, p_inv)
        } else {
            (
                -x.id / 1.0e-6_f64.max(self.p.period_s() / 8.0),
                -x.iq / 1.0e-6_f64.max(self.p.period_s() / 8.0),
                0.0,
            )
        };
        let te = 1.5 * pp * (m.psi_vs * x.iq + (m.ld_h - m.lq_h) * x.id * x.iq);
        let mech = &self.p.mech;
        let mut dx = State {
            id: did,
            iq: diq,
            ..State::default()
        };
        if let Some(dc) = &self.p.dc_link {
            let v = x.vdc.max(1.0);
            let i_rect = ((dc.mains_peak_v - x.vdc) / dc.source_ohm.max(1e-6)).max(0.0);
            let i_brake = if self.chopper_on && dc.brake_resistor_ohm > 0.0 {
                x.vdc.max(0.0) / dc.brake_resistor_ohm
            } else {
                0.0
            };
            dx.vdc = (i_rect - p_inv / v - i_brake) / dc.capacitance_f.max(1e-9);
            dx.e_mains = i_rect * x.vdc;
            dx.e_brake = i_brake * x.vdc;
        }
        match mech.shaft {
            Shaft::Locked => {}
            Shaft::Driven { .. } => {
                dx.theta_m = x.omega_m;
                dx.theta_l = x.omega_l;
            }
            Shaft::Free => {
                let shaft = mech.two_mass.map(|t| {
                    t.stiffness_nm_per_rad * (x.theta_m - x.theta_l)
                        + t.damping_nm_s_per_rad * (x.omega_m - x.omega_l)
                });
                let drive = te - shaft.unwrap_or(0.0) + if shaft.is_none() { mech.gravity_nm } else { 0.0 };
                let hold = mech.coulomb_nm + if self.brake_engaged { mech.brake_nm } else { 0.0 };
                let friction = if x.omega_m == 0.0 {
                    -drive.clamp(-hold, hold)
                } else {
                    -hold * x.omega_m.signum()
                } - mech.viscous_nm_s_per_rad * x.omega_m;
                dx.theta_m = x.omega_m;
                dx.omega_m = (drive + friction) / mech.inertia_kg_m2.max(1.0e-9);
                if let (Some(t), Some(ts)) = (mech.two_mass, shaft) {
                    dx.theta_l = x.omega_l;
                    dx.omega_l = (ts + mech.gravity_nm) / t.load_inertia_kg_m2.max(1.0e-9);
                }
            }
        }
        dx
    }

    fn take_sample(&mut self) -> Sample {
        let adc = self.p.adc;
        let full = f64::from((1u32 << adc.bits.min(16)) - 1);
        let i = self.phase_currents();
        let legs = if self.p.faults.swapped_bc {
            [i[0], i[2], i[1]]
        } else {
            i
        };
        let mut legs = legs;
        let f = self.p.faults;
        if let (Some((ph, r)), true) = (f.leg_to_dc_minus, self.pwm.gate_enable) {
            let k = phase_index(ph);
            let period = f64::from(self.p.inverter.pwm_period_counts.max(1));
            let d = self
                .pwm
                .compare
                .get(k)
                .map_or(0.0, |&c| (f64::from(c) / period).clamp(0.0, 1.0));
            if let Some(l) = legs.get_mut(k) {
                *l += d * self.x.vdc / r.max(1e-3);
            }
        }
        if let Some(l) = f.broken_sensor.and_then(|ph| legs.get_mut(phase_index(ph))) {
            *l = 0.0;
        }
        let mut counts = [0u16; 3];
        for (c, il) in counts.iter_mut().zip(legs) {
            let x = adc.zero_count + il / adc.amps_per_count + adc.current_noise_counts * self.rng.normal();
            *c = libm::round(x).clamp(0.0, full) as u16;
        }
        let vdc = self.x.vdc / adc.volts_per_count + adc.dc_noise_counts * self.rng.normal();
        let encoder_ok = !self.p.faults.encoder_lost;
        if encoder_ok {
            let count = self.encoder_count();
            self.held_position = if self.p.faults.encoder_reversed {
                count.wrapping_neg()
            } else {
                count
            };
        }
        Sample {
            phase_counts: counts,
            dc_link_count: libm::round(vdc).clamp(0.0, full) as u16,
            position_inc: self.held_position,
            encoder_ok,
        }
    }
}

/// The index of a phase (leg) in the a, b, c arrays.
fn phase_index(ph: Phase) -> usize {
    match ph {
        Phase::A => 0,
        Phase::B => 1,
        Phase::C => 2,
    }
}

/// Unit vector of a phase's axis in the αβ plane.
fn phase_axis(ph: Phase) -> (f64, f64) {
    match ph {
        Phase::A => (1.0, 0.0),
        Phase::B => (-0.5, SQRT_3_2),
        Phase::C => (-0.5, -SQRT_3_2),
    }
}

impl PowerStage for Plant {
    fn sample(&mut self) -> Sample {
        self.sample
    }

    fn apply(&mut self, out: &PwmOut) {
        self.pwm = *out;
    }
}
