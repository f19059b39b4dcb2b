//! A line of simulated drives in simulated time: each drive is a simulated ESC
//! with the real slave stack (`ecat`) and the drive's objects (`drive`) behind
//! its PDI. Frames from any master go through [`Simulation::exchange`].

use crate::esc::{Esc, EscConfig, LineTiming};
use crate::frame::process_frame;
use crate::motor::{Motor, MotorOutputs};
mod axis_io;
mod datagram;
mod flash;
mod plant;
pub mod profile;
mod snapshot;
mod stamps;
mod variant;

use crate::pcap::Recording;
pub(crate) use axis_io::axis_io;
pub use datagram::{datagram_frame, MIN_FRAME_LEN};
pub use flash::{firmware_body, FirmwareFlash, FirmwareSlots, SimFlash};
use nanos::Nanos;
pub use stamps::{CycleStamp, LockLoss, PllLock, Sync0Stamp};
use std::collections::VecDeque;
use std::io;
use std::path::Path;

/// Most drives on one simulated line that `hil-sim serve --slaves` takes:
/// a line of 128 reaches Op through ethercrab in-process
/// (`e002_line_of_128_drives_reaches_op`). The simulation itself has no limit.
pub const MAX_DRIVES: usize = 128;
/// Local poll period of the slave firmware between frames (the mailbox/ESM task).
pub const POLL_PERIOD: Nanos = Nanos::from_us(100);
/// SYNC0 pulses closer than this reach the drive as one interrupt (a
/// cycle no drive runs; a master or a fuzzer can still set it).
const MIN_SYNC0_IRQ_NS: u32 = 10_000;
/// Forwarding delay of one slave, ns (out and back: half of it each way).
const SLAVE_DELAY_NS: u64 = 500;
/// SYNC0 pulses kept in [`SimDrive::sync0_log`].
pub const SYNC0_LOG_LEN: usize = 64;
/// One byte on the wire at 100 Mbit/s, ns.
const BYTE_NS: u64 = 80;
/// Preamble, FCS and inter-frame gap, bytes.
const FRAME_OVERHEAD: u64 = 8 + 4 + 12;

/// Control cycle of the simulated drive (A150 default).
pub const CONTROL_CYCLE: Nanos = Nanos::from_ms(1);
/// Control-cycle starts kept in [`SimDrive::cycle_log`].
pub const CYCLE_LOG_LEN: usize = 256;
/// Tick frequency of the simulated control-cycle timer, Hz.
const TIMER_HZ: u64 = drive_ecat::runtime::TIMER_HZ as u64;
const NS_PER_S: u128 = 1_000_000_000;

/// The conditions of one axis that are not the motor's: additional enable
/// (A60), supply, STO, the encoder's health. "Ready" by default in the simulator, so a master alone
/// can enable the drive; tests switch them off to check each refusal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxisConditions {
    /// Additional enable A60 active.
    pub additional_enable: bool,
    /// DC-link supply present.
    pub supply_ok: bool,
    /// Safe torque off active.
    pub sto_active: bool,
    /// The motor encoder delivers its position (false: an encoder fault,
    /// the drive sees [`drive_ecat::axis::AxisIo::encoder_ok`] false).
    pub encoder_ok: bool,
}

impl AxisConditions {
    /// Everything ready.
    pub const READY: Self = Self {
        additional_enable: true,
        supply_ok: true,
        sto_active: false,
        encoder_ok: true,
    };
}

