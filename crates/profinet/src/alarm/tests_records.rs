//! The diagnosis records (0x800A/B/C, 0xC00x, 0xE00x, 0xF00x) through the
//! whole device: a record read as a UDP frame answers with what the
//! diagnosis list holds, as TIA Portal's online diagnostics reads it.

use crate::cm::PnioStatus;
use crate::pdev::tests::rig;
use crate::pdev::tests_check::{check, LINK_UP_CHECK, PEERS_SW1};
use crate::rpc::tests::hex;
use nanos::Nanos;

const OK: PnioStatus = PnioStatus::OK;

fn rw(code1: u8, write: bool) -> PnioStatus {
    PnioStatus::rw(if write { 0xDF } else { 0xDE }, code1)
}

/// Whether `data` holds a DiagnosisData block (0x0010) for `subslot` of
/// slot 0 with (ChannelErrorType, ExtChannelErrorType) `types`.
fn names(data: &[u8], subslot: u16, types: (u16, u16)) -> bool {
    let mut e = types.0.to_be_bytes().to_vec();
    e.extend_from_slice(&types.1.to_be_bytes());
    data.len() > 14
        && data[..2] == [0x00, 0x10]
        && data[6..12] == [0, 0, 0, 0, 0, 0]
        && data[12..14] == subslot.to_be_bytes()
        && data.windows(4).any(|w| w == e)
}

#[test]
fn p030_p040_diagnosis_records_report_the_drive_error_and_the_port_mismatch() {
    let mut r = rig();
    // nothing present: every scope reads empty
    for (sub, index) in [(1, 0x800A), (1, 0xC00C), (1, 0xE00C), (1, 0xF00C)] {
        assert_eq!(r.read(sub, index), (OK, std::vec![]), "0x{index:04X}");
    }
    // drive error 54-3 on the DAP's subslot 1 (P-030): ChannelErrorType 0x1036, ext 0x1003
    assert!(r.d.raise_diagnosis(54, 3));
    let (st, data) = r.read(1, 0x800A);
    assert_eq!(st, OK);
    assert!(names(&data, 1, (0x1036, 0x1003)), "{data:02X?}");
    assert_eq!(
        r.read(0x8001, 0x800A),
        (OK, std::vec![]),
        "another subslot's is empty"
    );
    for index in [0xC00B, 0xE00C, 0xF00C] {
        let (st, d) = r.read(0x8000, index);
        assert_eq!(
            (st, &d),
            (OK, &data),
            "0x{index:04X}: the slot's, the AR's, the API's"
        );
    }
    // port 1 checked against sw-1's port-003, no neighbour: 0x8001/0x8005 on 0x8001 (P-040)
    let mut subs = hex(PEERS_SW1);
    subs.extend_from_slice(&hex(LINK_UP_CHECK));
    assert_eq!(r.record(true, 0, 0x8001, 0x802B, &check(0x8001, &subs)).0, OK);
    r.d.poll(Nanos::from_ms(1), &mut |_: &[u8]| {});
    let (st, port) = r.read(0x8001, 0x800A);
    assert_eq!(st, OK);
    assert!(names(&port, 0x8001, (0x8001, 0x8005)), "{port:02X?}");
    let (_, all) = r.read(1, 0xE00C);
    assert_eq!(
        all.len(),
        data.len() + port.len(),
        "the AR's: both submodules' blocks"
    );
    // a missing submodule or slot; the records are read only
    assert_eq!(r.read(0x9000, 0x800A).0, rw(0xB2, false));
    assert_eq!(r.record(false, 9, 1, 0xC00A, &[]).0, rw(0xB2, false));
    assert_eq!(r.record(true, 0, 1, 0x800A, &data).0, rw(0xB6, true));
    // the drive error acknowledged (P-035): gone from the record
    assert!(r.d.clear_diagnosis(54, 3));
    assert_eq!(r.read(1, 0x800A), (OK, std::vec![]));
    let Some(text) = crate::tests_tshark::device_rpc(&r.frames) else {
        return;
    };
    assert!(text.contains("DiagnosisData"), "DiagnosisData not dissected");
}
