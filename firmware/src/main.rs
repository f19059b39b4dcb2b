//! Reference-board image: Infineon XMC4800 (Cortex-M4F, on-chip ESC), defmt
//! over RTT, flashed by `cargo run` through probe-rs (see docs/flashing.md).
//!
//! Task map (docs/architecture.md has the worst-case path of each):
//!
//! | task | interrupt | priority | body |
//! |---|---|---|---|
//! | `fast` | VADC0_G0_0 (the DC-link result, last of the conversions CCU80 triggers at the PWM centre: 16 kHz) | 4 | `firmware::xmc::fast::FastLoop::period`: both axes' current loops, PWM compare values, trips |
//! | `sync0` | ERU1_0 (ESC SYNC0 routed through ERU1) | 3 | `firmware_tasks::tasks::sync0` |
//! | `control` | CCU40_0 (control-cycle timer compare, CCU40 slice 3) | 3 | `firmware_tasks::tasks::control` on the fast task's measurements, its commands to the fast task; `firmware_tasks::tasks::scope` (one sample when armed) |
//! | `esc` | ECAT0_0 (ESC PDI interrupt: AL events, SM2/SM3, mailbox) | 2 | `firmware_tasks::tasks::esc_event` |
//! | `mailbox` | CCU42_0 (a spare interrupt, pended by `esc` and by `idle` when the IP stack's timers are due) | 1 | `firmware_tasks::tasks::mailbox_scoped` and the IP stack over EoE (`mailbox_net`'s steps; group T through the scope) |
//! | `idle` | — | 0 | `firmware_tasks::tasks::background` (a requested save) |
//!
//! The ESC is reached through `pdi::mmio::OnChip` over ECAT0's register
//! window; the clock is the DWT cycle counter at the CPU clock.
//!
//! The power stage's peripherals (`firmware::xmc::motor`, crate `xmc-motor`)
//! are programmed in `init`: CCU8 PWM (gate enable low, and with the
//! feature `power-pins` the PWM pins low, until the fast task runs an axis
//! commanded on), the VADC on the PWM centre, the POSIF encoders, the CCU4
//! control-cycle timer whose compare fires `control`, and ERU1's route of
//! SYNC0 to `sync0`. The fast task (`firmware::xmc::fast`) runs both axes'
//! current loops (crate `foc`) on every PWM period; the control cycle hands
//! it the iq references and takes the positions, the measured iq and the
//! trips (`fast::Link`). What stays unverified without a board, and the
//! bring-up order, is in docs/hardware.md.
#![no_std]
#![no_main]

use cortex_m_rt as _; // the reset handler and vector table; the PAC does not pull it in
use defmt_rtt as _;

/// Ed25519 through the boot loader's table (`boot::BootApi`): the FoE path's
/// signature check (`BootSlots::finish_verified`) without a second copy of
/// the verifier in this image.
#[path = "bootapi.rs"]
mod bootapi;

/// The board's panic stop (`firmware::xmc::panic_stop`): interrupts
/// masked, power stage off, reported over RTT, core stopped.
#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    firmware::xmc::panic_stop()
}

/// The XMC4800 PAC as RTIC expects a device crate (`firmware::xmc::pac`).
use firmware::xmc::pac;

/// The power stage's gate-driver enable (P5.9), shared with `firmware-pn`.
use firmware::xmc::power;

/// CPU clock after the boot ROM's PLL setup, Hz (DWT CYCCNT counts it).
const CPU_HZ: u32 = 144_000_000;

