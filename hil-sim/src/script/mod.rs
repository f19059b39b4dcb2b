//! A scripted EtherCAT master for one simulated drive, `no_std` and heap-free.
//!
//! The QEMU end-to-end image (`firmware-qemu`) has no room for a real master
//! stack: this one sends single-datagram frames straight into the simulated
//! [`Esc`] and walks a fixed sequence, one [`Script::step`] per master cycle:
//!
//! 1. Init: station address, mailbox SyncManagers, request Pre-Op;
//! 2. Pre-Op: SDO downloads through the mailbox (both axes in csp, both
//!    channels assigned, DC-Sync), process-data SyncManagers and FMMUs,
//!    with [`Script::with_eoe`] the EoE step ([`eoe`]: set the IP, ARP,
//!    ping, a UDP parameter read), SYNC0 every [`CYCLE`], request Safe-Op,
//!    then Op with cyclic LRW;
//! 3. Op: enable both axes (6 → 7 → 15 on the controlword), a csp move of
//!    [`MOVE_INC`] increments on each axis with a smooth profile, settle,
//!    disable, back to Init.
//!
//! Each step reports [`Progress`] for the log. The same script runs on the
//! host against the same drive code (this crate's tests), so a failure in
//! QEMU can be reproduced with `cargo test`.

pub mod eoe;
#[cfg(feature = "std")]
mod sim_link;
#[cfg(feature = "std")]
pub use sim_link::SimLink;

use crate::esc::Esc;
use crate::frame::{Command, Datagram, DATAGRAM_HEADER_LEN, WKC_LEN};

/// Where the script's datagrams go: one datagram (header, data, working
/// counter) is processed in place.
pub trait Link {
    /// Sends `datagram` and leaves the reply in it.
    fn transfer(&mut self, datagram: &mut [u8]);
}

/// A [`Link`] straight into one simulated ESC at a fixed time.
pub struct EscLink<'a> {
    /// The ESC.
    pub esc: &'a mut Esc,
    /// Simulation time of the frame.
    pub now: Nanos,
}

impl Link for EscLink<'_> {
    fn transfer(&mut self, datagram: &mut [u8]) {
        if let Ok(mut dg) = Datagram::new_checked(datagram) {
            self.esc.process_datagram(&mut dg, self.now);
        }
    }
}
use ::esc::regs;
use ::esc::{Fmmu, SyncManager};
use nanos::Nanos;

/// Master cycle (and SYNC0 period).
pub const CYCLE: Nanos = Nanos::from_ms(1);
/// Configured station address the script assigns.
pub const STATION: u16 = 0x1001;
/// Distance of the csp move of each axis, increments (2^20 per revolution).
pub const MOVE_INC: i32 = 1 << 20;
/// Master cycles of the csp move.
pub const MOVE_CYCLES: u32 = 200;
/// Master cycles a state or statusword may take before the script fails.
const TIMEOUT_CYCLES: u32 = 500;
/// Largest datagram payload the script sends (a mailbox buffer).
const MAX_DATA: usize = 256;
/// Logical address of the outputs (RxPDO) and inputs (TxPDO).
const LOG_OUT: u32 = 0x0000;
const LOG_IN: u32 = 0x0800;
/// RxPDO bytes per axis in the standard map (spec §5.4).
pub const RX_AXIS: usize = 23;
/// TxPDO bytes per axis in the standard map.
pub const TX_AXIS: usize = 29;
/// Byte offsets inside one axis' RxPDO / TxPDO (standard map).
const RX_CONTROLWORD: usize = 0;
const RX_MODE: usize = 2;
const RX_TARGET: usize = 3;
const TX_STATUSWORD: usize = 0;
const TX_POSITION: usize = 3;
const TX_FOLLOWING_ERROR: usize = 13;

