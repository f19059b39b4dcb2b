//! A simulated drive on PROFINET ([`PnSim`]): the firmware's drive
//! personality (`drive_pn`: the PROFINET IO device in front of the
//! fieldbus-neutral drive core, with the PROFIdrive-style profile on its
//! cyclic data) with a motor on each axis, its control cycle run at A150. A
//! control channel ([`Command`]) raises drive events and acknowledges
//! faults. `hil-sim serve --fieldbus profinet` runs
//! it on a raw interface (`cli/serve_pn.rs`).

use std::collections::VecDeque;

use crate::motor::{Motor, MotorOutputs};
use crate::sim::{axis_io, AxisConditions, SimFlash};
use drive_ecat::params::{E43, E82};
use drive_pn::Hardware;
use nanos::Nanos;
use profinet::cm::{CmEvent, Im0, ImData, RecordHook};
use profinet::dcp::server::Event as DcpEvent;
use profinet::dcp::{IpSuite, NameOfStation};
use profinet::device::{Device, DeviceEvent, RtEvent};
use profinet::model;
use profinet::rpc::uuid::Uuid;
use profinet::wire::MacAddr;

/// The serial number in the first simulated drive's I&M0 (the k-th is
/// [`serial_number`]`(k)`).
pub const SERIAL_NUMBER: &str = "SIM0001";

/// The serial number of drive `k` (0-based): SIM0001, SIM0002, …
pub fn serial_number(k: u16) -> String {
    format!("SIM{:04}", u32::from(k) + 1)
}

/// The interface MAC of drive `k` of a simulated line on an interface
/// with MAC `iface`: drive 0 has the interface's own, drive k > 0 a locally
/// administered variant (byte 0 | 0x02, byte 4 XOR k), never one of
/// another drive's port MACs ([`port_macs`] changes byte 5 only).
pub fn device_mac(iface: MacAddr, k: u16) -> MacAddr {
    if k == 0 {
        return iface;
    }
    let mut m = iface;
    m.0[0] |= 0x02;
    m.0[4] ^= (k & 0xFF) as u8;
    m.0[3] ^= (k >> 8) as u8;
    m
}

/// The port MACs for an interface MAC (LLDP sources): locally administered
/// variants of it (bit 1 of the first byte set, the last byte + port number),
/// never the interface MAC itself.
pub fn port_macs(mac: MacAddr) -> [MacAddr; model::PORTS as usize] {
    let mut out = [mac; model::PORTS as usize];
    for (port, m) in (1u8..).zip(out.iter_mut()) {
        m.0[0] |= 0x02;
        m.0[5] = mac.0[5].wrapping_add(port);
    }
    out
}

/// A MAC written as `aa:bb:cc:dd:ee:ff` (as `/sys/class/net/IF/address`).
pub fn parse_mac(s: &str) -> Option<MacAddr> {
    let mut mac = [0u8; 6];
    let mut parts = s.trim().split(':');
    for b in mac.iter_mut() {
        *b = u8::from_str_radix(parts.next()?, 16).ok()?;
    }
    parts.next().is_none().then_some(MacAddr(mac))
}

/// `aa:bb:cc:dd:ee:ff`.
pub fn mac_text(mac: MacAddr) -> String {
    let m = mac.0;
    format!(
        "{:02x}:{:02x}:{:02x}:{:02x}:{:02x}:{:02x}",
        m[0], m[1], m[2], m[3], m[4], m[5]
    )
}

fn uuid_text(u: &Uuid) -> String {
    let hex: String = u.0.iter().map(|b| format!("{b:02x}")).collect();
    let part = |r: core::ops::Range<usize>| hex.get(r).unwrap_or_default().to_string();
    format!(
        "{}-{}-{}-{}-{}",
        part(0..8),
        part(8..12),
        part(12..16),
        part(16..20),
        part(20..32)
    )
}

fn suite_text(s: &IpSuite) -> String {
    if *s == IpSuite::UNSET {
        return "unset".into();
    }
    format!("{} mask {} gateway {}", s.ip, s.mask, s.gateway)
}

fn kept(permanent: bool) -> &'static str {
    if permanent {
        "permanent"
    } else {
        "temporary"
    }
}

