//! IP through EtherCAT in the simulation (spec §9): the drive side binds a
//! [`net::NetStack`] to a simulated drive ([`SimDrive::bind_net`]), polled
//! after each poll of the drive in simulated time; the master side is an
//! [`EoeTunnel`]: it fragments Ethernet frames into EoE mailbox messages for
//! SM0 and reassembles the drive's EoE fragments from SM1, and is a smoltcp
//! [`Device`] for a host-side interface (ping, UDP). [`EoeTunnel::pump`]
//! moves the mailbox through a real master (ethercrab register accesses).

use crate::sim::SimDrive;
use drive_ecat::runtime::Drive;
use ecat::eoe::{frame_type, EoeHeader, Fragmenter, Reassembly, HEADER_LEN, MAX_FRAME};
use ethercrab::SubDeviceRef;
use nanos::Nanos;
use net::smoltcp;
use net::{NetBuffers, NetConfig, NetStack, SocketSlots};
use smoltcp::iface::SocketStorage;
use smoltcp::phy::{Device, DeviceCapabilities, Medium, RxToken, TxToken};
use smoltcp::time::Instant;
use std::collections::VecDeque;

/// The drive's mailboxes: SM0 (master → slave) and SM1 (slave → master).
pub const MAILBOX_OUT: u16 = 0x1000;
/// SM1 start.
pub const MAILBOX_IN: u16 = 0x1100;
/// Mailbox length (both), bytes.
pub const MAILBOX_LEN: usize = 256;
/// Mailbox header length.
const MBX_HEADER: usize = 6;
/// Mailbox type EoE.
pub const MBX_EOE: u8 = 2;

pub use firmware_tasks::net::net_settings;

/// A drive's IP stack in the simulation: the firmware's [`firmware_tasks::net::NodeNet`]
/// (the same poll the mailbox task runs) on leaked buffers (a few KiB per
/// drive, for the life of the process).
pub struct DriveNet(firmware_tasks::net::NodeNet);

impl DriveNet {
    /// Bound to `drive`'s EoE queue at `now`: MAC `mac` until the master
    /// sets one, `seed` for the random delays.
    pub fn new<F: store::Flash, B: store::Flash>(
        drive: &mut Drive<F, B>,
        mac: [u8; 6],
        seed: u64,
        now: Nanos,
    ) -> Self {
        let bufs: &'static mut NetBuffers = Box::leak(Box::new(NetBuffers::new()));
        let slots: &'static mut SocketSlots<'static> =
            Box::leak(Box::new([SocketStorage::EMPTY; net::SOCKETS]));
        Self(firmware_tasks::net::NodeNet::new(
            drive,
            NetConfig { mac, seed },
            bufs,
            slots,
            now,
        ))
    }

    /// Polls the stack after the drive's poll (local time = simulation time).
    pub fn poll<F: store::Flash, B: store::Flash>(&mut self, drive: &mut Drive<F, B>, now: Nanos) {
        self.0.poll(drive, now);
    }

    /// The stack (address, counters).
    pub fn stack(&self) -> &NetStack<'static> {
        self.0.stack()
    }
}

impl SimDrive {
    /// Binds an IP stack to the drive's EoE interface ([`DriveNet::new`]),
    /// polled after each poll of the drive.
    pub fn bind_net(&mut self, mac: [u8; 6], seed: u64, now: Nanos) {
        self.net = Some(Box::new(DriveNet::new(&mut self.drive, mac, seed, now)));
    }

    /// Polls the bound IP stack (after the drive's poll).
    pub(crate) fn poll_net(&mut self, now: Nanos) {
        if let Some(net) = self.net.as_deref_mut() {
            net.poll(&mut self.drive, now);
        }
    }
}

/// Counters of the tunnel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TunnelStats {
    /// Ethernet frames sent to the drive.
    pub frames_out: u64,
    /// Ethernet frames received from the drive.
    pub frames_in: u64,
    /// Mailbox messages written to SM0.
    pub mailbox_out: u64,
    /// Mailbox messages read from SM1.
    pub mailbox_in: u64,
}

