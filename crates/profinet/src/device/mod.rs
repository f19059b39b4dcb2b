//! The PROFINET IO device as one sans-IO value: every protocol of the crate
//! behind one frame input and one timer.
//!
//! ```text
//!  frame ──▶ Device::receive ─┬─ 0x8892 ─ FrameID ─┬─ DCP ──────────▶ dcp::DcpServer
//!                             │                    ├─ cyclic ───────▶ rt (consumer)
//!                             │                    ├─ alarm ────────▶ alarm (RTA)
//!                             │                    └─ other: dropped, counted
//!                             ├─ ARP / IPv4 ─▶ ip::Stack ─ UDP 34964 ─▶ rpc::Server ─▶ cm::Cm
//!                             └─ LLDP ─▶ the neighbour's alias for DCP
//!  Device::poll(now) ─▶ delayed DCP answers, RPC responses and the device's own
//!                       calls (ApplicationReady), LLDP every 5 s, rt provider,
//!                       watchdog, alarm retransmission; returns the next deadline
//! ```
//!
//! Frames go out through a `tx: &mut impl FnMut(&[u8])` the caller passes to
//! each call; what the application must act on (a name or IP to persist, a
//! DCP Signal, an AR established or lost, an I&M write) comes out of
//! [`Device::take_event`]. Time is an argument; nothing here reads a clock.

use heapless::{Deque, Vec};
use nanos::Nanos;

use crate::alarm::{AbortCode, AlarmEvent, DriveError, Location, Maintenance, Output, Priority};
use crate::cm::{Cm, CmConfig, CmEvent, Im0, ImData, NoRecords, RecordHook};
use crate::dcp::server::{DcpServer, Event as DcpEvent, Identity};
use crate::dcp::{IpSuite, NameOfStation};
use crate::ip::{IpConfig, Received, Stack, UdpTx, RPC_PORT, UDP_PAYLOAD_OFFSET};
use crate::led::LedInputs;
use crate::lldp::{self, Schedule};
use crate::model;
use crate::pdev::{Mismatch, Pdev, Peer};
use crate::rpc::epm::{self, EpmInfo};
use crate::rpc::server::{Server, ServerConfig};
use crate::rpc::uuid;
use crate::rpc::uuid::Uuid;
use crate::rt::ConsumerEvent;
use crate::wire::{ethertype, split_frame_id, EthFrame, FrameKind, MacAddr};

mod cyclic;
mod snmp_port;
#[cfg(test)]
mod tests;

use cyclic::Cyclic;
pub use cyclic::{MAX_MODULES, MAX_MODULE_BYTES};

/// The largest frame the device sends or accepts (without FCS, with a VLAN tag).
pub const MAX_FRAME: usize = 1518;
/// Events kept for the application between two [`Device::take_event`] drains.
pub const MAX_DEVICE_EVENTS: usize = 16;
/// Diagnoses the device keeps at once.
pub const MAX_DIAGNOSES: usize = 16;

/// What the device starts with (from the parameter store and the production data).
#[derive(Clone, Debug)]
pub struct DeviceConfig {
    /// The interface MAC (DCP, IP, RT).
    pub mac: MacAddr,
    /// The port MACs (LLDP sources, P-006).
    pub port_macs: [MacAddr; model::PORTS as usize],
    /// The stored name of station (P-007; empty: none).
    pub name: NameOfStation,
    /// The stored IP suite (P-010; unset: none).
    pub ip: IpSuite,
    /// I&M0 (identity).
    pub im0: Im0,
    /// The stored I&M1–4.
    pub im: ImData,
    /// The RPC server boot time: different after every start (a boot counter).
    pub boot_time: u32,
}

/// What the application must act on.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DeviceEvent {
    /// DCP changed the name or IP (persist or clear), signalled, or reset.
    Dcp(DcpEvent),
    /// Connection management: an AR established, ready, released, aborted; an
    /// I&M record written.
    Cm(CmEvent),
    /// The real-time side of the AR.
    Rt(RtEvent),
    /// An SNMP set changed sysContact, sysName or sysLocation (persist them, P-038).
    SnmpChanged,
}

