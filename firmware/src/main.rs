//! Reference-board image: Infineon XMC4800 (Cortex-M4F, on-chip ESC), defmt
//! over RTT, flashed by `cargo run` through probe-rs (see docs/flashing.md).
//!
//! Task map (priorities as in docs/architecture.md):
//! - `sync0` bound to ERU1_0, where the XMC4800 routes the ESC's SYNC0 output:
//!   the highest priority;
//! - `mailbox` software task at the lowest priority.
//!
//! Until the on-chip ESC driver lands (issue 7) nothing raises SYNC0, so the
//! mailbox task pends it itself at boot, the same self-test the QEMU image runs.
#![no_std]
#![no_main]

use cortex_m_rt as _; // the reset handler and vector table; the PAC does not pull it in
use defmt_rtt as _;
use panic_probe as _;

/// The XMC4800 PAC as RTIC expects a device crate: svd2rust 0.14 output lacks
/// the `interrupt` alias of the `Interrupt` enum, so it is added here.
mod pac {
    pub use xmc4800::Interrupt as interrupt;
    pub use xmc4800::*;
}

#[rtic::app(device = crate::pac, dispatchers = [CCU40_0])]
mod app {
    use crate::pac::Interrupt;
    use firmware::{SyncState, SELF_TEST_CYCLES};

    #[shared]
    struct Shared {
        sync: SyncState,
    }

    #[local]
    struct Local {}

    #[init]
    fn init(_cx: init::Context) -> (Shared, Local) {
        defmt::info!("init: firmware (XMC4800), SYNC0 on ERU1_0");
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

    /// SYNC0 from the ESC (via ERU1): the highest priority in the system.
    #[task(binds = ERU1_0, priority = 3, shared = [sync])]
    fn sync0(mut cx: sync0::Context) {
        let n = cx.shared.sync.lock(|s| s.on_sync0());
        defmt::trace!("sync0: cycle {=u32}", n);
    }

    /// Mailbox work: the lowest priority, preempted by SYNC0.
    #[task(priority = 1, shared = [sync])]
    async fn mailbox(mut cx: mailbox::Context) {
        for _ in 0..SELF_TEST_CYCLES {
            rtic::pend(Interrupt::ERU1_0);
            cortex_m::asm::dsb();
            cortex_m::asm::isb();
        }
        let total = cx.shared.sync.lock(|s| s.cycles());
        if total == SELF_TEST_CYCLES {
            defmt::info!("self-test: {=u32} SYNC0 cycles, ok", total);
        } else {
            defmt::error!(
                "self-test: {=u32} SYNC0 cycles, expected {=u32}",
                total,
                SELF_TEST_CYCLES
            );
        }
    }
}
