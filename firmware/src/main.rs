//! Reference-board image: Infineon XMC4800 (Cortex-M4F, on-chip ESC), defmt
//! over RTT, flashed by `cargo run` through probe-rs (see docs/flashing.md).
//!
//! Task map (docs/architecture.md has the worst-case path of each):
//!
//! | task | interrupt | priority | body |
//! |---|---|---|---|
//! | `sync0` | ERU1_0 (ESC SYNC0 routed through ERU1) | 3 | `node::tasks::sync0` |
//! | `control` | CCU40_0 (control-cycle timer compare) | 3 | `node::tasks::control` |
//! | `esc` | ECAT0_0 (ESC PDI interrupt: AL events, SM2/SM3, mailbox) | 2 | `node::tasks::esc_event` |
//! | `mailbox` | CCU42_0 (a spare interrupt, pended by `esc` and by `idle` when the IP stack's timers are due) | 1 | `node::tasks::mailbox_net` (mailbox request, IP stack over EoE) |
//! | `idle` | — | 0 | `node::tasks::background` (a requested save) |
//!
//! The ESC is reached through `pdi::mmio::OnChip` over ECAT0's register
//! window; the clock is the DWT cycle counter at the CPU clock.
//!
//! Board bring-up that needs the hardware to verify — the ECAT0 clock and
//! reset release, the port pin functions, the ERU1 routing of SYNC0 and the
//! CCU4 compare programming from `CycleTimer::next_at_ns`, the ADC/encoder
//! inputs and PWM outputs of the power stage — is listed in docs/flashing.md
//! and not done here: this image pends its timer interrupt from the idle loop
//! and feeds the axes "ready, at rest" inputs.
#![no_std]
#![no_main]

use cortex_m_rt as _; // the reset handler and vector table; the PAC does not pull it in
use defmt_rtt as _;

/// Ed25519 through the boot loader's table (`boot::BootApi`): the FoE path's
/// signature check (`BootSlots::finish_verified`) without a second copy of
/// the verifier in this image.
#[path = "bootapi.rs"]
mod bootapi;

/// A panic masks every interrupt first, so no task can command the power
/// stage again, switches the power stage off (gate enable low), then
/// reports over RTT and stops the core. `scripts/cross panics` checks that
/// no panic path is reachable from any task.
#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    cortex_m::interrupt::disable();
    power::set(false);
    defmt::error!("panic: interrupts masked, power stage off, halted");
    loop {
        cortex_m::asm::bkpt();
    }
}

/// The XMC4800 PAC as RTIC expects a device crate: svd2rust 0.14 output lacks
/// the `interrupt` alias of the `Interrupt` enum, so it is added here.
mod pac {
    pub use xmc4800::Interrupt as interrupt;
    pub use xmc4800::*;
}

/// The power stage's gate-driver enable: P5.9, push-pull, active high
/// (docs/flashing.md, wiring). Low from `init` until a control cycle
/// commands an axis' power stage on; the panic handler drives it low.
mod power {
    /// Port 5 (only its output-modification register, whose set/reset
    /// writes are atomic, and at `init` its pin 8–11 control register).
    #[allow(unsafe_code)]
    fn port() -> &'static xmc4800::port5::RegisterBlock {
        // SAFETY: PORT5 is a fixed peripheral address; OMR writes touch only
        // the bits written (no read-modify-write race with other users).
        unsafe { &*xmc4800::PORT5::ptr() }
    }

    /// P5.9 as a push-pull output, low.
    pub fn init() {
        port().omr().write(|w| w.pr9().set_bit());
        port().iocr8().modify(|_, w| w.pc9().value9());
    }

    /// Gate enable high (`on`) or low.
    pub fn set(on: bool) {
        port()
            .omr()
            .write(|w| if on { w.ps9().set_bit() } else { w.pr9().set_bit() });
    }
}

/// CPU clock after the boot ROM's PLL setup, Hz (DWT CYCCNT counts it).
const CPU_HZ: u32 = 144_000_000;

#[rtic::app(device = crate::pac)]
mod app {
    use crate::pac::Interrupt;
    use crate::CPU_HZ;
    use cortex_m::peripheral::DWT;
    use drive::axis::{AxisCommand, AxisIo};
    use firmware::clock::Clock;
    use firmware::cycle::CycleTimer;
    #[cfg(not(feature = "net"))]
    use firmware::net::NoNet as Net;
    #[cfg(feature = "net")]
    use firmware::net::{NetBuffers, NodeNet as Net, SocketSlots, BOARD_NET, EMPTY_SLOTS};
    use firmware::{tasks, Drive, ParamFlash};
    use pdi::mmio::{OnChip, VolatileWindow};

