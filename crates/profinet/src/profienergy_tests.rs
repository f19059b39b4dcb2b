//! PROFIenergy through the device's record read and write: the service
//! requests as a controller writes them to 0x80A0, the responses it reads.

use super::*;
use crate::cm::{NoRecords, PnioStatus};
use crate::device::Device;
use crate::pdev::tests::Rig;
use crate::rpc::tests::hex;
use crate::testing;
use std::vec::Vec;

/// A product that may pause when `may` says so; switched on by `on`.
#[derive(Debug, Default)]
struct Product {
    on: bool,
    may: bool,
}

impl PeApplication for Product {
    fn enabled(&self) -> bool {
        self.on
    }
    fn may_pause(&self) -> bool {
        self.may
    }
    fn mode(&self) -> ModeTimes {
        ModeTimes {
            min_pause: 500,
            to_pause: 0,
            to_operate: 200,
            min_stay: 0,
            max_stay: 0xFFFF_FFFF,
        }
    }
}

type Hook = WithProfiEnergy<Product, NoRecords>;

fn rig(on: bool) -> Rig<Hook> {
    let hook = WithProfiEnergy {
        pe: ProfiEnergy::default(),
        app: Product { on, may: true },
        inner: NoRecords,
    };
    let mut r = Rig::new(Device::new(testing::device_config(), hook));
    r.connect();
    r
}

/// A service request: block 0x0800, the four fields, `data`.
fn request(service: u8, reference: u8, modifier: u8, dsi: u8, data: &[u8]) -> Vec<u8> {
    let mut v = std::vec![0x08, 0x00, 0, 0, 1, 0, service, reference, modifier, dsi];
    v.extend_from_slice(data);
    let len = (v.len() - 4) as u16;
    v[2..4].copy_from_slice(&len.to_be_bytes());
    v
}

/// Writes `req` to 0x80A0 at 0/1 and reads the response.
fn service(r: &mut Rig<Hook>, req: &[u8]) -> Vec<u8> {
    assert_eq!(r.record(true, 0, 1, INDEX, req).0, PnioStatus::OK);
    let (status, data) = r.record(false, 0, 1, INDEX, &[]);
    assert_eq!(status, PnioStatus::OK);
    data
}

/// The response block with `body` after its header.
fn response(body: &str) -> Vec<u8> {
    let mut v = hex("0801 0000 0100");
    v.extend(hex(body));
    let len = (v.len() - 4) as u16;
    v[2..4].copy_from_slice(&len.to_be_bytes());
    v
}

#[test]
fn p016_pe_identify_lists_the_services() {
    let mut r = rig(true);
    assert_eq!(
        service(&mut r, &request(5, 7, 0, 0, &[])),
        response("05 07 01 01 05 0102030405")
    );
}

#[test]
fn p016_query_modes_lists_one_mode_and_gets_its_times() {
    let mut r = rig(true);
    assert_eq!(
        service(&mut r, &request(3, 1, 1, 0, &[])),
        response("03 01 01 01 01 01")
    );
    let got = service(&mut r, &request(3, 2, 2, 1, &[PAUSE_MODE, 0]));
    assert_eq!(
        got,
        response(
            "03 02 01 01 01 00 000001f4 00000000 000000c8 00000000 ffffffff
             00000000 00000000 00000000"
        )
    );
    assert_eq!(got.len(), 44, "as the IM151-3 shows it: length 0x28");
    // an unknown mode: impermissible PE_Mode_ID
    assert_eq!(
        service(&mut r, &request(3, 3, 2, 1, &[0x07, 0])),
        response("03 03 02 ff 52 00")
    );
}

#[test]
fn p016_start_and_end_pause_with_pem_status() {
    let mut r = rig(true);
    assert_eq!(
        service(&mut r, &request(4, 1, 0, 0, &[])),
        response("04 01 01 01 ff ff 00000000 00000000 00000000 00000000 00000000")
    );
    assert_eq!(
        service(&mut r, &request(1, 2, 0, 1, &600u32.to_be_bytes())),
        response("01 02 01 01 01 00")
    );
    assert!(r.d.hook().pe.paused());
    assert_eq!(
        service(&mut r, &request(4, 3, 0, 0, &[])),
        response("04 03 01 01 01 01 000000c8 00000000 00000000 00000000 00000000")
    );
    assert_eq!(
        service(&mut r, &request(2, 4, 0, 0, &[])),
        response("02 04 01 01 000000c8")
    );
    assert!(!r.d.hook().pe.paused());
    // End_Pause in operation: nothing to end, no time to operate
    assert_eq!(
        service(&mut r, &request(2, 5, 0, 0, &[])),
        response("02 05 01 01 00000000")
    );
}