#[rtic::app(device = crate::pac)]
mod app {
    use crate::pac::Interrupt;
    use crate::CPU_HZ;
    use cortex_m::peripheral::DWT;
    use drive_ecat::axis::AxisCommand;
    use drive_ecat::stage::set_dc_link_voltage;
    use firmware::clock::Clock;
    use firmware::cycle::CycleTimer;
    #[cfg(not(feature = "net"))]
    use firmware::net::NoNet as Net;
    #[cfg(feature = "net")]
    use firmware::net::NodeNet as Net;
    use firmware::once::Once;
    use firmware::xmc::fast::{guard, hand_over, stage_if_moved, FastLoop, Link};
    use firmware::xmc::motor::{self, ControlTimer};
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
        /// The CCU4 compare that fires `control` at `timer.next_at()`.
        ctimer: ControlTimer,
        /// Between `control` and `fast`: the commands in, the measurements out.
        seam: [Link; 2],
        /// The scope (group T): sampled by `control`, configured and read
        /// out by `mailbox`; its buffer is 64 KiB of DSRAM2.
        scope: tasks::Scope,
    }

    #[local]
    struct Local {
        /// PWM, ADC and encoders of both axes and their current loops.
        fast: FastLoop,
    }

    #[init]
    fn init(cx: init::Context) -> (Shared, Local) {
        let mut core = cx.core;
        core.DCB.enable_trace();
        core.DWT.enable_cycle_counter();
        crate::power::init();
        let (motor, mut ctimer) = motor::init();
        motor::route_sync0();
        let Some(fast) = FastLoop::new(motor) else {
            defmt::error!("init: current-loop parameters refused");
            loop {
                cortex_m::asm::bkpt();
            }
        };
        let seam = [Link::new(fast.kt()); 2];
        let Some(words) = firmware::xmc::scope_buffer() else {
            defmt::error!("init: scope buffer already taken");
            loop {
                cortex_m::asm::bkpt();
            }
        };
        defmt::info!("init: firmware (XMC4800), SYNC0 on ERU1_0, ESC on ECAT0_0, control on CCU40_0");
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
        let timer = CycleTimer::new();
        let mut clock = Clock::new(CPU_HZ);
        ctimer.arm(timer.next_at(), clock.now(DWT::cycle_count()));
        (
            Shared {
                drive,
                timer,
                pdi: OnChip::new(window),
                clock,
                cmd: [AxisCommand::OFF; 2],
                net,
                ctimer,
                seam,
                scope: tasks::Scope::new(words),
            },
            Local { fast },
        )
    }

    /// The device this image is: the double-axis drive (SC6A062), or with
    /// the feature `single-axis` the single-axis drive (SI6A061: its own
    /// identity and SII, no axis-B objects or PDOs, axis B idle).
    const VARIANT: drive_ecat::Variant = if cfg!(feature = "single-axis") {
        drive_ecat::Variant::Single
    } else {
        drive_ecat::Variant::Double
    };

    /// The drive in its static, built in this function's own frame.
    #[inline(never)]
    fn make_drive() -> Option<&'static mut Drive> {
        static DRIVE: Once<Drive> = Once::new();
        let drive = DRIVE
            .take()?
            .write(Drive::unstarted_for(VARIANT, ParamFlash::new(), None));
        drive.start();
        Some(drive)
    }

    /// The IP stack on `drive`'s EoE queue, in its statics.
    #[cfg(feature = "net")]
    fn make_net(drive: &mut Drive) -> Option<&'static mut Net> {
        firmware::make_net(drive)
    }

    /// No IP stack in this image.
    #[cfg(not(feature = "net"))]
    fn make_net(_drive: &mut Drive) -> Option<&'static mut Net> {
        cortex_m::singleton!(: Net = Net)
    }

    /// Background: a requested save (`tasks::background`), the image's
    /// confirmation point (`tasks::confirm_point`: the first Op; this image's
    /// drive has no firmware slots yet, docs/flashing.md), a restart A09
    /// requested (`Drive::restart_due`: a system reset), and pending the
    /// mailbox task when the IP stack's timers are due. The control cycle
    /// is the CCU4 compare's (`control`).
    #[idle(shared = [drive, clock, net])]
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
            // the IP stack's own timers (DHCP, ARP, SNTP) without a frame
            if cx.shared.net.lock(|n| tasks::NetPoll::poll_at(&**n)) <= now {
                rtic::pend(Interrupt::CCU42_0);
            }
        }
    }

    /// SYNC0 from the ESC (via ERU1): acknowledge, PLL measurement.
    /// The PLL may move the next cycle start: the compare follows.
    #[task(binds = ERU1_0, priority = 3, shared = [drive, timer, pdi, clock, ctimer])]
    fn sync0(cx: sync0::Context) {
        (
            cx.shared.drive,
            cx.shared.timer,
            cx.shared.pdi,
            cx.shared.clock,
            cx.shared.ctimer,
        )
            .lock(|drive, timer, pdi, clock, ctimer| {
                let now = clock.now(DWT::cycle_count());
                if tasks::sync0(drive, timer, pdi, now).is_err() {
                    defmt::warn!("sync0: PDI access failed");
                }
                ctimer.arm(timer.next_at(), clock.now(DWT::cycle_count()));
            });
    }

    /// The current loops of both axes, once per PWM period: the VADC's
    /// DC-link result (the last conversion of the PWM centre's trigger).
    /// Above every other task: nothing delays it but `control`'s short
    /// locks of `seam`.
    #[task(binds = VADC0_G0_0, priority = 4, shared = [seam], local = [fast])]
    fn fast(mut cx: fast::Context) {
        let fast = cx.local.fast;
        cx.shared.seam.lock(|seam| fast.period(seam));
    }

    /// The control-cycle timer's compare (CCU40 slice 3): one cycle of both
    /// axes when its time has come (a compare short of a far start only
    /// arms again) on the fast task's positions and measured currents, its
    /// commands handed to the fast task, the next compare armed.
    #[task(binds = CCU40_0, priority = 3, shared = [drive, timer, clock, cmd, ctimer, seam, scope], local = [stage_gen: u32 = u32::MAX])]
    fn control(cx: control::Context) {
        let stage_gen = cx.local.stage_gen;
        // `seam` under its own short locks: the fast task waits for a copy,
        // never for the control cycle
        let mut seam = cx.shared.seam;
        (
            cx.shared.drive,
            cx.shared.timer,
            cx.shared.clock,
            cx.shared.cmd,
            cx.shared.ctimer,
            cx.shared.scope,
        )
            .lock(|drive, timer, clock, cmd, ctimer, scope| {
                let now = clock.now(DWT::cycle_count());
                if timer.next_at() <= now {
                    let io = seam.lock(|l| l.each_mut().map(|l| l.io()));
                    guard(&io);
                    *cmd = tasks::control(drive, timer, now, &io);
                    tasks::scope(drive, scope, &io);
                    let stage = stage_if_moved(drive.objects(), stage_gen);
                    let mv = seam.lock(|l| hand_over(l, cmd, drive.axes(), stage.as_ref()));
                    set_dc_link_voltage(drive.objects_mut(), mv);
                }
                ctimer.arm(timer.next_at(), clock.now(DWT::cycle_count()));
            });
    }

    /// The ESC's PDI interrupt: ESM, process data; the mailbox below it.
    /// The ESC task may move the next cycle start (PLL lost or found): the
    /// compare follows.
    #[task(binds = ECAT0_0, priority = 2, shared = [drive, timer, pdi, clock, ctimer])]
    fn esc(cx: esc::Context) {
        // a pended mailbox task runs once more after this one
        rtic::pend(Interrupt::CCU42_0);
        (
            cx.shared.drive,
            cx.shared.timer,
            cx.shared.pdi,
            cx.shared.clock,
            cx.shared.ctimer,
        )
            .lock(|drive, timer, pdi, clock, ctimer| {
                let now = clock.now(DWT::cycle_count());
                let next = timer.next_at();
                match tasks::esc_event(drive, timer, pdi, now) {
                    Ok(Some(c)) => {
                        defmt::info!("esc: AL state {=u8} (code {=u16:04X})", c.to.code(), c.code.0)
                    }
                    Ok(None) => {}
                    Err(_) => defmt::warn!("esc: PDI access failed"),
                }
                if timer.next_at() != next {
                    ctimer.arm(timer.next_at(), clock.now(DWT::cycle_count()));
                }
            });
    }

    /// The mailbox (CoE, EoE, FoE, EMCY, save) below the ESC task, and the
    /// IP stack behind EoE: `tasks::mailbox_net`'s steps (the request, the
    /// stack's poll, the answer's first fragment), each under the drive's
    /// lock for itself only, so the control cycle and the ESC task wait for
    /// one step at most, not the whole run (docs/architecture.md, CPU load).
    /// A hardware task on a spare interrupt, not an async software task: an
    /// `async fn` carries a "resumed after completion" panic path.
    #[task(binds = CCU42_0, priority = 1, shared = [drive, pdi, clock, net, scope])]
    fn mailbox(mut cx: mailbox::Context) {
        let now = { &mut cx.shared.clock }.lock(|clock| clock.now(DWT::cycle_count()));
        let request = |cx: &mut mailbox::Context| {
            (&mut cx.shared.drive, &mut cx.shared.pdi, &mut cx.shared.scope)
                .lock(|drive, pdi, scope| tasks::mailbox_scoped(drive, scope, pdi, now))
        };
        let mut ok = request(&mut cx).is_ok();
        if <Net as tasks::NetPoll>::ACTIVE {
            (&mut cx.shared.drive, &mut cx.shared.net)
                .lock(|drive, net| tasks::NetPoll::poll(&mut **net, drive, now));
            ok &= request(&mut cx).is_ok();
        }
        if !ok {
            defmt::warn!("mailbox: PDI access failed");
        }
        // the drive reports a verified FoE download once (issue 33 point 7)
        let stored = { &mut cx.shared.drive }.lock(|drive| drive.take_firmware_stored());
        if let Some(s) = stored {
            let slot = if s.slot.index() == 0 { "A" } else { "B" };
            defmt::info!(
                "foe: image version {=u32} verified and stored in slot {=str}; it starts at the next power-on",
                s.version,
                slot
            );
        }
    }
}
