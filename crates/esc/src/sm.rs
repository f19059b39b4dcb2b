//! SyncManager register block (0x0800 + 8·n, 8 bytes).

use crate::{byte, le_u16, Truncated};

/// Buffer type of a SyncManager (control bits 0..1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SmMode {
    /// Three-buffer (process data) mode, code 00b.
    Buffered,
    /// One-buffer mailbox mode with handshake, code 10b.
    Mailbox,
    /// Reserved codes 01b and 11b.
    Reserved(u8),
}

/// Direction of a SyncManager seen from the master (control bits 2..3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SmDirection {
    /// ECAT reads, PDI writes (code 00b): inputs, read mailbox.
    MasterRead,
    /// ECAT writes, PDI reads (code 01b): outputs, write mailbox.
    MasterWrite,
    /// Reserved codes.
    Reserved(u8),
}

/// The control byte (offset 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SmControl(pub u8);

impl SmControl {
    /// Buffer type.
    pub const fn mode(self) -> SmMode {
        match self.0 & 0x03 {
            0 => SmMode::Buffered,
            2 => SmMode::Mailbox,
            m => SmMode::Reserved(m),
        }
    }

    /// Direction.
    pub const fn direction(self) -> SmDirection {
        match (self.0 >> 2) & 0x03 {
            0 => SmDirection::MasterRead,
            1 => SmDirection::MasterWrite,
            d => SmDirection::Reserved(d),
        }
    }

    /// Interrupt in the ECAT event request register (bit 4).
    pub const fn ecat_irq(self) -> bool {
        self.0 & 0x10 != 0
    }

    /// Interrupt in the AL event request register (bit 5).
    pub const fn pdi_irq(self) -> bool {
        self.0 & 0x20 != 0
    }

    /// Watchdog trigger enable (bit 6).
    pub const fn watchdog(self) -> bool {
        self.0 & 0x40 != 0
    }

    /// Builds a control byte.
    pub const fn new(mode: SmMode, dir: SmDirection, pdi_irq: bool, watchdog: bool) -> Self {
        let m = match mode {
            SmMode::Buffered => 0,
            SmMode::Mailbox => 2,
            SmMode::Reserved(m) => m & 3,
        };
        let d = match dir {
            SmDirection::MasterRead => 0,
            SmDirection::MasterWrite => 1,
            SmDirection::Reserved(d) => d & 3,
        };
        Self(m | d << 2 | if pdi_irq { 0x20 } else { 0 } | if watchdog { 0x40 } else { 0 })
    }
}

/// Status byte (offset 5) bits.
pub mod status {
    /// Interrupt write: the buffer was written by the writing side.
    pub const IRQ_WRITE: u8 = 1 << 0;
    /// Interrupt read: the buffer was read by the reading side.
    pub const IRQ_READ: u8 = 1 << 1;
    /// Mailbox full (one-buffer mode).
    pub const MAILBOX_FULL: u8 = 1 << 3;
    /// Three-buffer mode: last written buffer (bits 4..5).
    pub const BUFFER_MASK: u8 = 0x30;
    /// Read buffer in use (opened).
    pub const READ_OPEN: u8 = 1 << 6;
    /// Write buffer in use (opened).
    pub const WRITE_OPEN: u8 = 1 << 7;
}

/// Activate byte (offset 6) bits, written by ECAT.
pub mod activate {
    /// SyncManager enabled.
    pub const ENABLE: u8 = 1 << 0;
    /// Repeat request (mailbox): toggled by the master to ask for the last read mailbox again.
    pub const REPEAT: u8 = 1 << 1;
    /// DC event 0 with ECAT write.
    pub const DC_EVENT_ECAT: u8 = 1 << 6;
    /// DC event 0 with local write.
    pub const DC_EVENT_LOCAL: u8 = 1 << 7;
}

