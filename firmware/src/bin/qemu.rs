//! QEMU image (`qemu-system-arm -machine netduinoplus2`, STM32F405, Cortex-M4F):
//! the whole drive end to end.
//!
//! The firmware's tasks are the reference board's (see `firmware::tasks` and
//! docs/architecture.md); the bus and the motors are `hil-sim`'s, run by the
//! idle loop ([`firmware::world`]): it advances simulated time to the next
//! event, pends the interrupt of the task that handles it, and the task runs
//! at its RTIC priority as it would on the board:
//!
//! | interrupt | task | priority |
//! |---|---|---|
//! | EXTI0 | `sync0` (SYNC0) | 3 |
//! | EXTI1 | `control` (control-cycle timer) | 3 |
//! | EXTI2 | `esc` (ESC PDI interrupt) | 2 |
//! | USART1 | `mailbox` (pended by `esc`) | 1 |
//!
//! The scripted master goes INIT → OP (in Pre-Op it sets the drive's IP over
//! EoE, resolves it by ARP, pings it and reads A150 over the UDP parameter
//! service: the mailbox task runs the IP stack, `firmware_tasks::tasks::mailbox_net`),
//! enables both axes, moves them in csp and disables them. The log goes out over semihosting; `scripts/cross qemu`
//! compares it with `firmware/qemu/expected/firmware-qemu.log` (lines with
//! `figure:` are measurements, printed but not compared). Measured under
//! `-icount shift=0` (one instruction per virtual ns): SysTick counts the
//! CPU clock, calibrated at boot against a loop of known length.
#![no_std]
#![no_main]

use cortex_m_rt as _;
use defmt_semihosting as _;

/// Any panic switches both power stages off (the world's motors get no
/// torque again: QEMU exits) and reports.
#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    firmware::semihost::panic_exit(info)
}

/// Measurement helpers: SysTick (`firmware::systick`, shared with the other
/// QEMU images) and stack painting, the only `unsafe` code of the image.
mod measure {
    pub use firmware::systick::{now, ticks};

    extern "C" {
        /// The end of the statics in SRAM (cortex-m-rt: after `.uninit`). Not
        /// `_stack_end`: qemu/memory.x inserts `.ccmram` after `.uninit`, so the
        /// location counter cortex-m-rt takes `_stack_end` from is in the CCM
        /// RAM (0x1000_0000), and a window bounded by it reached into the
        /// statics once they grew (the scope's buffer: the ESC pointer painted).
        static __euninit: u32;
    }

    const PAINT: u32 = 0x5A5A_A5A5;
    /// Bytes below the current stack pointer that are painted and scanned.
    const WINDOW: usize = 32 * 1024;

    fn window() -> (usize, usize) {
        // only the address of the linker symbol is taken
        let end = core::ptr::addr_of!(__euninit) as usize;
        let sp = cortex_m::register::msp::read() as usize;
        let top = sp.saturating_sub(64) & !3;
        (top.saturating_sub(WINDOW).max(end), top)
    }

    /// Paints the free stack below the caller's frame.
    #[allow(unsafe_code)]
    pub fn paint() {
        let (lo, hi) = window();
        let mut p = lo;
        while p < hi {
            // SAFETY: [lo, hi) is free stack below the current frame and above
            // the end of .bss/.uninit; nothing runs concurrently (interrupts
            // are only pended by the caller afterwards).
            unsafe { core::ptr::write_volatile(p as *mut u32, PAINT) };
            p += 4;
        }
    }

    /// Bytes of the painted window used since [`paint`] (deepest write).
    #[allow(unsafe_code)]
    pub fn used() -> u32 {
        let (lo, hi) = window();
        let mut p = lo;
        // SAFETY: reads of the same free stack window as `paint`.
        while p < hi && unsafe { core::ptr::read_volatile(p as *const u32) } == PAINT {
            p += 4;
        }
        (hi - p) as u32
    }
}

