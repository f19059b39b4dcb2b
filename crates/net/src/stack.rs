//! [`NetStack`]: the smoltcp interface on the EoE queue with the UDP
//! parameter service and the SNTP client. Heap-free: the sockets live in
//! [`NetBuffers`] and [`SocketSlots`] the owner provides (statics on the
//! firmware). ICMP echo requests are answered by the interface itself.

use crate::device::QueueDevice;
use crate::param::{self, MAX_MESSAGE, PARAM_PORT};
use crate::sntp::{self, Ipv4, SntpClient, SntpConfig, NTP_PORT};
use ecat::eoe::{prefix_len, IpParams};
use ecat::eoe_queue::EoeQueue;
use nanos::Nanos;
use od::{CommState, Dictionary};
use smoltcp::iface::{Config, Interface, SocketHandle, SocketSet, SocketStorage};
use smoltcp::socket::{dhcpv4, udp, Socket};
use smoltcp::time::Instant;
use smoltcp::wire::{EthernetAddress, HardwareAddress, IpAddress, IpCidr, IpEndpoint, Ipv4Address, Ipv4Cidr};

/// Sockets of the stack (parameter service, SNTP, DHCP client).
pub const SOCKETS: usize = 3;
/// The socket slots the owner provides.
pub type SocketSlots<'a> = [SocketStorage<'a>; SOCKETS];

/// Datagrams each parameter-service buffer holds.
const PARAM_DATAGRAMS: usize = 2;
/// Payload bytes of each parameter-service buffer (a longer datagram than
/// [`MAX_MESSAGE`] still fits and is answered `ERR SYNTAX`).
const PARAM_BYTES: usize = 2 * 512;
/// SNTP buffers: one packet each way (plus slack for a longer answer).
const SNTP_BYTES: usize = 2 * 68;

/// The sockets' buffers (under 3 KiB).
pub struct NetBuffers {
    param_rx_meta: [udp::PacketMetadata; PARAM_DATAGRAMS],
    param_rx: [u8; PARAM_BYTES],
    param_tx_meta: [udp::PacketMetadata; PARAM_DATAGRAMS],
    param_tx: [u8; PARAM_BYTES],
    sntp_rx_meta: [udp::PacketMetadata; 2],
    sntp_rx: [u8; SNTP_BYTES],
    sntp_tx_meta: [udp::PacketMetadata; 2],
    sntp_tx: [u8; SNTP_BYTES],
}

impl Default for NetBuffers {
    fn default() -> Self {
        Self::new()
    }
}

impl NetBuffers {
    /// Zeroed.
    pub const fn new() -> Self {
        Self {
            param_rx_meta: [udp::PacketMetadata::EMPTY; PARAM_DATAGRAMS],
            param_rx: [0; PARAM_BYTES],
            param_tx_meta: [udp::PacketMetadata::EMPTY; PARAM_DATAGRAMS],
            param_tx: [0; PARAM_BYTES],
            sntp_rx_meta: [udp::PacketMetadata::EMPTY; 2],
            sntp_rx: [0; SNTP_BYTES],
            sntp_tx_meta: [udp::PacketMetadata::EMPTY; 2],
            sntp_tx: [0; SNTP_BYTES],
        }
    }
}

/// Fixed at power-on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NetConfig {
    /// MAC address of the EoE interface until the master sets one.
    pub mac: [u8; 6],
    /// Seed of the random delays and of smoltcp's port/ID choices.
    pub seed: u64,
}

/// The parameters the stack follows, read from the dictionary by the owner
/// before each poll (A166, A175, A199).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct NetSettings {
    /// A166 = 2 "DHCP + DS6": the address comes from DHCP until the master
    /// sets one over EoE (E-098).
    pub dhcp: bool,
    /// A175: gateway; 0.0.0.0 = the one the master set over EoE (or DHCP's).
    pub gateway: Ipv4,
    /// A199: SNTP.
    pub sntp: SntpConfig,
    /// The master has used EoE since the mailbox was set up
    /// (`ecat::eoe::EoeServer::master_active`). Until then the stack is
    /// dormant: no DHCP, nothing queued for the master (E-098).
    pub tunnel_open: bool,
    /// What the UDP parameter service may do (A269).
    pub param_policy: param::Policy,
}

