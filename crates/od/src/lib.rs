//! The object dictionary model, shared by the CoE server (`ecat`) and the
//! drive's one declaration of its objects (`drive`).
//!
//! - [`DataType`]: CoE data types with their ETG.1000.6 codes and sizes.
//! - [`ObjectInfo`] / [`EntryInfo`]: the static metadata of an object and its
//!   entries (name, type, access rights, PDO mapping, range, default, unit,
//!   persistence): what SDO Info, PDO mapping checks, ESI, SII and the docs read.
//! - [`packed`]: the same metadata in a compact form ([`PackedTable`],
//!   [`Entries`]) for firmware images.
//! - [`Dictionary`]: what the CoE server needs from an object dictionary:
//!   metadata lookup and value access with the spec's abort codes.
//! - [`SdoAbort`]: the abort codes of spec §6.5.
#![no_std]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]
#![deny(missing_docs)]

mod abort;
pub mod error_register;
pub mod packed;
mod pdo;
mod types;

pub use abort::SdoAbort;
pub use packed::{Entries, PackedEntry, PackedRef, PackedTable, UNITS};
pub use pdo::PdoEntry;
pub use types::DataType;

/// Object code (ETG.1000.6 SDO Info object description).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ObjectCode {
    /// A single value (sub 0 only).
    Var,
    /// Entries of one type, sub 0 = number of entries.
    Array,
    /// Entries of different types, sub 0 = highest subindex.
    Record,
}

impl ObjectCode {
    /// The code on the wire: 7 VAR, 8 ARRAY, 9 RECORD.
    pub const fn code(self) -> u8 {
        match self {
            ObjectCode::Var => 7,
            ObjectCode::Array => 8,
            ObjectCode::Record => 9,
        }
    }
}

/// Access rights of an entry, as the SDO Info entry description encodes them
/// (ETG.1000.6 Table 46): bits 0..2 readable in PreOp/SafeOp/Op, bits 3..5
/// writable in PreOp/SafeOp/Op, bit 6 RxPDO-mappable, bit 7 TxPDO-mappable,
/// bit 8 backup, bit 9 setting.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Access(pub u16);

impl Access {
    /// Readable in PreOp, SafeOp and Op.
    pub const READ: u16 = 0b000_111;
    /// Writable in PreOp, SafeOp and Op.
    pub const WRITE: u16 = 0b111_000;
    /// Writable in PreOp only.
    pub const WRITE_PREOP: u16 = 0b001_000;
    /// RxPDO-mappable.
    pub const RXPDO: u16 = 1 << 6;
    /// TxPDO-mappable.
    pub const TXPDO: u16 = 1 << 7;
    /// Part of the backup (saved by "save values").
    pub const BACKUP: u16 = 1 << 8;
    /// A setting (startup parameter).
    pub const SETTING: u16 = 1 << 9;

    /// Read-only.
    pub const RO: Self = Self(Self::READ);
    /// Read-write in every state.
    pub const RW: Self = Self(Self::READ | Self::WRITE);
    /// Read in every state, written in PreOp only.
    pub const RW_PREOP: Self = Self(Self::READ | Self::WRITE_PREOP);
    /// Write-only.
    pub const WO: Self = Self(Self::WRITE);

    /// With more bits set.
    pub const fn with(self, bits: u16) -> Self {
        Self(self.0 | bits)
    }

    /// Readable in ESM state `state_bit` (0 PreOp, 1 SafeOp, 2 Op)?
    pub const fn readable_in(self, state_bit: u8) -> bool {
        self.0 & (1 << state_bit) != 0
    }

    /// Writable in ESM state `state_bit` (0 PreOp, 1 SafeOp, 2 Op)?
    pub const fn writable_in(self, state_bit: u8) -> bool {
        self.0 & (1 << (3 + state_bit)) != 0
    }

    /// Readable in any state.
    pub const fn readable(self) -> bool {
        self.0 & Self::READ != 0
    }

    /// Writable in any state.
    pub const fn writable(self) -> bool {
        self.0 & Self::WRITE != 0
    }

    /// RxPDO-mappable.
    pub const fn rx_mappable(self) -> bool {
        self.0 & Self::RXPDO != 0
    }

    /// TxPDO-mappable.
    pub const fn tx_mappable(self) -> bool {
        self.0 & Self::TXPDO != 0
    }
}

/// Where the CoE server is: the ESM state an access happens in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CommState {
    /// Init (no mailbox; only local accesses).
    Init,
    /// Pre-Operational.
    PreOp,
    /// Safe-Operational.
    SafeOp,
    /// Operational.
    Op,
}

impl CommState {
    /// The state bit used by [`Access`] (Init counts as PreOp).
    pub const fn access_bit(self) -> u8 {
        match self {
            CommState::Init | CommState::PreOp => 0,
            CommState::SafeOp => 1,
            CommState::Op => 2,
        }
    }
}

