//! CCU8: one axis' three phases on slices 0…2 of a CCU8 module, centre
//! aligned, complementary outputs with dead time (OUTy0 = high side = ST1,
//! OUTy1 = low side = inverted ST1), the trap input (event 2, input A,
//! active low) forcing both outputs of every phase to their passive level
//! (low: gate off) until software clears it, and the start on the SCU's
//! global start signal (input H) so both axes run in phase.

use crate::regs::*;
use crate::Regs;

/// PWM settings of an axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PwmConfig {
    /// Period register: the counter runs 0…`period`…0, so one PWM period is
    /// 2 · (`period` + 1) clocks of fCCU.
    pub period: u16,
    /// Dead time in fCCU clocks (both edges).
    pub dead_time: u8,
}

impl PwmConfig {
    /// The settings for a PWM rate and a dead time at fCCU = `f_ccu_hz`;
    /// `None` when the period or dead time does not fit its register or the
    /// dead time is not below half a period.
    pub const fn new(f_ccu_hz: u32, pwm_hz: u32, dead_ns: u32) -> Option<PwmConfig> {
        if pwm_hz == 0 {
            return None;
        }
        let half = f_ccu_hz / pwm_hz / 2;
        let dead = (f_ccu_hz as u64 * dead_ns as u64).div_ceil(1_000_000_000);
        if half < 2 || half > 0x1_0000 || dead > 0xFF || dead as u32 >= half / 2 {
            return None;
        }
        Some(PwmConfig {
            period: (half - 1) as u16,
            dead_time: dead as u8,
        })
    }
}

/// Duty cycle as a Q16 fraction of the period the high side conducts
/// (0 = low side on, 65535 ≈ high side on).
pub type Duty = u16;

/// 50 % on every phase: zero voltage between the phases.
pub const DUTY_HALF: Duty = 0x8000;

/// One axis' PWM unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pwm {
    module: u32,
    period: u16,
}

/// The slices of the three phases.
const PHASES: [u32; 3] = [0, 1, 2];

impl Pwm {
    /// Programs slices 0…2 of the CCU8 `module` ([`CCU80`] or [`CCU81`]):
    /// period, dead time, 50 % duty, trap, passive levels, start on the
    /// global start. With `adc_trigger` slice 0's one match (counter at 0:
    /// the centre of the low sides' conduction, where low-side shunts carry
    /// the phase currents) raises service request SR2, the VADC's trigger
    /// input I. The timers stay stopped until the image pulses
    /// SCU_GENERAL.CCUCON's GSC8x bits.
    pub fn init<R: Regs>(r: &mut R, module: u32, cfg: PwmConfig, adc_trigger: bool) -> Pwm {
        r.write(module + GIDLC, GIDLC_SPRB);
        let mut gcss = 0;
        for y in PHASES {
            let s = slice(module, y);
            r.write(s + TCCLR, TRBC | TCC);
            r.write(s + TC, TC_TCM | TC_TRAPE0 | TC_TRAPE1 | TC_TRPSE | TC_TRPSW);
            r.write(
                s + INS,
                (INPUT_H << INS_EV0IS_SHIFT)
                    | INS_EV0EM_RISING
                    | (INPUT_A << INS_EV2IS_SHIFT)
                    | INS_EV2LM_LOW,
            );
            r.write(s + CMC, CMC_STRTS_EV0 | CMC_TS);
            r.write(s + PSL, 0);
            r.write(s + CHC, 0);
            r.write(s + DTC, DTC_DTE1 | DTC_DCEN1 | DTC_DCEN2);
            r.write(s + DC1R, u32::from(cfg.dead_time) * 0x0101);
            r.write(s + PSC, 0);
            r.write(s + PRS, u32::from(cfg.period));
            r.write(s + CR1S, compare(cfg.period, DUTY_HALF));
            r.write(s + SWR, 0xFFF);
            gcss |= gcss_se(y) | gcss_pse(y);
        }
        if adc_trigger {
            let s = slice(module, 0);
            r.write(s + SRS, 2 << SRS_POSR_SHIFT);
            r.write(s + INTE, INTE_OME);
        }
        r.write(module + GCSS, gcss);
        r.write(module + GIDLC, 0b0111 | GIDLC_SPRB);
        Pwm {
            module,
            period: cfg.period,
        }
    }

    /// The period register value.
    pub fn period(&self) -> u16 {
        self.period
    }

    /// Writes the three duty cycles to the compare shadow registers and
    /// requests their transfer, which the CCU8 makes at the next period or
    /// one match (never mid-pulse).
    pub fn set_duties<R: Regs>(&self, r: &mut R, duty: [Duty; 3]) {
        let mut gcss = 0;
        for (y, d) in PHASES.into_iter().zip(duty) {
            r.write(slice(self.module, y) + CR1S, compare(self.period, d));
            gcss |= gcss_se(y);
        }
        r.write(self.module + GCSS, gcss);
    }

    /// Whether any phase is in the trap state (its flag latched).
    pub fn trapped<R: Regs>(&self, r: &mut R) -> bool {
        PHASES
            .into_iter()
            .any(|y| r.read(slice(self.module, y) + INTS) & INTS_TRPF != 0)
    }

    /// Clears the trap flags: the outputs leave the passive level at the
    /// next PWM period if the trap input is inactive by then; while it is
    /// still active the trap state stays.
    pub fn clear_trap<R: Regs>(&self, r: &mut R) {
        for y in PHASES {
            r.write(slice(self.module, y) + SWR, SWR_RTRPF);
        }
    }
}

/// The compare value of a duty: ST1 (the high side) is active while the
/// counter is at or above it, so `period + 1` is 0 % and 0 is 100 %.
pub fn compare(period: u16, duty: Duty) -> u32 {
    let n = u32::from(period) + 1;
    ((u64::from(n) * u64::from(0x1_0000 - u32::from(duty))) >> 16) as u32
}
