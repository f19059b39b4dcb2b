//! QEMU measurement image of the PROFINET personality
//! (`qemu-system-arm -machine netduinoplus2`, STM32F405, Cortex-M4F; no NIC
//! needed): the drive on PROFINET ([`drive_pn::PnDrive`], as the board image
//! `firmware-pn` runs it) fed by the scripted controller of `profinet`'s
//! `testing` feature: profinet-py's Connect, then cyclic output frames, one
//! per cycle of the AR (1 ms × 8).
//!
//! Measured under `-icount shift=0` (one instruction per virtual ns) with
//! SysTick at the CPU clock, calibrated at boot against a loop of known
//! length, as `firmware-qemu` measures the control cycle:
//!
//! - `receive` of one cyclic output frame (frame check, consumer, data
//!   hold), the RT_CLASS_1 input;
//! - `poll` at the cycle time when it sends the input frame (provider:
//!   the frame built and handed to the transmit closure);
//! - one control cycle of both axes (`PnDrive::control_cycle`).
//!
//! Without the MAC driver's copy into its DMA buffer (`gmac`: a 1.5 KiB
//! bounded copy per frame sent) and without interrupt entry. `scripts/cross
//! qemu` prints the figures and compares the other lines with
//! `firmware/qemu/expected/firmware-qemu-pn.log`.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use defmt_semihosting as _;
use drive_ecat::axis::AxisIo;
use drive_pn::PnParamFlash as ParamFlash;
use drive_pn::{Hardware, PnDrive};
use firmware::systick::{now as now_ticks, ticks};
use nanos::Nanos;
use profidrive::telegram::{FbPositioning, FbSpeed, FbTorque, FB_RECEIVE_BYTES};
use profinet::cm::CmEvent;
use profinet::device::{DeviceEvent, RtEvent};
use profinet::testing;
use stm32f4 as _; // the interrupt vectors

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    firmware::semihost::panic_exit(info)
}

/// Cyclic frames measured.
const FRAMES: u32 = 1000;

/// A150 of the telegram runs, us: the fastest control cycle.
const A150_FAST_US: u32 = 250;

type Drive = PnDrive<ParamFlash>;

/// The board data of the scripted controller's device.
fn hardware() -> Hardware {
    Hardware::from(testing::device_config())
}

/// Running figures of one measurement.
#[derive(Default, Clone, Copy)]
struct Figure {
    n: u32,
    sum: u64,
    min: u32,
    max: u32,
    /// The run (1-based) that took the max.
    max_at: u32,
}

impl Figure {
    fn add(&mut self, v: u32) {
        self.min = if self.n == 0 { v } else { self.min.min(v) };
        self.n += 1;
        self.sum += u64::from(v);
        if v > self.max || self.n == 1 {
            self.max = v;
            self.max_at = self.n;
        }
    }
    fn mean(&self) -> u32 {
        (self.sum / u64::from(self.n.max(1))) as u32
    }
}

/// The drive commissioned as the scripted controller expects it ("drive-1",
/// 192.168.0.50/24, saved) and restarted, in its static.
#[inline(never)]
#[allow(unsafe_code)]
fn make_drive() -> Option<&'static mut Drive> {
    // in the CCM RAM (qemu/memory.x), away from the stack and `.bss`
    #[link_section = ".ccmram"]
    static mut DRIVE: core::mem::MaybeUninit<Drive> = core::mem::MaybeUninit::uninit();
    static TAKEN: core::sync::atomic::AtomicBool = core::sync::atomic::AtomicBool::new(false);
    if TAKEN.swap(true, core::sync::atomic::Ordering::AcqRel) {
        return None;
    }
    // SAFETY: the flag hands out the static once.
    let slot = unsafe { &mut *core::ptr::addr_of_mut!(DRIVE) };
    let first = build(&mut *slot, ParamFlash::new());
    let c = testing::device_config();
    drive_pn::settings::write_name(first.objects_mut(), &c.name);
    drive_pn::settings::write_ip(first.objects_mut(), c.ip);
    if !first.save() {
        return None;
    }
    // the power cycle keeps the flash: taken out of the first drive (not the
    // whole drive read out onto the stack: two drives do not fit it)
    let flash = core::mem::replace(first.flash_mut(), ParamFlash::new());
    let drive = build(slot, flash);
    // the scope as on the board (its buffer smaller: the STM32F405 has no
    // DSRAM2), idle: the figures include what an idle scope costs a cycle
    static WORDS: firmware::once::Once<[u32; 1024]> = firmware::once::Once::new();
    drive.attach_scope(WORDS.take()?.write([0; 1024]));
    Some(drive)
}

