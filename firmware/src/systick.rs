//! SysTick as the QEMU images' instruction counter: under `-icount
//! shift=0` (one instruction per virtual ns) SysTick at the core clock
//! counts time, and [`calibrate`] converts its ticks to instructions.

use cortex_m::peripheral::SYST;

/// SysTick value now (24-bit down counter).
#[inline]
pub fn now() -> u32 {
    SYST::get_current()
}

/// SysTick ticks from `start` to `end` (a down counter, wraps at 2^24: one
/// wrap at most).
#[inline]
pub fn ticks(start: u32, end: u32) -> u32 {
    start.wrapping_sub(end) & 0x00FF_FFFF
}

/// SysTick started as the instruction counter: the core clock, the full 24
/// bits; returns its [`calibrate`]d instructions per 1000 ticks.
pub fn start(syst: &mut SYST) -> u32 {
    syst.set_clock_source(cortex_m::peripheral::syst::SystClkSource::Core);
    syst.set_reload(0x00FF_FFFF);
    syst.clear_current();
    syst.enable_counter();
    calibrate()
}

/// Instructions per 1000 SysTick ticks, from a loop of `2 · n`
/// instructions (`subs` + `bne`).
#[allow(unsafe_code)]
pub fn calibrate() -> u32 {
    let n: u32 = 200_000;
    let t0 = now();
    // SAFETY: a register-only countdown loop, no memory access.
    unsafe {
        core::arch::asm!("1:", "subs {0}, {0}, #1", "bne 1b", inout(reg) n => _, options(nomem, nostack));
    }
    let t = ticks(t0, now()).max(1);
    (u64::from(2 * n) * 1000 / u64::from(t)) as u32
}
