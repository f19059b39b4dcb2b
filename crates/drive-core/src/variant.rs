//! The devices one declaration describes (issue 20): the double-axis device
//! (SC6A062: axis A, and axis B with its CiA 402 objects at +800h and its
//! manufacturer objects at +8000h) and the single-axis device (SI6A061:
//! axis A only).
//!
//! The single-axis device is the double-axis declaration without axis B's
//! objects ([`Variant::has_object`]: hidden from CoE, SDO Info, PDO mapping
//! checks and the ESI as an object above the access level is) and with a few
//! objects declared again where its description differs
//! ([`crate::objects::single`]: identity, device name, channel 2 free and
//! empty, no module ident of axis B). Its RAM image has the same layout, so
//! one dictionary type serves both; a saved set names its variant
//! ([`Variant::layout_hash`]), so neither loads the other's.

use crate::objects::{single, Object, LAYOUT_HASH};

/// Which device the declaration describes, chosen when the dictionary is
/// built ([`crate::DriveObjects::for_variant`]) and fixed from then on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Variant {
    /// The double-axis device (SC6A062): axes A and B (the default).
    #[default]
    Double,
    /// The single-axis device (SI6A061): axis A only, no axis-B objects or
    /// PDOs.
    Single,
}

impl Variant {
    /// Both variants, the default first.
    pub const ALL: [Variant; 2] = [Variant::Double, Variant::Single];

    /// Number of axes (A, or A and B).
    pub const fn axes(self) -> usize {
        match self {
            Variant::Double => 2,
            Variant::Single => 1,
        }
    }

    /// Product code 1018h:02 (E-005: nominal power in 0.1 kW).
    pub const fn product_code(self) -> u32 {
        match self {
            Variant::Double => crate::PRODUCT_CODE,
            Variant::Single => crate::PRODUCT_CODE_SINGLE,
        }
    }

    /// Manufacturer device name 1008h (E50).
    pub const fn device_name(self) -> &'static str {
        match self {
            Variant::Double => crate::DEVICE_NAME,
            Variant::Single => crate::DEVICE_NAME_SINGLE,
        }
    }

    /// Does the device have the object at `index`? The single-axis device
    /// has none of axis B's ([`is_axis_b`]).
    pub const fn has_object(self, index: u16) -> bool {
        match self {
            Variant::Double => true,
            Variant::Single => !is_axis_b(index),
        }
    }

    /// The objects this variant declares again (empty for the double-axis
    /// device), sorted by index.
    pub fn redeclared(self) -> &'static [Object] {
        match self {
            Variant::Double => &[],
            Variant::Single => &single::OBJECTS,
        }
    }

    /// `o` (an object of [`crate::objects::OBJECTS`]) as this variant
    /// declares it: its own declaration where it has one, else `o`.
    pub fn declared(self, o: &'static Object) -> &'static Object {
        self.redeclared()
            .iter()
            .find(|r| r.info.index == o.info.index)
            .unwrap_or(o)
    }

    /// The layout hash a saved parameter set of this variant carries: the
    /// declaration's [`LAYOUT_HASH`], one more FNV-1a step for the
    /// single-axis device (its image has the same layout, but a set saved
    /// by the other device, e.g. channel 2 mapping axis B, must not load).
    pub const fn layout_hash(self) -> u32 {
        match self {
            Variant::Double => LAYOUT_HASH,
            Variant::Single => (LAYOUT_HASH ^ 0x01).wrapping_mul(0x0100_0193),
        }
    }
}

/// Is `index` one of axis B's objects: its CiA 402 objects (axis A's at
/// +800h, 6800h…6FFFh, E-015) or its manufacturer objects (axis A's at
/// +8000h, A000h…DFFFh, E-010)?
pub const fn is_axis_b(index: u16) -> bool {
    matches!(index, 0x6800..=0x6FFF | 0xA000..=0xDFFF)
}
