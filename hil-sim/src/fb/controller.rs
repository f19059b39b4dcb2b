//! A scripted IO controller in the same process as a simulated drive
//! ([`PnSim`]), on simulated time: profinet-py's Connect (the vector of
//! `profinet::testing`, with its IO cycle shortened from 1 ms × 8 to 1 ms
//! × 1 so the controller exchanges a telegram every millisecond, the
//! drive's control cycle A150), then one output frame per cycle carrying
//! the receive telegram, and the drive's input frames read back for the
//! response telegram. The drive's alarms are acknowledged as profinet-py
//! does ([`AlarmAcker`]: a transport ACK and an AlarmAck, at the time the
//! alarm goes out), so a fault does not cost the AR.

use super::alarms::{AlarmAcker, AlarmStats, Received};
use crate::pcap::Recording;
use crate::pn::PnSim;
use nanos::Nanos;
use profinet::cm::CmEvent;
use profinet::dcp::{IpSuite, NameOfStation};
use profinet::device::DeviceEvent;
use profinet::ip::{Ipv4Addr, UDP_PAYLOAD_OFFSET};
use profinet::testing::{self, CONTROLLER_MAC, DEVICE_IP, DEVICE_MAC};
use profinet::wire::EthFrame;

/// The controller's cycle (and the drive's control cycle, A150 default).
pub const CYCLE: Nanos = Nanos::from_ms(1);
/// Where in each cycle the output frame arrives (mid-cycle: never on a
/// control-cycle boundary).
pub const FRAME_PHASE: Nanos = Nanos::from_us(500);
/// PROFINET's EtherType.
const ETHERTYPE_PN: u16 = 0x8892;

/// The in-process controller and the drive it drives.
pub struct PnController {
    sim: PnSim,
    now: Nanos,
    counter: u16,
    out_slot: u16,
    in_slot: u16,
    /// The last response telegram (the drive → controller module's data).
    response: Vec<u8>,
    /// A new response arrived in the last [`exchange`](Self::exchange).
    fresh: bool,
    frames_out: u64,
    frames_in: u64,
    events: Vec<(Nanos, String)>,
    /// Every frame both ways, when recording.
    pcap: Option<Recording>,
    /// The controller's end of the alarm CR.
    alarms: AlarmAcker,
}

/// Where the response telegram lies in the drive's input frames.
struct InputLayout {
    frame_id: [u8; 2],
    /// (offset in the C_SDU, length) of the IN module's data objects.
    objects: Vec<(usize, usize)>,
}

/// Device frames one call may set off (answers to answers), bounded.
const MAX_FRAMES_PER_STEP: usize = 64;

/// profinet-py's Connect with the IOCRs' ReductionRatio set to `ratio`
/// (the UDP payload rebuilt: the checksum stays right). The IOCR blocks
/// (type 0x0102) carry SendClockFactor at +20 and ReductionRatio at +22.
fn connect_with_reduction(ratio: u16) -> Result<testing::Frame, String> {
    let frame = testing::connect_frame();
    let mut payload = frame
        .get(UDP_PAYLOAD_OFFSET..)
        .ok_or("the Connect vector has no UDP payload")?
        .to_vec();
    let mut patched = 0;
    let mut k = 0;
    while k + 26 <= payload.len() {
        let block = &payload[k..k + 26];
        let is_iocr = block[0..2] == [0x01, 0x02] && block[4..6] == [0x01, 0x00];
        let scf = u16::from_be_bytes([block[20], block[21]]);
        let rr = u16::from_be_bytes([block[22], block[23]]);
        if is_iocr && scf == 32 && rr == 8 {
            payload[k + 22..k + 24].copy_from_slice(&ratio.to_be_bytes());
            patched += 1;
            k += 26;
        } else {
            k += 1;
        }
    }
    if patched != 2 {
        return Err(format!("the Connect vector has {patched} IOCR blocks, not 2"));
    }
    Ok(testing::udp_to_device(&payload))
}

impl PnController {
    /// A drive commissioned as "drive-1" at profinet-py's device address
    /// (192.168.0.50/24, MAC 02:00:00:00:00:50), powered on at t = 0.
    pub fn drive() -> PnSim {
        let name: NameOfStation = "drive-1".parse().unwrap_or(NameOfStation::EMPTY);
        let ip = IpSuite {
            ip: DEVICE_IP,
            mask: Ipv4Addr::new(255, 255, 255, 0),
            gateway: Ipv4Addr::UNSPECIFIED,
        };
        PnSim::commissioned(DEVICE_MAC, crate::pn::SERIAL_NUMBER, &name, ip, 1)
    }