/// One line for a device event, e.g. `DCP name of station "drive-1"
/// (permanent)`, `AR 1234…: connected`, `AR 1234…: aborted (Local)`.
pub fn describe(e: &DeviceEvent) -> String {
    match e {
        DeviceEvent::Dcp(DcpEvent::NameOfStation { name, permanent }) => {
            format!("DCP name of station \"{}\" ({})", name.as_str(), kept(*permanent))
        }
        DeviceEvent::Dcp(DcpEvent::IpSuite { suite, permanent }) => {
            format!("DCP IP {} ({})", suite_text(suite), kept(*permanent))
        }
        DeviceEvent::Dcp(DcpEvent::Signal { until }) => {
            format!("DCP signal (flashing until {:.3} s)", until.as_ns() as f64 / 1e9)
        }
        DeviceEvent::Dcp(DcpEvent::ResetToFactory(mode)) => format!("DCP reset to factory ({mode:?})"),
        DeviceEvent::Cm(CmEvent::Connected(u)) => format!("AR {}: connected", uuid_text(u)),
        DeviceEvent::Cm(CmEvent::PrmEnd(u)) => format!("AR {}: PrmEnd", uuid_text(u)),
        DeviceEvent::Cm(CmEvent::Ready(u)) => {
            format!("AR {}: ready (ApplicationReady confirmed)", uuid_text(u))
        }
        DeviceEvent::Cm(CmEvent::Released(u)) => format!("AR {}: released", uuid_text(u)),
        DeviceEvent::Cm(CmEvent::Aborted(u, why)) => format!("AR {}: aborted ({why:?})", uuid_text(u)),
        DeviceEvent::Cm(CmEvent::ImWritten(r)) => format!("I&M written ({r:?})"),
        DeviceEvent::Rt(RtEvent::Exchanging(u)) => format!("AR {}: cyclic data exchanged", uuid_text(u)),
        DeviceEvent::Rt(RtEvent::DataHoldExpired(u)) => {
            format!(
                "AR {}: data hold expired (outputs no longer current)",
                uuid_text(u)
            )
        }
        DeviceEvent::Rt(RtEvent::ArLost(u)) => {
            format!("AR {}: lost (cyclic watchdog or alarm channel)", uuid_text(u))
        }
        DeviceEvent::SnmpChanged => "SNMP sysContact/sysName/sysLocation set (saved)".to_string(),
    }
}

/// The axis letters of the control channel.
const AXES: [char; 2] = ['A', 'B'];

/// Control cycles a fault acknowledgement holds controlword bit 7.
const ACK_CYCLES: u8 = 2;

/// A command of the simulator's control channel (`serve --control`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    /// Raise drive event `event` with `cause` on `axis` (0 = A, 1 = B), as
    /// the power stage or a monitoring function would.
    Fault {
        /// 0 = A, 1 = B.
        axis: usize,
        /// The E82 event number (HH).
        event: u8,
        /// The E43 cause (S, 0…15).
        cause: u8,
    },
    /// Acknowledge the fault of `axis`: controlword bit 7 (C-017), as the
    /// drive's own acknowledgement input would; while a controller sends
    /// CW1 the profile writes the controlword of axis A every cycle, and
    /// CW1 bit 7 is the acknowledgement there.
    Reset {
        /// 0 = A, 1 = B.
        axis: usize,
    },
    /// Report the axes' state.
    Status,
    /// Power the drive off and on again over the same parameter flash (what
    /// was saved comes back; what was not is lost).
    Restart,
}

impl Command {
    /// Parses one line: `fault A 44 1`, `reset B`, `status`.
    pub fn parse(line: &str) -> Result<Command, String> {
        let words: Vec<&str> = line.split_whitespace().collect();
        let axis = |w: Option<&&str>| -> Result<usize, String> {
            let w = w.ok_or("an axis (A or B) is missing")?;
            AXES.iter()
                .position(|c| w.eq_ignore_ascii_case(&c.to_string()))
                .ok_or_else(|| format!("{w:?} is no axis (A or B)"))
        };
        let number = |w: Option<&&str>, what: &str| -> Result<u8, String> {
            let w = w.ok_or_else(|| format!("the {what} is missing"))?;
            w.parse()
                .map_err(|_| format!("{what} {w:?} is not a number 0…255"))
        };
        match words.as_slice() {
            ["fault", rest @ ..] if rest.len() == 3 => {
                let cause = number(rest.get(2), "cause")?;
                if cause > 15 {
                    return Err(format!("cause {cause}: E43 causes are 0…15"));
                }
                Ok(Command::Fault {
                    axis: axis(rest.first())?,
                    event: number(rest.get(1), "event")?,
                    cause,
                })
            }
            ["reset", rest @ ..] if rest.len() == 1 => Ok(Command::Reset {
                axis: axis(rest.first())?,
            }),
            ["status"] => Ok(Command::Status),
            ["restart"] => Ok(Command::Restart),
            _ => Err(format!(
                "{:?}: commands are `fault A|B EVENT CAUSE`, `reset A|B`, `status`, `restart`",
                line.trim()
            )),
        }
    }
}