/// PDI control byte (offset 7) bits, written by the PDI.
pub mod pdi_control {
    /// Deactivate the SyncManager from the PDI side.
    pub const DEACTIVATE: u8 = 1 << 0;
    /// Repeat acknowledge: the PDI copies the repeat bit here after re-writing the mailbox.
    pub const REPEAT_ACK: u8 = 1 << 1;
}

/// The 8-byte SyncManager register block.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SyncManager {
    /// Physical start address (offset 0, u16).
    pub start: u16,
    /// Length in bytes (offset 2, u16).
    pub length: u16,
    /// Control byte (offset 4).
    pub control: u8,
    /// Status byte (offset 5), read-only for ECAT and PDI.
    pub status: u8,
    /// Activate byte (offset 6), written by ECAT.
    pub activate: u8,
    /// PDI control byte (offset 7), written by the PDI.
    pub pdi_control: u8,
}

impl SyncManager {
    /// Register block length in bytes.
    pub const LEN: usize = 8;

    /// Parses the register block; errors when `b` is shorter than 8 bytes.
    pub fn parse(b: &[u8]) -> Result<Self, Truncated> {
        Ok(Self {
            start: le_u16(b, 0)?,
            length: le_u16(b, 2)?,
            control: byte(b, 4)?,
            status: byte(b, 5)?,
            activate: byte(b, 6)?,
            pdi_control: byte(b, 7)?,
        })
    }

    /// The register block as bytes.
    pub fn to_bytes(&self) -> [u8; 8] {
        let s = self.start.to_le_bytes();
        let l = self.length.to_le_bytes();
        [
            s[0],
            s[1],
            l[0],
            l[1],
            self.control,
            self.status,
            self.activate,
            self.pdi_control,
        ]
    }

    /// Typed control byte.
    pub const fn control(&self) -> SmControl {
        SmControl(self.control)
    }

    /// Enabled by the master.
    pub const fn enabled(&self) -> bool {
        self.activate & activate::ENABLE != 0
    }

    /// Last byte of the buffer area (start + length − 1), `None` for length 0 or overflow.
    pub fn end(&self) -> Option<u16> {
        self.length.checked_sub(1).and_then(|l| self.start.checked_add(l))
    }

    /// Physical area occupied in memory: a three-buffer SM uses three times its length.
    pub fn occupied_len(&self) -> u32 {
        let n = if self.control().mode() == SmMode::Buffered {
            3
        } else {
            1
        };
        u32::from(self.length) * n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sm_round_trip_and_truncation() {
        let sm = SyncManager {
            start: 0x1000,
            length: 128,
            control: 0x26,
            status: 0,
            activate: 1,
            pdi_control: 0,
        };
        let b = sm.to_bytes();
        assert_eq!(SyncManager::parse(&b), Ok(sm));
        assert_eq!(SyncManager::parse(&b[..7]), Err(Truncated));
        assert_eq!(sm.control().mode(), SmMode::Mailbox);
        assert_eq!(sm.control().direction(), SmDirection::MasterWrite);
        assert!(sm.control().pdi_irq());
        assert_eq!(sm.end(), Some(0x107F));
        assert_eq!(SyncManager { length: 0, ..sm }.end(), None);
    }

    #[test]
    fn control_builder_matches_etg_values() {
        // ETG default values: SM0 0x26, SM1 0x22, SM2 0x64, SM3 0x20.
        assert_eq!(
            SmControl::new(SmMode::Mailbox, SmDirection::MasterWrite, true, false).0,
            0x26
        );
        assert_eq!(
            SmControl::new(SmMode::Mailbox, SmDirection::MasterRead, true, false).0,
            0x22
        );
        assert_eq!(
            SmControl::new(SmMode::Buffered, SmDirection::MasterWrite, true, true).0,
            0x64
        );
        assert_eq!(
            SmControl::new(SmMode::Buffered, SmDirection::MasterRead, true, false).0,
            0x20
        );
    }
}