    /// Connects to `sim` at `at` (after its start-up): the AR with one OUT
    /// and one IN module of 18 words, 1 ms IO cycle. With `pcap`, every
    /// frame both ways from here on is recorded.
    pub fn connect(mut sim: PnSim, at: Nanos, mut pcap: Option<Recording>) -> Result<PnController, String> {
        let mut record = |b: &[u8]| {
            if let Some(r) = pcap.as_mut() {
                r.frame(at, b);
            }
        };
        sim.poll(at, &mut record);
        let connect = connect_with_reduction(1)?;
        record(&connect);
        sim.receive(at, &connect, &mut record);
        let mut events = Vec::new();
        let mut connected = false;
        while let Some(e) = sim.take_event() {
            connected |= matches!(e, DeviceEvent::Cm(CmEvent::Connected(_)));
            events.push((at, crate::pn::describe(&e)));
        }
        if !connected {
            return Err("the drive did not accept the Connect".into());
        }
        let slot = |to_drive: bool| {
            sim.device()
                .data_modules()
                .find(|(_, _, to)| *to == to_drive)
                .map(|(s, _, _)| s)
        };
        let (Some(out_slot), Some(in_slot)) = (slot(true), slot(false)) else {
            return Err("the AR has no OUT or no IN module".into());
        };
        let alarm_cr = sim
            .device()
            .cm()
            .ar()
            .and_then(|a| a.alarm_cr)
            .ok_or("the AR has no alarm CR")?;
        let alarms = AlarmAcker::new(
            CONTROLLER_MAC,
            DEVICE_MAC,
            alarm_cr.timeout(),
            alarm_cr.rta_retries,
        );
        Ok(PnController {
            sim,
            now: at,
            counter: 0,
            out_slot,
            in_slot,
            response: Vec::new(),
            fresh: false,
            frames_out: 0,
            frames_in: 0,
            events,
            pcap,
            alarms,
        })
    }

    /// The controller's alarm counters (alarms taken and acknowledged).
    pub fn alarm_stats(&self) -> AlarmStats {
        self.alarms.stats()
    }

    /// The simulated time.
    pub fn now(&self) -> Nanos {
        self.now
    }

    /// The drive.
    pub fn sim(&self) -> &PnSim {
        &self.sim
    }

    /// The drive, mutable (its control channel).
    pub fn sim_mut(&mut self) -> &mut PnSim {
        &mut self.sim
    }

    /// The recording (flush it at the end), taken.
    pub fn take_recording(&mut self) -> Option<Recording> {
        self.pcap.take()
    }

    /// Output frames sent and input frames taken.
    pub fn frames(&self) -> (u64, u64) {
        (self.frames_out, self.frames_in)
    }

    /// The device's events so far (time, line), oldest first; taken.
    pub fn take_events(&mut self) -> Vec<(Nanos, String)> {
        std::mem::take(&mut self.events)
    }

    /// An output frame carrying `telegram` in the OUT module.
    fn output_frame(&self, telegram: &[u8]) -> Result<Vec<u8>, String> {
        let ar = self.sim.device().cm().ar().ok_or("the AR is gone")?;
        let cr = ar.output_cr.as_ref().ok_or("the AR has no output CR")?;
        let len = usize::from(cr.data_length);
        let mut csdu = vec![0u8; len];
        for o in &cr.data {
            let at = usize::from(o.frame_offset);
            let n = usize::from(o.data_len);
            if o.slot == self.out_slot {
                let dst = csdu
                    .get_mut(at..at + n.min(telegram.len()))
                    .ok_or("the OUT module lies beyond the frame")?;
                dst.copy_from_slice(&telegram[..dst.len()]);
            }
            if let Some(iops) = csdu.get_mut(at + n) {
                *iops = 0x80;
            }
        }
        for c in &cr.iocs {
            if let Some(iocs) = csdu.get_mut(usize::from(c.frame_offset)) {
                *iocs = 0x80;
            }
        }
        let mut f = Vec::with_capacity(len + 20);
        f.extend_from_slice(&DEVICE_MAC.0);
        f.extend_from_slice(&CONTROLLER_MAC.0);
        f.extend_from_slice(&ETHERTYPE_PN.to_be_bytes());
        f.extend_from_slice(&cr.frame_id.to_be_bytes());
        f.extend_from_slice(&csdu);
        f.extend_from_slice(&self.counter.to_be_bytes());
        f.extend_from_slice(&[0x35, 0x00]);
        Ok(f)
    }

    /// Where the response telegram lies in the input frames.
    fn input_layout(&self) -> Result<InputLayout, String> {
        let ar = self.sim.device().cm().ar().ok_or("the AR is gone")?;
        let input = ar.input_cr.as_ref().ok_or("the AR has no input CR")?;
        Ok(InputLayout {
            frame_id: input.frame_id.to_be_bytes(),
            objects: input
                .data
                .iter()
                .filter(|o| o.slot == self.in_slot)
                .map(|o| (usize::from(o.frame_offset), usize::from(o.data_len)))
                .collect(),
        })
    }

