//! Ethernet MAC driver for Synopsys DWC GMAC-style MACs, as on the Infineon
//! XMC4800's ETH0 (10/100 Mbit/s, RMII or MII): DMA descriptor rings in
//! static RAM, MDIO, and a clause-22 PHY bring-up ([`phy`]).
//!
//! `#![no_std]`, heap-free and panic-free: every busy wait is bounded by a
//! poll count and ends in an [`Error`]; a received frame is handed out as a
//! slice of its DMA buffer while the CPU owns the descriptor.
//!
//! The registers are reached through [`Regs`] (32-bit accesses at offsets
//! from the MAC's base): [`Mmio`] on the chip, a model on the host (the
//! tests). Descriptors use the MAC's "enhanced" 4-word layout (ATDS = 0)
//! in ring mode (end-of-ring bit on the last one), one buffer of [`BUF`]
//! bytes per descriptor, so every frame fits one descriptor.
//!
//! Written from the XMC4800 reference manual's ETH chapter (DWC GMAC
//! descriptor and register layout) without the hardware: see
//! docs/hardware.md of the repository for what is not verified.
#![no_std]
#![deny(missing_docs)]

use core::cell::UnsafeCell;
use core::mem::MaybeUninit;
use core::sync::atomic::{fence, Ordering};

pub mod phy;
pub mod regs;

#[cfg(test)]
extern crate std;
#[cfg(test)]
mod tests;

use regs::*;

/// Bytes per DMA buffer: one whole frame (1518 bytes, 1522 with a VLAN tag)
/// plus room, a multiple of 4 as the DMA requires.
pub const BUF: usize = 1536;

/// 32-bit register access at offsets from the MAC's base.
pub trait Regs {
    /// Reads the register at `offset`.
    fn read(&mut self, offset: u32) -> u32;
    /// Writes `value` to the register at `offset`.
    fn write(&mut self, offset: u32, value: u32);
    /// Read-modify-write: clears `clear`, then sets `set`.
    fn modify(&mut self, offset: u32, clear: u32, set: u32) {
        let v = self.read(offset);
        self.write(offset, (v & !clear) | set);
    }
}

/// The MAC's registers in the address space.
#[derive(Debug)]
pub struct Mmio {
    base: usize,
}

impl Mmio {
    /// The MAC whose registers start at `base`.
    ///
    /// # Safety
    /// `base` must be the MAC's register block (e.g.
    /// [`regs::XMC4800_ETH0`]) with its clock on and out of reset, and this
    /// value its only user.
    #[allow(unsafe_code)]
    pub const unsafe fn new(base: usize) -> Mmio {
        Mmio { base }
    }
}

#[allow(unsafe_code)]
impl Regs for Mmio {
    fn read(&mut self, offset: u32) -> u32 {
        // SAFETY: an aligned register of the block `new` was given.
        unsafe { core::ptr::read_volatile((self.base + offset as usize) as *const u32) }
    }
    fn write(&mut self, offset: u32, value: u32) {
        // SAFETY: as in `read`.
        unsafe { core::ptr::write_volatile((self.base + offset as usize) as *mut u32, value) }
    }
}

/// A 32-bit word the DMA reads and writes behind the CPU's back.
#[repr(transparent)]
struct Shared(UnsafeCell<u32>);

#[allow(unsafe_code)]
impl Shared {
    fn get(&self) -> u32 {
        // SAFETY: a valid, aligned u32 of the ring; volatile because the DMA changes it.
        unsafe { core::ptr::read_volatile(self.0.get()) }
    }
    fn set(&self, v: u32) {
        // SAFETY: as in `get`.
        unsafe { core::ptr::write_volatile(self.0.get(), v) }
    }
}

/// One DMA descriptor (4 words: status, control/size, buffer 1, buffer 2).
#[repr(C, align(16))]
struct Desc([Shared; 4]);

impl Desc {
    fn word(&self, i: usize) -> u32 {
        self.0.get(i).map_or(0, Shared::get)
    }
    fn set_word(&self, i: usize, v: u32) {
        if let Some(w) = self.0.get(i) {
            w.set(v);
        }
    }
}

