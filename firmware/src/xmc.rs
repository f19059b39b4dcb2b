//! What the reference board's images (`firmware` on EtherCAT, `firmware-pn`
//! on PROFINET) share: the PAC as RTIC wants it, the power stage's gate
//! enable, the power-stage peripherals (`motor`: PWM, ADC, encoders, the
//! control-cycle timer; crate `xmc-motor`), the current-loop fast task's body
//! and its board constants (`fast`), the scope's buffer in DSRAM2 and the
//! panic stop.

/// The XMC4800 PAC as RTIC expects a device crate: svd2rust 0.14 output lacks
/// the `interrupt` alias of the `Interrupt` enum, so it is added here.
pub mod pac {
    pub use xmc4800::Interrupt as interrupt;
    pub use xmc4800::*;
}

/// The power stage's gate-driver enable: P5.9, push-pull, active high
/// (docs/flashing.md, wiring). Low from `init` until the fast task
/// (`fast`) runs an axis commanded on; the fast task drives it low when no
/// axis is on (trips included), the panic stop drives it low.
pub mod power {
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
    #[inline]
    pub fn set(on: bool) {
        port()
            .omr()
            .write(|w| if on { w.ps9().set_bit() } else { w.pr9().set_bit() });
    }
}

pub mod fast;

/// The power stage's peripherals as the images program them (crate
/// `xmc-motor`; pins, channels and what is unverified: docs/hardware.md).
pub mod motor {
    use nanos::Nanos;
    use xmc_motor::adc::Adc;
    use xmc_motor::enc::{Encoder, EncoderPins};
    use xmc_motor::pwm::{Duty, Pwm, PwmConfig, DUTY_HALF};
    use xmc_motor::{pins, regs, timer, Mmio};

    /// PWM rate (issue 34): 16 kHz, 8 kHz with the feature `pwm-8k`.
    pub const PWM_HZ: u32 = if cfg!(feature = "pwm-8k") { 8_000 } else { 16_000 };
    /// Dead time of the gate drivers, ns (a placeholder until the power
    /// board's switches are known: docs/hardware.md).
    pub const DEAD_NS: u32 = 500;
    /// POSIF input selections (phase A, phase B, index) of axes A and B.
    pub const ENCODER_PINS: [EncoderPins; 2] = [EncoderPins([0, 0, 0]), EncoderPins([1, 1, 1])];
    /// The PWM settings (checked at compile time).
    const PWM: PwmConfig = match PwmConfig::new(xmc_motor::F_CCU_HZ, PWM_HZ, DEAD_NS) {
        Some(c) => c,
        None => PwmConfig {
            period: 0,
            dead_time: 0,
        },
    };
    const _: () = assert!(PWM.period != 0, "PWM rate or dead time out of range");

    /// The control-cycle timer (CCU40 slice 3 → CCU40_0), shared by the
    /// tasks that move the next cycle start.
    pub struct ControlTimer {
        regs: Mmio,
        timer: timer::CycleTimer,
    }

    impl ControlTimer {
        /// Fires CCU40_0 at local time `next` (`now` is the time now); a
        /// start more than one timer shot away fires early and the task
        /// arms again.
        #[inline]
        pub fn arm(&mut self, next: Nanos, now: Nanos) {
            self.timer.arm(&mut self.regs, next.saturating_sub(now).as_ns());
        }
    }

    /// The PWM pins of axes A and B: driven only with the feature
    /// `power-pins` (on the development kit they are the ESC's MII pins).
    const PWM_PINS: Option<[&[pins::Pin; 6]; 2]> = if cfg!(feature = "power-pins") {
        Some([&pins::AXIS_A, &pins::AXIS_B])
    } else {
        None
    };

    /// One axis' PWM, its pins' state and its encoder.
    struct Axis {
        pwm: Pwm,
        pins: Option<&'static [pins::Pin; 6]>,
        on: bool,
        enc: Encoder,
    }

    /// The power stage: both axes' PWM and encoders, the ADC.
    pub struct Motor {
        regs: Mmio,
        axes: [Axis; 2],
        adc: Adc,
    }