/// Static metadata of one entry (one subindex, or one template for all
/// elements of an array).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EntryInfo {
    /// Subindex.
    pub sub: u8,
    /// Name.
    pub name: &'static str,
    /// Data type.
    pub data_type: DataType,
    /// Access rights and PDO mappability.
    pub access: Access,
    /// Lowest accepted value (integers, as i64), if limited.
    pub min: Option<i64>,
    /// Highest accepted value (integers, as i64), if limited.
    pub max: Option<i64>,
    /// Default value (integers, as i64; 0 for strings).
    pub default: i64,
    /// Unit, e.g. "inc", "rpm", "ms", "" for none.
    pub unit: &'static str,
    /// Saved by "save values" (A00 / 1010h) and restored at start-up.
    pub persistent: bool,
}

impl EntryInfo {
    /// An entry without range, default 0, no unit, not persistent.
    pub const fn new(sub: u8, name: &'static str, data_type: DataType, access: Access) -> Self {
        Self {
            sub,
            name,
            data_type,
            access,
            min: None,
            max: None,
            default: 0,
            unit: "",
            persistent: false,
        }
    }

    /// With the accepted range `min..=max`.
    pub const fn range(mut self, min: i64, max: i64) -> Self {
        self.min = Some(min);
        self.max = Some(max);
        self
    }

    /// With the default value `value`.
    pub const fn default_value(mut self, value: i64) -> Self {
        self.default = value;
        self
    }

    /// With the unit `unit`.
    pub const fn unit(mut self, unit: &'static str) -> Self {
        self.unit = unit;
        self
    }

    /// Persistent: saved by "save values" and restored at start-up.
    pub const fn saved(mut self) -> Self {
        self.persistent = true;
        self
    }

    /// RxPDO-mappable.
    pub const fn rx(mut self) -> Self {
        self.access = self.access.with(Access::RXPDO);
        self
    }

    /// TxPDO-mappable.
    pub const fn tx(mut self) -> Self {
        self.access = self.access.with(Access::TXPDO);
        self
    }

    /// The same entry at subindex `sub`.
    pub const fn at(mut self, sub: u8) -> Self {
        self.sub = sub;
        self
    }

    /// Size in bits.
    pub const fn bit_len(&self) -> u16 {
        self.data_type.bits()
    }

    /// Lowest accepted value: the declared minimum, else the type's.
    pub const fn lowest(&self) -> i64 {
        match self.min {
            Some(m) => m,
            None => self.data_type.min_value(),
        }
    }

    /// Highest accepted value: the declared maximum, else the type's.
    pub const fn highest(&self) -> i64 {
        match self.max {
            Some(m) => m,
            None => self.data_type.max_value(),
        }
    }

    /// Checks a decoded integer value against the range: 0609 0032h below,
    /// 0609 0031h above. REAL32 and strings are not range-checked.
    pub const fn check_range(&self, value: i64) -> Result<(), SdoAbort> {
        if !self.data_type.is_integer() {
            Ok(())
        } else if value < self.lowest() {
            Err(SdoAbort::VALUE_TOO_LOW)
        } else if value > self.highest() {
            Err(SdoAbort::VALUE_TOO_HIGH)
        } else {
            Ok(())
        }
    }
}

/// Static metadata of one object.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectInfo {
    /// Index.
    pub index: u16,
    /// Name.
    pub name: &'static str,
    /// Object code.
    pub code: ObjectCode,
    /// Entries, sub 0 first, sorted by subindex.
    pub entries: Entries,
}

impl ObjectInfo {
    /// The entry with subindex `sub`, decoded.
    pub fn entry(&self, sub: u8) -> Option<EntryInfo> {
        self.entries.find(sub)
    }

    /// Highest subindex.
    pub fn max_sub(&self) -> u8 {
        self.entries.max_sub()
    }
}

/// An object dictionary as the CoE server sees it.
///
/// Value access checks existence, access rights in `state`, size, range and
/// consistency, and answers with the abort code of spec §6.5; a refused
/// write changes nothing.
pub trait Dictionary {
    /// Metadata of object `index`, if it exists (and is visible).
    fn object(&self, index: u16) -> Option<&'static ObjectInfo>;

    /// The visible object with the smallest index greater than `after`
    /// (`None` = from the start): iteration for the SDO Info OD list.
    fn next_object(&self, after: Option<u16>) -> Option<&'static ObjectInfo>;

    /// Reads `index`:`sub` into `buf`, returning the byte count.
    fn read(&mut self, index: u16, sub: u8, buf: &mut [u8], state: CommState) -> Result<usize, SdoAbort>;

    /// Writes `data` to `index`:`sub`.
    fn write(&mut self, index: u16, sub: u8, data: &[u8], state: CommState) -> Result<(), SdoAbort>;

    /// The lengths in bytes of the currently mapped process data: (RxPDO =
    /// outputs = SM2, TxPDO = inputs = SM3), the sums of the entries of the
    /// PDOs assigned in 1C12h/1C13h. `None`: the dictionary has no PDO
    /// objects (the stack then uses its device description).
    fn process_data_bytes(&self) -> Option<(usize, usize)> {
        None
    }

    /// Is the SDO Information service available? (Spec §7: only with the
    /// "EtherCAT Rx SDO Info" template.)
    fn sdo_info_enabled(&self) -> bool {
        true
    }

    /// Does the SDO Info OD list show object `index`? (A device's own
    /// selection of the listed objects, e.g. the drive's A268; objects not
    /// listed keep their descriptions and values.)
    fn listed(&self, _index: u16) -> bool {
        true
    }
}
