//! A byte-level model of a LAN9252 behind SPI, for the driver tests.
//!
//! The model decodes each chip-select frame like the chip: command byte
//! (0x03 / 0x0B + one dummy byte / 0x02), 16-bit big-endian address, then data.
//! It keeps the chip's registers (CSR window, process RAM engines, FIFOs with
//! their DWORD counts, BYTE_TEST, HW_CFG) and the ESC's 64 KiB memory. Busy
//! bits stay set for a configurable number of polls, FIFOs fill and drain a
//! configurable number of DWORDs per status poll. Protocol violations the
//! chip would not survive (a CSR size/alignment outside the datasheet's table,
//! popping an empty FIFO, overfilling the write FIFO, starting a command while
//! one is running, partial DWORD accesses) panic, failing the test.

extern crate std;
use std::collections::VecDeque;
use std::vec::Vec;

use embedded_hal::spi::{ErrorKind, ErrorType, Operation, SpiDevice};

use super::lan9252::regs;

/// The injected bus error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct BusFault;

impl embedded_hal::spi::Error for BusFault {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Other
    }
}

/// Depth of each process RAM FIFO in DWORDs.
const FIFO_DEPTH: usize = 16;

#[derive(Default)]
struct ReadEngine {
    addr_len: u32,
    active: bool,
    /// DWORDs the engine has yet to fetch from the ESC into the FIFO.
    pending: VecDeque<u32>,
    fifo: VecDeque<u32>,
    delay_left: u32,
}

#[derive(Default)]
struct WriteEngine {
    addr_len: u32,
    active: bool,
    expected: usize,
    accepted: usize,
    drained: usize,
    fifo: VecDeque<u32>,
    delay_left: u32,
}

pub(crate) struct MockLan9252 {
    /// The ESC's address space.
    pub esc: Vec<u8>,
    /// Status reads a CSR command stays busy.
    pub csr_busy_polls: u32,
    /// The CSR command never completes.
    pub csr_stuck: bool,
    /// Status polls before a started process RAM transfer moves data.
    pub fifo_delay_polls: u32,
    /// DWORDs the engines move between FIFO and ESC per status poll.
    pub fifo_per_poll: usize,
    /// The process RAM engines never move data.
    pub pram_stuck: bool,
    /// `HW_CFG` reads before `READY` is set.
    pub ready_after: u32,
    /// The transaction (1-based count) that fails with [`BusFault`].
    pub fail_at: Option<usize>,
    /// Transactions so far.
    pub transactions: usize,
    /// CSR commands: (ESC address, size, is_read).
    pub csr_log: Vec<(u16, u8, bool)>,
    /// FIFO bursts: (is_read, DWORDs).
    pub bursts: Vec<(bool, usize)>,
    /// Reads of `ECAT_CSR_CMD`.
    pub csr_cmd_reads: usize,
    /// Fast reads seen (and serial reads).
    pub fast_reads: usize,
    pub serial_reads: usize,
    csr_data: u32,
    csr_cmd: u32,
    csr_wdata: u32,
    csr_pending: bool,
    csr_left: u32,
    rd: ReadEngine,
    wr: WriteEngine,
}

/// Decoder state within one chip-select frame.
enum Phase {
    Command,
    AddrHi(u8),
    AddrLo(u8, u8),
    Dummy(u16),
    Read { addr: u16, n: usize, latched: [u8; 4] },
    Write { addr: u16, n: usize, bytes: [u8; 4] },
}

impl MockLan9252 {
    pub fn new() -> Self {
        let esc = (0..0x1_0000usize)
            .map(|i| (i as u8).wrapping_mul(13) ^ (i >> 8) as u8)
            .collect();
        Self {
            esc,
            csr_busy_polls: 2,
            csr_stuck: false,
            fifo_delay_polls: 1,
            fifo_per_poll: 3,
            pram_stuck: false,
            ready_after: 0,
            fail_at: None,
            transactions: 0,
            csr_log: Vec::new(),
            bursts: Vec::new(),
            csr_cmd_reads: 0,
            fast_reads: 0,
            serial_reads: 0,
            csr_data: 0,
            csr_cmd: 0,
            csr_wdata: 0,
            csr_pending: false,
            csr_left: 0,
            rd: ReadEngine::default(),
            wr: WriteEngine::default(),
        }
    }

