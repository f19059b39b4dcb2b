//! LAN9252-class SPI ESC: indirect CSR access and process RAM FIFOs.

use embedded_hal::spi::{Operation, SpiDevice};

use super::Error;

/// The LAN9252's own register space (reached with the SPI commands) and the
/// bits the driver uses. Addresses and bits as in the LAN9252 datasheet
/// (DS00001909, "System Control and Status Registers" and "EtherCAT Host
/// Interface" sections).
pub mod regs {
    /// Process RAM read data FIFO (aliased over 0x0000..0x001F).
    pub const PRAM_RD_FIFO: u16 = 0x0000;
    /// Process RAM write data FIFO (aliased over 0x0020..0x003F).
    pub const PRAM_WR_FIFO: u16 = 0x0020;
    /// Size of each FIFO's address alias, the longest burst the driver issues.
    pub const FIFO_ALIAS_LEN: usize = 32;
    /// Chip ID (bits 31:16, 0x9252) and revision.
    pub const ID_REV: u16 = 0x0050;
    /// Interrupt configuration (IRQ pin).
    pub const IRQ_CFG: u16 = 0x0054;
    /// Interrupt status.
    pub const INT_STS: u16 = 0x0058;
    /// Interrupt enable.
    pub const INT_EN: u16 = 0x005C;
    /// Byte order test register, reads [`BYTE_TEST_VALUE`].
    pub const BYTE_TEST: u16 = 0x0064;
    /// Hardware configuration; bit 27 is `READY`.
    pub const HW_CFG: u16 = 0x0074;
    /// Reset control; bit 6 resets the EtherCAT core.
    pub const RESET_CTL: u16 = 0x01F8;
    /// EtherCAT CSR interface data.
    pub const ECAT_CSR_DATA: u16 = 0x0300;
    /// EtherCAT CSR interface command.
    pub const ECAT_CSR_CMD: u16 = 0x0304;
    /// Process RAM read address (15:0) and length (31:16).
    pub const ECAT_PRAM_RD_ADDR_LEN: u16 = 0x0308;
    /// Process RAM read command / status.
    pub const ECAT_PRAM_RD_CMD: u16 = 0x030C;
    /// Process RAM write address (15:0) and length (31:16).
    pub const ECAT_PRAM_WR_ADDR_LEN: u16 = 0x0310;
    /// Process RAM write command / status.
    pub const ECAT_PRAM_WR_CMD: u16 = 0x0314;

    /// What `BYTE_TEST` reads once the SPI interface is up.
    pub const BYTE_TEST_VALUE: u32 = 0x8765_4321;
    /// `HW_CFG.READY`: the device is ready to be accessed.
    pub const HW_CFG_READY: u32 = 1 << 27;
    /// `RESET_CTL.ECAT_RST`.
    pub const RESET_CTL_ECAT_RST: u32 = 1 << 6;
    /// `IRQ_CFG.IRQ_EN`: master enable of the IRQ pin.
    pub const IRQ_CFG_IRQ_EN: u32 = 1 << 8;
    /// `IRQ_CFG.IRQ_POL`: 1 = active high.
    pub const IRQ_CFG_IRQ_POL: u32 = 1 << 4;
    /// `IRQ_CFG.IRQ_BUF_TYPE`: 1 = push-pull, 0 = open drain.
    pub const IRQ_CFG_IRQ_PUSH_PULL: u32 = 1 << 0;
    /// `INT_EN.ECAT_INT_EN` / `INT_STS.ECAT_INT`: the ESC's PDI interrupt (AL
    /// event request & AL event mask 0x0204) drives the IRQ pin.
    pub const INT_ECAT: u32 = 1 << 0;

    /// `ECAT_CSR_CMD.CSR_BUSY`: write 1 to start, reads 1 until done.
    pub const CSR_BUSY: u32 = 1 << 31;
    /// `ECAT_CSR_CMD.R_NOT_W`: 1 = read.
    pub const CSR_READ: u32 = 1 << 30;
    /// `ECAT_CSR_CMD.CSR_SIZE` position (bits 18:16, 1, 2 or 4 bytes).
    pub const CSR_SIZE_SHIFT: u32 = 16;

    /// `ECAT_PRAM_*_CMD.PRAM_*_BUSY`: write 1 to start, reads 1 until done.
    pub const PRAM_BUSY: u32 = 1 << 31;
    /// `ECAT_PRAM_*_CMD.PRAM_*_ABORT`: write 1 to abort the transfer.
    pub const PRAM_ABORT: u32 = 1 << 30;
    /// `PRAM_READ_AVAIL` / `PRAM_WRITE_SPACE_AVAIL`.
    pub const PRAM_AVAIL: u32 = 1 << 0;
    /// `PRAM_READ_AVAIL_CNT` / `PRAM_WRITE_SPACE_CNT` position (bits 12:8,
    /// in DWORDs).
    pub const PRAM_CNT_SHIFT: u32 = 8;
    /// Mask of the count after shifting.
    pub const PRAM_CNT_MASK: u32 = 0x1F;