/// SDO downloads of the Pre-Op start-up list: (index, sub, value, bytes).
const STARTUP: [(u16, u8, u32, u8); 9] = [
    (0x6060, 0, 8, 1),      // axis A: csp
    (0x6860, 0, 8, 1),      // axis B: csp
    (0x1C12, 0, 0, 1),      // RxPDO assignment: channel 1 and 2
    (0x1C12, 2, 0x1601, 2), //
    (0x1C12, 0, 2, 1),      //
    (0x1C13, 0, 0, 1),      // TxPDO assignment: channel 1 and 2
    (0x1C13, 2, 0x1A01, 2), //
    (0x1C13, 0, 2, 1),      //
    (0x1C32, 1, 2, 2),      // DC-Sync (SYNC0)
];

/// What a step did, for the log.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Progress {
    /// Nothing worth a line.
    Busy,
    /// The drive reached an AL state (1, 2, 4, 8).
    State(u8),
    /// An SDO download of the start-up list was confirmed.
    Sdo { index: u16, sub: u8 },
    /// SYNC0 was started with this period, ns.
    Sync0(u32),
    /// Both axes report Operation enabled.
    Enabled,
    /// The csp move finished: per axis the actual position and the largest
    /// |following error| (6064h, 60F4h) seen during the move, increments.
    Moved {
        position: [i32; 2],
        max_following_error: [i32; 2],
    },
    /// Both axes report Switched on after the disable.
    Disabled,
    /// EoE: the drive confirmed the IP parameters ([`eoe::DRIVE_IP`]).
    IpSet,
    /// EoE: the drive answered the master's ARP request with this MAC.
    Arp([u8; 6]),
    /// EoE: the drive answered the ping.
    Pinged,
    /// EoE: the UDP parameter service answered [`eoe::UDP_REQUEST`] with this value.
    UdpRead(i32),
    /// The sequence failed at this stage (see [`Failure`]).
    Failed(Failure),
}

/// Why the script stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Failure {
    /// A datagram came back with an unexpected working counter.
    WorkingCounter { ado: u16, wkc: u16 },
    /// The drive refused an AL state request (AL status, AL status code).
    AlState { status: u16, code: u16 },
    /// An SDO download was aborted (index, sub, abort code).
    SdoAbort { index: u16, sub: u8, code: u32 },
    /// A state, SDO answer or statusword did not come in time.
    Timeout { stage: u8 },
    /// An EoE answer was an error (step: 0 set-IP, 3 UDP read; the result
    /// code or 0).
    Eoe { step: u8, result: u16 },
}

/// The EoE step's exchanges, in order.
const EOE_STEPS: u8 = 4;

/// Stages of the sequence.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stage {
    Start,
    WaitPreOp,
    Sdo(usize),
    SdoAnswer(usize),
    /// EoE exchange `k` ([`EOE_STEPS`]): request sent / answer awaited.
    Eoe(u8),
    EoeAnswer(u8),
    ProcessData,
    WaitSafeOp,
    WaitOp,
    Enable(u8),
    Move(u32),
    Settle(u32),
    Disable,
    WaitInit,
    Done,
    Failed,
}

impl Stage {
    fn code(self) -> u8 {
        match self {
            Stage::Start => 0,
            Stage::WaitPreOp => 1,
            Stage::Sdo(_) => 2,
            Stage::SdoAnswer(_) => 3,
            Stage::ProcessData => 4,
            Stage::WaitSafeOp => 5,
            Stage::WaitOp => 6,
            Stage::Enable(_) => 7,
            Stage::Move(_) => 8,
            Stage::Settle(_) => 9,
            Stage::Disable => 10,
            Stage::WaitInit => 11,
            Stage::Done => 12,
            Stage::Failed => 13,
            Stage::Eoe(_) => 14,
            Stage::EoeAnswer(_) => 15,
        }
    }
}

/// The scripted master.
#[derive(Debug, Clone)]
pub struct Script {
    stage: Stage,
    /// Cycles spent in the current stage.
    waited: u32,
    /// Datagram index (echoed by the ESC).
    index: u8,
    /// Mailbox counter (1..7).
    mbx_counter: u8,
    out: [u8; 2 * RX_AXIS],
    inputs: [u8; 2 * TX_AXIS],
    start: [i32; 2],
    max_ferr: [i32; 2],
    /// Run the EoE step in Pre-Op.
    eoe: bool,
    /// The drive's MAC from its ARP reply.
    drive_mac: [u8; 6],
}