/// Parameter requests taken at once before the rate applies.
pub const PARAM_BURST: u32 = 16;
/// One more request is taken per this time (100 per second): a flood
/// cannot keep the mailbox task busy with dictionary accesses.
pub const PARAM_REFILL: Nanos = Nanos::from_ms(10);

/// The parameter service's rate limit: a token bucket of [`PARAM_BURST`]
/// requests, refilled one per [`PARAM_REFILL`].
#[derive(Debug, Clone, Copy)]
struct Bucket {
    tokens: u32,
    /// Time the last token was added (`None`: never used, full).
    at: Option<Nanos>,
}

impl Bucket {
    const FULL: Bucket = Bucket {
        tokens: PARAM_BURST,
        at: None,
    };

    /// Takes one token at `now`; `false` when none is left.
    fn take(&mut self, now: Nanos) -> bool {
        let at = *self.at.get_or_insert(now);
        let earned = now.saturating_sub(at).checked_div_span(PARAM_REFILL).unwrap_or(0);
        if earned > 0 {
            let earned32 = u32::try_from(earned).unwrap_or(u32::MAX);
            self.tokens = self.tokens.saturating_add(earned32).min(PARAM_BURST);
            self.at = Some(at.saturating_add(PARAM_REFILL.saturating_mul(earned)));
        }
        if self.tokens == 0 {
            return false;
        }
        self.tokens -= 1;
        true
    }
}

/// Counters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct NetStats {
    /// Parameter-service requests answered.
    pub param_requests: u32,
    /// Answers that could not be sent (buffer full).
    pub param_dropped: u32,
    /// Requests that were not requests: answered `ERR SYNTAX`, or dropped
    /// unanswered when longer than [`param::MAX_MESSAGE`].
    pub param_malformed: u32,
    /// Writes the policy refused (writes off, or the guard).
    pub param_writes_refused: u32,
    /// Requests dropped unanswered by the rate limit ([`PARAM_BURST`],
    /// [`PARAM_REFILL`]).
    pub param_limited: u32,
    /// SNTP packets not used (see [`sntp::Reject`]).
    pub sntp_rejected: u32,
}

/// The IP stack of the drive.
pub struct NetStack<'a> {
    iface: Interface,
    sockets: SocketSet<'a>,
    /// The parameter service's socket (`None` only if the set had no room, which
    /// [`SOCKETS`] rules out).
    param: Option<SocketHandle>,
    /// The SNTP client's socket (as `param`).
    sntp_socket: Option<SocketHandle>,
    sntp: SntpClient,
    /// The address in force (the master's, E-096, or DHCP's, E-098).
    ip: Option<Ipv4Cidr>,
    /// The master set the address: DHCP stays off.
    ip_from_master: bool,
    eoe_gateway: Option<Ipv4>,
    /// The DHCP client while it runs.
    dhcp: Option<SocketHandle>,
    /// The address came from DHCP (dropped when DHCP stops).
    ip_from_dhcp: bool,
    dhcp_gateway: Option<Ipv4>,
    /// The gateway in force as a default route.
    route: Option<Ipv4>,
    stats: NetStats,
    param_bucket: Bucket,
}

/// The UDP socket of handle `h`: looked up by iterating the set rather than
/// with `SocketSet::get_mut`, whose `expect` and wrong-type panic are code
/// on the board even though the stack only passes its own handles.
fn udp_socket<'s, 'a>(
    sockets: &'s mut SocketSet<'a>,
    h: Option<SocketHandle>,
) -> Option<&'s mut udp::Socket<'a>> {
    let h = h?;
    sockets.iter_mut().find_map(|(k, s)| match s {
        Socket::Udp(u) if k == h => Some(u),
        _ => None,
    })
}

/// The DHCP socket of handle `h` (as [`udp_socket`]).
fn dhcp_socket<'s, 'a>(
    sockets: &'s mut SocketSet<'a>,
    h: SocketHandle,
) -> Option<&'s mut dhcpv4::Socket<'a>> {
    sockets.iter_mut().find_map(|(k, s)| match s {
        Socket::Dhcpv4(d) if k == h => Some(d),
        _ => None,
    })
}