/// One simulated drive: ESC + the drive's runtime (slave stack, objects,
/// store) + a motor and load per axis, stepped once per control cycle.
///
/// # Control-cycle timing
///
/// The MCU's control-cycle timer counts ticks of [`drive_ecat::runtime::TIMER_HZ`]
/// of the MCU's local time. The MCU runs from the same crystal as the ESC
/// ([`SimDrive::set_clock`]: `local(t) = offset + t · (1 + drift)`), but
/// its timer is *not* corrected by the ESC's drift-control loop: that loop
/// only trims the ESC's DC clock. So the PLL sees the oscillator's full
/// drift against the DC system time and trims it, and aligns the phase.
///
/// - Without SYNC0: a free-running [`CONTROL_CYCLE`] cycle in simulation
///   time, run when [`SimDrive::poll`] finds it due (as before DC-Sync).
/// - From the first SYNC0 pulse the PLL runs ([`drive_ecat::runtime::Drive::pll`]):
///   the next start is the PLL's `start + period_ticks`, converted to
///   simulation time through the MCU clock; [`Node::next_timer_at`] makes
///   the [`Simulation`] stop at each start, so cycles run at their exact time.
pub struct SimDrive {
    /// The simulated ESC (what the master sees).
    pub esc: Esc,
    /// The drive firmware's communication runtime.
    pub drive: drive_ecat::runtime::Drive<SimFlash, FirmwareFlash>,
    /// State changes with their simulated time, oldest first.
    pub state_log: Vec<(Nanos, ecat::StateChange)>,
    /// Motor and load of axis A and B.
    pub motors: [Motor; 2],
    /// A60, supply and STO per axis.
    pub conditions: [AxisConditions; 2],
    /// Length of the last control cycle: the time until the next one
    /// starts (A150 in free run, the PLL's period under DC), which the
    /// motors are stepped by.
    pub cycle: Nanos,
    /// The last [`SYNC0_LOG_LEN`] SYNC0 pulses the ESC delivered, oldest first.
    pub sync0_log: VecDeque<Sync0Stamp>,
    /// The last [`CYCLE_LOG_LEN`] control-cycle starts under the PLL, oldest first.
    pub cycle_log: VecDeque<CycleStamp>,
    /// The PLL's phase lock over the whole run (every gain and loss counted).
    pub pll_lock: PllLock,
    feedback: [Option<MotorOutputs>; 2],
    /// Axis A's and B's current loop and PMSM ([`SimDrive::set_plant`]);
    /// `None`: the rigid motor model.
    electrical: crate::plants::Plants,
    next_cycle: Nanos,
    /// Next start of the PLL-driven timer, ticks of the MCU clock (`None`: free-running).
    next_tick: Option<u64>,
    /// SM2 event pending after the last poll (a new one means a new RxPDO frame).
    sm2_event: bool,
    /// The IP stack on the EoE interface, if bound ([`SimDrive::bind_net`]).
    pub net: Option<Box<crate::eoe::DriveNet>>,
    /// The scope (group T, issue 35) over [`SCOPE_WORDS`] words: sampled
    /// after each control cycle, its objects answered through
    /// [`Drive::poll_with`](drive_ecat::runtime::Drive::poll_with). Volatile:
    /// a power cycle empties it.
    pub scope: drive_ecat::scope::Recorder<Vec<u32>>,
}

/// Words of the simulated drive's scope buffer: 64 KiB, the most the trace
/// data object T11 reads (16 blocks of 4096 bytes).
pub const SCOPE_WORDS: usize = 16 * 1024;

/// The SII image generated from the description of `variant`
/// ([`drive_ecat::device`]).
fn sii_image(variant: drive_ecat::Variant) -> ([u8; ecat::sii::EEPROM_BYTES], usize) {
    let mut sii = [0u8; ecat::sii::EEPROM_BYTES];
    let len = ecat::build_sii(drive_ecat::device(variant), &mut sii).unwrap_or(0);
    (sii, len)
}

impl SimDrive {
    /// A drive powered on with empty non-volatile memory and default servo motors.
    pub fn new() -> Self {
        Self::power_on(SimFlash::new())
    }

    /// A drive with firmware slots (FoE firmware download in Bootstrap into
    /// the inactive slot, `hil-sim serve`): both slots empty, so the first
    /// download becomes the image the next power-on starts on trial.
    pub fn with_firmware_slots() -> Self {
        Self::power_on_with(SimFlash::new(), Some(FirmwareFlash::new()))
    }

    /// A drive powered on with the given non-volatile memory.
    pub fn power_on(flash: SimFlash) -> Self {
        Self::power_on_with(flash, None)
    }

    /// A drive powered on with the given parameter flash and, if any,
    /// firmware flash (the boot decision runs first).
    pub fn power_on_with(flash: SimFlash, firmware: Option<FirmwareFlash>) -> Self {
        Self::power_on_for(drive_ecat::Variant::Double, flash, firmware)
    }