/// The master side of one drive's EoE interface.
pub struct EoeTunnel {
    to_slave: VecDeque<Vec<u8>>,
    from_slave: VecDeque<Vec<u8>>,
    tx: Fragmenter,
    rx: Reassembly,
    counter: u8,
    /// EoE messages from the drive that are not fragments (set-IP
    /// responses …), EoE header first.
    pub responses: VecDeque<Vec<u8>>,
    /// Other mailbox messages from the drive (CoE emergencies …): type, data.
    pub other: Vec<(u8, Vec<u8>)>,
    stats: TunnelStats,
}

impl Default for EoeTunnel {
    fn default() -> Self {
        Self::new()
    }
}

impl EoeTunnel {
    /// Nothing in transit.
    pub fn new() -> Self {
        Self {
            to_slave: VecDeque::new(),
            from_slave: VecDeque::new(),
            tx: Fragmenter::new(),
            rx: Reassembly::new(),
            counter: 0,
            responses: VecDeque::new(),
            other: Vec::new(),
            stats: TunnelStats::default(),
        }
    }

    /// Counters.
    pub fn stats(&self) -> TunnelStats {
        self.stats
    }

    /// Queues an Ethernet frame for the drive.
    pub fn send_frame(&mut self, frame: &[u8]) {
        self.to_slave.push_back(frame.to_vec());
    }

    /// The next Ethernet frame the drive sent.
    pub fn recv_frame(&mut self) -> Option<Vec<u8>> {
        self.from_slave.pop_front()
    }

    /// Whether frames wait to go out (or are going out).
    pub fn busy(&self) -> bool {
        self.tx.active() || !self.to_slave.is_empty()
    }

    async fn write_mailbox<S>(&mut self, sd: &SubDeviceRef<'_, S>, kind: u8, data: &[u8]) -> bool {
        self.counter = self.counter % 7 + 1;
        let mut m = [0u8; MAILBOX_LEN];
        let len = data.len().min(MAILBOX_LEN - MBX_HEADER);
        m[0..2].copy_from_slice(&(len as u16).to_le_bytes());
        m[5] = (kind & 0x0F) | (self.counter << 4);
        m[MBX_HEADER..MBX_HEADER + len].copy_from_slice(&data[..len]);
        self.stats.mailbox_out += 1;
        sd.register_write(MAILBOX_OUT, m).await.is_ok()
    }

    /// Sends one EoE service request (set IP parameter …, EoE header
    /// first) ahead of any frame; the answer arrives in [`responses`](Self::responses).
    pub async fn request<S>(&mut self, sd: &SubDeviceRef<'_, S>, eoe: &[u8]) -> bool {
        self.write_mailbox(sd, MBX_EOE, eoe).await
    }

    /// One round: takes a message from SM1 if there is one, writes the next
    /// fragment into SM0 if it is free. Returns whether anything moved.
    pub async fn pump<S>(&mut self, sd: &SubDeviceRef<'_, S>) -> bool {
        let mut moved = false;
        let full = esc::sm::status::MAILBOX_FULL;
        let st1: u8 = sd.register_read(esc::regs::sm(1) + 5).await.unwrap_or(0);
        if st1 & full != 0 {
            if let Ok(buf) = sd.register_read::<[u8; MAILBOX_LEN]>(MAILBOX_IN).await {
                self.stats.mailbox_in += 1;
                moved = true;
                let len = usize::from(u16::from_le_bytes([buf[0], buf[1]])).min(MAILBOX_LEN - MBX_HEADER);
                let data = &buf[MBX_HEADER..MBX_HEADER + len];
                self.take(buf[5] & 0x0F, data);
            }
        }
        if self.tx.active() || !self.to_slave.is_empty() {
            let st0: u8 = sd.register_read(esc::regs::sm(0) + 5).await.unwrap_or(full);
            if st0 & full == 0 {
                let next = &mut self.to_slave;
                let frames_out = &mut self.stats.frames_out;
                self.tx.load(|buf| {
                    let f = next.pop_front()?;
                    let n = f.len().min(MAX_FRAME).min(buf.len());
                    buf[..n].copy_from_slice(&f[..n]);
                    *frames_out += 1;
                    Some(n)
                });
                let mut out = [0u8; MAILBOX_LEN - MBX_HEADER];
                if let Some(n) = self.tx.next(&mut out) {
                    moved |= self.write_mailbox(sd, MBX_EOE, &out[..n]).await;
                }
            }
        }
        moved
    }