#[test]
fn p016_start_pause_is_refused_while_the_product_operates_or_for_a_short_pause() {
    let mut r = rig(true);
    r.d.hook_mut().app.may = false;
    assert_eq!(
        service(&mut r, &request(1, 1, 0, 1, &600u32.to_be_bytes())),
        response("01 01 02 ff 53 00")
    );
    r.d.hook_mut().app.may = true;
    assert_eq!(
        service(&mut r, &request(1, 2, 0, 1, &100u32.to_be_bytes())),
        response("01 02 02 ff 50 00")
    );
    assert!(!r.d.hook().pe.paused());
}

#[test]
fn p016_bad_requests_get_the_profiles_error_codes() {
    let mut r = rig(true);
    let cases: [(Vec<u8>, &str); 6] = [
        // Query_Measurement: not offered
        (request(0x10, 1, 1, 0, &[]), "10 01 02 ff 01 00"),
        (request(5, 0, 0, 0, &[]), "05 00 02 ff 02 00"),
        (request(5, 1, 1, 0, &[]), "05 01 02 ff 03 00"),
        (request(1, 1, 0, 0, &600u32.to_be_bytes()), "01 01 02 ff 04 00"),
        // Start_Pause without its pause time
        (request(1, 1, 0, 1, &[]), "01 01 02 ff 04 00"),
        // a block length that does not match the record
        (
            {
                let mut v = request(5, 9, 0, 0, &[]);
                v[3] = 9;
                v
            },
            "05 09 02 ff 08 00",
        ),
    ];
    for (req, want) in cases {
        assert_eq!(service(&mut r, &req), response(want));
    }
    let mut wrong_type = request(5, 9, 0, 0, &[]);
    wrong_type[1] = 0x01;
    assert_eq!(service(&mut r, &wrong_type), response("05 09 02 ff 08 00"));
    assert!(!r.d.hook().pe.paused());
}

#[test]
fn p016_a_short_request_is_refused_with_write_length_and_changes_nothing() {
    let mut r = rig(true);
    service(&mut r, &request(5, 7, 0, 0, &[]));
    let before = r.d.hook().pe.clone();
    for n in [0, 3, 9] {
        let short = &request(1, 1, 0, 1, &600u32.to_be_bytes())[..n];
        assert_eq!(r.record(true, 0, 1, INDEX, short).0, PnioStatus::rw(0xDF, 0xB1));
        assert_eq!(r.d.hook().pe, before);
    }
}

#[test]
fn p016_the_record_lives_at_the_dap_and_a_read_needs_a_request() {
    let mut r = rig(true);
    assert_eq!(r.record(false, 0, 1, INDEX, &[]).0, PnioStatus::rw(0xDE, 0xB5));
    let req = request(5, 1, 0, 0, &[]);
    assert_eq!(
        r.record(true, 0, 0x8000, INDEX, &req).0,
        PnioStatus::rw(0xDF, 0xB0)
    );
    assert_eq!(r.record(true, 0, 7, INDEX, &req).0, PnioStatus::rw(0xDF, 0xB2));
}

#[test]
fn p015_p016_with_profienergy_off_the_record_is_an_invalid_index() {
    let mut r = rig(false);
    let req = request(5, 1, 0, 0, &[]);
    assert_eq!(r.record(true, 0, 1, INDEX, &req).0, PnioStatus::rw(0xDF, 0xB0));
    assert_eq!(r.record(false, 0, 1, INDEX, &[]).0, PnioStatus::rw(0xDE, 0xB0));
    // other records still go to the inner hook (none here)
    assert_eq!(r.record(false, 0, 1, 0x1000, &[]).0, PnioStatus::rw(0xDE, 0xB0));
}

#[test]
fn p016_service_frames_dissect_without_malformed_packets() {
    let mut r = rig(true);
    service(&mut r, &request(5, 1, 0, 0, &[]));
    service(&mut r, &request(1, 2, 0, 1, &600u32.to_be_bytes()));
    service(&mut r, &request(3, 3, 2, 1, &[PAUSE_MODE, 0]));
    // this tshark (4.0) shows 0x80A0's data as undecoded bytes: the check
    // is that the record accesses around them are well formed
    let text = crate::tests_tshark::dissect_with(&r.frames, "dcerpc && ip.src == 192.168.0.50", true);
    if let Some(t) = text {
        assert_eq!(t.matches("(0x80a0)").count(), 6, "3 writes and 3 reads");
    }
}
