//! Raw Ethernet (AF_PACKET) transport: the simulated line answers EtherCAT
//! frames on a real or virtual network interface, so any master can drive it.
//! Linux only; needs root or CAP_NET_RAW.
//!
//! Every received frame carries the kernel's receive timestamp
//! (`SO_TIMESTAMPNS`, [`Received::rx`]): `hil-sim serve` runs the
//! simulation to that instant before processing the frame, so neither its own
//! waiting nor its scheduling delays change the timing the drive sees.

use nanos::Nanos;
use std::io;
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::time::Duration;

/// EtherType of EtherCAT frames.
pub const ETHERTYPE_ECAT: u16 = 0x88A4;

/// `PACKET_IGNORE_OUTGOING` (Linux 4.20): the socket does not see the frames
/// this host sends.
const PACKET_IGNORE_OUTGOING: libc::c_int = 23;

/// One received frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Received {
    /// Length of the frame in the buffer, bytes.
    pub len: usize,
    /// This host sent the frame (only from [`RawSocket::open_sniffer`]).
    pub outgoing: bool,
    /// When the kernel received it, on `CLOCK_MONOTONIC` (the time base of
    /// [`monotonic`]); `None` if the kernel gave no timestamp.
    pub rx: Option<Nanos>,
}

/// Reads a clock, ns.
fn clock_ns(clock: libc::clockid_t) -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: ts is a valid timespec to write.
    #[allow(unsafe_code)]
    unsafe {
        libc::clock_gettime(clock, &mut ts);
    }
    timespec_ns(&ts)
}

fn timespec_ns(ts: &libc::timespec) -> u64 {
    let s = u64::try_from(ts.tv_sec).unwrap_or(0);
    let ns = u64::try_from(ts.tv_nsec).unwrap_or(0);
    s.saturating_mul(1_000_000_000).saturating_add(ns)
}

/// `CLOCK_MONOTONIC` (what [`std::time::Instant`] reads on Linux).
pub fn monotonic() -> Nanos {
    Nanos::from_ns(clock_ns(libc::CLOCK_MONOTONIC))
}

/// A `CLOCK_REALTIME` instant (socket timestamps) on the `CLOCK_MONOTONIC`
/// time base, with the offset between the clocks as it is now (both clocks
/// are slewed alike; only a step of the wall clock changes the offset, and
/// then only frames received before the step are misplaced).
pub fn monotonic_from_realtime(realtime: Nanos) -> Nanos {
    let mono = clock_ns(libc::CLOCK_MONOTONIC);
    let real = clock_ns(libc::CLOCK_REALTIME);
    let mono2 = clock_ns(libc::CLOCK_MONOTONIC);
    // the realtime reading sits between the two monotonic ones
    let offset = i128::from(real) - (i128::from(mono) + i128::from(mono2)) / 2;
    Nanos::from_ns(u64::try_from((i128::from(realtime.as_ns()) - offset).max(0)).unwrap_or(0))
}

/// An AF_PACKET socket bound to one interface, receiving only EtherCAT frames.
pub struct RawSocket {
    fd: OwnedFd,
    ifindex: i32,
    /// Frames this host sends are received too ([`RawSocket::open_sniffer`]).
    sniff: bool,
}

impl RawSocket {
    /// Opens a socket on `iface` (name shorter than 16 bytes).
    pub fn open(iface: &str) -> io::Result<Self> {
        Self::open_with(iface, false)
    }

    /// Like [`RawSocket::open`], but receives every frame on `iface`, of any
    /// EtherType, including those this host sends ([`Received::outgoing`],
    /// stamped when they left): tests watch a master's frames on the wire.
    pub fn open_sniffer(iface: &str) -> io::Result<Self> {
        Self::open_with(iface, true)
    }

