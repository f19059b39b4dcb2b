//! IP through EoE with a real master (E-095, E-096, E-102, E-105, E-106):
//! the master sets the drive's address with the EoE set-IP-parameter
//! service, pings it, reads and writes parameters over the UDP parameter
//! service and serves SNTP to it, all in simulated time through
//! hil-sim's master-side EoE tunnel (`hil_sim::eoe::HostNet`).

use drive_ecat::runtime::Drive;
use drive_tests::{al_status, init, line, with_master, CoeClient};
use ethercrab::SubDeviceRef;
use hil_sim::eoe::{get_ip_request, set_ip_request, DriveNet, HostNet};
use hil_sim::esc::{Esc, EscConfig};
use hil_sim::sim::{Node, SimFlash, Simulation};
use net::sntp::{to_ntp, NTP_UNIX_OFFSET_S};
use smoltcp::socket::udp;
use std::cell::RefCell;
use std::sync::atomic::{AtomicU64, Ordering};

const DRIVE_IP: [u8; 4] = [10, 0, 0, 20];
const HOST_IP: [u8; 4] = [10, 0, 0, 1];
const SERVER2_IP: [u8; 4] = [10, 0, 0, 2];
const MASK: [u8; 4] = [255, 255, 255, 0];
const DRIVE_MAC: [u8; 6] = [0x02, 0x00, 0x00, 0x00, 0x00, 0x14];
const HOST_MAC: [u8; 6] = [0x02, 0x00, 0x00, 0x00, 0x00, 0x01];
const STEPS: usize = 200;

fn sim_with_net() -> RefCell<Simulation> {
    let sim = line(1);
    sim.borrow_mut().drives_mut()[0].bind_net(DRIVE_MAC, 0x5EED, nanos::Nanos::from_ns(0));
    sim
}

/// Sets the drive's IP over EoE and waits for the answer.
async fn set_ip<S>(host: &mut HostNet, sd: &SubDeviceRef<'_, S>, clock: &AtomicU64) -> Vec<u8> {
    assert!(
        host.tunnel
            .request(sd, &set_ip_request(DRIVE_IP, MASK, HOST_IP))
            .await
    );
    for _ in 0..STEPS {
        host.step(sd, clock).await;
        if let Some(r) = host.tunnel.responses.pop_front() {
            return r;
        }
    }
    panic!("no set-IP response")
}

/// The master-side host at 10.0.0.1, the drive's address not set.
fn new_host(clock: &AtomicU64) -> HostNet {
    HostNet::new(
        HOST_MAC,
        &[(HOST_IP, 24)],
        nanos::Nanos::from_ns(clock.load(Ordering::Relaxed)),
    )
}

/// 1.1 s of simulated time on: the host repeats an unanswered ARP request
/// only 1 s after the last.
fn past_arp_retry(sim: &RefCell<Simulation>) {
    let now = sim.borrow().now().as_ns();
    sim.borrow_mut()
        .catch_up(nanos::Nanos::from_ns(now + 1_100_000_000));
}

/// The master-side host at 10.0.0.1 with the drive's address set over EoE.
async fn addressed_host<S>(sd: &SubDeviceRef<'_, S>, clock: &AtomicU64) -> HostNet {
    let mut host = new_host(clock);
    assert_eq!(set_ip(&mut host, sd, clock).await, vec![0x03, 0x01, 0x00, 0x00]);
    host
}

async fn ask<S>(host: &mut HostNet, sd: &SubDeviceRef<'_, S>, clock: &AtomicU64, req: &str) -> String {
    match host.param_request(sd, clock, DRIVE_IP, req, STEPS).await {
        Some((answer, _)) => answer,
        None => panic!("no answer to {req:?}"),
    }
}

