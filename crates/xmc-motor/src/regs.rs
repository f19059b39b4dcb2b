//! Register addresses and bits (XMC4800 reference manual, chapters CCU8,
//! CCU4, VADC, POSIF, ERU, Ports; the offsets are those of the `xmc4800`
//! 0.14 PAC's register blocks).

/// CCU80 (axis A's PWM; its SR2 triggers the VADC).
pub const CCU80: u32 = 0x4002_0000;
/// CCU81 (axis B's PWM).
pub const CCU81: u32 = 0x4002_4000;
/// CCU40 (axis A's encoder counter on slice 0, the control timer on slice 3).
pub const CCU40: u32 = 0x4000_C000;
/// CCU41 (axis B's encoder counter on slice 0).
pub const CCU41: u32 = 0x4001_0000;
/// POSIF0 (axis A's encoder).
pub const POSIF0: u32 = 0x4002_8000;
/// POSIF1 (axis B's encoder).
pub const POSIF1: u32 = 0x4002_C000;
/// VADC global registers.
pub const VADC: u32 = 0x4000_4000;
/// VADC group `g` (0…3).
pub const fn vadc_group(g: u32) -> u32 {
    0x4000_4400 + 0x400 * g
}
/// ERU1.
pub const ERU1: u32 = 0x4004_4000;
/// Port `n`'s register block.
pub const fn port(n: u32) -> u32 {
    0x4802_8000 + 0x100 * n
}

/// A CCU4/CCU8 slice's base (`slice` 0…3).
pub const fn slice(module: u32, slice: u32) -> u32 {
    module + 0x100 * (slice + 1)
}

// ---- CCU4/CCU8 global (offsets from the module base) ----
/// Global control.
pub const GCTRL: u32 = 0x00;
/// Global status: slice idle bits 0…3, prescaler run bit 8.
pub const GSTAT: u32 = 0x04;
/// Idle set (write 1).
pub const GIDLS: u32 = 0x08;
/// Idle clear (write 1): CSxI bits 0…3, SPRB bit 8 (prescaler run).
pub const GIDLC: u32 = 0x0C;
/// Shadow transfer set (write 1): slice y's compare/period at bit 4y,
/// prescaler at 4y + 2.
pub const GCSS: u32 = 0x10;
/// Shadow transfer status (read): pending transfers, same bits as GCSS.
pub const GCST: u32 = 0x18;
/// GIDLC: prescaler run bit set.
pub const GIDLC_SPRB: u32 = 1 << 8;
/// GSTAT: prescaler running.
pub const GSTAT_PRB: u32 = 1 << 8;
/// GCSS/GCST: slice `y`'s period/compare shadow transfer.
pub const fn gcss_se(y: u32) -> u32 {
    1 << (4 * y)
}
/// GCSS/GCST: slice `y`'s prescaler shadow transfer.
pub const fn gcss_pse(y: u32) -> u32 {
    1 << (4 * y + 2)
}

// ---- CCU4/CCU8 slice (offsets from the slice base) ----
/// Input selector.
pub const INS: u32 = 0x00;
/// Connection matrix control.
pub const CMC: u32 = 0x04;
/// Timer status: TRB bit 0 (running), CDIR bit 1.
pub const TCST: u32 = 0x08;
/// Timer run set (write 1): TRBS bit 0.
pub const TCSET: u32 = 0x0C;
/// Timer clear (write 1): TRBC bit 0 (stop), TCC bit 1 (clear).
pub const TCCLR: u32 = 0x10;
/// Timer control.
pub const TC: u32 = 0x14;
/// Passive level.
pub const PSL: u32 = 0x18;
/// Prescaler.
pub const PSC: u32 = 0x24;
/// Period (active).
pub const PR: u32 = 0x30;
/// Period shadow.
pub const PRS: u32 = 0x34;
/// CCU4 compare (active) / CCU8 channel-1 compare.
pub const CR1: u32 = 0x38;
/// CCU4 compare shadow / CCU8 channel-1 compare shadow.
pub const CR1S: u32 = 0x3C;
/// CCU8 channel control.
pub const CHC: u32 = 0x48;
/// CCU8 dead-time control.
pub const DTC: u32 = 0x4C;
/// CCU8 channel-1 dead-time values (rising 0…7, falling 8…15).
pub const DC1R: u32 = 0x50;
/// Timer value.
pub const TIMER: u32 = 0x70;
/// Interrupt status.
pub const INTS: u32 = 0xA0;
/// Interrupt enable.
pub const INTE: u32 = 0xA4;
/// Service request selector.
pub const SRS: u32 = 0xA8;
/// Interrupt status clear (write 1).
pub const SWR: u32 = 0xB0;

