//! Record 0xB02E through the drive's device (P-206): a parameter request
//! written, its response read back, over the RPC record channel of the
//! Connect's AR.

use super::tests::drive;
use super::tests_energy::record_at;
use profidrive::bmp::RECORD_INDEX;
use profinet::cm::PnioStatus;

/// A read request of (PNU, subindex) values.
pub(crate) fn read_req(reference: u8, params: &[(u16, u16)]) -> std::vec::Vec<u8> {
    let mut v = std::vec![reference, 0x01, 0x01, params.len() as u8];
    for &(pnu, sub) in params {
        v.extend_from_slice(&[0x10, 1]);
        v.extend_from_slice(&pnu.to_be_bytes());
        v.extend_from_slice(&sub.to_be_bytes());
    }
    v
}

/// Written, then read: the response; PNU 964.0 (U16) and the CANopen
/// object 6041h (U16) in one request; a change of PNU 1004 (U16) is done
/// and reads back.
#[test]
fn p206_record_0xb02e_serves_parameter_requests() {
    let mut d = drive();
    let (s, _) = record_at(
        &mut d,
        10,
        true,
        RECORD_INDEX,
        &read_req(5, &[(964, 0), (0x6041, 0)]),
    );
    assert_eq!(s, PnioStatus::OK, "the request is taken");
    let (s, r) = record_at(&mut d, 11, false, RECORD_INDEX, &[]);
    assert_eq!(s, PnioStatus::OK);
    let vendor = profinet::model::VENDOR_ID.to_be_bytes();
    let sw = (d.objects().get(0x6041, 0).unwrap() as u16).to_be_bytes();
    assert_eq!(
        r,
        [5, 0x01, 0x01, 2, 0x06, 1, vendor[0], vendor[1], 0x06, 1, sw[0], sw[1]]
    );
    // change PNU 1004 (override) to 1500 ‰
    let mut change = std::vec![6, 0x02, 0x01, 1, 0x10, 1, 0x03, 0xEC, 0, 0];
    change.extend_from_slice(&[0x06, 1, 0x05, 0xDC]);
    assert_eq!(
        record_at(&mut d, 12, true, RECORD_INDEX, &change).0,
        PnioStatus::OK
    );
    let (_, r) = record_at(&mut d, 13, false, RECORD_INDEX, &[]);
    assert_eq!(r, [6, 0x02, 0x01, 1], "done: the header only");
    assert_eq!(d.objects().get(drive_core::objects::records::J403, 0), Ok(1500));
}

/// A read before any request, or a second read of one response, is a
/// state conflict; a request too short for its header a write length
/// error; a missing PNU answers its error block (0x81, format 0x44, error
/// 0x00) and changes nothing.
#[test]
fn p206_record_0xb02e_refusals() {
    let mut d = drive();
    let (s, _) = record_at(&mut d, 20, false, RECORD_INDEX, &[]);
    assert_ne!(s, PnioStatus::OK, "nothing to read yet");
    assert_ne!(
        record_at(&mut d, 21, true, RECORD_INDEX, &[1, 1]).0,
        PnioStatus::OK,
        "too short"
    );
    assert_eq!(
        record_at(&mut d, 22, true, RECORD_INDEX, &read_req(9, &[(999, 0)])).0,
        PnioStatus::OK
    );
    let (_, r) = record_at(&mut d, 23, false, RECORD_INDEX, &[]);
    assert_eq!(r, [9, 0x81, 0x01, 1, 0x44, 1, 0x00, 0x00]);
    let (s, _) = record_at(&mut d, 24, false, RECORD_INDEX, &[]);
    assert_ne!(s, PnioStatus::OK, "read once");
}

