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

use crate::cm::{Cm, CmConfig, CmEvent, Im0, ImData, NoRecords, RecordHook};
use crate::dcp::server::{DcpServer, Event as DcpEvent, Identity};
use crate::dcp::{IpSuite, NameOfStation};
use crate::ip::{IpConfig, Received, Stack, UdpTx, RPC_PORT, UDP_PAYLOAD_OFFSET};
use crate::lldp::{self, PortIdForm, PortInfo, Schedule};
use crate::model;
use crate::rpc::epm::{self, EpmInfo};
use crate::rpc::server::{Server, ServerConfig};
use crate::rpc::uuid;
use crate::wire::{ethertype, split_frame_id, EthFrame, FrameKind, MacAddr};

#[cfg(test)]
mod tests;

/// The largest frame the device sends or accepts (without FCS, with a VLAN tag).
pub const MAX_FRAME: usize = 1518;
/// Events kept for the application between two [`Device::take_event`] drains.
pub const MAX_DEVICE_EVENTS: usize = 16;

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
    port_macs: [MacAddr; model::PORTS as usize],
    /// A delayed DCP Identify answer and when to send it.
    identify: Option<(Nanos, Vec<u8, 128>)>,
    events: Deque<DeviceEvent, MAX_DEVICE_EVENTS>,
    counters: DeviceCounters,
    started: bool,
}

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
            port_macs: config.port_macs,
            identify: None,
            events: Deque::new(),
            counters: DeviceCounters::default(),
            started: false,
        }
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

    /// The RPC server (counters).
    pub fn rpc(&self) -> &Server {
        &self.rpc
    }

    /// The record hook of the profile.
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
                if let Some(n) = lldp::Neighbor::parse(&f) {
                    let mut alias = Vec::new();
                    if n.alias(&mut alias).is_some() {
                        self.dcp.set_alias(0, Some(&alias));
                    }
                }
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
                for e in outcome.events {
                    self.on_dcp_event(now, &e, tx);
                    self.push(DeviceEvent::Dcp(e));
                }
            }
            FrameKind::DcpHello | FrameKind::DcpIdentifyResponse => {}
            FrameKind::Cyclic(_) | FrameKind::AlarmHigh | FrameKind::AlarmLow => {
                self.counters.no_ar = self.counters.no_ar.saturating_add(1);
            }
            FrameKind::Other(_) => {
                self.counters.unknown_frame_id = self.counters.unknown_frame_id.saturating_add(1);
            }
        }
    }

    fn on_dcp_event(&mut self, now: Nanos, e: &DcpEvent, tx: &mut impl FnMut(&[u8])) {
        match e {
            DcpEvent::IpSuite { suite, .. } => {
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
            DcpEvent::NameOfStation { .. } => self.lldp.kick(now),
            DcpEvent::Signal { .. } | DcpEvent::ResetToFactory(_) => {}
        }
    }

    fn ip_frame(&mut self, now: Nanos, frame: &[u8], tx: &mut impl FnMut(&[u8])) {
        let mut out = [0u8; MAX_FRAME];
        match self.ip.receive(now, frame, &mut out) {
            Received::Replied(n) => tx(out.get(..n).unwrap_or(&[])),
            Received::Rpc(dg) => self.rpc.receive(now, dg.src, dg.payload, &mut self.cm),
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
                CmEvent::Connected(_) => self.dcp.set_in_operation(true),
                CmEvent::Released(_) | CmEvent::Aborted(..) => {
                    self.dcp.set_in_operation(self.cm.ar().is_some())
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
        while let Some(port) = self.lldp.due(now) {
            let station = lldp::Station {
                name: self.dcp.name_of_station(),
                interface_mac: self.dcp.mac(),
                ip: Some(self.dcp.ip_suite().ip).filter(|ip| !ip.is_unspecified()),
                port_id_form: PortIdForm::default(),
            };
            let mac = self
                .port_macs
                .get(usize::from(port).wrapping_sub(1))
                .copied()
                .unwrap_or(self.dcp.mac());
            let mut out = [0u8; 512];
            if let Some(n) = lldp::build_frame(&station, port, &PortInfo::fast_ethernet(mac), &mut out) {
                tx(out.get(..n).unwrap_or(&[]));
            }
            self.lldp.sent(port, now);
        }
        self.drain_rpc(now, tx);
        let mut next = now.saturating_add(Nanos::from_ms(100));
        if let Some(t) = self.lldp.next_deadline() {
            next = next.min(t);
        }
        if let Some((t, _)) = &self.identify {
            next = next.min(*t);
        }
        next.max(now)
    }
}

impl Device<NoRecords> {
    /// A device without profile records.
    pub fn plain(config: DeviceConfig) -> Device<NoRecords> {
        Device::new(config, NoRecords)
    }
}
