//! A host model of the registers this crate uses, with the behaviour the
//! XMC4800 reference manual gives them (not the drivers' own numbers):
//! write-1 set/clear registers that read 0, CCU4/CCU8 shadow registers that
//! reach the active ones only on a GCSS request, at once while the timer is
//! stopped and at the next period/one match while it runs; timers that run
//! only out of idle with the prescaler running; the CCU8 trap state entered
//! at the trap input's active level and, with TRPSW, left only after the
//! flag is cleared with the input inactive, at a period boundary; VADC
//! write-control bits, scan sources converting on their selected trigger
//! into the result register a channel names, valid flags cleared by
//! reading RES; POSIF counting into the CCU4 slice wired to it; ERU1.
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use crate::regs::*;
use std::collections::{HashMap, HashSet};
use std::vec::Vec;

const CCU_MODULES: [u32; 4] = [CCU80, CCU81, CCU40, CCU41];
const WRITE_ONLY_GLOBAL: [u32; 3] = [GIDLS, GIDLC, GCSS];
const WRITE_ONLY_SLICE: [u32; 3] = [TCSET, TCCLR, SWR];

#[derive(Default)]
pub struct Model {
    pub mem: HashMap<u32, u32>,
    /// (module, service request line) in the order raised.
    pub sr: Vec<(u32, u32)>,
    /// Slices in the trap state.
    trapped: HashSet<u32>,
    /// Trap pin level per CCU8 module (true: low).
    trap_low: HashMap<u32, bool>,
    /// Analog input values per (group, channel).
    pub analog: HashMap<(u32, u32), u16>,
}

fn ccu_of(addr: u32) -> Option<(u32, Option<u32>, u32)> {
    CCU_MODULES.iter().find_map(|&m| {
        let off = addr.checked_sub(m)?;
        if off < 0x100 {
            Some((m, None, off))
        } else if off < 0x500 {
            Some((m, Some(off / 0x100 - 1), off % 0x100))
        } else {
            None
        }
    })
}

impl Model {
    pub fn new() -> Model {
        let mut m = Model::default();
        for module in CCU_MODULES {
            m.mem.insert(module + GSTAT, 0xF); // every slice idle, prescaler stopped
        }
        m.mem.insert(VADC + CLC, 0b11); // module disabled after reset
        m
    }
    pub fn get(&self, addr: u32) -> u32 {
        self.mem.get(&addr).copied().unwrap_or(0)
    }
    fn set(&mut self, addr: u32, v: u32) {
        self.mem.insert(addr, v);
    }
    fn running(&self, module: u32, y: u32) -> bool {
        self.get(slice(module, y) + TCST) & TRB != 0
    }
    fn transfer(&mut self, module: u32, y: u32) {
        let s = slice(module, y);
        let pending = self.get(module + GCST);
        if pending & gcss_se(y) != 0 {
            self.set(s + PR, self.get(s + PRS));
            self.set(s + CR1, self.get(s + CR1S));
        }
        self.set(module + GCST, pending & !(0b111 << (4 * y)));
    }
    fn trap_active(&self, module: u32, y: u32) -> bool {
        let s = slice(module, y);
        let low = self.trap_low.get(&module).copied().unwrap_or(false);
        let active_low = self.get(s + INS) & INS_EV2LM_LOW != 0;
        self.get(s + CMC) & CMC_TS != 0
            && (self.get(s + INS) >> INS_EV2IS_SHIFT) & 0xF == INPUT_A
            && low == active_low
    }

    /// The trap pin of a CCU8 module goes low (`true`) or high.
    pub fn trap_pin(&mut self, module: u32, low: bool) {
        self.trap_low.insert(module, low);
        for y in 0..4 {
            if self.trap_active(module, y) {
                let s = slice(module, y);
                self.set(s + INTS, self.get(s + INTS) | INTS_TRPF);
                self.trapped.insert(s);
            }
        }
    }
    /// Whether slice `y`'s outputs are forced to their passive level.
    pub fn passive(&self, module: u32, y: u32) -> bool {
        let s = slice(module, y);
        let tc = self.get(s + TC);
        self.trapped.contains(&s) && tc & (TC_TRAPE0 | TC_TRAPE1) == TC_TRAPE0 | TC_TRAPE1
    }

    /// A period or one match of the module's running slices: pending shadow
    /// transfers happen, trap states end where allowed, and with `one` the
    /// one-match flags and their service requests (CCU80.SR2 triggers the VADC).
    pub fn boundary(&mut self, module: u32, one: bool) {
        for y in 0..4 {
            if !self.running(module, y) {
                continue;
            }
            self.transfer(module, y);
            let s = slice(module, y);
            let tc = self.get(s + TC);
            let cleared = self.get(s + INTS) & INTS_TRPF == 0 || tc & TC_TRPSW == 0;
            if self.trapped.contains(&s) && cleared && !self.trap_active(module, y) {
                self.trapped.remove(&s);
            }
            if one {
                self.set(s + INTS, self.get(s + INTS) | INTS_OMDS);
                if self.get(s + INTE) & INTE_OME != 0 {
                    let line = (self.get(s + SRS) >> SRS_POSR_SHIFT) & 0b11;
                    self.sr.push((module, line));
                    if module == CCU80 && line == 2 {
                        self.trigger(TRIGGER_CCU80_SR2);
                    }
                }
            }
        }
    }

