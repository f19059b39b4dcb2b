//! A line of simulated drives in simulated time: each drive is a simulated ESC
//! with the real slave stack (`ecat`) and the drive's objects (`drive`) behind
//! its PDI. Frames from any master go through [`Simulation::exchange`].

use crate::esc::{Esc, EscConfig};
use crate::frame::process_frame;
use crate::pcap::PcapWriter;
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

/// One simulated drive: ESC + the drive's runtime (slave stack, objects, store).
pub struct SimDrive {
    /// The simulated ESC (what the master sees).
    pub esc: Esc,
    /// The drive firmware's communication runtime.
    pub drive: drive::runtime::Drive<SimFlash>,
    /// State changes with their simulated time, oldest first.
    pub state_log: Vec<(u64, ecat::StateChange)>,
}

/// The SII image generated from [`drive::DEVICE`].
fn sii_image() -> ([u8; ecat::sii::EEPROM_BYTES], usize) {
    let mut sii = [0u8; ecat::sii::EEPROM_BYTES];
    let len = ecat::build_sii(&drive::DEVICE, &mut sii).unwrap_or(0);
    (sii, len)
}

impl SimDrive {
    /// A drive powered on with empty non-volatile memory.
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
        }
    }

    /// Switches the drive off and on again: RAM values and ESC state are lost,
    /// the non-volatile memory stays.
    pub fn power_cycle(&mut self) {
        let flash = std::mem::replace(self, Self::power_on(SimFlash::new()))
            .drive
            .into_flash();
        *self = Self::power_on(flash);
    }

    /// Runs the slave firmware once at `now_ns`.
    pub fn poll(&mut self, now_ns: u64) {
        self.esc.tick(now_ns);
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