/// A change request of (PNU, subindex, format, big-endian value) in one
/// request: the addresses first, then the values.
pub(crate) fn change_req(reference: u8, params: &[(u16, u16, u8, &[u8])]) -> std::vec::Vec<u8> {
    let mut v = std::vec![reference, 0x02, 0x01, params.len() as u8];
    for &(pnu, sub, _, _) in params {
        v.extend_from_slice(&[0x10, 1]);
        v.extend_from_slice(&pnu.to_be_bytes());
        v.extend_from_slice(&sub.to_be_bytes());
    }
    for &(_, _, format, value) in params {
        v.extend_from_slice(&[format, 1]);
        v.extend_from_slice(value);
    }
    v
}

/// One request written and its response read.
pub(crate) fn exchange(
    d: &mut super::PnDrive<super::tests::TestFlash>,
    seq: u32,
    req: &[u8],
) -> std::vec::Vec<u8> {
    assert_eq!(record_at(d, seq, true, RECORD_INDEX, req).0, PnioStatus::OK);
    let (s, r) = record_at(d, seq + 1, false, RECORD_INDEX, &[]);
    assert_eq!(s, PnioStatus::OK);
    r
}

const G472: u16 = drive_core::parameter_index(6, 472);
const C31: u16 = drive_core::parameter_index(2, 31);

/// P-199 through record 0xB02E alone (a device-access AR, no cyclic
/// data): G472 and the speed controller's Kp C31 changed, PNU 971 = 1
/// saves at once (PNU 971 reads 0 in the next request), a change after
/// the save is lost at the restart, the saved values come back.
#[test]
fn p199_p206_pnu_971_through_0xb02e_saves_without_cyclic_data() {
    let mut d = drive();
    let r = exchange(
        &mut d,
        30,
        &change_req(
            1,
            &[
                (G472, 0, 0x06, &500u16.to_be_bytes()),
                (C31, 0, 0x07, &90_000u32.to_be_bytes()),
            ],
        ),
    );
    assert_eq!(r, [1, 0x02, 0x01, 2], "both changed");
    let r = exchange(&mut d, 32, &change_req(2, &[(971, 0, 0x06, &1u16.to_be_bytes())]));
    assert_eq!(r, [2, 0x02, 0x01, 1], "save taken");
    let r = exchange(&mut d, 34, &read_req(3, &[(971, 0)]));
    assert_eq!(
        r,
        [3, 0x01, 0x01, 1, 0x06, 1, 0, 0],
        "PNU 971 reads 0: the save is over"
    );
    assert_eq!(
        d.objects().get(drive_core::params::A00, 3),
        Ok(0),
        "A00[2]: saved"
    );
    // not saved: gone at the restart
    exchange(
        &mut d,
        36,
        &change_req(4, &[(C31, 0, 0x07, &70_000u32.to_be_bytes())]),
    );
    let mut d = super::tests::connected(super::PnDrive::new(d.into_flash(), super::tests::hardware()));
    let r = exchange(&mut d, 40, &read_req(5, &[(G472, 0), (C31, 0)]));
    let (g, c) = (500u16.to_be_bytes(), 90_000u32.to_be_bytes());
    assert_eq!(
        r,
        [5, 0x01, 0x01, 2, 0x06, 1, g[0], g[1], 0x07, 1, c[0], c[1], c[2], c[3]]
    );
}

/// The dictionary's save (A00\[0\] = 1, PNU = index 2000h sub 1) through
/// 0xB02E saves as PNU 971 does; A00\[0\] reads 0 afterwards.
#[test]
fn p199_a00_through_0xb02e_saves() {
    let mut d = drive();
    exchange(
        &mut d,
        50,
        &change_req(1, &[(G472, 0, 0x06, &300u16.to_be_bytes())]),
    );
    let a00 = drive_core::params::A00;
    let r = exchange(&mut d, 52, &change_req(2, &[(a00, 1, 0x05, &[1, 0])]));
    assert_eq!(r, [2, 0x02, 0x01, 1], "save taken");
    assert_eq!(d.objects().get(a00, 1), Ok(0), "A00[0]: done");
    let d = super::PnDrive::new(d.into_flash(), super::tests::hardware());
    assert_eq!(d.objects().get(G472, 0), Ok(300));
}
