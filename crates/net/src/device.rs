//! The EoE queue as a smoltcp [`Device`]: frames the master tunnelled in
//! are received, frames sent go to the transmit queue for SM1.

use ecat::eoe_queue::{EoeQueue, Frame, QUEUE_FRAMES};
use smoltcp::phy::{Device, DeviceCapabilities, Medium, RxToken, TxToken};
use smoltcp::time::Instant;

/// Largest IP packet plus Ethernet header smoltcp sends (MTU 1500).
pub const ETHERNET_MTU: usize = 1514;

/// [`EoeQueue`] borrowed as a smoltcp device for one poll.
pub struct QueueDevice<'q>(pub &'q mut EoeQueue);

/// A received frame (owned: taken out of the queue).
pub struct QueueRx(Frame);

/// Room in the transmit queue.
pub struct QueueTx<'q>(&'q mut EoeQueue);

impl RxToken for QueueRx {
    fn consume<R, F>(self, f: F) -> R
    where
        F: FnOnce(&[u8]) -> R,
    {
        f(&self.0)
    }
}

impl TxToken for QueueTx<'_> {
    fn consume<R, F>(self, len: usize, f: F) -> R
    where
        F: FnOnce(&mut [u8]) -> R,
    {
        let mut frame = Frame::new();
        // smoltcp never asks for more than the MTU; a longer frame is cut
        // to the buffer and then dropped by the queue
        let _ = frame.resize(len.min(frame.capacity()), 0);
        let r = f(&mut frame);
        if frame.len() == len {
            let _ = self.0.push_tx(&frame);
        }
        r
    }
}

impl Device for QueueDevice<'_> {
    type RxToken<'a>
        = QueueRx
    where
        Self: 'a;
    type TxToken<'a>
        = QueueTx<'a>
    where
        Self: 'a;

    fn receive(&mut self, _timestamp: Instant) -> Option<(Self::RxToken<'_>, Self::TxToken<'_>)> {
        // a frame is taken only when its answer has room
        if !self.0.tx_ready() {
            return None;
        }
        let f = self.0.pop_rx()?;
        Some((QueueRx(f), QueueTx(self.0)))
    }

    fn transmit(&mut self, _timestamp: Instant) -> Option<Self::TxToken<'_>> {
        self.0.tx_ready().then_some(QueueTx(self.0))
    }

    fn capabilities(&self) -> DeviceCapabilities {
        let mut caps = DeviceCapabilities::default();
        caps.medium = Medium::Ethernet;
        caps.max_transmission_unit = ETHERNET_MTU;
        caps.max_burst_size = Some(QUEUE_FRAMES);
        caps
    }
}
