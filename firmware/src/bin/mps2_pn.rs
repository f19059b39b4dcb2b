//! The PROFINET personality in QEMU on a machine with a NIC:
//! `qemu-system-arm -machine mps2-an386` (Arm MPS2 with the AN386 FPGA
//! image: Cortex-M4F, the reference board's core), [`drive_pn::PnDrive`]
//! as the board image `firmware-pn` runs it, on the board's LAN9118
//! Ethernet controller (`lan9118`), which QEMU connects to a tap
//! interface. An independent PROFINET controller (profinet-py,
//! `scripts/cross qemu-net`) names, connects and exchanges cyclic data with
//! this binary over that tap. Not a product image: the MPS2 stands in for
//! the reference board because QEMU models its MAC (the LM3S6965 of
//! `lm3s6965evb`, the other QEMU machine with a NIC, has 64 KiB of RAM: the
//! drive's 35 KiB and the 27 KiB of stack its construction takes do not fit).
//!
//! | task | interrupt | priority | body |
//! |---|---|---|---|
//! | `tick` | SysTick (every [`TICK_NS`]) | 4 | counts the time base |
//! | `control` | IRQ 30 (no device; pended by `idle`) | 3 | `PnDrive::control_cycle` |
//! | `eth` | IRQ 13, the LAN9118 (frame received; pended by `idle` when the device's timers are due) | 2 | `PnDrive::receive` per frame, then `PnDrive::poll` |
//! | `idle` | — | 0 | fires `control` and `eth` when their time has come, then sleeps (WFI) |
//!
//! Time is SysTick on the core clock ([`SYSCLK_HZ`], the MPS2's 25 MHz),
//! its wraps counted by `tick`, the count within a wrap read from the
//! counter. Run without `-icount` QEMU's virtual clock follows the host's,
//! so the device's cycle (the input frame every 1 ms) is roughly real time.
//! The parameter store is `drive_pn::PnParamFlash` (RAM): a name and IP set
//! permanently by DCP last until QEMU exits. Logging: defmt over
//! semihosting.
#![no_std]
#![no_main]

use core::sync::atomic::{AtomicU32, Ordering};
use cortex_m_rt as _; // the reset handler and vector table
use defmt_semihosting as _;

#[path = "../lan9118.rs"]
mod lan9118;

/// The MPS2-AN386's interrupts as RTIC expects a device crate (there is
/// none for this board): the two this image binds.
mod mps2 {
    /// External interrupts used (named as the vector table's handlers).
    #[allow(clippy::upper_case_acronyms)]
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    #[repr(u16)]
    pub enum Interrupt {
        /// The LAN9118 Ethernet controller.
        ETHERNET = 13,
        /// No device on it in QEMU: the control task.
        CONTROL = 30,
    }
    pub use Interrupt as interrupt;

    // SAFETY: the numbers are external interrupts of the AN386 (32 lines).
    #[allow(unsafe_code)]
    unsafe impl cortex_m::interrupt::InterruptNumber for Interrupt {
        fn number(self) -> u16 {
            self as u16
        }
    }

    /// Priority bits of the AN386's NVIC.
    pub const NVIC_PRIO_BITS: u8 = 3;

    extern "C" {
        fn ETHERNET();
        fn CONTROL();
        fn DefaultHandler();
    }

    /// The external interrupts' vectors (cortex-m-rt's `device` feature:
    /// the handler names come from build.rs's device.x).
    #[link_section = ".vector_table.interrupts"]
    #[no_mangle]
    #[used]
    static __INTERRUPTS: [unsafe extern "C" fn(); 32] = {
        let mut v = [DefaultHandler as unsafe extern "C" fn(); 32];
        v[13] = ETHERNET;
        v[30] = CONTROL;
        v
    };
}

/// Interrupts masked, report, stop (QEMU exits with a failure status).
#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    cortex_m::interrupt::disable();
    defmt::error!("panic: interrupts masked, halted");
    firmware::semihost::exit(false)
}

/// The core clock (the MPS2's SYSCLK).
pub const SYSCLK_HZ: u32 = 25_000_000;
/// SysTick period.
pub const TICK_NS: u32 = 500_000;
/// Core-clock cycles per SysTick period.
const TICK_CYCLES: u32 = (SYSCLK_HZ as u64 * TICK_NS as u64 / 1_000_000_000) as u32;
/// ns per core-clock cycle (40).
const NS_PER_CYCLE: u32 = 1_000_000_000 / SYSCLK_HZ;

/// SysTick wraps since start.
static TICKS: AtomicU32 = AtomicU32::new(0);

