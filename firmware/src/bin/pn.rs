//! Reference-board image on PROFINET: Infineon XMC4800, the drive's
//! PROFINET personality ([`drive_pn::PnDrive`]) on the MCU's own Ethernet
//! MAC ETH0 (RMII to an external PHY; driver: the `gmac` crate), defmt over
//! RTT, flashed through probe-rs (docs/flashing.md).
//!
//! | task | interrupt | priority | body |
//! |---|---|---|---|
//! | `fast` | VADC0_G0_0 (the DC-link result, last of the conversions CCU80 triggers at the PWM centre: 16 kHz) | 4 | `firmware::xmc::fast::FastLoop::period`: both axes' current loops, PWM compare values, trips |
//! | `control` | CCU40_0 (control-cycle timer compare, CCU40 slice 3) | 3 | `PnDrive::control_cycle` on the fast task's measurements, its commands to the fast task |
//! | `eth` | ETH0_0 (MAC DMA: frame received; pended by `idle` when the device's timers are due) | 2 | `PnDrive::receive` per frame, then `PnDrive::poll` |
//! | `idle` | — | 0 | fires `eth` when the device's timers are due, follows the PHY's link |
//!
//! As on the EtherCAT image, `init` programs the power stage's peripherals
//! (`firmware::xmc::motor`: PWM with the gate enable low, and with
//! `power-pins` its pins low, until the fast task runs an axis commanded
//! on, ADC, encoders; the fast task's current loops, `firmware::xmc::fast`)
//! and the CCU4 compare
//! (CCU40 slice 3) that fires `control` at [`PnCycle::next_at`]; the
//! device's next deadline (the input frame of each cycle, watchdogs) is
//! still pended by `idle`. The parameter store is `drive_pn::PnParamFlash` (two
//! slots of 2 × 2 KiB in RAM, the parameters and I&M1…4: the PFLASH driver is not used by the images yet,
//! as on the EtherCAT image). Board bring-up that needs the hardware to verify — ETH0 pins,
//! PHY address, RMII clock, the MAC address — is listed in docs/hardware.md.
#![no_std]
#![no_main]

use cortex_m_rt as _; // the reset handler and vector table
use defmt_rtt as _;

/// As on the EtherCAT image: interrupts masked, power stage off, report, stop.
#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    firmware::xmc::panic_stop()
}

/// The XMC4800 PAC as RTIC expects a device crate, as on the EtherCAT image.
use firmware::xmc::pac;

#[path = "../xmc_eth.rs"]
mod board;

/// CPU clock after the boot ROM's PLL setup, Hz (DWT CYCCNT counts it).
const CPU_HZ: u32 = 144_000_000;

/// Receive and transmit descriptors (one 1536-byte frame each): 8 × 1.5 KiB
/// receive buffers take a DCP/RPC burst between two runs of the `eth` task.
pub const RX: usize = 8;
/// Transmit descriptors.
pub const TX: usize = 4;

/// The MAC on ETH0 with its rings in DSRAM2.
pub type Eth = gmac::Eth<'static, gmac::Mmio, RX, TX>;
/// The drive on PROFINET as this image runs it.
pub type Drive = drive_pn::PnDrive<drive_pn::PnParamFlash>;

/// The control-cycle timer of the PROFINET image: free-running at A150
/// (no SYNC0 on PROFINET RT_CLASS_1), first cycle at `firmware::cycle::CYCLE`.
pub struct PnCycle {
    next: nanos::Nanos,
}

impl Default for PnCycle {
    fn default() -> Self {
        Self::new()
    }
}

impl PnCycle {
    /// First cycle at A150's default.
    pub const fn new() -> PnCycle {
        PnCycle {
            next: firmware::cycle::CYCLE,
        }
    }
    /// Local time of the next cycle start.
    pub fn next_at(&self) -> nanos::Nanos {
        self.next
    }
    /// Runs the cycle due at `now` and programs the next one A150 later.
    pub fn run(
        &mut self,
        drive: &mut Drive,
        now: nanos::Nanos,
        io: &[drive_ecat::axis::AxisIo; 2],
    ) -> [drive_ecat::axis::AxisCommand; 2] {
        self.next = now.saturating_add(drive.control_period());
        drive.control_cycle(now, io)
    }
}

