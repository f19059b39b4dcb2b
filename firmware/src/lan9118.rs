//! The SMSC LAN9118 Ethernet controller of QEMU's MPS2 boards
//! (`hw/net/lan9118.c`; on the real AN386 FPGA board a LAN9220, software
//! compatible): a MAC and PHY behind 32-bit registers with a receive and
//! a transmit FIFO, no DMA; on `mps2-an386` at 0x4020_0000, interrupt 13.
//!
//! Receive: `RX_FIFO_INF.RXSUSED` counts the frames waiting; each has a
//! status word (`RX_STATUS_FIFO`: its length with the 4-byte FCS in bits
//! 29:16, error flags) and its bytes, four per word little-endian, in the
//! data FIFO (`RX_DATA_FIFO`), the last word padded.
//!
//! Transmit: TX command A (buffer size, first and last segment), TX
//! command B (frame length), then the frame, four bytes per word, into
//! `TX_DATA_FIFO`; the MAC pads short frames and appends the FCS. The
//! frame's status word (`TX_STATUS_FIFO`) is read back after each frame.
//!
//! MAC registers (`MAC_CR`, the address) go through `MAC_CSR_CMD` /
//! `MAC_CSR_DATA`. QEMU's PHY reports the link up once a peer is attached;
//! the MAC does not need it to send. Every frame byte goes through bounded
//! slice access: a length out of range drains the frame and drops it.

use core::ptr;

/// The controller's register block on `mps2-an386`.
pub const BASE: usize = 0x4020_0000;

const RX_DATA_FIFO: usize = 0x00;
const TX_DATA_FIFO: usize = 0x20;
const RX_STATUS_FIFO: usize = 0x40;
const TX_STATUS_FIFO: usize = 0x48;
const ID_REV: usize = 0x50;
const IRQ_CFG: usize = 0x54;
const INT_STS: usize = 0x58;
const INT_EN: usize = 0x5C;
const BYTE_TEST: usize = 0x64;
const FIFO_INT: usize = 0x68;
const RX_CFG: usize = 0x6C;
const TX_CFG: usize = 0x70;
const HW_CFG: usize = 0x74;
const RX_FIFO_INF: usize = 0x7C;
const TX_FIFO_INF: usize = 0x80;
const MAC_CSR_CMD: usize = 0xA4;
const MAC_CSR_DATA: usize = 0xA8;

/// `BYTE_TEST` reads this when the bus and the chip are there.
const BYTE_TEST_VALUE: u32 = 0x8765_4321;

/// `IRQ_CFG`: interrupt pin on, active high, push-pull.
const IRQ_EN: u32 = 1 << 8;
const IRQ_POL: u32 = 1 << 4;
const IRQ_TYPE: u32 = 1 << 0;
/// `INT_STS`/`INT_EN`: receive status FIFO above its level (a frame).
pub const INT_RSFL: u32 = 1 << 3;
/// `INT_STS`: receiver error (data FIFO read past a frame).
pub const INT_RXE: u32 = 1 << 14;
/// `INT_STS`: transmit data FIFO overrun.
pub const INT_TDFO: u32 = 1 << 10;
/// `HW_CFG.SRST`: soft reset (self-clearing).
const HW_CFG_SRST: u32 = 1 << 0;
/// `TX_CFG`: transmitter on; dump the status FIFO.
const TX_CFG_TX_ON: u32 = 1 << 1;
const TX_CFG_TXS_DUMP: u32 = 1 << 15;
/// `RX_CFG.RX_DUMP`: empty the receive FIFOs.
const RX_CFG_RX_DUMP: u32 = 1 << 15;
/// `MAC_CSR_CMD`: busy (write: start), read (not write).
const CSR_BUSY: u32 = 1 << 31;
const CSR_READ: u32 = 1 << 30;