    fn open_with(iface: &str, sniff: bool) -> io::Result<Self> {
        if iface.is_empty() || iface.len() >= libc::IFNAMSIZ {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                "interface name must have 1..15 bytes",
            ));
        }
        let name = std::ffi::CString::new(iface)
            .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "interface name contains NUL"))?;
        // SAFETY: plain libc calls with valid arguments; the fd is owned right away.
        #[allow(unsafe_code)]
        unsafe {
            let ifindex = libc::if_nametoindex(name.as_ptr()) as i32;
            if ifindex == 0 {
                return Err(io::Error::last_os_error());
            }
            // outgoing frames reach only ETH_P_ALL sockets: a sniffer takes every frame
            let ethertype = if sniff {
                libc::ETH_P_ALL as u16
            } else {
                ETHERTYPE_ECAT
            };
            let proto = ethertype.to_be() as i32;
            let raw = libc::socket(libc::AF_PACKET, libc::SOCK_RAW, proto);
            if raw < 0 {
                return Err(io::Error::last_os_error());
            }
            let fd = OwnedFd::from_raw_fd(raw);
            let mut sll: libc::sockaddr_ll = std::mem::zeroed();
            sll.sll_family = libc::AF_PACKET as u16;
            sll.sll_protocol = ethertype.to_be();
            sll.sll_ifindex = ifindex;
            let r = libc::bind(
                fd.as_raw_fd(),
                &sll as *const libc::sockaddr_ll as *const libc::sockaddr,
                std::mem::size_of::<libc::sockaddr_ll>() as u32,
            );
            if r < 0 {
                return Err(io::Error::last_os_error());
            }
            let on: libc::c_int = 1;
            let opt = |level, name| {
                libc::setsockopt(
                    fd.as_raw_fd(),
                    level,
                    name,
                    (&on as *const libc::c_int).cast(),
                    std::mem::size_of::<libc::c_int>() as u32,
                )
            };
            if opt(libc::SOL_SOCKET, libc::SO_TIMESTAMPNS) < 0 {
                return Err(io::Error::last_os_error());
            }
            // best effort: without it our own frames are skipped one by one
            if !sniff {
                let _ = opt(libc::SOL_PACKET, PACKET_IGNORE_OUTGOING);
            }
            Ok(Self { fd, ifindex, sniff })
        }
    }

    /// Waits up to `timeout` for an incoming frame; returns its length, or
    /// `None` on timeout.
    pub fn recv(&self, buf: &mut [u8], timeout: Duration) -> io::Result<Option<usize>> {
        if !self.wait(timeout)? {
            return Ok(None);
        }
        Ok(self.try_recv(buf)?.map(|r| r.len))
    }

    /// Waits up to `timeout` (µs resolution) until a frame can be read;
    /// `false` on timeout or a signal.
    pub fn wait(&self, timeout: Duration) -> io::Result<bool> {
        let mut pfd = libc::pollfd {
            fd: self.fd.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        };
        let ts = libc::timespec {
            tv_sec: libc::time_t::try_from(timeout.as_secs()).unwrap_or(libc::time_t::MAX),
            // below 10^9: fits a c_long of any width
            tv_nsec: timeout.subsec_nanos() as libc::c_long,
        };
        // SAFETY: pfd and ts are valid for the duration of the call.
        #[allow(unsafe_code)]
        let r = unsafe { libc::ppoll(&mut pfd, 1, &ts, std::ptr::null()) };
        if r < 0 {
            let e = io::Error::last_os_error();
            return if e.kind() == io::ErrorKind::Interrupted {
                Ok(false)
            } else {
                Err(e)
            };
        }
        Ok(r > 0)
    }

    /// Reads one waiting frame without blocking, with its kernel receive
    /// time; `None` if no frame waits. Frames this host sent are skipped
    /// (unless the socket is a sniffer).
    pub fn try_recv(&self, buf: &mut [u8]) -> io::Result<Option<Received>> {
        loop {
            // SAFETY: all-zero bytes are a valid sockaddr_ll and msghdr (plain C data).
            #[allow(unsafe_code)]
            let (mut sll, mut msg): (libc::sockaddr_ll, libc::msghdr) =
                unsafe { (std::mem::zeroed(), std::mem::zeroed()) };
            let mut iov = libc::iovec {
                iov_base: buf.as_mut_ptr().cast(),
                iov_len: buf.len(),
            };
            // room for one cmsghdr with a timespec (and some to spare)
            let mut control = [0u64; 16];
            msg.msg_name = (&mut sll as *mut libc::sockaddr_ll).cast();
            msg.msg_namelen = std::mem::size_of::<libc::sockaddr_ll>() as libc::socklen_t;
            msg.msg_iov = &mut iov;
            msg.msg_iovlen = 1;
            msg.msg_control = control.as_mut_ptr().cast();
            msg.msg_controllen = std::mem::size_of_val(&control) as _;
            // SAFETY: msg points at sll, iov (over buf) and control, all
            // valid and exclusively borrowed for the call.
            #[allow(unsafe_code)]
            let n = unsafe { libc::recvmsg(self.fd.as_raw_fd(), &mut msg, libc::MSG_DONTWAIT) };
            if n < 0 {
                let e = io::Error::last_os_error();
                return match e.kind() {
                    io::ErrorKind::WouldBlock => Ok(None),
                    io::ErrorKind::Interrupted => continue,
                    _ => Err(e),
                };
            }
            let outgoing = sll.sll_pkttype == libc::PACKET_OUTGOING;
            if outgoing && !self.sniff {
                continue;
            }
            let len = (n as usize).min(buf.len());
            return Ok(Some(Received {
                len,
                outgoing,
                rx: rx_timestamp(&msg).map(|t| monotonic_from_realtime(Nanos::from_ns(t))),
            }));
        }
    }

    /// Sends one whole Ethernet frame.
    pub fn send(&self, frame: &[u8]) -> io::Result<()> {
        #[allow(unsafe_code)]
        // SAFETY: frame is valid for reads of its length; sll is fully initialised.
        unsafe {
            let mut sll: libc::sockaddr_ll = std::mem::zeroed();
            sll.sll_family = libc::AF_PACKET as u16;
            sll.sll_protocol = ETHERTYPE_ECAT.to_be();
            sll.sll_ifindex = self.ifindex;
            sll.sll_halen = 6;
            if let Some(dst) = frame.get(..6) {
                sll.sll_addr[..6].copy_from_slice(dst);
            }
            let n = libc::sendto(
                self.fd.as_raw_fd(),
                frame.as_ptr().cast(),
                frame.len(),
                0,
                &sll as *const libc::sockaddr_ll as *const libc::sockaddr,
                std::mem::size_of::<libc::sockaddr_ll>() as u32,
            );
            if n < 0 {
                return Err(io::Error::last_os_error());
            }
        }
        Ok(())
    }
}

