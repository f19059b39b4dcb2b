//! The SNMP agent (P-038) on the device's UDP port 161: what the agent
//! reads of the device (its MACs, the ports' links, name and IP, what LLDP
//! sends on each port and the LLDP neighbours the PDev holds) gathered per
//! request, and the kept state in and out.

use nanos::Nanos;

use super::{Device, DeviceEvent, MAX_FRAME, SNMP_PORT};
use crate::cm::RecordHook;
use crate::ip::{UdpTx, UDP_PAYLOAD_OFFSET};
use crate::lldp::{self, PortInfo};
use crate::model;
use crate::pdev::Peer;

fn pno(delay: lldp::PnioDelay, (rt2, rt3): (u16, u16)) -> snmp::Pno {
    snmp::Pno {
        delay: snmp::Delays {
            line: delay.cable_local,
            tx: delay.tx_local,
            rx: delay.rx_local,
        },
        rt2,
        rt3,
    }
}

fn mac_phy(m: lldp::MacPhy) -> snmp::MacPhy {
    snmp::MacPhy {
        autoneg: m.autoneg,
        advertised: m.advertised.to_be_bytes(),
        mau_type: m.mau_type,
    }
}

fn man_addr(m: lldp::ManAddr) -> snmp::ManAddr {
    snmp::ManAddr {
        ipv4: m.ip.octets(),
        if_subtype: m.if_subtype,
        if_id: m.if_id,
    }
}

/// The neighbour as the agent shows it: the IDs as PDPortDataReal has them
/// and the optional TLVs as its last LLDPDU carried them.
fn neighbor(peer: &Peer) -> snmp::Neighbor<'_> {
    snmp::Neighbor {
        // locallyAssigned (7): the station name and the port name as LLDP sent them
        chassis_subtype: 7,
        chassis_id: &peer.station,
        port_subtype: 7,
        port_id: &peer.port,
        sys_name: &peer.station,
        pno: (peer.delay.is_some() || peer.port_status.is_some()).then(|| {
            pno(
                peer.delay.unwrap_or_default(),
                peer.port_status.unwrap_or_default(),
            )
        }),
        mac_phy: peer.mac_phy.map(mac_phy),
        man_addr: peer.man_addr.map(man_addr),
    }
}

impl<H: RecordHook> Device<H> {
    /// What LLDP sends on `port` (1-based): the port's MAC, MAC/PHY and
    /// PROFINET delays and status. The SNMP agent's local tables read the same.
    pub(super) fn lldp_port_info(&self, port: u16) -> PortInfo {
        let mac = self
            .port_macs
            .get(usize::from(port).wrapping_sub(1))
            .copied()
            .unwrap_or(self.dcp.mac());
        PortInfo::fast_ethernet(mac)
    }

    /// The LLDP agent as LLDP-MIB shows it: the transmitter's fixed timing and the counters.
    pub(super) fn lldp_agent(&self) -> snmp::LldpAgent {
        let cs = |t: Nanos| u32::try_from(t.as_ms() / 10).unwrap_or(u32::MAX);
        let s = &self.lldp_stats;
        let interval = u32::try_from(lldp::TX_INTERVAL.as_ms() / 1000).unwrap_or(u32::MAX);
        let rx = |p: usize| {
            let r = s.rx.get(p).copied().unwrap_or_default();
            snmp::RxStats {
                discarded: r.discarded,
                errors: r.errors,
                frames: r.frames,
                tlvs_discarded: 0,
                tlvs_unrecognized: r.tlvs_unrecognized,
                ageouts: r.ageouts,
            }
        };
        snmp::LldpAgent {
            tx_interval: interval,
            hold: u32::from(lldp::TTL_SECS) / interval.max(1),
            reinit_delay: lldp::REINIT_DELAY_SECS,
            tx_delay: lldp::TX_DELAY_SECS,
            notification_interval: lldp::NOTIFICATION_INTERVAL_SECS,
            // no Port Description, System Name, System Description or Capabilities TLV
            tlvs_tx: 0,
            stats: snmp::LldpStats {
                last_change_cs: s.last_change.map_or(0, cs),
                inserts: s.inserts,
                deletes: 0,
                drops: 0,
                ageouts: s.ageouts,
                tx: [
                    s.tx.first().copied().unwrap_or(0),
                    s.tx.get(1).copied().unwrap_or(0),
                ],
                rx: [rx(0), rx(1)],
            },
        }
    }