/// The time base: SysTick wraps and the counter within one, never going
/// back.
pub struct TickClock {
    last: nanos::Nanos,
}

impl TickClock {
    const fn new() -> TickClock {
        TickClock {
            last: nanos::Nanos::ZERO,
        }
    }

    /// Now, since SysTick started.
    fn now(&mut self) -> nanos::Nanos {
        // the count and the counter from the same wrap (`tick` has the
        // highest priority: a wrap cannot stay pending across the reads)
        let (wraps, current) = loop {
            let a = TICKS.load(Ordering::Acquire);
            let c = cortex_m::peripheral::SYST::get_current();
            if TICKS.load(Ordering::Acquire) == a {
                break (a, c);
            }
        };
        let within =
            u64::from(TICK_CYCLES.saturating_sub(1).saturating_sub(current)) * u64::from(NS_PER_CYCLE);
        let t = nanos::Nanos::from_ns(u64::from(wraps) * u64::from(TICK_NS) + within);
        if t > self.last {
            self.last = t;
        }
        self.last
    }
}

/// The drive on PROFINET as this image runs it.
pub type Drive = drive_pn::PnDrive<drive_pn::PnParamFlash>;

/// The identity of this image: the station address the LAN9118 reports
/// (QEMU's `macaddr=`), the port MACs next to it.
fn hardware(mac: [u8; 6]) -> drive_pn::Hardware {
    let port = |k: u8| {
        let mut m = mac;
        m[5] = m[5].wrapping_add(k);
        profinet::wire::MacAddr(m)
    };
    drive_pn::Hardware {
        mac: profinet::wire::MacAddr(mac),
        port_macs: [port(1), port(2)],
        im0: profinet::cm::Im0::drive("MPS2-QEMU-0001"),
        im: profinet::cm::ImData::default(),
        boot_time: 1,
    }
}

/// Control-cycle timer: free-running at A150, first cycle at
/// `firmware::cycle::CYCLE` (as `firmware-pn`'s).
pub struct PnCycle {
    next: nanos::Nanos,
}

impl PnCycle {
    const fn new() -> PnCycle {
        PnCycle {
            next: firmware::cycle::CYCLE,
        }
    }
}

#[rtic::app(device = crate::mps2, peripherals = false)]
mod app {
    use crate::lan9118::{self, Lan9118};
    use crate::mps2::Interrupt;
    use crate::{Drive, PnCycle, TickClock, TICKS, TICK_CYCLES};
    use core::sync::atomic::Ordering;
    use cortex_m::peripheral::syst::SystClkSource;
    use drive_ecat::axis::{AxisCommand, AxisIo};
    use drive_pn::PnParamFlash as ParamFlash;
    use firmware::pn_log::log_event;
    use nanos::Nanos;

    #[shared]
    struct Shared {
        drive: &'static mut Drive,
        timer: PnCycle,
        /// When the device's timers are due next.
        deadline: Nanos,
        clock: TickClock,
        cmd: [AxisCommand; 2],
    }

    #[local]
    struct Local {
        /// The MAC (`None` when its bring-up failed: the drive runs
        /// without a network).
        enet: Option<Lan9118>,
        /// One received frame.
        rx: [u8; lan9118::MAX_FRAME],
        next_report: Nanos,
        frames: u32,
    }

    #[init]
    fn init(cx: init::Context) -> (Shared, Local) {
        let mut core = cx.core;
        // SAFETY: the controller's register block; `eth` is its only user.
        #[allow(unsafe_code)]
        let lan = unsafe { Lan9118::new(lan9118::BASE) };
        let (enet, mac) = match lan.start() {
            Ok((mac, id)) => {
                defmt::info!(
                    "init: firmware-mps2-pn (QEMU mps2-an386): PROFINET on the LAN9118 (ID_REV {=u32:08X}), MAC {=[u8]:02x}",
                    id,
                    mac
                );
                (Some(lan), mac)
            }
            Err(e) => {
                defmt::error!("init: LAN9118 bring-up failed: {}", defmt::Debug2Format(&e));
                (None, [0x02, 0, 0, 0, 0, 1])
            }
        };
        let Some(drive) = make_drive(mac) else {
            defmt::error!("init: drive already taken");
            loop {
                cortex_m::asm::bkpt();
            }
        };
        core.SYST.set_clock_source(SystClkSource::Core);
        core.SYST.set_reload(TICK_CYCLES.saturating_sub(1));
        core.SYST.clear_current();
        core.SYST.enable_interrupt();
        core.SYST.enable_counter();
        if let Some(e) = &enet {
            e.listen();
        }
        (
            Shared {
                drive,
                timer: PnCycle::new(),
                deadline: Nanos::ZERO,
                clock: TickClock::new(),
                cmd: [AxisCommand::OFF; 2],
            },
            Local {
                enet,
                rx: [0; lan9118::MAX_FRAME],
                next_report: Nanos::from_ms(10_000),
                frames: 0,
            },
        )
    }

