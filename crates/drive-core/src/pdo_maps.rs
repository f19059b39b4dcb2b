//! The process-data maps the drive ships: the default RxPDO/TxPDO of each
//! axis (1600h/1A00h, 1601h/1A01h) and the mode-specific maps of ip and vl
//! (spec §5.4, cia402.md §6.5). The mapping objects' defaults and the
//! EtherCAT device description both derive from them.

use crate::parameter_index;
use od::{DataType, PdoEntry};

/// Axis-A RxPDO entries (spec §5.4, 23 bytes): the default of 1600h.
pub const RX_A: [PdoEntry; 8] = [
    PdoEntry::new(0x6040, 0, DataType::U16, "Controlword"),
    PdoEntry::new(0x6060, 0, DataType::I8, "Modes of operation"),
    PdoEntry::new(0x607A, 0, DataType::I32, "Target position"),
    PdoEntry::new(0x60FF, 0, DataType::I32, "Target velocity"),
    PdoEntry::new(0x60B1, 0, DataType::I32, "Velocity offset"),
    PdoEntry::new(0x60B2, 0, DataType::I16, "Torque offset"),
    PdoEntry::new(0x6071, 0, DataType::I16, "Target torque"),
    PdoEntry::new(0x60FE, 1, DataType::U32, "Digital outputs"),
];

/// Axis-A TxPDO entries (spec §5.4, 29 bytes): the default of 1A00h.
pub const TX_A: [PdoEntry; 10] = [
    PdoEntry::new(0x6041, 0, DataType::U16, "Statusword"),
    PdoEntry::new(0x6061, 0, DataType::I8, "Modes of operation display"),
    PdoEntry::new(0x6064, 0, DataType::I32, "Position actual value"),
    PdoEntry::new(0x606C, 0, DataType::I32, "Velocity actual value"),
    PdoEntry::new(0x6077, 0, DataType::I16, "Torque actual value"),
    PdoEntry::new(0x60F4, 0, DataType::I32, "Following error actual value"),
    PdoEntry::new(0x60FD, 0, DataType::U32, "Digital inputs"),
    PdoEntry::new(0x60E4, 1, DataType::I32, "Additional position actual value"),
    PdoEntry::new(parameter_index(4, 201), 0, DataType::U16, "E201 Status word 2"),
    PdoEntry::new(
        parameter_index(0, 67),
        0,
        DataType::U16,
        "A67 Status word user-defined",
    ),
];

/// The mode-specific maps of cia402.md §6.5.1 and §6.5.6: ip and vl cannot use
/// the standard maps. A master (startup list) or the commissioning side writes
/// them into 1600h/1A00h in Pre-Op ([`DriveObjects::apply_map`](crate::DriveObjects::apply_map)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PdoLayout {
    /// RxPDO 23 bytes, TxPDO 29 bytes (spec §5.4).
    Standard,
    /// Interpolated position (ip, 7): 6040h, 6060h, 60C1h:01 / 6041h, 6061h, 6064h; 7 bytes each.
    Ip,
    /// Velocity mode (vl, 2): 6040h, 6060h, 6042h / 6041h, 6061h, 6044h; 5 bytes each.
    Vl,
}

/// ip RxPDO (7 bytes).
pub const IP_RX: [PdoEntry; 3] = [
    PdoEntry::new(0x6040, 0, DataType::U16, "Controlword"),
    PdoEntry::new(0x6060, 0, DataType::I8, "Modes of operation"),
    PdoEntry::new(0x60C1, 1, DataType::I32, "Interpolation data record 1"),
];
/// ip TxPDO (7 bytes).
pub const IP_TX: [PdoEntry; 3] = [
    PdoEntry::new(0x6041, 0, DataType::U16, "Statusword"),
    PdoEntry::new(0x6061, 0, DataType::I8, "Modes of operation display"),
    PdoEntry::new(0x6064, 0, DataType::I32, "Position actual value"),
];
/// vl RxPDO (5 bytes).
pub const VL_RX: [PdoEntry; 3] = [
    PdoEntry::new(0x6040, 0, DataType::U16, "Controlword"),
    PdoEntry::new(0x6060, 0, DataType::I8, "Modes of operation"),
    PdoEntry::new(0x6042, 0, DataType::I16, "vl target velocity"),
];
/// vl TxPDO (5 bytes).
pub const VL_TX: [PdoEntry; 3] = [
    PdoEntry::new(0x6041, 0, DataType::U16, "Statusword"),
    PdoEntry::new(0x6061, 0, DataType::I8, "Modes of operation display"),
    PdoEntry::new(0x6044, 0, DataType::I16, "vl velocity actual value"),
];