/// What the cyclic and alarm channels report.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RtEvent {
    /// The first valid output frame arrived: cyclic data is exchanged.
    Exchanging(Uuid),
    /// No valid output frame for the data hold time: the outputs are no
    /// longer current (substitute values; spec Q-07, docs/conformance.md).
    DataHoldExpired(Uuid),
    /// The AR is lost: the output CR's watchdog expired (no frame for
    /// WatchdogFactor cycles), the alarm channel gave up, or the controller
    /// sent an RTA error. The drive raises its communication fault (Q-07).
    ArLost(Uuid),
}

/// Frames the device did not take, by reason.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DeviceCounters {
    /// Shorter than an Ethernet header.
    pub runt: u32,
    /// For another unicast MAC.
    pub not_for_us: u32,
    /// PROFINET frames with a FrameID this device does not serve.
    pub unknown_frame_id: u32,
    /// Cyclic or alarm frames without an AR that owns their FrameID.
    pub no_ar: u32,
    /// Other EtherTypes.
    pub other_ethertype: u32,
    /// Events lost because the application did not drain them.
    pub events_lost: u32,
}

/// The PROFINET IO device. See the [module documentation](self).
pub struct Device<H: RecordHook = NoRecords> {
    dcp: DcpServer,
    ip: Stack,
    rpc: Server,
    cm: Cm<H>,
    lldp: Schedule,
    lldp_stats: lldp::Stats,
    port_macs: [MacAddr; model::PORTS as usize],
    /// A delayed DCP Identify answer and when to send it.
    identify: Option<(Nanos, Vec<u8, 1500>)>,
    events: Deque<DeviceEvent, MAX_DEVICE_EVENTS>,
    counters: DeviceCounters,
    started: bool,
    cyclic: Option<Cyclic>,
    watchdog_expired: bool,
    snmp: snmp::Agent,
}

/// The SNMP agent's UDP port (P-038).
pub const SNMP_PORT: u16 = 161;

fn ip_config(s: IpSuite) -> IpConfig {
    IpConfig {
        addr: s.ip,
        netmask: s.mask,
        gateway: s.gateway,
    }
}

fn epm_info(ip: IpSuite) -> EpmInfo {
    EpmInfo {
        object: uuid::pnio_object(1, model::DEVICE_ID, model::VENDOR_ID),
        ip: ip.ip,
        port: RPC_PORT,
        annotation: epm::annotation(
            model::STATION_TYPE,
            model::ORDER_NUMBER,
            model::HARDWARE_REVISION,
            model::SOFTWARE_REVISION,
        ),
    }
}

impl<H: RecordHook> Device<H> {
    /// A device with its stored settings and the profile's record hook.
    pub fn new(config: DeviceConfig, hook: H) -> Device<H> {
        let name = config.name.clone();
        Device {
            dcp: DcpServer::new(config.mac, Identity::DRIVE, config.name, config.ip),
            ip: Stack::new(config.mac, ip_config(config.ip)),
            rpc: Server::new(ServerConfig {
                boot_time: config.boot_time,
                epm: epm_info(config.ip),
            }),
            cm: Cm::new(
                CmConfig {
                    mac: config.mac,
                    im0: config.im0,
                },
                config.im,
                hook,
            ),
            lldp: Schedule::default(),
            lldp_stats: lldp::Stats::default(),
            port_macs: config.port_macs,
            identify: None,
            events: Deque::new(),
            counters: DeviceCounters::default(),
            started: false,
            cyclic: None,
            watchdog_expired: false,
            snmp: snmp::Agent::default(),
        }
        .with_pdev(config.port_macs, name, config.ip)
    }

    fn with_pdev(
        mut self,
        port_macs: [MacAddr; model::PORTS as usize],
        name: NameOfStation,
        ip: IpSuite,
    ) -> Self {
        let mac = self.dcp.mac();
        *self.cm.pdev_mut() = Pdev::new(mac, port_macs, name, ip);
        self
    }

    /// The DCP server (name, IP, signal).
    pub fn dcp(&self) -> &DcpServer {
        &self.dcp
    }

