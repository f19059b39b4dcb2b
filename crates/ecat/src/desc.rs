//! Device description: how the slave looks on the bus.
//!
//! A product declares one `static` [`Device`]; the SII image ([`crate::sii`]), the
//! stack's SyncManager checks and process-data sizes, and later the ESI XML and the
//! object dictionary all derive from it.

/// Identity (object 1018h, SII words 8..15).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Identity {
    /// Vendor ID (1018h:01).
    pub vendor_id: u32,
    /// Product code (1018h:02).
    pub product_code: u32,
    /// Revision number (1018h:03).
    pub revision: u32,
    /// Serial number (1018h:04).
    pub serial: u32,
}

/// A mailbox SyncManager (SM0 = master → slave, SM1 = slave → master).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MailboxSm {
    /// Physical start address.
    pub start: u16,
    /// Length in bytes.
    pub length: u16,
    /// Control byte (0x26 for SM0, 0x22 for SM1).
    pub control: u8,
}

/// A process-data SyncManager (SM2 = outputs, SM3 = inputs); its length follows
/// from the assigned PDOs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ProcessSm {
    /// Physical start address.
    pub start: u16,
    /// Control byte (0x64 for SM2, 0x20 for SM3).
    pub control: u8,
}

/// What an FMMU is used for (SII category FMMU).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FmmuUsage {
    /// Not used (0).
    Unused,
    /// Outputs, RxPDO (1).
    Outputs,
    /// Inputs, TxPDO (2).
    Inputs,
    /// SyncManager status, mailbox polling (3).
    MailboxStatus,
}

impl FmmuUsage {
    /// The SII code.
    pub const fn code(self) -> u8 {
        match self {
            FmmuUsage::Unused => 0,
            FmmuUsage::Outputs => 1,
            FmmuUsage::Inputs => 2,
            FmmuUsage::MailboxStatus => 3,
        }
    }
}

pub use od::{DataType, PdoEntry};

/// A PDO: mapping object index (1600h.. RxPDO, 1A00h.. TxPDO), name, entries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pdo {
    /// Mapping object index.
    pub index: u16,
    /// Name.
    pub name: &'static str,
    /// Mapped entries.
    pub entries: &'static [PdoEntry],
}

impl Pdo {
    /// Total size in bits.
    pub const fn bits(&self) -> u32 {
        let mut sum = 0u32;
        let mut rest = self.entries;
        while let [e, tail @ ..] = rest {
            sum += e.bits() as u32;
            rest = tail;
        }
        sum
    }
}

/// A distributed-clock operation mode (SII category DC, ESI `Dc/OpMode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DcOpMode {
    /// Name (e.g. "DC").
    pub name: &'static str,
    /// Description (e.g. "DC SYNC0").
    pub description: &'static str,
    /// AssignActivate word: 0x0300 for SYNC0, 0 for free run / SM-synchronous.
    pub assign_activate: u16,
    /// SYNC0 cycle time in ns (0 = the master's cycle).
    pub cycle_time_ns: u32,
    /// SYNC0 shift in ns.
    pub shift_ns: u32,
    /// SYNC0 cycle factor (multiple of the master cycle).
    pub sync0_cycle_factor: i16,
}

/// Bits of the SII GENERAL category's CoE details byte.
pub mod coe_details {
    /// SDO supported.
    pub const SDO: u8 = 1 << 0;
    /// SDO Information supported.
    pub const SDO_INFO: u8 = 1 << 1;
    /// PDO assignment configurable.
    pub const PDO_ASSIGN: u8 = 1 << 2;
    /// PDO mapping configurable.
    pub const PDO_CONFIG: u8 = 1 << 3;
    /// PDO configuration uploaded at startup.
    pub const UPLOAD_AT_STARTUP: u8 = 1 << 4;
    /// SDO complete access supported.
    pub const SDO_COMPLETE_ACCESS: u8 = 1 << 5;
}

/// The whole device as seen from the bus.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Device {
    /// Identity.
    pub identity: Identity,
    /// Device type (object 1000h).
    pub device_type: u32,
    /// Device name (1008h, SII GENERAL name).
    pub name: &'static str,
    /// Order code.
    pub order_code: &'static str,
    /// Device group.
    pub group: &'static str,
    /// SM0: write mailbox (master → slave).
    pub mailbox_out: MailboxSm,
    /// SM1: read mailbox (slave → master).
    pub mailbox_in: MailboxSm,
    /// SM2: outputs (RxPDO).
    pub outputs: ProcessSm,
    /// SM3: inputs (TxPDO).
    pub inputs: ProcessSm,
    /// FMMU usage, one per FMMU.
    pub fmmus: &'static [FmmuUsage],
    /// Supported mailbox protocols (bits of `esc::sii::mailbox_protocol`).
    pub mailbox_protocols: u16,
    /// CoE details (bits of [`coe_details`]).
    pub coe_details: u8,
    /// Number of MII ports (port 0, 1, ...).
    pub ports: u8,
    /// End (exclusive) of the ESC's process RAM: 0x2000 for 4 KiB, 0x3000 for 8 KiB.
    pub process_ram_end: u32,
    /// DC op modes; empty = no DC support.
    pub dc_modes: &'static [DcOpMode],
    /// RxPDOs (outputs), 1600h...
    pub rx_pdos: &'static [Pdo],
    /// TxPDOs (inputs), 1A00h...
    pub tx_pdos: &'static [Pdo],
    /// RxPDOs assigned to SM2 by default (1C12h).
    pub rx_assign: &'static [u16],
    /// TxPDOs assigned to SM3 by default (1C13h).
    pub tx_assign: &'static [u16],
}

impl Device {
    /// An RxPDO by mapping index.
    pub fn rx_pdo(&self, index: u16) -> Option<&'static Pdo> {
        self.rx_pdos.iter().find(|p| p.index == index)
    }

    /// A TxPDO by mapping index.
    pub fn tx_pdo(&self, index: u16) -> Option<&'static Pdo> {
        self.tx_pdos.iter().find(|p| p.index == index)
    }

    /// A PDO (Rx or Tx) by mapping index.
    pub fn pdo(&self, index: u16) -> Option<&'static Pdo> {
        self.rx_pdo(index).or_else(|| self.tx_pdo(index))
    }

    /// Bytes of the outputs (SM2): the assigned RxPDOs, rounded up to whole bytes.
    pub fn output_bytes(&self) -> usize {
        bytes_of(self.rx_assign.iter().filter_map(|&i| self.rx_pdo(i)))
    }

    /// Bytes of the inputs (SM3): the assigned TxPDOs, rounded up to whole bytes.
    pub fn input_bytes(&self) -> usize {
        bytes_of(self.tx_assign.iter().filter_map(|&i| self.tx_pdo(i)))
    }

    /// Whether distributed clocks are supported.
    pub fn dc_supported(&self) -> bool {
        !self.dc_modes.is_empty()
    }
}

fn bytes_of<'a>(pdos: impl Iterator<Item = &'a Pdo>) -> usize {
    let bits: u32 = pdos.map(Pdo::bits).sum();
    bits.div_ceil(8) as usize
}