    /// [`power_on_with`](Self::power_on_with) for the device `variant`: its
    /// SII in the ESC's EEPROM, its dictionary and axes.
    pub fn power_on_for(
        variant: drive_ecat::Variant,
        flash: SimFlash,
        firmware: Option<FirmwareFlash>,
    ) -> Self {
        let (sii, len) = sii_image(variant);
        let esc = Esc::new(EscConfig::default(), sii.get(..len).unwrap_or(&[]));
        let boot = firmware.map(|f| {
            let mut slots = FirmwareSlots::new(f);
            // a flash in RAM does not fail; nothing to start is "no image";
            // only images signed with the drive's key start (issue 18)
            let _ = slots.boot_verified(&drive_ecat::runtime::FIRMWARE_PUBLIC_KEY, 0);
            slots
        });
        Self {
            esc,
            drive: drive_ecat::runtime::Drive::with_boot_for(variant, flash, boot),
            state_log: Vec::new(),
            motors: [Motor::default_servo(), Motor::default_servo()],
            conditions: [AxisConditions::READY; 2],
            cycle: CONTROL_CYCLE,
            sync0_log: VecDeque::with_capacity(SYNC0_LOG_LEN),
            cycle_log: VecDeque::with_capacity(CYCLE_LOG_LEN),
            pll_lock: PllLock::default(),
            feedback: [None, None],
            electrical: crate::plants::Plants::default(),
            next_cycle: CONTROL_CYCLE,
            next_tick: None,
            sm2_event: false,
            net: None,
            scope: drive_ecat::scope::Recorder::new(vec![0; SCOPE_WORDS]),
        }
    }

    /// Switches the drive off and on again: RAM values, ESC state and motor
    /// motion are lost, the non-volatile memory stays.
    ///
    /// The oscillator (drift and offset, see [`SimDrive::set_clock`]) is the
    /// same hardware and keeps running.
    pub fn power_cycle(&mut self) {
        let old = std::mem::replace(self, Self::power_on(SimFlash::new()));
        let (drift, offset) = (old.esc.config().clock_drift_ppb, old.esc.config().clock_offset_ns);
        let variant = old.drive.variant();
        let (flash, firmware) = old.drive.into_flashes();
        // (the simulated drive saves at once: its store is never out in a job)
        *self = Self::power_on_for(variant, flash.unwrap_or_else(SimFlash::new), firmware);
        self.esc.set_clock(drift, offset);
    }

    /// The device restarts (A09, [`drive_ecat::runtime::Drive::restart_due`]):
    /// a [`power_cycle`](Self::power_cycle) of the electronics; the motors,
    /// the axes' conditions, the state log and a bound IP stack stay (the
    /// machine did not move, the line did not change).
    pub fn restart(&mut self) {
        let motors = self.motors.clone();
        let conditions = self.conditions;
        let log = std::mem::take(&mut self.state_log);
        let net = self.net.take();
        self.power_cycle();
        self.motors = motors;
        self.conditions = conditions;
        self.state_log = log;
        self.net = net;
    }

    /// Sets the drive's oscillator: drift in ppm (+: runs fast) and the ESC's
    /// local time at simulation time 0, ns. Call it before the first frame.
    pub fn set_clock(&mut self, drift_ppm: f64, offset_ns: u64) {
        let ppb = (drift_ppm * 1000.0).round();
        let ppb = ppb.clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32;
        self.esc.set_clock(ppb, offset_ns);
    }

    /// The MCU's local time at simulation time `now` (the ESC's crystal
    /// without the DC drift correction).
    pub fn mcu_local(&self, now: Nanos) -> Nanos {
        let c = self.esc.config();
        // the drift term in 64 bits where the product fits (the same
        // truncating division)
        let drift = i64::try_from(now.as_ns())
            .ok()
            .and_then(|n| n.checked_mul(i64::from(c.clock_drift_ppb)))
            .map(|p| i128::from(p / 1_000_000_000));
        let now = i128::from(now.as_ns());
        let drift = drift.unwrap_or_else(|| now * i128::from(c.clock_drift_ppb) / 1_000_000_000);
        let t = i128::from(c.clock_offset_ns) + now + drift;
        Nanos::from_ns(u64::try_from(t.max(0)).unwrap_or(u64::MAX))
    }