    /// SPI command: serial read (no dummy byte; the slower clock limit).
    pub const CMD_READ: u8 = 0x03;
    /// SPI command: fast read (one dummy byte after the address in SPI mode).
    pub const CMD_FAST_READ: u8 = 0x0B;
    /// SPI command: write.
    pub const CMD_WRITE: u8 = 0x02;
}

/// First ESC address served by the process RAM FIFOs; below it the CSR window.
const PROCESS_RAM: u16 = esc::regs::PROCESS_RAM;

/// Which SPI read command the driver uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReadCommand {
    /// `0x03`: no dummy byte; only for the lower SPI clock limit of the chip.
    Serial,
    /// `0x0B`: one dummy byte after the address; for the full SPI clock.
    Fast,
}

/// Driver settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Config {
    /// Read command for the chip's registers and FIFO.
    pub read_command: ReadCommand,
    /// Upper bound of status polls per wait (CSR busy, FIFO data/space,
    /// write completion, ready); then the access fails with
    /// [`Error::Timeout`]. At least one poll is always made.
    pub max_polls: u32,
}

impl Default for Config {
    fn default() -> Self {
        Self {
            read_command: ReadCommand::Fast,
            max_polls: 1000,
        }
    }
}

/// A LAN9252-class SPI ESC (see the crate documentation for the protocol).
#[derive(Debug)]
pub struct Lan9252<D> {
    spi: D,
    config: Config,
    /// A CSR command may still be running (an earlier wait timed out).
    csr_pending: bool,
    /// The read engine may hold a half-finished transfer: abort first.
    rd_dirty: bool,
    /// The write engine may hold a half-finished transfer: abort first.
    wr_dirty: bool,
}

impl<D: SpiDevice> Lan9252<D> {
    /// A driver with the default [`Config`] (fast read, 1000 polls).
    pub fn new(spi: D) -> Self {
        Self::with_config(spi, Config::default())
    }

    /// A driver with explicit settings.
    pub fn with_config(spi: D, config: Config) -> Self {
        // The MCU may have restarted while the chip was in a transfer: the
        // first process RAM access of each direction aborts first.
        Self {
            spi,
            config,
            csr_pending: true,
            rd_dirty: true,
            wr_dirty: true,
        }
    }

    /// The settings.
    pub fn config(&self) -> Config {
        self.config
    }

    /// The SPI device (tests inspect and steer the chip model).
    #[cfg(test)]
    pub(crate) fn spi_mut(&mut self) -> &mut D {
        &mut self.spi
    }

    /// Gives the SPI device back.
    pub fn release(self) -> D {
        self.spi
    }

    /// Waits until the chip answers: `BYTE_TEST` reads 0x8765_4321 and
    /// `HW_CFG.READY` is set (after power-up or a reset), at most
    /// `max_polls` polls.
    pub fn wait_ready(&mut self) -> Result<(), Error<D::Error>> {
        let mut byte_test = 0;
        for _ in 0..self.config.max_polls.max(1) {
            byte_test = self.read_register(regs::BYTE_TEST)?;
            if byte_test == regs::BYTE_TEST_VALUE
                && self.read_register(regs::HW_CFG)? & regs::HW_CFG_READY != 0
            {
                return Ok(());
            }
        }
        Err(Error::NotReady { byte_test })
    }

    /// Reads one DWORD register of the chip's own register space (`addr`
    /// 4-aligned, e.g. [`regs::ID_REV`], [`regs::INT_STS`]).
    pub fn read_register(&mut self, addr: u16) -> Result<u32, Error<D::Error>> {
        let mut b = [0u8; 4];
        self.spi_read(addr, &mut b)?;
        Ok(u32::from_le_bytes(b))
    }

    /// Writes one DWORD register of the chip's own register space (e.g.
    /// [`regs::IRQ_CFG`], [`regs::INT_EN`]).
    pub fn write_register(&mut self, addr: u16, value: u32) -> Result<(), Error<D::Error>> {
        self.spi_write(addr, &value.to_le_bytes())
    }

    fn spi_read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Error<D::Error>> {
        let [hi, lo] = addr.to_be_bytes();
        let result = match self.config.read_command {
            ReadCommand::Serial => self
                .spi
                .transaction(&mut [Operation::Write(&[regs::CMD_READ, hi, lo]), Operation::Read(buf)]),
            ReadCommand::Fast => self.spi.transaction(&mut [
                Operation::Write(&[regs::CMD_FAST_READ, hi, lo, 0x00]),
                Operation::Read(buf),
            ]),
        };
        result.map_err(Error::Spi)
    }