    /// The IP stack (addresses, counters).
    pub fn ip(&self) -> &Stack {
        &self.ip
    }

    /// Connection management (the AR, I&M).
    pub fn cm(&self) -> &Cm<H> {
        &self.cm
    }

    /// Replaces I&M1…4 (a reset to factory clears them).
    pub fn set_im_data(&mut self, im: crate::cm::ImData) {
        self.cm.set_im_data(im);
    }

    /// The RPC server (counters).
    pub fn rpc(&self) -> &Server {
        &self.rpc
    }

    /// The record hook of the profile.
    pub fn hook(&self) -> &H {
        self.cm.hook()
    }

    /// The record hook of the profile, mutable.
    pub fn hook_mut(&mut self) -> &mut H {
        self.cm.hook_mut()
    }

    /// Frames dropped, by reason.
    pub fn counters(&self) -> &DeviceCounters {
        &self.counters
    }

    /// The next event for the application, oldest first.
    pub fn take_event(&mut self) -> Option<DeviceEvent> {
        self.events.pop_front()
    }

    fn push(&mut self, e: DeviceEvent) {
        if self.events.push_back(e).is_err() {
            self.counters.events_lost = self.counters.events_lost.saturating_add(1);
        }
    }

    /// Takes one received Ethernet frame (without FCS) at `now`; answers due
    /// at once go out through `tx`.
    pub fn receive(&mut self, now: Nanos, frame: &[u8], tx: &mut impl FnMut(&[u8])) {
        let mut sent = 0usize;
        let mut counted = |f: &[u8]| {
            sent = sent.wrapping_add(f.len());
            tx(f);
        };
        self.cm
            .pdev_mut()
            .count_in(frame.len(), EthFrame::parse(frame).is_none());
        self.receive_frame(now, frame, &mut counted);
        self.cm.pdev_mut().count_out(sent);
    }

    fn receive_frame(&mut self, now: Nanos, frame: &[u8], tx: &mut impl FnMut(&[u8])) {
        let Some(f) = EthFrame::parse(frame) else {
            self.counters.runt = self.counters.runt.saturating_add(1);
            return;
        };
        if !f.dst.is_multicast() && f.dst != self.dcp.mac() {
            self.counters.not_for_us = self.counters.not_for_us.saturating_add(1);
            return;
        }
        match f.ethertype {
            ethertype::PROFINET => self.profinet(now, &f, tx),
            ethertype::ARP | ethertype::IPV4 => self.ip_frame(now, frame, tx),
            ethertype::LLDP => {
                let n = lldp::Neighbor::parse(&f);
                let mut inserted = false;
                if let Some(n) = &n {
                    let mut alias = Vec::new();
                    if n.alias(&mut alias).is_some() {
                        self.dcp.set_alias(0, Some(&alias));
                    }
                    // one receive path: the neighbour is port 1's (P-040)
                    if let Some(p) = self.cm.pdev_mut().port_mut(1) {
                        let had = p.peer.is_some();
                        p.peer = Peer::from_lldp(n, f.src, now);
                        inserted = !had && p.peer.is_some();
                    }
                }
                self.lldp_stats.received(1, f.payload, n.is_some(), inserted, now);
            }
            _ => self.counters.other_ethertype = self.counters.other_ethertype.saturating_add(1),
        }
        self.drain_rpc(now, tx);
    }

