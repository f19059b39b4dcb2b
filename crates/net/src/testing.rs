//! For tests of the drive's IP stack on the host (feature `testing`): the
//! answers of a DHCP server ([`DhcpLease::answer`]), as crates/net's hostile
//! frames and the end-to-end EoE tests serve the drive's DHCP client.

use smoltcp::wire::{DhcpMessageType, DhcpOption, DhcpPacket, DhcpRepr, Ipv4Address};

/// What a test's DHCP server leases: for an hour, broadcast (the client has
/// no address yet).
#[derive(Debug, Clone, Copy)]
pub struct DhcpLease<'a> {
    /// The server's address, also its identifier.
    pub server: [u8; 4],
    /// The address offered to the client.
    pub offer: [u8; 4],
    /// The subnet mask.
    pub mask: [u8; 4],
    /// The default router, if any.
    pub router: Option<[u8; 4]>,
    /// More options (a renewal time, …).
    pub options: &'a [DhcpOption<'a>],
}

impl DhcpLease<'_> {
    /// The server's answer to the client's message `request`: an OFFER to a
    /// DISCOVER, an ACK to a REQUEST, emitted into `buf`; its type and bytes
    /// (the UDP payload, to port 68). `None` for any other message or a
    /// `buf` too short.
    pub fn answer<'b>(&self, request: &DhcpRepr, buf: &'b mut [u8]) -> Option<(DhcpMessageType, &'b [u8])> {
        let kind = match request.message_type {
            DhcpMessageType::Discover => DhcpMessageType::Offer,
            DhcpMessageType::Request => DhcpMessageType::Ack,
            _ => return None,
        };
        let repr = DhcpRepr {
            message_type: kind,
            transaction_id: request.transaction_id,
            secs: 0,
            client_hardware_address: request.client_hardware_address,
            client_ip: Ipv4Address::UNSPECIFIED,
            your_ip: Ipv4Address::from(self.offer),
            server_ip: Ipv4Address::from(self.server),
            router: self.router.map(Ipv4Address::from),
            subnet_mask: Some(Ipv4Address::from(self.mask)),
            relay_agent_ip: Ipv4Address::UNSPECIFIED,
            broadcast: true,
            requested_ip: None,
            client_identifier: None,
            server_identifier: Some(Ipv4Address::from(self.server)),
            parameter_request_list: None,
            dns_servers: None,
            max_size: None,
            lease_duration: Some(3600),
            renew_duration: None,
            rebind_duration: None,
            additional_options: self.options,
        };
        let out = buf.get_mut(..repr.buffer_len())?;
        repr.emit(&mut DhcpPacket::new_unchecked(&mut *out)).ok()?;
        Some((kind, out))
    }
}