    // ---- registers -------------------------------------------------------

    fn read_reg(&mut self, addr: u16) -> u32 {
        match addr {
            regs::BYTE_TEST => regs::BYTE_TEST_VALUE,
            regs::ID_REV => 0x9252_0001,
            regs::HW_CFG => {
                if self.ready_after > 0 {
                    self.ready_after -= 1;
                    0
                } else {
                    regs::HW_CFG_READY
                }
            }
            regs::ECAT_CSR_DATA => self.csr_data,
            regs::ECAT_CSR_CMD => {
                self.csr_cmd_reads += 1;
                if self.csr_pending && !self.csr_stuck {
                    if self.csr_left == 0 {
                        self.csr_execute();
                        self.csr_pending = false;
                    } else {
                        self.csr_left -= 1;
                    }
                }
                (self.csr_cmd & !regs::CSR_BUSY) | if self.csr_pending { regs::CSR_BUSY } else { 0 }
            }
            regs::ECAT_PRAM_RD_ADDR_LEN => self.rd.addr_len,
            regs::ECAT_PRAM_RD_CMD => self.rd_status(),
            regs::ECAT_PRAM_WR_ADDR_LEN => self.wr.addr_len,
            regs::ECAT_PRAM_WR_CMD => self.wr_status(),
            _ => 0,
        }
    }

    fn write_reg(&mut self, addr: u16, v: u32) {
        match addr {
            regs::ECAT_CSR_DATA => self.csr_data = v,
            regs::ECAT_CSR_CMD => {
                assert!(v & regs::CSR_BUSY != 0, "CSR command without CSR_BUSY: {v:#010x}");
                assert!(
                    !self.csr_pending,
                    "CSR command {v:#010x} while the previous one is busy"
                );
                let esc_addr = (v & 0xFFFF) as u16;
                let size = ((v >> regs::CSR_SIZE_SHIFT) & 0x7) as u8;
                assert!(matches!(size, 1 | 2 | 4), "CSR size {size}");
                assert_eq!(
                    esc_addr % u16::from(size),
                    0,
                    "CSR size {size} at {esc_addr:#06x}"
                );
                assert!(esc_addr + u16::from(size) <= 0x1000, "CSR access to process RAM");
                self.csr_log.push((esc_addr, size, v & regs::CSR_READ != 0));
                self.csr_cmd = v;
                self.csr_wdata = self.csr_data;
                self.csr_pending = true;
                self.csr_left = self.csr_busy_polls;
            }
            regs::ECAT_PRAM_RD_ADDR_LEN => self.rd.addr_len = v,
            regs::ECAT_PRAM_RD_CMD => {
                if v & regs::PRAM_ABORT != 0 {
                    self.rd = ReadEngine {
                        addr_len: self.rd.addr_len,
                        ..ReadEngine::default()
                    };
                } else if v & regs::PRAM_BUSY != 0 {
                    assert!(!self.rd.active, "read engine started while busy");
                    self.rd_start();
                }
            }
            regs::ECAT_PRAM_WR_ADDR_LEN => self.wr.addr_len = v,
            regs::ECAT_PRAM_WR_CMD => {
                if v & regs::PRAM_ABORT != 0 {
                    self.wr = WriteEngine {
                        addr_len: self.wr.addr_len,
                        ..WriteEngine::default()
                    };
                } else if v & regs::PRAM_BUSY != 0 {
                    assert!(!self.wr.active, "write engine started while busy");
                    self.wr_start();
                }
            }
            _ => {}
        }
    }

    fn csr_execute(&mut self) {
        let a = (self.csr_cmd & 0xFFFF) as usize;
        let size = ((self.csr_cmd >> regs::CSR_SIZE_SHIFT) & 0x7) as usize;
        if self.csr_cmd & regs::CSR_READ != 0 {
            let mut b = [0u8; 4];
            b[..size].copy_from_slice(&self.esc[a..a + size]);
            self.csr_data = u32::from_le_bytes(b);
        } else {
            self.esc[a..a + size].copy_from_slice(&self.csr_wdata.to_le_bytes()[..size]);
        }
    }