/// One frame buffer, written by the DMA (receive) or read by it (transmit).
#[repr(C, align(16))]
struct Buffer(UnsafeCell<[u8; BUF]>);

#[allow(unsafe_code)]
impl Buffer {
    fn addr(&self) -> u32 {
        // the DMA's 32-bit bus address (on the host, the tests' model never
        // dereferences it)
        self.0.get() as usize as u32
    }
    /// The buffer's bytes while the CPU owns its descriptor.
    fn bytes(&self) -> &[u8; BUF] {
        // SAFETY: the caller owns the descriptor (OWN clear, read after an
        // acquire fence), so the DMA does not write the buffer now.
        unsafe { &*self.0.get() }
    }
    #[allow(clippy::mut_from_ref)]
    fn bytes_mut(&self) -> &mut [u8; BUF] {
        // SAFETY: as in `bytes`; the ring is borrowed mutably by its one user.
        unsafe { &mut *self.0.get() }
    }
}

/// The receive ring: `N` descriptors and their buffers.
#[repr(C)]
pub struct RxRing<const N: usize> {
    desc: [Desc; N],
    buf: [Buffer; N],
    next: usize,
}

/// The transmit ring: `N` descriptors and their buffers.
#[repr(C)]
pub struct TxRing<const N: usize> {
    desc: [Desc; N],
    buf: [Buffer; N],
    next: usize,
}

/// Both rings, for a static in RAM the MAC's DMA reaches.
#[repr(C)]
pub struct Rings<const RX: usize, const TX: usize> {
    rx: RxRing<RX>,
    tx: TxRing<TX>,
}

// SAFETY: the rings are only reached through the `&mut` the driver holds;
// the DMA is the other party, synchronised by the OWN bits and fences.
#[allow(unsafe_code)]
unsafe impl<const RX: usize, const TX: usize> Sync for Rings<RX, TX> {}

impl<const RX: usize, const TX: usize> Rings<RX, TX> {
    /// Zeroes `slot` in place (no copy through the stack) and returns the
    /// rings in it. A slot in a NOLOAD section (not zeroed at start) is fine.
    #[allow(unsafe_code)]
    pub fn init(slot: &mut MaybeUninit<Self>) -> &mut Self {
        // SAFETY: every field is u32/u8 storage or a usize, for which all
        // zeroes is a valid value.
        unsafe {
            core::ptr::write_bytes(slot.as_mut_ptr(), 0, 1);
            slot.assume_init_mut()
        }
    }
}

/// What went wrong in a bounded wait.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Error {
    /// The DMA's software reset did not finish (no receive/reference clock
    /// from the PHY?).
    ResetTimeout,
    /// The transmit FIFO flush did not finish.
    FlushTimeout,
    /// An MDIO transfer did not finish.
    MdioTimeout,
    /// No PHY answers at that address (ID all ones or all zeroes).
    NoPhy,
    /// The PHY's own reset did not finish.
    PhyResetTimeout,
}

/// Why a frame was not sent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TxError {
    /// Every transmit descriptor is still the DMA's.
    Busy,
    /// Empty, or longer than [`BUF`].
    Length,
}

/// Link speed and duplex, as the PHY resolved them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Link {
    /// 100 Mbit/s (else 10).
    pub speed_100: bool,
    /// Full duplex.
    pub full_duplex: bool,
}

/// Frame counters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    /// Good frames received.
    pub rx_frames: u32,
    /// Frames the DMA flagged (error summary, or spread over descriptors).
    pub rx_errors: u32,
    /// Frames handed to the DMA.
    pub tx_frames: u32,
    /// Frames not sent: ring full.
    pub tx_busy: u32,
    /// Frames not sent: empty or too long.
    pub tx_length: u32,
    /// Sent frames the DMA flagged (seen when their descriptor is reused).
    pub tx_errors: u32,
    /// Fatal bus errors (the DMA stopped; [`Eth::new`] again).
    pub fatal: u32,
}

/// Polls of a bounded wait (a few ms at 144 MHz).
const POLLS: u32 = 200_000;

/// The MAC with its rings.
pub struct Eth<'r, R: Regs, const RX: usize, const TX: usize> {
    regs: R,
    rx: &'r mut RxRing<RX>,
    tx: &'r mut TxRing<TX>,
    stats: Stats,
}