    impl Motor {
        /// Axis `i`'s power stage on (`on`: its pins to the CCU8, which
        /// starts from 50 %, zero voltage) or off (its pins low as plain
        /// outputs: both switches of every phase off, whatever the CCU8
        /// does; pins only with `power-pins`). A change only.
        pub fn set_on(&mut self, i: usize, on: bool) {
            if let Some(axis) = self.axes.get_mut(i) {
                if on != axis.on {
                    if on {
                        axis.pwm.set_duties(&mut self.regs, [DUTY_HALF; 3]);
                    }
                    if let Some(p) = axis.pins {
                        pins::set_axis(&mut self.regs, p, on);
                    }
                    axis.on = on;
                }
            }
        }

        /// Axis `i`'s duty cycles for the next PWM period (compare shadow
        /// registers, transferred at the period boundary).
        #[inline]
        pub fn set_duties(&mut self, i: usize, duty: [Duty; 3]) {
            if let Some(axis) = self.axes.get(i) {
                axis.pwm.set_duties(&mut self.regs, duty);
            }
        }

        /// Axis `i`'s encoder: its position in counts since start and
        /// whether POSIF saw a phase error since the last call.
        #[inline]
        pub fn encoder(&mut self, i: usize) -> (i32, bool) {
            match self.axes.get_mut(i) {
                Some(a) => (a.enc.position(&mut self.regs), a.enc.take_error(&mut self.regs)),
                None => (0, true),
            }
        }

        /// Whether axis `i`'s PWM unit is in its trap state (over-current
        /// input: its outputs held passive by the CCU8 itself).
        #[inline]
        pub fn trapped(&mut self, i: usize) -> bool {
            let regs = &mut self.regs;
            self.axes.get(i).is_none_or(|a| a.pwm.trapped(regs))
        }

        /// Clears axis `i`'s trap flags (the outputs leave the passive level
        /// at the next period if the trap input is inactive by then).
        pub fn clear_trap(&mut self, i: usize) {
            if let Some(a) = self.axes.get(i) {
                a.pwm.clear_trap(&mut self.regs);
            }
        }

        /// The last PWM centre's samples, if fresh.
        #[inline]
        pub fn samples(&mut self) -> Option<xmc_motor::adc::Samples> {
            self.adc.read(&mut self.regs)
        }
    }