/// A simulated drive on PROFINET: the firmware's drive personality
/// ([`drive_pn::PnDrive`]: the device, the object dictionary, both axes, the
/// parameter store, the PROFIdrive profile on the cyclic data) with a motor
/// on each axis, its control cycle run at A150 on the caller's clock.
pub struct PnSim {
    drive: drive_pn::PnDrive<SimFlash>,
    motors: [Motor; 2],
    /// The axes' current loops on the PMSM plant (`set_plant`), or none:
    /// the rigid torque-in model.
    electrical: crate::plants::Plants,
    feedback: [Option<MotorOutputs>; 2],
    conditions: [AxisConditions; 2],
    /// When the next control cycle starts.
    next_cycle: Nanos,
    /// Control cycles run.
    cycles: u64,
    /// Cycles left that hold controlword bit 7 per axis.
    acknowledge: [u8; 2],
    /// The personality's events, oldest first.
    events: VecDeque<DeviceEvent>,
    /// What the drive was powered on with (a restart powers it on again).
    hw: Hardware,
}

crate::plants::plant_drive!(PnSim);

impl PnSim {
    /// A drive powered on over `flash` (empty: as shipped) on interface
    /// `mac`, started at `boot_time` (any value that differs after every
    /// start: the wall clock's seconds).
    pub fn power_on(flash: SimFlash, mac: MacAddr, boot_time: u32) -> PnSim {
        PnSim::power_on_as(flash, mac, SERIAL_NUMBER, boot_time)
    }

    /// [`power_on`](PnSim::power_on) with the serial number `serial` in
    /// I&M0.
    pub fn power_on_as(flash: SimFlash, mac: MacAddr, serial: &str, boot_time: u32) -> PnSim {
        let hw = Hardware {
            mac,
            port_macs: port_macs(mac),
            im0: Im0::drive(serial),
            im: ImData::default(),
            boot_time,
        };
        let mut drive = drive_pn::PnDrive::new(flash, hw.clone());
        // the scope over as many words as the EtherCAT drive's (the board's
        // 64 KiB of DSRAM2); kept for the drive's life and handed to the
        // next one at a restart
        drive.attach_scope(Vec::leak(vec![0; crate::sim::SCOPE_WORDS]));
        PnSim {
            drive,
            hw,
            motors: [Motor::default_servo(), Motor::default_servo()],
            electrical: crate::plants::Plants::default(),
            feedback: [None, None],
            conditions: [AxisConditions::READY; 2],
            next_cycle: Nanos::ZERO,
            cycles: 0,
            acknowledge: [0; 2],
            events: VecDeque::new(),
        }
    }

    /// A drive as shipped, except that its name of station is `name`
    /// (stored in A271 and saved, then powered on again: the name a
    /// commissioning tool left behind).
    pub fn named(mac: MacAddr, serial: &str, name: &NameOfStation, boot_time: u32) -> PnSim {
        let mut first = PnSim::power_on_as(SimFlash::new(), mac, serial, boot_time);
        if name.is_empty() {
            return first;
        }
        drive_pn::settings::write_name(first.drive.objects_mut(), name);
        first.drive.save();
        PnSim::power_on_as(first.drive.into_flash(), mac, serial, boot_time)
    }

    /// A drive as shipped, except that its name of station is `name` and
    /// its IP suite `ip` (both stored and saved, then powered on again: a
    /// drive a commissioning tool has named and addressed, ready for a
    /// controller's Connect without DCP).
    pub fn commissioned(
        mac: MacAddr,
        serial: &str,
        name: &NameOfStation,
        ip: IpSuite,
        boot_time: u32,
    ) -> PnSim {
        let mut first = PnSim::power_on_as(SimFlash::new(), mac, serial, boot_time);
        drive_pn::settings::write_name(first.drive.objects_mut(), name);
        drive_pn::settings::write_ip(first.drive.objects_mut(), ip);
        first.drive.save();
        PnSim::power_on_as(first.drive.into_flash(), mac, serial, boot_time)
    }

    /// The drive personality (objects, axes, store).
    pub fn drive(&self) -> &drive_pn::PnDrive<SimFlash> {
        &self.drive
    }

