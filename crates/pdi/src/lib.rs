//! PDI drivers: the hardware implementations of [`esc::Pdi`].
//!
//! The slave stack reaches the EtherCAT slave controller (ESC) only through
//! [`esc::Pdi`]: byte reads and writes in the ESC's 64 KiB address space
//! (registers below 0x1000, process RAM from 0x1000) and the AL event request
//! register (0x0220). This crate provides the two ways real hardware offers
//! that access. Both are `#![no_std]`, heap-free and panic-free; every busy
//! wait is bounded and ends in an error.
//!
//! # [`spi::Lan9252`]: LAN9252-class SPI ESC
//!
//! The LAN9252 (Microchip, datasheet DS00001909) puts an ET1100-compatible ESC
//! core behind its own small register space. The SPI slave speaks to that
//! register space only, with flash-like commands: `0x03` serial read, `0x0B`
//! fast read (one dummy byte after the address) and `0x02` write, each followed
//! by a 16-bit big-endian address; data bytes follow in ascending address order
//! (registers are little-endian DWORDs). The ESC itself is reached indirectly:
//!
//! - **ESC registers** (below 0x1000) through the CSR window: write the data to
//!   `ECAT_CSR_DATA` (0x0300, for writes), then `ECAT_CSR_CMD` (0x0304) =
//!   `CSR_BUSY` (bit 31) | `R_NOT_W` (bit 30, reads) | size (bits 18:16: 1, 2
//!   or 4) | ESC address (bits 15:0); poll `ECAT_CSR_CMD` until `CSR_BUSY`
//!   clears; a read's data is then in `ECAT_CSR_DATA` (right-aligned). A
//!   4-byte access needs a 4-aligned address, a 2-byte one a 2-aligned address
//!   ("EtherCAT CSR address vs. size" table); the driver splits every access
//!   into the widest legal chunks (1, 2 or 4 bytes).
//! - **Process RAM** (0x1000 and up) through the process RAM FIFOs: write
//!   length (bits 31:16) and address (bits 15:0) to `ECAT_PRAM_RD_ADDR_LEN`
//!   (0x0308) or `ECAT_PRAM_WR_ADDR_LEN` (0x0310), start with `PRAM_*_BUSY`
//!   (bit 31) in `ECAT_PRAM_RD_CMD` (0x030C) or `ECAT_PRAM_WR_CMD` (0x0314),
//!   then move DWORDs through the data FIFOs (read FIFO at 0x0000, write FIFO
//!   at 0x0020, each aliased over 32 bytes) while the command register reports
//!   data available / space available (bit 0) and how many DWORDs (bits 12:8).
//!   The first DWORD is the one containing the start address (the bytes below
//!   it are padding). `PRAM_*_ABORT` (bit 30) resets an engine; the driver uses
//!   it before the next transfer whenever a transfer did not finish (SPI error,
//!   timeout). Bursts never exceed the reported count nor the 32-byte alias, so
//!   they are correct whether or not the chip increments the address in a burst.
//!
//! The AL event request register is read as one 4-byte CSR access.
//!
//! # [`spi::Et1100`]: ET1100-class SPI ESC
//!
//! Beckhoff's ET1100 (and ESCs with the same SPI PDI: ET1200, FPGA IP cores)
//! decode the ESC address directly. Each access starts with an address/command
//! phase; the driver always uses 3-byte addressing, which reaches all 64 KiB:
//! byte 0 = A\[12:5\], byte 1 = A\[4:0\] << 3 | `0b110` (address extension),
//! byte 2 = A\[15:13\] << 5 | command << 2, with the commands `0b000` NOP,
//! `0b011` read with wait state byte and `0b100` write. While the master
//! clocks out these three bytes the ESC clocks out the AL event request
//! register (0x0220, 0x0221, 0x0222), so every access refreshes
//! [`spi::Et1100::last_al_event`] and [`esc::Pdi::al_event`] costs one 3-byte
//! NOP. A read sends one wait state byte (0xFF), then 0x00 for every data byte
//! but the last, which is 0xFF (read termination).
//!
//! # [`mmio::OnChip`]: memory-mapped on-chip ESC
//!
//! MCUs with an on-chip ESC (the reference board's Infineon XMC4800: ECAT0 at
//! 0x5401_0000, registers and 8 KiB process RAM in one 12 KiB window) map the
//! ESC address space 1:1 into the bus. [`mmio::OnChip`] implements
//! [`esc::Pdi`] over a tiny [`mmio::RegisterWindow`] trait (8/16/32-bit access
//! at an offset) and splits every access into naturally aligned accesses of
//! the widest width that fits, so multi-byte registers are read and written
//! consistently (the AL event request is one 32-bit read). The only `unsafe`
//! code of the crate is [`mmio::VolatileWindow`], the volatile-pointer
//! implementation of the window with bounds and alignment checks; the host
//! tests run the `OnChip` logic over a RAM-backed window.
#![no_std]
#![deny(missing_docs)]

pub mod mmio;
pub mod spi;

/// Size of the ESC address space in bytes (addresses are 16 bits).
pub const ESC_SPACE: usize = 0x1_0000;

/// `true` if `len` bytes from `addr` stay inside the 64 KiB ESC address space.
pub(crate) fn in_esc_space(addr: u16, len: usize) -> bool {
    (addr as usize)
        .checked_add(len)
        .is_some_and(|end| end <= ESC_SPACE)
}
