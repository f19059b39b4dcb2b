//! A line of simulated drives in simulated time: each drive is a simulated ESC
//! with the real slave stack (`ecat`) and the drive's objects (`drive`) behind
//! its PDI. Frames from any master go through [`Simulation::exchange`].

use crate::esc::{Esc, EscConfig};
use crate::frame::process_frame;
use crate::motor::{Input, Motor, MotorOutputs};
use crate::pcap::PcapWriter;
use drive::axis::{AxisIo, IndexLatch, ProbeEdge};
use std::fs::File;
use std::io::{self, BufWriter};
use std::path::Path;

/// Local poll period of the slave firmware between frames (the mailbox/ESM task), ns.
pub const POLL_PERIOD_NS: u64 = 100_000;
/// Forwarding delay of one slave, ns.
const SLAVE_DELAY_NS: u64 = 500;
/// One byte on the wire at 100 Mbit/s, ns.
const BYTE_NS: u64 = 80;
/// Preamble, FCS and inter-frame gap, bytes.
const FRAME_OVERHEAD: u64 = 8 + 4 + 12;

/// The simulated non-volatile memory of a drive: two 4 KiB sectors (one per slot).
pub type SimFlash = store::RamFlash<4096, 2>;

/// Control cycle of the simulated drive (A150 default), ns.
pub const CONTROL_CYCLE_NS: u64 = 1_000_000;

/// The conditions of one axis that are not the motor's: additional enable
/// (A60), supply, STO. "Ready" by default in the simulator, so a master alone
/// can enable the drive; tests switch them off to check each refusal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxisConditions {
    /// Additional enable A60 active.
    pub additional_enable: bool,
    /// DC-link supply present.
    pub supply_ok: bool,
    /// Safe torque off active.
    pub sto_active: bool,
}

impl AxisConditions {
    /// Everything ready.
    pub const READY: Self = Self {
        additional_enable: true,
        supply_ok: true,
        sto_active: false,
    };
}

/// One simulated drive: ESC + the drive's runtime (slave stack, objects,
/// store) + a motor and load per axis, stepped once per control cycle.
pub struct SimDrive {
    /// The simulated ESC (what the master sees).
    pub esc: Esc,
    /// The drive firmware's communication runtime.
    pub drive: drive::runtime::Drive<SimFlash>,
    /// State changes with their simulated time, oldest first.
    pub state_log: Vec<(u64, ecat::StateChange)>,
    /// Motor and load of axis A and B.
    pub motors: [Motor; 2],
    /// A60, supply and STO per axis.
    pub conditions: [AxisConditions; 2],
    /// Control cycle, ns.
    pub cycle_ns: u64,
    feedback: [Option<MotorOutputs>; 2],
    next_cycle_ns: u64,
}

/// The SII image generated from [`drive::DEVICE`].
fn sii_image() -> ([u8; ecat::sii::EEPROM_BYTES], usize) {
    let mut sii = [0u8; ecat::sii::EEPROM_BYTES];
    let len = ecat::build_sii(&drive::DEVICE, &mut sii).unwrap_or(0);
    (sii, len)
}

/// What the axis runtime reads from the motor's last step.
fn axis_io(out: Option<&MotorOutputs>, motor: &Motor, c: AxisConditions) -> AxisIo {
    let mut io = AxisIo::ready(0);
    io.additional_enable = c.additional_enable;
    io.supply_ok = c.supply_ok;
    io.sto_active = c.sto_active;
    let Some(out) = out else {
        io.position_inc = motor.position_inc_i64() as i32;
        return io;
    };
    io.position_inc = out.position_inc;
    let sw = motor.switches();
    // electrical level -> "switch actuated" (normally closed contacts read low when hit)
    let hit = |which: Input| out.inputs.get(which) != sw.get(which).is_active_low();
    io.limit_positive = hit(Input::PositiveLimit);
    io.limit_negative = hit(Input::NegativeLimit);
    io.reference = hit(Input::Reference);
    io.index = out.index.map(|i| IndexLatch {
        position_inc: i.position_inc,
        time_ns: out.step_start_ns + i.time_offset_ns,
    });
    let probes = out.edges.iter().filter_map(|e| {
        let input = match e.input {
            Input::Probe1 => 1,
            Input::Probe2 => 2,
            _ => return None,
        };
        Some(ProbeEdge {
            input,
            rising: e.rising,
            time_ns: out.step_start_ns + e.time_offset_ns,
            position_inc: Some(e.position_inc),
        })
    });
    for (slot, edge) in io.probe_edges.iter_mut().zip(probes) {
        *slot = Some(edge);
    }
    io
}

impl SimDrive {
    /// A drive powered on with empty non-volatile memory and default servo motors.
    pub fn new() -> Self {
        Self::power_on(SimFlash::new())
    }

    /// A drive powered on with the given non-volatile memory.
    pub fn power_on(flash: SimFlash) -> Self {
        let (sii, len) = sii_image();
        let esc = Esc::new(EscConfig::default(), sii.get(..len).unwrap_or(&[]));
        Self {
            esc,
            drive: drive::runtime::Drive::new(flash),
            state_log: Vec::new(),
            motors: [Motor::default_servo(), Motor::default_servo()],
            conditions: [AxisConditions::READY; 2],
            cycle_ns: CONTROL_CYCLE_NS,
            feedback: [None, None],
            next_cycle_ns: CONTROL_CYCLE_NS,
        }
    }