/// The transmit side, lent out while a received frame is being handled.
pub struct Transmitter<'a, R: Regs, const TX: usize> {
    regs: &'a mut R,
    ring: &'a mut TxRing<TX>,
    stats: &'a mut Stats,
}

fn wait_clear<R: Regs>(regs: &mut R, offset: u32, bits: u32) -> bool {
    (0..POLLS).any(|_| regs.read(offset) & bits == 0)
}

impl<'r, R: Regs, const RX: usize, const TX: usize> Eth<'r, R, RX, TX> {
    /// Resets the DMA, programs `mac`, the frame filter, the rings and the
    /// interrupts (receive, abnormal); the MAC stays stopped until
    /// [`start`](Eth::start). The port pins, the RMII/MII selection and the
    /// PHY's clock must be set up first: the reset needs the PHY's clock.
    pub fn new(mut regs: R, rings: &'r mut Rings<RX, TX>, mac: [u8; 6]) -> Result<Self, Error> {
        regs.modify(BUS_MODE, 0, BUS_SWR);
        if !wait_clear(&mut regs, BUS_MODE, BUS_SWR) {
            return Err(Error::ResetTimeout);
        }
        regs.write(BUS_MODE, BUS_AAL | BUS_FB | (8 << BUS_PBL_SHIFT));
        // counters and PMT/timestamp events never raise the interrupt
        regs.write(MMC_RECEIVE_INTERRUPT_MASK, u32::MAX);
        regs.write(MMC_TRANSMIT_INTERRUPT_MASK, u32::MAX);
        regs.write(MMC_IPC_RECEIVE_INTERRUPT_MASK, u32::MAX);
        regs.write(INTERRUPT_MASK, (1 << 3) | (1 << 9));
        let [m0, m1, m2, m3, m4, m5] = mac;
        regs.write(MAC_ADDRESS0_HIGH, u32::from(m5) << 8 | u32::from(m4));
        regs.write(MAC_ADDRESS0_LOW, u32::from_le_bytes([m0, m1, m2, m3]));
        regs.write(MAC_FRAME_FILTER, FILTER_PM);
        regs.write(FLOW_CONTROL, 0);
        let Rings { rx, tx } = rings;
        for (i, (d, b)) in rx.desc.iter().zip(rx.buf.iter()).enumerate() {
            let end = if i + 1 == RX { RDES1_RER } else { 0 };
            d.set_word(1, end | (BUF as u32 & DES1_BS1_MASK));
            d.set_word(2, b.addr());
            d.set_word(3, 0);
            d.set_word(0, DES0_OWN);
        }
        for (i, (d, b)) in tx.desc.iter().zip(tx.buf.iter()).enumerate() {
            d.set_word(0, if i + 1 == TX { TDES0_TER } else { 0 });
            d.set_word(1, 0);
            d.set_word(2, b.addr());
            d.set_word(3, 0);
        }
        rx.next = 0;
        tx.next = 0;
        fence(Ordering::SeqCst);
        regs.write(RECEIVE_DESCRIPTOR_LIST_ADDRESS, desc_addr(&rx.desc));
        regs.write(TRANSMIT_DESCRIPTOR_LIST_ADDRESS, desc_addr(&tx.desc));
        regs.write(STATUS, DMA_W1C);
        regs.write(
            INTERRUPT_ENABLE,
            DMA_NIS | DMA_RI | DMA_AIS | DMA_RU | DMA_FBI | DMA_OVF,
        );
        regs.write(OPERATION_MODE, OP_RSF | OP_TSF | OP_OSF | OP_FTF);
        if !wait_clear(&mut regs, OPERATION_MODE, OP_FTF) {
            return Err(Error::FlushTimeout);
        }
        Ok(Eth {
            regs,
            rx,
            tx,
            stats: Stats::default(),
        })
    }

    /// Sets speed and duplex and starts transmitter, receiver and both DMA
    /// directions.
    pub fn start(&mut self, link: Link) {
        self.set_link(link);
        self.regs.modify(MAC_CONFIGURATION, 0, MAC_TE | MAC_RE);
        self.regs.modify(OPERATION_MODE, 0, OP_ST | OP_SR);
    }