#[test]
fn e096_e095_ping_and_parameters_over_udp() {
    let sim = sim_with_net();
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let mut host = new_host(clock);
        // no address yet: no answer
        assert_eq!(host.ping(&sd, clock, DRIVE_IP, 1, 60).await, None);
        // (the host repeats its unanswered ARP request only after 1 s)
        past_arp_retry(&sim);
        // E-096: the address from the master
        assert_eq!(set_ip(&mut host, &sd, clock).await, vec![0x03, 0x01, 0x00, 0x00]);
        let rtt = host
            .ping(&sd, clock, DRIVE_IP, 2, STEPS)
            .await
            .expect("echo reply");
        assert!(
            rtt > nanos::Nanos::ZERO && rtt < nanos::Nanos::from_ms(50),
            "rtt {rtt}"
        );
        // parameters by coordinate; writes only once the master opens them
        // with A269 over CoE (E-101, docs/eoe.md)
        assert_eq!(ask(&mut host, &sd, clock, "R A150").await, "OK 1000");
        assert_eq!(ask(&mut host, &sd, clock, "W A150 2000").await, "ERR 06010000");
        assert_eq!(ask(&mut host, &sd, clock, "W A269 1").await, "ERR 06010002");
        let mut coe = CoeClient::new();
        coe.hand_over(&sd).await;
        coe.download(&sd, drive_ecat::params::A269, 0, &[1])
            .await
            .unwrap();
        coe.hand_over(&sd).await;
        assert_eq!(ask(&mut host, &sd, clock, "W A150 2000").await, "OK");
        assert_eq!(ask(&mut host, &sd, clock, "R A150").await, "OK 2000");
        let axis_b = if drive_tests::variant().axes() == 2 {
            "OK A8C8:01"
        } else {
            "ERR 06020000" // the single-axis device has no axis-B window
        };
        assert_eq!(ask(&mut host, &sd, clock, "M 2.E200[0]").await, axis_b);
        let name = format!("OK {}", drive_tests::variant().device_name());
        assert_eq!(ask(&mut host, &sd, clock, "R E50").await, name);
        // refused writes: the SDO abort codes, nothing changed
        assert_eq!(ask(&mut host, &sd, clock, "W E50 XY").await, "ERR 06010002");
        assert_eq!(ask(&mut host, &sd, clock, "W A166 7").await, "ERR 06090031");
        assert_eq!(ask(&mut host, &sd, clock, "R A166").await, "OK 2");
        assert_eq!(ask(&mut host, &sd, clock, "R A511").await, "ERR 06020000");
        assert_eq!(ask(&mut host, &sd, clock, "W A150 twenty").await, "ERR SYNTAX");
        assert_eq!(ask(&mut host, &sd, clock, "R A150").await, "OK 2000");
        // a ping to another address on the subnet stays unanswered
        assert_eq!(host.ping(&sd, clock, [10, 0, 0, 21], 3, 60).await, None);
    });
    let mut s = sim.borrow_mut();
    let d = &mut s.drives_mut()[0];
    let mut buf = [0u8; 4];
    let n = d
        .drive
        .read_object(0x2096, 0, &mut buf, od::CommState::PreOp)
        .unwrap();
    assert_eq!(u16::from_le_bytes([buf[0], buf[1]]), 2000);
    assert_eq!(n, 2);
    let net = &d.net.as_ref().unwrap().stack();
    assert_eq!(net.ip(), Some((DRIVE_IP, 24)));
    assert_eq!(net.gateway(), Some(HOST_IP));
    assert_eq!(net.stats().param_requests, 13);
    assert_eq!(net.stats().param_writes_refused, 2);
    assert_eq!(net.stats().param_malformed, 1, "W A150 twenty");
    assert_eq!(d.drive.slave().eoe().params().ip, Some(DRIVE_IP));
}

