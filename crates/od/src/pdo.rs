//! An entry of a process-data mapping: the object it maps and its type.
//! Fieldbus-neutral: a CoE PDO (1600h…/1A00h…) and a PROFIdrive telegram
//! are lists of these.

use crate::DataType;

/// One entry of a process-data mapping (a PDO entry, a telegram entry).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PdoEntry {
    /// Object index.
    pub index: u16,
    /// Subindex.
    pub sub: u8,
    /// Data type; its size is the entry's bit length.
    pub data_type: DataType,
    /// Name.
    pub name: &'static str,
}

impl PdoEntry {
    /// An entry.
    pub const fn new(index: u16, sub: u8, data_type: DataType, name: &'static str) -> Self {
        Self {
            index,
            sub,
            data_type,
            name,
        }
    }

    /// Bit length (PDO entries are at most 64 bits; longer types saturate at 255).
    pub const fn bits(&self) -> u8 {
        let b = self.data_type.bits();
        if b > 255 {
            255
        } else {
            b as u8
        }
    }

    /// The CoE mapping value `index << 16 | sub << 8 | bits` (mapping objects 16xxh/1Axxh).
    pub const fn mapping_value(&self) -> u32 {
        ((self.index as u32) << 16) | ((self.sub as u32) << 8) | self.bits() as u32
    }
}