    /// The drive personality, mutable.
    pub fn drive_mut(&mut self) -> &mut drive_pn::PnDrive<SimFlash> {
        &mut self.drive
    }

    crate::plants::plant_methods!();

    /// The motor of `axis` (0 = A).
    pub fn motor(&self, axis: usize) -> Option<&Motor> {
        self.motors.get(axis)
    }

    /// The motor of `axis`, mutable (switches, end stops, index offset).
    pub fn motor_mut(&mut self, axis: usize) -> Option<&mut Motor> {
        self.motors.get_mut(axis)
    }

    /// The last step of the motor of `axis` (0 = A): position, torque,
    /// whether the holding brake acted; `None` before the first cycle.
    pub fn motor_outputs(&self, axis: usize) -> Option<&MotorOutputs> {
        self.feedback.get(axis).and_then(Option::as_ref)
    }

    /// The device (name, IP, AR, counters).
    pub fn device(&self) -> &Device<impl RecordHook> {
        self.drive.device()
    }

    /// Control cycles run so far.
    pub fn cycles(&self) -> u64 {
        self.cycles
    }

    /// The next event, oldest first.
    pub fn take_event(&mut self) -> Option<DeviceEvent> {
        self.events.pop_front()
    }

    /// One received frame at `now` (the control cycles due before it run
    /// first); answers go out through `tx`.
    pub fn receive(&mut self, now: Nanos, frame: &[u8], tx: &mut impl FnMut(&[u8])) {
        self.run_due_cycles(now);
        let events = &mut self.events;
        self.drive
            .receive(now, frame, tx, &mut |e| events.push_back(e.clone()));
    }

    /// The control cycles due at `now`, then the device's timers; returns
    /// when to call again at the latest (the next control cycle or the
    /// device's deadline).
    pub fn poll(&mut self, now: Nanos, tx: &mut impl FnMut(&[u8])) -> Nanos {
        self.run_due_cycles(now);
        let events = &mut self.events;
        let next = self.drive.poll(now, tx, &mut |e| events.push_back(e.clone()));
        next.min(self.next_cycle)
    }

    /// Carries out a control-channel command; returns what to print.
    pub fn command(&mut self, c: Command) -> String {
        match c {
            Command::Fault { axis, event, cause } => {
                let Some(a) = self.drive.axes_mut().get_mut(axis) else {
                    return format!("no axis {axis}");
                };
                a.raise_event(motion_event(event, cause));
                format!("axis {}: event {event} cause {cause} raised", axis_name(axis))
            }
            Command::Reset { axis } => {
                if let Some(n) = self.acknowledge.get_mut(axis) {
                    *n = ACK_CYCLES;
                }
                format!("axis {}: fault acknowledged (controlword bit 7)", axis_name(axis))
            }
            Command::Status => self.status(),
            Command::Restart => {
                let hw = Hardware {
                    boot_time: self.hw.boot_time.wrapping_add(1),
                    ..self.hw.clone()
                };
                let mut old = std::mem::replace(
                    &mut self.drive,
                    drive_pn::PnDrive::new(SimFlash::new(), hw.clone()),
                );
                let words = old.detach_scope();
                self.drive = drive_pn::PnDrive::new(old.into_flash(), hw.clone());
                if let Some(words) = words {
                    words.fill(0);
                    self.drive.attach_scope(words);
                }
                self.hw = hw;
                self.events.clear();
                "restarted over the same parameter flash".to_string()
            }
        }
    }

    /// The axes' state, E82/E43 and the device's diagnosis, one line.
    pub fn status(&self) -> String {
        let objects = self.drive.objects();
        let e82 = objects.get(E82, 0).unwrap_or(-1);
        let e43 = objects.get(E43, 0).unwrap_or(-1);
        let axes: Vec<String> = self
            .drive
            .axes()
            .iter()
            .enumerate()
            .map(|(i, a)| format!("axis {} {:?}", axis_name(i), a.state()))
            .collect();
        format!(
            "{}; E82 {e82} E43 {e43}; diagnosis {}",
            axes.join(", "),
            if self.device().diagnosis_present() {
                "present"
            } else {
                "none"
            }
        )
    }