    /// SCU_GENERAL.CCUCON's global start bit of a module pulsed: slices
    /// started by a rising edge on input H start.
    pub fn global_start(&mut self, module: u32) {
        let st = self.get(module + GSTAT);
        for y in 0..4 {
            let s = slice(module, y);
            let ins = self.get(s + INS);
            let on_h = self.get(s + CMC) & 0b11 == CMC_STRTS_EV0
                && ins & 0xF == INPUT_H
                && ins & (0b11 << 16) == INS_EV0EM_RISING;
            if on_h && st & (1 << y) == 0 && st & GSTAT_PRB != 0 {
                self.set(s + TCST, self.get(s + TCST) | TRB);
            }
        }
    }

    /// `ticks` clocks of a CCU4 slice's prescaled counter (edge aligned: the
    /// period match when the counter, counting from 0, reaches PR).
    pub fn advance(&mut self, module: u32, y: u32, ticks: u32) {
        if !self.running(module, y) {
            return;
        }
        let s = slice(module, y);
        let pr = self.get(s + PR);
        let t = self.get(s + TIMER) + ticks;
        if t >= pr {
            self.set(s + INTS, self.get(s + INTS) | INTS_PMUS);
            if self.get(s + INTE) & INTE_PME != 0 {
                self.sr
                    .push((module, (self.get(s + SRS) >> SRS_POSR_SHIFT) & 0b11));
            }
            self.transfer(module, y);
            self.set(s + TIMER, 0);
            if self.get(s + TC) & TC_TSSM != 0 {
                self.set(s + TCST, self.get(s + TCST) & !TRB);
            }
        } else {
            self.set(s + TIMER, t);
        }
    }

    /// A VADC trigger input pulse (rising edge).
    pub fn trigger(&mut self, input: u32) {
        if self.get(VADC + CLC) & 1 != 0 {
            return;
        }
        for g in 0..4 {
            let b = vadc_group(g);
            let on = self.get(b + ARBCFG) & 0b11 == ARBCFG_ANONC_ON && self.get(b + ARBPR) & (1 << 25) != 0;
            let mode = self.get(b + ASMR);
            let ctrl = self.get(b + ASCTRL);
            if !on
                || mode & 0b11 != ASMR_ENGT_PENDING
                || mode & ASMR_ENTR == 0
                || (ctrl >> ASCTRL_XTSEL_SHIFT) & 0xF != input
                || ctrl & (0b11 << 13) != ASCTRL_XTMODE_RISING
            {
                continue;
            }
            let sel = self.get(b + ASSEL);
            for ch in 0..8 {
                if sel & (1 << ch) != 0 {
                    let v = u32::from(*self.analog.get(&(g, ch)).unwrap_or(&0)) & 0xFFF;
                    let reg = (self.get(b + chctr(ch)) >> CHCTR_RESREG_SHIFT) & 0xF;
                    self.set(b + res(reg), RES_VF | (ch << RES_CHNR_SHIFT) | v);
                    if self.get(b + rcr(reg)) & RCR_SRGEN != 0 {
                        let node = (self.get(b + REVNP0) >> (4 * reg)) & 0xF;
                        self.sr.push((b, node));
                    }
                }
            }
        }
    }

    /// `counts` quadrature edges (signed: direction) at a POSIF.
    pub fn quad(&mut self, posif: u32, counts: i32) {
        let ccu4 = if posif == POSIF0 { CCU40 } else { CCU41 };
        if self.get(posif + PRUN) & RUN == 0 || self.get(posif + PCONF) & 0b11 != PCONF_FSEL_QD {
            return;
        }
        let s = slice(ccu4, 0);
        let ins = self.get(s + INS);
        let cmc = self.get(s + CMC);
        let wired = ins & 0xF == INPUT_E
            && (ins >> INS_EV1IS_SHIFT) & 0xF == INPUT_F
            && cmc & (0b11 << 14) == CMC_CNTS_EV0
            && cmc & (0b11 << 10) == CMC_UDS_EV1;
        if !wired || !self.running(ccu4, 0) {
            return;
        }
        let period = i64::from(self.get(s + PR)) + 1;
        let t = (i64::from(self.get(s + TIMER)) + i64::from(counts)).rem_euclid(period);
        self.set(s + TIMER, t as u32);
    }
    /// An index pulse at a POSIF.
    pub fn index(&mut self, posif: u32) {
        if self.get(posif + PRUN) & RUN != 0 && self.get(posif + QDC) & (0b11 << 4) != 0 {
            self.set(posif + PFLG, self.get(posif + PFLG) | PFLG_INDX);
        }
    }
    /// A rising edge on ERU1 input 0B`sel`.
    pub fn eru1_edge(&mut self, sel: u32) {
        let icon = self.get(ERU1 + exicon(0));
        if (self.get(ERU1 + EXISEL) >> 2) & 0b11 == sel
            && icon & (EXICON_RE | EXICON_PE) == EXICON_RE | EXICON_PE
            && icon & (0b11 << 8) == EXICON_SS_B
            && (icon >> 4) & 0b111 == 0
            && self.get(ERU1 + exocon(0)) & (0b11 << 4) == EXOCON_GP_ALWAYS
        {
            self.sr.push((ERU1, 0));
        }
    }
}