    /// One SNMP request: answered from port 161 or dropped (P-038).
    pub(super) fn snmp_request(
        &mut self,
        now: Nanos,
        from: crate::ip::Endpoint,
        req: &[u8],
        tx: &mut impl FnMut(&[u8]),
    ) {
        let mut out = [0u8; MAX_FRAME];
        let mac = self.dcp.mac();
        let mut neighbors = [None, None];
        let pdev = self.cm.pdev();
        let mut ports = [snmp::LocalPort::default(); 2];
        for (p, (slot, local)) in neighbors.iter_mut().zip(ports.iter_mut()).enumerate() {
            let state = pdev.port(p as u16 + 1);
            *slot = state.and_then(|port| port.peer.as_ref()).map(neighbor);
            let info = self.lldp_port_info(p as u16 + 1);
            *local = snmp::LocalPort {
                pno: pno(info.delay, info.rt_status),
                mac_phy: mac_phy(lldp::MacPhy {
                    autoneg: info.autoneg,
                    advertised: info.advertised,
                    // as PDPortDataReal reports it (no LLDPDU while the link is down)
                    mau_type: state.map_or(0, |s| s.oper_mau_type()),
                }),
            };
        }
        let ip = self.dcp.ip_suite().ip;
        let dev = snmp::Device {
            descr: model::STATION_TYPE.as_bytes(),
            uptime_cs: u32::try_from(now.as_ms() / 10).unwrap_or(u32::MAX),
            macs: [
                mac.0,
                self.port_macs.first().map_or([0; 6], |m| m.0),
                self.port_macs.get(1).map_or([0; 6], |m| m.0),
            ],
            links: [
                pdev.port(1).is_some_and(|p| p.link_up),
                pdev.port(2).is_some_and(|p| p.link_up),
            ],
            neighbors,
            name_of_station: self.dcp.name_of_station().as_bytes(),
            // as LLDP's Management Address TLV: ifIndex numbering, interface 1
            man_addr: (!ip.is_unspecified()).then(|| snmp::ManAddr {
                ipv4: ip.octets(),
                if_subtype: lldp::MAN_ADDR_IF_SUBTYPE,
                if_id: lldp::MAN_ADDR_IF_ID,
            }),
            // the Management Address TLV goes out on every port that sends LLDP
            man_addr_ports: [(1..=model::PORTS)
                .filter(|&p| pdev.lldp_allowed(p))
                .fold(0u8, |bits, p| bits | (0x80 >> (p - 1)))],
            ports,
            lldp: self.lldp_agent(),
        };
        let Some(payload) = out.get_mut(UDP_PAYLOAD_OFFSET..) else {
            return;
        };
        let Some(ans) = self.snmp.handle(req, &dev, payload) else {
            return;
        };
        if ans.changed {
            self.push(DeviceEvent::SnmpChanged);
        }
        if let Ok(UdpTx::Frame(len)) = self.ip.emit_udp(now, &mut out, SNMP_PORT, from, ans.len) {
            tx(out.get(..len).unwrap_or(&[]));
        }
    }

    /// The SNMP agent's kept state (communities, sysContact/sysName/sysLocation).
    pub fn snmp(&self) -> &snmp::Agent {
        &self.snmp
    }

    /// Restores the SNMP agent's kept state (from the parameter store at start).
    pub fn set_snmp(&mut self, agent: snmp::Agent) {
        self.snmp = agent;
    }
}
