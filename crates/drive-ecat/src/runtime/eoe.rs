//! The drive's side of IP over EoE (E-095…E-098, docs/eoe.md): the frame
//! queues handed to an IP stack with the dictionary, and the settings it
//! follows (A166, A175, A199, whether the master opened the tunnel).

use super::*;

/// The dictionary's IP settings ([`Drive::ip_settings`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct IpSettings {
    /// A166: IP address source (2 = DHCP + DS6).
    pub address_source: u8,
    /// A175: gateway (0.0.0.0 = none).
    pub gateway: [u8; 4],
    /// A199\[0\]: SNTP client on.
    pub sntp_active: bool,
    /// A199\[1\], A199\[2\]: SNTP servers (0.0.0.0 = none).
    pub sntp_servers: [[u8; 4]; 2],
    /// The master has used EoE since the mailbox was set up: until then
    /// the IP stack stays dormant (E-098).
    pub tunnel_open: bool,
    /// A269 = 1: the UDP parameter service may write.
    pub udp_writes: bool,
}

impl<F: Flash, B: Flash> Drive<F, B> {
    /// Runs `f` with the EoE queue and the object dictionary as the bus
    /// sees it (live values included, the A213-scaled entries in the
    /// parameter channel's representation A213\[1\], as over SDO) in the
    /// present communication state:
    /// the seam of the IP stack (crate `net`), which answers UDP parameter
    /// requests through [`od::Dictionary::read`]/[`write`](od::Dictionary::write)
    /// with exactly the SDO access rules and abort codes. Requests a write
    /// raises (e.g. "save") run at the next [`poll`](Self::poll).
    pub fn with_eoe<R>(
        &mut self,
        f: impl FnOnce(&mut ecat::eoe_queue::EoeQueue, &mut dyn od::Dictionary, od::CommState) -> R,
    ) -> R {
        let state = ecat::coe::comm_state(self.slave.state());
        let mut live = Live {
            diag: &mut self.diag,
            extra: &mut NoLive,
        };
        let mut dict = self.objects.parameter_channel(&mut live);
        f(&mut self.eoe, &mut dict, state)
    }

    /// The IP settings of the dictionary (A166, A175, A199) for the IP
    /// stack. IPv4 addresses are DWORDs with the first octet in the most
    /// significant byte (0A000001h = 10.0.0.1).
    pub fn ip_settings(&self) -> IpSettings {
        let get = |line: u16, sub: u8| {
            self.objects
                .get(crate::parameter_index(0, line), sub)
                .unwrap_or(0)
        };
        let ip = |v: i64| (v as u32).to_be_bytes();
        IpSettings {
            address_source: get(166, 0) as u8,
            gateway: ip(get(175, 0)),
            sntp_active: get(199, 1) != 0,
            sntp_servers: [ip(get(199, 2)), ip(get(199, 3))],
            tunnel_open: self.slave.eoe().master_active(),
            udp_writes: get(269, 0) == 1,
        }
    }
}
