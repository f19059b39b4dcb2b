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
/// Submodule ident of port 1's subslot 0x8001 (port 2's is 0x8002, see
/// [`port_submodule_ident`]).
pub const PORT_SUBMODULE_IDENT: u32 = 0x0000_8001;
/// Number of Ethernet ports (P-003, P-006).
pub const PORTS: u16 = 2;

/// Submodule ident of port `port` (1 or 2): 0x8000 + port, one ident per
/// port (an engineering tool tells the GSDML's PortSubmoduleItems apart by
/// their idents; the ports' hardware is alike).
pub const fn port_submodule_ident(port: u16) -> u32 {
    PORT_SUBMODULE_IDENT - 1 + port as u32
}

/// The largest record the device reads or writes (GSDML
/// `MaxSupportedRecordSize`): 4,068 bytes, the least every device must take.
/// The RPC buffers hold an IODWriteMultiple with one record this big.
pub const MAX_RECORD_SIZE: usize = 4068;

/// Vendor name of the GSDML and of I&M0's manufacturer text. A placeholder,
/// like [`VENDOR_ID`].
pub const VENDOR_NAME: &str = "Open Servo Firmware";
/// Order number (GSDML `OrderNumber`, I&M0 OrderID, at most 20 characters). A
/// placeholder until the project has part numbers.
pub const ORDER_NUMBER: &str = "BL4000-PN";
/// Software release (GSDML `SoftwareRelease`): "V" and the crate version.
pub const SOFTWARE_RELEASE: &str = concat!("V", env!("CARGO_PKG_VERSION"));

const fn parse_u8(s: &str) -> u8 {
    let b = s.as_bytes();
    let mut i = 0;
    let mut v: u8 = 0;
    while i < b.len() {
        // in bounds: i < b.len() (`get` is not const-callable with a match here)
        let d = match b.split_at_checked(i) {
            Some((_, [d, ..])) => *d,
            _ => 0,
        };
        if d.is_ascii_digit() {
            v = v.saturating_mul(10).saturating_add(d - b'0');
        }
        i += 1;
    }
    v
}

/// Software revision of I&M0 and the endpoint mapper's annotation: 'V' and
/// the crate version's major, minor and patch numbers.
pub const SOFTWARE_REVISION: (u8, u8, u8, u8) = (
    b'V',
    parse_u8(env!("CARGO_PKG_VERSION_MAJOR")),
    parse_u8(env!("CARGO_PKG_VERSION_MINOR")),
    parse_u8(env!("CARGO_PKG_VERSION_PATCH")),
);
/// Hardware revision of I&M0.
pub const HARDWARE_REVISION: u16 = 1;

/// Smallest cycle the device supports, in units of 31.25 µs (GSDML
/// `MinDeviceInterval`): 32 = 1 ms, spec Q-17.
pub const MIN_DEVICE_INTERVAL: u16 = 32;
/// Send clock factor the device accepts (× 31.25 µs): 32 = 1 ms.
pub const SEND_CLOCK_FACTOR: u16 = 32;
/// Reduction ratios the device accepts with [`SEND_CLOCK_FACTOR`]: 1 ms … 512 ms.
pub const REDUCTION_RATIOS: [u16; 10] = [1, 2, 4, 8, 16, 32, 64, 128, 256, 512];
/// The slots data modules may be plugged into: one module per direction, in
/// either order (the manual's example has OUT in slot 1, IN in slot 2).
pub const DATA_SLOTS: core::ops::RangeInclusive<u16> = 1..=2;
/// I&M records a controller may write on the DAP's subslot 1: I&M1…I&M4 (I&M0
/// is read-only; spec Q-17 recommends I&M0–4).
pub const WRITEABLE_IM_RECORDS: [u8; 4] = [1, 2, 3, 4];

/// Diagnosis numbering (spec §2.7, P-031/P-032): a drive error HH-S is its
/// main error HH, the drive's E82 event (`drive_core::faults::EVENTS`), and
/// its sub error S, the E43 cause. ChannelErrorType = 0x1000 + HH, added as a
/// binary number (decision on Q-13: 22 → 0x1016).
pub const fn channel_error_type(main_error: u8) -> u16 {
    0x1000 + main_error as u16
}

/// Sub errors with an ExtChannelErrorType: the manufacturer range 0x1000 …
/// 0x100F of spec §2.7 holds S = 0 … 15.
pub const SUB_ERRORS: core::ops::RangeInclusive<u8> = 0..=15;

/// ExtChannelErrorType of sub error `sub` (P-032): 0x1000 + S; `None` beyond
/// [`SUB_ERRORS`].
pub const fn ext_channel_error_type(sub: u8) -> Option<u16> {
    if sub <= *SUB_ERRORS.end() {
        Some(0x1000 + sub as u16)
    } else {
        None
    }
}
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

    #[test]
    fn diagnosis_error_types_are_0x1000_plus_main_and_sub() {
        assert_eq!(channel_error_type(8), 0x1008);
        assert_eq!(channel_error_type(22), 0x1016);
        assert_eq!(ext_channel_error_type(6), Some(0x1006));
        assert_eq!(ext_channel_error_type(15), Some(0x100F));
        assert_eq!(ext_channel_error_type(16), None);
        assert_eq!(port_submodule_ident(1), 0x8001);
        assert_eq!(port_submodule_ident(2), 0x8002);
        assert!(ORDER_NUMBER.len() <= 20);
    }
}
