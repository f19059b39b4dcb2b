//! The plant's parameters.

use core::f64::consts::TAU;

/// The motor's electrical data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PmsmParams {
    /// Phase resistance R, Ω.
    pub r_ohm: f64,
    /// d-axis inductance, H.
    pub ld_h: f64,
    /// q-axis inductance, H.
    pub lq_h: f64,
    /// Magnet flux linkage ψ, V·s.
    pub psi_vs: f64,
    /// Pole pairs.
    pub pole_pairs: u32,
    /// Mechanical angle (rad) at which the rotor's d axis points along phase a:
    /// the commutation offset a real encoder has; 0 = at encoder count 0.
    pub commutation_offset_rad: f64,
}

impl PmsmParams {
    /// The electrical data of `foc::MotorData` (f32 → f64).
    pub fn from_motor_data(m: &foc::MotorData) -> Self {
        Self {
            r_ohm: f64::from(m.r_ohm),
            ld_h: f64::from(m.ld_h),
            lq_h: f64::from(m.lq_h),
            psi_vs: f64::from(m.psi_vs),
            pole_pairs: m.pole_pairs,
            commutation_offset_rad: 0.0,
        }
    }

    /// Torque constant 1.5·p·ψ, N·m/A.
    pub fn torque_constant(&self) -> f64 {
        1.5 * f64::from(self.pole_pairs) * self.psi_vs
    }
}

/// The averaged two-level inverter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InverterParams {
    /// DC-link voltage at start, V (with [`PlantParams::dc_link`] `None` the
    /// stiff source's, always).
    pub vdc_v: f64,
    /// Dead time, s.
    pub dead_time_s: f64,
    /// Current below which a leg's dead-time voltage error is proportional to its
    /// current (the switching node's capacitance is recharged partly), A.
    pub dead_time_band_a: f64,
    /// PWM frequency, Hz.
    pub pwm_hz: f64,
    /// Compare value of a full period.
    pub pwm_period_counts: u16,
}

impl InverterParams {
    /// 565 V DC link (400 V mains), 1 µs dead time, 16 kHz, 4500 counts per period
    /// (as `foc::Scaling::default_board`).
    pub const fn default_16k() -> Self {
        Self {
            vdc_v: 565.0,
            dead_time_s: 1.0e-6,
            dead_time_band_a: 0.05,
            pwm_hz: 16_000.0,
            pwm_period_counts: 4500,
        }
    }
}

/// The DC link as a state: a capacitor fed by a diode rectifier from the mains
/// (current only into the link, through the source's resistance), discharged
/// by the inverter's power and by the brake resistor while the chopper
/// conducts:
///
/// ```text
/// C·dV/dt = max(0, (V_mains − V) / R_source) − p_inv / V − (chopper ? V / R_brake : 0)
/// p_inv = Σ_k v_k·i_k   (the legs' averaged terminal voltages times the phase currents)
/// ```
///
/// The rectifier is averaged (a stiff source at the mains' peak behind its
/// resistance; no 300 Hz ripple).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DcLinkParams {
    /// Capacitance, F.
    pub capacitance_f: f64,
    /// The rectified mains' peak, V (the link's voltage at rest).
    pub mains_peak_v: f64,
    /// The mains' and rectifier's resistance, Ω.
    pub source_ohm: f64,
    /// The brake resistor on the chopper, Ω (0 = none fitted: the chopper's
    /// gate changes nothing).
    pub brake_resistor_ohm: f64,
}

impl DcLinkParams {
    /// 470 µF (assumed: the SC6's capacitance is not in the sources), 565 V
    /// (400 V mains: √2·400 V), 1 Ω source, the 100 Ω brake resistor of the
    /// manual's example (A21).
    pub const fn default_400v() -> Self {
        Self {
            capacitance_f: 470.0e-6,
            mains_peak_v: 565.0,
            source_ohm: 1.0,
            brake_resistor_ohm: 100.0,
        }
    }

    /// Energy in the capacitor at `v`, J: ½·C·V².
    pub fn energy_j(&self, v: f64) -> f64 {
        0.5 * self.capacitance_f * v * v
    }
}