/// The simulated ESC's PDI with the SysTick ticks spent inside it (the
/// register model, which on the board is the ESC chip itself) added to
/// `ticks`, so the ESC task's own part can be printed apart.
pub struct TimedPdi<'a, P> {
    inner: P,
    ticks: &'a mut u32,
}

impl<P: esc::pdi::Pdi> esc::pdi::Pdi for TimedPdi<'_, P> {
    type Error = P::Error;
    fn read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Self::Error> {
        let t0 = measure::now();
        let r = self.inner.read(addr, buf);
        *self.ticks = self.ticks.wrapping_add(measure::ticks(t0, measure::now()));
        r
    }
    fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), Self::Error> {
        let t0 = measure::now();
        let r = self.inner.write(addr, data);
        *self.ticks = self.ticks.wrapping_add(measure::ticks(t0, measure::now()));
        r
    }
}

/// Running figures of one task.
#[derive(Default, Clone, Copy)]
pub struct Figure {
    n: u32,
    sum: u64,
    max: u32,
}

impl Figure {
    fn add(&mut self, v: u32) {
        self.n += 1;
        self.sum += u64::from(v);
        self.max = self.max.max(v);
    }
    fn mean(&self) -> u32 {
        (self.sum / u64::from(self.n.max(1))) as u32
    }
}

#[rtic::app(device = stm32f4::stm32f405)]
mod app {
    use super::{measure, Figure};
    use drive_ecat::axis::{AxisCommand, AxisIo};
    use firmware::cycle::{CycleTimer, CYCLE};
    use firmware::net::NodeNet;
    use firmware::once::Once;
    use firmware::world::{new_esc, Event, World};
    use firmware::{tasks, Drive, ParamFlash};
    use hil_sim::esc::Esc;
    use hil_sim::script::Progress;
    use nanos::Nanos;
    use stm32f4::stm32f405::Interrupt;

    #[shared]
    struct Shared {
        /// The drive (a `'static` singleton: built once, never moved through the stack).
        drive: &'static mut Drive,
        timer: CycleTimer,
        /// The simulated ESC (on the board: the chip behind the PDI).
        esc: &'static mut Esc,
        /// The firmware's clock: the world's simulated time.
        clock: Nanos,
        /// Hardware inputs of the next control cycle / its power-stage commands.
        io: [AxisIo; 2],
        cmd: [AxisCommand; 2],
        /// SysTick ticks of the last run of `control`, `esc` and `mailbox`,
        /// and of the mailbox run's longest hold of the drive's lock
        /// without the simulated ESC's register model.
        cost: [u32; 4],
        /// SysTick ticks of the last `mailbox` run spent in the simulated ESC.
        mailbox_model: u32,
        /// SysTick ticks of the last `esc` run spent in the simulated ESC.
        esc_model: u32,
        /// The IP stack on the EoE interface, polled by `mailbox`.
        net: &'static mut NodeNet,
        /// The scope (group T, issue 35) over [`SCOPE_WORDS`] words, armed
        /// by the world for the move, sampled after each control cycle.
        scope: tasks::Scope,
        /// SysTick ticks of the last scope sample, and whether the recorder
        /// was recording (armed or triggered) when it was taken.
        scope_cost: (u32, bool),
    }

    /// Words of this image's scope buffer (the board's is 64 KiB of DSRAM2;
    /// the cost per sample does not depend on it): 128 samples of 8 channels.
    const SCOPE_WORDS: usize = 1024;

    #[local]
    struct Local {
        world: &'static mut World,
        per_kilo_tick: u32,
    }