    fn take(&mut self, kind: u8, data: &[u8]) {
        if kind != MBX_EOE {
            self.other.push((kind, data.to_vec()));
            return;
        }
        let Some(h) = EoeHeader::parse(data) else { return };
        if h.frame_type != frame_type::FRAGMENT {
            self.responses.push_back(data.to_vec());
            return;
        }
        if let Ok(Some(n)) = self.rx.push(&h, &data[HEADER_LEN..]) {
            self.from_slave.push_back(self.rx.frame()[..n].to_vec());
            self.stats.frames_in += 1;
        }
    }
}

/// A received frame for the host interface.
pub struct TunnelRx(Vec<u8>);

/// Room for a frame to the drive.
pub struct TunnelTx<'a>(&'a mut VecDeque<Vec<u8>>);

impl RxToken for TunnelRx {
    fn consume<R, F: FnOnce(&[u8]) -> R>(self, f: F) -> R {
        f(&self.0)
    }
}

impl TxToken for TunnelTx<'_> {
    fn consume<R, F: FnOnce(&mut [u8]) -> R>(self, len: usize, f: F) -> R {
        let mut buf = vec![0u8; len];
        let r = f(&mut buf);
        self.0.push_back(buf);
        r
    }
}

impl Device for EoeTunnel {
    type RxToken<'a> = TunnelRx;
    type TxToken<'a> = TunnelTx<'a>;

    fn receive(&mut self, _t: Instant) -> Option<(TunnelRx, TunnelTx<'_>)> {
        let f = self.from_slave.pop_front()?;
        Some((TunnelRx(f), TunnelTx(&mut self.to_slave)))
    }

    fn transmit(&mut self, _t: Instant) -> Option<TunnelTx<'_>> {
        Some(TunnelTx(&mut self.to_slave))
    }

    fn capabilities(&self) -> DeviceCapabilities {
        let mut caps = DeviceCapabilities::default();
        caps.medium = Medium::Ethernet;
        caps.max_transmission_unit = net::device::ETHERNET_MTU;
        caps
    }
}

/// The EoE set-IP-parameter request (EoE header first) for `ip`/`mask`/`gateway`,
/// as SOEM's `ecx_EOEsetIp` writes it: only the flagged fields, packed, each
/// address a little-endian UINT32 (the first octet last).
pub fn set_ip_request(ip: [u8; 4], mask: [u8; 4], gateway: [u8; 4]) -> Vec<u8> {
    let le = |a: [u8; 4]| [a[3], a[2], a[1], a[0]];
    let mut b = EoeHeader::response(frame_type::SET_IP_REQUEST, 0, 0)
        .to_bytes()
        .to_vec();
    b.extend_from_slice(&0x0Eu32.to_le_bytes()); // IP, mask, gateway
    b.extend_from_slice(&le(ip));
    b.extend_from_slice(&le(mask));
    b.extend_from_slice(&le(gateway));
    b
}

/// The EoE get-IP-parameter request (EoE header only).
pub fn get_ip_request() -> Vec<u8> {
    EoeHeader::response(frame_type::GET_IP_REQUEST, 0, 0)
        .to_bytes()
        .to_vec()
}

/// A master-side IP host on an [`EoeTunnel`]: a smoltcp interface with an
/// ICMP socket (ping), a UDP client socket and a UDP socket on port 123
/// (a simulated SNTP server). Buffers are leaked (test and bench use).
pub struct HostNet {
    /// The tunnel to the drive.
    pub tunnel: EoeTunnel,
    /// The host's interface.
    pub iface: smoltcp::iface::Interface,
    /// Its sockets.
    pub sockets: smoltcp::iface::SocketSet<'static>,
    /// ICMP socket (identifier [`PING_IDENT`]).
    pub icmp: smoltcp::iface::SocketHandle,
    /// UDP client socket (port [`HOST_UDP_PORT`]).
    pub udp: smoltcp::iface::SocketHandle,
    /// UDP socket on port 123.
    pub ntp: smoltcp::iface::SocketHandle,
}

