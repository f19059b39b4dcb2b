//! The single-axis device in the simulator ([`drive_ecat::Variant::Single`],
//! issue 20): drives and lines of it. The motor of axis B is still there,
//! unpowered (the drive leaves axis B idle).

use super::{FirmwareFlash, SimDrive, SimFlash, Simulation};
use drive_ecat::Variant;

impl SimDrive {
    /// A single-axis drive (SI6A061: its SII, no axis-B objects or PDOs,
    /// axis B idle) with empty non-volatile memory.
    pub fn single_axis() -> Self {
        Self::power_on_for(Variant::Single, SimFlash::new(), None)
    }

    /// A drive of `variant` with firmware slots, both empty (as
    /// [`SimDrive::with_firmware_slots`], `hil-sim serve`).
    pub fn with_firmware_slots_for(variant: Variant) -> Self {
        Self::power_on_for(variant, SimFlash::new(), Some(FirmwareFlash::new()))
    }

    /// The device this drive is.
    pub fn variant(&self) -> Variant {
        self.drive.variant()
    }
}

impl Simulation<SimDrive> {
    /// `n` drives of `variant` in a line, time 0.
    pub fn of(variant: Variant, n: usize) -> Self {
        Self::with_nodes(
            (0..n)
                .map(|_| SimDrive::power_on_for(variant, SimFlash::new(), None))
                .collect(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A power cycle keeps the device: the same variant, its SII and
    /// description, its saved set.
    #[test]
    fn a_power_cycle_keeps_the_single_axis_device() {
        let mut d = SimDrive::single_axis();
        assert_eq!(d.variant(), Variant::Single);
        d.power_cycle();
        assert_eq!(d.variant(), Variant::Single);
        assert_eq!(
            d.drive.slave().device().identity.product_code,
            drive_ecat::PRODUCT_CODE_SINGLE
        );
        let line = Simulation::of(Variant::Single, 2);
        assert!(line.drives().iter().all(|d| d.variant() == Variant::Single));
        assert_eq!(SimDrive::new().variant(), Variant::Double);
        assert_eq!(
            SimDrive::with_firmware_slots_for(Variant::Single).variant(),
            Variant::Single
        );
    }
}
