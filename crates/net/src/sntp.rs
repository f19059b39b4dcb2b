//! SNTP client (RFC 4330, spec §10), sans-IO: it says when to send which
//! request to which server and takes the answers; the socket is the
//! stack's ([`crate::NetStack`]). Time is always an argument (`now_us`, the
//! drive's local monotonic clock since power-on, in whole µs; [`crate::NetStack`]
//! takes it as [`Nanos`] and hands the client `now.as_us()`).//!
//! - First request after a random delay of 1–5 min (E-105), then every
//!   5–6 h (random within) to the same server (E-106).
//! - A server that does not answer within [`RESPONSE_TIMEOUT_US`] or
//!   answers unusably (kiss-o'-death, wrong mode, unsynchronised) fails: the
//!   next configured server is tried after [`RETRY_US`]; a server that
//!   answers stays in use.
//! - Each answer gives the clock offset; the first one sets the clock, the
//!   following ones also trim its rate (E-102). [`SntpClient::time_ns`]
//!   is the disciplined clock.

use nanos::Nanos;

/// Length of an SNTP packet.
pub const PACKET_LEN: usize = 48;
/// UDP port of NTP.
pub const NTP_PORT: u16 = 123;
/// An answer later than this after the request is a failure, µs.
pub const RESPONSE_TIMEOUT_US: u64 = 5_000_000;
/// After a failure the next server is asked after this, µs.
pub const RETRY_US: u64 = 60_000_000;
/// First request: earliest, latest after power-on, µs (E-105).
pub const FIRST_DELAY_US: (u64, u64) = (60_000_000, 300_000_000);
/// Repetition interval: shortest, longest, µs (E-106).
pub const INTERVAL_US: (u64, u64) = (5 * 3_600_000_000, 6 * 3_600_000_000);
/// Largest rate correction the client applies, ppb (±500 ppm).
pub const MAX_RATE_PPB: i64 = 500_000;
/// Seconds from the NTP era (1900-01-01) to the Unix epoch (1970-01-01).
pub const NTP_UNIX_OFFSET_S: u64 = 2_208_988_800;

/// An IPv4 address (network byte order).
pub type Ipv4 = [u8; 4];

/// A seeded pseudo-random generator (SplitMix64): deterministic.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rng(u64);

impl Rng {
    /// Seeded.
    pub const fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `lo..=hi`.
    pub fn range(&mut self, lo: u64, hi: u64) -> u64 {
        let span = hi.saturating_sub(lo).saturating_add(1);
        lo.saturating_add(self.next_u64() % span)
    }
}

/// What configures the client (A199, spec §10).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SntpConfig {
    /// A199\[0\]: the client runs.
    pub active: bool,
    /// A199\[1\], A199\[2\]: the servers (0.0.0.0 = none).
    pub servers: [Ipv4; 2],
}

impl SntpConfig {
    /// Server `i` if it is a unicast address (0.0.0.0 = none; broadcast
    /// and multicast are not servers).
    fn server(&self, i: usize) -> Option<Ipv4> {
        self.servers.get(i).copied().filter(|&[a, b, c, d]| {
            [a, b, c, d] != [0; 4] && [a, b, c, d] != [255; 4] && !(224..=239).contains(&a)
        })
    }
}

/// A request to send: 48 bytes to `server`, port [`NTP_PORT`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Request {
    /// The server.
    pub server: Ipv4,
    /// The packet.
    pub packet: [u8; PACKET_LEN],
}

/// Why an answer was not used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reject {
    /// No request outstanding, or from another server.
    Unexpected,
    /// Shorter than 48 bytes.
    TooShort,
    /// Originate time stamp is not the request's transmit time stamp (a
    /// stale or forged answer): ignored, the request stays outstanding.
    Originate,
    /// Kiss-o'-death (stratum 0), not a server answer, leap indicator
    /// "unsynchronised" or a zero transmit time stamp: the server fails.
    Unusable,
}