    #[shared]
    struct Shared {
        /// The drive (a `'static` singleton: built once, never moved through the stack).
        drive: &'static mut Drive,
        timer: CycleTimer,
        pdi: OnChip<VolatileWindow>,
        clock: Clock,
        cmd: [AxisCommand; 2],
        /// The IP stack on the EoE interface (docs/eoe.md), polled by
        /// `mailbox` (feature `net`; without it EoE frames are counted and dropped).
        net: &'static mut Net,
    }

    #[local]
    struct Local {}

    #[init]
    fn init(cx: init::Context) -> (Shared, Local) {
        let mut core = cx.core;
        core.DCB.enable_trace();
        core.DWT.enable_cycle_counter();
        crate::power::init();
        defmt::info!("init: firmware (XMC4800), SYNC0 on ERU1_0, ESC on ECAT0_0");
        // SAFETY: ECAT0 is this chip's ESC; the window is owned by the `pdi`
        // resource alone, so RTIC serialises every access to it.
        #[allow(unsafe_code)]
        let window = unsafe { VolatileWindow::xmc4800_ecat0() };
        // built once into its static, not moved through `init`'s stack
        let Some((drive, net)) = make_drive().and_then(|d| make_net(d).map(|n| (d, n))) else {
            defmt::error!("init: drive already taken");
            loop {
                cortex_m::asm::bkpt();
            }
        };
        (
            Shared {
                drive,
                timer: CycleTimer::new(),
                pdi: OnChip::new(window),
                clock: Clock::new(CPU_HZ),
                cmd: [AxisCommand::OFF; 2],
                net,
            },
            Local {},
        )
    }

    /// The device this image is: the double-axis drive (SC6A062), or with
    /// the feature `single-axis` the single-axis drive (SI6A061: its own
    /// identity and SII, no axis-B objects or PDOs, axis B idle).
    const VARIANT: drive::Variant = if cfg!(feature = "single-axis") {
        drive::Variant::Single
    } else {
        drive::Variant::Double
    };