/// Module ident of a user PDO configuration (bit 31; the low bits are a hash
/// of the mapping, [`DriveObjects::module_ident`](crate::DriveObjects::module_ident)).
pub const USER_MODULE: u32 = 0x8000_0000;

/// The bit that sets an axis-B module's ident apart from axis A's module of
/// the same layout ([`module_ident`]).
pub const AXIS_B_MODULE: u32 = 0x0000_0100;

/// The ident of the ESI module of `layout` on `axis` (0 = A, any other = B;
/// E-148, E-149): CiA 402's profile number 0192h in the high word, the axis
/// in bits 8…15 ([`AXIS_B_MODULE`] for axis B), the layout's number (1…) in
/// bits 0…7; bit 31 clear (set: a user module, [`USER_MODULE`]).
///
/// | layout | axis A | axis B |
/// |---|---|---|
/// | standard | 0192_0001h | 0192_0101h |
/// | ip | 0192_0002h | 0192_0102h |
/// | vl | 0192_0003h | 0192_0103h |
pub const fn module_ident(layout: PdoLayout, axis: u16) -> u32 {
    let number = match layout {
        PdoLayout::Standard => 1,
        PdoLayout::Ip => 2,
        PdoLayout::Vl => 3,
    };
    let axis_bit = if axis == 0 { 0 } else { AXIS_B_MODULE };
    0x0192_0000 | axis_bit | number
}

impl PdoLayout {
    /// Every layout, the system modules of the ESI.
    pub const ALL: [PdoLayout; 3] = [PdoLayout::Standard, PdoLayout::Ip, PdoLayout::Vl];

    /// The RxPDO and TxPDO entries of axis A.
    pub const fn entries(self) -> (&'static [PdoEntry], &'static [PdoEntry]) {
        self.axis_entries(0)
    }

    /// The RxPDO and TxPDO entries of the layout on `axis` (0 = A, any other
    /// = B: the CiA 402 objects at +800h, the manufacturer ones at +8000h).
    pub const fn axis_entries(self, axis: u16) -> (&'static [PdoEntry], &'static [PdoEntry]) {
        match (self, axis) {
            (PdoLayout::Standard, 0) => (&RX_A, &TX_A),
            (PdoLayout::Ip, 0) => (&IP_RX, &IP_TX),
            (PdoLayout::Vl, 0) => (&VL_RX, &VL_TX),
            (PdoLayout::Standard, _) => (&RX_B, &TX_B),
            (PdoLayout::Ip, _) => (&IP_RX_B, &IP_TX_B),
            (PdoLayout::Vl, _) => (&VL_RX_B, &VL_TX_B),
        }
    }

    /// The layout's name (the ESI module names, E-149).
    pub const fn name(self) -> &'static str {
        match self {
            PdoLayout::Standard => "Standard",
            PdoLayout::Ip => "Interpolated position (ip)",
            PdoLayout::Vl => "Velocity mode (vl)",
        }
    }
}

/// The same entries for axis B: CiA 402 objects +800h, manufacturer +8000h.
const fn axis_b<const N: usize>(a: [PdoEntry; N]) -> [PdoEntry; N] {
    let mut b = a;
    let mut i = 0;
    while i < N {
        // N is the array's length: compile-time evaluation, no run-time index.
        #[allow(clippy::indexing_slicing)]
        let e = &mut b[i];
        e.index = crate::objects::axis_b_index(e.index);
        i += 1;
    }
    b
}

/// Axis-B RxPDO entries: the default of 1601h.
pub const RX_B: [PdoEntry; 8] = axis_b(RX_A);
/// Axis-B TxPDO entries: the default of 1A01h.
pub const TX_B: [PdoEntry; 10] = axis_b(TX_A);
/// Axis-B ip RxPDO entries.
pub const IP_RX_B: [PdoEntry; 3] = axis_b(IP_RX);
/// Axis-B ip TxPDO entries.
pub const IP_TX_B: [PdoEntry; 3] = axis_b(IP_TX);
/// Axis-B vl RxPDO entries.
pub const VL_RX_B: [PdoEntry; 3] = axis_b(VL_RX);
/// Axis-B vl TxPDO entries.
pub const VL_TX_B: [PdoEntry; 3] = axis_b(VL_TX);