/// E-101: a flood of parameter requests through the gateway is answered
/// at the service's rate (a burst of 16, then 100 per second), the rest
/// dropped and counted, oversized datagrams dropped unanswered; the drive
/// stays in its state without an error and its mailbox keeps answering
/// CoE; once the flood ends a request is answered again.
#[test]
fn e101_a_parameter_flood_is_rate_limited_and_the_drive_keeps_serving() {
    let sim = sim_with_net();
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let mut host = addressed_host(&sd, clock).await;
        assert_eq!(ask(&mut host, &sd, clock, "R A150").await, "OK 1000");
        let before = al_status(&sd).await;
        let t0 = sim.borrow().now();
        let (mut sent, mut answered) = (0u32, 0u32);
        let big = "R A150 ".repeat(60);
        for k in 0..400 {
            for _ in 0..4 {
                sent += u32::from(host.send_udp(DRIVE_IP, net::param::PARAM_PORT, b"R A150"));
            }
            if k % 50 == 0 {
                sent += u32::from(host.send_udp(DRIVE_IP, net::param::PARAM_PORT, big.as_bytes()));
            }
            // 1 ms of the line per round: 400 ms of flood
            let now = sim.borrow().now().as_ns();
            sim.borrow_mut().catch_up(nanos::Nanos::from_ns(now + 1_000_000));
            host.step(&sd, clock).await;
            while let Some(a) = host.recv_udp() {
                assert_eq!(a, b"OK 1000");
                answered += 1;
            }
        }
        let elapsed = sim.borrow().now().saturating_sub(t0);
        let allowed = net::PARAM_BURST + (elapsed.as_ns() / net::PARAM_REFILL.as_ns()) as u32 + 1;
        println!("figure: e101 flood: {sent} requests sent in {elapsed}, {answered} answered (the rate allows {allowed})");
        assert!(sent > 4 * allowed, "a flood: {sent} sent");
        assert!(
            answered >= allowed / 2 && answered <= allowed,
            "{answered} answered, {allowed} allowed: the rate, neither more nor starved"
        );
        assert_eq!(al_status(&sd).await, before, "AL state and code unchanged");
        let mut coe = CoeClient::new();
        coe.hand_over(&sd).await; // the mailbox answers CoE
        coe.hand_over(&sd).await;
        // the flood over, the service answers again
        let now = sim.borrow().now().as_ns();
        sim.borrow_mut()
            .catch_up(nanos::Nanos::from_ns(now + 200_000_000));
        while host.recv_udp().is_some() {}
        assert_eq!(ask(&mut host, &sd, clock, "R A150").await, "OK 1000");
    });
    let s = sim.borrow();
    let st = s.drives()[0].net.as_ref().unwrap().stack().stats();
    assert!(st.param_limited > 0, "{st:?}");
    assert!(st.param_malformed > 0, "the oversized datagrams: {st:?}");
}

#[test]
fn e099_refused_eoe_configuration_shows_er10() {
    let sim = sim_with_net();
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let mut host = addressed_host(&sd, clock).await;
        let er = |t: &str| t.split(' ').nth(1).unwrap_or_default().to_string();
        assert_eq!(er(&ask(&mut host, &sd, clock, "R A257[0]").await), "Er0");
        // the subnet's broadcast address: refused (0001h), the old address stays
        let bad = set_ip_request([10, 0, 0, 255], MASK, HOST_IP);
        assert!(host.tunnel.request(&sd, &bad).await);
        let mut resp = None;
        for _ in 0..STEPS {
            host.step(&sd, clock).await;
            if let Some(r) = host.tunnel.responses.pop_front() {
                resp = Some(r);
                break;
            }
        }
        assert_eq!(resp, Some(vec![0x03, 0x01, 0x01, 0x00]));
        assert_eq!(er(&ask(&mut host, &sd, clock, "R A257[0]").await), "Er10");
        // an accepted configuration clears it
        assert_eq!(set_ip(&mut host, &sd, clock).await, vec![0x03, 0x01, 0x00, 0x00]);
        assert_eq!(er(&ask(&mut host, &sd, clock, "R A257[0]").await), "Er0");
    });
}