const MAC_CR: u32 = 1;
const MAC_ADDRH: u32 = 2;
const MAC_ADDRL: u32 = 3;
/// `MAC_CR`: full duplex, all multicast in (DCP, LLDP), transmitter and
/// receiver on; unicast only for the station address (no PRMS).
const MAC_CR_FDPX: u32 = 1 << 20;
const MAC_CR_MCPAS: u32 = 1 << 19;
const MAC_CR_TXEN: u32 = 1 << 3;
const MAC_CR_RXEN: u32 = 1 << 2;

/// TX command A: first and last segment of a frame in one buffer.
const TX_A_FIRST: u32 = 1 << 13;
const TX_A_LAST: u32 = 1 << 12;

/// The longest frame taken (1518: a VLAN-tagged 1500-byte payload).
pub const MAX_FRAME: usize = 1518;
/// The shortest frame sent or taken (an Ethernet header).
const MIN_FRAME: usize = 14;
/// Polls of a busy bit before giving up (QEMU completes at once).
const WAIT: u32 = 100_000;
/// Words of the largest frame the data FIFO holds (2 KiB).
const MAX_WORDS: usize = 2048 / 4;

/// Why the controller did not come up or a frame was not sent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Error {
    /// `BYTE_TEST` did not read 0x87654321: no LAN9118 at this address.
    NotFound(u32),
    /// The soft reset or a MAC register access did not complete.
    Timeout,
    /// Shorter than an Ethernet header or longer than [`MAX_FRAME`].
    Length,
    /// The transmit data FIFO has no room for the frame.
    Busy,
}

/// The controller (one instance: it owns the register block).
pub struct Lan9118 {
    base: usize,
}

impl Lan9118 {
    /// The controller at `base`.
    ///
    /// # Safety
    /// `base` is a LAN9118's register block and nothing else uses it while
    /// this value lives.
    #[allow(unsafe_code)]
    pub const unsafe fn new(base: usize) -> Lan9118 {
        Lan9118 { base }
    }

    #[allow(unsafe_code)]
    fn read(&self, off: usize) -> u32 {
        // SAFETY: a register of the block `new` was given.
        unsafe { ptr::read_volatile((self.base + off) as *const u32) }
    }

    #[allow(unsafe_code)]
    fn write(&self, off: usize, v: u32) {
        // SAFETY: a register of the block `new` was given.
        unsafe { ptr::write_volatile((self.base + off) as *mut u32, v) }
    }

    fn wait_clear(&self, off: usize, bit: u32) -> Result<(), Error> {
        let mut n = WAIT;
        while self.read(off) & bit != 0 {
            n = n.checked_sub(1).ok_or(Error::Timeout)?;
        }
        Ok(())
    }

    fn mac_read(&self, reg: u32) -> Result<u32, Error> {
        self.wait_clear(MAC_CSR_CMD, CSR_BUSY)?;
        self.write(MAC_CSR_CMD, CSR_BUSY | CSR_READ | reg);
        self.wait_clear(MAC_CSR_CMD, CSR_BUSY)?;
        Ok(self.read(MAC_CSR_DATA))
    }

    fn mac_write(&self, reg: u32, v: u32) -> Result<(), Error> {
        self.wait_clear(MAC_CSR_CMD, CSR_BUSY)?;
        self.write(MAC_CSR_DATA, v);
        self.write(MAC_CSR_CMD, CSR_BUSY | reg);
        self.wait_clear(MAC_CSR_CMD, CSR_BUSY)
    }

