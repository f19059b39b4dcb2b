//! The IP stack on the drive's EoE interface in the firmware images (spec §9):
//! [`net::NetStack`] on buffers the image provides as statics, polled by the
//! mailbox task after each mailbox request ([`crate::tasks::mailbox`]) and at
//! the time the stack asks for ([`NodeNet::poll_at`]: DHCP and ARP timers,
//! the SNTP client's next request), which the idle loop watches.
//!
//! The simulator binds the same stack to its drives (`hil_sim::eoe`).

use drive_ecat::runtime::Drive;
use nanos::Nanos;
use net::{NetConfig, NetSettings, NetStack};
use store::Flash;

pub use net::{NetBuffers, SocketSlots, SOCKETS};

/// Empty socket slots for a static.
pub const EMPTY_SLOTS: SocketSlots<'static> = [net::smoltcp::iface::SocketStorage::EMPTY; SOCKETS];

/// The board images' EoE interface until the master sets a MAC (E-096): a
/// locally administered unicast address; the seed of the stack's random
/// choices (DHCP transaction IDs, ports, SNTP poll jitter) is fixed, so a
/// drive's start is the same at every power-on.
pub const BOARD_NET: NetConfig = NetConfig {
    mac: [0x02, 0x5C, 0x06, 0x00, 0x00, 0x01],
    seed: 0x5C06_E0E0,
};

/// The settings the stack follows, read from `drive`'s dictionary before
/// each poll (A166, A175, A199, A269 and whether the master opened the tunnel).
pub fn net_settings<F: Flash, B: Flash>(drive: &Drive<F, B>) -> NetSettings {
    let s = drive.ip_settings();
    NetSettings {
        dhcp: s.address_source == 2,
        gateway: s.gateway,
        sntp: net::sntp::SntpConfig {
            active: s.sntp_active,
            servers: s.sntp_servers,
        },
        tunnel_open: s.tunnel_open,
        param_policy: net::param::Policy {
            writes: s.udp_writes,
            guard: Some(drive_ecat::params::A269),
        },
    }
}

/// A drive's IP stack: ping, DHCP, SNTP, the UDP parameter service.
pub struct NodeNet {
    stack: NetStack<'static>,
    /// When the stack wants to be polled again without a frame.
    next_at: Nanos,
}

impl NodeNet {
    /// The stack on `drive`'s EoE queue at local time `now`, with MAC `mac`
    /// until the master sets one and `seed` for its random choices.
    pub fn new<F: Flash, B: Flash>(
        drive: &mut Drive<F, B>,
        cfg: NetConfig,
        bufs: &'static mut NetBuffers,
        slots: &'static mut SocketSlots<'static>,
        now: Nanos,
    ) -> Self {
        let stack = NetStack::new(cfg, bufs, slots, drive.eoe_mut(), now);
        Self { stack, next_at: now }
    }

    /// One poll at local time `now`: frames the master tunnelled in are
    /// answered into the EoE queue (sent by the drive's next mailbox poll),
    /// the drive's message time stamps follow the SNTP time (E-147).
    pub fn poll<F: Flash, B: Flash>(&mut self, drive: &mut Drive<F, B>, now: Nanos) {
        let settings = net_settings(drive);
        let stack = &mut self.stack;
        drive.with_eoe(|q, dict, state| stack.poll(now, q, dict, state, &settings));
        let sntp = stack.sntp_time(now);
        drive.set_sntp_time(
            sntp.map(|unix| net::sntp::message_time_stamp(None, Some(unix))),
            now,
        );
        self.next_at = stack.poll_at(now);
    }

    /// When the stack next wants a poll without new frames.
    pub fn poll_at(&self) -> Nanos {
        self.next_at
    }

    /// The stack (address, counters).
    pub fn stack(&self) -> &NetStack<'static> {
        &self.stack
    }
}

/// What the mailbox task polls after a request: the IP stack
/// ([`NodeNet`]) or nothing ([`NoNet`], an image built without it).
pub trait NetPoll {
    /// Whether there is a stack to poll.
    const ACTIVE: bool;
    /// One poll at local time `now`.
    fn poll(&mut self, drive: &mut crate::Drive, now: Nanos);
    /// When the stack next wants a poll without new frames.
    fn poll_at(&self) -> Nanos;
}

impl NetPoll for NodeNet {
    const ACTIVE: bool = true;
    fn poll(&mut self, drive: &mut crate::Drive, now: Nanos) {
        NodeNet::poll(self, drive, now);
    }
    fn poll_at(&self) -> Nanos {
        NodeNet::poll_at(self)
    }
}

/// No IP stack: EoE frames are counted and dropped (`ecat::eoe::FrameCounter`).
#[derive(Debug, Clone, Copy, Default)]
pub struct NoNet;

impl NetPoll for NoNet {
    const ACTIVE: bool = false;
    fn poll(&mut self, _drive: &mut crate::Drive, _now: Nanos) {}
    fn poll_at(&self) -> Nanos {
        Nanos::MAX
    }
}