/// A DHCP server on the host side of the tunnel: answers DISCOVER with an
/// OFFER and REQUEST with an ACK of `offer` (broadcast, as the client has no
/// address yet). Returns the message types it answered.
fn dhcp_serve(host: &mut HostNet, server: smoltcp::iface::SocketHandle, offer: [u8; 4]) -> Vec<&'static str> {
    use smoltcp::wire::{DhcpMessageType, DhcpPacket, DhcpRepr, IpAddress, IpEndpoint, Ipv4Address};
    let lease = net::testing::DhcpLease {
        server: HOST_IP,
        offer,
        mask: MASK,
        router: Some(HOST_IP),
        options: &[],
    };
    let mut answered = Vec::new();
    let sock = host.sockets.get_mut::<udp::Socket>(server);
    while let Ok((data, _)) = sock.recv() {
        let data = data.to_vec();
        let pkt = DhcpPacket::new_checked(&data[..]).unwrap();
        let req = DhcpRepr::parse(&pkt).unwrap();
        let mut buf = [0u8; 576];
        let Some((kind, reply)) = lease.answer(&req, &mut buf) else {
            continue;
        };
        let to = IpEndpoint::new(IpAddress::Ipv4(Ipv4Address::BROADCAST), 68);
        sock.send_slice(reply, to).unwrap();
        answered.push(if kind == DhcpMessageType::Offer {
            "offer"
        } else {
            "ack"
        });
    }
    answered
}

#[test]
fn e098_dhcp_while_a166_is_2_until_the_master_sets_an_address() {
    let sim = sim_with_net();
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let mut host = new_host(clock);
        let server = host.add_udp(67);
        // E-098: nothing before the master has used EoE
        for _ in 0..100 {
            host.step(&sd, clock).await;
            assert!(dhcp_serve(&mut host, server, [10, 0, 0, 50]).is_empty());
        }
        assert_eq!(host.tunnel.stats().frames_in, 0, "the drive sent nothing yet");
        // the master asks for the IP parameters: it uses EoE
        assert!(host.tunnel.request(&sd, &get_ip_request()).await);
        host.step(&sd, clock).await;
        let r = host.tunnel.responses.pop_front().expect("get IP response");
        assert_eq!(
            &r[..4],
            &[0x07, 0x01, 0x00, 0x00],
            "get IP response, success, nothing set"
        );
        // A166 = 2 (default): DISCOVER, OFFER, REQUEST, ACK
        let mut answered = Vec::new();
        for _ in 0..400 {
            host.step(&sd, clock).await;
            answered.extend(dhcp_serve(&mut host, server, [10, 0, 0, 50]));
            if answered.len() == 2 {
                break;
            }
        }
        assert_eq!(answered, ["offer", "ack"]);
        // the ACK on its way to the drive
        for _ in 0..20 {
            host.step(&sd, clock).await;
        }
        let leased = [10, 0, 0, 50];
        assert!(
            host.ping(&sd, clock, leased, 1, STEPS).await.is_some(),
            "ping the leased address"
        );
        assert_eq!(
            host.param_request(&sd, clock, leased, "R A166", STEPS)
                .await
                .map(|a| a.0),
            Some("OK 2".to_string())
        );
        // the master's address wins and DHCP stops
        assert_eq!(set_ip(&mut host, &sd, clock).await, vec![0x03, 0x01, 0x00, 0x00]);
        // (the host sends its next ARP request only 1 s after the last)
        past_arp_retry(&sim);
        assert!(host.ping(&sd, clock, DRIVE_IP, 2, STEPS).await.is_some());
        assert_eq!(
            host.ping(&sd, clock, leased, 3, 60).await,
            None,
            "the lease is gone"
        );
    });
    let s = sim.borrow();
    let net = &s.drives()[0].net.as_ref().unwrap().stack();
    assert_eq!(net.ip(), Some((DRIVE_IP, 24)));
    assert!(!net.address_from_dhcp());
}