/// Adds `socket` to the set; `None` when the set is full.
///
/// With the firmware's smoltcp (feature `patched-smoltcp`, firmware/patches/smoltcp) this is
/// `SocketSet::try_add`, so the board image has no panic behind it; crates.io's 0.12.0 has only
/// the panicking `add`, which cannot fail here: [`SOCKETS`] slots take the two fixed sockets
/// and the DHCP client, which is added only while its handle is `None`.
fn add_socket<'a, T: smoltcp::socket::AnySocket<'a>>(
    sockets: &mut SocketSet<'a>,
    socket: T,
) -> Option<SocketHandle> {
    #[cfg(feature = "patched-smoltcp")]
    return sockets.try_add(socket).ok();
    #[cfg(not(feature = "patched-smoltcp"))]
    return Some(sockets.add(socket));
}

/// Removes the socket of `h` (as [`add_socket`]: `try_remove` with the firmware's smoltcp;
/// `remove` cannot panic here as `h` is a handle of this set still in it).
fn remove_socket(sockets: &mut SocketSet<'_>, h: SocketHandle) {
    #[cfg(feature = "patched-smoltcp")]
    let _ = sockets.try_remove(h);
    #[cfg(not(feature = "patched-smoltcp"))]
    let _ = sockets.remove(h);
}

/// smoltcp's time: whole µs (truncated, as the callers did before they passed [`Nanos`]).
fn instant(now: Nanos) -> Instant {
    Instant::from_micros(i64::try_from(now.as_us()).unwrap_or(i64::MAX))
}

fn addr(a: Ipv4) -> Ipv4Address {
    Ipv4Address::from(a)
}

/// A unicast address (not 0.0.0.0, not broadcast or multicast): the only
/// kind smoltcp accepts as an interface address, gateway or destination.
pub fn is_unicast(a: Ipv4) -> bool {
    let a = addr(a);
    !(a.is_unspecified() || a.is_broadcast() || a.is_multicast())
}

impl<'a> NetStack<'a> {
    /// The stack at local time `now` on `queue`, without an address.
    pub fn new(
        cfg: NetConfig,
        bufs: &'a mut NetBuffers,
        slots: &'a mut SocketSlots<'a>,
        queue: &mut EoeQueue,
        now: Nanos,
    ) -> Self {
        let mut c = Config::new(HardwareAddress::Ethernet(EthernetAddress(cfg.mac)));
        c.random_seed = cfg.seed;
        let iface = Interface::new(c, &mut QueueDevice(queue), instant(now));
        let mut sockets = SocketSet::new(slots.as_mut_slice());
        let NetBuffers {
            param_rx_meta,
            param_rx,
            param_tx_meta,
            param_tx,
            sntp_rx_meta,
            sntp_rx,
            sntp_tx_meta,
            sntp_tx,
        } = bufs;
        let mut p = udp::Socket::new(
            udp::PacketBuffer::new(param_rx_meta.as_mut_slice(), param_rx.as_mut_slice()),
            udp::PacketBuffer::new(param_tx_meta.as_mut_slice(), param_tx.as_mut_slice()),
        );
        let _ = p.bind(PARAM_PORT);
        let mut s = udp::Socket::new(
            udp::PacketBuffer::new(sntp_rx_meta.as_mut_slice(), sntp_rx.as_mut_slice()),
            udp::PacketBuffer::new(sntp_tx_meta.as_mut_slice(), sntp_tx.as_mut_slice()),
        );
        let _ = s.bind(NTP_PORT);
        let param = add_socket(&mut sockets, p);
        let sntp_socket = add_socket(&mut sockets, s);
        Self {
            iface,
            sockets,
            param,
            sntp_socket,
            sntp: SntpClient::new(cfg.seed ^ 0x5A5A_5A5A),
            ip: None,
            ip_from_master: false,
            eoe_gateway: None,
            dhcp: None,
            ip_from_dhcp: false,
            dhcp_gateway: None,
            route: None,
            stats: NetStats::default(),
            param_bucket: Bucket::FULL,
        }
    }

    /// The IPv4 address and prefix in force.
    pub fn ip(&self) -> Option<(Ipv4, u8)> {
        self.ip.map(|c| (c.address().octets(), c.prefix_len()))
    }

