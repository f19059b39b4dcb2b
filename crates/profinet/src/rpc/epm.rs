//! The endpoint mapper (EPM v4) as far as a controller uses it before the
//! Connect: `ept_lookup` (opnum 2) answers the first call (nil entry handle)
//! with our one entry — the PNIO device interface with its protocol tower
//! (NDR, connectionless RPC, UDP port, IP) and annotation — and a non-nil
//! handle; the continuation call gets no entries and "not registered"
//! (= no more entries). `ept_lookup_handle_free` (opnum 4) is answered with a
//! nil handle. Inquiry filters are not evaluated: we have one entry.

use super::cursor::{Endian, Reader, Writer};
use super::uuid::{Uuid, NDR_TRANSFER_SYNTAX, PNIO_DEVICE_INTERFACE};
use crate::ip::Ipv4Addr;

/// Operation number of `ept_lookup`.
pub const OP_LOOKUP: u16 = 2;
/// Operation number of `ept_lookup_handle_free`.
pub const OP_LOOKUP_HANDLE_FREE: u16 = 4;
/// EPM status "not registered" (here: no more entries).
pub const EPT_S_NOT_REGISTERED: u32 = 0x16C9_A0D6;
/// Length of the annotation string (including the terminating NUL).
pub const ANNOTATION_LEN: usize = 64;

/// What the endpoint mapper says about us.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EpmInfo {
    /// Our PNIO object UUID (see [`super::uuid::pnio_object`]).
    pub object: Uuid,
    /// Our IP address (tower floor 5).
    pub ip: Ipv4Addr,
    /// Our RPC port (tower floor 4).
    pub port: u16,
    /// The annotation (see [`annotation`]), NUL-terminated.
    pub annotation: [u8; ANNOTATION_LEN],
}

/// Builds the PROFINET annotation: device type (25), order ID (20), hardware
/// revision (5 digits), software revision (prefix + 3 × 3 digits), blank
/// separated and NUL-terminated: 64 bytes.
pub fn annotation(
    device_type: &str,
    order_id: &str,
    hw_rev: u16,
    sw_rev: (u8, u8, u8, u8),
) -> [u8; ANNOTATION_LEN] {
    use core::fmt::Write;
    let mut s: heapless::String<ANNOTATION_LEN> = heapless::String::new();
    let field = |s: &mut heapless::String<ANNOTATION_LEN>, v: &str, n: usize| {
        for c in v
            .chars()
            .filter(char::is_ascii)
            .chain(core::iter::repeat(' '))
            .take(n)
        {
            let _ = s.push(c);
        }
    };
    field(&mut s, device_type, 25);
    let _ = s.push(' ');
    field(&mut s, order_id, 20);
    let (p, a, b, c) = sw_rev;
    let _ = write!(s, " {:>5} {}{:>3}{:>3}{:>3}", hw_rev, char::from(p), a, b, c);
    let mut out = [0u8; ANNOTATION_LEN];
    for (o, i) in out.iter_mut().zip(s.as_bytes().iter().take(ANNOTATION_LEN - 1)) {
        *o = *i;
    }
    out
}

/// Length of the tower octet string we emit.
const TOWER_LEN: u32 = 75;

fn tower(w: &mut Writer<'_>, info: &EpmInfo) -> Option<()> {
    // Tower floors are little-endian whatever the drep; port and IP big-endian.
    let floor_uuid = |w: &mut Writer<'_>, u: Uuid, major: u16| -> Option<()> {
        w.bytes(&19u16.to_le_bytes())?;
        w.u8(0x0D)?;
        w.bytes(&u.to_wire(Endian::Little))?;
        w.bytes(&major.to_le_bytes())?;
        w.bytes(&2u16.to_le_bytes())?;
        w.bytes(&0u16.to_le_bytes())
    };
    w.bytes(&5u16.to_le_bytes())?;
    floor_uuid(w, PNIO_DEVICE_INTERFACE, 1)?;
    floor_uuid(w, NDR_TRANSFER_SYNTAX, 2)?;
    w.bytes(&[1, 0, 0x0A, 2, 0, 0, 0])?; // RPC connectionless, minor 0
    w.bytes(&[1, 0, 0x08, 2, 0])?; // UDP
    w.bytes(&info.port.to_be_bytes())?;
    w.bytes(&[1, 0, 0x09, 4, 0])?; // IP
    w.bytes(&info.ip.octets())
}

/// Answers an EPM call `opnum` with body `req` (in `endian`) into `out`;
/// `None` for an opnum we do not serve or a body too short to be a lookup.
pub fn answer(info: &EpmInfo, opnum: u16, endian: Endian, req: &[u8], out: &mut [u8]) -> Option<usize> {
    let mut w = Writer::new(out, endian);
    match opnum {
        OP_LOOKUP => {
            // inquiry_type first; entry_handle (20) and max_ents (4) last, whatever
            // the object/interface pointers in between (and profinet-py's short form).
            let tail = req.len().checked_sub(24)?;
            let mut r = Reader::new(req, endian);
            let _inquiry = r.u32()?;
            let mut t = Reader::new(req.get(tail..)?, endian);
            let _attributes = t.u32()?;
            let handle = Uuid::from_wire(t.array()?, endian);
            let max_ents = t.u32()?;
            if handle.is_nil() && max_ents > 0 {
                w.u32(0)?;
                w.bytes(&info.object.to_wire(endian))?; // our continuation handle
                w.u32(1)?; // num_ents
                w.u32(1)?; // max_count
                w.u32(0)?; // offset
                w.u32(1)?; // actual_count
                w.bytes(&info.object.to_wire(endian))?;
                w.u32(3)?; // tower referent id
                let alen = info
                    .annotation
                    .iter()
                    .position(|&b| b == 0)
                    .unwrap_or(ANNOTATION_LEN - 1)
                    + 1;
                w.u32(0)?; // annotation offset
                w.u32(u32::try_from(alen).ok()?)?;
                w.bytes(info.annotation.get(..alen)?)?;
                w.align(4)?;
                w.u32(TOWER_LEN)?; // conformance
                w.u32(TOWER_LEN)?; // tower_length
                tower(&mut w, info)?;
                w.align(4)?;
                w.u32(0)?; // status ok
            } else {
                w.zeros(20)?; // nil handle
                w.u32(0)?; // num_ents
                w.u32(0)?; // max_count
                w.u32(0)?; // offset
                w.u32(0)?; // actual_count
                w.u32(EPT_S_NOT_REGISTERED)?;
            }
        }
        OP_LOOKUP_HANDLE_FREE => {
            if req.len() < 20 {
                return None;
            }
            w.zeros(20)?;
            w.u32(0)?;
        }
        _ => return None,
    }
    Some(w.pos())
}