    /// Runs every control cycle due at `now`, each at its own start time:
    /// the axes with the motors' last feedback, then one motor step each
    /// with the commanded torque.
    fn run_due_cycles(&mut self, now: Nanos) {
        // bounded: a clock jump cannot hang the simulation
        for _ in 0..100_000 {
            let t = self.next_cycle;
            if t > now {
                return;
            }
            self.acknowledge_step();
            let mut io = [
                axis_io(self.feedback[0].as_ref(), &self.motors[0], self.conditions[0]),
                axis_io(self.feedback[1].as_ref(), &self.motors[1], self.conditions[1]),
            ];
            // the current seam: the loops' measurement in, their commands down
            self.electrical.measure(&mut io);
            let commands = self.drive.control_cycle(t, &io);
            let period = self.drive.control_period();
            self.electrical.step(
                &mut self.motors,
                &mut self.feedback,
                commands,
                self.drive.axes(),
                self.drive.objects(),
                period,
            );
            if let Some(mv) = self.electrical.dc_link_mv() {
                drive_ecat::stage::set_dc_link_voltage(self.drive.objects_mut(), mv);
            }
            self.cycles += 1;
            self.next_cycle = t + period;
        }
        // far behind (the first call after a long pause): skip to now
        self.next_cycle = now;
    }

    /// Holds controlword bit 7 for [`ACK_CYCLES`] cycles after a reset
    /// command (the rising edge acknowledges, C-017), then clears it.
    fn acknowledge_step(&mut self) {
        for (axis, left) in self.acknowledge.iter_mut().enumerate() {
            if *left == 0 {
                continue;
            }
            *left -= 1;
            let word = if *left > 0 { 0x80 } else { 0x00 };
            let index = self.drive.axes().get(axis).map(|a| a.cia402_index(0x6040));
            if let Some(index) = index {
                let _ = self.drive.objects_mut().set(index, 0, word);
            }
        }
    }
}

fn axis_name(axis: usize) -> char {
    AXES.get(axis).copied().unwrap_or('?')
}