    /// The default gateway in force.
    pub fn gateway(&self) -> Option<Ipv4> {
        self.route
    }

    /// The interface's MAC address.
    pub fn mac(&self) -> [u8; 6] {
        match self.iface.hardware_addr() {
            HardwareAddress::Ethernet(e) => e.0,
        }
    }

    /// The SNTP client.
    pub fn sntp(&self) -> &SntpClient {
        &self.sntp
    }

    /// The SNTP time at local `now`, since the Unix epoch (`None` until a
    /// server answered).
    pub fn sntp_time(&self, now: Nanos) -> Option<Nanos> {
        self.sntp.time_ns(now.as_us()).map(Nanos::from_ns)
    }

    /// Counters.
    pub fn stats(&self) -> NetStats {
        self.stats
    }

    /// Takes over IP parameters set by the master (E-096). Addresses
    /// smoltcp cannot hold (multicast, broadcast; it would panic) are
    /// ignored: the previous ones stay.
    fn apply_ip(&mut self, p: &IpParams) {
        if let Some(mac) = p.mac.filter(|m| EthernetAddress(*m).is_unicast()) {
            self.iface
                .set_hardware_addr(HardwareAddress::Ethernet(EthernetAddress(mac)));
        }
        if let Some(ip) = p.ip.filter(|a| is_unicast(*a)) {
            let prefix = p.mask.and_then(prefix_len).unwrap_or(24) as u8;
            self.set_address(Some(Ipv4Cidr::new(addr(ip), prefix)));
            self.ip_from_master = true;
            self.ip_from_dhcp = false;
        }
        self.eoe_gateway = match p.gateway {
            Some(g) if is_unicast(g) => Some(g),
            Some([0, 0, 0, 0]) | None => None,
            Some(_) => self.eoe_gateway,
        };
    }

    fn set_address(&mut self, cidr: Option<Ipv4Cidr>) {
        self.ip = cidr;
        self.iface.update_ip_addrs(|addrs| {
            addrs.clear();
            if let Some(c) = cidr {
                let _ = addrs.push(IpCidr::Ipv4(c));
            }
        });
    }

    /// Starts the DHCP client while A166 = 2 and the master set no
    /// address, stops it otherwise (E-098).
    fn follow_dhcp(&mut self, settings: &NetSettings) {
        let want = settings.dhcp && settings.tunnel_open && !self.ip_from_master;
        match (want, self.dhcp) {
            (true, None) => self.dhcp = add_socket(&mut self.sockets, dhcpv4::Socket::new()),
            (false, Some(h)) => {
                remove_socket(&mut self.sockets, h);
                self.dhcp = None;
                self.dhcp_gateway = None;
                if core::mem::take(&mut self.ip_from_dhcp) {
                    self.set_address(None);
                }
            }
            _ => {}
        }
    }

    /// Takes the DHCP client's news.
    fn run_dhcp(&mut self) {
        let Some(h) = self.dhcp else { return };
        let Some(dhcp) = dhcp_socket(&mut self.sockets, h) else {
            return;
        };
        let event = match dhcp.poll() {
            None => return,
            Some(dhcpv4::Event::Configured(c)) => Some((c.address, c.router)),
            Some(dhcpv4::Event::Deconfigured) => None,
        };
        match event {
            Some((cidr, router)) if is_unicast(cidr.address().octets()) => {
                self.set_address(Some(cidr));
                self.ip_from_dhcp = true;
                self.dhcp_gateway = router.map(|r| r.octets()).filter(|r| is_unicast(*r));
            }
            _ => {
                self.set_address(None);
                self.ip_from_dhcp = false;
                self.dhcp_gateway = None;
            }
        }
    }

    /// Whether the address in force came from DHCP.
    pub fn address_from_dhcp(&self) -> bool {
        self.ip_from_dhcp
    }

    /// Puts the default route on A175, else the EoE gateway, else DHCP's router.
    fn follow_gateway(&mut self, settings: &NetSettings) {
        let gw = Some(settings.gateway)
            .filter(|g| is_unicast(*g))
            .or(self.eoe_gateway)
            .or(self.dhcp_gateway);
        if gw != self.route {
            let routes = self.iface.routes_mut();
            routes.remove_default_ipv4_route();
            if let Some(g) = gw {
                let _ = routes.add_default_ipv4_route(addr(g));
            }
            self.route = gw;
        }
    }