impl Default for Script {
    fn default() -> Self {
        Self::new()
    }
}

fn get_u16(b: &[u8], at: usize) -> u16 {
    match b.get(at..at + 2) {
        Some(&[l, h]) => u16::from_le_bytes([l, h]),
        _ => 0,
    }
}

fn get_i32(b: &[u8], at: usize) -> i32 {
    match b.get(at..at + 4) {
        Some(&[a, b2, c, d]) => i32::from_le_bytes([a, b2, c, d]),
        _ => 0,
    }
}

fn put(b: &mut [u8], at: usize, v: &[u8]) {
    if let Some(s) = b.get_mut(at..at + v.len()) {
        s.copy_from_slice(v);
    }
}

/// The csp set-point `k` cycles into a move of `n` cycles over `dist`:
/// a cosine-free smooth step (cubic 3s² − 2s³), exact integers.
fn smooth_step(dist: i32, k: u32, n: u32) -> i32 {
    let (k, n) = (i64::from(k.min(n)), i64::from(n.max(1)));
    // dist * (3 k² n − 2 k³) / n³
    let num = i64::from(dist) * (3 * k * k * n - 2 * k * k * k);
    i32::try_from(num / (n * n * n)).unwrap_or(dist)
}

impl Script {
    /// A master at the start of the sequence.
    pub const fn new() -> Self {
        Self {
            stage: Stage::Start,
            waited: 0,
            index: 0,
            mbx_counter: 0,
            out: [0; 2 * RX_AXIS],
            inputs: [0; 2 * TX_AXIS],
            start: [0; 2],
            max_ferr: [0; 2],
            eoe: false,
            drive_mac: [0xFF; 6],
        }
    }

    /// The same sequence with the EoE step in Pre-Op (the drive needs its
    /// IP stack polled after each mailbox request).
    pub const fn with_eoe() -> Self {
        let mut s = Self::new();
        s.eoe = true;
        s
    }

    /// Whether the sequence ended (done or failed).
    pub fn finished(&self) -> bool {
        matches!(self.stage, Stage::Done | Stage::Failed)
    }

    /// Whether the sequence ran to its end (back in Init).
    pub fn succeeded(&self) -> bool {
        self.stage == Stage::Done
    }

    /// Sends one datagram over `link`; `data` is sent and
    /// replaced by what comes back. Returns the working counter.
    fn xfer(&mut self, link: &mut impl Link, cmd: Command, addr: u32, data: &mut [u8]) -> u16 {
        let n = data.len().min(MAX_DATA);
        let mut buf = [0u8; DATAGRAM_HEADER_LEN + MAX_DATA + WKC_LEN];
        self.index = self.index.wrapping_add(1);
        put(&mut buf, 0, &[cmd.code(), self.index]);
        put(&mut buf, 2, &addr.to_le_bytes());
        put(&mut buf, 6, &(n as u16).to_le_bytes());
        if let (Some(dst), Some(src)) = (buf.get_mut(DATAGRAM_HEADER_LEN..), data.get(..n)) {
            for (d, s) in dst.iter_mut().zip(src) {
                *d = *s;
            }
        }
        let total = DATAGRAM_HEADER_LEN + n + WKC_LEN;
        let Some(dg) = buf.get_mut(..total) else {
            return 0;
        };
        link.transfer(dg);
        let reply = dg
            .get(DATAGRAM_HEADER_LEN..DATAGRAM_HEADER_LEN + n)
            .unwrap_or(&[]);
        for (d, s) in data.iter_mut().zip(reply) {
            *d = *s;
        }
        get_u16(dg, DATAGRAM_HEADER_LEN + n)
    }

    /// FPWR of `data` to register `ado`; a failure when the WKC is not 1.
    fn write(&mut self, link: &mut impl Link, ado: u16, data: &[u8]) -> Result<(), Failure> {
        let mut b = [0u8; MAX_DATA];
        let n = data.len().min(MAX_DATA);
        put(&mut b, 0, data.get(..n).unwrap_or(&[]));
        let addr = u32::from(STATION) | (u32::from(ado) << 16);
        match self.xfer(link, Command::Fpwr, addr, b.get_mut(..n).unwrap_or(&mut [])) {
            1 => Ok(()),
            wkc => Err(Failure::WorkingCounter { ado, wkc }),
        }
    }

