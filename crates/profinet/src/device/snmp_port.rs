//! The SNMP agent (P-038) on the device's UDP port 161: what the agent
//! reads of the device (its MACs, the ports' links, the LLDP neighbours the
//! PDev holds) gathered per request, and the kept state in and out.

use nanos::Nanos;

use super::{Device, DeviceEvent, MAX_FRAME, SNMP_PORT};
use crate::cm::RecordHook;
use crate::ip::{UdpTx, UDP_PAYLOAD_OFFSET};
use crate::model;

impl<H: RecordHook> Device<H> {
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
        for (p, slot) in neighbors.iter_mut().enumerate() {
            *slot = pdev
                .port(p as u16 + 1)
                .and_then(|port| port.peer.as_ref())
                .map(|peer| snmp::Neighbor {
                    // locallyAssigned (7): the station name and the port name as LLDP sent them
                    chassis_subtype: 7,
                    chassis_id: &peer.station,
                    port_subtype: 7,
                    port_id: &peer.port,
                    sys_name: &peer.station,
                });
        }
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