    fn profinet(&mut self, now: Nanos, f: &EthFrame<'_>, tx: &mut impl FnMut(&[u8])) {
        let Some((kind, _rest)) = split_frame_id(f.payload) else {
            self.counters.runt = self.counters.runt.saturating_add(1);
            return;
        };
        match kind {
            FrameKind::DcpIdentifyRequest | FrameKind::DcpGetSet => {
                let mut out = [0u8; 1500];
                let outcome = self.dcp.handle(now, f, &mut out);
                if let Some(reply) = outcome.reply {
                    let bytes = out.get(..reply.len).unwrap_or(&[]);
                    if reply.send_at <= now {
                        tx(bytes);
                    } else if let Ok(v) = Vec::from_slice(bytes) {
                        // a later Identify replaces the pending answer
                        self.identify = Some((reply.send_at, v));
                    }
                }
                // popped from the front in order: a by-value `for` over the
                // heapless Vec carries an index panic in its iterator's drop
                let mut events = outcome.events;
                events.reverse();
                while let Some(e) = events.pop() {
                    self.on_dcp_event(now, &e, tx);
                    self.push(DeviceEvent::Dcp(e));
                }
            }
            FrameKind::DcpHello | FrameKind::DcpIdentifyResponse => {}
            FrameKind::Cyclic(_) => self.cyclic_frame(now, f),
            FrameKind::AlarmHigh | FrameKind::AlarmLow => {
                let got = self
                    .cyclic
                    .as_mut()
                    .and_then(|c| c.alarm.as_mut())
                    .map(|a| a.receive(now, f));
                match got {
                    None => self.counters.no_ar = self.counters.no_ar.saturating_add(1),
                    Some(Ok(Some(e))) => self.on_alarm_event(e),
                    // refused frames are counted by the alarm CR
                    Some(_) => {}
                }
                self.run_alarms(now, tx);
            }
            FrameKind::Other(_) => {
                self.counters.unknown_frame_id = self.counters.unknown_frame_id.saturating_add(1);
            }
        }
    }

    pub(crate) fn on_dcp_event(&mut self, now: Nanos, e: &DcpEvent, tx: &mut impl FnMut(&[u8])) {
        match e {
            DcpEvent::IpSuite { suite, .. } => {
                self.cm.pdev_mut().ip = *suite;
                self.ip.set_config(ip_config(*suite));
                let mut cfg = *self.rpc.config();
                cfg.epm = epm_info(*suite);
                self.rpc.set_config(cfg);
                let mut out = [0u8; 64];
                if let Some(n) = self.ip.emit_gratuitous_arp(&mut out) {
                    tx(out.get(..n).unwrap_or(&[]));
                }
                self.lldp.kick(now);
            }
            DcpEvent::NameOfStation { name, .. } => {
                self.cm.pdev_mut().name = name.clone();
                self.lldp.kick(now);
            }
            DcpEvent::Signal { .. } | DcpEvent::ResetToFactory(_) => {}
        }
    }

    fn ip_frame(&mut self, now: Nanos, frame: &[u8], tx: &mut impl FnMut(&[u8])) {
        let mut out = [0u8; MAX_FRAME];
        match self.ip.receive(now, frame, &mut out) {
            Received::Replied(n) => tx(out.get(..n).unwrap_or(&[])),
            Received::Rpc(dg) => self.rpc.receive(now, dg.src, dg.payload, &mut self.cm),
            Received::Udp(dg) if dg.dst_port == SNMP_PORT => self.snmp_request(now, dg.src, dg.payload, tx),
            Received::Consumed | Received::Udp(_) | Received::Dropped(_) => {}
        }
    }

    /// Sends what the RPC server has queued and takes connection events.
    fn drain_rpc(&mut self, now: Nanos, tx: &mut impl FnMut(&[u8])) {
        self.rpc.poll(now, &mut self.cm);
        let mut out = [0u8; MAX_FRAME];
        loop {
            let payload = out.get_mut(UDP_PAYLOAD_OFFSET..).unwrap_or(&mut []);
            let Some((to, n)) = self.rpc.transmit(now, payload) else {
                break;
            };
            match self.ip.emit_udp(now, &mut out, RPC_PORT, to, n) {
                Ok(UdpTx::Frame(len)) | Ok(UdpTx::ArpRequest(len)) => tx(out.get(..len).unwrap_or(&[])),
                // no address or route: the RPC layer's retries try again
                Err(_) => {}
            }
        }
        while let Some(e) = self.cm.poll_event() {
            match e {
                CmEvent::Connected(uuid) => {
                    self.dcp.set_in_operation(true);
                    let cyclic = self
                        .cm
                        .ar()
                        .filter(|ar| ar.ar_uuid == uuid)
                        .map(|ar| Cyclic::new(ar, self.dcp.mac(), now));
                    self.cm
                        .diag
                        .set_alarms(cyclic.as_ref().is_some_and(|c| c.alarm.is_some()));
                    self.watchdog_expired = false;
                    self.cyclic = cyclic;
                }
                CmEvent::Released(uuid) | CmEvent::Aborted(uuid, _) => {
                    self.dcp.set_in_operation(self.cm.ar().is_some());
                    if self.cyclic.as_ref().is_some_and(|c| c.ar == uuid) {
                        self.cyclic = None;
                        self.cm.diag.set_alarms(false);
                    }
                }
                _ => {}
            }
            self.push(DeviceEvent::Cm(e));
        }
    }