    /// The first simulation time at which the MCU's local time reaches `local`.
    fn mcu_now_for(&self, local: Nanos) -> Nanos {
        let c = self.esc.config();
        let rel = i128::from(local.as_ns()) - i128::from(c.clock_offset_ns);
        if rel <= 0 {
            return Nanos::ZERO;
        }
        let den = (1_000_000_000 + i128::from(c.clock_drift_ppb)).max(1);
        // rel · 1e9 / den (rel > 0: rounded down) = rel + ⌊−rel · (den − 1e9) / den⌋,
        // in 64 bits where it fits
        let quick = i64::try_from(rel).ok().and_then(|r| {
            let d = i64::try_from(den).ok()?;
            let y = r.checked_mul(d - 1_000_000_000)?.checked_neg()?;
            r.checked_add(y.div_euclid(d))
        });
        let first = quick.map_or_else(|| rel * 1_000_000_000 / den, i128::from);
        let mut t = u64::try_from(first).unwrap_or(u64::MAX);
        while self.mcu_local(Nanos::from_ns(t)) < local {
            t = t.saturating_add(1);
        }
        while t > 0 && self.mcu_local(Nanos::from_ns(t - 1)) >= local {
            t -= 1;
        }
        Nanos::from_ns(t)
    }

    /// Local time of timer tick `tick` (rounded up to the ns: the tick is reached then).
    fn tick_local(tick: u64) -> Nanos {
        let ns = match tick.checked_mul(NS_PER_S as u64) {
            Some(p) => u128::from(p.div_ceil(TIMER_HZ)),
            None => (u128::from(tick) * NS_PER_S).div_ceil(u128::from(TIMER_HZ)),
        };
        Nanos::from_ns(u64::try_from(ns).unwrap_or(u64::MAX))
    }

    /// Simulation time of the next control-cycle start.
    pub fn next_cycle_at(&self) -> Nanos {
        match self.next_tick {
            Some(tick) => self.mcu_now_for(Self::tick_local(tick)),
            None => self.next_cycle,
        }
    }

    /// Follows the PLL's presence: the timer switches to the PLL's periods
    /// (continuing from the free-running phase) or back to free-running.
    fn follow_pll(&mut self) {
        match (self.drive.pll().is_some(), self.next_tick) {
            (true, None) => {
                let local = u128::from(self.mcu_local(self.next_cycle).as_ns());
                let tick = (local * u128::from(TIMER_HZ)).div_ceil(NS_PER_S);
                self.next_tick = Some(u64::try_from(tick).unwrap_or(u64::MAX));
            }
            (false, Some(_)) => {
                self.next_cycle = self.next_cycle_at();
                self.next_tick = None;
            }
            _ => {}
        }
    }

    /// SYNC0 hook: records the pulse in [`SimDrive::sync0_log`],
    /// acknowledges it (reads 0x098E through the PDI, as the firmware's SYNC0
    /// interrupt does) and hands the MCU's local time of the edge to the
    /// drive's PLL (built at the first pulse).
    pub fn on_sync0(&mut self, now: Nanos) {
        let p = self.esc.take_sync0_events(now);
        if p.count == 0 {
            return;
        }
        let mut status = [0u8; 1];
        let _ = ::esc::Pdi::read(&mut self.esc, ::esc::regs::dc::SYNC0_STATUS, &mut status);
        if self.sync0_log.len() >= SYNC0_LOG_LEN {
            self.sync0_log.pop_front();
        }
        self.sync0_log.push_back(Sync0Stamp {
            now: p.last_now,
            local_ns: self.esc.local_ns(p.last_now),
            system_ns: p.last_system_ns,
            pulses: p.count,
        });
        let local = self.mcu_local(p.last_now);
        let mut pdi = self.esc.pdi();
        let _ = self.drive.on_sync0(&mut pdi, local);
        self.follow_pll();
    }

