//! The control-cycle timer (CCU40 slice 3, single shot, its period match on
//! service request SR0 = the CCU40_0 interrupt) and the route of the ESC's
//! SYNC0 through ERU1 (event trigger logic 0, input B, rising edge, output
//! gating unit 0 → ERU1.SR0 = the ERU1_0 interrupt).

use crate::regs::*;
use crate::Regs;

/// The timer's slice.
pub const SLICE: u32 = 3;
/// Prescaler: fCCU / 2^4 = 9 MHz, 111 ns per tick, up to 7.28 ms per shot.
pub const PRESCALER: u32 = 4;
/// Timer ticks per second.
pub const TICK_HZ: u32 = crate::F_CCU_HZ >> PRESCALER;

/// The control-cycle timer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CycleTimer(());

impl CycleTimer {
    /// Programs CCU40 slice 3: single shot, prescaler [`PRESCALER`], period
    /// match → SR0. Stopped until [`CycleTimer::arm`].
    pub fn init<R: Regs>(r: &mut R) -> CycleTimer {
        let s = slice(CCU40, SLICE);
        r.write(CCU40 + GIDLC, GIDLC_SPRB);
        r.write(s + TCCLR, TRBC | TCC);
        r.write(s + TC, TC_TSSM);
        r.write(s + CMC, 0);
        r.write(s + INS, 0);
        r.write(s + PSC, PRESCALER);
        r.write(s + SRS, 0);
        r.write(s + INTE, INTE_PME);
        r.write(s + SWR, 0xFFF);
        r.write(CCU40 + GCSS, gcss_pse(SLICE));
        r.write(CCU40 + GIDLC, (1 << SLICE) | GIDLC_SPRB);
        CycleTimer(())
    }

    /// The ticks of a delay in ns, rounded up (the interrupt never comes
    /// before the time asked for), at least 1 and at most one shot (65535
    /// ticks): a longer delay fires early and the task re-arms.
    pub fn ticks(delay_ns: u64) -> u32 {
        let t = (delay_ns.saturating_mul(u64::from(TICK_HZ))).div_ceil(1_000_000_000);
        t.clamp(1, 0xFFFF) as u32
    }

    /// Fires the interrupt `delay_ns` from now: stops and clears the timer,
    /// loads the period (transferred at once: the timer is stopped; the
    /// period match comes when the counter, started at 0, reaches it),
    /// clears a stale period-match flag and starts it.
    pub fn arm<R: Regs>(&self, r: &mut R, delay_ns: u64) {
        let s = slice(CCU40, SLICE);
        r.write(s + TCCLR, TRBC | TCC);
        r.write(s + PRS, Self::ticks(delay_ns));
        r.write(CCU40 + GCSS, gcss_se(SLICE));
        r.write(s + SWR, INTS_PMUS);
        r.write(s + TCSET, TRBS);
    }
}

/// ERU1.0B's source selection for SYNC0 (EXISEL.EXS0B). ASSUMED (see
/// docs/hardware.md): the reference manual's ERU1 connection table names
/// the input that carries ECAT0.SYNC0; check it before the first board.
pub const SYNC0_EXS0B: u32 = 0b01;

/// Routes SYNC0 to ERU1.SR0: event source B of ETL0 (input [`SYNC0_EXS0B`]),
/// rising edge, trigger pulse to OGU0, which requests service on every
/// trigger.
pub fn route_sync0<R: Regs>(r: &mut R) {
    r.modify(ERU1 + EXISEL, 0b11 << 2, SYNC0_EXS0B << 2);
    r.write(ERU1 + exicon(0), EXICON_PE | EXICON_RE | EXICON_SS_B);
    r.write(ERU1 + exocon(0), EXOCON_GP_ALWAYS);
}