    fn spi_write(&mut self, addr: u16, data: &[u8]) -> Result<(), Error<D::Error>> {
        let [hi, lo] = addr.to_be_bytes();
        self.spi
            .transaction(&mut [
                Operation::Write(&[regs::CMD_WRITE, hi, lo]),
                Operation::Write(data),
            ])
            .map_err(Error::Spi)
    }

    /// Polls `register` until `done(value)`, at most `max_polls` times.
    fn poll(&mut self, register: u16, done: impl Fn(u32) -> bool) -> Result<u32, Error<D::Error>> {
        for _ in 0..self.config.max_polls.max(1) {
            let v = self.read_register(register)?;
            if done(v) {
                return Ok(v);
            }
        }
        Err(Error::Timeout { register })
    }

    fn csr_wait_idle(&mut self) -> Result<(), Error<D::Error>> {
        self.csr_pending = true;
        self.poll(regs::ECAT_CSR_CMD, |v| v & regs::CSR_BUSY == 0)?;
        self.csr_pending = false;
        Ok(())
    }

    fn csr_command(&mut self, esc_addr: u16, size: usize, read: bool) -> Result<(), Error<D::Error>> {
        if self.csr_pending {
            self.csr_wait_idle()?;
        }
        let mut cmd = regs::CSR_BUSY | ((size as u32) << regs::CSR_SIZE_SHIFT) | u32::from(esc_addr);
        if read {
            cmd |= regs::CSR_READ;
        }
        self.csr_pending = true;
        self.write_register(regs::ECAT_CSR_CMD, cmd)?;
        self.csr_wait_idle()
    }

    fn csr_read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Error<D::Error>> {
        let mut addr = addr;
        let mut rest = buf;
        while !rest.is_empty() {
            let size = csr_chunk(addr, rest.len());
            self.csr_command(addr, size, true)?;
            let data = self.read_register(regs::ECAT_CSR_DATA)?.to_le_bytes();
            let (chunk, tail) = rest.split_at_mut_checked(size).unwrap_or_default();
            for (d, s) in chunk.iter_mut().zip(data) {
                *d = s;
            }
            rest = tail;
            addr = addr.wrapping_add(size as u16);
        }
        Ok(())
    }

    fn csr_write(&mut self, addr: u16, data: &[u8]) -> Result<(), Error<D::Error>> {
        let mut addr = addr;
        let mut rest = data;
        while !rest.is_empty() {
            let size = csr_chunk(addr, rest.len());
            let (chunk, tail) = rest.split_at_checked(size).unwrap_or_default();
            let mut value = [0u8; 4];
            for (d, s) in value.iter_mut().zip(chunk) {
                *d = *s;
            }
            if self.csr_pending {
                self.csr_wait_idle()?;
            }
            self.write_register(regs::ECAT_CSR_DATA, u32::from_le_bytes(value))?;
            self.csr_command(addr, size, false)?;
            rest = tail;
            addr = addr.wrapping_add(size as u16);
        }
        Ok(())
    }

    /// Aborts a transfer of the engine whose command register is `cmd_reg`
    /// and waits until it is idle.
    fn pram_abort(&mut self, cmd_reg: u16) -> Result<(), Error<D::Error>> {
        self.write_register(cmd_reg, regs::PRAM_ABORT)?;
        self.poll(cmd_reg, |v| v & regs::PRAM_BUSY == 0)?;
        Ok(())
    }

    /// Starts a process RAM command: aborts the one left unfinished
    /// (`dirty`), then writes address and length and sets the busy bit.
    fn pram_start(
        &mut self,
        cmd_reg: u16,
        addr_len_reg: u16,
        dirty: bool,
        addr: u16,
        len: usize,
    ) -> Result<(), Error<D::Error>> {
        if dirty {
            self.pram_abort(cmd_reg)?;
        }
        self.write_register(addr_len_reg, addr_len(addr, len))?;
        self.write_register(cmd_reg, regs::PRAM_BUSY)
    }

    fn pram_read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Error<D::Error>> {
        let dirty = core::mem::replace(&mut self.rd_dirty, true);
        self.pram_start(
            regs::ECAT_PRAM_RD_CMD,
            regs::ECAT_PRAM_RD_ADDR_LEN,
            dirty,
            addr,
            buf.len(),
        )?;

        // Byte position in the DWORD stream, which starts at the DWORD that
        // holds `addr`; the first `lead` bytes are padding.
        let lead = usize::from(addr & 3);
        let mut dwords_left = (lead + buf.len()).div_ceil(4);
        let mut stream_pos = 0usize;
        let mut out = buf.iter_mut();
        while dwords_left > 0 {
            let status = self.poll(regs::ECAT_PRAM_RD_CMD, |v| v & regs::PRAM_AVAIL != 0)?;
            let n = burst_dwords(status, dwords_left);
            let mut burst = [0u8; regs::FIFO_ALIAS_LEN];
            let chunk = burst.get_mut(..n * 4).unwrap_or_default();
            self.spi_read(regs::PRAM_RD_FIFO, chunk)?;
            for b in chunk.iter() {
                if stream_pos >= lead {
                    if let Some(d) = out.next() {
                        *d = *b;
                    }
                }
                stream_pos += 1;
            }
            dwords_left -= n;
        }
        self.rd_dirty = false;
        Ok(())
    }

