//! The seam below the axis: what a power board (or the simulated plant) gives and
//! takes per axis, sampled and updated once per PWM period.
//!
//! Integers at the seam, scaled once ([`Scaling`]): the board's ADC counts and
//! compare values never leave it as anything else, the loop computes in f32.

/// What one axis' power stage delivers, sampled at the centre of a PWM period
/// (where the low-side shunts carry the phase currents and the ripple crosses its
/// mean).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Sample {
    /// Phase currents a, b, c as ADC counts. With two shunts ([`Shunts::Two`]) the
    /// third entry is not read.
    pub phase_counts: [u16; 3],
    /// DC-link voltage, ADC counts.
    pub dc_link_count: u16,
    /// Encoder position, increments (2^20 per revolution, wrapping).
    pub position_inc: u32,
    /// The encoder's own status: false once it reports an error or stops answering.
    pub encoder_ok: bool,
}

/// What one axis' power stage takes: three compare values and the gate enable.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PwmOut {
    /// Compare values of the half bridges a, b, c, 0 ..= [`Scaling::pwm_period_counts`]
    /// (0: the low side conducts the whole period, the period: the high side).
    pub compare: [u16; 3],
    /// Gate drivers on. Off: all six switches open (and the trap input can force
    /// this in hardware).
    pub gate_enable: bool,
}

/// One axis of a power board, or of the simulated plant. The board samples at the
/// PWM centre on its own (ADC trigger from the PWM timer); [`PowerStage::sample`]
/// hands out the latest sample, [`PowerStage::apply`] loads the compare values for
/// the next period (shadow registers, taken over at the period boundary).
pub trait PowerStage {
    /// The sample taken at the centre of the current period.
    fn sample(&mut self) -> Sample;
    /// Compare values and gate enable for the next period.
    fn apply(&mut self, out: &PwmOut);
}

/// How many phase currents the board measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shunts {
    /// Phases a and b; c = −a − b (no plausibility check possible).
    Two,
    /// All three; their sum is checked ([`crate::protect::PhaseSum`]).
    Three,
}

/// The board's scaling of its integers, applied once per sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scaling {
    /// Amperes per ADC count (sign included: positive current flows into the motor).
    pub amps_per_count: f32,
    /// ADC count of zero current per phase (offset, calibrated with the gates off).
    pub zero_counts: [f32; 3],
    /// Volts per DC-link ADC count.
    pub volts_per_count: f32,
    /// Compare value of a full period.
    pub pwm_period_counts: u16,
    /// Two or three shunts.
    pub shunts: Shunts,
    /// Encoder increments of the d axis (the commutation offset): the position at
    /// which the rotor flux points along phase a.
    pub commutation_offset_inc: u32,
}

impl Scaling {
    /// A 12-bit ADC over ±10 A (midscale 2048, 4.88 mA per count), a DC-link divider
    /// of 0.25 V per count (1023 V full scale), 4500 counts per period
    /// (144 MHz, 16 kHz centre-aligned), three shunts, offset 0.
    pub const fn default_board() -> Self {
        Self {
            amps_per_count: 20.0 / 4096.0,
            zero_counts: [2048.0; 3],
            volts_per_count: 0.25,
            pwm_period_counts: 4500,
            shunts: Shunts::Three,
            commutation_offset_inc: 0,
        }
    }
}