/// TCSET: timer run set.
pub const TRBS: u32 = 1 << 0;
/// TCST: timer running.
pub const TRB: u32 = 1 << 0;
/// TCCLR: timer run clear.
pub const TRBC: u32 = 1 << 0;
/// TCCLR: timer clear.
pub const TCC: u32 = 1 << 1;
/// TC: centre-aligned counting.
pub const TC_TCM: u32 = 1 << 0;
/// TC: single shot.
pub const TC_TSSM: u32 = 1 << 1;
/// TC (CCU8): trap enable for OUTy0.
pub const TC_TRAPE0: u32 = 1 << 17;
/// TC (CCU8): trap enable for OUTy1.
pub const TC_TRAPE1: u32 = 1 << 18;
/// TC (CCU8): trap exit synchronised with the PWM period.
pub const TC_TRPSE: u32 = 1 << 21;
/// TC (CCU8): trap state left only on a software request.
pub const TC_TRPSW: u32 = 1 << 22;
/// CMC: start on event 0.
pub const CMC_STRTS_EV0: u32 = 0b01;
/// CMC: up/down on event 1 (bits 10…11).
pub const CMC_UDS_EV1: u32 = 0b10 << 10;
/// CMC: count on event 0 (bits 14…15).
pub const CMC_CNTS_EV0: u32 = 0b01 << 14;
/// CMC (CCU8): trap function on event 2.
pub const CMC_TS: u32 = 1 << 17;
/// INS: event 0 input select (bits 0…3).
pub const INS_EV0IS_SHIFT: u32 = 0;
/// INS: event 1 input select (bits 4…7).
pub const INS_EV1IS_SHIFT: u32 = 4;
/// INS: event 2 input select (bits 8…11).
pub const INS_EV2IS_SHIFT: u32 = 8;
/// INS: event 0 on the rising edge.
pub const INS_EV0EM_RISING: u32 = 0b01 << 16;
/// INS: event 2 active low.
pub const INS_EV2LM_LOW: u32 = 1 << 24;
/// Slice input A (a pin: the CCU8 trap input).
pub const INPUT_A: u32 = 0;
/// Slice input E (CCU4: POSIFx.OUT0, the quadrature clock).
pub const INPUT_E: u32 = 4;
/// Slice input F (CCU4: POSIFx.OUT1, the direction).
pub const INPUT_F: u32 = 5;
/// Slice input H (SCU.GSCxx, the global start of SCU_GENERAL.CCUCON).
pub const INPUT_H: u32 = 7;
/// DTC: dead time on channel 1.
pub const DTC_DTE1: u32 = 1 << 0;
/// DTC: dead time on ST1's output.
pub const DTC_DCEN1: u32 = 1 << 2;
/// DTC: dead time on inverted ST1's output.
pub const DTC_DCEN2: u32 = 1 << 3;
/// INTE: period match.
pub const INTE_PME: u32 = 1 << 0;
/// INTE: one match (counting down, centre-aligned).
pub const INTE_OME: u32 = 1 << 1;
/// INTS: period match.
pub const INTS_PMUS: u32 = 1 << 0;
/// INTS: one match.
pub const INTS_OMDS: u32 = 1 << 1;
/// INTS (CCU8): trap flag.
pub const INTS_TRPF: u32 = 1 << 11;
/// SWR (CCU8): clear the trap flag.
pub const SWR_RTRPF: u32 = 1 << 11;
/// SRS: period/one match service request line (bits 0…1).
pub const SRS_POSR_SHIFT: u32 = 0;

// ---- POSIF (offsets from the module base) ----
/// Configuration.
pub const PCONF: u32 = 0x00;
/// Run set (write 1).
pub const PRUNS: u32 = 0x08;
/// Run clear (write 1).
pub const PRUNC: u32 = 0x0C;
/// Run status.
pub const PRUN: u32 = 0x10;
/// Quadrature decoder control.
pub const QDC: u32 = 0x60;
/// Flags.
pub const PFLG: u32 = 0x70;
/// Flag clear (write 1).
pub const RPFLG: u32 = 0x7C;
/// PCONF: quadrature decoder mode.
pub const PCONF_FSEL_QD: u32 = 0b01;
/// PCONF: input selection shifts (phase A, phase B, index).
pub const PCONF_INSEL_SHIFT: [u32; 3] = [8, 10, 12];
/// QDC: index marker on every index pulse (ICM = 10b).
pub const QDC_ICM_EVERY: u32 = 0b10 << 4;
/// PFLG/RPFLG: index seen.
pub const PFLG_INDX: u32 = 1 << 8;
/// PFLG/RPFLG: phase error.
pub const PFLG_ERR: u32 = 1 << 9;
/// PRUNS/PRUN: run bit.
pub const RUN: u32 = 1 << 0;