/// The `SCM_TIMESTAMPNS` control message of a received message, realtime ns.
fn rx_timestamp(msg: &libc::msghdr) -> Option<u64> {
    // SAFETY: msg was filled by recvmsg; the CMSG macros stay within
    // msg_control/msg_controllen, and the timespec is read unaligned.
    #[allow(unsafe_code)]
    unsafe {
        let mut c = libc::CMSG_FIRSTHDR(msg);
        while !c.is_null() {
            if (*c).cmsg_level == libc::SOL_SOCKET && (*c).cmsg_type == libc::SCM_TIMESTAMPNS {
                let ts: libc::timespec = std::ptr::read_unaligned(libc::CMSG_DATA(c).cast());
                return Some(timespec_ns(&ts));
            }
            c = libc::CMSG_NXTHDR(msg, c);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn realtime_maps_onto_the_monotonic_clock() {
        let mono = monotonic().as_ns();
        let real = clock_ns(libc::CLOCK_REALTIME);
        let back = monotonic_from_realtime(Nanos::from_ns(real)).as_ns();
        assert!(back.abs_diff(mono) < 1_000_000, "{back} vs {mono}");
        // a realtime instant 1 ms earlier maps 1 ms earlier
        let earlier = monotonic_from_realtime(Nanos::from_ns(real - 1_000_000)).as_ns();
        assert!(back.abs_diff(earlier + 1_000_000) < 100_000);
    }
}