    /// A frame passed the ESC at `arrival`: when it completed an SM2
    /// (RxPDO) buffer, the drive's SM2 event tells the PLL (`A261[1]`, `[2]`).
    pub fn on_frame(&mut self, arrival: Nanos) {
        self.pll_lock.last_frame = Some(arrival);
        let event = self.esc.al_event_request() & ::esc::regs::al_event::sm(2) != 0;
        if event && !self.sm2_event {
            let local = self.mcu_local(arrival);
            let _ = self.drive.on_frame(local);
        }
        self.sm2_event = event;
    }

    /// Runs every control cycle due at `now`, each at its own start time.
    pub fn run_due_cycles(&mut self, now: Nanos) {
        // bounded: a broken timer cannot hang the simulation
        for _ in 0..1_000_000 {
            let t = self.next_cycle_at();
            if t > now {
                return;
            }
            self.run_cycle(t);
        }
    }

    /// One control cycle starting at `t`: the PLL's command (when it runs)
    /// programs the next start and gives the cycle's steps (Rx, application,
    /// Tx in the A149 order, Rx/Tx in the aligned cycle only:
    /// [`drive_ecat::runtime::Drive::sync_cycle`]); then one motor step.
    fn run_cycle(&mut self, t: Nanos) {
        let mut command = None;
        match self.next_tick {
            Some(tick) => {
                let local = Self::tick_local(tick);
                match self.drive.cycle_start(local) {
                    Some(cmd) => {
                        self.next_tick = Some(tick.saturating_add(u64::from(cmd.period_ticks.max(1))));
                        if self.cycle_log.len() >= CYCLE_LOG_LEN {
                            self.cycle_log.pop_front();
                        }
                        self.cycle_log.push_back(CycleStamp {
                            now: t,
                            local,
                            system_ns: self.esc.system_time_ns(t),
                            index: cmd.index,
                            locked: self.drive.pll().is_some_and(|p| p.is_locked()),
                            rx: cmd.rx,
                            tx: cmd.tx,
                        });
                        command = Some(cmd);
                    }
                    None => {
                        self.next_tick = None;
                        self.next_cycle = t.saturating_add(self.drive.free_run_period());
                    }
                }
            }
            // free run: the cycle the axes integrate with (A150, E-125)
            None => self.next_cycle = t.saturating_add(self.drive.free_run_period()),
        }
        let mut io = [
            axis_io(self.feedback[0].as_ref(), &self.motors[0], self.conditions[0]),
            axis_io(self.feedback[1].as_ref(), &self.motors[1], self.conditions[1]),
        ];
        self.measure_currents(&mut io);
        self.show_dc_link();
        let cmd = match command {
            Some(c) => self.drive.sync_cycle(&c, t, &io),
            None => self.drive.control_cycle(t, &io),
        };
        let (drive, scope) = (&self.drive, &mut self.scope);
        scope.sample(drive.objects(), || {
            let [a, b] = drive.axes();
            let s = drive_ecat::scope::Signals::of;
            [s(a, &io[0]), s(b, &io[1])]
        });
        let locked = self.drive.pll().is_some_and(|p| p.is_locked());
        self.pll_lock.follow(locked, t, self.drive.slave().state());
        // the torque holds until the next cycle starts (a broken timer that
        // schedules nothing ahead steps the motors by the last length)
        let dt = self.next_cycle_at().saturating_sub(t);
        if !dt.is_zero() {
            self.cycle = dt;
        }
        self.step_motors(cmd);
    }

    /// Runs the drive firmware up to `now`: every control cycle that is due
    /// (axis runtime, then one motor step with the commanded torque), then the
    /// communication stack once.
    pub fn poll(&mut self, now: Nanos) {
        self.esc.tick(now);
        self.run_due_cycles(now);
        let mut pdi = self.esc.pdi();
        if let Ok(Some(change)) = self.drive.poll_with(&mut pdi, now, &mut self.scope) {
            self.state_log.push((now, change));
        }
        if self.drive.restart_due(now) {
            self.restart();
            return;
        }
        self.sm2_event = self.esc.al_event_request() & ::esc::regs::al_event::sm(2) != 0;
        self.poll_net(now);
        self.follow_pll();
    }
}

