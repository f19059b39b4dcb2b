//! DCE UUIDs and the well-known ones of PROFINET IO and the endpoint mapper.

use super::cursor::Endian;

/// A UUID in canonical byte order (the order of its text form,
/// `time_low-time_mid-time_hi-clock_seq-node`), the order PROFINET blocks carry.
/// In an RPC header the first three fields follow the `drep` byte order
/// ([`Uuid::from_wire`], [`Uuid::to_wire`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Uuid(pub [u8; 16]);

impl Uuid {
    /// The nil UUID.
    pub const NIL: Uuid = Uuid([0; 16]);

    /// Builds a UUID from its five text fields.
    pub const fn from_fields(
        time_low: u32,
        time_mid: u16,
        time_hi: u16,
        clock_seq: u16,
        node: [u8; 6],
    ) -> Uuid {
        let a = time_low.to_be_bytes();
        let b = time_mid.to_be_bytes();
        let c = time_hi.to_be_bytes();
        let d = clock_seq.to_be_bytes();
        Uuid([
            a[0], a[1], a[2], a[3], b[0], b[1], c[0], c[1], d[0], d[1], node[0], node[1], node[2], node[3],
            node[4], node[5],
        ])
    }

    /// Decodes 16 bytes of an RPC header written in `endian` order.
    pub const fn from_wire(b: [u8; 16], endian: Endian) -> Uuid {
        match endian {
            Endian::Big => Uuid(b),
            Endian::Little => Uuid(swap(b)),
        }
    }

    /// Encodes for an RPC header in `endian` order.
    pub const fn to_wire(self, endian: Endian) -> [u8; 16] {
        match endian {
            Endian::Big => self.0,
            Endian::Little => swap(self.0),
        }
    }

    /// True for the nil UUID.
    pub fn is_nil(&self) -> bool {
        self.0 == [0; 16]
    }
}

const fn swap(b: [u8; 16]) -> [u8; 16] {
    [
        b[3], b[2], b[1], b[0], b[5], b[4], b[7], b[6], b[8], b[9], b[10], b[11], b[12], b[13], b[14], b[15],
    ]
}

const PNIO_NODE: [u8; 6] = [0x00, 0xA0, 0x24, 0x42, 0xDF, 0x7D];

/// PNIO device interface DEA00001-6C97-11D1-8271-00A02442DF7D (served by us).
pub const PNIO_DEVICE_INTERFACE: Uuid = Uuid::from_fields(0xDEA0_0001, 0x6C97, 0x11D1, 0x8271, PNIO_NODE);
/// PNIO controller interface DEA00002-… (the controller's CControl server).
pub const PNIO_CONTROLLER_INTERFACE: Uuid = Uuid::from_fields(0xDEA0_0002, 0x6C97, 0x11D1, 0x8271, PNIO_NODE);
/// Version of the PNIO interfaces (major 1, minor 0).
pub const PNIO_INTERFACE_VERSION: u32 = 1;
/// The endpoint mapper interface E1AF8308-5D1F-11C9-91A4-08002B14A0FA.
pub const EPM_INTERFACE: Uuid = Uuid::from_fields(
    0xE1AF_8308,
    0x5D1F,
    0x11C9,
    0x91A4,
    [0x08, 0x00, 0x2B, 0x14, 0xA0, 0xFA],
);
/// Version of the endpoint mapper interface (3.0).
pub const EPM_INTERFACE_VERSION: u32 = 3;
/// The NDR transfer syntax 8A885D04-1CEB-11C9-9FE8-08002B104860, version 2.
pub const NDR_TRANSFER_SYNTAX: Uuid = Uuid::from_fields(
    0x8A88_5D04,
    0x1CEB,
    0x11C9,
    0x9FE8,
    [0x08, 0x00, 0x2B, 0x10, 0x48, 0x60],
);

/// The device's PNIO object UUID DEA00000-6C97-11D1-8271-{instance}{device ID}{vendor ID}.
pub const fn pnio_object(instance: u16, device_id: u16, vendor_id: u16) -> Uuid {
    let i = instance.to_be_bytes();
    let d = device_id.to_be_bytes();
    let v = vendor_id.to_be_bytes();
    Uuid::from_fields(
        0xDEA0_0000,
        0x6C97,
        0x11D1,
        0x8271,
        [i[0], i[1], d[0], d[1], v[0], v[1]],
    )
}
