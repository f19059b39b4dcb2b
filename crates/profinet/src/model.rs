//! The device's module model (`profidrive.md` §2.6) and PROFINET identity: one
//! declaration read by the device (expected vs. real submodules, ModuleDiffBlock)
//! and by the GSDML generator.
//!
//! - Slot 0: the DAP "smartServo BL 4000-M/D/C" with subslot 1 (the device),
//!   0x8000 (interface X1) and 0x8001/0x8002 (ports 1 and 2).
//! - Slots 1…: IN and OUT modules of 2…19 words (4…38 bytes). Their names follow
//!   the manual and are written from the **drive's** side (E-18): an "OUT module"
//!   carries drive → controller data (the response telegram, the controller's
//!   *input* CR); an "IN module" carries controller → drive data (the receive
//!   telegram, the controller's *output* CR).

/// PROFINET vendor ID. Not PI-assigned: a placeholder until the project has its
/// own (the manual's 0x0115 is Metronix's and is not ours to use).
pub const VENDOR_ID: u16 = 0xFEFE;
/// PROFINET device ID of the drive family.
pub const DEVICE_ID: u16 = 0x0001;
/// The DAP's name in the hardware catalogue (P-025).
pub const DAP_NAME: &str = "smartServo BL 4000-M/D/C";
/// DCP NameOfVendor / device vendor value ("type of station").
pub const STATION_TYPE: &str = "smartServo BL 4000";
/// Module ident number of the DAP.
pub const DAP_MODULE_IDENT: u32 = 0x0000_0001;
/// Submodule ident numbers of the DAP's subslots.
pub const DAP_SUBMODULE_IDENT: u32 = 0x0000_0001;
/// Submodule ident of the interface subslot 0x8000.
pub const INTERFACE_SUBMODULE_IDENT: u32 = 0x0000_8000;
/// Submodule ident of a port subslot 0x8001/0x8002.
pub const PORT_SUBMODULE_IDENT: u32 = 0x0000_8001;
/// Number of Ethernet ports (P-003, P-006).
pub const PORTS: u16 = 2;
/// The DAP's subslots.
pub const DAP_SUBSLOTS: [u16; 4] = [0x0001, 0x8000, 0x8001, 0x8002];
/// Smallest and largest data module, in 16-bit words (P-026).
pub const MODULE_WORDS: core::ops::RangeInclusive<u8> = 2..=19;
/// The submodule ident of every data module's single subslot 1.
pub const DATA_SUBMODULE_IDENT: u32 = 0x0000_0001;

/// Which way a data module's bytes go.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// "IN module": controller → drive (receive telegram; controller output CR).
    ToDrive,
    /// "OUT module": drive → controller (response telegram; controller input CR).
    FromDrive,
}

/// A data module of the catalogue.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DataModule {
    /// Direction of its data.
    pub direction: Direction,
    /// Length in 16-bit words (2…19).
    pub words: u8,
}

impl DataModule {
    /// Its module ident number: 0x100 + words for IN, 0x200 + words for OUT.
    pub const fn ident(self) -> u32 {
        match self.direction {
            Direction::ToDrive => 0x100 + self.words as u32,
            Direction::FromDrive => 0x200 + self.words as u32,
        }
    }

    /// Its length in bytes.
    pub const fn bytes(self) -> usize {
        self.words as usize * 2
    }

    /// The catalogue module for a module ident number, if there is one.
    pub fn from_ident(ident: u32) -> Option<DataModule> {
        let (direction, words) = match ident {
            0x100..=0x1FF => (Direction::ToDrive, ident - 0x100),
            0x200..=0x2FF => (Direction::FromDrive, ident - 0x200),
            _ => return None,
        };
        let words = u8::try_from(words).ok()?;
        MODULE_WORDS
            .contains(&words)
            .then_some(DataModule { direction, words })
    }

    /// Every catalogue module, IN modules first (for the GSDML).
    pub fn catalogue() -> impl Iterator<Item = DataModule> {
        [Direction::ToDrive, Direction::FromDrive]
            .into_iter()
            .flat_map(|direction| MODULE_WORDS.map(move |words| DataModule { direction, words }))
    }

    /// Catalogue name, e.g. "18 Word Output Data" (drive's side, E-18).
    pub fn name(self) -> heapless::String<24> {
        use core::fmt::Write;
        let mut s = heapless::String::new();
        let what = match self.direction {
            Direction::ToDrive => "Input",
            Direction::FromDrive => "Output",
        };
        // 24 bytes hold "19 Word Output Data".
        let _ = write!(s, "{} Word {} Data", self.words, what);
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn p026_catalogue_has_in_and_out_modules_of_2_to_19_words() {
        let all: std::vec::Vec<_> = DataModule::catalogue().collect();
        assert_eq!(all.len(), 36);
        for m in &all {
            assert_eq!(DataModule::from_ident(m.ident()), Some(*m));
        }
        assert_eq!(DataModule::from_ident(0x101), None);
        assert_eq!(DataModule::from_ident(0x214), None);
        let out18 = DataModule {
            direction: Direction::FromDrive,
            words: 18,
        };
        assert_eq!(out18.name().as_str(), "18 Word Output Data");
        assert_eq!(out18.bytes(), 36);
    }
}