impl SimDrive {
    /// What motor `axis` (0 = A, 1 = B) did in the last control cycle
    /// (torque applied, brake applied, …), `None` before the first cycle.
    pub fn motor_outputs(&self, axis: usize) -> Option<&MotorOutputs> {
        self.feedback.get(axis).and_then(Option::as_ref)
    }

    /// The drive's four EtherCAT LEDs at `now` (E-132…E-134): the
    /// firmware's patterns ([`drive_ecat::runtime::Drive::leds`]) with the port
    /// activity the simulated ESC saw.
    pub fn leds(&self, now: Nanos) -> drive_ecat::runtime::Leds {
        let activity = [self.esc.port_activity(0, now), self.esc.port_activity(1, now)];
        self.drive.leds(activity)
    }
}

impl Default for SimDrive {
    fn default() -> Self {
        Self::new()
    }
}

/// One slave on the simulated line: its ESC and the firmware behind the PDI.
/// [`SimDrive`] is the drive; tests and benchmarks may plug in other slaves.
pub trait Node {
    /// The node's simulated ESC.
    fn esc_mut(&mut self) -> &mut Esc;
    /// Runs the node's firmware once at `now`.
    fn poll(&mut self, now: Nanos);
    /// The ESC raised SYNC0 at `now` (the simulation stops at each edge and
    /// calls this after advancing the ESC to it). Default: nothing.
    fn on_sync0(&mut self, now: Nanos) {
        let _ = now;
    }
    /// Simulation time of the node's next timer interrupt that must run at
    /// its exact time (the simulation stops there and calls
    /// [`Node::on_timer`]). Default: none. A function of the node's own
    /// state: the simulation asks once per round of event delivery and again
    /// after each event it delivered to this node.
    fn next_timer_at(&self) -> Option<Nanos> {
        None
    }
    /// The timer of [`Node::next_timer_at`] is due at `now`. Default: nothing.
    fn on_timer(&mut self, now: Nanos) {
        let _ = now;
    }
    /// A frame passed the node's ESC, arriving there at `arrival`.
    /// Default: nothing.
    fn on_frame(&mut self, arrival: Nanos) {
        let _ = arrival;
    }
}

impl Node for SimDrive {
    fn esc_mut(&mut self) -> &mut Esc {
        &mut self.esc
    }
    fn poll(&mut self, now: Nanos) {
        SimDrive::poll(self, now);
    }
    fn on_sync0(&mut self, now: Nanos) {
        SimDrive::on_sync0(self, now);
    }
    fn next_timer_at(&self) -> Option<Nanos> {
        self.next_tick.map(|_| self.next_cycle_at())
    }
    fn on_timer(&mut self, now: Nanos) {
        self.run_due_cycles(now);
    }
    fn on_frame(&mut self, arrival: Nanos) {
        SimDrive::on_frame(self, arrival);
    }
}

/// Seeded frame-arrival jitter: xorshift64, uniform in ±`max_ns`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Jitter {
    max_ns: u64,
    state: u64,
}

impl Jitter {
    /// The next jitter value, ns, in `-max_ns..=max_ns`.
    fn next(&mut self) -> i64 {
        if self.max_ns == 0 {
            return 0;
        }
        let mut x = self.state;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.state = x;
        let span = self.max_ns.saturating_mul(2).saturating_add(1);
        (x % span) as i64 - self.max_ns as i64
    }
}

/// A line of simulated slaves (drives by default) and the simulated clock.
pub struct Simulation<N: Node = SimDrive> {
    drives: Vec<N>,
    now: Nanos,
    last_poll: Nanos,
    frames: u64,
    pcap: Option<Recording>,
    jitter: Jitter,
    /// Scratch of [`Simulation::deliver_events`]: each node's next SYNC0
    /// edge and timer (kept to reuse its allocation).
    next_events: Vec<(Option<Nanos>, Option<Nanos>)>,
}

impl Simulation<SimDrive> {
    /// `n` drives in a line, time 0.
    pub fn new(n: usize) -> Self {
        Self::with_nodes((0..n).map(|_| SimDrive::new()).collect())
    }