    /// Follows a new link speed/duplex (the MAC keeps running).
    pub fn set_link(&mut self, link: Link) {
        let set = if link.speed_100 { MAC_FES } else { 0 } | if link.full_duplex { MAC_DM } else { 0 };
        self.regs.modify(MAC_CONFIGURATION, MAC_FES | MAC_DM, set);
    }

    /// The counters.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// Reads and clears the DMA interrupt status; returns what was set
    /// (the [`regs`] `DMA_*` bits). A fatal bus error is counted.
    pub fn take_interrupt(&mut self) -> u32 {
        let s = self.regs.read(STATUS);
        self.regs.write(STATUS, s & DMA_W1C);
        if s & DMA_FBI != 0 {
            self.stats.fatal = self.stats.fatal.saturating_add(1);
        }
        s & DMA_W1C
    }

    /// Hands every frame received so far (at most one ring's worth) to `f`
    /// with the transmit side, and gives each descriptor back to the DMA
    /// afterwards. Frames the DMA flagged are counted and skipped. Returns
    /// the number of good frames.
    pub fn receive(&mut self, mut f: impl FnMut(&[u8], &mut Transmitter<'_, R, TX>)) -> usize {
        let mut good = 0;
        let mut given_back = false;
        for _ in 0..RX {
            let i = self.rx.next;
            let (Some(d), Some(b)) = (self.rx.desc.get(i), self.rx.buf.get(i)) else {
                self.rx.next = 0;
                break;
            };
            let s = d.word(0);
            if s & DES0_OWN != 0 {
                break;
            }
            fence(Ordering::Acquire);
            let whole = s & (RDES0_FS | RDES0_LS) == RDES0_FS | RDES0_LS;
            // the length counts the CRC, which the frame is handed out without
            let len = ((s >> RDES0_FL_SHIFT) & RDES0_FL_MASK) as usize;
            let frame = b.bytes().get(..len.saturating_sub(4)).filter(|f| !f.is_empty());
            match frame {
                Some(frame) if whole && s & RDES0_ES == 0 => {
                    self.stats.rx_frames = self.stats.rx_frames.wrapping_add(1);
                    good += 1;
                    let mut tx = Transmitter {
                        regs: &mut self.regs,
                        ring: &mut *self.tx,
                        stats: &mut self.stats,
                    };
                    f(frame, &mut tx);
                }
                _ => self.stats.rx_errors = self.stats.rx_errors.wrapping_add(1),
            }
            fence(Ordering::Release);
            d.set_word(0, DES0_OWN);
            given_back = true;
            self.rx.next = if i + 1 >= RX { 0 } else { i + 1 };
        }
        if given_back {
            // restarts a receive DMA that stopped on "buffer unavailable"
            self.regs.write(RECEIVE_POLL_DEMAND, 0);
        }
        good
    }

    /// The transmit side.
    pub fn transmitter(&mut self) -> Transmitter<'_, R, TX> {
        Transmitter {
            regs: &mut self.regs,
            ring: &mut *self.tx,
            stats: &mut self.stats,
        }
    }

    /// Reads PHY register `reg` of the PHY at `phy` over MDIO.
    pub fn mdio_read(&mut self, phy: u8, reg: u8) -> Result<u16, Error> {
        self.mdio(phy, reg, 0)?;
        Ok((self.regs.read(GMII_DATA) & 0xFFFF) as u16)
    }

    /// Writes `value` to PHY register `reg` of the PHY at `phy` over MDIO.
    pub fn mdio_write(&mut self, phy: u8, reg: u8, value: u16) -> Result<(), Error> {
        self.regs.write(GMII_DATA, u32::from(value));
        self.mdio(phy, reg, MII_WRITE)
    }

    fn mdio(&mut self, phy: u8, reg: u8, write: u32) -> Result<(), Error> {
        if !wait_clear(&mut self.regs, GMII_ADDRESS, MII_BUSY) {
            return Err(Error::MdioTimeout);
        }
        self.regs.write(
            GMII_ADDRESS,
            u32::from(phy & 0x1F) << MII_PA_SHIFT
                | u32::from(reg & 0x1F) << MII_MR_SHIFT
                | MII_CR_100_150MHZ << MII_CR_SHIFT
                | write
                | MII_BUSY,
        );
        if wait_clear(&mut self.regs, GMII_ADDRESS, MII_BUSY) {
            Ok(())
        } else {
            Err(Error::MdioTimeout)
        }
    }

