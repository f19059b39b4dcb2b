//! The simulated drives' non-volatile memories: the parameter store's
//! flash and the firmware slots' flash (copy on write, so a copy of a line
//! shares it).

/// The simulated non-volatile memory of a drive: two 4 KiB sectors (one per slot).
pub type SimFlash = store::RamFlash<4096, 2>;

/// The simulated firmware flash: 2 × 66 sectors of 4 KiB (a slot takes a
/// 256 KiB image), NOR in RAM, on the heap. Copy on write: a clone (a copy
/// of a line, [`Simulation::try_clone`](super::Simulation::try_clone)) shares the 528 KiB until one of
/// them erases or writes, so a snapshot costs what it changes.
#[derive(Clone)]
pub struct FirmwareFlash(pub std::sync::Arc<drive_ecat::boot::RamFlash<4096, 132>>);

impl FirmwareFlash {
    /// An erased flash.
    pub fn new() -> Self {
        Self(std::sync::Arc::new(drive_ecat::boot::RamFlash::new()))
    }
}

impl Default for FirmwareFlash {
    fn default() -> Self {
        Self::new()
    }
}

impl drive_ecat::boot::Flash for FirmwareFlash {
    const SECTOR: usize = 4096;
    const SECTORS: usize = 132;
    const WRITE: usize = 8;
    fn read(&mut self, addr: u32, buf: &mut [u8]) -> Result<(), drive_ecat::boot::FlashError> {
        // a read changes nothing: only erase and write copy a shared flash
        self.0.read_shared(addr, buf)
    }
    fn erase(&mut self, sector: u32) -> Result<(), drive_ecat::boot::FlashError> {
        drive_ecat::boot::Flash::erase(std::sync::Arc::make_mut(&mut self.0), sector)
    }
    fn write(&mut self, addr: u32, data: &[u8]) -> Result<(), drive_ecat::boot::FlashError> {
        drive_ecat::boot::Flash::write(std::sync::Arc::make_mut(&mut self.0), addr, data)
    }
}

/// The firmware slots of a simulated drive.
pub type FirmwareSlots = drive_ecat::boot::BootSlots<FirmwareFlash>;

/// A firmware body of `len` bytes for a test download, derived from
/// `version` (byte 3 of `i·2654435761 + version`, little-endian, for byte
/// `i`), so that two versions differ throughout: the update files of the FoE
/// bench, the end-to-end tests and the SOEM FoE test (version 0).
pub fn firmware_body(len: usize, version: u32) -> Vec<u8> {
    (0..len)
        .map(|i| {
            (i as u32)
                .wrapping_mul(2_654_435_761)
                .wrapping_add(version)
                .to_le_bytes()[3]
        })
        .collect()
}