    /// FPRD of `buf.len()` bytes at `ado`.
    fn read(&mut self, link: &mut impl Link, ado: u16, buf: &mut [u8]) -> Result<(), Failure> {
        let addr = u32::from(STATION) | (u32::from(ado) << 16);
        match self.xfer(link, Command::Fprd, addr, buf) {
            1 => Ok(()),
            wkc => Err(Failure::WorkingCounter { ado, wkc }),
        }
    }

    fn al_status(&mut self, link: &mut impl Link) -> Result<(u16, u16), Failure> {
        let mut b = [0u8; 6];
        self.read(link, regs::AL_STATUS, &mut b)?;
        Ok((get_u16(&b, 0), get_u16(&b, 4)))
    }

    fn write_sm(
        &mut self,
        link: &mut impl Link,
        n: u8,
        start: u16,
        length: u16,
        control: u8,
    ) -> Result<(), Failure> {
        let sm = SyncManager {
            start,
            length,
            control,
            status: 0,
            activate: 1,
            pdi_control: 0,
        };
        self.write(link, regs::sm(n), &sm.to_bytes())
    }

    /// Waits for AL state `want`: `Ok(true)` when reached, a failure on an
    /// error indication or after [`TIMEOUT_CYCLES`].
    fn wait_state(&mut self, link: &mut impl Link, want: u16) -> Result<bool, Failure> {
        let (status, code) = self.al_status(link)?;
        if status & 0x10 != 0 {
            return Err(Failure::AlState { status, code });
        }
        Ok(status & 0x0F == want)
    }

    /// The process-data exchange of one cycle (LRW: outputs out, inputs in).
    fn cyclic(&mut self, link: &mut impl Link) {
        let mut b = [0u8; 2 * TX_AXIS];
        put(&mut b, 0, &self.out);
        let _ = self.xfer(
            link,
            Command::Lrw,
            LOG_OUT,
            b.get_mut(..2 * RX_AXIS).unwrap_or(&mut []),
        );
        let mut i = [0u8; 2 * TX_AXIS];
        if self.xfer(link, Command::Lrd, LOG_IN, &mut i) == 1 {
            self.inputs = i;
        }
    }

    fn statusword(&self, axis: usize) -> u16 {
        get_u16(&self.inputs, axis * TX_AXIS + TX_STATUSWORD)
    }

    fn position(&self, axis: usize) -> i32 {
        get_i32(&self.inputs, axis * TX_AXIS + TX_POSITION)
    }

    fn following_error(&self, axis: usize) -> i32 {
        get_i32(&self.inputs, axis * TX_AXIS + TX_FOLLOWING_ERROR)
    }

    fn set_controlword(&mut self, cw: u16) {
        for axis in 0..2 {
            put(&mut self.out, axis * RX_AXIS + RX_CONTROLWORD, &cw.to_le_bytes());
            put(&mut self.out, axis * RX_AXIS + RX_MODE, &[8]);
        }
    }

    fn set_target(&mut self, axis: usize, target: i32) {
        put(&mut self.out, axis * RX_AXIS + RX_TARGET, &target.to_le_bytes());
    }

    /// Sends an expedited SDO download request into the SM0 mailbox.
    fn sdo_request(&mut self, link: &mut impl Link, i: usize) -> Result<(), Failure> {
        let Some(&(index, sub, value, len)) = STARTUP.get(i) else {
            return Ok(());
        };
        let mut m = [0u8; 10];
        // CoE header: SDO request (2 << 12)
        put(&mut m, 0, &0x2000u16.to_le_bytes());
        // expedited download, size indicated
        let ccs = 0x20 | 0x03 | ((4 - len) << 2);
        put(&mut m, 2, &[ccs]);
        put(&mut m, 3, &index.to_le_bytes());
        put(&mut m, 5, &[sub]);
        put(&mut m, 6, &value.to_le_bytes());
        // mailbox type CoE (3)
        self.mailbox_out(link, 0x03, &m)
    }