/// The ADCs: phase currents and DC link, and their noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdcParams {
    /// Resolution, bits.
    pub bits: u32,
    /// Amperes per count of the phase-current ADC.
    pub amps_per_count: f64,
    /// Count of zero current.
    pub zero_count: f64,
    /// Noise of a current sample, standard deviation in counts (0 = none).
    pub current_noise_counts: f64,
    /// Volts per count of the DC-link ADC.
    pub volts_per_count: f64,
    /// Noise of a DC-link sample, counts.
    pub dc_noise_counts: f64,
}

impl AdcParams {
    /// 12 bits over ±10 A, 0.25 V per DC-link count (as `foc::Scaling::default_board`),
    /// 1.5 counts (7 mA) current noise, 1 count DC-link noise.
    pub const fn default_board() -> Self {
        Self {
            bits: 12,
            amps_per_count: 20.0 / 4096.0,
            zero_count: 2048.0,
            current_noise_counts: 1.5,
            volts_per_count: 0.25,
            dc_noise_counts: 1.0,
        }
    }
}

/// What holds the motor shaft.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shaft {
    /// The mechanics below move it.
    Free,
    /// Locked at its present angle (a locked-rotor test).
    Locked,
    /// A dynamometer holds this speed, rad/s (mechanical).
    Driven {
        /// Shaft speed, rad/s.
        speed_rad_s: f64,
    },
}

/// A load behind a shaft spring (resonance).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoMass {
    /// Load inertia, kg·m².
    pub load_inertia_kg_m2: f64,
    /// Shaft stiffness, N·m/rad.
    pub stiffness_nm_per_rad: f64,
    /// Shaft damping, N·m·s/rad.
    pub damping_nm_s_per_rad: f64,
}

impl TwoMass {
    /// The resonance of the two masses: ω = √(k·(Jm + Jl)/(Jm·Jl)), rad/s.
    pub fn resonance_rad_s(&self, motor_inertia_kg_m2: f64) -> f64 {
        let (jm, jl) = (motor_inertia_kg_m2, self.load_inertia_kg_m2);
        libm::sqrt(self.stiffness_nm_per_rad * (jm + jl) / (jm * jl))
    }
}

/// Mechanics: the rotor (with the load reflected, or the motor's own inertia with
/// a [`TwoMass`] load).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MechParams {
    /// Inertia on the motor shaft, kg·m².
    pub inertia_kg_m2: f64,
    /// Viscous friction, N·m·s/rad.
    pub viscous_nm_s_per_rad: f64,
    /// Coulomb friction (sliding = breakaway), N·m.
    pub coulomb_nm: f64,
    /// Gravity torque, N·m (constant, on the load; negative pulls towards
    /// negative angles).
    pub gravity_nm: f64,
    /// Rigid end stops (lowest, highest) of the load's angle, rad.
    pub end_stops_rad: Option<(f64, f64)>,
    /// Holding torque of the brake (also its sliding torque), N·m.
    pub brake_nm: f64,
    /// An elastic load, or none (rigid).
    pub two_mass: Option<TwoMass>,
    /// What holds the shaft.
    pub shaft: Shaft,
    /// Mechanical angle at start, rad.
    pub initial_angle_rad: f64,
}

impl MechParams {
    /// hil-sim's servo (`MotorParams::default_servo`): 1e-4 kg·m², viscous 2e-5
    /// N·m·s/rad, Coulomb 0.02 N·m, brake 2 N·m (released), horizontal, no stops.
    pub const fn default_servo() -> Self {
        Self {
            inertia_kg_m2: 1.0e-4,
            viscous_nm_s_per_rad: 2.0e-5,
            coulomb_nm: 0.02,
            gravity_nm: 0.0,
            end_stops_rad: None,
            brake_nm: 2.0,
            two_mass: None,
            shaft: Shaft::Free,
            initial_angle_rad: 0.0,
        }
    }
}

/// One of the three phases.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Phase a (U).
    A,
    /// Phase b (V).
    B,
    /// Phase c (W).
    C,
}