    /// Switches the drive off and on again: RAM values, ESC state and motor
    /// motion are lost, the non-volatile memory stays.
    pub fn power_cycle(&mut self) {
        let flash = std::mem::replace(self, Self::power_on(SimFlash::new()))
            .drive
            .into_flash();
        *self = Self::power_on(flash);
    }

    /// Runs the drive firmware up to `now_ns`: every control cycle that is due
    /// (axis runtime, then one motor step with the commanded torque), then the
    /// communication stack once.
    pub fn poll(&mut self, now_ns: u64) {
        self.esc.tick(now_ns);
        while self.next_cycle_ns <= now_ns {
            let t = self.next_cycle_ns;
            let io = [
                axis_io(self.feedback[0].as_ref(), &self.motors[0], self.conditions[0]),
                axis_io(self.feedback[1].as_ref(), &self.motors[1], self.conditions[1]),
            ];
            let cmd = self.drive.control_cycle(t, &io);
            for ((motor, fb), c) in self.motors.iter_mut().zip(self.feedback.iter_mut()).zip(cmd) {
                let torque = if c.power_stage {
                    f64::from(c.torque_nm)
                } else {
                    0.0
                };
                *fb = Some(motor.step(torque, !c.brake_release, self.cycle_ns));
            }
            self.next_cycle_ns += self.cycle_ns;
        }
        let mut pdi = self.esc.pdi();
        if let Ok(Some(change)) = self.drive.poll(&mut pdi, now_ns) {
            self.state_log.push((now_ns, change));
        }
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
    /// Runs the node's firmware once at `now_ns`.
    fn poll(&mut self, now_ns: u64);
}

impl Node for SimDrive {
    fn esc_mut(&mut self) -> &mut Esc {
        &mut self.esc
    }
    fn poll(&mut self, now_ns: u64) {
        SimDrive::poll(self, now_ns);
    }
}

/// A line of simulated slaves (drives by default) and the simulated clock.
pub struct Simulation<N: Node = SimDrive> {
    drives: Vec<N>,
    now_ns: u64,
    last_poll_ns: u64,
    frames: u64,
    pcap: Option<PcapWriter<BufWriter<File>>>,
}

impl Simulation<SimDrive> {
    /// `n` drives in a line, time 0.
    pub fn new(n: usize) -> Self {
        Self::with_nodes((0..n).map(|_| SimDrive::new()).collect())
    }
}

impl<N: Node> Simulation<N> {
    /// A line of the given nodes, position 0 first, time 0.
    pub fn with_nodes(nodes: Vec<N>) -> Self {
        Self {
            drives: nodes,
            now_ns: 0,
            last_poll_ns: 0,
            frames: 0,
            pcap: None,
        }
    }

    /// Records every frame, both directions, to a pcap file at `path`.
    pub fn record_pcap(&mut self, path: &Path) -> io::Result<()> {
        self.pcap = Some(PcapWriter::new(BufWriter::new(File::create(path)?))?);
        Ok(())
    }

    /// Simulated time, ns.
    pub fn now_ns(&self) -> u64 {
        self.now_ns
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
    /// advancing the clock by its time on the wire, then lets every slave's
    /// firmware run once. Non-EtherCAT frames come back unchanged.
    pub fn exchange(&mut self, frame: &mut [u8]) {
        self.frames += 1;
        let t_out = self.now_ns;
        if let Some(p) = self.pcap.as_mut() {
            let _ = p.frame(t_out, frame);
        }
        let n = self.drives.len() as u64;
        self.now_ns += (frame.len() as u64 + FRAME_OVERHEAD) * BYTE_NS + n * SLAVE_DELAY_NS;
        let mut escs: Vec<&mut Esc> = self.drives.iter_mut().map(|d| d.esc_mut()).collect();
        let _ = process_frame(&mut escs, frame, t_out);
        if let Some(p) = self.pcap.as_mut() {
            let _ = p.frame(self.now_ns, frame);
        }
        self.poll_all();
    }

    /// Advances the clock to `t_ns` (no frames), running the slaves' firmware
    /// every [`POLL_PERIOD_NS`].
    pub fn advance_to(&mut self, t_ns: u64) {
        while self.now_ns < t_ns {
            let next = (self.last_poll_ns + POLL_PERIOD_NS).min(t_ns).max(self.now_ns);
            self.now_ns = next;
            if self.now_ns >= self.last_poll_ns + POLL_PERIOD_NS {
                self.poll_all();
            }
        }
    }

    /// Moves the clock to `t_ns` and runs the slaves' firmware once, however
    /// far behind the simulation is: for wall-clock pacing (`hil-sim serve`),
    /// where simulating every poll period of a long gap would starve the frames.
    pub fn catch_up(&mut self, t_ns: u64) {
        if t_ns > self.now_ns {
            self.now_ns = t_ns;
            self.poll_all();
        }
    }

    fn poll_all(&mut self) {
        let now = self.now_ns;
        for d in &mut self.drives {
            d.poll(now);
        }
        self.last_poll_ns = now;
    }

    /// Flushes the pcap file, if any.
    pub fn flush(&mut self) -> io::Result<()> {
        match self.pcap.as_mut() {
            Some(p) => p.flush(),
            None => Ok(()),
        }
    }
}