#[test]
fn e098_no_dhcp_when_a166_is_not_2() {
    let sim = sim_with_net();
    // A166 = 0 before the first poll
    sim.borrow_mut().drives_mut()[0]
        .drive
        .objects_mut()
        .set(0x20A6, 0, 0)
        .unwrap();
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let mut host = new_host(clock);
        let server = host.add_udp(67);
        // the master uses EoE (E-098): DHCP could start now, but A166 says no
        assert!(host.tunnel.request(&sd, &get_ip_request()).await);
        host.step(&sd, clock).await;
        assert!(host.tunnel.responses.pop_front().is_some(), "get IP response");
        for _ in 0..200 {
            host.step(&sd, clock).await;
            assert!(dhcp_serve(&mut host, server, [10, 0, 0, 50]).is_empty());
        }
        assert_eq!(host.tunnel.stats().frames_in, 0, "the drive sent no frame");
    });
    assert_eq!(sim.borrow().drives()[0].net.as_ref().unwrap().stack().ip(), None);
}

/// A drive without motors or control cycles, with its IP stack: six
/// simulated hours stay cheap (the 1 ms motor steps would be 21.6 million).
struct NetNode {
    esc: Esc,
    drive: Drive<SimFlash>,
    net: DriveNet,
}

impl NetNode {
    fn new() -> Self {
        let mut sii = [0u8; ecat::sii::EEPROM_BYTES];
        let n = ecat::build_sii(&drive_ecat::DEVICE, &mut sii).unwrap();
        let mut drive = Drive::new(SimFlash::new());
        let net = DriveNet::new(&mut drive, DRIVE_MAC, 0x5EED, nanos::Nanos::ZERO);
        Self {
            esc: Esc::new(EscConfig::default(), &sii[..n]),
            drive,
            net,
        }
    }
}

impl Node for NetNode {
    fn esc_mut(&mut self) -> &mut Esc {
        &mut self.esc
    }
    fn poll(&mut self, now: nanos::Nanos) {
        self.esc.tick(now);
        let _ = self.drive.poll(&mut self.esc.pdi(), now);
        self.net.poll(&mut self.drive, now);
    }
}

/// The simulated SNTP server's clock at simulation time `t_ns`: Unix
/// 1.7·10⁹ s at 0, running 25 ppm faster than the simulation.
fn server_ntp_ns(t_ns: u64) -> u64 {
    (NTP_UNIX_OFFSET_S + 1_700_000_000) * 1_000_000_000 + t_ns + t_ns / 40_000
}

/// The server's answer to `req` at `t_ns`.
fn sntp_answer(req: &[u8], t_ns: u64) -> [u8; 48] {
    let mut a = [0u8; 48];
    a[0] = 0x24;
    a[1] = 2;
    a[24..32].copy_from_slice(&req[40..48]);
    let ts = to_ntp(server_ntp_ns(t_ns)).to_be_bytes();
    a[32..40].copy_from_slice(&ts);
    a[40..48].copy_from_slice(&ts);
    a
}

/// Requests the simulated servers saw: (simulation time, server address).
type Seen = Vec<(u64, [u8; 4])>;

/// Advances the simulation to `until_ns` in steps of `step_ns`, moving the
/// mailbox each step, or until `seen` holds `stop` requests; the servers
/// answer while `answer(server)` says so.
#[allow(clippy::too_many_arguments)] // a test helper: the run's parameters spelled out
async fn run_until<S>(
    sim: &RefCell<Simulation<NetNode>>,
    host: &mut HostNet,
    sd: &SubDeviceRef<'_, S>,
    clock: &AtomicU64,
    until_ns: u64,
    step_ns: u64,
    answer: &dyn Fn([u8; 4]) -> bool,
    seen: &mut Seen,
    stop: usize,
) {
    loop {
        let now = sim.borrow().now().as_ns();
        if now >= until_ns || seen.len() >= stop {
            return;
        }
        sim.borrow_mut()
            .catch_up(nanos::Nanos::from_ns((now + step_ns).min(until_ns)));
        loop {
            pump(host, sd, clock).await;
            // each request is answered as soon as the host has it
            let now = sim.borrow().now().as_ns();
            let sock = host.sockets.get_mut::<udp::Socket>(host.ntp);
            let mut got = false;
            while let Ok((data, meta)) = sock.recv() {
                got = true;
                let data = data.to_vec();
                let server = match meta.local_address {
                    Some(smoltcp::wire::IpAddress::Ipv4(a)) => a.octets(),
                    None => [0; 4],
                };
                assert_eq!(data.len(), 48);
                assert_eq!(data[0] & 0x3F, 0x23, "version 4, client mode");
                seen.push((now, server));
                if answer(server) {
                    sock.send_slice(&sntp_answer(&data, now), meta).unwrap();
                }
            }
            if !got {
                break;
            }
        }
    }
}