/// Faults a test can provoke, at start or mid-run ([`crate::Plant::set_faults`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaultOptions {
    /// This phase's wire is open: its current is zero.
    pub open_phase: Option<Phase>,
    /// Motor phases b and c are wired to the inverter's legs c and b.
    pub swapped_bc: bool,
    /// Each phase's resistance as a multiple of R (an unbalanced winding).
    pub r_scale: [f64; 3],
    /// The encoder reports an error and its position stops.
    pub encoder_lost: bool,
    /// The encoder counts the other way (mounted or wired reversed): its
    /// position is the negated rotor angle. hil-sim's electrical axis gives
    /// the drive's cycle (`AxisIo::position_inc`) the same reversed count.
    pub encoder_reversed: bool,
    /// An insulation fault: this inverter leg's output (between its current
    /// sensor and the motor) is connected to the DC link's negative rail
    /// through this resistance, Ω. With the gates on the leg's sensor carries
    /// the motor's phase current plus the fault's d·Vdc/R (the inverter is a
    /// stiff voltage source: the motor's currents are unchanged); the three
    /// measured currents no longer sum to zero. A low resistance (1 Ω: some
    /// 280 A at half duty) is a short: the over-current trip; a high one
    /// (100 Ω: some 2.8 A) an earth fault: the phase-sum plausibility.
    pub leg_to_dc_minus: Option<(Phase, f64)>,
    /// This leg's current sensor (shunt or amplifier) is broken: it reads
    /// zero current (its zero count and noise) whatever flows.
    pub broken_sensor: Option<Phase>,
}

impl FaultOptions {
    /// No fault.
    pub const NONE: Self = Self {
        open_phase: None,
        swapped_bc: false,
        r_scale: [1.0; 3],
        encoder_lost: false,
        encoder_reversed: false,
        leg_to_dc_minus: None,
        broken_sensor: None,
    };
}

/// Everything of one plant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlantParams {
    /// The motor.
    pub motor: PmsmParams,
    /// The inverter.
    pub inverter: InverterParams,
    /// The ADCs.
    pub adc: AdcParams,
    /// The mechanics.
    pub mech: MechParams,
    /// Faults.
    pub faults: FaultOptions,
    /// The DC link as a state ([`DcLinkParams`]), or `None`: a stiff source at
    /// [`InverterParams::vdc_v`] (nothing raises or lowers it but
    /// [`crate::Plant::set_dc_link`]).
    pub dc_link: Option<DcLinkParams>,
    /// RK4 sub-steps per half PWM period (the sample is taken between the halves).
    pub substeps_per_half: u32,
    /// Seed of the ADC noise.
    pub seed: u64,
}

impl PlantParams {
    /// The default servo ([`foc::MotorData::default_servo`] and hil-sim's mechanics)
    /// behind the default inverter and ADCs, the DC link a state
    /// ([`DcLinkParams::default_400v`]), 4 sub-steps per half period.
    pub fn default_servo() -> Self {
        Self {
            motor: PmsmParams::from_motor_data(&foc::MotorData::default_servo()),
            inverter: InverterParams::default_16k(),
            adc: AdcParams::default_board(),
            mech: MechParams::default_servo(),
            faults: FaultOptions::NONE,
            dc_link: Some(DcLinkParams::default_400v()),
            substeps_per_half: 4,
            seed: 0x5eed_f0c0_0000_0001,
        }
    }

    /// PWM period, s.
    pub fn period_s(&self) -> f64 {
        1.0 / self.inverter.pwm_hz
    }

    /// Electrical time constant of the d axis Ld/R, s.
    pub fn tau_d_s(&self) -> f64 {
        self.motor.ld_h / self.motor.r_ohm
    }

    /// The `foc::Scaling` that reads this plant's integers.
    pub fn scaling(&self) -> foc::Scaling {
        let zero = self.adc.zero_count as f32;
        foc::Scaling {
            amps_per_count: self.adc.amps_per_count as f32,
            zero_counts: [zero; 3],
            volts_per_count: self.adc.volts_per_count as f32,
            pwm_period_counts: self.inverter.pwm_period_counts,
            shunts: foc::Shunts::Three,
            commutation_offset_inc: (libm::round(
                self.motor.commutation_offset_rad / TAU * crate::INC_PER_REV as f64,
            ) as i64) as u32,
        }
    }
}