/// ICMP echo identifier of [`HostNet`].
pub const PING_IDENT: u16 = 0x4242;
/// Local UDP port of [`HostNet`]'s client socket.
pub const HOST_UDP_PORT: u16 = 40_000;

fn leak<T: Clone>(v: T, n: usize) -> &'static mut [T] {
    vec![v; n].leak()
}

fn udp_socket() -> smoltcp::socket::udp::Socket<'static> {
    use smoltcp::socket::udp;
    udp::Socket::new(
        udp::PacketBuffer::new(leak(udp::PacketMetadata::EMPTY, 8), leak(0u8, 8192)),
        udp::PacketBuffer::new(leak(udp::PacketMetadata::EMPTY, 8), leak(0u8, 8192)),
    )
}

fn host_instant(now: Nanos) -> Instant {
    Instant::from_micros(now.as_us() as i64)
}

impl HostNet {
    /// A host with MAC `mac` and the addresses `ips` (address, prefix) at
    /// simulated time `now`.
    pub fn new(mac: [u8; 6], ips: &[([u8; 4], u8)], now: Nanos) -> Self {
        use smoltcp::iface::{Config, Interface, SocketSet};
        use smoltcp::socket::icmp;
        use smoltcp::wire::{EthernetAddress, HardwareAddress, IpCidr, Ipv4Address};
        let mut tunnel = EoeTunnel::new();
        let mut cfg = Config::new(HardwareAddress::Ethernet(EthernetAddress(mac)));
        cfg.random_seed = 1;
        let mut iface = Interface::new(cfg, &mut tunnel, host_instant(now));
        iface.update_ip_addrs(|a| {
            for &(ip, prefix) in ips {
                let _ = a.push(IpCidr::new(Ipv4Address::from(ip).into(), prefix));
            }
        });
        let slots: &'static mut [SocketStorage<'static>; 4] = Box::leak(Box::new([SocketStorage::EMPTY; 4]));
        let mut sockets = SocketSet::new(slots.as_mut_slice());
        let mut ping = icmp::Socket::new(
            icmp::PacketBuffer::new(leak(icmp::PacketMetadata::EMPTY, 8), leak(0u8, 4096)),
            icmp::PacketBuffer::new(leak(icmp::PacketMetadata::EMPTY, 8), leak(0u8, 4096)),
        );
        let _ = ping.bind(icmp::Endpoint::Ident(PING_IDENT));
        let mut udp = udp_socket();
        let _ = udp.bind(HOST_UDP_PORT);
        let mut ntp = udp_socket();
        let _ = ntp.bind(net::sntp::NTP_PORT);
        let icmp = sockets.add(ping);
        let udp = sockets.add(udp);
        let ntp = sockets.add(ntp);
        Self {
            tunnel,
            iface,
            sockets,
            icmp,
            udp,
            ntp,
        }
    }

    /// Adds a UDP socket bound to `port` (one more fits).
    pub fn add_udp(&mut self, port: u16) -> smoltcp::iface::SocketHandle {
        let mut s = udp_socket();
        let _ = s.bind(port);
        self.sockets.add(s)
    }

    /// Runs the host interface at `now`.
    pub fn poll(&mut self, now: Nanos) {
        self.iface
            .poll(host_instant(now), &mut self.tunnel, &mut self.sockets);
    }

    /// Sends an ICMP echo request with `payload` to `to`.
    pub fn send_ping(&mut self, to: [u8; 4], seq: u16, payload: &[u8]) -> bool {
        use smoltcp::phy::ChecksumCapabilities;
        use smoltcp::socket::icmp;
        use smoltcp::wire::{Icmpv4Packet, Icmpv4Repr, IpAddress, Ipv4Address};
        let repr = Icmpv4Repr::EchoRequest {
            ident: PING_IDENT,
            seq_no: seq,
            data: payload,
        };
        let sock = self.sockets.get_mut::<icmp::Socket>(self.icmp);
        let Ok(buf) = sock.send(repr.buffer_len(), IpAddress::Ipv4(Ipv4Address::from(to))) else {
            return false;
        };
        repr.emit(
            &mut Icmpv4Packet::new_unchecked(buf),
            &ChecksumCapabilities::default(),
        );
        true
    }

    /// The sequence number and payload of an echo reply received, if any.
    pub fn recv_pong(&mut self) -> Option<(u16, Vec<u8>)> {
        use smoltcp::phy::ChecksumCapabilities;
        use smoltcp::socket::icmp;
        use smoltcp::wire::{Icmpv4Packet, Icmpv4Repr};
        let sock = self.sockets.get_mut::<icmp::Socket>(self.icmp);
        while let Ok((data, _from)) = sock.recv() {
            let Ok(pkt) = Icmpv4Packet::new_checked(data) else {
                continue;
            };
            if let Ok(Icmpv4Repr::EchoReply { seq_no, data, .. }) =
                Icmpv4Repr::parse(&pkt, &ChecksumCapabilities::default())
            {
                return Some((seq_no, data.to_vec()));
            }
        }
        None
    }

    /// Sends `data` from the client socket to `to`:`port`.
    pub fn send_udp(&mut self, to: [u8; 4], port: u16, data: &[u8]) -> bool {
        use smoltcp::socket::udp;
        use smoltcp::wire::{IpAddress, IpEndpoint, Ipv4Address};
        let sock = self.sockets.get_mut::<udp::Socket>(self.udp);
        sock.send_slice(
            data,
            IpEndpoint::new(IpAddress::Ipv4(Ipv4Address::from(to)), port),
        )
        .is_ok()
    }

    /// A datagram the client socket received.
    pub fn recv_udp(&mut self) -> Option<Vec<u8>> {
        use smoltcp::socket::udp;
        let sock = self.sockets.get_mut::<udp::Socket>(self.udp);
        sock.recv().ok().map(|(d, _)| d.to_vec())
    }

    /// One step of the link: host interface, mailbox round, host interface.
    pub async fn step<S>(&mut self, sd: &SubDeviceRef<'_, S>, clock: &core::sync::atomic::AtomicU64) -> bool {
        use core::sync::atomic::Ordering;
        self.poll(Nanos::from_ns(clock.load(Ordering::Relaxed)));
        let moved = self.tunnel.pump(sd).await;
        self.poll(Nanos::from_ns(clock.load(Ordering::Relaxed)));
        moved
    }

    /// Pings `to` once and returns the round-trip time in simulated time
    /// (`None`: no reply within `max_steps` steps).
    pub async fn ping<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        clock: &core::sync::atomic::AtomicU64,
        to: [u8; 4],
        seq: u16,
        max_steps: usize,
    ) -> Option<Nanos> {
        self.ping_with(sd, clock, to, seq, 56, max_steps).await
    }

    /// [`ping`](Self::ping) with a payload of `len` bytes (up to 1472 in one frame).
    pub async fn ping_with<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        clock: &core::sync::atomic::AtomicU64,
        to: [u8; 4],
        seq: u16,
        len: usize,
        max_steps: usize,
    ) -> Option<Nanos> {
        use core::sync::atomic::Ordering;
        let payload: Vec<u8> = (0..len).map(|i| i as u8 ^ seq as u8).collect();
        let t0 = clock.load(Ordering::Relaxed);
        if !self.send_ping(to, seq, &payload) {
            return None;
        }
        for _ in 0..max_steps {
            self.step(sd, clock).await;
            if let Some((s, data)) = self.recv_pong() {
                if s == seq && data == payload {
                    return Some(Nanos::from_ns(clock.load(Ordering::Relaxed) - t0));
                }
            }
        }
        None
    }

    /// Sends a parameter-service request to `to` and returns the answer and
    /// its latency in simulated time.
    pub async fn param_request<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        clock: &core::sync::atomic::AtomicU64,
        to: [u8; 4],
        request: &str,
        max_steps: usize,
    ) -> Option<(String, Nanos)> {
        use core::sync::atomic::Ordering;
        let t0 = clock.load(Ordering::Relaxed);
        if !self.send_udp(to, net::param::PARAM_PORT, request.as_bytes()) {
            return None;
        }
        for _ in 0..max_steps {
            self.step(sd, clock).await;
            if let Some(d) = self.recv_udp() {
                return Some((
                    String::from_utf8_lossy(&d).into_owned(),
                    Nanos::from_ns(clock.load(Ordering::Relaxed) - t0),
                ));
            }
        }
        None
    }
}