    /// A line of drives whose oscillators drift: drive `i` with
    /// `drifts_ppm[i]` and `offsets_ns[i]` ([`SimDrive::set_clock`]).
    pub fn with_clocks(drifts_ppm: &[f64], offsets_ns: &[u64]) -> Self {
        let mut sim = Self::new(drifts_ppm.len().min(offsets_ns.len()));
        for (d, (drift, offset)) in sim.drives_mut().iter_mut().zip(drifts_ppm.iter().zip(offsets_ns)) {
            d.set_clock(*drift, *offset);
        }
        sim
    }
}

impl<N: Node> Simulation<N> {
    /// A line of the given nodes, position 0 first, time 0.
    pub fn with_nodes(nodes: Vec<N>) -> Self {
        Self {
            drives: nodes,
            now: Nanos::ZERO,
            last_poll: Nanos::ZERO,
            frames: 0,
            pcap: None,
            jitter: Jitter { max_ns: 0, state: 1 },
            next_events: Vec::new(),
        }
    }

    /// Frame-arrival jitter: every frame reaches the line `max + u` after
    /// the master sent it, `u` uniform in `-max..=max` from a xorshift
    /// generator seeded with `seed` (deterministic; 0 = no jitter, the default).
    pub fn set_frame_jitter(&mut self, max: Nanos, seed: u64) {
        // splitmix64 of the seed: nearby seeds give unrelated sequences, never state 0
        let mut z = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        self.jitter = Jitter {
            max_ns: max.as_ns().min(i64::MAX as u64 / 4),
            state: z.max(1),
        };
    }

    /// Records every frame, both directions, to a pcap file at `path`
    /// (created and its header written now: an unwritable path fails here).
    pub fn record_pcap(&mut self, path: &Path) -> io::Result<()> {
        self.pcap = Some(Recording::create(path)?);
        Ok(())
    }

    /// The first error writing the pcap recording, if any (also returned by
    /// [`Simulation::flush`]).
    pub fn recording_error(&self) -> Option<&io::Error> {
        self.pcap.as_ref().and_then(Recording::error)
    }

    /// Simulated time.
    pub fn now(&self) -> Nanos {
        self.now
    }

    /// Frames exchanged so far.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// The drives, position 0 first.
    pub fn drives(&self) -> &[N] {
        &self.drives
    }

    /// Mutable access to the drives (tests inject faults this way).
    pub fn drives_mut(&mut self) -> &mut [N] {
        &mut self.drives
    }

    /// Passes one frame from the master through the line and back (in place),
    /// advancing the clock by its time on the wire (plus the frame-arrival
    /// jitter, [`Simulation::set_frame_jitter`]), then lets every slave's
    /// firmware run once. SYNC0 edges before the frame's arrival and during
    /// its round trip are delivered at their times. Non-EtherCAT frames come
    /// back unchanged.
    pub fn exchange(&mut self, frame: &mut [u8]) {
        self.frames += 1;
        let t_out = self.now;
        if let Some(p) = self.pcap.as_mut() {
            p.frame(t_out, frame);
        }
        let j = self.jitter.next();
        let t_arr = Nanos::from_ns(
            t_out
                .as_ns()
                .saturating_add(self.jitter.max_ns)
                .saturating_add_signed(j),
        );
        self.deliver_events(t_arr);
        self.now = self.now.max(t_arr);
        let n = self.drives.len() as u64;
        let wire = (frame.len() as u64 + FRAME_OVERHEAD) * BYTE_NS + n * SLAVE_DELAY_NS;
        let hop = SLAVE_DELAY_NS / 2;
        let mut escs: Vec<&mut Esc> = self.drives.iter_mut().map(|d| d.esc_mut()).collect();
        for (k, esc) in (0u64..).zip(escs.iter_mut()) {
            esc.set_line_timing(LineTiming {
                arrival: Nanos::from_ns(k * hop),
                loop_time: Nanos::from_ns(2 * n.saturating_sub(k + 1) * hop),
            });
        }
        let _ = process_frame(&mut escs, frame, t_arr);
        drop(escs);
        for (k, d) in (0u64..).zip(self.drives.iter_mut()) {
            d.on_frame(t_arr.saturating_add(Nanos::from_ns(k * hop)));
        }
        let t_back = t_arr.saturating_add(Nanos::from_ns(wire));
        self.deliver_events(t_back);
        self.now = self.now.max(t_back);
        if let Some(p) = self.pcap.as_mut() {
            p.frame(self.now, frame);
        }
        self.poll_all();
    }