/// Moves the mailbox until nothing moved for three rounds and nothing waits
/// (the drive fills SM1 at its poll after a frame: one idle round is not
/// yet quiet).
async fn pump<S>(host: &mut HostNet, sd: &SubDeviceRef<'_, S>, clock: &AtomicU64) {
    let mut idle = 0;
    for _ in 0..100 {
        if host.step(sd, clock).await || host.tunnel.busy() {
            idle = 0;
        } else {
            idle += 1;
            if idle == 3 {
                return;
            }
        }
    }
}

const S: u64 = 1_000_000_000;
const H: u64 = 3600 * S;

#[test]
fn e105_e106_e102_sntp_over_eoe_in_simulated_time() {
    let sim = RefCell::new(Simulation::with_nodes(vec![NetNode::new()]));
    let mut seen = Seen::new();
    let config = ethercrab::MainDeviceConfig {
        dc_static_sync_iterations: 100,
        ..Default::default()
    };
    hil_sim::master::run_with(&sim, drive_tests::timeouts(), config, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let t0 = clock.load(Ordering::Relaxed);
        let mut host = HostNet::new(
            HOST_MAC,
            &[(HOST_IP, 24), (SERVER2_IP, 24)],
            nanos::Nanos::from_ns(t0),
        );
        assert_eq!(set_ip(&mut host, &sd, clock).await, vec![0x03, 0x01, 0x00, 0x00]);
        // A199: on, servers 10.0.0.1 and 10.0.0.2 (written by the master;
        // the UDP service only reads while A269 = 0)
        let a199 = drive_ecat::parameter_index(0, 199);
        let mut coe = CoeClient::new();
        coe.hand_over(&sd).await;
        coe.download(&sd, a199, 1, &[1]).await.unwrap();
        coe.download(&sd, a199, 2, &0x0A00_0001u32.to_le_bytes())
            .await
            .unwrap();
        coe.download(&sd, a199, 3, &0x0A00_0002u32.to_le_bytes())
            .await
            .unwrap();
        coe.hand_over(&sd).await;
        assert_eq!(ask(&mut host, &sd, clock, "R A199[2]").await, "OK 167772162");
        // E-105: the first request 1..5 min after power-on, to server 1
        run_until(&sim, &mut host, &sd, clock, 310 * S, S, &|_| true, &mut seen, 9).await;
        assert_eq!(seen.len(), 1, "{seen:?}");
        let (first, server) = seen[0];
        assert!((60 * S..=301 * S).contains(&first), "first request at {first} ns");
        assert_eq!(server, HOST_IP);
        // E-102: the drive's clock follows the server (compared where it was
        // set: the rate is learnt from the second answer on)
        let now = first;
        let drive_time = sim.borrow().drives()[0]
            .net
            .stack()
            .sntp_time(nanos::Nanos::from_ns(now))
            .map(nanos::Nanos::as_ns);
        let server_unix = server_ntp_ns(now) - NTP_UNIX_OFFSET_S * S;
        let err = drive_time.expect("SNTP time") as i64 - server_unix as i64;
        assert!(err.abs() < 1_000_000, "clock error {err} ns");
        // E-106: the next request 5..6 h later to the same server; it stays
        // unanswered, so after the time-out the next server is asked
        let no_s1 = |s: [u8; 4]| s != HOST_IP;
        run_until(
            &sim,
            &mut host,
            &sd,
            clock,
            first + 5 * H,
            600 * S,
            &no_s1,
            &mut seen,
            9,
        )
        .await;
        assert_eq!(seen.len(), 1, "{seen:?}");
        run_until(
            &sim,
            &mut host,
            &sd,
            clock,
            first + 6 * H + 10 * S,
            10 * S,
            &no_s1,
            &mut seen,
            2,
        )
        .await;
        assert!(seen.len() >= 2, "{seen:?}");
        let (second, server) = seen[1];
        assert!(
            (first + 5 * H..=first + 6 * H + 10 * S).contains(&second),
            "second request at {second}"
        );
        assert_eq!(server, HOST_IP);
        run_until(
            &sim,
            &mut host,
            &sd,
            clock,
            second + 90 * S,
            S,
            &no_s1,
            &mut seen,
            9,
        )
        .await;
        assert_eq!(seen.len(), 3, "{seen:?}");
        let (third, server) = seen[2];
        assert_eq!(server, SERVER2_IP, "the next server only after the failure");
        // time-out 5 s, retry after 60 s (polled every 1 s here)
        assert!((second + 64 * S..=second + 67 * S).contains(&third), "{seen:?}");
    });
    let s = sim.borrow();
    let net = &s.drives()[0].net.stack();
    let st = net.sntp().stats();
    assert_eq!((st.requests, st.answers, st.failures), (3, 2, 1), "{st:?}");
    // two answers 5..6 h apart: the 25 ppm rate difference is learned
    assert!(
        (net.sntp().rate_ppb() - 25_000).abs() < 500,
        "rate {}",
        net.sntp().rate_ppb()
    );
}