    /// One pass at local time `now`: frames in and out of `queue`, the
    /// parameter requests answered through `dict` in `state`, the SNTP
    /// schedule. Call it after each poll of the slave stack.
    pub fn poll<D: Dictionary + ?Sized>(
        &mut self,
        now: Nanos,
        queue: &mut EoeQueue,
        dict: &mut D,
        state: CommState,
        settings: &NetSettings,
    ) {
        if let Some(p) = queue.take_ip_change() {
            self.apply_ip(&p);
        }
        self.follow_dhcp(settings);
        if !settings.tunnel_open {
            // E-098: nothing goes to a master that has not used EoE (and
            // nothing can arrive from it)
            queue.clear();
            return;
        }
        let t = instant(now);
        self.iface.poll(t, &mut QueueDevice(queue), &mut self.sockets);
        self.run_dhcp();
        self.follow_gateway(settings);
        self.serve_parameters(now, dict, state, settings.param_policy);
        self.run_sntp(now.as_us(), settings);
        self.iface.poll(t, &mut QueueDevice(queue), &mut self.sockets);
    }

    /// Answers the waiting parameter requests at `now` (docs/eoe.md): at
    /// most [`PARAM_DATAGRAMS`] per poll and the rate of the bucket, the
    /// rest dropped unanswered and counted; an oversized datagram is
    /// dropped and counted as malformed.
    fn serve_parameters<D: Dictionary + ?Sized>(
        &mut self,
        now: Nanos,
        dict: &mut D,
        state: CommState,
        policy: param::Policy,
    ) {
        let Some(sock) = udp_socket(&mut self.sockets, self.param) else {
            return;
        };
        let stats = &mut self.stats;
        for _ in 0..PARAM_DATAGRAMS {
            if !sock.can_send() {
                break;
            }
            let mut answer = [0u8; MAX_MESSAGE];
            let (n, to) = match sock.recv() {
                Ok(_) if !self.param_bucket.take(now) => {
                    stats.param_limited = stats.param_limited.wrapping_add(1);
                    continue;
                }
                Ok((data, meta)) if data.len() <= MAX_MESSAGE => {
                    let (n, outcome) = param::handle(data, &mut answer, dict, state, policy);
                    match outcome {
                        param::Outcome::Served => {}
                        param::Outcome::Malformed => {
                            stats.param_malformed = stats.param_malformed.wrapping_add(1);
                        }
                        param::Outcome::WriteRefused => {
                            stats.param_writes_refused = stats.param_writes_refused.wrapping_add(1);
                        }
                    }
                    (n, meta.endpoint)
                }
                Ok(_) => {
                    stats.param_malformed = stats.param_malformed.wrapping_add(1);
                    continue;
                }
                Err(_) => break,
            };
            stats.param_requests = stats.param_requests.wrapping_add(1);
            let out = answer.get(..n).unwrap_or_default();
            if sock.send_slice(out, to).is_err() {
                stats.param_dropped = stats.param_dropped.wrapping_add(1);
            }
        }
    }

    fn run_sntp(&mut self, now_us: u64, settings: &NetSettings) {
        let Some(sock) = udp_socket(&mut self.sockets, self.sntp_socket) else {
            return;
        };
        while let Ok((data, meta)) = sock.recv() {
            let from = match meta.endpoint.addr {
                IpAddress::Ipv4(a) => a.octets(),
            };
            if meta.endpoint.port != NTP_PORT || self.sntp.on_response(now_us, from, data).is_err() {
                self.stats.sntp_rejected = self.stats.sntp_rejected.wrapping_add(1);
            }
        }
        let can_send = self.ip.is_some() && sock.can_send();
        if let Some(req) = self.sntp.poll(now_us, &settings.sntp, can_send) {
            let to = IpEndpoint::new(IpAddress::Ipv4(addr(req.server)), NTP_PORT);
            let _ = sock.send_slice(&req.packet, to);
        }
    }