    /// (start address, length, first aligned address, DWORDs).
    fn pram_window(addr_len: u32) -> (usize, usize, usize, usize) {
        let addr = (addr_len & 0xFFFF) as usize;
        let len = (addr_len >> 16) as usize;
        assert!(addr >= 0x1000, "process RAM transfer below 0x1000: {addr:#06x}");
        assert!(
            len > 0 && addr + len <= 0x1_0000,
            "process RAM length {len} at {addr:#06x}"
        );
        let aligned = addr & !3;
        (addr, len, aligned, (addr + len - aligned).div_ceil(4))
    }

    fn rd_start(&mut self) {
        let (addr, len, aligned, dwords) = Self::pram_window(self.rd.addr_len);
        self.rd.pending = (0..dwords)
            .map(|i| {
                let mut b = [0xEEu8; 4]; // padding the driver must skip
                for (k, byte) in b.iter_mut().enumerate() {
                    let a = aligned + 4 * i + k;
                    if (addr..addr + len).contains(&a) {
                        *byte = self.esc[a];
                    }
                }
                u32::from_le_bytes(b)
            })
            .collect();
        self.rd.fifo.clear();
        self.rd.active = true;
        self.rd.delay_left = self.fifo_delay_polls;
    }

    fn rd_status(&mut self) -> u32 {
        if self.rd.active && !self.pram_stuck {
            if self.rd.delay_left > 0 {
                self.rd.delay_left -= 1;
            } else {
                for _ in 0..self.fifo_per_poll {
                    if self.rd.fifo.len() == FIFO_DEPTH {
                        break;
                    }
                    match self.rd.pending.pop_front() {
                        Some(d) => self.rd.fifo.push_back(d),
                        None => break,
                    }
                }
            }
        }
        let mut v = (self.rd.fifo.len() as u32) << regs::PRAM_CNT_SHIFT;
        if !self.rd.fifo.is_empty() {
            v |= regs::PRAM_AVAIL;
        }
        if self.rd.active {
            v |= regs::PRAM_BUSY;
        }
        v
    }

    fn rd_pop(&mut self) -> u32 {
        let d = self
            .rd
            .fifo
            .pop_front()
            .expect("driver read an empty process RAM read FIFO");
        if self.rd.pending.is_empty() && self.rd.fifo.is_empty() {
            self.rd.active = false;
        }
        d
    }

    fn wr_start(&mut self) {
        let (_, _, _, dwords) = Self::pram_window(self.wr.addr_len);
        self.wr.expected = dwords;
        self.wr.accepted = 0;
        self.wr.drained = 0;
        self.wr.fifo.clear();
        self.wr.active = true;
        self.wr.delay_left = self.fifo_delay_polls;
    }

    fn wr_push(&mut self, d: u32) {
        assert!(self.wr.active, "write FIFO written with no transfer running");
        assert!(self.wr.fifo.len() < FIFO_DEPTH, "write FIFO overfilled");
        assert!(
            self.wr.accepted < self.wr.expected,
            "more DWORDs than the transfer length"
        );
        self.wr.fifo.push_back(d);
        self.wr.accepted += 1;
    }

    fn wr_status(&mut self) -> u32 {
        if self.wr.active && !self.pram_stuck {
            if self.wr.delay_left > 0 {
                self.wr.delay_left -= 1;
            } else {
                let (addr, len, aligned, _) = Self::pram_window(self.wr.addr_len);
                for _ in 0..self.fifo_per_poll {
                    let Some(d) = self.wr.fifo.pop_front() else { break };
                    for (k, byte) in d.to_le_bytes().into_iter().enumerate() {
                        let a = aligned + 4 * self.wr.drained + k;
                        if (addr..addr + len).contains(&a) {
                            self.esc[a] = byte;
                        }
                    }
                    self.wr.drained += 1;
                }
                if self.wr.drained == self.wr.expected {
                    self.wr.active = false;
                }
            }
        }
        let space = FIFO_DEPTH - self.wr.fifo.len();
        let mut v = (space as u32) << regs::PRAM_CNT_SHIFT;
        if self.wr.active && space > 0 && self.wr.accepted < self.wr.expected {
            v |= regs::PRAM_AVAIL;
        }
        if self.wr.active {
            v |= regs::PRAM_BUSY;
        }
        v
    }

