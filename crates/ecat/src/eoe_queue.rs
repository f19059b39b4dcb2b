//! The drive's EoE interface as two small frame queues (E-095): what the
//! master tunnels to the drive waits in the receive queue for the IP stack,
//! what the IP stack sends waits in the transmit queue for SM1. Heap-free,
//! [`QUEUE_FRAMES`] frames of up to [`MAX_FRAME`] bytes each way. The IP
//! stack (crate `net`) sits on top of it; the slave stack sees only
//! [`EthernetPort`].

use crate::eoe::{fnv1a, EthernetPort, IpParams, MAX_FRAME};
use heapless::{Deque, Vec};

/// Frames each queue holds. One: the mailbox task polls the IP stack after
/// every mailbox request, so a reassembled frame is taken before the next
/// can be complete, and the stack takes a frame only when its answer has
/// room (`net::device`); a second slot each way cost 3 KiB of the board's
/// RAM for no frame that would otherwise be lost (issue 18).
pub const QUEUE_FRAMES: usize = 1;

/// One Ethernet frame (destination MAC first, no FCS).
pub type Frame = Vec<u8, MAX_FRAME>;

/// Counters of the queue.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct QueueStats {
    /// Frames dropped because the receive queue was full.
    pub rx_overflow: u32,
    /// Frames refused because the transmit queue was full.
    pub tx_overflow: u32,
    /// Frames handed to SM1.
    pub tx_frames: u32,
}

/// Receive and transmit queues between the slave's EoE server and an IP stack.
#[derive(Clone)]
pub struct EoeQueue {
    rx: Deque<Frame, QUEUE_FRAMES>,
    tx: Deque<Frame, QUEUE_FRAMES>,
    /// Frames received from the master (also those dropped for a full queue).
    pub frames: u32,
    /// Length of the last frame received.
    pub last_len: usize,
    /// FNV-1a (32 bit) of the last frame received.
    pub last_hash: u32,
    stats: QueueStats,
    /// IP parameters set by the master since the IP stack last looked.
    ip: Option<IpParams>,
}

impl Default for EoeQueue {
    fn default() -> Self {
        Self::new()
    }
}

impl EoeQueue {
    /// Empty queues.
    pub const fn new() -> Self {
        Self {
            rx: Deque::new(),
            tx: Deque::new(),
            frames: 0,
            last_len: 0,
            last_hash: 0,
            stats: QueueStats {
                rx_overflow: 0,
                tx_overflow: 0,
                tx_frames: 0,
            },
            ip: None,
        }
    }

    /// The oldest received frame, removed from the queue.
    pub fn pop_rx(&mut self) -> Option<Frame> {
        self.rx.pop_front()
    }

    /// Whether a received frame waits.
    pub fn rx_pending(&self) -> bool {
        !self.rx.is_empty()
    }

    /// Whether the transmit queue has room for one more frame.
    pub fn tx_ready(&self) -> bool {
        !self.tx.is_full()
    }

    /// Queues a frame of `len` bytes that `fill` writes; `false` (and nothing
    /// queued) when the queue is full or `len` is beyond [`MAX_FRAME`].
    pub fn push_tx_with(&mut self, len: usize, fill: impl FnOnce(&mut [u8])) -> bool {
        let mut f = Frame::new();
        if self.tx.is_full() || f.resize(len, 0).is_err() {
            self.stats.tx_overflow = self.stats.tx_overflow.wrapping_add(1);
            return false;
        }
        fill(&mut f);
        self.tx.push_back(f).is_ok()
    }

    /// Queues `frame` for the master; `false` when it does not fit.
    pub fn push_tx(&mut self, frame: &[u8]) -> bool {
        // element-wise: the lengths are equal, but `copy_from_slice` would
        // keep a panic path the compiler cannot rule out (scripts/cross panics)
        self.push_tx_with(frame.len(), |b| {
            for (d, s) in b.iter_mut().zip(frame) {
                *d = *s;
            }
        })
    }

    /// The IP parameters the master set since the last call (E-096).
    pub fn take_ip_change(&mut self) -> Option<IpParams> {
        self.ip.take()
    }

    /// Counters.
    pub fn stats(&self) -> QueueStats {
        self.stats
    }

    /// Drops every queued frame (the counters stay).
    pub fn clear(&mut self) {
        self.rx.clear();
        self.tx.clear();
    }
}

impl EthernetPort for EoeQueue {
    fn receive(&mut self, frame: &[u8]) {
        self.frames = self.frames.wrapping_add(1);
        self.last_len = frame.len();
        self.last_hash = fnv1a(frame);
        let mut f = Frame::new();
        if f.extend_from_slice(frame).is_err() || self.rx.push_back(f).is_err() {
            self.stats.rx_overflow = self.stats.rx_overflow.wrapping_add(1);
        }
    }

    fn transmit(&mut self, buf: &mut [u8]) -> Option<usize> {
        let f = self.tx.front()?;
        let n = f.len();
        let dst = buf.get_mut(..n)?;
        dst.copy_from_slice(f);
        self.tx.pop_front();
        self.stats.tx_frames = self.stats.tx_frames.wrapping_add(1);
        Some(n)
    }

    fn ip_changed(&mut self, params: &IpParams) {
        self.ip = Some(*params);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// E-095: each queue holds [`QUEUE_FRAMES`] frames in order; one more
    /// is dropped and counted, and a frame stays queued until SM1 takes it.
    #[test]
    fn e095_queue_fifo_and_overflow() {
        let mut q = EoeQueue::new();
        for k in 0..=QUEUE_FRAMES {
            q.receive(&[k as u8; 60 + 10 * QUEUE_FRAMES][..60 + 10 * k]);
        }
        let last = 60 + 10 * QUEUE_FRAMES;
        assert_eq!((q.frames as usize, q.last_len), (QUEUE_FRAMES + 1, last));
        assert_eq!(
            q.last_hash,
            fnv1a(&[QUEUE_FRAMES as u8; 60 + 10 * QUEUE_FRAMES][..last])
        );
        assert_eq!(q.stats().rx_overflow, 1);
        for k in 0..QUEUE_FRAMES {
            assert_eq!(q.pop_rx().map(|f| f.len()), Some(60 + 10 * k));
        }
        assert!(q.pop_rx().is_none());

        for k in 0..QUEUE_FRAMES {
            assert!(q.push_tx(&[7 + k as u8; 100][..100 - k]));
        }
        assert!(!q.tx_ready());
        assert!(!q.push_tx(&[9; 10]));
        assert!(!q.push_tx_with(MAX_FRAME + 1, |_| {}));
        assert_eq!(q.stats().tx_overflow, 2);
        let mut buf = [0u8; MAX_FRAME];
        // a buffer too small keeps the frame queued
        assert_eq!(q.transmit(&mut [0u8; 10]), None);
        for k in 0..QUEUE_FRAMES {
            assert_eq!(q.transmit(&mut buf), Some(100 - k));
            assert_eq!(buf.get(..100 - k), Some(&[7 + k as u8; 100][..100 - k]));
        }
        assert_eq!(q.transmit(&mut buf), None);
        assert!(q.tx_ready());
        assert_eq!(q.stats().tx_frames as usize, QUEUE_FRAMES);
    }

    #[test]
    fn e096_ip_change_is_forwarded_once() {
        let mut q = EoeQueue::new();
        assert_eq!(q.take_ip_change(), None);
        let p = IpParams {
            ip: Some([10, 0, 0, 5]),
            ..IpParams::default()
        };
        q.ip_changed(&p);
        assert_eq!(q.take_ip_change(), Some(p));
        assert_eq!(q.take_ip_change(), None);
    }
}