    /// The drive in its static, built in this function's own frame.
    #[inline(never)]
    #[allow(unsafe_code)]
    fn make_drive() -> Option<&'static mut Drive> {
        static mut DRIVE: core::mem::MaybeUninit<Drive> = core::mem::MaybeUninit::uninit();
        static TAKEN: core::sync::atomic::AtomicBool = core::sync::atomic::AtomicBool::new(false);
        if TAKEN.swap(true, core::sync::atomic::Ordering::AcqRel) {
            return None;
        }
        // SAFETY: the flag hands out the static once; `write` lets the drive
        // be built in place (no copy of ~30 KiB through this frame, which
        // `cortex_m::singleton!` makes).
        let slot = unsafe { &mut *core::ptr::addr_of_mut!(DRIVE) };
        let drive = slot.write(Drive::unstarted_for(VARIANT, ParamFlash::new(), None));
        drive.start();
        Some(drive)
    }

    /// The IP stack on `drive`'s EoE queue, in its statics (buffers, socket
    /// slots, the stack itself: built in place like the drive).
    #[cfg(feature = "net")]
    #[inline(never)]
    #[allow(unsafe_code)]
    fn make_net(drive: &mut Drive) -> Option<&'static mut Net> {
        static mut NET: core::mem::MaybeUninit<Net> = core::mem::MaybeUninit::uninit();
        static TAKEN: core::sync::atomic::AtomicBool = core::sync::atomic::AtomicBool::new(false);
        if TAKEN.swap(true, core::sync::atomic::Ordering::AcqRel) {
            return None;
        }
        let bufs = cortex_m::singleton!(: NetBuffers = NetBuffers::new())?;
        let slots = cortex_m::singleton!(: SocketSlots<'static> = EMPTY_SLOTS)?;
        // SAFETY: as for the drive's static.
        let slot = unsafe { &mut *core::ptr::addr_of_mut!(NET) };
        Some(slot.write(Net::new(drive, BOARD_NET, bufs, slots, nanos::Nanos::ZERO)))
    }

    /// No IP stack in this image.
    #[cfg(not(feature = "net"))]
    fn make_net(_drive: &mut Drive) -> Option<&'static mut Net> {
        cortex_m::singleton!(: Net = Net)
    }

    /// Background: a requested save (`tasks::background`), the image's
    /// confirmation point (`tasks::confirm_point`: the first Op; this image's
    /// drive has no firmware slots yet, docs/flashing.md), a restart A09
    /// requested (`Drive::restart_due`: a system reset), and firing the
    /// control cycle when its time has come (until the CCU4 compare does it
    /// in hardware).
    #[idle(shared = [drive, timer, clock, net])]
    fn idle(mut cx: idle::Context) -> ! {
        let mut confirmed = false;
        loop {
            tasks::background(&mut cx.shared.drive);
            if !confirmed {
                confirmed = cx.shared.drive.lock(|d| tasks::confirm_point(d));
            }
            let now = cx.shared.clock.lock(|c| c.now(DWT::cycle_count()));
            // A09 restart (E-019): the MCU resets, the boot loader decides anew
            if cx.shared.drive.lock(|d| d.restart_due(now)) {
                defmt::info!("restart requested (A09)");
                cortex_m::peripheral::SCB::sys_reset();
            }
            if cx.shared.timer.lock(|t| t.next_at()) <= now {
                rtic::pend(Interrupt::CCU40_0);
            }
            // the IP stack's own timers (DHCP, ARP, SNTP) without a frame
            if cx.shared.net.lock(|n| tasks::NetPoll::poll_at(&**n)) <= now {
                rtic::pend(Interrupt::CCU42_0);
            }
        }
    }

    /// SYNC0 from the ESC (via ERU1): acknowledge, PLL measurement.
    #[task(binds = ERU1_0, priority = 3, shared = [drive, timer, pdi, clock])]
    fn sync0(cx: sync0::Context) {
        (cx.shared.drive, cx.shared.timer, cx.shared.pdi, cx.shared.clock).lock(
            |drive, timer, pdi, clock| {
                let now = clock.now(DWT::cycle_count());
                if tasks::sync0(drive, timer, pdi, now).is_err() {
                    defmt::warn!("sync0: PDI access failed");
                }
            },
        );
    }

    /// The control-cycle timer: one cycle of both axes.
    #[task(binds = CCU40_0, priority = 3, shared = [drive, timer, clock, cmd])]
    fn control(cx: control::Context) {
        (cx.shared.drive, cx.shared.timer, cx.shared.clock, cx.shared.cmd).lock(
            |drive, timer, clock, cmd| {
                let now = clock.now(DWT::cycle_count());
                if timer.next_at() <= now {
                    *cmd = tasks::control(drive, timer, now, &[AxisIo::ready(0); 2]);
                    crate::power::set(cmd.iter().any(|c| c.power_stage));
                }
            },
        );
    }

    /// The ESC's PDI interrupt: ESM, process data; the mailbox below it.
    #[task(binds = ECAT0_0, priority = 2, shared = [drive, timer, pdi, clock])]
    fn esc(cx: esc::Context) {
        // a pended mailbox task runs once more after this one
        rtic::pend(Interrupt::CCU42_0);
        (cx.shared.drive, cx.shared.timer, cx.shared.pdi, cx.shared.clock).lock(
            |drive, timer, pdi, clock| {
                let now = clock.now(DWT::cycle_count());
                match tasks::esc_event(drive, timer, pdi, now) {
                    Ok(Some(c)) => {
                        defmt::info!("esc: AL state {=u8} (code {=u16:04X})", c.to.code(), c.code.0)
                    }
                    Ok(None) => {}
                    Err(_) => defmt::warn!("esc: PDI access failed"),
                }
            },
        );
    }

    /// The mailbox (CoE, EoE, FoE, EMCY, save) below the ESC task, and the
    /// IP stack behind EoE: the drive is locked for one request and the
    /// stack's poll. A hardware task on a spare interrupt, not an async
    /// software task: an `async fn` carries a "resumed after completion"
    /// panic path.
    #[task(binds = CCU42_0, priority = 1, shared = [drive, pdi, clock, net])]
    fn mailbox(cx: mailbox::Context) {
        (cx.shared.drive, cx.shared.pdi, cx.shared.clock, cx.shared.net).lock(|drive, pdi, clock, net| {
            let now = clock.now(DWT::cycle_count());
            if tasks::mailbox_net(drive, &mut **net, pdi, now).is_err() {
                defmt::warn!("mailbox: PDI access failed");
            }
        });
    }
}
