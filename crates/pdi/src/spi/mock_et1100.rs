//! A byte-level model of an ET1100-class SPI PDI, for the driver tests.
//!
//! Decodes each chip-select frame like the ESC: address/command phase in 2- or
//! 3-byte form, clocking out the AL event request (0x0220, 0x0221, 0x0222)
//! meanwhile; then NOP, read (with or without the wait state byte) or write.
//! A read must send 0x00 on MOSI for every data byte but the last and 0xFF
//! (read termination) on the last; anything else panics, failing the test.

extern crate std;
use std::vec::Vec;

use embedded_hal::spi::{ErrorType, Operation, SpiDevice};

use super::et1100::{
    CMD_ADDRESS_EXTENSION, CMD_NOP, CMD_READ, CMD_READ_WAIT_STATE, CMD_WRITE, READ_TERMINATION, WAIT_STATE,
};
use super::mock_lan9252::BusFault;

pub(crate) struct MockEt1100 {
    /// The ESC's address space.
    pub esc: Vec<u8>,
    /// The transaction (1-based count) that fails with [`BusFault`].
    pub fail_at: Option<usize>,
    /// Transactions so far.
    pub transactions: usize,
    /// Decoded commands: (command, address, data bytes).
    pub log: Vec<(u8, u16, usize)>,
    /// Raw address/command bytes of every frame.
    pub headers: Vec<Vec<u8>>,
}

enum Phase {
    Header(Vec<u8>),
    WaitState(u16),
    Read { addr: u16, n: usize, terminated: bool },
    Write { addr: u16, n: usize },
    Nop,
}

impl MockEt1100 {
    pub fn new() -> Self {
        let esc = (0..0x1_0000usize)
            .map(|i| (i as u8).wrapping_mul(7) ^ (i >> 8) as u8)
            .collect();
        Self {
            esc,
            fail_at: None,
            transactions: 0,
            log: Vec::new(),
            headers: Vec::new(),
        }
    }

    fn start(&mut self, cmd: u8, addr: u16) -> Phase {
        match cmd {
            CMD_NOP => Phase::Nop,
            CMD_READ => Phase::Read {
                addr,
                n: 0,
                terminated: false,
            },
            CMD_READ_WAIT_STATE => Phase::WaitState(addr),
            CMD_WRITE => Phase::Write { addr, n: 0 },
            _ => panic!("reserved SPI command {cmd:#05b}"),
        }
    }

    fn exchange(&mut self, phase: &mut Phase, mosi: u8) -> u8 {
        match phase {
            Phase::Header(bytes) => {
                let i = bytes.len();
                bytes.push(mosi);
                let miso = self.esc[0x220 + i];
                let (b0, b1) = (u16::from(bytes[0]), bytes.get(1).copied().map(u16::from));
                let next = match (i, b1) {
                    (1, Some(b1)) if (b1 & 7) as u8 != CMD_ADDRESS_EXTENSION => {
                        // 2-byte addressing: A[12:5], A[4:0] | cmd.
                        Some(((b1 & 7) as u8, (b0 << 5) | (b1 >> 3)))
                    }
                    (2, Some(b1)) => {
                        assert_eq!(mosi & 0b11, 0, "reserved bits of the third header byte");
                        let a = (u16::from(mosi >> 5) << 13) | (b0 << 5) | (b1 >> 3);
                        Some(((mosi >> 2) & 7, a))
                    }
                    _ => None,
                };
                if let Some((cmd, addr)) = next {
                    self.headers.push(bytes.clone());
                    self.log.push((cmd, addr, 0));
                    *phase = self.start(cmd, addr);
                }
                miso
            }
            Phase::WaitState(addr) => {
                assert_eq!(mosi, WAIT_STATE, "wait state byte must be 0xFF");
                *phase = Phase::Read {
                    addr: *addr,
                    n: 0,
                    terminated: false,
                };
                0
            }
            Phase::Read { addr, n, terminated } => {
                assert!(!*terminated, "byte clocked after the read termination byte");
                assert!(
                    mosi == 0x00 || mosi == READ_TERMINATION,
                    "MOSI {mosi:#04x} during read"
                );
                let miso = self.esc[usize::from(*addr)];
                *addr = addr.wrapping_add(1);
                *n += 1;
                *terminated = mosi == READ_TERMINATION;
                miso
            }
            Phase::Write { addr, n } => {
                self.esc[usize::from(*addr)] = mosi;
                *addr = addr.wrapping_add(1);
                *n += 1;
                0
            }
            Phase::Nop => panic!("data after a NOP header"),
        }
    }

    fn end_frame(&mut self, phase: &Phase) {
        let n = match *phase {
            Phase::Header(_) => panic!("frame ended inside the address/command phase"),
            Phase::WaitState(_) => panic!("frame ended before the wait state byte"),
            Phase::Read { n, terminated, .. } => {
                assert!(terminated, "read not terminated with 0xFF on the last byte");
                n
            }
            Phase::Write { n, .. } => n,
            Phase::Nop => 0,
        };
        if let Some(last) = self.log.last_mut() {
            last.2 = n;
        }
    }
}

impl ErrorType for MockEt1100 {
    type Error = BusFault;
}

impl SpiDevice for MockEt1100 {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), BusFault> {
        self.transactions += 1;
        if self.fail_at == Some(self.transactions) {
            return Err(BusFault);
        }
        let mut phase = Phase::Header(Vec::new());
        super::clock_operations(operations, &mut phase, |p, b| self.exchange(p, b));
        self.end_frame(&phase);
        Ok(())
    }
}