/// SOEM reads the mailbox without an EoE handler: an EoE fragment the drive
/// sent unasked answers its next SDO request and fails it. A master that
/// speaks only CoE must get only CoE answers, on every drive of a line, for
/// as long as it runs; DHCP (A166 = 2, the default) starts once the master
/// has used EoE.
#[test]
fn e098_coe_only_master_gets_only_coe_answers_on_a_line() {
    const DRIVES: usize = 3;
    let sim = line(DRIVES);
    for (i, d) in (1u8..).zip(sim.borrow_mut().drives_mut()) {
        d.bind_net([0x02, 0, 0, 0, 0, i], u64::from(i), nanos::Nanos::from_ns(0));
    }
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        for k in 0..1000 {
            for (i, sd) in group.iter(md).enumerate() {
                let v: u32 = match sd.sdo_read(0x1000, 0).await {
                    Ok(v) => v,
                    Err(e) => panic!("request {k} to drive {i}: {e}"),
                };
                assert_eq!(v & 0xFFFF, 402, "device type: CiA 402");
            }
        }
        let queued: Vec<u32> = sim
            .borrow()
            .drives()
            .iter()
            .map(|d| d.drive.eoe().stats().tx_frames)
            .collect();
        assert_eq!(
            queued, [0; DRIVES],
            "no EoE frame left a drive for a CoE-only master"
        );
        // the master starts to use EoE on drive 0: its DHCP client starts
        let sd = group.subdevice(md, 0).unwrap();
        let mut host = new_host(clock);
        let server = host.add_udp(67);
        assert!(host.tunnel.request(&sd, &get_ip_request()).await);
        let mut answered = Vec::new();
        for _ in 0..400 {
            host.step(&sd, clock).await;
            answered.extend(dhcp_serve(&mut host, server, [10, 0, 0, 50]));
            if !answered.is_empty() {
                break;
            }
        }
        assert_eq!(
            answered.first(),
            Some(&"offer"),
            "DHCP DISCOVER after the master used EoE"
        );
    });
    let s = sim.borrow();
    let sent: Vec<u32> = s
        .drives()
        .iter()
        .map(|d| d.drive.eoe().stats().tx_frames)
        .collect();
    assert!(sent[0] > 0, "drive 0 sent its DHCP frames");
    assert_eq!(&sent[1..], &[0; DRIVES - 1], "the others sent nothing");
}
