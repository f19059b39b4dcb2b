//! QEMU image (`qemu-system-arm -machine netduinoplus2`, STM32F405, Cortex-M4F).
//!
//! EXTI0 stands in for SYNC0 (highest priority); the `mailbox` software task
//! (lowest priority) pends it and reads the shared [`SyncState`] under a lock.
//! The log goes out over semihosting and is compared with
//! `firmware/qemu/expected/firmware-qemu.log` by `scripts/cross qemu`.
#![no_std]
#![no_main]

use cortex_m_rt as _;
use defmt_semihosting as _;

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    defmt::error!("panic: {}", defmt::Display2Format(info));
    cortex_m_semihosting::debug::exit(cortex_m_semihosting::debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}

#[rtic::app(device = stm32f4::stm32f405, dispatchers = [USART1])]
mod app {
    use cortex_m_semihosting::debug;
    use firmware::{SyncState, SELF_TEST_CYCLES};
    use stm32f4::stm32f405::Interrupt;

    #[shared]
    struct Shared {
        sync: SyncState,
    }

    #[local]
    struct Local {}

    #[init]
    fn init(_cx: init::Context) -> (Shared, Local) {
        defmt::info!("init: firmware-qemu (STM32F405), SYNC0 stand-in on EXTI0");
        if mailbox::spawn().is_err() {
            defmt::error!("init: mailbox task already spawned");
        }
        (
            Shared {
                sync: SyncState::new(),
            },
            Local {},
        )
    }

    #[idle]
    fn idle(_cx: idle::Context) -> ! {
        loop {
            cortex_m::asm::wfi();
        }
    }

    /// Stand-in for the SYNC0 interrupt: the highest priority in the system.
    #[task(binds = EXTI0, priority = 3, shared = [sync])]
    fn sync0(mut cx: sync0::Context) {
        let n = cx.shared.sync.lock(|s| s.on_sync0());
        defmt::info!("sync0: cycle {=u32}", n);
    }

    /// Stand-in for mailbox work: the lowest priority, preempted by SYNC0.
    #[task(priority = 1, shared = [sync])]
    async fn mailbox(mut cx: mailbox::Context) {
        for request in 1..=SELF_TEST_CYCLES {
            rtic::pend(Interrupt::EXTI0);
            // QEMU takes a pended interrupt only after a barrier.
            cortex_m::asm::dsb();
            cortex_m::asm::isb();
            let seen = cx.shared.sync.lock(|s| s.cycles());
            defmt::info!("mailbox: request {=u32} sees cycle {=u32}", request, seen);
        }
        let total = cx.shared.sync.lock(|s| s.cycles());
        if total == SELF_TEST_CYCLES {
            defmt::info!("done: {=u32} SYNC0 cycles, exit 0", total);
            debug::exit(debug::EXIT_SUCCESS);
        } else {
            defmt::error!(
                "done: {=u32} SYNC0 cycles, expected {=u32}",
                total,
                SELF_TEST_CYCLES
            );
            debug::exit(debug::EXIT_FAILURE);
        }
    }
}