    /// Takes the frames the drive sent at `at`: each is recorded, an input
    /// frame's IN module becomes the response telegram, an alarm is
    /// acknowledged at once (the answers go to the drive at `at`, and what
    /// it sends back is taken in turn). Returns whether an input frame came.
    fn take_from_drive(&mut self, at: Nanos, sent: Vec<Vec<u8>>, layout: &InputLayout) -> bool {
        let mut queue = std::collections::VecDeque::from(sent);
        let mut got = false;
        let mut answers = Vec::new();
        for _ in 0..MAX_FRAMES_PER_STEP {
            let Some(b) = queue.pop_front() else { break };
            if let Some(r) = self.pcap.as_mut() {
                r.frame(at, &b);
            }
            let Some(e) = EthFrame::parse(&b) else { continue };
            if e.ethertype == ETHERTYPE_PN && e.payload.get(..2) == Some(&layout.frame_id[..]) {
                for (o, n) in &layout.objects {
                    if let Some(d) = e.payload.get(2 + o..2 + o + n) {
                        self.response = d.to_vec();
                        got = true;
                    }
                }
                continue;
            }
            match self.alarms.receive(at, &b, &mut answers) {
                Some(Received::Alarm {
                    alarm_type,
                    slot,
                    subslot,
                    sequence,
                }) => self.events.push((
                    at,
                    format!(
                        "alarm {alarm_type:#06x} at {slot}/{subslot:#06x} (sequence {sequence}) acknowledged"
                    ),
                )),
                Some(Received::Abort(s)) => {
                    self.events.push((
                        at,
                        format!("alarm channel: the drive aborted the AR ({:02x?})", s.0),
                    ));
                }
                _ => {}
            }
            for a in answers.drain(..) {
                if let Some(r) = self.pcap.as_mut() {
                    r.frame(at, &a);
                }
                let mut back = Vec::new();
                self.sim.receive(at, &a, &mut |f| back.push(f.to_vec()));
                // the drive's transport ACK of our AlarmAck goes out at its
                // next poll: now
                self.sim.poll(at, &mut |f| back.push(f.to_vec()));
                queue.extend(back);
            }
        }
        got
    }

    /// Runs the drive up to `t` (its control cycles and timers at their own
    /// times) and takes its input frames.
    fn run_to(&mut self, t: Nanos) -> Result<(), String> {
        let layout = self.input_layout()?;
        let mut got = false;
        // every deadline up to t, bounded: a deadline that does not move on
        // cannot hang the simulation
        let mut at = self.now;
        for _ in 0..1000 {
            let mut due = Vec::new();
            self.alarms.poll(at, &mut due);
            let mut sent = Vec::new();
            for f in &due {
                if let Some(r) = self.pcap.as_mut() {
                    r.frame(at, f);
                }
                self.sim.receive(at, f, &mut |b| sent.push(b.to_vec()));
            }
            let next = self.sim.poll(at, &mut |b| sent.push(b.to_vec()));
            got |= self.take_from_drive(at, sent, &layout);
            if next >= t || next <= at {
                break;
            }
            at = next;
        }
        let mut sent = Vec::new();
        self.sim.poll(t, &mut |b| sent.push(b.to_vec()));
        got |= self.take_from_drive(t, sent, &layout);
        self.now = t;
        if got {
            self.fresh = true;
            self.frames_in += 1;
        }
        while let Some(e) = self.sim.take_event() {
            self.events.push((t, crate::pn::describe(&e)));
        }
        Ok(())
    }

    /// One controller cycle: the drive runs to this cycle's frame time,
    /// the output frame with `telegram` goes in; returns the latest
    /// response telegram (`None` before the first).
    pub fn exchange(&mut self, telegram: &[u8]) -> Result<Option<&[u8]>, String> {
        self.fresh = false;
        let k = self
            .now
            .saturating_sub(FRAME_PHASE)
            .checked_div_span(CYCLE)
            .unwrap_or(0);
        let t = (k + 1) * CYCLE + FRAME_PHASE;
        self.run_to(t)?;
        self.counter = self.counter.wrapping_add(32);
        let f = self.output_frame(telegram)?;
        if let Some(r) = self.pcap.as_mut() {
            r.frame(t, &f);
        }
        let mut sent = Vec::new();
        self.sim.receive(t, &f, &mut |b| sent.push(b.to_vec()));
        let layout = self.input_layout()?;
        if self.take_from_drive(t, sent, &layout) {
            self.fresh = true;
            self.frames_in += 1;
        }
        self.frames_out += 1;
        Ok((!self.response.is_empty()).then_some(self.response.as_slice()))
    }

    /// Did the last [`exchange`](Self::exchange) bring a new response?
    pub fn fresh(&self) -> bool {
        self.fresh
    }
}