    /// Reads the SM1 mailbox when full: the whole mailbox buffer.
    fn mailbox_in(&mut self, link: &mut impl Link) -> Result<Option<[u8; MAX_DATA]>, Failure> {
        let dev = &drive_ecat::DEVICE;
        let mut st = [0u8; 1];
        self.read(link, regs::sm(1) + 5, &mut st)?;
        if st.first().copied().unwrap_or(0) & 0x08 == 0 {
            return Ok(None);
        }
        let mut m = [0u8; MAX_DATA];
        let n = usize::from(dev.mailbox_in.length).min(MAX_DATA);
        self.read(link, dev.mailbox_in.start, m.get_mut(..n).unwrap_or(&mut []))?;
        Ok(Some(m))
    }

    /// Writes `body` as a mailbox message of type `kind` into SM0.
    fn mailbox_out(&mut self, link: &mut impl Link, kind: u8, body: &[u8]) -> Result<(), Failure> {
        let dev = &drive_ecat::DEVICE;
        self.mbx_counter = ecat::mailbox::next_counter(self.mbx_counter);
        let mut m = [0u8; MAX_DATA];
        let n = usize::from(dev.mailbox_out.length).min(MAX_DATA);
        let len = body.len().min(n.saturating_sub(6));
        put(&mut m, 0, &(len as u16).to_le_bytes());
        put(&mut m, 5, &[kind | (self.mbx_counter << 4)]);
        put(&mut m, 6, body.get(..len).unwrap_or(&[]));
        self.write(link, dev.mailbox_out.start, m.get(..n).unwrap_or(&[]))
    }

    /// Sends EoE request `k`.
    fn eoe_request(&mut self, link: &mut impl Link, k: u8) -> Result<(), Failure> {
        let mut b = [0u8; MAX_DATA];
        let n = match k {
            0 => eoe::set_ip_request(&mut b),
            1 => eoe::arp_request(&mut b),
            2 => eoe::echo_request(&mut b, self.drive_mac),
            _ => eoe::param_request(&mut b, self.drive_mac),
        };
        self.mailbox_out(link, eoe::MBX_EOE, b.get(..n).unwrap_or(&[]))
    }

    /// Reads SM1 for the answer to EoE request `k`: `Ok(Some(progress))`
    /// when it came; other messages (an unsolicited frame) are skipped.
    fn eoe_answer(&mut self, link: &mut impl Link, k: u8) -> Result<Option<Progress>, Failure> {
        let Some(m) = self.mailbox_in(link)? else {
            return Ok(None);
        };
        let len = usize::from(get_u16(&m, 0));
        let body = m.get(6..6 + len).unwrap_or(&[]);
        if m.get(5).copied().unwrap_or(0) & 0x0F != eoe::MBX_EOE {
            return Ok(None);
        }
        if k == 0 {
            return match eoe::set_ip_result(body) {
                Some(0) => Ok(Some(Progress::IpSet)),
                Some(result) => Err(Failure::Eoe { step: 0, result }),
                None => Ok(None),
            };
        }
        // the answers are short: one fragment each
        let frame = match ecat::eoe::EoeHeader::parse(body) {
            Some(h)
                if h.frame_type == ecat::eoe::frame_type::FRAGMENT && h.last && h.fragment_number() == 0 =>
            {
                body.get(ecat::eoe::HEADER_LEN..).unwrap_or(&[])
            }
            _ => return Ok(None),
        };
        Ok(match k {
            1 => eoe::arp_reply(frame).map(|mac| {
                self.drive_mac = mac;
                Progress::Arp(mac)
            }),
            2 => eoe::is_echo_reply(frame).then_some(Progress::Pinged),
            _ => match eoe::param_answer(frame) {
                Some(Ok(v)) => Some(Progress::UdpRead(v)),
                Some(Err(())) => return Err(Failure::Eoe { step: 3, result: 0 }),
                None => None,
            },
        })
    }

