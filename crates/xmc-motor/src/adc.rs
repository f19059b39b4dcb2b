//! VADC: both axes' phase currents (U and V; W = −U − V) and the DC-link
//! voltage, converted by the scan sources of groups 0 and 1 on one trigger,
//! CCU80.SR2 (the PWM centre, see [`crate::pwm::Pwm::init`]), so the two
//! phases of an axis are sampled at the same instant in two converters. The
//! DC link is group 0's third conversion, the last of the five (group 1
//! converts two): its result raises group 0's service request 0
//! (VADC0_G0_0), the interrupt a current-loop task binds to.
//!
//! | group | channel | result | signal |
//! |---|---|---|---|
//! | 0 | 0 | 0 | axis A, phase U current |
//! | 0 | 1 | 1 | axis B, phase U current |
//! | 1 | 0 | 0 | axis A, phase V current |
//! | 1 | 1 | 1 | axis B, phase V current |
//! | 0 | 2 | 2 | DC-link voltage (service request VADC0_G0_0) |

use crate::regs::*;
use crate::Regs;

/// Analog clock divider: fADCI = fPERIPH / (DIVA + 1) = 144 / 5 = 28.8 MHz
/// (the reference manual's limit is 30 MHz).
pub const DIVA: u32 = 4;

/// (group, channel, result register) of each conversion, in [`Samples`] order:
/// A iU, B iU, A iV, B iV, DC link.
pub const MAP: [(u32, u32, u32); 5] = [(0, 0, 0), (0, 1, 1), (1, 0, 0), (1, 1, 1), (0, 2, 2)];

/// The group whose result ends a trigger's conversions, and its result register.
pub const LAST: (u32, u32) = (0, 2);

/// One trigger's raw 12-bit results.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Samples {
    /// Phase U current of axes A and B (raw).
    pub iu: [u16; 2],
    /// Phase V current of axes A and B (raw).
    pub iv: [u16; 2],
    /// DC-link voltage (raw).
    pub udc: u16,
}

/// The converter as this board uses it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Adc(());

impl Adc {
    /// Module on, clock divider, groups 0 and 1 powered, their scan sources
    /// armed on trigger input I (CCU80.SR2, rising edge) with the channels
    /// of [`MAP`], the [`LAST`] result raising the group's service request 0,
    /// start-up calibration started.
    pub fn init<R: Regs>(r: &mut R) -> Adc {
        r.write(VADC + CLC, 0);
        r.write(VADC + GLOBCFG, GLOBCFG_DIVWC | DIVA);
        for g in 0..2 {
            let base = vadc_group(g);
            let mut sel = 0;
            for &(mg, ch, res_reg) in MAP.iter() {
                if mg == g {
                    r.write(base + chctr(ch), res_reg << CHCTR_RESREG_SHIFT);
                    sel |= 1 << ch;
                }
            }
            r.write(base + ARBCFG, ARBCFG_ANONC_ON);
            r.write(base + CHASS, sel);
            r.write(base + ARBPR, ARBPR_SCAN);
            r.write(
                base + ASCTRL,
                (TRIGGER_CCU80_SR2 << ASCTRL_XTSEL_SHIFT) | ASCTRL_XTMODE_RISING | ASCTRL_XTWC | ASCTRL_GTWC,
            );
            r.write(base + ASSEL, sel);
            r.write(base + ASMR, ASMR_ENGT_PENDING | ASMR_ENTR);
        }
        let (g, last) = LAST;
        r.write(vadc_group(g) + rcr(last), RCR_SRGEN);
        r.modify(vadc_group(g) + REVNP0, 0xF << (4 * last), 0);
        r.write(VADC + GLOBCFG, GLOBCFG_SUCAL);
        Adc(())
    }

    /// The results of the last trigger, each read once (reading clears its
    /// valid flag); `None` when any of them was not valid (no conversion
    /// since the last read: the trigger did not come or the conversions
    /// have not finished).
    pub fn read<R: Regs>(&self, r: &mut R) -> Option<Samples> {
        let mut v = [0u16; 5];
        let mut valid = true;
        for (out, &(g, _, res_reg)) in v.iter_mut().zip(MAP.iter()) {
            let word = r.read(vadc_group(g) + res(res_reg));
            valid &= word & RES_VF != 0;
            *out = (word & 0xFFFF) as u16;
        }
        let [a_u, b_u, a_v, b_v, udc] = v;
        valid.then_some(Samples {
            iu: [a_u, b_u],
            iv: [a_v, b_v],
            udc,
        })
    }
}