/// Counters and state for diagnosis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SntpStats {
    /// Requests sent.
    pub requests: u32,
    /// Answers used.
    pub answers: u32,
    /// Server failures (timeouts, unusable answers).
    pub failures: u32,
    /// Index of the server in use (0 or 1).
    pub server: u8,
    /// Last measured offset, ns (signed).
    pub last_offset_ns: i64,
    /// Last round-trip delay, ns.
    pub last_delay_ns: i64,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Pending {
    server: Ipv4,
    sent_us: u64,
    /// The transmit time stamp we sent (raw NTP format).
    t1_raw: u64,
    /// Our clock at sending, ns since 1900.
    t1_ns: u64,
}

/// The disciplined clock: NTP ns since 1900 at local `ref_us`, running at
/// `1 + rate_ppb·10⁻⁹` times the local clock.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Clock {
    ref_us: u64,
    ref_ns: u64,
    rate_ppb: i64,
}

impl Clock {
    fn at(&self, now_us: u64) -> u64 {
        let dt_ns = i128::from(now_us) * 1000 - i128::from(self.ref_us) * 1000;
        let corr = dt_ns * i128::from(self.rate_ppb) / 1_000_000_000;
        let t = i128::from(self.ref_ns) + dt_ns + corr;
        t.clamp(0, i128::from(u64::MAX)) as u64
    }
}

/// The SNTP client.
#[derive(Debug, Clone)]
pub struct SntpClient {
    rng: Rng,
    next_us: u64,
    current: usize,
    pending: Option<Pending>,
    clock: Option<Clock>,
    /// Local time of the last answer used, µs.
    last_sync_us: Option<u64>,
    stats: SntpStats,
}

impl SntpClient {
    /// Powered on at local time 0; `seed` drives the random delays.
    pub fn new(seed: u64) -> Self {
        let mut rng = Rng::new(seed);
        let next_us = rng.range(FIRST_DELAY_US.0, FIRST_DELAY_US.1);
        Self {
            rng,
            next_us,
            current: 0,
            pending: None,
            clock: None,
            last_sync_us: None,
            stats: SntpStats::default(),
        }
    }

    /// Local time of the next request, µs.
    pub fn next_request_us(&self) -> u64 {
        self.next_us
    }

    /// Counters.
    pub fn stats(&self) -> SntpStats {
        self.stats
    }

    /// The server asked next (or being asked).
    pub fn current_server(&self, cfg: &SntpConfig) -> Option<Ipv4> {
        cfg.server(self.current)
            .or_else(|| cfg.server(1 - self.current.min(1)))
    }

    /// Our clock, NTP ns since 1900 (local time before the first answer).
    fn clock_ns(&self, now_us: u64) -> u64 {
        match &self.clock {
            Some(c) => c.at(now_us),
            None => now_us.saturating_mul(1000),
        }
    }

    /// The SNTP time at local `now_us`: ns since the Unix epoch, `None`
    /// before the first answer.
    pub fn time_ns(&self, now_us: u64) -> Option<u64> {
        let c = self.clock.as_ref()?;
        c.at(now_us).checked_sub(NTP_UNIX_OFFSET_S * 1_000_000_000)
    }

    /// The rate correction in force, ppb.
    pub fn rate_ppb(&self) -> i64 {
        self.clock.map_or(0, |c| c.rate_ppb)
    }

    /// Runs the schedule at `now_us`: a request to send, if one is due.
    /// `can_send`: the interface has an address and a route to the server.
    pub fn poll(&mut self, now_us: u64, cfg: &SntpConfig, can_send: bool) -> Option<Request> {
        if let Some(p) = self.pending {
            if now_us.saturating_sub(p.sent_us) < RESPONSE_TIMEOUT_US {
                return None;
            }
            self.fail(now_us);
        }
        if !cfg.active || now_us < self.next_us {
            return None;
        }
        if cfg.server(self.current).is_none() {
            // the server in use was removed from the configuration
            self.current = 1 - self.current.min(1);
        }
        let server = cfg.server(self.current)?;
        if !can_send {
            return None;
        }
        let t1_ns = self.clock_ns(now_us);
        let t1_raw = to_ntp(t1_ns);
        let mut packet = [0u8; PACKET_LEN];
        // LI 0, version 4, mode 3 (client)
        if let Some(b) = packet.first_mut() {
            *b = 0x23;
        }
        if let Some(b) = packet.get_mut(40..48) {
            b.copy_from_slice(&t1_raw.to_be_bytes());
        }
        self.pending = Some(Pending {
            server,
            sent_us: now_us,
            t1_raw,
            t1_ns,
        });
        self.stats.requests = self.stats.requests.wrapping_add(1);
        Some(Request { server, packet })
    }