    /// Runs the timers at `now`: delayed DCP answers, RPC (the device's own
    /// ApplicationReady call and its retries), LLDP. Returns when to call
    /// again at the latest.
    pub fn poll(&mut self, now: Nanos, tx: &mut impl FnMut(&[u8])) -> Nanos {
        let mut sent = 0usize;
        let mut counted = |f: &[u8]| {
            sent = sent.wrapping_add(f.len());
            tx(f);
        };
        let next = self.poll_timers(now, &mut counted);
        self.cm.pdev_mut().count_out(sent);
        next
    }

    fn poll_timers(&mut self, now: Nanos, tx: &mut impl FnMut(&[u8])) -> Nanos {
        if !self.started {
            self.started = true;
            self.lldp.kick(now);
        }
        if let Some((at, _)) = &self.identify {
            if *at <= now {
                if let Some((_, frame)) = self.identify.take() {
                    tx(&frame);
                }
            }
        }
        let aged = self.cm.pdev_mut().expire(now);
        self.lldp_stats.aged_out(aged, now);
        // one port's LLDPDU per poll (≈ 2,700 instructions each on the
        // M4F): the poll that also sends the cyclic frame stays within twice
        // its usual length (issue 36); a second port due goes out with the
        // next poll, which the returned deadline (now) asks for at once
        while let Some(port) = self.lldp.due(now) {
            self.lldp.sent(port, now);
            if !self.cm.pdev().lldp_allowed(port) {
                // stopped by the controller's peer-to-peer boundary
                continue;
            }
            let station = lldp::Station {
                name: self.dcp.name_of_station(),
                interface_mac: self.dcp.mac(),
                ip: Some(self.dcp.ip_suite().ip).filter(|ip| !ip.is_unspecified()),
                port_id_form: crate::pdev::interface::port_id_form(self.cm.pdev().interface_mode),
            };
            let mut out = [0u8; 512];
            if let Some(n) = lldp::build_frame(&station, port, &self.lldp_port_info(port), &mut out) {
                tx(out.get(..n).unwrap_or(&[]));
                self.cm.pdev_mut().count_lldp(port, n);
                self.lldp_stats.sent(port);
            }
            break;
        }
        self.check_topology();
        self.drain_rpc(now, tx);
        self.run_cyclic(now, tx);
        self.run_alarms(now, tx);
        let mut next = now.saturating_add(Nanos::from_ms(100));
        if let Some(c) = &self.cyclic {
            if let Some(p) = &c.provider {
                next = next.min(p.poll_at());
            }
            if let Some(k) = &c.consumer {
                next = next.min(k.poll_at());
            }
            if let Some(a) = &c.alarm {
                next = next.min(a.poll_at(now));
            }
        }
        if let Some(t) = self.lldp.next_deadline() {
            next = next.min(t);
        }
        if let Some((t, _)) = &self.identify {
            next = next.min(*t);
        }
        next.max(now)
    }
}

impl<H: RecordHook> Device<H> {
    /// A drive error HH-S appears (P-030): a diagnosis alarm goes to the
    /// controller when an AR with an alarm CR runs; the diagnosis records and
    /// the station-problem bit show it in any case. `false` if HH-S is out of
    /// range or the list is full.
    pub fn raise_diagnosis(&mut self, main: u8, sub: u8) -> bool {
        let Some(e) = DriveError::new(main, sub) else {
            return false;
        };
        self.cm
            .diag
            .raise(Cyclic::drive_location(), e, Maintenance::Fault, 0)
            .is_ok()
    }