    /// When the stack wants to be polled next at the latest (local time, whole
    /// µs): smoltcp's timers and the SNTP schedule.
    pub fn poll_at(&mut self, now: Nanos) -> Nanos {
        let now_us = now.as_us();
        let iface = self
            .iface
            .poll_at(instant(now), &self.sockets)
            .map_or(u64::MAX, |t| u64::try_from(t.total_micros()).unwrap_or(0));
        Nanos::from_us(iface.min(self.sntp.next_request_us()).max(now_us))
    }
}

/// Re-exported for the owner's convenience.
pub use sntp::message_time_stamp;

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use drive_ecat::dictionary::DriveObjects;

    /// The parameter service's rate: a burst of 16, then one request per
    /// 10 ms, never more than 16 saved up.
    #[test]
    fn e101_the_rate_limit_takes_a_burst_then_one_per_10_ms() {
        let mut b = Bucket::FULL;
        let t0 = Nanos::from_secs(3);
        assert_eq!((0..20).filter(|_| b.take(t0)).count(), PARAM_BURST as usize);
        assert!(!b.take(t0 + Nanos::from_ms(9)));
        assert!(b.take(t0 + Nanos::from_ms(10)));
        assert!(!b.take(t0 + Nanos::from_ms(19)));
        // 1 s of flood at 1 per ms: 100 taken
        let taken = (20..1020).filter(|ms| b.take(t0 + Nanos::from_ms(*ms))).count();
        assert!((99..=101).contains(&taken), "{taken} in 1 s");
        // a long pause saves up the burst, not more
        let later = t0 + Nanos::from_secs(60);
        assert_eq!((0..40).filter(|_| b.take(later)).count(), PARAM_BURST as usize);
    }

    #[test]
    fn buffers_stay_small() {
        assert!(core::mem::size_of::<NetBuffers>() < 3 * 1024);
    }

    #[test]
    fn e096_addresses_smoltcp_cannot_hold_are_ignored() {
        let mut q = EoeQueue::new();
        let mut bufs = NetBuffers::new();
        let mut slots = [SocketStorage::EMPTY; SOCKETS];
        let cfg = NetConfig {
            mac: [2, 0, 0, 0, 0, 1],
            seed: 1,
        };
        let mut net = NetStack::new(cfg, &mut bufs, &mut slots, &mut q, Nanos::ZERO);
        let mut d = DriveObjects::new();
        let good = IpParams {
            ip: Some([10, 0, 0, 5]),
            mask: Some([255, 255, 255, 0]),
            gateway: Some([10, 0, 0, 1]),
            ..IpParams::default()
        };
        ecat::eoe::EthernetPort::ip_changed(&mut q, &good);
        let s = NetSettings {
            tunnel_open: true,
            ..NetSettings::default()
        };
        net.poll(Nanos::from_us(1), &mut q, &mut d, CommState::PreOp, &s);
        assert_eq!(net.ip(), Some(([10, 0, 0, 5], 24)));
        assert_eq!(net.gateway(), Some([10, 0, 0, 1]));
        // multicast / broadcast address, gateway and MAC: the old ones stay
        let bad = IpParams {
            mac: Some([1, 0, 0x5E, 0, 0, 1]),
            ip: Some([224, 0, 0, 5]),
            mask: Some([255, 255, 255, 0]),
            gateway: Some([255, 255, 255, 255]),
            ..IpParams::default()
        };
        ecat::eoe::EthernetPort::ip_changed(&mut q, &bad);
        // A175 and the SNTP servers multicast/broadcast too
        let s = NetSettings {
            dhcp: false,
            gateway: [239, 1, 1, 1],
            sntp: SntpConfig {
                active: true,
                servers: [[255, 255, 255, 255], [224, 0, 1, 1]],
            },
            tunnel_open: true,
            param_policy: param::Policy::default(),
        };
        for t in [2, 400_000_000, 800_000_000] {
            net.poll(Nanos::from_us(t), &mut q, &mut d, CommState::PreOp, &s);
        }
        assert_eq!(net.ip(), Some(([10, 0, 0, 5], 24)));
        assert_eq!(net.mac(), [2, 0, 0, 0, 0, 1]);
        assert_eq!(net.gateway(), Some([10, 0, 0, 1]));
        assert_eq!(net.sntp().stats().requests, 0);
    }
}