    // ---- SPI framing -----------------------------------------------------

    fn exchange(&mut self, phase: &mut Phase, mosi: u8) -> u8 {
        match *phase {
            Phase::Command => {
                assert!(
                    matches!(mosi, regs::CMD_READ | regs::CMD_FAST_READ | regs::CMD_WRITE),
                    "unknown SPI command {mosi:#04x}"
                );
                *phase = Phase::AddrHi(mosi);
                0
            }
            Phase::AddrHi(cmd) => {
                assert_eq!(mosi & 0xC0, 0, "address bits 15:14 set");
                *phase = Phase::AddrLo(cmd, mosi);
                0
            }
            Phase::AddrLo(cmd, hi) => {
                let addr = u16::from_be_bytes([hi, mosi]);
                *phase = match cmd {
                    regs::CMD_FAST_READ => Phase::Dummy(addr),
                    regs::CMD_READ => {
                        self.serial_reads += 1;
                        Phase::Read {
                            addr,
                            n: 0,
                            latched: [0; 4],
                        }
                    }
                    _ => Phase::Write {
                        addr,
                        n: 0,
                        bytes: [0; 4],
                    },
                };
                0
            }
            Phase::Dummy(addr) => {
                self.fast_reads += 1;
                *phase = Phase::Read {
                    addr,
                    n: 0,
                    latched: [0; 4],
                };
                0
            }
            Phase::Read { addr, n, mut latched } => {
                if n % 4 == 0 {
                    latched = if addr < regs::PRAM_WR_FIFO {
                        self.rd_pop().to_le_bytes()
                    } else {
                        assert_eq!(n, 0, "register read of more than one DWORD at {addr:#06x}");
                        assert_eq!(addr % 4, 0, "unaligned register read at {addr:#06x}");
                        self.read_reg(addr).to_le_bytes()
                    };
                }
                *phase = Phase::Read {
                    addr,
                    n: n + 1,
                    latched,
                };
                latched[n % 4]
            }
            Phase::Write { addr, n, mut bytes } => {
                bytes[n % 4] = mosi;
                if n % 4 == 3 {
                    let v = u32::from_le_bytes(bytes);
                    if (regs::PRAM_WR_FIFO..regs::PRAM_WR_FIFO + 0x20).contains(&addr) {
                        self.wr_push(v);
                    } else {
                        assert_eq!(n, 3, "register write of more than one DWORD at {addr:#06x}");
                        assert_eq!(addr % 4, 0, "unaligned register write at {addr:#06x}");
                        self.write_reg(addr, v);
                    }
                }
                *phase = Phase::Write {
                    addr,
                    n: n + 1,
                    bytes,
                };
                0
            }
        }
    }

    fn end_frame(&mut self, phase: &Phase) {
        match *phase {
            Phase::Read { addr, n, .. } => {
                assert!(
                    n > 0 && n % 4 == 0,
                    "partial DWORD read ({n} bytes) at {addr:#06x}"
                );
                if addr < regs::PRAM_WR_FIFO {
                    assert!(n <= regs::FIFO_ALIAS_LEN, "FIFO burst beyond the alias");
                    self.bursts.push((true, n / 4));
                }
            }
            Phase::Write { addr, n, .. } => {
                assert!(
                    n > 0 && n % 4 == 0,
                    "partial DWORD write ({n} bytes) at {addr:#06x}"
                );
                if addr == regs::PRAM_WR_FIFO {
                    assert!(n <= regs::FIFO_ALIAS_LEN, "FIFO burst beyond the alias");
                    self.bursts.push((false, n / 4));
                }
            }
            _ => panic!("frame ended in the command/address phase"),
        }
    }
}

impl ErrorType for MockLan9252 {
    type Error = BusFault;
}

impl SpiDevice for MockLan9252 {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), BusFault> {
        self.transactions += 1;
        if self.fail_at == Some(self.transactions) {
            return Err(BusFault);
        }
        let mut phase = Phase::Command;
        super::clock_operations(operations, &mut phase, |p, b| self.exchange(p, b));
        self.end_frame(&phase);
        Ok(())
    }
}