    /// The drive in its static, built in place (`PnDrive::init`: this
    /// frame never holds a whole drive).
    #[inline(never)]
    fn make_drive(mac: [u8; 6]) -> Option<&'static mut Drive> {
        static DRIVE: firmware::once::Once<Drive> = firmware::once::Once::new();
        Some(Drive::init(
            DRIVE.take()?,
            ParamFlash::new(),
            crate::hardware(mac),
        ))
    }

    /// Background: fires the control cycle and the device's timers when
    /// their time has come, then sleeps until the next interrupt (SysTick
    /// or a frame).
    #[idle(shared = [timer, deadline, clock])]
    fn idle(mut cx: idle::Context) -> ! {
        loop {
            let now = cx.shared.clock.lock(|c| c.now());
            if cx.shared.timer.lock(|t| t.next) <= now {
                rtic::pend(Interrupt::CONTROL);
            }
            if cx.shared.deadline.lock(|d| *d) <= now {
                rtic::pend(Interrupt::ETHERNET);
            }
            cortex_m::asm::wfi();
        }
    }

    /// The time base.
    #[task(binds = SysTick, priority = 4)]
    fn tick(_cx: tick::Context) {
        TICKS.fetch_add(1, Ordering::AcqRel);
    }

    /// One control cycle of both axes (no power stage: at rest).
    #[task(binds = CONTROL, priority = 3, shared = [drive, timer, clock, cmd])]
    fn control(cx: control::Context) {
        (cx.shared.drive, cx.shared.timer, cx.shared.clock, cx.shared.cmd).lock(
            |drive, timer, clock, cmd| {
                let now = clock.now();
                if timer.next <= now {
                    timer.next = now.saturating_add(drive.control_period());
                    *cmd = drive.control_cycle(now, &[AxisIo::ready(0); 2]);
                }
            },
        );
    }

    /// The MAC: every received frame through the device, then its timers
    /// (the input frame of the cycle, watchdogs, DCP/alarm timeouts).
    #[task(binds = ETHERNET, priority = 2, shared = [drive, deadline, clock], local = [enet, rx, next_report, frames])]
    fn eth(cx: eth::Context) {
        let enet = cx.local.enet.as_ref();
        let rx = cx.local.rx;
        let frames = cx.local.frames;
        let next_report = cx.local.next_report;
        (cx.shared.drive, cx.shared.deadline, cx.shared.clock).lock(|drive, deadline, clock| {
            let now = clock.now();
            let Some(enet) = enet else {
                // no MAC: the device's timers still run (watchdogs, A270)
                *deadline = drive.poll(now, &mut |_: &[u8]| {}, &mut log_event);
                return;
            };
            let status = enet.take_interrupt();
            if status & (lan9118::INT_RXE | lan9118::INT_TDFO) != 0 {
                defmt::warn!("eth: receive or transmit FIFO error, status {=u32:08X}", status);
            }
            let mut send = |f: &[u8]| {
                if enet.send(f).is_err() {
                    defmt::warn!("eth: frame of {=usize} bytes not sent", f.len());
                }
            };
            // at most one FIFO's worth per run: the timers below still run
            for _ in 0..32 {
                let Some(n) = enet.receive(rx) else { break };
                *frames = frames.wrapping_add(1);
                if let Some(frame) = rx.get(..n) {
                    if n > 0 {
                        drive.receive(now, frame, &mut send, &mut log_event);
                    }
                }
            }
            *deadline = drive.poll(now, &mut send, &mut log_event);
            if now >= *next_report {
                *next_report = now.saturating_add(Nanos::from_ms(10_000));
                let c = drive.device().counters();
                defmt::info!(
                    "eth: at {=u64} ms: {=u32} frames received; device counters: runt {=u32}, not for us {=u32}, unknown FrameID {=u32}, no AR {=u32}, other EtherType {=u32}",
                    now.as_ms(),
                    *frames,
                    c.runt,
                    c.not_for_us,
                    c.unknown_frame_id,
                    c.no_ar,
                    c.other_ethertype
                );
            }
            if enet.pending() > 0 {
                rtic::pend(Interrupt::ETHERNET);
            }
        });
    }
}