    fn fail(&mut self, now_us: u64) {
        self.pending = None;
        self.stats.failures = self.stats.failures.wrapping_add(1);
        self.current = 1 - self.current.min(1);
        self.stats.server = self.current as u8;
        self.next_us = now_us.saturating_add(RETRY_US);
    }

    /// An answer from `from` arrived at local `now_us`.
    pub fn on_response(&mut self, now_us: u64, from: Ipv4, data: &[u8]) -> Result<(), Reject> {
        let p = self
            .pending
            .filter(|p| p.server == from)
            .ok_or(Reject::Unexpected)?;
        let field = |off: usize| -> Result<u64, Reject> {
            let b = data.get(off..off + 8).ok_or(Reject::TooShort)?;
            let mut a = [0u8; 8];
            a.copy_from_slice(b);
            Ok(u64::from_be_bytes(a))
        };
        let (originate, receive, transmit) = (field(24)?, field(32)?, field(40)?);
        let first = data.first().copied().ok_or(Reject::TooShort)?;
        let stratum = data.get(1).copied().ok_or(Reject::TooShort)?;
        if originate != p.t1_raw {
            return Err(Reject::Originate);
        }
        let (li, mode) = (first >> 6, first & 7);
        if mode != 4 || stratum == 0 || li == 3 || transmit == 0 {
            self.fail(now_us);
            return Err(Reject::Unusable);
        }
        let t1 = i128::from(p.t1_ns);
        let t2 = i128::from(from_ntp(receive));
        let t3 = i128::from(from_ntp(transmit));
        let t4_ns = self.clock_ns(now_us);
        let t4 = i128::from(t4_ns);
        let offset = ((t2 - t1) + (t3 - t4)) / 2;
        let delay = (t4 - t1) - (t3 - t2);
        let offset64 = offset.clamp(i128::from(i64::MIN), i128::from(i64::MAX)) as i64;
        let rate_ppb = match (self.clock, self.last_sync_us) {
            (Some(c), Some(last)) if now_us > last => {
                // the offset gathered since the last answer is the rate error
                let dt_ns = i128::from(now_us - last) * 1000;
                let err = offset * 1_000_000_000 / dt_ns;
                (i128::from(c.rate_ppb) + err).clamp(i128::from(-MAX_RATE_PPB), i128::from(MAX_RATE_PPB))
                    as i64
            }
            (Some(c), _) => c.rate_ppb,
            (None, _) => 0,
        };
        let ref_ns = (t4 + offset).clamp(0, i128::from(u64::MAX)) as u64;
        self.clock = Some(Clock {
            ref_us: now_us,
            ref_ns,
            rate_ppb,
        });
        self.last_sync_us = Some(now_us);
        self.pending = None;
        self.next_us = now_us.saturating_add(self.rng.range(INTERVAL_US.0, INTERVAL_US.1));
        self.stats.answers = self.stats.answers.wrapping_add(1);
        self.stats.server = self.current as u8;
        self.stats.last_offset_ns = offset64;
        self.stats.last_delay_ns = delay.clamp(i128::from(i64::MIN), i128::from(i64::MAX)) as i64;
        Ok(())
    }
}

/// ns since 1900 → NTP time stamp (seconds · 2³² + fraction), era folded.
pub fn to_ntp(ns: u64) -> u64 {
    let s = ns / 1_000_000_000;
    let frac = ((ns % 1_000_000_000) << 32) / 1_000_000_000;
    ((s & 0xFFFF_FFFF) << 32) | frac
}

