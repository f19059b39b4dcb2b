//! POSIF in quadrature-decoder mode with a CCU4 slice counting its clock
//! (POSIFx.OUT0 on the slice's input E) in the direction it decodes
//! (POSIFx.OUT1 on input F): POSIF0 with CCU40 slice 0 (axis A), POSIF1 with
//! CCU41 slice 0 (axis B). The index marker sets POSIF's index flag.

use crate::regs::*;
use crate::Regs;

/// Input selection of phase A, phase B and the index (0: POSIFx.IN*A
/// pins, 1: IN*B pins).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EncoderPins(pub [u32; 3]);

/// One axis' encoder.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Encoder {
    posif: u32,
    counter: u32,
    last: u16,
    position: i32,
}

impl Encoder {
    /// Programs the counter slice (16-bit, counts on input E's rising edge,
    /// direction from input F's level, free running over 0…65535), then
    /// POSIF (quadrature mode, index on every pulse) and starts both.
    pub fn init<R: Regs>(r: &mut R, posif: u32, ccu4: u32, pins: EncoderPins) -> Encoder {
        let s = slice(ccu4, 0);
        r.write(ccu4 + GIDLC, GIDLC_SPRB);
        r.write(s + TCCLR, TRBC | TCC);
        r.write(
            s + INS,
            (INPUT_E << INS_EV0IS_SHIFT) | INS_EV0EM_RISING | (INPUT_F << INS_EV1IS_SHIFT),
        );
        r.write(s + CMC, CMC_CNTS_EV0 | CMC_UDS_EV1);
        r.write(s + TC, 0);
        r.write(s + PRS, 0xFFFF);
        r.write(ccu4 + GCSS, gcss_se(0));
        r.write(ccu4 + GIDLC, 1 | GIDLC_SPRB);
        r.write(s + TCSET, TRBS);
        let mut pconf = PCONF_FSEL_QD;
        for (shift, sel) in PCONF_INSEL_SHIFT.iter().zip(pins.0) {
            pconf |= (sel & 0b11) << shift;
        }
        r.write(posif + PRUNC, RUN);
        r.write(posif + PCONF, pconf);
        r.write(posif + QDC, QDC_ICM_EVERY);
        r.write(posif + RPFLG, PFLG_INDX | PFLG_ERR);
        r.write(posif + PRUNS, RUN);
        let last = (r.read(s + TIMER) & 0xFFFF) as u16;
        Encoder {
            posif,
            counter: s,
            last,
            position: 0,
        }
    }

    /// The position in counts (four per line) since `init`, extended from
    /// the 16-bit counter: call at least once per 32767 counts of travel.
    pub fn position<R: Regs>(&mut self, r: &mut R) -> i32 {
        let now = (r.read(self.counter + TIMER) & 0xFFFF) as u16;
        let delta = now.wrapping_sub(self.last) as i16;
        self.last = now;
        self.position = self.position.wrapping_add(i32::from(delta));
        self.position
    }

    /// Whether an index pulse came since the last call (the flag cleared).
    pub fn take_index<R: Regs>(&self, r: &mut R) -> bool {
        let seen = r.read(self.posif + PFLG) & PFLG_INDX != 0;
        if seen {
            r.write(self.posif + RPFLG, PFLG_INDX);
        }
        seen
    }

    /// Whether POSIF saw a phase error (both phases changed at once: a
    /// signal too fast or disturbed) since the last call (the flag cleared).
    pub fn take_error<R: Regs>(&self, r: &mut R) -> bool {
        let err = r.read(self.posif + PFLG) & PFLG_ERR != 0;
        if err {
            r.write(self.posif + RPFLG, PFLG_ERR);
        }
        err
    }
}