#[rtic::app(device = crate::pac)]
mod app {
    use crate::pac::Interrupt;
    use crate::{board, Drive, Eth, PnCycle, CPU_HZ};
    use cortex_m::peripheral::DWT;
    use drive_ecat::axis::AxisCommand;
    use drive_ecat::stage::set_dc_link_voltage;
    use drive_pn::PnParamFlash as ParamFlash;
    use firmware::clock::Clock;
    use firmware::pn_log::log_event;
    use firmware::xmc::fast::{guard, hand_over, stage_if_moved, FastLoop, Link};
    use firmware::xmc::motor::{self, ControlTimer};
    use gmac::phy;
    use nanos::Nanos;

    #[shared]
    struct Shared {
        /// The drive (a `'static` singleton, built in place).
        drive: &'static mut Drive,
        /// The MAC (`None` when its bring-up failed: the drive runs without
        /// a network, the axes stay off).
        eth: Option<Eth>,
        timer: PnCycle,
        /// When the device's timers are due next.
        deadline: Nanos,
        clock: Clock,
        cmd: [AxisCommand; 2],
        /// Between `control` and `fast`: the commands in, the measurements out.
        seam: [Link; 2],
    }

    #[local]
    struct Local {
        /// PWM, ADC and encoders of both axes and their current loops.
        fast: FastLoop,
        /// The CCU4 compare that fires `control` (only `control` moves the
        /// next cycle start on this image).
        ctimer: ControlTimer,
        /// The PHY's MDIO address as found at start.
        phy: Option<u8>,
        link: Option<gmac::Link>,
        next_link_check: Nanos,
    }

    #[init]
    fn init(cx: init::Context) -> (Shared, Local) {
        let mut core = cx.core;
        core.DCB.enable_trace();
        core.DWT.enable_cycle_counter();
        firmware::xmc::power::init();
        let (motor, mut ctimer) = motor::init();
        let Some(fast) = FastLoop::new(motor) else {
            defmt::error!("init: current-loop parameters refused");
            loop {
                cortex_m::asm::bkpt();
            }
        };
        let seam = [Link::new(fast.kt()); 2];
        defmt::info!("init: firmware-pn (XMC4800), PROFINET on ETH0 (RMII), control on CCU40_0");
        let Some(drive) = make_drive() else {
            defmt::error!("init: drive already taken");
            loop {
                cortex_m::asm::bkpt();
            }
        };
        let (eth, phy) = match make_eth() {
            Ok(v) => v,
            Err(e) => {
                defmt::error!("init: ETH0 bring-up failed: {}", defmt::Debug2Format(&e));
                (None, None)
            }
        };
        let timer = PnCycle::new();
        let mut clock = Clock::new(CPU_HZ);
        ctimer.arm(timer.next_at(), clock.now(DWT::cycle_count()));
        (
            Shared {
                drive,
                eth,
                timer,
                deadline: Nanos::ZERO,
                clock,
                cmd: [AxisCommand::OFF; 2],
                seam,
            },
            Local {
                fast,
                ctimer,
                phy,
                link: None,
                next_link_check: Nanos::ZERO,
            },
        )
    }