/// NTP time stamp → ns since 1900; seconds with the top bit clear are era 1
/// (from 2036, RFC 4330 §3).
pub fn from_ntp(ts: u64) -> u64 {
    let mut s = ts >> 32;
    if s & 0x8000_0000 == 0 {
        s += 1 << 32;
    }
    let frac = ((ts & 0xFFFF_FFFF) * 1_000_000_000) >> 32;
    s * 1_000_000_000 + frac
}

/// Seconds from 1970-01-01 to the DC epoch 2000-01-01.
pub const DC_EPOCH_UNIX_S: u64 = 946_684_800;

/// The time stamp of a message (spec §17, E-147), ns since 2000-01-01 (the
/// DC system time's epoch): the DC system time when the drive is
/// DC-synchronised, else the SNTP time (Unix ns), else 0.
pub fn message_time_stamp(dc_synced: Option<Nanos>, sntp_unix: Option<Nanos>) -> Nanos {
    match (dc_synced, sntp_unix) {
        (Some(dc), _) => dc,
        (None, Some(unix)) => unix.saturating_sub(Nanos::from_secs(DC_EPOCH_UNIX_S)),
        (None, None) => Nanos::ZERO,
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    extern crate std;
    use super::*;

    const S1: Ipv4 = [10, 0, 0, 1];
    const S2: Ipv4 = [10, 0, 0, 2];
    const H: u64 = 3_600_000_000;

    fn cfg() -> SntpConfig {
        SntpConfig {
            active: true,
            servers: [S1, S2],
        }
    }

    /// A server whose clock is `base_ns + t·(1 + ppm)` (NTP ns) at local `t`.
    fn answer(req: &Request, t_us: u64, base_ns: u64, ppm: f64) -> [u8; 48] {
        let server = base_ns + (t_us as f64 * 1000.0 * (1.0 + ppm * 1e-6)) as u64;
        let mut a = [0u8; 48];
        a[0] = 0x24; // LI 0, VN 4, mode 4
        a[1] = 2;
        a[24..32].copy_from_slice(&req.packet[40..48]);
        a[32..40].copy_from_slice(&to_ntp(server).to_be_bytes());
        a[40..48].copy_from_slice(&to_ntp(server).to_be_bytes());
        a
    }

    #[test]
    fn e105_first_request_after_1_to_5_minutes() {
        let mut seen = std::collections::BTreeSet::new();
        for seed in 0..200 {
            let mut c = SntpClient::new(seed);
            let t = c.next_request_us();
            assert!((60_000_000..=300_000_000).contains(&t), "{t}");
            seen.insert(t / 60_000_000);
            assert_eq!(c.poll(t - 1, &cfg(), true), None);
            assert_eq!(c.poll(t, &cfg(), true).unwrap().server, S1);
        }
        // spread over the whole window
        assert!(seen.len() >= 4, "{seen:?}");
        // inactive or no route: nothing
        let mut c = SntpClient::new(1);
        let t = c.next_request_us();
        let off = SntpConfig {
            active: false,
            ..cfg()
        };
        assert_eq!(c.poll(t, &off, true), None);
        assert_eq!(c.poll(t, &cfg(), false), None);
        assert!(c.poll(t, &cfg(), true).is_some());
    }

    #[test]
    fn e103_e106_same_server_every_5_to_6_hours_next_only_on_failure() {
        let mut c = SntpClient::new(7);
        let base = (NTP_UNIX_OFFSET_S + 1_700_000_000) * 1_000_000_000;
        let mut t = c.next_request_us();
        for _ in 0..4 {
            let r = c.poll(t, &cfg(), true).unwrap();
            assert_eq!(r.server, S1);
            assert_eq!(c.poll(t + 1000, &cfg(), true), None, "one request outstanding");
            c.on_response(t + 2000, S1, &answer(&r, t + 1000, base, 0.0))
                .unwrap();
            let next = c.next_request_us();
            assert!((5 * H..=6 * H).contains(&(next - (t + 2000))), "{}", next - t);
            assert_eq!(c.poll(next - 1, &cfg(), true), None);
            t = next;
        }
        // S1 stops answering: timeout, S2 after the retry delay, and S2 stays
        let r = c.poll(t, &cfg(), true).unwrap();
        assert_eq!(r.server, S1);
        assert_eq!(c.poll(t + RESPONSE_TIMEOUT_US - 1, &cfg(), true), None);
        assert_eq!(c.poll(t + RESPONSE_TIMEOUT_US, &cfg(), true), None);
        assert_eq!(c.stats().failures, 1);
        let t2 = t + RESPONSE_TIMEOUT_US + RETRY_US;
        let r = c.poll(t2, &cfg(), true).unwrap();
        assert_eq!(r.server, S2);
        c.on_response(t2 + 10, S2, &answer(&r, t2 + 5, base, 0.0))
            .unwrap();
        let t3 = c.next_request_us();
        let r = c.poll(t3, &cfg(), true).unwrap();
        assert_eq!(r.server, S2);
        // an answer from elsewhere or with a stale originate is ignored
        let good = answer(&r, t3 + 5, base, 0.0);
        assert_eq!(c.on_response(t3 + 10, S1, &good), Err(Reject::Unexpected));
        let mut stale = good;
        stale[24] ^= 1;
        assert_eq!(c.on_response(t3 + 10, S2, &stale), Err(Reject::Originate));
        assert_eq!(c.on_response(t3 + 10, S2, &good[..30]), Err(Reject::TooShort));
        // a kiss-o'-death answer fails S2: S1 is asked next
        let mut kod = good;
        kod[1] = 0;
        assert_eq!(c.on_response(t3 + 10, S2, &kod), Err(Reject::Unusable));
        assert_eq!(c.stats().failures, 2);
        assert_eq!(c.poll(t3 + 10 + RETRY_US - 1, &cfg(), true), None);
        assert_eq!(c.poll(t3 + 10 + RETRY_US, &cfg(), true).unwrap().server, S1);
    }

    #[test]
    fn e102_clock_follows_server_and_trims_its_rate() {
        let mut c = SntpClient::new(3);
        assert_eq!(c.time_ns(0), None);
        let base = (NTP_UNIX_OFFSET_S + 1_700_000_000) * 1_000_000_000;
        // the server's clock runs 40 ppm faster than the drive's oscillator
        let ppm = 40.0;
        for _ in 0..3 {
            let t = c.next_request_us();
            let r = c.poll(t, &cfg(), true).unwrap();
            // 2 ms round trip, symmetric
            c.on_response(t + 2000, S1, &answer(&r, t + 1000, base, ppm))
                .unwrap();
        }
        assert!((c.rate_ppb() - 40_000).abs() < 100, "rate {}", c.rate_ppb());
        // 5 h later the clock is still within 1 ms of the server
        let t = c.next_request_us() - 1;
        let server_unix =
            base + (t as f64 * 1000.0 * (1.0 + ppm * 1e-6)) as u64 - NTP_UNIX_OFFSET_S * 1_000_000_000;
        let err = c.time_ns(t).unwrap() as i64 - server_unix as i64;
        assert!(err.abs() < 1_000_000, "error {err} ns");
        // the 2 ms round trip, measured on the drive's disciplined clock
        assert!(
            (c.stats().last_delay_ns - 2_000_000).abs() < 10_000,
            "{:?}",
            c.stats()
        );
    }

    #[test]
    fn e147_time_stamp_dc_then_sntp_then_zero() {
        assert_eq!(
            message_time_stamp(Some(Nanos::from_ns(5)), Some(Nanos::from_secs(7_000_000_000))),
            Nanos::from_ns(5)
        );
        let unix = Nanos::from_secs(DC_EPOCH_UNIX_S + 10);
        assert_eq!(message_time_stamp(None, Some(unix)), Nanos::from_secs(10));
        assert_eq!(message_time_stamp(None, None), Nanos::ZERO);
    }

    #[test]
    fn ntp_time_stamp_round_trip() {
        let ns = (NTP_UNIX_OFFSET_S + 1_700_000_000) * 1_000_000_000 + 123_456_789;
        let back = from_ntp(to_ntp(ns));
        assert!(ns.abs_diff(back) <= 1);
    }
}