    /// Clocks and resets of the power-stage peripherals, then: PWM pins low
    /// (before the CCU8 drives them; `power-pins` only), both CCU8 units (CCU80 triggering the
    /// VADC at the PWM centre), the VADC, both encoders, the control timer;
    /// the PWM timers started together by SCU_GENERAL.CCUCON.
    #[allow(unsafe_code)]
    pub fn init() -> (Motor, ControlTimer) {
        // SAFETY: fixed SCU addresses, used only here at start (before any
        // task runs); the bits written are this module's peripherals'.
        let (clk, reset, general) = unsafe {
            (
                &*xmc4800::SCU_CLK::ptr(),
                &*xmc4800::SCU_RESET::ptr(),
                &*xmc4800::SCU_GENERAL::ptr(),
            )
        };
        clk.clkset().write(|w| w.ccucen().set_bit());
        clk.cgatclr0().write(|w| {
            w.vadc().set_bit();
            w.ccu40().set_bit();
            w.ccu41().set_bit();
            w.ccu80().set_bit();
            w.ccu81().set_bit();
            w.posif0().set_bit();
            w.posif1().set_bit();
            w.eru1().set_bit()
        });
        reset.prclr0().write(|w| {
            w.vadcrs().set_bit();
            w.ccu40rs().set_bit();
            w.ccu41rs().set_bit();
            w.ccu80rs().set_bit();
            w.ccu81rs().set_bit();
            w.posif0rs().set_bit();
            w.posif1rs().set_bit();
            w.eru1rs().set_bit()
        });
        // SAFETY: the peripherals are clocked and out of reset; the `motor`
        // and `ctimer` resources are their only users, each touching its own
        // registers (the timer CCU40 slice 3, the rest the others).
        let (mut regs, timer_regs) = unsafe { (Mmio::new(), Mmio::new()) };
        let [pins_a, pins_b] = match PWM_PINS {
            Some([a, b]) => {
                pins::set_axis(&mut regs, a, false);
                pins::set_axis(&mut regs, b, false);
                [Some(a), Some(b)]
            }
            None => [None, None],
        };
        let pwm_a = Pwm::init(&mut regs, regs::CCU80, PWM, true);
        let pwm_b = Pwm::init(&mut regs, regs::CCU81, PWM, false);
        let adc = Adc::init(&mut regs);
        let [enc_pins_a, enc_pins_b] = ENCODER_PINS;
        let enc_a = Encoder::init(&mut regs, regs::POSIF0, regs::CCU40, enc_pins_a);
        let enc_b = Encoder::init(&mut regs, regs::POSIF1, regs::CCU41, enc_pins_b);
        let mut timer_regs = timer_regs;
        let timer = timer::CycleTimer::init(&mut timer_regs);
        general.ccucon().write(|w| w.gsc80().set_bit().gsc81().set_bit());
        general
            .ccucon()
            .write(|w| w.gsc80().clear_bit().gsc81().clear_bit());
        (
            Motor {
                regs,
                axes: [
                    Axis {
                        pwm: pwm_a,
                        pins: pins_a,
                        on: false,
                        enc: enc_a,
                    },
                    Axis {
                        pwm: pwm_b,
                        pins: pins_b,
                        on: false,
                        enc: enc_b,
                    },
                ],
                adc,
            },
            ControlTimer {
                regs: timer_regs,
                timer,
            },
        )
    }

    /// The ESC's SYNC0 to ERU1.SR0 (the `sync0` task's ERU1_0): the
    /// EtherCAT image only.
    #[allow(unsafe_code)]
    pub fn route_sync0() {
        // SAFETY: ERU1 is clocked (`init`) and only written here, at start.
        let mut regs = unsafe { Mmio::new() };
        timer::route_sync0(&mut regs);
    }
}

/// Words of the scope's trace buffer on the board: 64 KiB, the most group T
/// reads out (T11: 16 blocks of 4096 bytes).
pub const SCOPE_WORDS: usize = 16 * 1024;

/// The scope's trace buffer (issue 35), once: 64 KiB of DSRAM2 (section
/// `.scope_ram` in memory.x, `scope_ram_bytes` in firmware/size-budget.toml),
/// beside the drive's data in DSRAM1 rather than in it. Zeroed here (the
/// section is not loaded), so no word is read before it was written.
#[allow(unsafe_code)]
pub fn scope_buffer() -> Option<&'static mut [u32]> {
    use core::sync::atomic::{AtomicBool, Ordering};
    #[link_section = ".scope_ram"]
    static mut RAM: core::mem::MaybeUninit<[u32; SCOPE_WORDS]> = core::mem::MaybeUninit::uninit();
    static TAKEN: AtomicBool = AtomicBool::new(false);
    if TAKEN.swap(true, Ordering::AcqRel) {
        return None;
    }
    let words = core::ptr::addr_of_mut!(RAM).cast::<u32>();
    // SAFETY: the flag hands the bank out once, so this is the only
    // reference to it; every word is written (zeroed) before the slice is made.
    unsafe {
        core::ptr::write_bytes(words, 0, SCOPE_WORDS);
        Some(core::slice::from_raw_parts_mut(words, SCOPE_WORDS))
    }
}

/// The board images' panic: masks every interrupt first, so no task can
/// command the power stage again, switches the power stage off (gate enable
/// low), then reports over RTT and stops the core. `scripts/cross panics`
/// checks that no panic path is reachable from any task.
pub fn panic_stop() -> ! {
    cortex_m::interrupt::disable();
    power::set(false);
    defmt::error!("panic: interrupts masked, power stage off, halted");
    loop {
        cortex_m::asm::bkpt();
    }
}