impl crate::Regs for Model {
    fn read(&mut self, addr: u32) -> u32 {
        if let Some((_, s, off)) = ccu_of(addr) {
            let wo = if s.is_some() {
                &WRITE_ONLY_SLICE[..]
            } else {
                &WRITE_ONLY_GLOBAL[..]
            };
            if wo.contains(&off) {
                return 0;
            }
        }
        if [PRUNS, PRUNC, RPFLG]
            .iter()
            .any(|&o| addr == POSIF0 + o || addr == POSIF1 + o)
        {
            return 0;
        }
        let v = self.get(addr);
        for g in 0..4 {
            let b = vadc_group(g);
            if (b + res(0)..b + res(16)).contains(&addr) {
                self.set(addr, v & !RES_VF);
            }
        }
        v
    }

    fn write(&mut self, addr: u32, v: u32) {
        if let Some((m, s, off)) = ccu_of(addr) {
            match (s, off) {
                (None, GIDLC) => {
                    let mut st = self.get(m + GSTAT) & !(v & 0xF);
                    if v & GIDLC_SPRB != 0 {
                        st |= GSTAT_PRB;
                    }
                    self.set(m + GSTAT, st);
                }
                (None, GIDLS) => self.set(m + GSTAT, self.get(m + GSTAT) | (v & 0xF)),
                (None, GCSS) => {
                    self.set(m + GCST, self.get(m + GCST) | (v & 0x7777));
                    for y in 0..4 {
                        if v & (0b111 << (4 * y)) != 0 && !self.running(m, y) {
                            self.transfer(m, y);
                        }
                    }
                }
                (Some(y), TCSET) => {
                    let st = self.get(m + GSTAT);
                    if v & TRBS != 0 && st & (1 << y) == 0 && st & GSTAT_PRB != 0 {
                        let a = slice(m, y) + TCST;
                        self.set(a, self.get(a) | TRB);
                    }
                }
                (Some(y), TCCLR) => {
                    let sb = slice(m, y);
                    if v & TRBC != 0 {
                        self.set(sb + TCST, self.get(sb + TCST) & !TRB);
                    }
                    if v & TCC != 0 {
                        self.set(sb + TIMER, 0);
                    }
                }
                (Some(y), SWR) => {
                    let sb = slice(m, y);
                    let mut ints = self.get(sb + INTS) & !v;
                    if self.trap_active(m, y) {
                        ints |= INTS_TRPF; // the level is still there
                    }
                    self.set(sb + INTS, ints);
                }
                _ => self.set(addr, v),
            }
            return;
        }
        for p in [POSIF0, POSIF1] {
            if addr == p + PRUNS {
                return self.set(p + PRUN, self.get(p + PRUN) | (v & RUN));
            }
            if addr == p + PRUNC {
                return self.set(p + PRUN, self.get(p + PRUN) & !(v & RUN));
            }
            if addr == p + RPFLG {
                return self.set(p + PFLG, self.get(p + PFLG) & !v);
            }
        }
        if addr == VADC + GLOBCFG && v & GLOBCFG_DIVWC == 0 {
            // the dividers keep their value without their write control bit
            let keep = self.get(addr) & 0x31F;
            return self.set(addr, (v & !0x31F & !GLOBCFG_DIVWC) | keep);
        }
        for g in 0..4 {
            if addr == vadc_group(g) + ASCTRL {
                let old = self.get(addr);
                let mut n = v & !(ASCTRL_XTWC | ASCTRL_GTWC | (1 << 31));
                if v & ASCTRL_XTWC == 0 {
                    n = (n & !0x7F00) | (old & 0x7F00);
                }
                return self.set(addr, n);
            }
        }
        if let Some(pn) = (0..16).find(|&n| addr == port(n) + OMR) {
            let out = self.get(port(pn));
            let (set, reset) = (v & 0xFFFF, v >> 16);
            return self.set(port(pn), (out & !reset) | set);
        }
        self.set(addr, v);
    }
}