    /// Advances the clock to `t` (no frames), running the slaves' firmware
    /// every [`POLL_PERIOD`] and delivering SYNC0 edges at their times.
    pub fn advance_to(&mut self, t: Nanos) {
        while self.now < t {
            let next = (self.last_poll + POLL_PERIOD).min(t).max(self.now);
            self.deliver_events(next);
            self.now = next;
            if self.now >= self.last_poll + POLL_PERIOD {
                self.poll_all();
            }
        }
    }

    /// Moves the clock to `t` and runs the slaves' firmware once, however
    /// far behind the simulation is: for wall-clock pacing (`hil-sim serve`),
    /// where simulating every poll period of a long gap would starve the frames.
    /// SYNC0 edges in the gap are still delivered one by one.
    pub fn catch_up(&mut self, t: Nanos) {
        if t > self.now {
            self.deliver_events(t);
            self.now = t;
            self.poll_all();
        }
    }

    /// Delivers every SYNC0 edge and node timer ([`Node::next_timer_at`]) up
    /// to and including `t` in time order (SYNC0 before a timer, then
    /// position order, for events at the same time): the clock moves to the
    /// event; for an edge the node's ESC is advanced to it and
    /// [`Node::on_sync0`] runs, for a timer [`Node::on_timer`].
    fn deliver_events(&mut self, t: Nanos) {
        // each node's next SYNC0 edge and timer, worked out once: an event
        // changes only the node it goes to, whose entry is then renewed
        let mut next = core::mem::take(&mut self.next_events);
        next.clear();
        next.extend(self.drives.iter_mut().map(Self::next_events_of));
        // bounded: a pathological SYNC0 cycle cannot hang the simulation
        for _ in 0..1_000_000 {
            // (time, 0 = SYNC0 / 1 = timer, node)
            let mut best: Option<(Nanos, u8, usize)> = None;
            for (i, &(sync0, timer)) in next.iter().enumerate() {
                let sync0 = sync0.map(|e| (e, 0u8, i));
                let timer = timer.map(|e| (e, 1u8, i));
                for ev in [sync0, timer].into_iter().flatten() {
                    if ev.0 <= t && best.is_none_or(|b| ev < b) {
                        best = Some(ev);
                    }
                }
            }
            let Some((e, kind, i)) = best else { break };
            self.now = self.now.max(e);
            let now = self.now;
            let (Some(d), Some(slot)) = (self.drives.get_mut(i), next.get_mut(i)) else {
                break;
            };
            if kind == 1 {
                d.on_timer(now);
                *slot = Self::next_events_of(d);
                if slot.1.is_some_and(|n| n <= e) {
                    // the timer did not move on (cannot happen); stop
                    break;
                }
                continue;
            }
            let before = d.esc_mut().sync0_total();
            // pulses closer together than the drive's SYNC0 interrupt can
            // take them coalesce into one interrupt (all up to `t` at once)
            let upto = if d.esc_mut().sync0_cycle_ns() < MIN_SYNC0_IRQ_NS {
                t
            } else {
                now
            };
            d.esc_mut().tick(upto);
            if d.esc_mut().sync0_total() == before {
                // no pulse fired (cannot happen: the edge time is exact); stop
                break;
            }
            d.on_sync0(now);
            *slot = Self::next_events_of(d);
        }
        self.next_events = next;
    }

    /// A node's next SYNC0 edge and next timer.
    fn next_events_of(d: &mut N) -> (Option<Nanos>, Option<Nanos>) {
        (d.esc_mut().next_sync0_at(), d.next_timer_at())
    }

    fn poll_all(&mut self) {
        let now = self.now;
        for d in &mut self.drives {
            d.poll(now);
        }
        self.last_poll = now;
    }

    /// Flushes the pcap file, if any; the first write error of the recording.
    pub fn flush(&mut self) -> io::Result<()> {
        match self.pcap.as_mut() {
            Some(p) => p.flush(),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests;