    /// The register access (tests, diagnostics).
    pub fn regs_mut(&mut self) -> &mut R {
        &mut self.regs
    }
}

impl<R: Regs, const TX: usize> Transmitter<'_, R, TX> {
    /// Copies `frame` (destination MAC first, no CRC: the MAC pads to 60
    /// bytes and appends the CRC) into the next free transmit buffer and
    /// hands it to the DMA.
    pub fn send(&mut self, frame: &[u8]) -> Result<(), TxError> {
        if frame.is_empty() || frame.len() > BUF {
            self.stats.tx_length = self.stats.tx_length.wrapping_add(1);
            return Err(TxError::Length);
        }
        let i = self.ring.next;
        let (Some(d), Some(b)) = (self.ring.desc.get(i), self.ring.buf.get(i)) else {
            self.ring.next = 0;
            return Err(TxError::Busy);
        };
        let s = d.word(0);
        if s & DES0_OWN != 0 {
            self.stats.tx_busy = self.stats.tx_busy.wrapping_add(1);
            return Err(TxError::Busy);
        }
        if s & TDES0_ES != 0 {
            self.stats.tx_errors = self.stats.tx_errors.wrapping_add(1);
        }
        fence(Ordering::Acquire);
        if let Some(dst) = b.bytes_mut().get_mut(..frame.len()) {
            dst.copy_from_slice(frame);
        }
        d.set_word(1, frame.len() as u32 & DES1_BS1_MASK);
        let end = if i + 1 >= TX { TDES0_TER } else { 0 };
        fence(Ordering::Release);
        d.set_word(0, DES0_OWN | TDES0_FS | TDES0_LS | end);
        self.regs.write(TRANSMIT_POLL_DEMAND, 0);
        self.stats.tx_frames = self.stats.tx_frames.wrapping_add(1);
        self.ring.next = if i + 1 >= TX { 0 } else { i + 1 };
        Ok(())
    }
}

fn desc_addr<const N: usize>(d: &[Desc; N]) -> u32 {
    d.as_ptr() as usize as u32
}

#[cfg(test)]
impl<const N: usize> RxRing<N> {
    /// Test model of the DMA: puts `frame` (+ a 4-byte CRC) into the
    /// descriptor at `i` and hands it to the CPU with `status` bits.
    pub(crate) fn dma_receive(&mut self, i: usize, frame: &[u8], status: u32) {
        let (d, b) = (&self.desc[i], &self.buf[i]);
        assert!(d.word(0) & DES0_OWN != 0, "the DMA owns it");
        b.bytes_mut()[..frame.len()].copy_from_slice(frame);
        let len = (frame.len() as u32 + 4) << RDES0_FL_SHIFT;
        d.set_word(0, len | status);
    }
    pub(crate) fn word(&self, i: usize, w: usize) -> u32 {
        self.desc[i].word(w)
    }
}

#[cfg(test)]
impl<const N: usize> TxRing<N> {
    /// Test model of the DMA: descriptor `i` sent (OWN cleared, `status` bits).
    pub(crate) fn dma_sent(&mut self, i: usize, status: u32) -> std::vec::Vec<u8> {
        let d = &self.desc[i];
        assert!(d.word(0) & DES0_OWN != 0);
        let n = (d.word(1) & DES1_BS1_MASK) as usize;
        d.set_word(0, (d.word(0) & !DES0_OWN) | status);
        self.buf[i].bytes()[..n].to_vec()
    }
    pub(crate) fn word(&self, i: usize, w: usize) -> u32 {
        self.desc[i].word(w)
    }
}

#[cfg(test)]
impl<R: Regs, const RX: usize, const TX: usize> Eth<'_, R, RX, TX> {
    pub(crate) fn rings_mut(&mut self) -> (&mut RxRing<RX>, &mut TxRing<TX>) {
        (&mut *self.rx, &mut *self.tx)
    }
}