    /// Soft reset, FIFOs emptied, MAC on (see `MAC_CR_*`), transmitter on,
    /// interrupts off until [`listen`](Lan9118::listen). Returns the
    /// station address (QEMU: the NIC's `macaddr=`, through the EEPROM the
    /// chip loads at reset) and `ID_REV`.
    pub fn start(&self) -> Result<([u8; 6], u32), Error> {
        let test = self.read(BYTE_TEST);
        if test != BYTE_TEST_VALUE {
            return Err(Error::NotFound(test));
        }
        self.write(HW_CFG, HW_CFG_SRST);
        self.wait_clear(HW_CFG, HW_CFG_SRST)?;
        self.write(INT_EN, 0);
        self.write(INT_STS, u32::MAX);
        self.write(IRQ_CFG, IRQ_EN | IRQ_POL | IRQ_TYPE);
        // the receive status level interrupt at its lowest level: any frame
        self.write(FIFO_INT, 0x4800_0000);
        self.write(RX_CFG, RX_CFG_RX_DUMP);
        self.write(TX_CFG, TX_CFG_TXS_DUMP | TX_CFG_TX_ON);
        let h = self.mac_read(MAC_ADDRH)?.to_le_bytes();
        let l = self.mac_read(MAC_ADDRL)?.to_le_bytes();
        self.mac_write(MAC_CR, MAC_CR_FDPX | MAC_CR_MCPAS | MAC_CR_TXEN | MAC_CR_RXEN)?;
        Ok(([l[0], l[1], l[2], l[3], h[0], h[1]], self.read(ID_REV)))
    }

    /// The interrupt for received frames on.
    pub fn listen(&self) {
        self.write(INT_EN, INT_RSFL | INT_RXE);
    }

    /// The interrupt status, acknowledged.
    pub fn take_interrupt(&self) -> u32 {
        let s = self.read(INT_STS);
        self.write(INT_STS, s);
        s
    }

    /// Frames waiting in the receive FIFO.
    pub fn pending(&self) -> u32 {
        (self.read(RX_FIFO_INF) >> 16) & 0xFF
    }

    /// The next received frame into `buf` (without its FCS): its length,
    /// or `None` when none is waiting. A frame that does not fit `buf`, or
    /// that the MAC flags as bad (error status), is read out and dropped:
    /// `Some(0)`.
    pub fn receive(&self, buf: &mut [u8]) -> Option<usize> {
        if self.pending() == 0 {
            return None;
        }
        let status = self.read(RX_STATUS_FIFO);
        // bytes in the data FIFO: the frame and its FCS
        let fifo = ((status >> 16) & 0x3FFF) as usize;
        let words = fifo.div_ceil(4).min(MAX_WORDS);
        let len = fifo.saturating_sub(4);
        // ES (error summary, bit 15)
        let keep = status & (1 << 15) == 0 && (MIN_FRAME..=MAX_FRAME.min(buf.len())).contains(&len);
        for w in 0..words {
            let v = self.read(RX_DATA_FIFO).to_le_bytes();
            if keep {
                for (i, b) in v.iter().enumerate() {
                    let at = 4 * w + i;
                    if at < len {
                        if let Some(d) = buf.get_mut(at) {
                            *d = *b;
                        }
                    }
                }
            }
        }
        Some(if keep { len } else { 0 })
    }

    /// Sends `frame` (destination MAC first, no FCS).
    pub fn send(&self, frame: &[u8]) -> Result<(), Error> {
        let len = frame.len();
        if !(MIN_FRAME..=MAX_FRAME).contains(&len) {
            return Err(Error::Length);
        }
        // free bytes of the data FIFO (TDFREE) for the two command words and the data
        if ((self.read(TX_FIFO_INF) & 0xFFFF) as usize) < len + 8 {
            return Err(Error::Busy);
        }
        let n = len as u32;
        self.write(TX_DATA_FIFO, TX_A_FIRST | TX_A_LAST | n);
        self.write(TX_DATA_FIFO, n << 16 | n);
        for chunk in frame.chunks(4) {
            let mut w = [0u8; 4];
            if let Some(d) = w.get_mut(..chunk.len()) {
                d.copy_from_slice(chunk);
            }
            self.write(TX_DATA_FIFO, u32::from_le_bytes(w));
        }
        // the frame's status: not kept (the FIFO holds 512 of them)
        if (self.read(TX_FIFO_INF) >> 16) & 0xFF != 0 {
            let _ = self.read(TX_STATUS_FIFO);
        }
        Ok(())
    }
}