    fn pram_write(&mut self, addr: u16, data: &[u8]) -> Result<(), Error<D::Error>> {
        let dirty = core::mem::replace(&mut self.wr_dirty, true);
        self.pram_start(
            regs::ECAT_PRAM_WR_CMD,
            regs::ECAT_PRAM_WR_ADDR_LEN,
            dirty,
            addr,
            data.len(),
        )?;

        let lead = usize::from(addr & 3);
        let mut dwords_left = (lead + data.len()).div_ceil(4);
        let mut stream_pos = 0usize;
        let mut src = data.iter();
        while dwords_left > 0 {
            let status = self.poll(regs::ECAT_PRAM_WR_CMD, |v| v & regs::PRAM_AVAIL != 0)?;
            let n = burst_dwords(status, dwords_left);
            let mut burst = [0u8; regs::FIFO_ALIAS_LEN];
            let chunk = burst.get_mut(..n * 4).unwrap_or_default();
            for b in chunk.iter_mut() {
                if stream_pos >= lead {
                    *b = src.next().copied().unwrap_or(0);
                }
                stream_pos += 1;
            }
            self.spi_write(regs::PRAM_WR_FIFO, chunk)?;
            dwords_left -= n;
        }
        // The data is in the ESC once the engine is idle again.
        self.poll(regs::ECAT_PRAM_WR_CMD, |v| v & regs::PRAM_BUSY == 0)?;
        self.wr_dirty = false;
        Ok(())
    }
}

/// Widest CSR access at `addr` for `remaining` bytes (LAN9252 "EtherCAT CSR
/// address vs. size": 4 bytes only 4-aligned, 2 bytes only 2-aligned).
fn csr_chunk(addr: u16, remaining: usize) -> usize {
    if addr & 1 != 0 || remaining < 2 {
        1
    } else if addr & 2 != 0 || remaining < 4 {
        2
    } else {
        4
    }
}

/// `ECAT_PRAM_*_ADDR_LEN` value. The length fits 16 bits: callers stay in the
/// 64 KiB space above 0x1000.
fn addr_len(addr: u16, len: usize) -> u32 {
    (((len as u32) & 0xFFFF) << 16) | u32::from(addr)
}

/// DWORDs to move in one burst: what the chip reports available (at least
/// one, the avail bit is set), what is left, and what the FIFO alias holds.
fn burst_dwords(status: u32, dwords_left: usize) -> usize {
    let count = ((status >> regs::PRAM_CNT_SHIFT) & regs::PRAM_CNT_MASK) as usize;
    count.max(1).min(dwords_left).min(regs::FIFO_ALIAS_LEN / 4)
}

impl<D: SpiDevice> esc::Pdi for Lan9252<D> {
    type Error = Error<D::Error>;

    fn read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Self::Error> {
        super::check_range(addr, buf.len())?;
        // Registers below 0x1000 through the CSR window, the rest through
        // the process RAM FIFO; an access across 0x1000 is split.
        let below = usize::from(PROCESS_RAM.saturating_sub(addr)).min(buf.len());
        let (regs_part, ram_part) = buf.split_at_mut_checked(below).unwrap_or_default();
        if !regs_part.is_empty() {
            self.csr_read(addr, regs_part)?;
        }
        if !ram_part.is_empty() {
            self.pram_read(addr.max(PROCESS_RAM), ram_part)?;
        }
        Ok(())
    }

    fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), Self::Error> {
        super::check_range(addr, data.len())?;
        let below = usize::from(PROCESS_RAM.saturating_sub(addr)).min(data.len());
        let (regs_part, ram_part) = data.split_at_checked(below).unwrap_or_default();
        if !regs_part.is_empty() {
            self.csr_write(addr, regs_part)?;
        }
        if !ram_part.is_empty() {
            self.pram_write(addr.max(PROCESS_RAM), ram_part)?;
        }
        Ok(())
    }

    fn al_event(&mut self) -> Result<u32, Self::Error> {
        // One 4-byte CSR read keeps the 32-bit register consistent.
        let mut b = [0u8; 4];
        self.csr_read(esc::regs::AL_EVENT_REQUEST, &mut b)?;
        Ok(u32::from_le_bytes(b))
    }
}