    /// The ports' topology against their PDPortDataCheck (P-040): each
    /// difference is a diagnosis on the port's subslot (an "appears" alarm in
    /// an AR), gone ("disappears") once the neighbour, MAU type or link
    /// matches again or the check is withdrawn.
    fn check_topology(&mut self) {
        for port in 1..=model::PORTS {
            let loc = Location {
                api: 0,
                slot: 0,
                subslot: 0x8000 | port,
                module_ident: model::DAP_MODULE_IDENT,
                submodule_ident: model::port_submodule_ident(port),
            };
            for kind in Mismatch::ALL {
                let (t, x) = kind.error_types();
                let e = DriveError::port(t, x);
                if self.cm.pdev().mismatch(port, kind) {
                    let _ = self.cm.diag.raise(loc, e, Maintenance::Fault, 0);
                } else {
                    self.cm.diag.clear(&loc, e);
                }
            }
        }
    }

    /// The drive error HH-S is gone (acknowledged, P-035): a "disappears"
    /// alarm follows.
    pub fn clear_diagnosis(&mut self, main: u8, sub: u8) -> bool {
        DriveError::new(main, sub).is_some_and(|e| self.cm.diag.clear(&Cyclic::drive_location(), e))
    }

    /// The alarm channel's counters of the AR in data exchange (sent,
    /// retransmitted, acknowledged), `None` without one.
    pub fn alarm_stats(&self) -> Option<crate::alarm::AlarmStats> {
        self.cyclic
            .as_ref()
            .and_then(|c| c.alarm.as_ref())
            .map(|a| *a.stats())
    }

    /// Whether any diagnosis is present.
    pub fn diagnosis_present(&self) -> bool {
        self.cm.diag.any_present()
    }

    /// Whether an AR exchanges valid cyclic data now.
    pub fn exchanging(&self) -> bool {
        self.cyclic.as_ref().is_some_and(|c| c.outputs_valid)
    }

    /// The link state of every port (LED BF, P-023; PDPortDataReal, P-040);
    /// the board or simulator sets it.
    pub fn set_link(&mut self, up: bool) {
        for p in 1..=model::PORTS {
            self.set_port_link(p, up);
        }
    }

    /// The link state of port `port` (1-based). At start port 1 is up and
    /// port 2 down (the simulator has one interface).
    pub fn set_port_link(&mut self, port: u16, up: bool) {
        if let Some(p) = self.cm.pdev_mut().port_mut(port) {
            if !up {
                p.peer = None;
            }
            p.link_up = up;
        }
    }

    /// The SF and BF LEDs at `now` (P-011, P-020…P-024): `(sf_lit, bf_lit)`.
    pub fn leds(&self, now: Nanos) -> (bool, bool) {
        let signal = self.dcp.signal();
        let inputs = LedInputs {
            link_up: self.cm.pdev().any_link_up(),
            ar_established: self.cyclic.is_some(),
            cyclic_exchange: self.exchanging(),
            watchdog_expired: self.watchdog_expired,
            diagnosis: self.cm.diag.any_present(),
            system_error: false,
            dcp_signal_until: signal.until(now),
        };
        (inputs.sf_lit(now), inputs.bf_lit(now))
    }

    fn cyclic_frame(&mut self, now: Nanos, f: &EthFrame<'_>) {
        let Some(c) = self.cyclic.as_mut() else {
            self.counters.no_ar = self.counters.no_ar.saturating_add(1);
            return;
        };
        let Some(consumer) = c.consumer.as_mut() else {
            self.counters.no_ar = self.counters.no_ar.saturating_add(1);
            return;
        };
        // a refused frame is counted by the consumer and changes nothing
        let Ok(r) = consumer.receive(now, f) else {
            return;
        };
        match r.outputs {
            Ok(data) => {
                for m in c.outputs.iter_mut() {
                    if let Some(d) = data.data(m.slot, 1) {
                        for (o, i) in m.data.iter_mut().zip(d) {
                            *o = *i;
                        }
                    }
                }
                let first = !c.outputs_valid && c.consumer.as_ref().is_some_and(|k| k.stats().accepted == 1);
                c.outputs_valid = true;
                if first {
                    let ar = c.ar;
                    self.push(DeviceEvent::Rt(RtEvent::Exchanging(ar)));
                }
            }
            Err(_) => c.outputs_valid = false,
        }
    }