fn motion_event(event: u8, cause: u8) -> motion::Event {
    motion::Event {
        number: u16::from(event),
        cause,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn port_macs_are_locally_administered_variants_of_the_interface_mac() {
        let mac = MacAddr([0x00, 0x1b, 0x1b, 0x01, 0x02, 0xff]);
        let p = port_macs(mac);
        assert_eq!(p[0].0, [0x02, 0x1b, 0x1b, 0x01, 0x02, 0x00]);
        assert_eq!(p[1].0, [0x02, 0x1b, 0x1b, 0x01, 0x02, 0x01]);
        assert!(p.iter().all(|m| *m != mac));
    }

    #[test]
    fn p006_the_drives_of_a_line_have_distinct_interface_and_port_macs() {
        let iface = MacAddr([0x00, 0x1b, 0x1b, 0x01, 0x02, 0x03]);
        let mut all = Vec::new();
        for k in 0..300 {
            let m = device_mac(iface, k);
            all.push(m);
            all.extend(port_macs(m));
        }
        assert_eq!(device_mac(iface, 0), iface);
        let n = all.len();
        all.sort_by_key(|m| m.0);
        all.dedup();
        assert_eq!(all.len(), n, "a MAC is used twice");
        assert_eq!(serial_number(0), SERIAL_NUMBER);
        assert_eq!(serial_number(11), "SIM0012");
    }

    #[test]
    fn a_mac_is_read_as_sysfs_writes_it() {
        let mac = parse_mac("aa:bb:cc:0d:0e:0f\n").unwrap();
        assert_eq!(mac.0, [0xaa, 0xbb, 0xcc, 0x0d, 0x0e, 0x0f]);
        assert_eq!(mac_text(mac), "aa:bb:cc:0d:0e:0f");
        assert!(parse_mac("aa:bb:cc:0d:0e").is_none());
        assert!(parse_mac("aa:bb:cc:0d:0e:0f:10").is_none());
    }

    /// profinet-py's Identify All as it leaves a veth (unpadded, 30 bytes)
    /// with the response delay factor `delay`.
    fn identify_all(delay: u8) -> Vec<u8> {
        let mut f = vec![0u8; 30];
        f[..6].copy_from_slice(&MacAddr::DCP_IDENTIFY.0);
        f[6..12].copy_from_slice(&[0xca, 0xf2, 0xc5, 0xb6, 0x1f, 0x9b]);
        f[12..14].copy_from_slice(&0x8892u16.to_be_bytes());
        f[14..30].copy_from_slice(&[
            0xFE, 0xFE, 0x05, 0x00, 0x11, 0x97, 0xab, 0x50, 0x00, delay, 0x00, 0x04, 0xFF, 0xFF, 0x00, 0x00,
        ]);
        f
    }

    /// The DCP frames a fresh drive sends within 1.3 s of an Identify All.
    fn identify_answers(delay: u8) -> Vec<Vec<u8>> {
        let mac = MacAddr([0x02, 0, 0, 0, 0, 0x42]);
        let mut d = PnSim::power_on(SimFlash::new(), mac, 7);
        assert!(d.device().dcp().name_of_station().is_empty());
        assert_eq!(d.device().dcp().ip_suite(), IpSuite::UNSET);
        let mut out = Vec::new();
        d.receive(Nanos::ZERO, &identify_all(delay), &mut |b: &[u8]| {
            out.push(b.to_vec())
        });
        let next = d.poll(Nanos::ZERO, &mut |b: &[u8]| out.push(b.to_vec()));
        d.poll(next, &mut |b: &[u8]| out.push(b.to_vec()));
        d.poll(Nanos::from_ms(1300), &mut |b: &[u8]| out.push(b.to_vec()));
        out.retain(|b| b[6..12] == mac.0 && b[12..16] == [0x88, 0x92, 0xFE, 0xFF]);
        out
    }

    #[test]
    fn a_fresh_drive_answers_identify_at_once() {
        assert_eq!(identify_answers(1).len(), 1);
    }

    /// profinet-py asks with response delay factor 0x80 (up to 1.28 s): the
    /// delayed answer (140 bytes for the unnamed drive) is kept whole and
    /// sent when due.
    #[test]
    fn p008_a_fresh_drive_answers_a_delayed_identify() {
        assert_eq!(identify_answers(0x80).len(), 1);
    }

    #[test]
    fn control_commands_parse_and_bad_ones_say_why() {
        assert_eq!(
            Command::parse("fault A 44 1"),
            Ok(Command::Fault {
                axis: 0,
                event: 44,
                cause: 1
            })
        );
        assert_eq!(Command::parse(" reset b\n"), Ok(Command::Reset { axis: 1 }));
        assert_eq!(Command::parse("status"), Ok(Command::Status));
        for bad in [
            "fault C 44 1",
            "fault A 44 16",
            "fault A x 1",
            "reset",
            "fault A 44",
            "jump",
        ] {
            assert!(Command::parse(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn c144_the_simulated_drive_runs_its_control_cycle_at_a150() {
        let mut d = PnSim::power_on(SimFlash::new(), MacAddr([2, 0, 0, 0, 0, 1]), 7);
        d.poll(Nanos::from_ms(100), &mut |_: &[u8]| {});
        assert_eq!(d.cycles(), 101, "0, 1, …, 100 ms");
    }

    /// A drive event raised through the control channel faults the axis
    /// and shows as the drive's diagnosis (E82/E43 set); the reset command
    /// clears both. (Without an AR no alarm goes out: the diagnosis is
    /// kept for the records.)
    #[test]
    fn p030_p035_a_control_channel_fault_is_a_diagnosis_until_its_reset() {
        let mut d = PnSim::power_on(SimFlash::new(), MacAddr([2, 0, 0, 0, 0, 1]), 7);
        let mut t = 0;
        let mut run = |d: &mut PnSim, ms: u64| {
            t += ms;
            d.poll(Nanos::from_ms(t), &mut |_: &[u8]| {});
        };
        run(&mut d, 10);
        assert!(!d.device().diagnosis_present());
        d.command(Command::parse("fault B 44 1").unwrap());
        run(&mut d, 10);
        assert!(d.drive().axes()[1].state().is_fault(), "{}", d.status());
        assert!(!d.drive().axes()[0].state().is_fault());
        assert!(d.device().diagnosis_present());
        assert_eq!(d.drive().objects().get(E82, 0).unwrap(), 44);
        assert_eq!(d.drive().objects().get(E43, 0).unwrap(), 1);
        d.command(Command::parse("reset B").unwrap());
        run(&mut d, 10);
        assert!(!d.drive().axes()[1].state().is_fault(), "{}", d.status());
        assert!(!d.device().diagnosis_present(), "{}", d.status());
    }

    #[test]
    fn p007_a_named_simulated_drive_starts_with_its_stored_name() {
        let name: NameOfStation = "drive-7".parse().unwrap();
        let d = PnSim::named(MacAddr([2, 0, 0, 0, 0, 1]), SERIAL_NUMBER, &name, 7);
        assert_eq!(d.device().dcp().name_of_station().as_str(), "drive-7");
    }
}