/// One drive built in place into `slot` (`PnDrive::init`: no whole drive on
/// the stack), in a function of its own so its parts' temporaries are in one
/// frame, not once per call site in `make_drive`'s.
#[inline(never)]
fn build(slot: &mut core::mem::MaybeUninit<Drive>, flash: ParamFlash) -> &mut Drive {
    Drive::init(slot, flash, hardware())
}

/// The receive telegrams the measurement sends (CW1 0x0406 each): 0
/// positioning (target 5000, profile velocity 1000, accelerations 10000),
/// 2 torque (no bound mode), 1 speed (100 rpm, ramps 10000). Built out of
/// line: `main`'s stack holds only the three frames.
#[inline(never)]
fn telegrams() -> (
    [u8; FB_RECEIVE_BYTES],
    [u8; FB_RECEIVE_BYTES],
    [u8; FB_RECEIVE_BYTES],
) {
    let mut t0_pos = [0u8; FB_RECEIVE_BYTES];
    let _ = FbPositioning {
        homing_method: 34,
        cw1: 0x0406,
        target: 5000,
        profile_velocity: 1000,
        accelerations: 10_000,
        ..FbPositioning::default()
    }
    .write(&mut t0_pos);
    let mut t2_torque = [0u8; FB_RECEIVE_BYTES];
    let _ = FbTorque {
        cw1: 0x0406,
        ..FbTorque::default()
    }
    .write(&mut t2_torque);
    let mut t1_speed = [0u8; FB_RECEIVE_BYTES];
    let _ = FbSpeed {
        cw1: 0x0406,
        velocity: 100,
        accelerations: 10_000,
        ..FbSpeed::default()
    }
    .write(&mut t1_speed);
    (t0_pos, t2_torque, t1_speed)
}

#[entry]
fn main() -> ! {
    let Some(mut cp) = cortex_m::Peripherals::take() else {
        firmware::semihost::exit(false)
    };
    let per_kilo_tick = firmware::systick::start(&mut cp.SYST);
    let insn = |t: u32| (u64::from(t) * u64::from(per_kilo_tick) / 1000) as u32;
    defmt::info!("init: firmware-qemu-pn (STM32F405): PnDrive + scripted PROFINET controller");
    let ok = run(insn);
    if ok {
        defmt::info!("done: PROFINET sequence complete, exit 0");
    } else {
        defmt::error!("done: PROFINET sequence failed");
    }
    firmware::semihost::exit(ok)
}