    fn lose_ar(&mut self, code: Option<AbortCode>) {
        let Some(c) = self.cyclic.as_mut() else {
            return;
        };
        let ar = c.ar;
        if let (Some(a), Some(code)) = (c.alarm.as_mut(), code) {
            // the ERR-RTA-PDU goes out with the next alarm poll
            a.abort(code);
        }
        c.consumer = None;
        c.provider = None;
        c.outputs_valid = false;
        c.lost = true;
        self.watchdog_expired = true;
        self.cm.abort(ar);
        self.push(DeviceEvent::Rt(RtEvent::ArLost(ar)));
    }

    fn on_alarm_event(&mut self, e: AlarmEvent) {
        match e {
            AlarmEvent::Acked {
                priority: Priority::Low,
                ..
            } => self.cm.diag.acked(),
            AlarmEvent::Acked { .. } => {}
            AlarmEvent::Abort(_) | AlarmEvent::ErrReceived(_) => self.lose_ar(None),
        }
    }

    fn run_cyclic(&mut self, now: Nanos, tx: &mut impl FnMut(&[u8])) {
        let event = self
            .cyclic
            .as_mut()
            .and_then(|c| c.consumer.as_mut())
            .and_then(|k| k.poll(now));
        match event {
            Some(ConsumerEvent::WatchdogExpired) => self.lose_ar(ConsumerEvent::WatchdogExpired.abort_code()),
            Some(ConsumerEvent::DataHoldExpired) => {
                if let Some(c) = self.cyclic.as_mut() {
                    c.outputs_valid = false;
                    let ar = c.ar;
                    self.push(DeviceEvent::Rt(RtEvent::DataHoldExpired(ar)));
                }
            }
            None => {}
        }
        let problem = self.cm.diag.any_present();
        let Some(c) = self.cyclic.as_mut() else {
            return;
        };
        let Some(p) = c.provider.as_mut() else {
            return;
        };
        p.set_station_problem(problem);
        let mut buf = [0u8; MAX_FRAME];
        if let Ok(Some(mut frame)) = p.poll(now, &mut buf) {
            for m in &c.inputs {
                frame.set_data(m.slot, 1, &m.data);
            }
            tx(frame.bytes());
        }
    }

    fn run_alarms(&mut self, now: Nanos, tx: &mut impl FnMut(&[u8])) {
        if self.cyclic.as_ref().is_some_and(|c| c.alarm_free()) {
            if let Some(n) = self.cm.diag.next_alarm() {
                let sent = self
                    .cyclic
                    .as_mut()
                    .and_then(|c| c.alarm.as_mut())
                    .is_some_and(|a| a.send(now, &n).is_ok());
                if sent {
                    self.cm.diag.sent();
                }
            }
        }
        let mut buf = [0u8; MAX_FRAME];
        while let Some(out) = self
            .cyclic
            .as_mut()
            .and_then(|c| c.alarm.as_mut())
            .and_then(|a| a.poll(now, &mut buf))
        {
            match out {
                Output::Frame(n) => tx(buf.get(..n).unwrap_or(&[])),
                Output::Event(e) => self.on_alarm_event(e),
            }
        }
        // an alarm CR that closed (after its ERR PDU) ends the AR's RT side
        if self
            .cyclic
            .as_ref()
            .is_some_and(|c| c.lost && c.alarm.as_ref().is_none_or(|a| a.is_closed()))
        {
            self.cyclic = None;
            self.cm.diag.set_alarms(false);
        }
    }
}

impl Device<NoRecords> {
    /// A device without profile records.
    pub fn plain(config: DeviceConfig) -> Device<NoRecords> {
        Device::new(config, NoRecords)
    }
}