    /// Reads the SM1 mailbox when full: `Ok(true)` on a download response.
    fn sdo_answer(&mut self, link: &mut impl Link, i: usize) -> Result<bool, Failure> {
        let Some(m) = self.mailbox_in(link)? else {
            return Ok(false);
        };
        let (index, sub) = STARTUP.get(i).map_or((0, 0), |s| (s.0, s.1));
        match m.get(8).copied().unwrap_or(0) >> 5 {
            3 => Ok(true),
            _ => Err(Failure::SdoAbort {
                index,
                sub,
                code: get_i32(&m, 12) as u32,
            }),
        }
    }

    /// One master cycle (call every [`CYCLE`]; the link carries the time).
    pub fn step(&mut self, link: &mut impl Link) -> Progress {
        let stage = self.stage;
        let (next, progress) = match self.run(link, stage) {
            Ok(r) => r,
            Err(f) => (Stage::Failed, Progress::Failed(f)),
        };
        if next == stage {
            self.waited += 1;
            if self.waited > TIMEOUT_CYCLES && !self.finished() {
                self.stage = Stage::Failed;
                return Progress::Failed(Failure::Timeout { stage: stage.code() });
            }
        } else {
            self.waited = 0;
        }
        self.stage = next;
        progress
    }

    fn run(&mut self, link: &mut impl Link, stage: Stage) -> Result<(Stage, Progress), Failure> {
        let dev = &drive_ecat::DEVICE;
        if matches!(
            stage,
            Stage::WaitOp | Stage::Enable(_) | Stage::Move(_) | Stage::Settle(_) | Stage::Disable
        ) || (stage == Stage::WaitSafeOp && self.waited > 0)
        {
            self.cyclic(link);
        }
        Ok(match stage {
            Stage::Start => {
                // APWR to the first slave (auto-increment address 0)
                let addr = u32::from(regs::STATION_ADDRESS) << 16;
                let mut a = STATION.to_le_bytes();
                let wkc = self.xfer(link, Command::Apwr, addr, &mut a);
                if wkc != 1 {
                    return Err(Failure::WorkingCounter {
                        ado: regs::STATION_ADDRESS,
                        wkc,
                    });
                }
                let (o, i) = (dev.mailbox_out, dev.mailbox_in);
                self.write_sm(link, 0, o.start, o.length, o.control)?;
                self.write_sm(link, 1, i.start, i.length, i.control)?;
                self.write(link, regs::AL_CONTROL, &2u16.to_le_bytes())?;
                (Stage::WaitPreOp, Progress::Busy)
            }
            Stage::WaitPreOp => match self.wait_state(link, 2)? {
                true => (Stage::Sdo(0), Progress::State(2)),
                false => (stage, Progress::Busy),
            },
            Stage::Sdo(i) if i >= STARTUP.len() => match self.eoe {
                true => (Stage::Eoe(0), Progress::Busy),
                false => (Stage::ProcessData, Progress::Busy),
            },
            Stage::Eoe(k) if k >= EOE_STEPS => (Stage::ProcessData, Progress::Busy),
            Stage::Eoe(k) => {
                self.eoe_request(link, k)?;
                (Stage::EoeAnswer(k), Progress::Busy)
            }
            Stage::EoeAnswer(k) => match self.eoe_answer(link, k)? {
                Some(p) => (Stage::Eoe(k + 1), p),
                None => (stage, Progress::Busy),
            },
            Stage::Sdo(i) => {
                self.sdo_request(link, i)?;
                (Stage::SdoAnswer(i), Progress::Busy)
            }
            Stage::SdoAnswer(i) => match self.sdo_answer(link, i)? {
                true => {
                    let (index, sub) = STARTUP.get(i).map_or((0, 0), |s| (s.0, s.1));
                    (Stage::Sdo(i + 1), Progress::Sdo { index, sub })
                }
                false => (stage, Progress::Busy),
            },
            Stage::ProcessData => {
                let (o, i) = (dev.outputs, dev.inputs);
                let (rx, tx) = (2 * RX_AXIS as u16, 2 * TX_AXIS as u16);
                self.write_sm(link, 2, o.start, rx, o.control)?;
                self.write_sm(link, 3, i.start, tx, i.control)?;
                for (n, (log, len, phys, kind)) in [
                    (LOG_OUT, rx, o.start, Fmmu::WRITE),
                    (LOG_IN, tx, i.start, Fmmu::READ),
                ]
                .into_iter()
                .enumerate()
                {
                    let f = Fmmu {
                        logical_start: log,
                        length: len,
                        logical_start_bit: 0,
                        logical_stop_bit: 7,
                        physical_start: phys,
                        physical_start_bit: 0,
                        kind,
                        activate: 1,
                    };
                    self.write(link, regs::fmmu(n as u8), &f.to_bytes())?;
                }
                // SYNC0 on whole cycles of the drive's system time, at least two
                // cycles ahead (the master's frames go out half a cycle off it)
                let mut t = [0u8; 8];
                self.read(link, regs::dc::SYSTEM_TIME, &mut t)?;
                let cycle_ns = CYCLE.as_ns();
                let start = (u64::from_le_bytes(t) / cycle_ns).saturating_add(3) * cycle_ns;
                let cycle = cycle_ns as u32;
                self.write(link, regs::dc::SYNC0_CYCLE, &cycle.to_le_bytes())?;
                self.write(link, regs::dc::START_TIME, &start.to_le_bytes())?;
                self.write(link, regs::dc::ACTIVATION, &[0x03])?;
                self.write(link, regs::AL_CONTROL, &4u16.to_le_bytes())?;
                (Stage::WaitSafeOp, Progress::Sync0(cycle))
            }
            Stage::WaitSafeOp => match self.wait_state(link, 4)? {
                true => {
                    self.write(link, regs::AL_CONTROL, &8u16.to_le_bytes())?;
                    (Stage::WaitOp, Progress::State(4))
                }
                false => (stage, Progress::Busy),
            },
            Stage::WaitOp => match self.wait_state(link, 8)? {
                true => (Stage::Enable(0), Progress::State(8)),
                false => (stage, Progress::Busy),
            },
            Stage::Enable(k) => {
                // Shutdown -> Switch on -> Enable operation, the target on the actual position
                let (cw, want) = match k {
                    0 => (0x06, 0x21),
                    1 => (0x07, 0x23),
                    _ => (0x0F, 0x27),
                };
                for axis in 0..2 {
                    let p = self.position(axis);
                    self.set_target(axis, p);
                    self.start[axis] = p;
                }
                self.set_controlword(cw);
                let reached = (0..2).all(|a| self.statusword(a) & 0x6F == want);
                match (reached, k) {
                    (true, 2) => (Stage::Move(0), Progress::Enabled),
                    (true, _) => (Stage::Enable(k + 1), Progress::Busy),
                    (false, _) => (stage, Progress::Busy),
                }
            }
            Stage::Move(k) => {
                for axis in 0..2 {
                    let dist = if axis == 0 { MOVE_INC } else { -MOVE_INC };
                    let target = self.start[axis].wrapping_add(smooth_step(dist, k + 1, MOVE_CYCLES));
                    self.set_target(axis, target);
                    let f = self.following_error(axis).saturating_abs();
                    self.max_ferr[axis] = self.max_ferr[axis].max(f);
                }
                if k + 1 >= MOVE_CYCLES {
                    (Stage::Settle(0), Progress::Busy)
                } else {
                    (Stage::Move(k + 1), Progress::Busy)
                }
            }
            Stage::Settle(k) if k < 50 => (Stage::Settle(k + 1), Progress::Busy),
            Stage::Settle(_) => {
                self.set_controlword(0x07);
                let moved = Progress::Moved {
                    position: [self.position(0), self.position(1)],
                    max_following_error: self.max_ferr,
                };
                (Stage::Disable, moved)
            }
            Stage::Disable => {
                if (0..2).all(|a| self.statusword(a) & 0x6F == 0x23) {
                    self.write(link, regs::AL_CONTROL, &1u16.to_le_bytes())?;
                    (Stage::WaitInit, Progress::Disabled)
                } else {
                    (stage, Progress::Busy)
                }
            }
            Stage::WaitInit => match self.wait_state(link, 1)? {
                true => (Stage::Done, Progress::State(1)),
                false => (stage, Progress::Busy),
            },
            Stage::Done => (stage, Progress::Busy),
            Stage::Failed => (stage, Progress::Busy),
        })
    }
}