fn run(insn: impl Fn(u32) -> u32) -> bool {
    let Some(d) = make_drive() else {
        defmt::error!("init: drive not built (save failed?)");
        return false;
    };
    let (mut connected, mut exchanging) = (false, false);
    let mut sent = 0u32;
    d.receive(
        Nanos::ZERO,
        &testing::connect_frame(),
        &mut |_: &[u8]| sent += 1,
        &mut |e| connected |= matches!(e, DeviceEvent::Cm(CmEvent::Connected(_))),
    );
    defmt::info!(
        "controller: Connect answered: {=bool} ({=u32} frame)",
        connected && sent == 1,
        sent
    );
    let Some(ar) = d.device().cm().ar().cloned() else {
        return false;
    };
    let cycle = ar.output_cr.as_ref().map_or(Nanos::from_ms(1), |c| c.cycle());
    let mut frame = testing::output_frame(&ar, 0, 0x11);
    let n = frame.len();
    let io = [AxisIo::ready(0); 2];
    let (mut rx, mut tx_poll, mut ctl) = (Figure::default(), Figure::default(), Figure::default());
    let mut inputs = 0u32;
    let (mut first, mut after_first) = (0u32, 0u32);
    for k in 1..=FRAMES {
        let now = cycle.saturating_mul(u64::from(k));
        let counter = (k as u16).wrapping_mul(256);
        if let Some(c) = frame.get_mut(n.saturating_sub(4)..n.saturating_sub(2)) {
            c.copy_from_slice(&counter.to_be_bytes());
        }
        let t0 = now_ticks();
        d.receive(now, &frame, &mut |_: &[u8]| {}, &mut |e| {
            exchanging |= matches!(e, DeviceEvent::Rt(RtEvent::Exchanging(_)))
        });
        rx.add(insn(ticks(t0, now_ticks())));
        let mut out = 0u32;
        let t0 = now_ticks();
        let _ = d.poll(now, &mut |_: &[u8]| out += 1, &mut |_| {});
        let t = insn(ticks(t0, now_ticks()));
        if out > 0 {
            tx_poll.add(t);
            inputs += 1;
        }
        let t0 = now_ticks();
        let _ = d.control_cycle(now, &io);
        let t = insn(ticks(t0, now_ticks()));
        if k == 1 {
            first = t;
        } else {
            after_first = after_first.max(t);
        }
        ctl.add(t);
    }
    let valid = d.device().output_data(2).is_some();
    // the PROFIdrive profile's cyclic path per receive telegram of the
    // Example Function block (CW1 0x0406 each): 0 positioning (target,
    // velocities, accelerations), 1 speed (100 rpm, ramps), 2 torque (no
    // bound mode); telegram 1 last, so its answer is the one checked
    let (t0_pos, t2_torque, t1_speed) = telegrams();
    // the telegram runs at the fastest settings: A150 = 250 us, four
    // control cycles per 1 ms send cycle, one of them with a new telegram
    let _ = d
        .objects_mut()
        .set(drive_ecat::params::A150, 0, i64::from(A150_FAST_US));
    let per_frame = (cycle.as_ns() / (u64::from(A150_FAST_US) * 1000)).max(1);
    let mut k = FRAMES;
    let mut figures = [(Figure::default(), Figure::default()); 3];
    for (n_tel, telegram) in [(0usize, &t0_pos), (2, &t2_torque), (1, &t1_speed)] {
        if let Some(cr) = ar.output_cr.as_ref() {
            let csdu = n.saturating_sub(4 + usize::from(cr.data_length));
            for o in cr.data.iter().filter(|o| o.slot == 2) {
                let at = csdu + usize::from(o.frame_offset);
                for (dst, b) in frame
                    .iter_mut()
                    .skip(at)
                    .zip(telegram.iter().take(usize::from(o.data_len)))
                {
                    *dst = *b;
                }
            }
        }
        let (mut profiled, mut between) = (Figure::default(), Figure::default());
        for _ in 0..FRAMES {
            k += 1;
            let now = cycle.saturating_mul(u64::from(k));
            let counter = (k as u16).wrapping_mul(256);
            if let Some(c) = frame.get_mut(n.saturating_sub(4)..n.saturating_sub(2)) {
                c.copy_from_slice(&counter.to_be_bytes());
            }
            d.receive(now, &frame, &mut |_: &[u8]| {}, &mut |_| {});
            let _ = d.poll(now, &mut |_: &[u8]| {}, &mut |_| {});
            let t0 = now_ticks();
            let _ = d.control_cycle(now, &io);
            profiled.add(insn(ticks(t0, now_ticks())));
            for i in 1..per_frame {
                let at = now.saturating_add(Nanos::from_us(i * u64::from(A150_FAST_US)));
                let t0 = now_ticks();
                let _ = d.control_cycle(at, &io);
                between.add(insn(ticks(t0, now_ticks())));
            }
        }
        if let Some(f) = figures.get_mut(n_tel) {
            *f = (profiled, between);
        }
    }
    let zsw1 = d.profile().own().zsw1;
    defmt::info!(
        "controller: PROFIdrive telegram 1 with CW1 0x0406 answered, ZSW1 state {=u16:#06x}",
        zsw1 & 0x47
    );
    defmt::info!(
        "controller: cyclic data exchanged: {=bool}, outputs valid: {=bool}",
        exchanging,
        valid
    );
    defmt::info!(
        "figure: PROFINET receive of a cyclic output frame ({=usize} bytes): mean {=u32} min {=u32} max {=u32} instructions over {=u32} frames",
        n,
        rx.mean(),
        rx.min,
        rx.max,
        rx.n
    );
    defmt::info!(
        "figure: PROFINET poll sending the input frame: mean {=u32} min {=u32} max {=u32} (input frame {=u32}) instructions over {=u32} cycles",
        tx_poll.mean(),
        tx_poll.min,
        tx_poll.max,
        tx_poll.max_at,
        tx_poll.n
    );
    defmt::info!(
        "figure: PnDrive control cycle (2 axes, at rest): mean {=u32} max {=u32} instructions",
        ctl.mean(),
        ctl.max
    );
    defmt::info!(
        "figure: PnDrive control cycle at rest: the first {=u32} instructions (the caches built on the first cycle), the max of the others {=u32}",
        first,
        after_first
    );
    for (n_tel, (f, b)) in figures.iter().enumerate() {
        defmt::info!(
            "figure: PnDrive control cycle with the PROFIdrive telegram {=usize}, the cycle a new telegram arrived (receive, CW1, response): mean {=u32} max {=u32} instructions, {=i32} more than at rest",
            n_tel,
            f.mean(),
            f.max,
            f.mean() as i32 - ctl.mean() as i32
        );
        defmt::info!(
            "figure: PnDrive control cycle with the PROFIdrive telegram {=usize}, the cycles between telegrams (A150 = {=u32} us): mean {=u32} max {=u32} instructions over {=u32} cycles",
            n_tel,
            A150_FAST_US,
            b.mean(),
            b.max,
            b.n
        );
    }
    defmt::info!(
        "figure: input frames sent {=u32} of {=u32} cycles",
        inputs,
        FRAMES
    );
    connected && exchanging && valid && inputs > FRAMES / 2 && zsw1 & 0x47 == 0x01
}
