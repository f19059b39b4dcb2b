//! Raw Ethernet (AF_PACKET) transport: the simulated line answers EtherCAT
//! frames on a real or virtual network interface, so any master can drive it.
//! Linux only; needs root or CAP_NET_RAW.

use std::io;
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::time::Duration;

/// EtherType of EtherCAT frames.
pub const ETHERTYPE_ECAT: u16 = 0x88A4;

/// An AF_PACKET socket bound to one interface, receiving only EtherCAT frames.
pub struct RawSocket {
    fd: OwnedFd,
    ifindex: i32,
}

impl RawSocket {
    /// Opens a socket on `iface` (name shorter than 16 bytes).
    pub fn open(iface: &str) -> io::Result<Self> {
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
            let proto = (ETHERTYPE_ECAT).to_be() as i32;
            let raw = libc::socket(libc::AF_PACKET, libc::SOCK_RAW, proto);
            if raw < 0 {
                return Err(io::Error::last_os_error());
            }
            let fd = OwnedFd::from_raw_fd(raw);
            let mut sll: libc::sockaddr_ll = std::mem::zeroed();
            sll.sll_family = libc::AF_PACKET as u16;
            sll.sll_protocol = ETHERTYPE_ECAT.to_be();
            sll.sll_ifindex = ifindex;
            let r = libc::bind(
                fd.as_raw_fd(),
                &sll as *const libc::sockaddr_ll as *const libc::sockaddr,
                std::mem::size_of::<libc::sockaddr_ll>() as u32,
            );
            if r < 0 {
                return Err(io::Error::last_os_error());
            }
            Ok(Self { fd, ifindex })
        }
    }

    /// Waits up to `timeout` for an incoming frame (frames this host sent are
    /// skipped); returns its length, or `None` on timeout.
    pub fn recv(&self, buf: &mut [u8], timeout: Duration) -> io::Result<Option<usize>> {
        let mut pfd = libc::pollfd {
            fd: self.fd.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        };
        let ms = i32::try_from(timeout.as_millis()).unwrap_or(i32::MAX);
        #[allow(unsafe_code)]
        // SAFETY: pfd and buf are valid for the duration of the calls.
        unsafe {
            if libc::poll(&mut pfd, 1, ms) <= 0 {
                return Ok(None);
            }
            let mut sll: libc::sockaddr_ll = std::mem::zeroed();
            let mut sl = std::mem::size_of::<libc::sockaddr_ll>() as libc::socklen_t;
            let n = libc::recvfrom(
                self.fd.as_raw_fd(),
                buf.as_mut_ptr().cast(),
                buf.len(),
                0,
                &mut sll as *mut libc::sockaddr_ll as *mut libc::sockaddr,
                &mut sl,
            );
            if n < 0 {
                return Err(io::Error::last_os_error());
            }
            if sll.sll_pkttype == libc::PACKET_OUTGOING {
                return Ok(None);
            }
            Ok(Some(n as usize))
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