    #[init]
    fn init(cx: init::Context) -> (Shared, Local) {
        let mut syst = cx.core.SYST;
        let per_kilo_tick = firmware::systick::start(&mut syst);
        defmt::info!("init: firmware-qemu (STM32F405): drive + simulated ESC, motors and master");
        // the large resources go straight to their statics: built by value in
        // `init`'s frame they would need several copies of ~50 KiB of stack
        let (Some(drive), Some(esc), Some(world)) = (make_drive(), make_esc(), make_world()) else {
            defmt::error!("init: resources already taken");
            firmware::semihost::exit(false)
        };
        let (Some(net), Some(words)) = (firmware::make_net(drive), make_scope_buffer()) else {
            defmt::error!("init: resources already taken");
            firmware::semihost::exit(false)
        };
        (
            Shared {
                drive,
                timer: CycleTimer::new(),
                esc,
                clock: Nanos::ZERO,
                io: [AxisIo::ready(0); 2],
                cmd: [AxisCommand::OFF; 2],
                cost: [0; 4],
                esc_model: 0,
                mailbox_model: 0,
                net,
                scope: tasks::Scope::new(words),
                scope_cost: (0, false),
            },
            Local { world, per_kilo_tick },
        )
    }

    // One function per singleton, never inlined: each builds its value in
    // its own frame, which is gone before the next one is built.
    #[inline(never)]
    fn make_drive() -> Option<&'static mut Drive> {
        static DRIVE: Once<Drive> = Once::new();
        let drive = DRIVE.take()?.write(Drive::unstarted(ParamFlash::new(), None));
        drive.start();
        Some(drive)
    }

    #[inline(never)]
    fn make_esc() -> Option<&'static mut Esc> {
        cortex_m::singleton!(: Esc = new_esc())
    }

    #[inline(never)]
    fn make_world() -> Option<&'static mut World> {
        cortex_m::singleton!(: World = World::with_eoe())
    }

    #[inline(never)]
    fn make_scope_buffer() -> Option<&'static mut [u32]> {
        static WORDS: Once<[u32; SCOPE_WORDS]> = Once::new();
        Some(WORDS.take()?.write([0; SCOPE_WORDS]))
    }

    /// The trace the world arms when the move starts: 8 channels, 4 objects
    /// of axis A (position actual value 6064h, following error actual value
    /// 60F4h, torque actual value 6077h, statusword 6041h) and 4 internal
    /// signals (axis A's speed set-point, speed actual value and iq, axis B's
    /// following error), every control cycle, at once, single.
    fn scope_config() -> drive_ecat::scope::Config {
        use drive_ecat::scope::{Config, Signal};
        let entry = |index: u32, bits: u32| index << 16 | bits;
        Config {
            channels: [
                entry(0x6064, 32),
                entry(0x60F4, 32),
                entry(0x6077, 16),
                entry(0x6041, 16),
                Signal::SpeedSetpoint.code(0),
                Signal::SpeedActual.code(0),
                Signal::Iq.code(0),
                Signal::FollowingError.code(1),
            ],
            count: 8,
            ..Config::default()
        }
    }

    /// Pends `irq` and lets it run (QEMU takes a pended interrupt only
    /// after a barrier).
    fn run(irq: Interrupt) {
        rtic::pend(irq);
        cortex_m::asm::dsb();
        cortex_m::asm::isb();
    }

    /// The simulated world: advances time event by event and pends the task
    /// of each event; logs the master's progress and the figures.
    #[idle(shared = [drive, timer, esc, clock, io, cmd, cost, esc_model, mailbox_model, scope, scope_cost], local = [world, per_kilo_tick])]
    fn idle(mut cx: idle::Context) -> ! {
        let world = &mut **cx.local.world;
        let insn = |ticks: u32| (u64::from(ticks) * u64::from(*cx.local.per_kilo_tick) / 1000) as u32;
        let (mut control, mut esc_cost) = (Figure::default(), Figure::default());
        let (mut mailbox_cost, mut mailbox_own, mut mailbox_hold) =
            (Figure::default(), Figure::default(), Figure::default());
        let mut esc_own = Figure::default();
        let (mut scope_armed, mut scope_idle) = (Figure::default(), Figure::default());
        let mut stack = [0u32; 3];
        let mut moving = false;
        let mut events: u32 = 0;
        let ok = loop {
            if let Some(ok) = world.finished() {
                break ok;
            }
            events = events.wrapping_add(1);
            if events > 200_000 {
                break false;
            }
            let sync0 = cx.shared.esc.lock(|e| e.next_sync0_at());
            let next_cycle = cx.shared.timer.lock(|t| t.next_at());
            let event = world.next(sync0, next_cycle);
            let now = world.now();
            cx.shared.clock.lock(|c| *c = now);
            match event {
                Event::Sync0 => {
                    let _ = cx.shared.esc.lock(|e| e.take_sync0_events(now));
                    measure::paint();
                    run(Interrupt::EXTI0);
                    stack[0] = stack[0].max(measure::used());
                }
                Event::Control => {
                    let io = world.io();
                    cx.shared.io.lock(|i| *i = io);
                    measure::paint();
                    run(Interrupt::EXTI1);
                    stack[1] = stack[1].max(measure::used());
                    let cmd = cx.shared.cmd.lock(|c| *c);
                    world.actuate(&cmd, CYCLE);
                    if moving {
                        control.add(insn(cx.shared.cost.lock(|c| c[0])));
                    }
                    match cx.shared.scope_cost.lock(|c| *c) {
                        (t, true) => scope_armed.add(insn(t)),
                        (t, false) => scope_idle.add(insn(t)),
                    }
                }
                Event::Frame => {
                    let progress = cx.shared.esc.lock(|e| world.frame(e));
                    measure::paint();
                    cx.shared.cost.lock(|c| c[2] = 0);
                    run(Interrupt::EXTI2);
                    stack[2] = stack[2].max(measure::used());
                    let mbx = cx.shared.cost.lock(|c| c[2]);
                    if mbx != 0 && !moving {
                        mailbox_cost.add(insn(mbx));
                        let model = cx.shared.mailbox_model.lock(|m| *m);
                        mailbox_own.add(insn(mbx.saturating_sub(model)));
                        mailbox_hold.add(insn(cx.shared.cost.lock(|c| c[3])));
                    }
                    tasks::background(&mut cx.shared.drive);
                    if moving {
                        let total = cx.shared.cost.lock(|c| c[1]);
                        esc_cost.add(insn(total));
                        let model = cx.shared.esc_model.lock(|m| *m);
                        esc_own.add(insn(total.saturating_sub(model)));
                    }
                    match progress {
                        Progress::Busy => {}
                        Progress::State(s) => defmt::info!("master: drive in AL state {=u8}", s),
                        Progress::Sdo { index, sub } => {
                            defmt::info!("master: SDO download {=u16:04X}:{=u8} confirmed", index, sub)
                        }
                        Progress::Sync0(ns) => defmt::info!("master: SYNC0 every {=u32} ns", ns),
                        Progress::Enabled => {
                            moving = true;
                            // armed as a master's SDO write arms it: the
                            // channels prepared in that (mailbox) context
                            let armed = (&mut cx.shared.drive, &mut cx.shared.scope).lock(|d, s| {
                                let armed = s.configure(scope_config()).and_then(|()| s.arm()).is_ok();
                                s.prepare(d.objects());
                                armed
                            });
                            if !armed {
                                defmt::error!("scope: configuration refused");
                            }
                            defmt::info!("master: both axes Operation enabled (csp), moving")
                        }
                        Progress::Moved {
                            position,
                            max_following_error,
                        } => {
                            moving = false;
                            // the move is 2^20 increments: report arrival to 1/64 revolution
                            let ok = (position[0] - (1 << 20)).abs() < (1 << 14)
                                && (position[1] + (1 << 20)).abs() < (1 << 14);
                            defmt::info!("master: move done, both axes at target: {=bool}", ok);
                            defmt::info!(
                                "figure: position A {=i32} B {=i32}, max following error A {=i32} B {=i32} inc",
                                position[0],
                                position[1],
                                max_following_error[0],
                                max_following_error[1]
                            );
                        }
                        Progress::Disabled => defmt::info!("master: both axes Switched on (disabled)"),
                        Progress::IpSet => defmt::info!("master: EoE IP parameters set (192.168.10.2/24)"),
                        Progress::Arp(m) => defmt::info!(
                            "master: EoE ARP reply from {=u8:02X}:{=u8:02X}:{=u8:02X}:{=u8:02X}:{=u8:02X}:{=u8:02X}",
                            m[0],
                            m[1],
                            m[2],
                            m[3],
                            m[4],
                            m[5]
                        ),
                        Progress::Pinged => defmt::info!("master: EoE ping answered"),
                        Progress::UdpRead(v) => defmt::info!("master: EoE UDP parameter read R A150 = {=i32}", v),
                        Progress::Failed(f) => defmt::error!("master: failed: {}", defmt::Debug2Format(&f)),
                    }
                }
            }
        };
        defmt::info!(
            "figure: control cycle (2 axes, csp, PDO copy): mean {=u32} max {=u32} instructions over {=u32} cycles",
            control.mean(),
            control.max,
            control.n
        );
        defmt::info!(
            "figure: ESC event task in Op: mean {=u32} max {=u32} instructions",
            esc_cost.mean(),
            esc_cost.max
        );
        defmt::info!(
            "figure: ESC event task in Op without the simulated ESC's register model (the task's own part): mean {=u32} max {=u32} instructions",
            esc_own.mean(),
            esc_own.max
        );
        defmt::info!(
            "figure: mailbox task with the IP stack, outside the move: mean {=u32} max {=u32} instructions over {=u32} runs",
            mailbox_cost.mean(),
            mailbox_cost.max,
            mailbox_cost.n
        );
        defmt::info!(
            "figure: mailbox task with the IP stack without the simulated ESC's register model (the task's own part): mean {=u32} max {=u32} instructions",
            mailbox_own.mean(),
            mailbox_own.max
        );
        defmt::info!(
            "figure: mailbox task's longest hold of the drive's lock (the request, the IP stack's poll or the answer's first fragment; own part): mean {=u32} max {=u32} instructions",
            mailbox_hold.mean(),
            mailbox_hold.max
        );
        defmt::info!(
            "figure: stack use sync0 {=u32} control {=u32} esc {=u32} bytes (measured, incl. exception frame)",
            stack[0],
            stack[1],
            stack[2]
        );
        defmt::info!(
            "figure: scope sample (8 channels: 4 objects, 4 signals) while recording: mean {=u32} max {=u32} instructions over {=u32} samples",
            scope_armed.mean(),
            scope_armed.max,
            scope_armed.n
        );
        defmt::info!(
            "figure: scope sample while idle or complete: mean {=u32} max {=u32} instructions over {=u32} cycles",
            scope_idle.mean(),
            scope_idle.max,
            scope_idle.n
        );
        defmt::info!("figure: control cycles run {=u32}", world.cycles);
        if ok {
            defmt::info!("done: end-to-end sequence complete, exit 0");
        } else {
            defmt::error!("done: end-to-end sequence failed");
        }
        firmware::semihost::exit(ok)
    }

    /// SYNC0 (ESC SYNC0 output): acknowledge, PLL measurement.
    #[task(binds = EXTI0, priority = 3, shared = [drive, timer, esc, clock])]
    fn sync0(cx: sync0::Context) {
        let now = { cx.shared.clock }.lock(|c| *c);
        (cx.shared.drive, cx.shared.timer, cx.shared.esc).lock(|drive, timer, esc| {
            let _ = tasks::sync0(drive, timer, &mut esc.pdi(), now);
        });
    }

    /// The control-cycle timer: one cycle of both axes.
    /// Then the scope's sample (its cost measured on its own, less the
    /// measurement's: the control figure stays the cycle's).
    #[task(binds = EXTI1, priority = 3, shared = [drive, timer, clock, io, cmd, cost, scope, scope_cost])]
    fn control(cx: control::Context) {
        use drive_ecat::scope::State;
        let now = { cx.shared.clock }.lock(|c| *c);
        let t0 = measure::now();
        let (cmd, sample) = (cx.shared.drive, cx.shared.timer, cx.shared.io, cx.shared.scope).lock(
            |drive, timer, io, scope| {
                let cmd = tasks::control(drive, timer, now, io);
                let recording = matches!(scope.state(), State::Armed | State::Triggered);
                let s0 = measure::now();
                let s1 = measure::now();
                tasks::scope(drive, scope, io);
                let s2 = measure::now();
                let t = measure::ticks(s1, s2).saturating_sub(measure::ticks(s0, s1));
                (cmd, (t, recording, measure::ticks(s0, s2)))
            },
        );
        let t = measure::ticks(t0, measure::now()).saturating_sub(sample.2);
        { cx.shared.cost }.lock(|c| c[0] = t);
        { cx.shared.scope_cost }.lock(|c| *c = (sample.0, sample.1));
        { cx.shared.cmd }.lock(|c| *c = cmd);
    }

    /// The ESC's PDI interrupt: the slave stack (ESM, mailbox, process data).
    #[task(binds = EXTI2, priority = 2, shared = [drive, timer, esc, clock, cost, esc_model])]
    fn esc(cx: esc::Context) {
        // a pended mailbox task runs once more after this one
        rtic::pend(Interrupt::USART1);
        let now = { cx.shared.clock }.lock(|c| *c);
        let mut model = 0u32;
        let t0 = measure::now();
        let change = (cx.shared.drive, cx.shared.timer, cx.shared.esc).lock(|drive, timer, esc| {
            let mut pdi = super::TimedPdi {
                inner: esc.pdi(),
                ticks: &mut model,
            };
            tasks::esc_event(drive, timer, &mut pdi, now)
        });
        let t = measure::ticks(t0, measure::now());
        { cx.shared.cost }.lock(|c| c[1] = t);
        { cx.shared.esc_model }.lock(|m| *m = model);
        if let Ok(Some(c)) = change {
            defmt::info!(
                "esc: AL state {=u8} (status code {=u16:04X})",
                c.to.code(),
                c.code.0
            );
        }
    }

    /// The mailbox (CoE, EoE, FoE, EMCY, save) below the ESC task, and the
    /// IP stack behind EoE: `tasks::mailbox_net`'s three steps (the request,
    /// the stack's poll, the answer's first fragment), each under the drive's
    /// lock for itself only, as on the board (`firmware/src/main.rs`).
    #[task(binds = USART1, priority = 1, shared = [drive, esc, clock, net, cost, mailbox_model])]
    fn mailbox(mut cx: mailbox::Context) {
        let now = { &mut cx.shared.clock }.lock(|c| *c);
        let (mut model, mut hold) = (0u32, 0u32);
        let t0 = measure::now();
        for step in 0..3 {
            let before = model;
            let s0 = measure::now();
            if step == 1 {
                (&mut cx.shared.drive, &mut cx.shared.net)
                    .lock(|drive, net| tasks::NetPoll::poll(&mut **net, drive, now));
            } else {
                (&mut cx.shared.drive, &mut cx.shared.esc).lock(|drive, esc| {
                    let mut pdi = super::TimedPdi {
                        inner: esc.pdi(),
                        ticks: &mut model,
                    };
                    let _ = tasks::mailbox(drive, &mut pdi, now);
                });
            }
            let own = measure::ticks(s0, measure::now()).saturating_sub(model.wrapping_sub(before));
            hold = hold.max(own);
        }
        let t = measure::ticks(t0, measure::now());
        { &mut cx.shared.cost }.lock(|c| {
            c[2] = t.max(1);
            c[3] = hold;
        });
        { &mut cx.shared.mailbox_model }.lock(|m| *m = model);
    }
}