    /// The drive in its static, built in place (`PnDrive::init`: this
    /// frame never holds a whole drive).
    #[inline(never)]
    fn make_drive() -> Option<&'static mut Drive> {
        static DRIVE: firmware::once::Once<Drive> = firmware::once::Once::new();
        let drive = Drive::init(DRIVE.take()?, ParamFlash::new(), board::hardware());
        // the scope's trace buffer: 64 KiB of DSRAM2 beside the Ethernet rings
        if let Some(words) = firmware::xmc::scope_buffer() {
            drive.attach_scope(words);
        }
        Some(drive)
    }

    /// ETH0's clock, reset, pins and RMII selection, the MAC with its rings
    /// in DSRAM2, the PHY found, reset and auto-negotiating.
    #[inline(never)]
    #[allow(unsafe_code)]
    fn make_eth() -> Result<(Option<Eth>, Option<u8>), gmac::Error> {
        #[link_section = ".eth_ram"]
        static mut RINGS: core::mem::MaybeUninit<gmac::Rings<{ crate::RX }, { crate::TX }>> =
            core::mem::MaybeUninit::uninit();
        static TAKEN: core::sync::atomic::AtomicBool = core::sync::atomic::AtomicBool::new(false);
        if TAKEN.swap(true, core::sync::atomic::Ordering::AcqRel) {
            return Ok((None, None));
        }
        board::eth0_enable();
        // SAFETY: the flag hands out the rings once; only the DMA shares them.
        let rings = gmac::Rings::init(unsafe { &mut *core::ptr::addr_of_mut!(RINGS) });
        // SAFETY: ETH0's register block, clocked and out of reset above; the
        // `eth` resource is its only user.
        let regs = unsafe { gmac::Mmio::new(gmac::regs::XMC4800_ETH0) };
        let mut eth = gmac::Eth::new(regs, rings, board::MAC.0)?;
        let (addr, id) = phy::find(&mut eth, board::PHY_ADDR)?;
        defmt::info!("init: PHY at MDIO address {=u8}, id {=u32:08X}", addr, id);
        phy::bring_up(&mut eth, addr, 100_000)?;
        // until the PHY reports its link: 100 Mbit/s full duplex
        eth.start(gmac::Link {
            speed_100: true,
            full_duplex: true,
        });
        Ok((Some(eth), Some(addr)))
    }

    /// Background: fires the device's timers when their time has come,
    /// follows the PHY's link every 100 ms (the control cycle is the CCU4
    /// compare's).
    #[idle(shared = [eth, deadline, clock], local = [phy, link, next_link_check])]
    fn idle(mut cx: idle::Context) -> ! {
        loop {
            let now = cx.shared.clock.lock(|c| c.now(DWT::cycle_count()));
            if cx.shared.deadline.lock(|d| *d) <= now {
                rtic::pend(Interrupt::ETH0_0);
            }
            if let (Some(addr), true) = (*cx.local.phy, *cx.local.next_link_check <= now) {
                *cx.local.next_link_check = now.saturating_add(Nanos::from_ms(100));
                let link = cx.shared.eth.lock(|e| {
                    let e = e.as_mut()?;
                    let l = phy::link(e, addr).ok().flatten();
                    if let Some(l) = l {
                        e.set_link(l);
                    }
                    Some(l)
                });
                if let Some(l) = link {
                    if l != *cx.local.link {
                        match l {
                            Some(l) => defmt::info!(
                                "eth: link up, 100 Mbit/s {=bool}, full duplex {=bool}",
                                l.speed_100,
                                l.full_duplex
                            ),
                            None => defmt::warn!("eth: link down"),
                        }
                        *cx.local.link = l;
                    }
                }
            }
        }
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
    /// axes when its time has come on the fast task's positions and measured
    /// currents, its commands handed to the fast task, the next compare
    /// armed.
    #[task(binds = CCU40_0, priority = 3, shared = [drive, timer, clock, cmd, seam], local = [ctimer, stage_gen: u32 = u32::MAX])]
    fn control(cx: control::Context) {
        let ctimer = cx.local.ctimer;
        let stage_gen = cx.local.stage_gen;
        // `seam` under its own short locks: the fast task waits for a copy,
        // never for the control cycle
        let mut seam = cx.shared.seam;
        (cx.shared.drive, cx.shared.timer, cx.shared.clock, cx.shared.cmd).lock(
            |drive, timer, clock, cmd| {
                let now = clock.now(DWT::cycle_count());
                if timer.next_at() <= now {
                    let io = seam.lock(|l| l.each_mut().map(|l| l.io()));
                    guard(&io);
                    *cmd = timer.run(drive, now, &io);
                    let stage = stage_if_moved(drive.objects(), stage_gen);
                    let mv = seam.lock(|l| hand_over(l, cmd, drive.axes(), stage.as_ref()));
                    set_dc_link_voltage(drive.objects_mut(), mv);
                }
                ctimer.arm(timer.next_at(), clock.now(DWT::cycle_count()));
            },
        );
    }

    /// ETH0: every received frame through the device, then its timers
    /// (the input frame of the cycle, watchdogs, DCP/alarm timeouts).
    #[task(binds = ETH0_0, priority = 2, shared = [drive, eth, deadline, clock])]
    fn eth(cx: eth::Context) {
        (
            cx.shared.drive,
            cx.shared.eth,
            cx.shared.deadline,
            cx.shared.clock,
        )
            .lock(|drive, eth, deadline, clock| {
                let now = clock.now(DWT::cycle_count());
                let Some(eth) = eth.as_mut() else {
                    // no MAC: the device's timers still run (watchdogs, A270)
                    *deadline = drive.poll(now, &mut |_: &[u8]| {}, &mut log_event);
                    return;
                };
                let status = eth.take_interrupt();
                if status & gmac::regs::DMA_FBI != 0 {
                    defmt::error!("eth: DMA bus error, status {=u32:08X}", status);
                }
                eth.receive(|frame, tx| {
                    drive.receive(
                        now,
                        frame,
                        &mut |f: &[u8]| {
                            let _ = tx.send(f);
                        },
                        &mut log_event,
                    )
                });
                let mut tx = eth.transmitter();
                *deadline = drive.poll(
                    now,
                    &mut |f: &[u8]| {
                        let _ = tx.send(f);
                    },
                    &mut log_event,
                );
            });
    }
}