// ---- VADC ----
/// Clock control (0: module on).
pub const CLC: u32 = 0x00;
/// Global configuration.
pub const GLOBCFG: u32 = 0x80;
/// GLOBCFG: write control for the dividers.
pub const GLOBCFG_DIVWC: u32 = 1 << 15;
/// GLOBCFG: start-up calibration.
pub const GLOBCFG_SUCAL: u32 = 1 << 31;
/// Group: arbitration configuration.
pub const ARBCFG: u32 = 0x80;
/// ARBCFG: converter in normal operation (ANONC = 11b).
pub const ARBCFG_ANONC_ON: u32 = 0b11;
/// Group: arbitration priority.
pub const ARBPR: u32 = 0x84;
/// ARBPR: source 1 (scan) priority 3, its arbitration slot enabled.
pub const ARBPR_SCAN: u32 = (0b11 << 4) | (1 << 25);
/// Group: channel assignment (priority channels of the group).
pub const CHASS: u32 = 0x88;
/// Group: scan source control.
pub const ASCTRL: u32 = 0x120;
/// ASCTRL: trigger input select shift (bits 8…11).
pub const ASCTRL_XTSEL_SHIFT: u32 = 8;
/// ASCTRL: trigger on the rising edge (XTMODE = 10b).
pub const ASCTRL_XTMODE_RISING: u32 = 0b10 << 13;
/// ASCTRL: write control for the trigger fields.
pub const ASCTRL_XTWC: u32 = 1 << 15;
/// ASCTRL: write control for the gate fields.
pub const ASCTRL_GTWC: u32 = 1 << 23;
/// Group: scan source mode.
pub const ASMR: u32 = 0x124;
/// ASMR: requests issued when pending bits are set (ENGT = 01b).
pub const ASMR_ENGT_PENDING: u32 = 0b01;
/// ASMR: external trigger enabled.
pub const ASMR_ENTR: u32 = 1 << 2;
/// Group: scan channel select.
pub const ASSEL: u32 = 0x128;
/// Group: channel `ch`'s control.
pub const fn chctr(ch: u32) -> u32 {
    0x200 + 4 * ch
}
/// CHCTR: result register shift (bits 16…19).
pub const CHCTR_RESREG_SHIFT: u32 = 16;
/// Group: result control of result register `n`.
pub const fn rcr(n: u32) -> u32 {
    0x280 + 4 * n
}
/// RCR: service request on a new result.
pub const RCR_SRGEN: u32 = 1 << 31;
/// Group: result event node pointers of result registers 0…7 (4 bits each;
/// 0…3: the group's service request lines 0…3).
pub const REVNP0: u32 = 0x1B0;
/// Group: result register `n`.
pub const fn res(n: u32) -> u32 {
    0x300 + 4 * n
}
/// RES: valid flag (cleared by reading RES).
pub const RES_VF: u32 = 1 << 31;
/// RES: channel number shift (bits 20…24).
pub const RES_CHNR_SHIFT: u32 = 20;
/// Trigger input I of every group: CCU80.SR2.
pub const TRIGGER_CCU80_SR2: u32 = 8;

// ---- ERU1 ----
/// Event input select.
pub const EXISEL: u32 = 0x00;
/// Event input control of ETL `n`.
pub const fn exicon(n: u32) -> u32 {
    0x10 + 4 * n
}
/// Event output control of OGU `n`.
pub const fn exocon(n: u32) -> u32 {
    0x20 + 4 * n
}
/// EXICON: output trigger pulse enable.
pub const EXICON_PE: u32 = 1 << 0;
/// EXICON: rising edge.
pub const EXICON_RE: u32 = 1 << 2;
/// EXICON: input source B (SS = 01b, bits 8…9).
pub const EXICON_SS_B: u32 = 0b01 << 8;
/// EXOCON: service request on every trigger (GP = 01b, bits 4…5).
pub const EXOCON_GP_ALWAYS: u32 = 0b01 << 4;

// ---- Ports ----
/// Output modification (write: set bit n, reset bit n + 16).
pub const OMR: u32 = 0x04;
/// Pin control of pins 0…3 (then +4 for every 4 pins).
pub const IOCR0: u32 = 0x10;
/// Pin control: push-pull general-purpose output.
pub const PC_GPIO_OUT: u32 = 0b1_0000;
/// Pin control: push-pull alternate output 3 (the CCU8 outputs).
pub const PC_ALT3: u32 = 0b1_0011;
